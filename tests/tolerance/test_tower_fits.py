"""The COP tower's mechanics a machinist measures: the splitter seat's pockets as fits on every
shipped printer, the tower's bolts long enough for their nuts with the conical spring washers, the
column foot under the projector's overturning moment, the camera's tilt adjuster, the shelf's first
mode and a lab's +-3 C (rigcad.parts.tower, rigcad.fab.loads, rigcad.fab.stack)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rigcad.fab.printers import load_printer
from rigcad.parts import tower as T
from rigcad.parts.recipe import Box, Cylinder

PRINTERS = sorted(p.stem for p in (Path(__file__).resolve().parents[2] / "profiles" / "printers").glob("*.yaml"))


@pytest.mark.parametrize("name", PRINTERS)
def test_every_seat_pocket_prints_a_clearance_fit_the_bond_fills(table31, name):
    """Drawn at the hardware's size the pockets printed 0.1-0.3 mm under it; now each prints over it by
    the clearance at least and by no more than the epoxy fills, on every shipped printer."""
    process = load_printer(name).process_errors
    for row in T.seat_pocket_fits(table31, process):
        # at least 0: the part drops in by hand (no interference a printed wall cracks on)
        assert row["gap_mm"] >= 0.0, f"{name}: the {row['pocket']}'s pocket prints {row['gap_mm']:.2f} mm under"
        # at most the bond's stated gap (SEAT_BOND: the epoxy's 0.5 mm)
        assert row["gap_mm"] <= T.SEAT_BOND[1], f"{name}: the {row['pocket']}'s pocket is too loose for the bond"
        assert row["fit"] == "clearance" and "bond" in row["step"] and "open the" not in row["step"]


def test_a_process_that_shrinks_past_the_allowance_gets_the_shop_step(table31):
    """A planted process shrinking holes by 0.6 mm (twice the allowance) prints each pocket under its
    hardware: the fit says interference and the step opens the pocket to its drawn size first."""
    from dataclasses import replace

    worse = replace(load_printer("prusa_mk3s").process_errors, hole_shrink_vertical=0.6)
    for row in T.seat_pocket_fits(table31, worse):
        assert row["fit"] == "interference" and row["gap_mm"] < 0
        assert row["step"].startswith(f"open the {row['pocket']}'s pocket to its drawn")


def test_the_shelf_cuts_the_pockets_at_their_drawn_size(table31_rig):
    """The recipe's cuts (what the STEP is built from) are the fit table's drawn sizes, not the hardware's."""
    p, t = table31_rig.profile, table31_rig.layout.tower
    fits = {f["pocket"]: f for f in T.seat_pocket_fits(p)}
    cone, vee, flat = T._seat_cuts(t, p)
    assert isinstance(cone, Cylinder) and 2 * cone.radius == pytest.approx(fits["cone"]["drawn_mm"][0], abs=1e-12)
    for cut, key in ((vee, "vee"), (flat, "flat")):
        assert isinstance(cut, Box)
        sizes = sorted((cut.hi[0] - cut.lo[0], cut.hi[1] - cut.lo[1]))
        assert sizes == pytest.approx(sorted(fits[key]["drawn_mm"]), abs=1e-12)
        assert min(sizes) > min(fits[key]["hardware_mm"]) + T.SEAT_POCKET_SHRINK  # over the hardware by the allowance
    # the bill's rows carry the fit and its step
    rows = [h for h in T.hardware(p, table31_rig.layout) if "fit_mm" in h]
    assert sorted(h["fit_mm"]["pocket"] for h in rows) == ["cone", "flat", "vee"]
    assert all("bond" in h["joins"] for h in rows)
