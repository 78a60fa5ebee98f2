"""The COP tower's own joints in the assembly check (rigcad.manual.tower_joints): declared where the
tower's parts put their holes, checked for their tool paths and their nuts' room; a blocked tool
path is refused."""

from __future__ import annotations

import manifold3d as m3
import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.manual import assembly_check as AC
from rigcad.manual import plan, tower_joints
from rigcad.standards import THREADS
from rigcad.manual.assembly import picture_meshes
from rigcad.parts import tower

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e


def _box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return m3.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))


@pytest.fixture(scope="module")
def rig_assembly(table31_rig):
    return plan.assembly(table31_rig, picture_meshes(table31_rig))


def test_the_tower_joints_are_declared_from_the_parts_holes(table31_rig, rig_assembly):
    t, p = table31_rig.layout.tower, table31_rig.profile
    steps = {s.name: s for s in rig_assembly.steps}
    flange = sorted(tower._column_flange_points(t, p))
    for name, axis in (("tower_column", plan.DOWN), ("tower_shelf", plan.UP)):
        fs = steps[name].fasteners
        assert sorted((f.head[0], f.head[1]) for f in fs) == flange and all(f.axis == axis for f in fs)
    holder = steps["splitter_holder"].fasteners
    springs = [f for f in holder if f.thread_in == "nut"]
    screws = [f for f in holder if f.thread_in == "insert"]
    assert sorted((f.head[0], f.head[1]) for f in springs) == sorted(tower._holder_flange_points(t, p))
    assert sorted((f.head[0], f.head[1]) for f in screws) == sorted(tower.seat_points(t, p).values())
    # every hardware row placed here is one of the tower's rows, and the rest stay with the tower's list
    rows = [h for h in tower.hardware(p, table31_rig.layout) if h.get("thread")]
    assert sum(tower_joints.placed(h) for h in rows) == len(tower_joints.PLACED)


def test_the_found_order_fits_the_tower_joints_and_a_blocked_tool_is_refused(rig_assembly):
    order = [p.step.name for p in AC.find_order(rig_assembly)]
    shelf_bolt = next(f for f in rig_assembly.by_name["tower_shelf"].fasteners)
    x, y, z = shelf_bolt.head
    # a block 50 mm under the bolt's head (it goes up from under the column's flange): in no part's
    # way, only in the hex tools' (the driver's 100 mm blade, the L key's 20 mm short arm + its long arm)
    blocker = _box((x - 5, y - 5, z - 30), (x + 5, y + 5, z - 24))
    a = AC.Assembly({**rig_assembly.solids, "blocker": blocker},
                    [AC.Step("blocker", ("blocker",), (plan.DOWN,), 10.0), *rig_assembly.steps])
    names = list(order)
    names.insert(names.index("tower_shelf"), "blocker")
    with pytest.raises(GeometryError, match=r"tower_shelf.*M4 x \d+ mm socket-head bolt.*blocked by blocker"):
        AC.check_order(a, names)
    names.remove("blocker")
    names.insert(names.index("tower_shelf") + 1, "blocker")  # after the shelf is bolted: no harm
    assert [p.step.name for p in AC.check_order(a, names)] == names


def test_the_nut_trap_holds_an_m4_nut_where_the_check_looks(table31_rig):
    """The trap (tower.NUT_TRAP, a hexagon 7.0 + 2 x 0.2 mm across flats, in the base plate's recipe)
    and the nut as the check sees it (an ISO 4032 hexagon, 7 mm across flats, a corner on +x as the
    trap holds it: 8.08 mm along x, 7.0 mm along y, closed form): the nut is clear of the trap; a trap
    0.2 mm narrower than the nut is refused; the nut cannot turn in its trap."""
    from rigcad.parts.recipe import HexPrism

    f = plan._socket_head("M4 bolt", (0.0, 0.0, 20.0), plan.DOWN, 20.0, "M4", thread_in="nut",
                          nut_size_mm=(THREADS["M4"].nut_af / np.sqrt(3.0), 3.2), grip_mm=14.0)
    # the nut alone: the shank and everything above z = 10 (the head, 7 mm across: ISO 4762) taken away
    nut = (f.solids() - AC.cylinder(np.array([0.0, 0.0, 30.0]), np.array([0.0, 0.0, -1.0]), 40.0, 2.5)
           - AC.cylinder(np.array([0.0, 0.0, 30.0]), np.array([0.0, 0.0, -1.0]), 20.0, 10.0))
    lo, hi = np.array(nut.bounding_box()[:3]), np.array(nut.bounding_box()[3:])
    assert hi[0] - lo[0] == pytest.approx(2 * 7.0 / np.sqrt(3.0), abs=1e-6)
    assert hi[1] - lo[1] == pytest.approx(7.0, abs=1e-6)
    traps = [c for c in _cuts(table31_rig.recipes["base_plate"].solid) if isinstance(c, HexPrism)]
    assert len(traps) == 4 and all(c.across_flats == tower.NUT_TRAP == 7.4 for c in traps)

    def trap(across_flats):
        pocket = AC.hex_prism(np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0]), 7.0, across_flats / np.sqrt(3.0))
        return _box((-20, -20, 0), (20, 20, 10)) - pocket - AC.cylinder(
            np.array([0.0, 0.0, 20.0]), np.array([0.0, 0.0, -1.0]), 30.0, 2.25)

    assert abs(AC.penetration(f.solids(), trap(tower.NUT_TRAP))) < 1e-6  # it touches the ceiling only
    assert AC.penetration(f.solids(), trap(THREADS["M4"].nut_af - 0.2)) > AC.CLEARANCE_MM
    assert f.nut_size_mm[0] > tower.NUT_TRAP / 2  # its corners reach past the trap's flats: it cannot turn


def _cuts(solid):
    from rigcad.parts.recipe import Difference, Translate, Union_

    if isinstance(solid, Difference):
        yield from _cuts(solid.base)
        yield from solid.cuts
    elif isinstance(solid, Union_):
        for s in solid.items:
            yield from _cuts(s)
    elif isinstance(solid, Translate):
        yield from _cuts(solid.solid)


@pytest.fixture(scope="module")
def bought_assembly(tmp_path_factory):
    import rigcad

    path = tmp_path_factory.mktemp("bought") / "p.yaml"
    path.write_text("extends: achutha2006\nbuy:\n  column: extrusion_40x40\n  shelf: aluminium_plate\n", encoding="utf-8")
    rig = rigcad.load(path)
    return rig, plan.assembly(rig, picture_meshes(rig))


def test_the_bought_extrusions_core_screws_are_checked_and_a_blocked_one_is_refused(bought_assembly):
    """The extrusion's M8 core screws sit on the column's axis, heads in the tongue's counterbore
    and the shelf's countersink; their thread stops short of the core's tapped depth; the found order
    fits them; a block over the shelf's screw before the shelf is refused, after it passes; the foot's
    screw, put in from below, needs the rig on blocks (without them the bench blocks its tools)."""
    rig, a = bought_assembly
    t = rig.layout.tower
    (foot,), (top,) = a.by_name["tower_column"].fasteners, a.by_name["tower_shelf"].fasteners
    from rigcad.manual.calibration import film_setup
    from rigcad.manual.document import step_text

    lift = film_setup(rig)["block_under_tongue_mm"]
    assert foot.lift_mm == lift and top.lift_mm == 0.0
    text = step_text(AC.Placed(a.by_name["tower_column"], plan.DOWN), {m.name: m for m in picture_meshes(rig)})
    assert f"lift the rig onto blocks {lift:g} mm high" in text
    assert foot.head == pytest.approx((t.column_x, 0.0, t.bench_z + tower.CORE_HEAD_BORE[1]))
    assert top.head == pytest.approx((t.column_x, 0.0, t.shelf_top_z - tower.CORE_TOP_SCREW[1]))
    # engaged thread = length - what the screw passes (plate under the counterbore, minus the pocket)
    engaged_foot = foot.length_mm - (-t.bench_z - tower.CORE_HEAD_BORE[1] - tower.POCKET_DEPTH)
    engaged_top = top.length_mm - (t.shelf_thickness - tower.CORE_TOP_SCREW[1] - tower.POCKET_DEPTH)
    for e in (engaged_foot, engaged_top):
        assert 1.5 * 8.0 <= e <= tower.CORE_TAP_DEPTH - 1.0
    order = [p.step.name for p in AC.find_order(a)]
    # a lid over the shelf's screw, going down with the shelf (one step): in the way of the driver's
    # 100 mm blade and of the L key's 28 mm short arm, in no part's way
    x, y, _ = top.head
    z = t.shelf_top_z
    lid = _box((x - 10, y - 10, z + 20), (x + 10, y + 10, z + 26))
    shelf = a.by_name["tower_shelf"]
    import dataclasses

    lidded = dataclasses.replace(shelf, members=(*shelf.members, "lid"))
    b = AC.Assembly({**a.solids, "lid": lid}, [lidded if s.name == "tower_shelf" else s for s in a.steps])
    with pytest.raises(GeometryError, match=r"tower_shelf.*M8 x 25 mm countersunk.*blocked by lid"):
        AC.check_order(b, order)
    high = _box((x - 10, y - 10, z + 130), (x + 10, y + 10, z + 136))  # beyond the blade: no harm
    b = AC.Assembly({**a.solids, "lid": high}, [lidded if s.name == "tower_shelf" else s for s in a.steps])
    assert [p.step.name for p in AC.check_order(b, order)] == order
    col = a.by_name["tower_column"]
    flat = dataclasses.replace(col, fasteners=(dataclasses.replace(foot, lift_mm=0.0),))
    c = AC.Assembly(a.solids, [flat if s.name == "tower_column" else s for s in a.steps])
    # M8 x 25: the tongue is 17 mm deep (the bench 2 mm under the collar), 7 mm under the counterbore
    # and pocket, so 25 mm engages 18 mm, 1 mm short of the 20 mm tapped core
    assert foot.length_mm == 25.0 and engaged_foot == pytest.approx(18.0)
    with pytest.raises(GeometryError, match=r"tower_column.*M8 x 25 mm socket-head.*blocked by the bench"):
        AC.check_order(c, order)


def test_the_bought_columns_screws_go_in_the_hardware_once(bought_assembly):
    rig, a = bought_assembly
    rows = [h for h in tower.hardware(rig.profile, rig.layout) if h.get("thread") == "M8"]
    assert len(rows) == 2 and all(tower_joints.placed(h) for h in rows)
    table = plan.hardware(a.steps, rig)
    m8 = [r for r in table if r["item"].startswith("M8")]
    assert sorted(r["quantity"] for r in m8) == [1, 1] and not any("M8 washer" in r["item"] for r in table)
