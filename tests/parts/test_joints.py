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
    # 1.0 large washer (ISO 7093-1 M4) + 1.3 spring washer at its free height (DIN 6796 M4) + the 5.98 mm
    # compression limiter through the 6 mm flange + 8.1 insert = 16.38 mm of reach: the longest M4 ISO 4762
    # sells within it is 16, 7.72 mm in the insert (the machinist measured M4 x 12: 3.7 mm, under one diameter)
    assert joint.datum and joint.limiter
    assert joint.length == 16 and joint.engagement == pytest.approx(7.72, abs=1e-9)
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


def test_every_screw_joint_engages_its_insert_by_a_diameter_and_ends_inside_it(table31_rig):
    """Every joint the parts declare: the grip counts everything under the head (its washer stack and,
    where the torque table asks for one, the conical spring washer at its free height); the screw
    engages an insert by at least one diameter (the common rule for a thread in a softer host) and
    ends inside it, or shows two pitches past its nut. Summed here from the standards' tables."""
    from rigcad.standards import CONICAL_SPRING_WASHERS, THREADS

    joints = [j for p in table31_rig.recipes.values() for j in p.joints if isinstance(j, ScrewJoint)]
    assert joints
    for j in joints:
        th = THREADS[j.thread]
        under = (j.washer_mm if j.washer_mm is not None else th.washer_thickness) + (
            CONICAL_SPRING_WASHERS[j.thread][3] if j.spring_washer else 0.0)
        grip = under + j.upper_z[1] - j.upper_z[0]
        if j.into == "insert":
            engaged = j.length - grip
            assert th.major <= engaged <= INSERTS[j.thread].length, (j.name, j.length, engaged)
        else:
            past = j.length - grip - (j.lower_z[1] - j.lower_z[0]) - th.washer_thickness - th.nut_height
            assert past >= 2 * th.pitch, (j.name, j.length, past)
    (flange,) = [j for j in joints if j.name == "dome_flange"]
    # the dome's flange: the large washer seated on its compression limiter over the opened hole
    # (rigcad.parts.washers.on_limiter) and the spring washer the torque table marks
    assert flange.spring_washer and flange.washer_mm == dome.flange_washers(table31_rig.profile,
                                                                            table31_rig.layout).thickness


def test_a_joint_too_short_for_one_diameter_in_its_insert_is_refused():
    # 6 mm flange + 0.8 washer + 1.3 spring: 8.1 mm grip; an M4 insert 8.1 mm long gives 16.2 mm of reach,
    # the longest M4 is 16: 7.9 mm engaged. 15.5 mm under the head: 21.5 mm grip, 29.6 mm of reach, the
    # longest M4 within it is 25 (ISO 4762 has no 28): 3.5 mm engaged, under 4: refused
    kw = dict(points=((0.0, 0.0),), upper_z=(0.0, 6.0), lower_z=(-10.0, 0.0), spring_washer=True)
    ok = ScrewJoint("j", "dome", "base_plate", "M4", **kw)
    assert ok.length == 16 and ok.engagement == pytest.approx(7.9, abs=1e-9)
    with pytest.raises(GeometryError, match="engages it 3.5 mm, under one diameter"):
        ScrewJoint("j", "dome", "base_plate", "M4", washer_mm=15.5 - 1.3, **kw).length
