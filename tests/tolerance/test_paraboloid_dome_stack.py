"""The paraboloid's and the dome's stacks as the precision machinist reads them: on the MK3S the
paraboloid is adjusted on all three axes by its shim stops (the clamp's x and y stops on the beam, the
beam's seats' height and tilt) and the dome indicated in from the sample bore, for the default rig and
a rig with other instruments; each stop and the indicating tested with its figure planted worse
(a thicker foil, a thinner pack, less travel), and read back from the STEP where it is geometry."""

from __future__ import annotations

import importlib
import math

import build123d as bd
import pytest

from rigcad.fab import stack as S
from rigcad.parts import locating as LOC
from rigcad.standards import INSERTS, SHIM_FOIL

paraboloid = importlib.import_module("rigcad.parts.paraboloid")
dome = importlib.import_module("rigcad.parts.dome")

ELEMENTS = ("paraboloid", "dome")

# mk3s and other_rig (the second rig, other instruments): tests/tolerance/conftest.py


def _axes(report):
    return {(v.element, v.axis): v for e in report.elements for v in e.axes}


def test_the_paraboloid_and_the_dome_hold_on_every_axis_for_two_rigs(table31_rig, other_rig, mk3s):
    assert other_rig.profile.projector.model == "benq_mw632st"
    for rig in (table31_rig, other_rig):
        report = S.stack(rig.profile, rig.layout, mk3s)
        v = _axes(report)
        for e in ELEMENTS:
            for a in S.AXES:
                assert v[e, a].status in ("held", "adjusted"), (rig.profile.name, e, a, v[e, a].reason)
                if v[e, a].status == "adjusted":  # range covers the worst case; the step is a quarter of the tolerance
                    adj = v[e, a].adjuster
                    assert adj.range >= v[e, a].worst and adj.resolution <= 0.25 * v[e, a].tolerance, (e, a)
        # the paraboloid's three axes need the stops (no float is left on its chain), the dome's lateral
        # the indicating: each is adjusted, not merely held
        assert all(v["paraboloid", a].status == "adjusted" for a in S.AXES)
        assert v["dome", "lateral"].status == "adjusted"
        names = {k.name for k in report.element("paraboloid").links}
        assert not names & set(S.PARABOLOID_FLOATS) and not names & set(S.DOME_FLOATS)
        assert all(math.isfinite(k.lateral) for k in report.element("paraboloid").links)


def test_each_stop_serves_its_axis_at_a_quarter_of_the_tolerance(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    tol = p.tolerancing
    stops = {s.axis: s for s in (*paraboloid.stops(p, lay), *dome.beam_seats(p, lay).stops())}
    assert set(stops) == {"x", "y", "vertical", "tilt", "roll"}
    step = min(SHIM_FOIL)
    # along and across the beam the stop moves the paraboloid one for one: the thinnest foil is the step
    assert stops["x"].resolution == stops["y"].resolution == step <= tol.paraboloid_offset / 4
    # in height both seats move together: a change at one seat moves the middle half as much
    assert stops["vertical"].resolution == step / 2 <= tol.paraboloid_height / 4
    # the tilt: one seat against the other over the span between their screws
    seats = dome.beam_seats(p, lay)
    assert stops["tilt"].resolution == pytest.approx(step / seats.span) and stops["tilt"].resolution <= tol.paraboloid_tilt / 4
    assert stops["tilt"].range == pytest.approx(2 * LOC.SHIM_PACK_MM / seats.span)
    # the roll: the roll bars' -y ends' packs against their +y ends', over the strips' middles
    lever = dome.ROLL_BAR.length - dome.ROLL_BAR.pad
    assert stops["roll"].resolution == pytest.approx(step / lever) and stops["roll"].resolution <= tol.paraboloid_tilt / 4
    ind = dome.indicating(p, lay)
    assert ind.resolution == LOC.INDICATOR_MM + dome.register(p, lay).repeatability[0] <= tol.dome_offset / 4


@pytest.mark.parametrize("planted, element, axis, why", [
    ("pack", "paraboloid", "lateral", "short of the stack"),      # a 0.3 mm pack cannot take up 1.25 mm
    ("foil", "paraboloid", "lateral", "exceeds a quarter"),       # 0.05 mm foil: twice a quarter of 0.1 mm
    ("travel", "dome", "lateral", "short of the stack"),          # 0.2 mm of travel against 0.81 mm
])
def test_a_planted_worse_stop_is_refused(table31_rig, mk3s, monkeypatch, planted, element, axis, why):
    p, lay = table31_rig.profile, table31_rig.layout
    good = _axes(S.stack(p, lay, mk3s))[element, axis]
    assert good.status == "adjusted"
    if planted == "pack":
        monkeypatch.setattr(paraboloid, "SHIM_PACK_MM", 0.3)
    elif planted == "foil":
        monkeypatch.setattr(LOC, "SHIM_FOIL", (0.05, 0.1))
    else:
        monkeypatch.setattr(dome, "INDICATE_TRAVEL_MM", 0.2)
    bad = _axes(S.stack(p, lay, mk3s))[element, axis]
    assert bad.status == "refused" and why in bad.reason, bad.reason


def test_a_printer_with_more_seams_is_refused_naming_them(table31_rig, mk3s):
    # four seams across the base plate (a smaller bed) put the dome past its travel: the seams are named
    report = S.stack(table31_rig.profile, table31_rig.layout, mk3s, seams={"base_plate": 4})
    v = _axes(report)[("dome", "lateral")]
    assert v.status == "refused" and v.dominating[0] == "base plate seams"
    assert "a printer whose bed takes the base plate whole (rigcad fab --printer)" in v.buy


def _inside(part, *points) -> list[bool]:
    return [part.is_inside(bd.Vector(*pt)) for pt in points]


def test_the_stops_are_geometry_in_the_parts(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    m, seats = paraboloid.mount(p, lay), dome.beam_seats(p, lay)
    z0, z1 = lay.beam_z
    w, pk = p.beam.width / 2, LOC.SHIM_PACK_MM
    para, beam, shell = (table31_rig.part(n) for n in ("paraboloid", "beam", "dome"))
    mid = 0.5 * (z0 + z1)
    # the clamp: its -y wall a pack's thickness off the beam's -y face, its +y wall pierced for the insert
    assert _inside(para, (0.0, -w - pk - 0.05, mid), (0.0, -w - pk + 0.05, mid)) == [True, False]
    ins = INSERTS[paraboloid.SET_SCREW]
    out = m.clamp.hi[1]
    assert _inside(para, (0.0, out - 0.5, mid), (0.0, out - 0.5, mid + ins.hole / 2 * math.sqrt(2) + 0.3)) == [False, True]
    # the beam: the stop pin's hole where the pin stands, a pack's thickness past the clamp's -x end
    x_pin = m.clamp.lo[0] - pk - m.pin.radius
    assert m.pin.base[0] == pytest.approx(x_pin)
    assert _inside(beam, (x_pin, 0.0, z1 - 1.0), (x_pin, 0.0, z0 + 0.2)) == [False, True]
    # each seat: the floor a pack under the beam, the tunnel's -y wall at the beam's -y face, the roof's insert
    for block in seats.blocks:
        x = 0.5 * (block.lo[0] + block.hi[0])
        # the floor a roll bar and a pack under the beam, across the bar's length and its clearance
        bar, c = dome.ROLL_BAR, p.dome_shell.slot_clearance
        floor = z0 - bar.thickness - pk
        for y in (0.0, bar.length / 2 - bar.pad / 2, -bar.length / 2 + bar.pad / 2):
            assert _inside(shell, (x, y, floor - 0.05), (x, y, floor + 0.05)) == [True, False]
        edge = bar.length / 2 + c
        assert _inside(shell, (x, edge - 0.05, floor + 0.5), (x, edge + 0.05, floor + 0.5)) == [False, True]
        # the slot leaves a bar's end room to rise by a whole pack
        assert _inside(shell, (x, edge - 0.5, z0 + pk + c - 0.05), (x, edge - 0.5, z0 + pk + c + 0.05)) == [False, True]
        # the +y set screw's insert is reached from the block's +y face
        assert _inside(shell, (math.copysign(seats.x, x), block.hi[1] - 0.5, mid)) == [False]
        xo = x + math.copysign(3.0, x)  # outside the wall's slot
        assert _inside(shell, (xo, -w - 0.05, mid), (xo, -w + 0.05, mid)) == [True, False]
        assert _inside(shell, (math.copysign(seats.x, x), 0.0, block.hi[2] - 1.0)) == [False]
    # the seats stand within the flange's radius: the dome's footprint on a bed does not grow
    assert max(math.hypot(b.hi[0] if b.hi[0] > 0 else b.lo[0], max(-b.lo[1], b.hi[1])) for b in seats.blocks) \
        <= lay.flange_outer_r


def test_the_new_hardware_is_among_the_occluders_and_hides_little(table31_rig):
    from rigcad.optics.design import profile_table
    from rigcad.parts.occlusion import blocked_solid_angle

    occ = table31_rig.occluders
    names = {n for n, _ in occ["paraboloid"]}
    assert {"pin", "set screw", "clamp", "stem"} <= names
    table = profile_table(table31_rig.geometry, table31_rig.dome)
    full = blocked_solid_angle(occ, table)
    assert full["pin_solid_angle_sr"] >= 0 and full["set screw_solid_angle_sr"] >= 0
    # what the 3D check may lose (raycheck.max_lost_fraction) is far above what the mount hides
    assert full["blocked_fraction"] < table31_rig.profile.raycheck.max_lost_fraction


def test_the_parts_page_states_the_codes_figures(table31_rig, mk3s):
    from pathlib import Path

    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "parts.md").read_text(encoding="utf-8").split())
    p, lay = table31_rig.profile, table31_rig.layout
    st = {s.axis: s for s in (*paraboloid.stops(p, lay), *dome.beam_seats(p, lay).stops())}
    seats, m = dome.beam_seats(p, lay), paraboloid.mount(p, lay)
    assert (f"| x, along the beam | the clamp's -x end on a {2 * m.pin.radius:g} mm dowel pin (ISO 8734) pressed into "
            f"the beam's top | {st['x'].range:g} mm | {st['x'].resolution:g} mm |") in text
    assert f"| {st['y'].range:g} mm | {st['y'].resolution:g} mm |" in text
    assert f"| {st['vertical'].range:g} mm | {st['vertical'].resolution:g} mm |" in text
    assert (f"one seat's pack against the other's, {seats.span:.0f} mm apart | {math.degrees(st['tilt'].range):.2f} deg "
            f"| {math.degrees(st['tilt'].resolution):.3f} deg |") in text
    lever = dome.roll_lever()
    assert (f"the packs under the roll bars' -y ends against their +y ends, {lever:g} mm apart (`rigcad.parts.dome.ROLL_BAR`: "
            f"bright steel flat bar {dome.ROLL_BAR.width:g} x {dome.ROLL_BAR.thickness:g} mm, {dome.ROLL_BAR.length:g} mm "
            f"long) | {math.degrees(st['roll'].range):.1f} deg | {math.degrees(st['roll'].resolution):.3f} deg |") in text
    v = _axes(S.stack(p, lay, mk3s))
    faces = 2 * mk3s.process_errors.position / p.beam.width  # the beam's underside and the clamp's roof
    assert (f"its roll {math.degrees(v['paraboloid', 'roll'].worst):.2f} deg, of which {math.degrees(faces):.2f} deg are "
            f"the beam's {p.beam.width:g} mm width printed flat to {mk3s.process_errors.position:.1f} mm") in text
    assert f"the bars give it {lever:g} mm" in text
    assert (f"({v['paraboloid', 'lateral'].worst:.2f} mm sideways, {v['paraboloid', 'vertical'].worst:.2f} mm in height "
            f"and {math.degrees(v['paraboloid', 'tilt'].worst):.2f} deg on the MK3S)") in text
    assert (f"bolt holes ({dome.flange_bolt_hole(p, lay):.2f} mm for M4, on ISO 7093 large washers) leaving it "
            f"{dome.INDICATE_TRAVEL_MM:g} mm each way") in text
    assert f"({v['dome', 'lateral'].worst:.2f} mm worst case on the MK3S)" in text
    assert f"stainless shim foil (`rigcad.standards.SHIM_FOIL`: {min(SHIM_FOIL):g} to {max(SHIM_FOIL):g} mm)" in text


def test_the_mechanics_page_states_the_codes_figures(table31_rig, mk3s):
    from pathlib import Path

    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md").read_text(encoding="utf-8")
                    .split())
    p, lay = table31_rig.profile, table31_rig.layout
    v = _axes(S.stack(p, lay, mk3s))
    x = paraboloid.stops(p, lay)[0]
    assert f"shim foil that steps {x.resolution:g} mm, {x.range:g} mm each way" in text
    assert f"its lateral stack ({v['paraboloid', 'lateral'].worst:.2f} mm)" in text
    assert f"the height in {dome.beam_seats(p, lay).stops()[0].resolution:g} mm" in text
    assert (f"a dial test indicator, {LOC.INDICATOR_MM:g} mm, on an arm turning in the bore; its bolt holes leave it "
            f"{dome.INDICATE_TRAVEL_MM:g} mm each way") in text
    assert f"what the indicating takes up ({v['dome', 'lateral'].worst:.2f} mm with the plate's print error)" in text
    reg = dome.register(p, lay)
    assert f"the pins then hold it to {reg.repeatability[0] * 1e3:.0f} um" in text


def test_the_bill_orders_the_stops_hardware_and_the_register_step_is_the_shop_step(table31_rig):
    from rigcad.manual import bom as B
    from rigcad.manual.document import register_text

    p, lay = table31_rig.profile, table31_rig.layout
    m, seats = paraboloid.mount(p, lay), dome.beam_seats(p, lay)
    bill = B.fasteners(table31_rig)
    rows = {r["item"]: r for r in bill}
    # the clamp's set screw (1) and the seats' (2 each), the inserts that take them, the stop pin, the foil
    screws = [r for r in bill if "flat point (ISO 4026)" in r["item"]]
    assert sorted(r["quantity"] for r in screws) == [1, 4]
    assert {r["item"] for r in screws} == {f"M3 x {n} mm set screw, flat point (ISO 4026)"
                                           for n in (m.screw_length, seats.screw_length)}
    assert sum(r["quantity"] for r in bill if r["item"].startswith("heat-set insert (ruthex")) == 5
    assert any(i.startswith("dowel pin, ISO 8734") and f"{2 * m.pin.radius:g} x {m.pin_length} mm" in i for i in rows)
    assert any(i.startswith("shim foil") and f"{min(SHIM_FOIL):g}," in i for i in rows)
    # the seats' screw holes, the pin's hole and the register slot's ends are not taken for bolts' holes
    assert not [j for j in B.bolt_joints(table31_rig) if {"beam", "dome"} & set(j["parts"])
                and "to suit" in j["item"]]
    # the register is drilled in place: the step says how (indicate in, then drill), not 'press into printed holes'
    reg = dome.register(p, lay)
    text = register_text(reg)
    assert "dial test indicator" in text and f"{dome.INDICATE_TRAVEL_MM:g} mm of travel" in text
    assert "printed at the pin's size" not in text


def test_the_calibration_page_says_how_to_set_the_paraboloid(table31_rig):
    from rigcad.calibrate.kit import manual_page

    p, lay = table31_rig.profile, table31_rig.layout
    text = manual_page(table31_rig)
    assert paraboloid.setting_text(p, lay) in text
    # the figures it gives are the stops': a change at one seat moves the paraboloid half the foil
    step = min(SHIM_FOIL)
    assert f"({step / 2:g} mm per {step:g} mm foil)" in text
    span = dome.beam_seats(p, lay).span
    assert f"take {span * math.radians(0.01):.3f} mm of foil per 0.01 deg" in text
