"""Fixtures the tolerance-stack tests share: the desktop printer and a second rig with other
instruments (a short-throw projector and an M3 machine-vision camera, 2.5 mm holes)."""

import pytest

from rigcad.fab.printers import load_printer
from rigcad.profile import load_profile
from rigcad.rig import Rig

#: The second rig's instruments, on top of the default profile.
OTHER = "projector:\n  model: benq_mw632st\ncamera:\n  model: flir_blackfly_s_bfs_u3_32s4c\n"


@pytest.fixture(scope="session")
def mk3s():
    return load_printer("prusa_mk3s")


@pytest.fixture(scope="session")
def other_rig(tmp_path_factory, table31_text):
    path = tmp_path_factory.mktemp("other") / "other.yaml"
    path.write_text(table31_text + OTHER, encoding="utf-8")
    return Rig.from_profile(load_profile(path))
