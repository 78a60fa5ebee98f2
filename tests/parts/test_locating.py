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
from rigcad.parts.locating import DowelRegister
from rigcad.rig import Rig
from rigcad.standards import THREADS

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
    assert reg.lower_depth + reg.upper_engagement == pytest.approx(reg.length + 0.5)
    # the flange: a round hole at +y, and the slot's two ends at -y +- half its extra length
    flange = [h for h in _holes(table31_rig, "dome", tmp_path, reg.diameter / 2)
              if abs(h[0]) < 1e-3 and abs(abs(h[1]) - r) < reg.slot]
    ends = sorted(round(y, 3) for _, y, _ in flange if y < 0)
    assert [y for _, y, _ in flange if y > 0] == [round(r, 3)]
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
    plate = [(x, y) for x, y, _ in _holes(rig, "base_plate", tmp_path, reg.diameter / 2) if abs(x) < 1e-3]
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
