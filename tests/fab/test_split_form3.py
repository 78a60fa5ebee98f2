"""The dome and the off-axis projector mounting plate on the Form 3 class resin printer (145 x
145 x 185 mm): the dome's band cut is joined by a tongue and groove (a 4 mm wall has no room for
vertical pins 1 mm behind the mirror); the plate is split by a grid in its own bounding box."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.export import mesh as M
from rigcad.fab import orientation as O
from rigcad.fab import split as SP
from rigcad.fab.mirror import MirrorSurface
from rigcad.fab.printers import load_printer
from rigcad.fab.stage import reassembly
from rigcad.parts import PARTS

from .conftest import ROOT

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def form3():
    return load_printer(ROOT / "profiles" / "printers" / "form3.yaml")


def _fits(piece, plan, printer, mirror) -> bool:
    v, _ = M.mesh_arrays(piece.manifold)
    cands = O.mirror_candidates(piece.sector_range) if mirror else O.generic_candidates()
    return any(O.fit_spin(v, o.direction, printer.usable)[0] is not None for o in cands)


def _partition(r):
    assert abs(r["pieces_volume_sum_mm3"] - r["drilled_volume_mm3"]) < 1e-6 * r["drilled_volume_mm3"]
    assert r["symmetric_difference_mm3"] < 1e-6 * r["drilled_volume_mm3"]


def test_form3_dome_sectors_and_bands_with_tongue_and_groove(table31, layout, form3):
    part = PARTS["dome"](table31, layout)
    name, design = part.mirrors[0]
    mirror = MirrorSurface(name, design.behind(layout.coating), design)
    man = M.build(part.solid, table31.tessellation.chord_error)
    z1 = man.bounding_box()[5]
    # what plan_split picks on the Form 3 (6 sectors, the band cut a quarter of the way up)
    plan = SP.SplitPlan(6, 2, math.radians(15.0), (0.0, 0.25 * z1, z1))
    tongues: list = []
    pieces, pins, drilled = SP.split_part(man, "dome", plan, form3.alignment_pin, mirror, tongues)
    assert len(pieces) == 12
    assert len(tongues) == 1 and all(abs(p.axis[2]) < 1e-9 for p in pins)  # band cut: tongue, not pins
    assert len(pins) >= 2 * 12  # two pins or more on each of the 12 sector faces
    for pc in pieces:
        assert _fits(pc, plan, form3, mirror), pc.name
    t = tongues[0]
    assert t.min_clearance_to_mirror >= SP.MIRROR_CLEARANCE
    # every upper piece carries a tongue, every lower piece a groove
    for i in range(6):
        assert SP.cell(t.tongue, plan, i, 0).volume() > SP.TONGUE_MIN_AREA * (t.depth - form3.alignment_pin.clearance)
    tol = table31.tessellation.chord_error + 2e-3
    r = reassembly(man, drilled, pieces, mirror, tol, pins, form3)
    _partition(r)
    # the drilled dome is the dome less the pin holes and the tongue's clearance in its groove
    hole = math.pi * form3.alignment_pin.hole_radius ** 2 * 2 * form3.alignment_pin.depth
    removed = r["part_volume_mm3"] - r["drilled_volume_mm3"]
    gap = t.groove.volume() - t.tongue.volume()
    assert abs(removed - len(pins) * hole - gap) < 0.02 * len(pins) * hole + 1e-6 * gap
    # the mirror is whole and untouched by the joints
    assert abs(r["mirror_area_pieces_mm2"] - r["mirror_area_part_mm2"]) < 1e-6 * r["mirror_area_part_mm2"]
    assert r["mirror_max_distance_pieces_mm"] < tol
    assert r["pin_hole_min_clearance_to_mirror_mm"] >= SP.MIRROR_CLEARANCE - 1e-9


def test_form3_long_plate_grid_split(table31, layout, form3):
    from rigcad.parts.recipe import Box

    # a plate off the axis, 297.4 x 144.4 x 7.5 mm (as the projector crosses' plate once was)
    man = M.build(Box((-22.2, -72.2, -6.0), (275.2, 72.2, 1.5)), table31.tessellation.chord_error)
    assert SP.is_off_axis(man)

    def fits(c, plan, i, j):
        v, _ = M.mesh_arrays(c)
        return c.is_empty() or any(O.fit_spin(v, o.direction, form3.usable)[0] is not None
                                   for o in O.generic_candidates())

    plan = SP.plan_grid(man, fits)
    assert isinstance(plan, SP.GridPlan) and plan.count == 2, plan  # ~297 mm long: two halves on edge
    pieces, pins, drilled = SP.split_part(man, "plate", plan, form3.alignment_pin, None)
    assert len(pieces) == plan.count
    for pc in pieces:
        assert _fits(pc, plan, form3, None), pc.name
    assert len(pins) >= 2 and all(abs(abs(p.axis[0]) - 1) < 1e-9 for p in pins)
    r = reassembly(man, drilled, pieces, None, 0.0, pins, form3)
    _partition(r)
    hole = math.pi * form3.alignment_pin.hole_radius ** 2 * 2 * form3.alignment_pin.depth
    removed = r["part_volume_mm3"] - r["drilled_volume_mm3"]
    assert abs(removed - len(pins) * hole) < 0.02 * len(pins) * hole
    # the pins stay inside the plate with the wall
    for p in pins:
        assert SP._inside(man, np.array(p.centre), np.array(p.axis), form3.alignment_pin.hole_radius + SP.MIN_WALL,
                          form3.alignment_pin.depth)
