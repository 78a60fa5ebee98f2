"""The dome's register (rigcad.parts.locating.DowelRegister, declared by rigcad.parts.dome.register):
two dowel pins pressed into the base plate, a round hole and a slot in the dome's flange. The holes
are read back from the STEP files (OpenCascade through build123d), the bill's line and the step's
words from the manual's plan, and the flange's bolt holes against the print's errors computed here."""

from __future__ import annotations

import importlib
import math
import textwrap

import build123d as bd
import pytest

import rigcad
from rigcad.errors import GeometryError
from rigcad.manual import plan
from rigcad.manual.assembly import picture_meshes
from rigcad.parts import locating
from rigcad.parts.locating import DowelRegister
from rigcad.rig import Rig
from rigcad.standards import REAMER_LEAD_MM, THREADS

dome = importlib.import_module("rigcad.parts.dome")
base = importlib.import_module("rigcad.parts.base")


def _register(rig) -> DowelRegister:
    (reg,) = [j for j in rig.recipes["dome"].joints if isinstance(j, DowelRegister)]
    return reg


def _holes(rig, part: str, tmp_path, radius: float) -> list[tuple[float, float, float]]:
    """(x, y, height) of the cylindrical faces of ``radius`` mm in ``part``'s STEP file as it reads back."""
    path = tmp_path / f"{part}.step"
    bd.export_step(rig.part(part), str(path))
    out = set()
    for f in bd.import_step(str(path)).faces():
        if f.geom_type == bd.GeomType.CYLINDER and abs(f.radius - radius) < 1e-6:
            bb = f.bounding_box()
            p = f.axis_of_rotation.position
            out.add((round(p.X, 3), round(p.Y, 3), round(bb.size.Z, 3)))
    return sorted(out)


def test_the_pins_holes_are_cut_from_the_declaration(table31_rig, tmp_path):
    reg = _register(table31_rig)
    r = table31_rig.layout.bolt_circle_r
    assert (reg.upper, reg.lower, reg.points, reg.drilled) == ("dome", "base_plate", ((0.0, r), (0.0, -r)), True)
    # the plate: drilled in place through the flange once the dome is indicated in, so no hole is printed
    # there; a split still keeps off where they go (the plate's register datums)
    plate = [h for h in _holes(table31_rig, "base_plate", tmp_path, reg.diameter / 2) if abs(abs(h[1]) - r) < 1e-3]
    assert plate == []
    datums = [d for d in table31_rig.recipes["base_plate"].datums if d.kind == "register"]
    assert sorted(round(d.centre[1], 3) for d in datums) == [round(-r, 3), round(r, 3)]
    # the blind hole runs the machine reamer's lead past the pin's end (its floor's under-size zone)
    assert reg.lower_depth + reg.upper_engagement == pytest.approx(reg.length + REAMER_LEAD_MM)
    # the flange: a round hole at +y printed at the drill's size before the reamers (3.8 mm for 4 mm pins:
    # a 0.2 mm reaming allowance), and the slot's two ends at -y +- half its extra length, at the pin's width
    assert reg.drill == pytest.approx(reg.diameter - 0.2) if reg.diameter <= 5 else reg.drill < reg.diameter
    hole = [h for h in _holes(table31_rig, "dome", tmp_path, reg.drill / 2) if abs(h[0]) < 1e-3 and abs(h[1] - r) < 1e-3]
    flange = [h for h in _holes(table31_rig, "dome", tmp_path, reg.diameter / 2)
              if abs(h[0]) < 1e-3 and abs(abs(h[1]) - r) < reg.slot]
    ends = sorted(round(y, 3) for _, y, _ in flange if y < 0)
    assert [y for _, y, _ in hole] == [round(r, 3)] and not [y for _, y, _ in flange if y > 0]
    assert ends == pytest.approx([-r - reg.slot / 2, -r + reg.slot / 2], abs=1e-3)


def test_moving_the_declaration_moves_both_parts_holes_the_bill_and_the_step(table31, tmp_path, monkeypatch):
    real = dome.register

    def moved(profile, layout):  # the pins on the y axis, 10 mm in from the bolt circle
        reg = real(profile, layout)
        r = layout.bolt_circle_r - 10.0
        return DowelRegister(reg.name, reg.upper, reg.lower, reg.diameter, ((0.0, r), (0.0, -r)), reg.upper_z,
                             reg.lower_z, reg.slot, reg.param)

    monkeypatch.setattr(dome, "register", moved)
    monkeypatch.setattr(base, "register", moved)
    rig = Rig.from_profile(table31)
    reg = _register(rig)
    plate = [(x, y) for x, y, _ in _holes(rig, "base_plate", tmp_path, reg.drill / 2) if abs(x) < 1e-3]
    assert plate == [(0.0, round(-reg.points[0][1], 3)), (0.0, round(reg.points[0][1], 3))]
    steps = plan.steps(rig, picture_meshes(rig))[0]
    rows = plan.bill_hardware(rig, steps, {"fasteners": [], "pins": None})
    (row,) = [r for r in rows if r["item"] == reg.item]
    assert row["quantity"] == 2 and row["steps"] == ["dome"]


def test_the_dome_returns_within_its_tolerance_and_its_bolts_only_clamp(table31_rig):
    p, reg = table31_rig.profile, _register(table31_rig)
    lateral, turn = reg.repeatability
    assert lateral <= p.tolerancing.dome_offset / 10
    assert turn * reg.spacing / 2 <= p.tolerancing.dome_offset / 10  # the turn's shift at the flange's edge
    # every flange bolt clears its hole with the print's errors between the two parts: both parts'
    # position errors and the scale error over its distance from the round pin (the slot takes the rest)
    (joint,) = [j for j in table31_rig.recipes["dome"].joints if j.__class__.__name__ == "ScrewJoint"]
    hole = dome.flange_bolt_hole(p, table31_rig.layout)
    px, py = reg.points[0]
    for x, y in joint.points:
        need = THREADS[joint.thread].major / 2 + 2 * p.datum.print_position + p.datum.print_scale * math.hypot(x - px, y - py)
        assert hole / 2 >= need, (x, y, hole, need)
    # the slot takes the scale error over the pins' spacing (and both parts' position errors)
    assert reg.slot / 2 >= p.datum.print_scale * reg.spacing + 2 * p.datum.print_position - 1e-12


def test_pins_among_crowded_bolts_are_refused_naming_the_key(tmp_path):
    path = tmp_path / "crowded.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent("""\
        dome_shell:
          bolts: 64
        """), encoding="utf-8")
    rig = rigcad.load(path)
    with pytest.raises(GeometryError, match="dome_shell.bolts"):
        rig.recipe("dome")


def test_each_pin_end_has_its_iso_286_fit_its_reamer_and_a_blind_hole(table31_rig):
    """The press end interferes over the whole zones (N7 over m6), the slip end slides but for the zones'
    worst pair (F7 over m6: at most 2 um tight, which the printed wall takes); the repeatability is half
    the slip end's loosest; the lower part's holes are blind (their floor stops the pin), printed at the
    drill's size; the step names the drill and both reamers, the bill's line both fits."""
    reg = _register(table31_rig)
    press, slip = reg.press.clearance, reg.slip.clearance
    # ISO 286-2 at 4 mm (3-6 mm): N7 -0.016..-0.004, F7 +0.010..+0.022, m6 +0.004..+0.012
    assert press == pytest.approx((-0.028, -0.008), abs=1e-12) and press[1] < 0
    assert slip == pytest.approx((-0.002, 0.018), abs=1e-12) and slip[1] > 0 and slip[0] >= -0.002
    assert reg.repeatability[0] == pytest.approx(slip[1] / 2)
    assert "N7" in reg.item and "F7" in reg.item
    text = dome.indicating_text(table31_rig.profile, table31_rig.layout, reg)
    for words in (f"{reg.drill:g} mm twist drill", f"{reg.diameter:g} N7", f"{reg.diameter:g} F7", "blind",
                  f"{reg.lower_depth:.1f} mm deep"):
        assert words in text, words
    # a register whose holes are printed (not drilled in place): blind holes from the lower part's top face,
    # at the drill's size, their floors above the lower part's underside
    printed = DowelRegister("r", "a", "b", 4.0, ((0.0, 0.0), (30.0, 0.0)), (0.0, 8.0), (-10.0, 0.0), 0.3)
    for c in printed.lower_holes():
        assert c.radius == pytest.approx(printed.drill / 2)
        assert c.base[2] > -10.0 and c.base[2] == pytest.approx(-printed.lower_depth)
    assert "N7" in printed.shop_text() and "F7" in printed.shop_text() and "blind" in printed.shop_text()


def test_the_parts_page_states_the_fits_the_code_computes(table31_rig):
    """docs/parts.md's fits paragraph, figure by figure, from the code (the holder's fit, the register's,
    the drawn sizes, the stop pin's)."""
    from pathlib import Path

    from rigcad.fab.stack import sample_link
    from rigcad.parts.locating import holder_fit, press_fit
    from rigcad.standards import pre_ream_drill

    paraboloid = importlib.import_module("rigcad.parts.paraboloid")
    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "parts.md").read_text(encoding="utf-8").split())
    p, lay = table31_rig.profile, table31_rig.layout
    fit, reg = holder_fit(2 * p.sample_holder.radius), _register(table31_rig)
    pin = 2 * paraboloid.mount(p, lay).pin.radius
    for words in (f"drawn at {base.bore_drawn(p):g} mm, it prints under by the printer's hole shrink and is bored to "
                  f"{fit.size:g} {fit.hole}", f"turned from aluminium bar (a bought part, never printed) to {fit.size:g} "
                  f"{fit.shaft}: {fit.describe()}", f"within {sample_link(p).lateral:.3f} mm of the bore's axis",
                  f"plugs are printed, at {base.holder_drawn(p, False):g} mm",
                  f"reamed N7, {reg.press.describe()}", f"reamed F7, {reg.slip.describe()}",
                  f"takes the dome's return as {reg.repeatability[0]:.3f} mm each way",
                  f"set back {locating.REPEAT_TRIALS} times", f"plus that {REAMER_LEAD_MM:g}<!--given--> mm lead",
                  "`tests/parts/test_reaming.py`; {:.3f} / {:.3f} mm for {:g} N7".format(*reg.press_gauges, reg.diameter),
                  f"at the {reg.drill:g} mm drill's size",
                  f"a {reg.diameter - reg.drill:.1f} mm reaming allowance", f"the beam's {pin:g} mm stop pin",
                  f"{press_fit(pin).describe()}, in a {pre_ream_drill(pin):g} mm hole"):
        assert words in text, words


def test_the_columns_dowels_stand_in_blind_holes_reamed_for_their_press_fit(table31_rig):
    """The column's registers (rigcad.parts.tower.column_register) cut their pins' holes in the tongue (from
    its top) and in the shelf (up from its underside: the shelf hangs over the column's flange) blind, at
    the drill's size, their floors at least a millimetre inside the part: a through hole lets a pin walk."""
    tower = importlib.import_module("rigcad.parts.tower")
    p, lay = table31_rig.profile, table31_rig.layout
    t, wall = lay.tower, p.tower.wall
    foot = tower.column_register(t, p, t.column_base_z, wall, "foot")
    top = tower.column_register(t, p, t.shelf_top_z - t.shelf_thickness - wall, wall, "top")
    assert not foot.hangs and top.hangs
    points = {tuple(round(v, 6) for v in q) for q in tower.column_dowel_points(t, p)}
    tongue = [c for c in tower.column_joint_cuts(t, p, t.bench_z, -t.bench_z, "top")
              if (round(c.base[0], 6), round(c.base[1], 6)) in points]
    shelf = [c for c in tower.shelf_joint_cuts(t, p, t.shelf_top_z - t.shelf_thickness)
             if hasattr(c, "radius") and (round(c.base[0], 6), round(c.base[1], 6)) in points]
    assert len(tongue) == len(shelf) == 2
    for c in tongue:  # open at the tongue's top face (z = 0), its floor above the bench
        assert c.radius == pytest.approx(foot.drill / 2) and c.base[2] + c.height > 0.0
        assert c.base[2] >= t.bench_z + 1.0, c.base
    for c in shelf:  # open at the shelf's underside, its floor under the shelf's top
        assert c.radius == pytest.approx(top.drill / 2) and c.base[2] < t.shelf_top_z - t.shelf_thickness
        assert c.base[2] + c.height <= t.shelf_top_z - 1.0, (c.base, c.height)
    row = next(h for h in tower.hardware(p, lay) if "dowel" in h["item"] and "shop_steps" in h)
    assert f"{foot.diameter:g} N7" in row["joins"] and f"{foot.diameter:g} F7" in row["joins"] and "H7" not in row["joins"]


def test_the_beams_stop_pin_is_set_in_a_blind_hole_reamed_f7(table31_rig):
    """The paraboloid's x stop: its ISO 8734 pin's hole in the beam prints at the drill's size before the
    reamer (2.8 mm for 3 mm), blind (its floor inside the beam by PIN_FLOOR_MM), and the row says drill,
    reamer, fit (a slip fit set in retaining compound: pressed, it overloaded the beam's 1.5 mm walls)."""
    from rigcad.parts.locating import slip_fit as press_fit
    from rigcad.standards import pre_ream_drill

    paraboloid = importlib.import_module("rigcad.parts.paraboloid")
    p, lay = table31_rig.profile, table31_rig.layout
    m = paraboloid.mount(p, lay)
    d = 2 * m.pin.radius
    radii = {round(abs(seg.p0[0]), 9) for seg in m.pin_hole.solid.section.segments} - {0.0}
    assert radii == {round(pre_ream_drill(d) / 2, 9)}, radii
    z0, _ = lay.beam_z
    # the floor above the beam's underside
    assert m.pin_hole.offset[2] >= z0 + paraboloid.PIN_FLOOR_MM - 1e-9, (m.pin_hole.offset, z0)
    (row,) = [h for h in paraboloid.hardware(p, lay) if "dowel pin" in h["item"]]
    assert f"{d:g} F7" in row["item"] and press_fit(d).describe() in row["joins"] and "retaining compound" in row["joins"]
    assert f"drill it {pre_ream_drill(d):g} mm" in row["joins"] and f"{d:g} mm F7 hand reamer" in row["joins"]
