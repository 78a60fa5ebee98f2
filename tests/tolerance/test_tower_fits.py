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


def _rigs(table31_rig, other_rig):
    return (("default", table31_rig), ("second", other_rig))


def test_every_tower_screw_joint_engages_its_nut_insert_or_socket(table31_rig, other_rig):
    """Each screw joint of the tower, on the default rig and the second: a nut stands a thread under the
    bolt's end (the conical spring washer's free height counted), an insert is engaged a diameter or
    more and never bottomed, an instrument's socket as its stack asks."""
    for name, rig in _rigs(table31_rig, other_rig):
        rows = T.screw_engagements(rig.profile, rig.layout)
        assert {r["into"] for r in rows} >= {"nut", "heat-set insert", "the instrument's socket"}
        bad = [r for r in rows if not r["ok"]]
        assert not bad, f"{name}: {bad}"


def test_the_column_foot_bolt_is_long_enough_by_the_standards_figures(table31_rig, other_rig):
    """Independently of the code's grip: the row's bolt length less the DIN 6796 washer's free height,
    the ISO 7093-1 M4 washer, the foot and the tongue over the trap leaves the ISO 4032 nut's height and
    at least one pitch; and the bolt ends above the bench. (Planted once: NUT_PROUD_PITCHES = 0, the
    trap as shallow as 'just reaches' fails here: the old 5.6 mm trap left 0.3 mm with the conical washer.)"""
    from rigcad.standards import CONICAL_SPRING_WASHERS, ISO_7093, THREADS

    for name, rig in _rigs(table31_rig, other_rig):
        p, t = rig.profile, rig.layout.tower
        row = next(h for h in T.hardware(p, rig.layout) if h["joins"].startswith("the column's foot"))
        assert "DIN 6796" in row["spring_washer"] and "DIN 6796" in row["item"]
        trap = T.nut_trap_depth(p, t)
        tongue = -t.bench_z
        grip = CONICAL_SPRING_WASHERS["M4"][3] + ISO_7093["M4"][2] + p.tower.wall + tongue - trap
        proud = row["length_mm"] - grip - THREADS["M4"].nut_height
        assert proud >= THREADS["M4"].pitch - 1e-9, f"{name}: the bolt stands {proud:.2f} mm out of its nut"
        # the bolt's end above the bench (the tongue stands on it): its head over the bench less its length
        above = CONICAL_SPRING_WASHERS["M4"][3] + ISO_7093["M4"][2] + p.tower.wall + tongue - row["length_mm"]
        assert above >= T.BENCH_CLEAR - 1e-9
        assert tongue - trap >= T.TRAP_ROOF_MIN  # a printed roof over the nut, not a skin
