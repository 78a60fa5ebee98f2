"""Washers over slots and opened holes (rigcad.parts.washers): the bearing area against an independent
count of a fine grid, the choice against the plain washer's area on its clearance hole, and the loads
table bearing on the area the washers really have."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.fab import loads as L
from rigcad.fab.printers import load_printer
from rigcad.parts import tower as T
from rigcad.parts.washers import bearing_area, large, plain, washers_over


def _grid_area(outer: float, bore: float, opening: tuple, n: int = 3001) -> float:
    """The washer's bearing area counted on an n x n grid (mm2): inside its ring, outside the opening."""
    r = outer / 2
    xs = np.linspace(-r, r, n)
    x, y = np.meshgrid(xs, xs)
    ring = (x * x + y * y <= r * r) & (x * x + y * y >= bore * bore / 4)
    if opening[0] == "round":
        free = x * x + y * y >= opening[1] ** 2 / 4
    else:
        free = (np.abs(x) > opening[1] / 2) | (np.abs(y) > opening[2] / 2)
    return float((ring & free).sum() * (xs[1] - xs[0]) ** 2)


@pytest.mark.parametrize("washer,opening", [
    (large("M5"), ("slot", 8.5, 16.5)), (large("M10"), ("slot", 19.1, 31.1)), (large("M4"), ("slot", 8.5, 4.5)),
    (large("M4"), ("round", 5.97)), (plain("M4"), ("slot", 8.5, 16.5)), (large("M8"), ("slot", 30.0, 6.0))])
def test_the_bearing_area_is_the_ring_less_the_opening(washer, opening):
    assert bearing_area(washer, opening) == pytest.approx(_grid_area(washer.outer, washer.bore, opening), rel=2e-3,
                                                         abs=0.05)


def test_a_plain_washer_over_the_projectors_slot_bears_too_little(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    slot = T.slot_openings(p, lay)["projector"]
    target = bearing_area(plain("M4"), ("round", 4.5))  # what the loads table used to assume: 48 mm2
    assert target == pytest.approx(math.pi / 4 * (81 - 4.5 ** 2))
    assert bearing_area(plain("M4"), slot) < 0.5 * target  # the review's 2-23 mm2
    chosen = T.joint_washers(p, lay)["projector"]
    assert chosen.area_mm2 >= target and chosen.bearing.standard == "ISO 7093-1"
    # each washer in the stack covers the bore of the one under it by at least a millimetre a side
    for upper, lower in zip(chosen.washers, chosen.washers[1:]):
        assert upper.outer >= lower.bore + 2.0
    # the column's opened holes: a large washer of its own size
    col = T.joint_washers(p, lay)["column"]
    assert col.washers == (large("M4"),) and col.area_mm2 == pytest.approx(math.pi / 4 * (144 - T.column_bolt_hole(
        lay.tower, p) ** 2))


def test_the_loads_bear_on_the_washers_real_areas(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    rows = {b.joint: b for b in L.bolt_loads(p, lay, load_printer("prusa_mk3s"))}
    w = T.joint_washers(p, lay)
    assert rows["projector on the shelf's slots"].area_mm2 == pytest.approx(w["projector"].area_mm2)
    assert rows["camera on its bracket's slot"].area_mm2 == pytest.approx(w["camera"].area_mm2)
    assert rows["column top under the shelf"].area_mm2 == pytest.approx(w["column"].area_mm2)
    assert "over the slot" in rows["projector on the shelf's slots"].bearing


def test_the_shelf_tilt_eats_the_projectors_tilt_twice(table31_rig):
    d = {x.part: x for x in L.deflections(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))}
    shelf, tol = d["shelf"], table31_rig.profile.tolerancing
    assert shelf.share == pytest.approx(max(shelf.sag_mm / tol.projector_height,
                                            2 * shelf.tilt_rad / tol.projector_tilt))
    assert shelf.share == pytest.approx(2 * shelf.tilt_rad / tol.projector_tilt)  # the tilt sets it on the default
    col = d["column"]
    assert col.share == pytest.approx(max(col.sag_mm / tol.projector_height, col.tilt_rad / tol.projector_tilt))
