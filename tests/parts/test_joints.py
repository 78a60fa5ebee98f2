"""Declared joints (rigcad.parts.joints): the dome's flange screws are a ScrewJoint the dome declares;
the base plate's insert pockets, the assembly step's screws and the bill's line are all read from it,
so moving the declaration moves the three together; the pockets are the insert maker's hole."""

from __future__ import annotations

import dataclasses
import math

import importlib

import build123d as bd
import pytest

from rigcad.errors import GeometryError
from rigcad.manual import plan
from rigcad.manual.assembly import picture_meshes
from rigcad.parts.joints import ScrewJoint
from rigcad.rig import Rig
from rigcad.standards import INSERTS

# the modules (rigcad.parts re-exports each part's function under the module's own name)
dome = importlib.import_module("rigcad.parts.dome")
base = importlib.import_module("rigcad.parts.base")


def _pockets(rig, tmp_path, radius: float) -> list[tuple[float, float]]:
    """The axes (x, y) of the cylindrical faces of ``radius`` mm on the flange's bolt circle in the base
    plate as its STEP file reads back through OpenCascade (build123d's reader), not as the recipe
    states them (the column's 4 mm dowel holes, off the circle, and the dome's register pins are left out)."""
    from rigcad.parts.locating import DowelRegister

    pins = {(round(x, 3), round(y, 3)) for j in rig.recipes["dome"].joints if isinstance(j, DowelRegister)
            for x, y in j.points}
    path = tmp_path / "base_plate.step"
    bd.export_step(rig.part("base_plate"), str(path))
    faces = [f for f in bd.import_step(str(path)).faces() if f.geom_type == bd.GeomType.CYLINDER]
    axes = {(round(f.axis_of_rotation.position.X, 3), round(f.axis_of_rotation.position.Y, 3))
            for f in faces if abs(f.radius - radius) < 1e-6  # a hole's wall may come as two half faces
            and abs(math.hypot(f.axis_of_rotation.position.X, f.axis_of_rotation.position.Y)
                    - rig.layout.bolt_circle_r) < 1e-3}
    return sorted(axes - pins)


def _hardware(rig) -> dict[str, tuple[int, str]]:
    steps = plan.steps(rig, picture_meshes(rig))[0]
    return {r["item"]: (r["quantity"], r["steps"]) for r in plan.hardware(steps, rig)}


def test_the_flange_joint_is_declared_and_the_plate_is_cut_at_the_insert_makers_hole(table31_rig, tmp_path):
    (joint,) = [j for j in table31_rig.recipes["dome"].joints if isinstance(j, ScrewJoint)]
    assert (joint.upper, joint.lower, joint.thread, joint.into, joint.count) == ("dome", "base_plate", "M4", "insert", 8)
    # ruthex's M4 insert: a 5.6 mm hole, never the insert's 6.3 mm outside
    got = _pockets(table31_rig, tmp_path, INSERTS["M4"].hole / 2)
    assert got == sorted((round(x, 3), round(y, 3)) for x, y in joint.points)
    # 0.8 washer + 6 flange + 8.1 insert = 14.9 mm of reach: the longest M4 ISO 4762 sells within it is 12
    assert joint.length == 12
    quantity, steps = _hardware(table31_rig)[joint.item]
    assert quantity == 8 and steps == "dome"


def test_moving_the_declaration_moves_the_hole_the_bill_line_and_the_step_together(table31, tmp_path, monkeypatch):
    real = dome.flange_joint

    def moved(profile, layout):  # six M3 screws, turned 10 deg from the eight M4s
        j = real(profile, layout)
        r = layout.bolt_circle_r
        pts = tuple((r * math.cos(a), r * math.sin(a)) for a in (math.radians(10 + 60 * k) for k in range(6)))
        return dataclasses.replace(j, thread="M3", points=pts)

    monkeypatch.setattr(dome, "flange_joint", moved)
    monkeypatch.setattr(base, "flange_joint", moved)
    rig = Rig.from_profile(table31)
    (joint,) = [j for j in rig.recipes["dome"].joints if isinstance(j, ScrewJoint)]
    assert _pockets(rig, tmp_path, INSERTS["M3"].hole / 2) == sorted((round(x, 3), round(y, 3)) for x, y in joint.points)
    assert _pockets(rig, tmp_path, INSERTS["M4"].hole / 2) == []  # the M4 pockets went with the declaration
    hardware = _hardware(rig)
    assert hardware[joint.item] == (6, "dome") and joint.item.startswith("M3 x ")
    assert not any(item.startswith("M4") and "melted into base_plate" in item for item in hardware)
    step = next(s for s in plan.steps(rig, picture_meshes(rig))[0] if s.name == "dome")
    heads = sorted((round(f.head[0], 3), round(f.head[1], 3)) for f in step.fasteners)
    assert heads == sorted((round(x, 3), round(y, 3)) for x, y in joint.points)


def test_a_joint_refuses_what_cannot_be_built():
    kw = dict(points=((0.0, 0.0),), upper_z=(0.0, 6.0), lower_z=(-10.0, 0.0))
    with pytest.raises(GeometryError, match="pocket .* is deeper than base_plate"):
        ScrewJoint("j", "dome", "base_plate", "M6", **{**kw, "lower_z": (-10.0, 0.0)})  # M6 insert: 13.2 mm
    with pytest.raises(GeometryError, match="no heat-set insert for M2"):
        ScrewJoint("j", "dome", "base_plate", "M2", **kw)
    with pytest.raises(GeometryError, match="unknown thread 'M7'"):
        ScrewJoint("j", "dome", "base_plate", "M7", **kw)
    through = ScrewJoint("j", "dome", "base_plate", "M4", **kw, into="nut")
    # 16 mm grip + 2 washers 0.8 + nut 3.2 + 2 pitches 0.7 = 22.2 mm: the shortest M4 of that or more is 25
    assert through.length == 25 and "nut (ISO 4032)" in through.item
