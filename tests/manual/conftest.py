"""Fixtures shared by the manual's tests."""

from __future__ import annotations

import pytest

from rigcad.manual import document as D


@pytest.fixture(scope="module")
def written(table31_rig, tmp_path_factory):
    """The default rig's manual for the MK3S, written once per test module beside a fab of the base
    plate only (the manual reads fab's report; the other parts' pieces are not needed): its folder."""
    from rigcad.fab.printers import load_printer

    fab = table31_rig.fab("prusa_mk3s", tmp_path_factory.mktemp("fab") / "fab", parts=["base_plate"]).report
    out = tmp_path_factory.mktemp("manual") / "prusa_mk3s"
    D.write_manual(table31_rig, load_printer("prusa_mk3s"), fab, out)
    return out
