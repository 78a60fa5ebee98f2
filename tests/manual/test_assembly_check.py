"""The assembly feasibility check on small hand-made assemblies whose answer is known by
construction: a plate, a block bolted to it, a cover over the block; a planted wrong order and a
blocked bolt are refused, the tool paths are checked, and the order search finds the one order
that works."""

from __future__ import annotations

import manifold3d as m3
import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.manual import assembly_check as AC
from rigcad.manual import fasteners, plan
from rigcad.standards import DRIVER_BLADE_MM

DOWN = (0.0, 0.0, -1.0)


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return m3.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))


def bolt(head_z: float, x: float = 0.0, tools=None) -> AC.Fastener:
    """An M4 x 12 screw straight down at (x, 0) into a heat-set insert in the plate."""
    tools = tools or fasteners.driver("M4")
    return AC.Fastener("M4 x 12 mm screw", (x, 0.0, head_z), DOWN, 12.0, 2.0, 3.0, 4.0, tools,
                       thread_in="insert", passes=("plate", "block"))


SLIDE = (-1.0, 0.0, 0.0)  # the block slides in from +x, between the cover's legs


def world(cover_gap: float = 15.0, tools=None):
    """plate (z -10..0, a 4.5 mm hole at the origin), a block on it (z 0..10, the same hole) that
    slides in along -x, screwed down by one M4 screw (head's bearing face on the block's top, z = 10),
    and a cover: a roof ``cover_gap`` mm above the block on two legs along x (at |y| = 40..45)."""
    hole = m3.Manifold.cylinder(40, 2.25, 2.25, 32).translate((0, 0, -20))
    top = 10 + cover_gap
    solids = {
        "plate": box((-50, -50, -10), (50, 50, 0)) - hole,
        "block": box((-20, -20, 0), (20, 20, 10)) - hole,
        "cover": box((-45, -45, top), (45, 45, top + 5)) + box((-45, -45, 0), (45, -40, top))
                 + box((-45, 40, 0), (45, 45, top)),
    }
    steps = [
        AC.Step("cover", ("cover",), (DOWN,), 100.0, needs=("plate",)),
        AC.Step("block", ("block",), (SLIDE,), 100.0, needs=("plate",), fasteners=(bolt(10.0, tools=tools),)),
        AC.Step("plate", ("plate",), (DOWN,), 100.0),
    ]
    return AC.Assembly(solids, steps)


def test_the_search_finds_the_one_order_that_works():
    """The cover's roof is 15 mm over the block, 11 mm over the screw's head: neither a 100 mm
    screwdriver nor an L key's 20 mm short arm fits under it, so the block must be screwed down
    before the cover goes on, and the plate first: plate, block, cover (declared the other way)."""
    order = AC.find_order(world())
    assert [p.step.name for p in order] == ["plate", "block", "cover"]
    assert [p.direction for p in order] == [DOWN, SLIDE, DOWN]


def test_a_planted_wrong_order_is_refused():
    a = world()
    with pytest.raises(GeometryError, match=r"step 1 \(block\).*needs plate"):
        AC.check_order(a, ["block", "plate", "cover"])
    with pytest.raises(GeometryError, match=r"step 3 \(block\).*blocked by cover"):
        AC.check_order(a, ["plate", "cover", "block"])  # the screw is under the cover's roof by now


def test_a_blocked_bolt_is_refused_and_a_clear_one_passes():
    """A lid 2 mm over the screw's head blocks every tool (and the head's own way in); with the
    cover 200 mm up the 100 mm driver reaches."""
    a = world()
    lid = box((-5, -5, 16), (5, 5, 20))  # 2 mm over the head (its top at z = 10 + 4 mm head = 14)
    blocked = AC.Assembly({**a.solids, "lid": lid},
                          [AC.Step("lid", ("lid",), (DOWN,), 100.0, needs=()), *a.steps], with_bench=False)
    with pytest.raises(GeometryError, match=r"block.*(screwdriver|L hex key).*blocked by lid"):
        AC.check_order(blocked, ["plate", "lid", "block", "cover"])
    high = world(cover_gap=200.0)
    assert [p.step.name for p in AC.check_order(high, ["plate", "cover", "block"])] == ["plate", "cover", "block"]


def test_the_tool_path_is_the_tools_length():
    """The driver's blade is 100 mm and the screw's head top is 4 mm above the block (z = 14): a roof
    1 mm beyond the blade's reach is clear of it, one 1 mm short of it is not; the tool's stated
    length decides (the driver alone here: no L key)."""
    only_driver = fasteners.driver("M4")[:1]
    for gap, ok in ((DRIVER_BLADE_MM + 4.0 + 1.0, True), (DRIVER_BLADE_MM + 4.0 - 1.0, False)):
        a = world(cover_gap=gap, tools=only_driver)
        try:
            AC.check_order(a, ["plate", "cover", "block"])
            passed = True
        except GeometryError:
            passed = False
        assert passed is ok, (gap, ok)


def test_a_part_swept_through_a_wall_is_refused_but_resting_contact_passes():
    """A block lowered onto a plate touches it (passes); a bar pushed sideways through a post
    collides on the way, though both end positions are clear."""
    solids = {"plate": box((-50, -50, -10), (50, 50, 0)), "block": box((-5, -5, 0), (5, 5, 5)),
              "post": box((20, -5, 0), (25, 5, 30)), "bar": box((30, -2, 10), (40, 2, 14))}
    steps = [AC.Step("plate", ("plate",), (DOWN,), 100.0), AC.Step("block", ("block",), (DOWN,), 100.0),
             AC.Step("post", ("post",), (DOWN,), 100.0),
             AC.Step("bar", ("bar",), ((1.0, 0.0, 0.0),), 100.0)]  # comes from -x, through the post
    a = AC.Assembly(solids, steps, with_bench=False)
    with pytest.raises(GeometryError, match=r"bar.*runs .* into post"):
        AC.check_order(a, ["plate", "block", "post", "bar"])
    ok = AC.check_order(a, ["plate", "block", "bar", "post"])  # the bar before the post: nothing in its way
    assert [p.step.name for p in ok] == ["plate", "block", "bar", "post"]


def test_steps_that_need_each_other_are_refused_at_once():
    solids = {"a": box((0, 0, 0), (1, 1, 1)), "b": box((2, 0, 0), (3, 1, 1))}
    steps = [AC.Step("a", ("a",), (DOWN,), 10.0, needs=("b",)), AC.Step("b", ("b",), (DOWN,), 10.0, needs=("a",))]
    with pytest.raises(GeometryError, match="loop"):
        AC.find_order(AC.Assembly(solids, steps))


@pytest.mark.slow
@pytest.mark.parametrize("buy", [None, "buy:\n  column: extrusion_40x40\n  shelf: aluminium_plate\n"])
def test_the_default_rig_has_a_feasible_order_printed_or_bought(tmp_path, buy):
    """The default profile, its tower printed or bought, goes together in an order the check finds
    (~15 s each); the plan takes no printer (a split piece is joined before assembly), so this holds
    for every printer. On the same rig, the planted wrong orders are refused: the dome before the
    plate it rests on, the paraboloid before the beam it clamps to."""
    import rigcad
    from rigcad.manual.assembly import picture_meshes

    path = tmp_path / "p.yaml"
    path.write_text("extends: achutha2006\n" + (buy or ""), encoding="utf-8")
    rig = rigcad.load(path)
    a = plan.assembly(rig, picture_meshes(rig))
    order = [p.step.name for p in AC.find_order(a)]
    assert order.index("base_plate") < order.index("dome") < order.index("beam") < order.index("paraboloid")
    assert order.index("camera_shims") < order.index("camera_body")  # the shims before the screws through them
    assert "projector_lens" not in [s.name for s in a.steps]  # the projector's lens goes with its body
    wrong = [n for n in order if n != "base_plate"]
    wrong.insert(wrong.index("dome") + 1, "base_plate")
    with pytest.raises(GeometryError, match=r"\(dome\).*needs base_plate"):
        AC.check_order(a, wrong)
