"""A tolerance-stack refusal names a remedy the lab can carry out: for a placement whose adjuster is
short of the stack, the profile key that sets the adjuster's range and the value that passes it (and
that value does pass it); for seams, only what a key or the printer choice can buy."""

from __future__ import annotations

import pytest

from rigcad.errors import FabricationError
from rigcad.fab import stack as S
from rigcad.fab.printers import load_printer
from rigcad.profile import load_profile
from rigcad.rig import Rig

#: Seams as a small bed leaves them (the newcomer's Prusa MINI+ run: fab.json's stack.seams).
MINI_SEAMS = {"base_plate": 4, "tower_shelf": 3, "tower_column": 1}


@pytest.fixture(scope="module")
def mk3s():
    return load_printer("prusa_mk3s")


def _refused(rig, printer) -> dict:
    report = S.stack(rig.profile, rig.layout, printer, seams=MINI_SEAMS)
    return {(v.element, v.axis): v for v in report.refused}


def test_a_short_adjuster_names_its_range_key_and_the_value_that_passes(table31_rig, table31_text, write_profile,
                                                                         mk3s):
    refused = _refused(table31_rig, mk3s)
    cop = refused["cop", "lateral"]
    assert cop.cure and cop.cure[0].startswith("tower.travel_across >= ")
    need = float(cop.cure[0].split(">= ")[1].removesuffix(" mm"))
    assert need >= cop.worst  # the travel must cover at least today's stack (which grows with the travel)
    with pytest.raises(FabricationError, match=r"set tower\.travel_across >= [0-9.]+ mm"):
        S.refuse(S.stack(table31_rig.profile, table31_rig.layout, mk3s, seams=MINI_SEAMS))
    # the value passes: the same seams, with the travel the refusal asks for
    cured = Rig.from_profile(load_profile(write_profile(table31_text + f"tower:\n  travel_across: {need} mm\n")))
    after = _refused(cured, mk3s)
    assert ("cop", "lateral") not in after
    # and it is the least such value to 0.1 mm: one step less is still refused
    short = Rig.from_profile(load_profile(write_profile(table31_text + f"tower:\n  travel_across: {need - 0.1:g} mm\n",
                                                        "short")))
    assert ("cop", "lateral") in _refused(short, mk3s)
    for (element, axis), v in after.items():  # whatever is still refused is not the travel's to cure
        assert not any(c.startswith("tower.travel_across") for c in v.cure), (element, axis, v.cure)


def test_no_refusal_offers_a_remedy_no_key_chooses(table31_rig, mk3s):
    """The seams' remedies are a bed that takes the part whole (the printer chosen) or the buy: key that
    buys the part whole; never parts no profile or printer key selects (steel dowels across a seam)."""
    refused = _refused(table31_rig, S.with_process(mk3s, position=0.3))
    assert refused
    buys = {b for v in refused.values() for b in v.buy}
    assert not any("ISO 8734" in b for b in buys)
    seam_buys = {b for b in buys if "whole" in b or b.startswith("buy.")}
    assert "buy.shelf: aluminium_plate" in seam_buys
    assert "a printer whose bed takes the base plate whole (rigcad fab --printer)" in seam_buys
    # a key the refusal names is one the profile has
    for b in seam_buys:
        if b.startswith("buy."):
            section, rest = b.split(".", 1)
            key, value = rest.split(": ")
            assert hasattr(getattr(table31_rig.profile, section), key)
