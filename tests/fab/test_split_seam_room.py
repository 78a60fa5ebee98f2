"""A split plan whose seams cannot take their pins is never chosen: when a grid's cuts fit the printer
but leave a cut face with no room for two pins (a narrow neck, a sliver between a cut and the part's
edge), the planner moves a cut within the room its keep-outs leave, or takes the next grid, before it
hands a plan on (rigcad.fab.split.plan_grid's ``joins``, rigcad.fab.split.seam_joints)."""

from __future__ import annotations

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.errors import FabricationError
from rigcad.fab import split as SP
from rigcad.fab.printers import AlignmentPin

PIN = AlignmentPin(2.0, 0.2, 5.0)  # a hole of 2.2 mm, 5 mm into each piece


def _necked_bar() -> m3d.Manifold:
    """Two 100 x 40 x 10 mm blocks joined by a 12 mm long neck 2 mm wide (too narrow even for
    the thinnest dowel rigcad.fab.split.pin_choices offers, 1 mm in a 1.2 mm hole with 0.6 mm walls): 212 mm long, its middle
    (x = 0, where two equal slabs are cut) in the neck."""
    left = m3d.Manifold.cube((100.0, 40.0, 10.0)).translate((-106.0, -20.0, 0.0))
    right = m3d.Manifold.cube((100.0, 40.0, 10.0)).translate((6.0, -20.0, 0.0))
    neck = m3d.Manifold.cube((12.0, 2.0, 10.0)).translate((-6.0, -1.0, 0.0))
    return left + neck + right


def _short(cell, *_):
    """Fits a 120 mm bed: the cell's extent along x."""
    bb = np.asarray(cell.bounding_box(), float)
    return bb[3] - bb[0] <= 120.0


def _joins(man):
    """The seam test with the one pin (seam_joints also tries thinner dowels: slower, the same answer here)."""
    return lambda plan: SP.place_pins(man, plan, PIN, None, wall=SP.MIN_WALL)


def test_a_cut_through_a_neck_too_narrow_for_pins_moves_to_where_they_fit():
    bar = _necked_bar()
    # without the seam test the planner cuts the neck (two equal slabs), whose face takes no pin
    bare = SP.plan_grid(bar, _short)
    assert bare.x_cuts == (0.0,) and bare.count == 2
    with pytest.raises(FabricationError, match="x cut 0.0 mm"):
        SP.seam_joints(bar, bare, PIN, None, SP.MIN_WALL)
    # with it: still two pieces, the cut moved off the neck into a block (|x| > 6 mm), and its pins placed
    plan = SP.plan_grid(bar, _short, joins=_joins(bar))
    assert plan.count == 2 and len(plan.x_cuts) == 1 and abs(plan.x_cuts[0]) > 6.0, plan.describe()
    # the smallest move whose pins (5 mm deep + 0.6 mm wall each way) stay out of the neck (x in -6..6):
    # 12.5 mm (five 2.5 mm steps; at 7.5 and 10 mm the holes reach into it), the lower side first on a tie
    assert plan.x_cuts == (-12.5,), plan.describe()
    pins, pin, _ = SP.seam_joints(bar, plan, PIN, None, SP.MIN_WALL)
    assert len(pins) >= 2 and pin == PIN
    # determinism: the same plan every run
    assert SP.plan_grid(bar, _short, joins=_joins(bar)) == plan


def test_a_moved_cut_keeps_off_the_keep_outs():
    bar = _necked_bar()
    # a keep-out over x in (-20, -3): the moves to the lower side land on its edges; the upper side is clear
    plan = SP.plan_grid(bar, _short, keep_out=[(np.array([-20.0, -30.0, -1.0]), np.array([-3.0, 30.0, 11.0]))],
                        joins=_joins(bar))
    assert plan.count == 2 and not (-20.0 < plan.x_cuts[0] < -3.0) and abs(plan.x_cuts[0]) > 6.0, plan.describe()
    assert plan.x_cuts == (12.5,), plan.describe()  # 7.5 and 10 mm leave a hole's wall at the neck's end


def test_a_part_whose_every_plan_leaves_a_face_without_pins_is_refused_naming_the_face():
    bar = _necked_bar()

    def never(plan):
        raise FabricationError(f"x cut {plan.x_cuts[0]:.1f} mm, y slab 1, z slab 1: planted refusal")

    def two_only(cell, plan, *_):  # only the two-piece grids fit: the refusal comes after their tries
        return plan.count == 2 and _short(cell)

    with pytest.raises(FabricationError) as e:
        SP.plan_grid(bar, two_only, joins=never)
    msg = str(e.value)
    assert "takes its pins on every seam" in msg and "x cut 0.0 mm, y slab 1, z slab 1: planted refusal" in msg
    assert "\n" not in msg
