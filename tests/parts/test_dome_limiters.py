"""The dome's flange joint carries compression limiters (the rule: every bolted joint on a datum chain,
rigcad.parts.joints): its holes are the bolt's room widened by the sleeve's walls, the washer under
each head seats on the sleeve all round, the preload lands the washer on the sleeve wherever the bolt
stands in its hole, the flange still has material round each hole, and the bill and the shop step
carry the sleeves."""

from __future__ import annotations

import dataclasses
import importlib
import math

import pytest

from rigcad.errors import GeometryError
from rigcad.fab import loads
from rigcad.fab.printers import load_printer
from rigcad.manual import bom
from rigcad.parts.joints import LIMITER_SQUEEZE_MM, ScrewJoint
from rigcad.parts.recipe import Cylinder, Difference
from rigcad.parts.washers import large, seat_edge
from rigcad.standards import COMPRESSION_LIMITERS, THREADS

dome = importlib.import_module("rigcad.parts.dome")


def _joint(rig) -> ScrewJoint:
    (joint,) = [j for j in rig.recipes["dome"].joints if isinstance(j, ScrewJoint)]
    return joint


def _lens(r1: float, r2: float, d: float) -> float:
    """Area (mm2) common to two discs of radii r1, r2 whose centres are d apart (the circle-circle lens)."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return math.pi * min(r1, r2) ** 2
    a = r1 * r1 * math.acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    b = r2 * r2 * math.acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    return a + b - 0.5 * math.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))


def test_the_flange_joint_is_a_datum_joint_with_a_sleeve_at_each_bolt(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    joint, lim = _joint(table31_rig), COMPRESSION_LIMITERS["M4"]
    assert joint.datum and joint.limiter and joint.limiter_part is lim
    # the sleeve is the flange's 6 mm less the squeeze, and the bolt's grip runs through it
    assert joint.limiter_length == pytest.approx(p.dome_shell.flange_thickness - LIMITER_SQUEEZE_MM, abs=1e-12)
    # the holes the dome's recipe cuts at the bolts: the bolt's room widened by the sleeve's two walls
    body = table31_rig.recipes["dome"].solid
    assert isinstance(body, Difference)
    hole = dome.flange_bolt_hole(p, lay)
    for x, y in joint.points:
        (cut,) = [c for c in body.cuts if isinstance(c, Cylinder) and math.hypot(c.base[0] - x, c.base[1] - y) < 1e-9]
        assert 2 * cut.radius == pytest.approx(hole, abs=1e-12)
    assert hole - dome.flange_bolt_room(p, lay) == pytest.approx(lim.outer - THREADS["M4"].major, abs=1e-12)
    # the sleeve keeps the indicating travel the bare bolt had: 1 mm each way past the print's errors
    assert dome.indicate_travel(p, lay) == pytest.approx(dome.INDICATE_TRAVEL_MM, abs=1e-12)


def test_the_washer_seats_on_the_sleeve_all_round_and_overlaps_the_plastic(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    lim, major = COMPRESSION_LIMITERS["M4"], THREADS["M4"].major
    stack = dome.flange_washers(p, lay)
    (w,) = stack.washers
    assert (w.standard, w.size, w.outer) == ("ISO 7093-1", "M4", 12.0)
    # slid on the bolt one way and the sleeve the other, its bore edge stays inside the sleeve wall's middle
    # (2.15 + 0.15 + 0.2 = 2.5 mm against 2.6 mm): the end face is seated all round
    assert seat_edge(w, major, lim) <= (lim.outer - lim.wall) / 2
    # the M5 large washer, which would bear more on the plastic, floats off the 6 mm sleeve on one side
    assert seat_edge(large("M5"), major, lim) > lim.outer / 2
    hole = dome.flange_bolt_hole(p, lay)
    assert w.outer > hole and stack.area_mm2 == pytest.approx(math.pi / 4 * (w.outer ** 2 - hole ** 2), abs=1e-9)
    # the joint orders that washer, and the flange's bolt is still M4 x 16 through it
    assert _joint(table31_rig).washer_mm == w.thickness and _joint(table31_rig).length == 16


def test_the_preload_lands_the_washer_on_the_sleeve_wherever_the_bolt_stands(table31_rig):
    """The torque table's preload squeezes the plastic under the washer by LIMITER_SQUEEZE_MM and then
    bears on the sleeve: the squeeze at PLA's stiffest modulus over the largest overlap of washer on
    plastic (the bolt anywhere in the hole's room round its sleeve) is under the preload, and the
    plastic's stress at the squeeze is under the creep allowance."""
    p, lay = table31_rig.profile, table31_rig.layout
    mk3s = load_printer("prusa_mk3s")
    (b,) = [x for x in loads.bolt_loads(p, lay, mk3s) if x.joint == "dome flange on the base plate"]
    pla = loads.material(mk3s)
    squeeze = pla.modulus_high * LIMITER_SQUEEZE_MM / p.dome_shell.flange_thickness  # MPa
    assert squeeze < loads.BEARING_SHARE * pla.yield_strength  # 10.1 MPa against 13 MPa
    hole, lim = dome.flange_bolt_hole(p, lay), COMPRESSION_LIMITERS["M4"]
    (w,) = dome.flange_washers(p, lay).washers
    room = (hole - lim.outer) / 2
    # the washer's disc less the part of it over the hole, the bolt offset 0 .. room (the overlap grows
    # as the hole slides out from under the washer: 35 mm2 centred, 42 mm2 at the room's end)
    overlap = max(math.pi * w.outer ** 2 / 4 - _lens(w.outer / 2, hole / 2, room * k / 50) for k in range(51))
    assert overlap * squeeze < b.preload_n, (overlap, squeeze, b.preload_n)
    assert b.spring_washer and b.bearing.startswith("large washer (ISO 7093-1 M4, 12 mm)")


def test_a_flange_too_narrow_for_the_sleeves_holes_is_refused_naming_its_width(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    hole = dome.flange_bolt_hole(p, lay)
    # the 12 mm washer and the 9.97 mm hole need 7 mm of flange each side of the bolt circle
    narrow = dataclasses.replace(lay, flange_outer_r=lay.bolt_circle_r + 6.5)
    with pytest.raises(GeometryError, match=r"dome_shell.flange_width") as err:
        dome.flange_bolt_hole(p, narrow)
    assert f"{hole:.2f} mm bolt holes" in str(err.value)
    assert dome.flange_bolt_hole(p, dataclasses.replace(lay, flange_outer_r=lay.bolt_circle_r + 7.0)) == hole


def test_the_bill_and_the_shop_step_carry_the_dome_s_sleeves(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    joint = _joint(table31_rig)
    lines = bom.limiter_lines(table31_rig)
    mine = {k: v for k, v in lines.items() if "under dome's bolts" in k}
    assert list(mine.values()) == [8] and f"faced to {joint.limiter_length:.2f} mm" in next(iter(mine))
    text = dome.register(p, lay).procedure
    # the sleeves go in before the dome is indicated in, and the bolts are snugged through them
    assert text.startswith(joint.limiter_step() + ". ") and "5.98 mm as drawn" in text
    assert f"through the sleeves in its {dome.flange_bolt_hole(p, lay):.2f} mm holes" in text
    assert "M4 large washers (ISO 7093-1, 12 mm: seated on the sleeves)" in text


def test_the_mechanics_page_states_the_dome_s_limiters_as_the_code_has_them(table31_rig):
    from pathlib import Path

    p, lay = table31_rig.profile, table31_rig.layout
    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md").read_text().split())
    joint, hole = _joint(table31_rig), dome.flange_bolt_hole(p, lay)
    mk3s = load_printer("prusa_mk3s")
    (b,) = [x for x in loads.bolt_loads(p, lay, mk3s) if x.joint == "dome flange on the base plate"]
    squeeze = loads.material(mk3s).modulus_high * LIMITER_SQUEEZE_MM / p.dome_shell.flange_thickness
    (w,) = dome.flange_washers(p, lay).washers
    room = (hole - COMPRESSION_LIMITERS["M4"].outer) / 2
    overlap = math.pi * w.outer ** 2 / 4 - _lens(w.outer / 2, hole / 2, room)  # the largest: the bolt at the room's end
    assert (f"a {joint.limiter_length:.2f} mm sleeve at each of its {joint.count} bolts, standing on the base plate's "
            f"insert, in holes of {hole:.2f} mm (the bolt's {dome.flange_bolt_room(p, lay):.2f} mm of room") in text
    assert f"large washer (ISO 7093-1 M4, {w.outer:g} mm)" in text
    assert (f"the largest overlap on the plastic, {overlap:.0f} mm2, takes {overlap * squeeze:.0f} N of the "
            f"{b.preload_n:.0f} N)") in text
