"""rigcad.fab.split on small manifold3d solids built here (tubes, boxes; milliseconds each): the
plans' cells against closed-form volumes and angles, the grid's order, the phase that keeps the
cut planes off a hole, the cut faces and their clear zones, pins on a tube (with a cylindrical
mirror whose distance is known in closed form), tongues and grooves, and the pieces reassembling
to the drilled part. The dome and the plate of the Table 3.1 rig are split in test_split.py and
test_split_form3.py."""

from __future__ import annotations

import math
from types import SimpleNamespace

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.errors import FabricationError
from rigcad.fab import split as SP
from rigcad.fab.printers import AlignmentPin

SEG = 96  # polygon segments of the test cylinders (a multiple of 8: sectors cut it symmetrically)


def _tube(r_out=50.0, r_in=35.0, h=30.0, z0=0.0):
    outer = m3d.Manifold.cylinder(h, r_out, r_out, SEG)
    inner = m3d.Manifold.cylinder(h + 2, r_in, r_in, SEG).translate((0, 0, -1))
    return (outer - inner).translate((0, 0, z0))


def _polygon_area(r, n=SEG):
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)


def _bbox(man):
    return np.asarray(man.bounding_box(), float)


def test_a_split_plan_describes_its_sectors_and_bands():
    plan = SP.SplitPlan(4, 2, math.radians(10), (0.0, 12.0, 30.0))
    assert plan.count == 8
    assert plan.sector_range(1) == pytest.approx((math.radians(100), math.radians(190)))
    d = plan.describe()
    assert d == {"sectors": 4, "bands": 2, "pieces": 8, "sector_phase_deg": pytest.approx(10.0),
                 "sector_planes_deg": pytest.approx([10.0, 100.0, 190.0, 280.0]), "band_cuts_z_mm": [12.0]}
    assert SP.SplitPlan(1, 1, 0.0, (0.0, 1.0)).describe()["sector_planes_deg"] == []
    assert SP.SplitPlan(2, 1, math.radians(300), (0.0, 1.0)).describe()["sector_planes_deg"] == \
        pytest.approx([300.0, 120.0])  # modulo 360


def test_a_grid_plan_counts_and_orders_its_cells():
    g = SP.GridPlan((10.0,), (5.0, 7.0), (3.0,))
    assert (g.nx, g.ny, g.nz, g.count) == (2, 3, 2, 12)
    assert g.cells()[:4] == [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)] and g.cells()[-1] == (1, 2, 1)
    assert [g.cuts(a) for a in range(3)] == [(10.0,), (5.0, 7.0), (3.0,)]
    assert (g.sectors, g.bands, g.sector_range(0)) == (1, 1, None)
    assert g.describe() == {"kind": "grid of planes in the part's bounding box", "sectors": 1, "bands": 1,
                            "grid": [2, 3, 2], "pieces": 12, "x_cuts_mm": [10.0], "y_cuts_mm": [5.0, 7.0],
                            "z_cuts_mm": [3.0], "sector_planes_deg": [], "band_cuts_z_mm": []}
    assert SP.GridPlan((), ()).count == 1


def test_cells_of_a_tube_are_its_sectors_and_bands():
    tube = _tube()
    ring = _polygon_area(50.0) - _polygon_area(35.0)
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 12.0, 30.0))
    for i in range(4):
        for j, h in ((0, 12.0), (1, 18.0)):
            c = SP.cell(tube, plan, i, j)
            assert c.volume() == pytest.approx(ring * h / 4, rel=1e-9), (i, j)
            v = np.asarray(c.to_mesh().vert_properties)[:, :3]
            ang = np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360
            lo = 90.0 * i
            assert np.all(((ang - lo + 1e-6) % 360) <= 90.0 + 2e-6), (i, j)  # inside its quarter
            z0, z1 = (0.0, 12.0) if j == 0 else (12.0, 30.0)
            assert (v[:, 2].min(), v[:, 2].max()) == pytest.approx((z0, z1), abs=1e-9)
    three = SP.SplitPlan(1, 3, 0.0, (0.0, 5.0, 20.0, 30.0))
    assert [SP.cell(tube, three, 0, j).volume() for j in range(3)] == pytest.approx([ring * 5, ring * 15, ring * 10])
    assert SP.cell(tube, SP.SplitPlan(1, 1, 0.0, (0.0, 30.0)), 0, 0).volume() == pytest.approx(ring * 30)
    # the first band holds all under the first cut and the last all above the last (no floor, no roof)
    short = SP.SplitPlan(1, 2, 0.0, (10.0, 12.0, 20.0))
    assert [SP.cell(tube, short, 0, j).volume() for j in range(2)] == pytest.approx([ring * 12, ring * 18])


def test_grid_cells_are_the_slabs_of_the_box():
    box = m3d.Manifold.cube((30.0, 20.0, 10.0))
    plan = SP.GridPlan((10.0,), (5.0, 15.0), (4.0,))
    total = 0.0
    for i, j, k in plan.cells():
        c = SP.grid_cell(box, plan, i, j, k)
        xs, ys, zs = (0.0, 10.0, 30.0), (0.0, 5.0, 15.0, 20.0), (0.0, 4.0, 10.0)
        want = (xs[i], ys[j], zs[k], xs[i + 1], ys[j + 1], zs[k + 1])
        assert _bbox(c) == pytest.approx(want, abs=1e-9), (i, j, k)
        total += c.volume()
    assert total == pytest.approx(6000.0, rel=1e-12)
    assert SP.grid_cell(box, SP.GridPlan((10.0,), ()), 1, 0).volume() == pytest.approx(4000.0)


def test_a_part_off_the_axis_by_more_than_5_percent_of_its_size():
    box = m3d.Manifold.cube((100.0, 40.0, 10.0), True)
    assert not SP.is_off_axis(box)
    assert not SP.is_off_axis(box.translate((4.9, -4.9, 50.0)))  # z does not count
    assert SP.is_off_axis(box.translate((5.1, 0, 0))) and SP.is_off_axis(box.translate((0, -5.1, 0)))
    assert SP.is_off_axis(box.translate((2.0, 0, 0)), rtol=0.01)
    assert not SP.is_off_axis(box.translate((5.0, 0, 0)))  # exactly 5 % off: still on the axis
    tall = m3d.Manifold.cube((40.0, 100.0, 10.0), True)  # its size is its y extent
    assert not SP.is_off_axis(tall.translate((4.9, 0, 0))) and SP.is_off_axis(tall.translate((5.1, 0, 0)))


def test_grid_options_fewest_pieces_first_and_the_longest_side_cut_first():
    opts = SP._grid_options(np.array([50.0, 300.0, 100.0]))
    assert len(opts) == 6 ** 3 and opts[0] == (1, 1, 1)
    assert opts[1:4] == [(1, 2, 1), (1, 1, 2), (2, 1, 1)]  # y, then z, then x: longest first
    assert [math.prod(o) for o in opts] == sorted(math.prod(o) for o in opts)
    # sides equal to rounding: x, y, z order
    assert SP._grid_options(np.array([100.0, 100.0 * (1 + 1e-12), 100.0]))[1:4] == [(2, 1, 1), (1, 2, 1), (1, 1, 2)]
    assert SP._grid_options(np.array([100.0, 100.0 * (1 + 1e-6), 100.0]))[1:4] == [(1, 2, 1), (2, 1, 1), (1, 1, 2)]
    assert SP._grid_options(np.array([10.0, 20.0, 30.0]))[4:13] == [
        (1, 1, 3), (1, 3, 1), (3, 1, 1), (1, 1, 4), (1, 2, 2), (2, 1, 2), (1, 4, 1), (2, 2, 1), (4, 1, 1)]


def test_plan_grid_cuts_the_long_side_into_equal_slabs_until_every_cell_fits():
    box = m3d.Manifold.cube((300.0, 100.0, 50.0)).translate((10.0, 0, 0))
    calls = []

    def fits(c, plan, i, j):
        assert isinstance(plan, SP.GridPlan)
        bb = _bbox(c)
        calls.append((i, j, round(bb[0], 6), round(bb[3], 6)))
        return float(np.ptp(bb.reshape(2, 3), axis=0).max()) <= 110.0

    plan = SP.plan_grid(box, fits)
    assert plan.x_cuts == pytest.approx((110.0, 210.0)) and plan.y_cuts == () and plan.z_cuts == ()
    # one failing cell each for 1 x 1 x 1 and the three 2-piece grids, then the three slabs of 3 x 1 x 1
    assert len(calls) == 7 and calls[-3:] == [(0, 0, 10.0, 110.0), (1, 0, 110.0, 210.0), (2, 0, 210.0, 310.0)]
    # two 2-piece grids fit: the longer side is cut, wherever the part lies
    either = m3d.Manifold.cube((300.0, 280.0, 50.0)).translate((-400.0, -10.0, 0.0))
    ext = lambda c: np.ptp(_bbox(c).reshape(2, 3), axis=0)  # noqa: E731
    two = SP.plan_grid(either, lambda c, *a: ext(c)[0] <= 160.0 or ext(c)[1] <= 150.0)
    assert (len(two.x_cuts), len(two.y_cuts)) == (1, 0) and two.x_cuts[0] == pytest.approx(-250.0)
    with pytest.raises(FabricationError) as e:
        SP.plan_grid(box, lambda *a: False)
    assert str(e.value) == "no grid of up to 6 x 6 x 6 pieces fits"  # rigcad.fab.choice names the printer


def test_band_cuts_low_to_high_for_two_and_equal_otherwise():
    two = list(SP.band_cuts(10.0, 30.0, 2))
    assert len(two) == 13 and [c[1] for c in two] == pytest.approx([10 + 20 * f for f in np.arange(0.2, 0.81, 0.05)])
    assert all(c[0] == 10.0 and c[2] == 30.0 for c in two)
    assert list(SP.band_cuts(0.0, 30.0, 3)) == [pytest.approx((0.0, 10.0, 20.0, 30.0))]
    assert list(SP.band_cuts(0.0, 30.0, 1)) == [pytest.approx((0.0, 30.0))]


def test_plan_split_takes_the_fewest_pieces_then_the_fewest_bands():
    tube = _tube()

    def fits(c, plan, i, j):  # pieces at most 20 mm tall and 101 mm wide
        assert isinstance(plan, SP.SplitPlan) and 0 <= i < plan.sectors and 0 <= j < plan.bands
        ext = np.ptp(_bbox(c).reshape(2, 3), axis=0)
        return ext[2] <= 20.0 and max(ext[0], ext[1]) <= 101.0

    plan = SP.plan_split(tube, fits)
    assert (plan.sectors, plan.bands, plan.phase) == (1, 2, 0.0)
    assert plan.band_z == pytest.approx((0.0, 30 * 0.35, 30.0))  # the lowest cut leaving both bands <= 20
    narrow = SP.plan_split(tube, lambda c, *a: float(np.ptp(_bbox(c).reshape(2, 3), axis=0)[:2].max()) <= 75.0)
    # a half ring is 100 mm long, a third 87 mm: quarters, at the phase that crosses fewest features
    assert (narrow.sectors, narrow.bands, narrow.phase) == (4, 1, SP.choose_phase(tube, 4))
    # fewest pieces first: two halves (50 mm across) before three bands of the whole ring (10 mm tall)
    def ext(c):
        return np.ptp(_bbox(c).reshape(2, 3), axis=0)

    halves = SP.plan_split(tube, lambda c, *a: max(ext(c)[:2]) <= 100.5 and (min(ext(c)[:2]) <= 60.0 or ext(c)[2] <= 12.0))
    assert (halves.sectors, halves.bands) == (2, 1)
    # two pieces in two bands before more pieces in one band (narrow sectors would fit too)
    bands = SP.plan_split(tube, lambda c, *a: ext(c)[2] <= 20.0 or max(ext(c)[:2]) <= 30.0)
    assert (bands.sectors, bands.bands) == (1, 2)
    with pytest.raises(FabricationError, match=r"^no split into up to 16 sectors x 4 bands fits$"):
        SP.plan_split(tube, lambda *a: False)


def _tube_with_hole(deg, r_hole=3.0):
    a = math.radians(deg)
    hole = m3d.Manifold.cylinder(40.0, r_hole, r_hole, 24).translate((42.5 * math.cos(a), 42.5 * math.sin(a), -5.0))
    return _tube() - hole


def test_the_phase_keeps_the_cut_planes_off_a_hole():
    plain = _tube()
    assert SP._loops_on_half_plane(plain, 0.3) == 1
    holed = _tube_with_hole(0.0)
    assert SP._loops_on_half_plane(holed, 0.0) == 2 and SP._loops_on_half_plane(holed, math.pi) == 1
    assert SP._loops_on_planes(holed, 2, 0.0) == 3 and SP._loops_on_planes(holed, 4, 0.0) == 5
    seen = {}
    assert SP._loops_on_planes(holed, 2, 0.0, seen) == 3 and seen == {0.0: 2, math.pi: 1}
    seen[0.0] = 7  # the angles counted already are not sliced again
    assert SP._loops_on_planes(holed, 2, 0.0, seen) == 8
    assert SP.choose_phase(holed, 1) == 0.0
    seen = {}
    SP.choose_phase(holed, 2, seen=seen)
    assert len(seen) == 144  # 72 phases (0 .. 177.5 deg) x two half-planes, each sliced once, kept
    # two clear runs as wide (holes at 0 and 90 deg): the first, 10 .. 80 deg
    two = _tube() - m3d.Manifold.cylinder(40.0, 3.0, 3.0, 24).translate((42.5, 0.0, -5.0)) \
        - m3d.Manifold.cylinder(40.0, 3.0, 3.0, 24).translate((0.0, 42.5, -5.0))
    assert math.degrees(SP.choose_phase(two, 2)) == pytest.approx(45.0, abs=1e-9)
    # a hole at 0 deg: the two half-planes (phase, phase + 180) are clear from 10 to 170 deg: the middle
    assert math.degrees(SP.choose_phase(holed, 2)) == pytest.approx(90.0, abs=1e-9)
    assert math.degrees(SP.choose_phase(_tube_with_hole(30.0), 2)) == pytest.approx(120.0, abs=1e-9)
    # the clear run wraps around the period: a hole at 100 deg, 2 sectors (period 180): clear from
    # 112.5 through 180 = 0 to 87.5 deg, its middle at 10 deg
    assert math.degrees(SP.choose_phase(_tube_with_hole(100.0), 2)) == pytest.approx(10.0, abs=1e-9)
    # a clear run whose middle falls between the last two grid phases (175, 177.5) or on the last one
    assert math.degrees(SP.choose_phase(_tube_with_hole(86.25), 2)) == pytest.approx(176.25, abs=1e-9)
    assert math.degrees(SP.choose_phase(_tube_with_hole(87.5), 2)) == pytest.approx(177.5, abs=1e-9)
    assert math.degrees(SP.choose_phase(_tube_with_hole(88.75), 2)) == pytest.approx(177.5, abs=1e-9)
    # every phase equally good: the middle of the whole period's grid (0 .. 87.5 deg)
    assert math.degrees(SP.choose_phase(plain, 4)) == pytest.approx(43.75, abs=1e-9)
    assert math.degrees(SP.choose_phase(plain, 4, step_deg=5.0)) == pytest.approx(42.5, abs=1e-9)


def test_the_plane_frame_puts_the_plane_at_z_0():
    for n, o in (((0.0, 0.0, 1.0), (1.0, 2.0, 3.0)), ((1.0, 1.0, 0.0), (0.0, 0.0, 0.0)), ((0.3, -0.2, 0.95), (5, 6, 7))):
        n, o = np.asarray(n, float), np.asarray(o, float)
        f = SP._plane_frame(n * 2.0, o)  # any length of the normal
        rot = f[:, :3]
        assert rot @ rot.T == pytest.approx(np.eye(3), abs=1e-12) and np.linalg.det(rot) == pytest.approx(1.0)
        assert rot[2] == pytest.approx(n / np.linalg.norm(n), abs=1e-12)
        assert rot @ o + f[:, 3] == pytest.approx(np.zeros(3), abs=1e-12)
    vertical = SP._plane_frame(np.array([0.0, 1.0, 0.0]), np.zeros(3))
    assert vertical[0, :3] == pytest.approx([0.0, 0.0, 1.0])  # e1 = z for a vertical plane
    assert SP._plane_frame(np.array([0.0, 0.0, 1.0]), np.zeros(3))[0, :3] == pytest.approx([1.0, 0.0, 0.0])
    # e1 is z projected onto the plane (x for a plane within 26 deg of horizontal)
    assert SP._plane_frame(np.array([1.0, 0.0, 0.0]), np.zeros(3))[0, :3] == pytest.approx([0.0, 0.0, 1.0])
    tilted = SP._plane_frame(np.array([0.0, 0.3, 0.95]), np.zeros(3))
    assert tilted[0, :3] == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)


def test_interfaces_of_sectors_and_bands():
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 12.0, 30.0))
    faces = SP._interfaces(plan, np.zeros(6))
    names = [f[0] for f in faces]
    assert names == ["sector plane 0.0 deg, band 1", "sector plane 90.0 deg, band 1", "sector plane 180.0 deg, band 1",
                     "sector plane 270.0 deg, band 1"] + [f"band cut z 12.0 mm, sector {i}" for i in (1, 2, 3, 4)] + \
                    ["sector plane 0.0 deg, band 2", "sector plane 90.0 deg, band 2", "sector plane 180.0 deg, band 2",
                     "sector plane 270.0 deg, band 2"]
    name, n, o, keep = faces[1]  # the plane at 90 deg, band 1: x < 0 side is the other half-plane
    assert n == pytest.approx([-1.0, 0.0, 0.0]) and o.tolist() == [0.0, 0.0, 0.0]
    p = np.array([[0.0, 40.0, 5.0], [0.0, -40.0, 5.0], [0.0, 40.0, 13.0], [0.0, 40.0, -1.0]])
    assert keep(p).tolist() == [True, False, False, True]  # band 1 is open below (the part ends there)
    assert faces[9][0] == "sector plane 90.0 deg, band 2"
    assert faces[9][3](p).tolist() == [False, False, True, False]  # band 2: above the cut, open above
    name, n, o, keep = faces[5]  # band cut, sector 2 (90..180 deg)
    assert n.tolist() == [0.0, 0.0, 1.0] and o.tolist() == [0.0, 0.0, 12.0]
    q = np.array([[-10.0, 10.0, 12.0], [10.0, 10.0, 12.0], [-10.0, -10.0, 12.0]])
    assert keep(q).tolist() == [True, False, False]
    one = SP._interfaces(SP.SplitPlan(1, 2, 0.0, (0.0, 12.0, 30.0)), np.zeros(6))
    assert [f[0] for f in one] == ["band cut z 12.0 mm, sector 1"] and one[0][3](q).tolist() == [True] * 3
    three = SP._interfaces(SP.SplitPlan(2, 3, 0.0, (0.0, 10.0, 20.0, 30.0)), np.zeros(6))
    # two sectors: their half-planes are one plane joining the same two pieces, one face per band, both sides
    assert [f[0] for f in three if f[0].startswith("sector")] == [f"sector plane 0.0/180.0 deg, band {j}" for j in (1, 2, 3)]
    mid = [f for f in three if f[0] == "sector plane 0.0/180.0 deg, band 2"][0][3]
    assert mid(np.array([[40.0, 0.0, 15.0], [40.0, 0.0, 9.0], [40.0, 0.0, 21.0], [-40.0, 0.0, 15.0]])).tolist() == \
        [True, False, False, True]


def test_interface_masks_at_their_edges():
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 12.0, 30.0))
    faces = {f[0]: f[3] for f in SP._interfaces(plan, np.zeros(6))}
    # the half-plane at 90 deg (x = 0, y > 0), band 1: strictly on the radial side, z not counted;
    # the band's edges are open (z = 12 belongs to neither band's sector planes)
    p = np.array([[0.0, -4.0, 5.0], [0.0, 0.0, 5.0], [0.0, 0.5, 5.0], [0.0, 40.0, 12.0]])
    assert faces["sector plane 90.0 deg, band 1"](p).tolist() == [False, False, True, False]
    # band 2, the last: open above (z = 31 past the top is on it), closed at z = 12
    top = np.array([[0.0, 40.0, 31.0], [0.0, 40.0, 12.0]])
    assert faces["sector plane 90.0 deg, band 2"](top).tolist() == [True, False]
    # a band cut's sector: its angular range is [a0, a1): 0 deg in, 90 deg out, 315 deg in sector 4
    q = np.array([[10.0, 0.0, 12.0], [0.0, 10.0, 12.0], [10.0, -10.0, 12.0]])
    assert faces["band cut z 12.0 mm, sector 1"](q).tolist() == [True, False, False]
    assert faces["band cut z 12.0 mm, sector 4"](q).tolist() == [False, False, True]
    # one sector: the whole band cut, boolean, even a point whose angle rounds to -0 (2 pi modulo 2 pi)
    one = SP._interfaces(SP.SplitPlan(1, 2, 0.0, (0.0, 12.0, 30.0)), np.zeros(6))[0][3]
    m = one(np.array([[1.0, -1e-17, 12.0], [-1.0, 0.0, 12.0]]))
    assert m.dtype == bool and m.tolist() == [True, True]
    # two sectors: each band cut keeps its half
    two = {f[0]: f[3] for f in SP._interfaces(SP.SplitPlan(2, 2, 0.0, (0.0, 12.0, 30.0)), np.zeros(6))}
    assert two["band cut z 12.0 mm, sector 1"](np.array([[0.0, 10.0, 12.0], [0.0, -10.0, 12.0]])).tolist() == \
        [True, False]
    # plane angles past 360 deg are named modulo 360
    names = [f[0] for f in SP._interfaces(SP.SplitPlan(2, 1, math.radians(300), (0.0, 30.0)), np.zeros(6))]
    assert names == ["sector plane 300.0/120.0 deg, band 1"]


def test_other_planes_clear_keeps_points_off_every_other_cut():
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 12.0, 30.0))
    face_n, face_o = np.array([0.0, 1.0, 0.0]), np.zeros(3)  # the plane at 0 deg (its own: ignored)
    pts = np.array([[40.0, 0.0, 5.0],  # on its own plane
                    [0.5, 40.0, 5.0],  # 0.5 from the plane at 90 deg
                    [-0.5, -40.0, 5.0],  # 0.5 from the half-plane at 270 deg
                    [0.5, -40.0, 5.0],  # 0.5 from the half-plane at 270 deg, other side
                    [30.0, 30.0, 11.5], [30.0, 30.0, 13.1], [30.0, 30.0, 12.5]])
    assert SP._other_planes_clear(pts, plan, face_n, face_o, 1.0).tolist() == \
        [True, False, False, False, False, True, False]
    # under a band cut with a groove 2 mm deep: 3 mm below it is needed
    assert SP._other_planes_clear(np.array([[30.0, 30.0, 9.5], [30.0, 30.0, 8.9]]), plan, face_n, face_o, 1.0,
                                  below=2.0).tolist() == [False, True]
    # the band cut's own face ignores its own plane, not the sector planes
    band = SP._other_planes_clear(np.array([[30.0, 30.0, 12.0], [30.0, 0.5, 12.0]]), plan,
                                  np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 12.0]), 1.0)
    assert band.tolist() == [True, False]
    # the opposite half-plane (180 deg) is the same plane as 0 deg: ignored too; a far point on the
    # other side of a half-plane's line is not near it
    assert SP._other_planes_clear(np.array([[-40.0, 0.2, 5.0], [-40.0, 0.0, 5.0]]), plan, face_n, face_o, 1.0).all()
    # no groove by default: 1.5 mm under the band cut is clear; exactly the margin above or below is clear
    edge = np.array([[30.0, 30.0, 10.5], [30.0, 30.0, 13.0], [30.0, 30.0, 11.0]])
    assert SP._other_planes_clear(edge, plan, face_n, face_o, 1.0).tolist() == [True, True, True]
    # exactly the margin from the half-plane at 0 deg (its normal (0, 1, 0) exact): clear
    assert SP._other_planes_clear(np.array([[40.0, 1.0, 5.0]]), plan, np.array([-1.0, 0.0, 0.0]), face_o,
                                  1.0).tolist() == [True]
    # three sectors (0, 120, 240 deg), the face at 120 deg: 0.5 mm from the 0 deg plane's line, on its
    # half-plane's side (x = 0.9) or exactly the margin behind it (x = -1: clear)
    three = SP.SplitPlan(3, 1, 0.0, (0.0, 30.0))
    f120 = np.array([-math.sin(2 * math.pi / 3), math.cos(2 * math.pi / 3), 0.0])
    assert SP._other_planes_clear(np.array([[0.9, 0.9, 5.0], [-1.0, 0.5, 5.0]]), three, f120, face_o,
                                  1.0).tolist() == [False, True]
    # the face at 0 deg: a point 0.5 mm from the 120 deg plane's line but 3 mm behind the axis (z ignored)
    a = 2 * math.pi / 3
    radial, normal = np.array([math.cos(a), math.sin(a), 0.0]), np.array([-math.sin(a), math.cos(a), 0.0])
    behind = -3.0 * radial + 0.5 * normal + np.array([0.0, 0.0, 5.0])
    assert SP._other_planes_clear(behind[None], three, face_n, face_o, 1.0).tolist() == [True]
    # phase 45 deg: the 45 deg half-plane (normal (-1, 1) / sqrt 2) keeps a point 0.35 mm off it out
    quad = SP.SplitPlan(4, 1, math.radians(45), (0.0, 30.0))
    f135 = np.array([-math.sin(math.radians(135)), math.cos(math.radians(135)), 0.0])
    assert SP._other_planes_clear(np.array([[30.0, 30.5, 5.0]]), quad, f135, face_o, 1.0).tolist() == [False]
    # a band cut's face skips its own plane only: a cut 0.5 mm above it still counts
    close = SP.SplitPlan(1, 3, 0.0, (0.0, 10.0, 10.5, 30.0))
    assert SP._other_planes_clear(np.array([[30.0, 30.0, 11.2], [30.0, 30.0, 12.0]]), close,
                                  np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 10.0]), 1.0).tolist() == [False, True]
    # one sector: its phase half-plane is no cut; two sectors: both half-planes are
    up = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 12.0])
    near = np.array([[30.0, 0.5, 12.0], [-30.0, 0.5, 12.0]])
    assert SP._other_planes_clear(near, SP.SplitPlan(1, 2, 0.0, (0.0, 12.0, 30.0)), *up, 1.0).tolist() == [True, True]
    assert SP._other_planes_clear(near, SP.SplitPlan(2, 2, 0.0, (0.0, 12.0, 30.0)), *up, 1.0).tolist() == \
        [False, False]
    g = SP.GridPlan((10.0,), (5.0,))
    gp = np.array([[10.0, 2.0, 0.0], [3.0, 5.5, 0.0], [3.0, 6.0, 0.0], [3.0, 2.0, 0.0]])
    assert SP._grid_planes_clear(gp, g, np.array([1.0, 0, 0]), np.array([10.0, 0, 0]), 1.0).tolist() == \
        [True, False, True, True]
    assert SP._grid_planes_clear(gp, g, np.array([0, 1.0, 0]), np.array([0, 5.0, 0]), 1.0).tolist() == \
        [False, True, True, True]
    # a face skips its own plane only: other cuts on its axis (20, and 10.5 half a millimetre away) and
    # a cut on another axis through its origin's coordinate still count
    g2 = SP.GridPlan((10.0, 10.5, 20.0), (0.0,))
    p2 = np.array([[10.0, 3.0, 0.0], [10.4, 3.0, 0.0], [19.5, 3.0, 0.0], [5.0, 0.5, 0.0], [5.0, 3.0, 0.0]])
    assert SP._grid_planes_clear(p2, g2, np.array([1.0, 0, 0]), np.array([10.0, 0, 0]), 1.0).tolist() == \
        [False, False, False, False, True]


def test_grid_interfaces_name_each_face_and_keep_its_slabs():
    faces = SP._grid_interfaces(SP.GridPlan((10.0,), (5.0,)))
    assert [f[0] for f in faces] == ["x cut 10.0 mm, y slab 1, z slab 1", "x cut 10.0 mm, y slab 2, z slab 1",
                                     "y cut 5.0 mm, x slab 1, z slab 1", "y cut 5.0 mm, x slab 2, z slab 1"]
    assert faces[0][3](np.array([[10.0, 5.0, 0.0], [10.0, 4.9, 0.0]])).tolist() == [False, True]  # open slabs
    name, n, o, keep = faces[1]
    assert n.tolist() == [1.0, 0.0, 0.0] and o.tolist() == [10.0, 0.0, 0.0]
    p = np.array([[10.0, 6.0, 0.0], [10.0, 4.0, 0.0], [10.0, 5.0, 0.0]])
    assert keep(p).tolist() == [True, False, False]
    assert faces[2][3](np.array([[9.0, 5.0, 3.0], [11.0, 5.0, 3.0]])).tolist() == [True, False]
    stacked = SP._grid_interfaces(SP.GridPlan((10.0,), (), (4.0,)))
    assert [f[0] for f in stacked][:2] == ["x cut 10.0 mm, y slab 1, z slab 1", "x cut 10.0 mm, y slab 1, z slab 2"]
    assert stacked[0][3](np.array([[10.0, 0.0, 3.0], [10.0, 0.0, 5.0]])).tolist() == [True, False]
    assert stacked[1][3](np.array([[10.0, 0.0, 3.0], [10.0, 0.0, 5.0]])).tolist() == [False, True]


def test_farthest_points_spread_and_skip_the_invalid():
    pts = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [-9.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    # centre 1.4: first the farthest (-9), then the farthest from it (10), then from both: 0 and 1
    # are both 9 away, the tie to the first in order
    assert [p[0] for p in SP._farthest(pts, 3, lambda p: True)] == [-9.0, 10.0, 0.0]
    assert [p[0] for p in SP._farthest(pts, 2, lambda p: p[0] != -9.0)] == [10.0, 0.0]
    assert len(SP._farthest(pts, 9, lambda p: True)) == 5
    seen = []
    assert SP._farthest(pts, 2, lambda p: seen.append(1) or False) == [] and len(seen) == 5
    # each pick is the farthest from all the picks so far, not from the last one alone: after 0 and
    # 10, 5 (5 from both) and not 2.5 (7.5 from 10 but 2.5 from 0)
    line = np.array([[x, 0.0, 0.0] for x in (0.0, 10.0, 5.0, 9.6, 2.5)])
    assert [p[0] for p in SP._farthest(line, 4, lambda p: True)] == [0.0, 10.0, 5.0, 2.5]
    # at most 200 candidates are tried: the 200th is, the 201st is not
    calls = []
    many = np.column_stack([np.arange(300.0), np.zeros(300), np.zeros(300)])
    assert len(SP._farthest(many, 2, lambda p: calls.append(1) or len(calls) >= 200)) == 1 and len(calls) == 200


def test_a_pin_hole_inside_the_wall_or_not():
    tube = _tube()
    n = np.array([0.0, 1.0, 0.0])
    assert SP._inside(tube, np.array([42.5, 0.0, 15.0]), n, 1.5, 6.0)
    assert not SP._inside(tube, np.array([36.0, 0.0, 15.0]), n, 1.5, 6.0)  # breaks into the bore
    assert not SP._inside(tube, np.array([42.5, 0.0, 3.0]), np.array([0.0, 0.0, 1.0]), 1.0, 3.0)  # out the bottom
    cyl = SP._cylinder(np.array([1.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0]), 2.0, 5.0)
    assert _bbox(cyl) == pytest.approx((-4.0, 0.0, 1.0, 6.0, 4.0, 5.0), abs=1e-9)
    assert cyl.volume() == pytest.approx(_polygon_area(2.0, 24) * 10.0, rel=1e-9)


class Bore:
    """A cylindrical mirror on the inside of the tube: signed distance r_mirror - r (negative behind
    it, in the wall), exact."""

    def __init__(self, r=35.0):
        self.r = r

    def signed_distance(self, p):
        return self.r - np.hypot(p[:, 0], p[:, 1])


PIN = AlignmentPin(2.0, 0.2, 5.0)  # a hole of 2.2 mm, 5 mm into each piece


def test_a_pin_keeps_its_hole_behind_the_mirror():
    n = np.array([0.0, 1.0, 0.0])
    r = PIN.hole_radius
    # the hole's surface reaches r = x - 1.1 mm across; 1 mm clearance: x > 35 + 1 + 1.1 (and a little)
    x = np.array([[37.2, 0, 15.0], [37.0, 0, 15.0], [45.0, 0, 15.0]])
    assert SP._mirror_clear(x, n, PIN, Bore()).tolist() == [True, False, True]
    # the hole runs +-5 mm along its axis, no further: a plane mirror at y = 7.5 is 2.5 mm from its end
    plane = SimpleNamespace(signed_distance=lambda p: p[:, 1] - 7.5)
    assert SP._mirror_clear(np.array([[0.0, 0.0, 0.0], [0.0, 1.6, 0.0]]), n, PIN, plane).tolist() == [True, False]
    assert r == pytest.approx(1.1)
    region = SP._mirror_region(Bore(), np.array([0.0, 10.0]), 1.0, 60.0)
    # all of the plane (a 4e4 mm square) but a disc of 35 + 1 mm (and the 0.02 mm sampling) about the axis
    hole = math.sqrt(((4 * SP._BIG) ** 2 - region.area()) / math.pi)
    assert 36.0 < hole < 36.06
    no = SP._mirror_region(SimpleNamespace(signed_distance=lambda p: np.ones(len(p))), np.array([0.0]), 1.0, 60.0)
    assert no.is_empty()
    # the hole's circle sampled at 12 azimuths: a plane mirror in any direction across the axis is
    # seen to within 15 degrees (r cos 15 deg of the hole's radius toward it), never less
    e1, e2 = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])  # the plane frame of a y axis
    for clearance in (SP.MIRROR_CLEARANCE + r * math.cos(math.pi / 12) - 2e-3, SP.MIRROR_CLEARANCE + r + 2e-3):
        seen = []
        for phi in np.radians(np.arange(360.0)):
            u = math.cos(phi) * e1 + math.sin(phi) * e2
            plane = SimpleNamespace(signed_distance=lambda p, u=u, d=clearance: p @ u - d)
            seen.append(SP._mirror_clear(np.zeros((1, 3)), n, PIN, plane)[0])
        assert seen == [clearance > SP.MIRROR_CLEARANCE + r] * 360, clearance
    ring = SP._mirror_region(SimpleNamespace(signed_distance=lambda p: np.abs(np.hypot(p[:, 0], p[:, 1]) - 20.0) - 5),
                             np.array([0.0]), 1.0, 60.0)
    assert ring.area() == pytest.approx(math.pi * (23.97 ** 2 - 16.03 ** 2), rel=5e-3)  # 16 < r < 24, 1 mm in


def test_pins_on_the_quarter_planes_of_a_tube_keep_their_walls_and_the_mirror_clear():
    tube = _tube(h=40.0)
    plan = SP.SplitPlan(4, 1, 0.0, (0.0, 40.0))
    pins = SP.place_pins(tube, plan, PIN, Bore())
    faces = sorted({p.face for p in pins})
    assert faces == sorted(f"sector plane {a:.1f} deg, band 1" for a in (0.0, 90.0, 180.0, 270.0))
    for p in pins:
        c, ax = np.array(p.centre), np.array(p.axis)
        r = math.hypot(c[0], c[1])
        # in the wall, 1 mm + the hole's radius from the bore (the mirror) and the wall's 0.6 mm inside
        assert 35.0 + 1.0 + PIN.hole_radius <= r <= 50.0 - PIN.hole_radius - SP.MIN_WALL + 0.05
        assert PIN.hole_radius + SP.MIN_WALL - 0.05 <= c[2] <= 40.0 - PIN.hole_radius - SP.MIN_WALL + 0.05
        assert abs(c @ ax) < 1e-9 and abs(np.linalg.norm(ax) - 1) < 1e-12 and abs(ax[2]) < 1e-12
        assert SP._inside(tube, c, ax, PIN.hole_radius + SP.MIN_WALL, PIN.depth)
    per_face = {f: [p for p in pins if p.face == f] for f in faces}
    # a face 40 mm tall and 15 mm wide: 2 pins (one per 60 mm, at least two), far apart
    assert all(len(v) == 2 for v in per_face.values())
    for v in per_face.values():
        assert np.linalg.norm(np.subtract(v[0].centre, v[1].centre)) > 25.0
    with pytest.raises(FabricationError, match=r"sector plane 0\.0 deg, band 1: no room for two 2 mm pins at 1 mm "
                                               r"from the mirror and 0\.6 mm walls"):
        SP.place_pins(tube, plan, PIN, Bore(47.0))
    with pytest.raises(FabricationError, match=r"the cut face is too thin for 2 mm pins \(needs 3\.40 mm"):
        SP.place_pins(_tube(r_out=38.0, r_in=35.0), plan, PIN, None)


def test_a_grid_split_of_a_plate_with_pins_reassembles():
    plate = m3d.Manifold.cube((120.0, 40.0, 12.0)).translate((100.0, 0.0, 0.0))
    plan = SP.GridPlan((160.0,), ())
    pieces, pins, drilled = SP.split_part(plate, "plate", plan, PIN, None)
    assert [p.name for p in pieces] == ["plate_x1of2", "plate_x2of2"]
    assert [(p.sector, p.band, p.sector_range) for p in pieces] == [(0, 0, None), (1, 0, None)]
    assert len(pins) == 2 and all(p.face == "x cut 160.0 mm, y slab 1, z slab 1" for p in pins)
    assert all(p.axis == (1.0, 0.0, 0.0) and p.centre[0] == pytest.approx(160.0) for p in pins)
    hole = SP._cylinder(np.array([1.0, 0, 0]), np.zeros(3), PIN.hole_radius, PIN.depth).volume()
    assert drilled.volume() == pytest.approx(120 * 40 * 12 - 2 * hole, rel=1e-9)
    assert sum(p.manifold.volume() for p in pieces) == pytest.approx(drilled.volume(), rel=1e-9)
    whole = SP.split_part(plate, "plate", SP.GridPlan((), ()), PIN, None)
    assert whole[0][0].name == "plate" and whole[1] == [] and whole[2] is plate
    assert (whole[0][0].sector, whole[0][0].band, whole[0][0].sector_range) == (0, 0, None)
    assert len(whole[0]) == 1 and whole[0][0].manifold is plate


def test_a_grid_in_x_and_y_names_its_pieces_and_keeps_pins_behind_the_mirror():
    plate = m3d.Manifold.cube((120.0, 40.0, 12.0)).translate((100.0, 0.0, 0.0))
    plan = SP.GridPlan((160.0,), (20.0,))
    wall = SimpleNamespace(signed_distance=lambda p: p[:, 0] - 200.0)  # a mirror at x = 200, behind it x < 200
    pieces, pins, drilled = SP.split_part(plate, "plate", plan, PIN, wall)
    assert [p.name for p in pieces] == ["plate_x1of2_y1of2", "plate_x2of2_y1of2", "plate_x1of2_y2of2",
                                        "plate_x2of2_y2of2"]
    assert [(p.sector, p.band) for p in pieces] == [(0, 0), (1, 0), (0, 1), (1, 1)]
    assert pins
    for p in pins:
        assert SP._mirror_clear(np.array([p.centre]), np.array(p.axis), PIN, wall).tolist() == [True]
        assert p.centre[0] + PIN.hole_radius < 200.0 - SP.MIRROR_CLEARANCE
    assert sum(p.manifold.volume() for p in pieces) == pytest.approx(drilled.volume(), rel=1e-9)


def test_a_tube_in_quarters_and_two_bands_with_a_tongue_and_groove():
    tube = _tube(h=40.0)
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 20.0, 40.0))
    tongues = []
    pieces, pins, drilled = SP.split_part(tube, "ring", plan, PIN, Bore(), tongues)
    assert [p.name for p in pieces] == [f"ring_s{i}of4_b{j}of2" for j in (1, 2) for i in (1, 2, 3, 4)]
    assert [(p.sector, p.band) for p in pieces] == [(i, j) for j in (0, 1) for i in range(4)]
    assert pieces[1].sector_range == pytest.approx((math.pi / 2, math.pi))
    (t,) = tongues
    assert (t.z, t.depth, t.face) == (20.0, PIN.depth, "band cut z 20.0 mm")
    # the groove keeps 1 mm behind the bore: its nearest point 1 + (a little) from r = 35
    assert SP.MIRROR_CLEARANCE <= t.min_clearance_to_mirror < SP.MIRROR_CLEARANCE + 0.1
    d = t.describe()
    assert d["groove_volume_mm3"] > d["tongue_volume_mm3"] > 0 and d["z_mm"] == 20.0 and d["depth_mm"] == 5.0
    assert d["face"] == "band cut z 20.0 mm" and d["min_clearance_to_mirror_mm"] == t.min_clearance_to_mirror
    assert set(d) == {"face", "z_mm", "depth_mm", "groove_volume_mm3", "tongue_volume_mm3", "min_clearance_to_mirror_mm"}
    # the band cut carries the tongue, not pins: every pin is on a sector plane
    assert pins and all(p.face.startswith("sector plane") for p in pins)
    for p in pins:  # every hole behind the bore
        assert SP._mirror_clear(np.array([p.centre]), np.array(p.axis), PIN, Bore()).tolist() == [True]
    assert {p.face for p in pins} == {f"sector plane {a:.1f} deg, band {j}" for a in (0, 90, 180, 270) for j in (1, 2)}
    # the pieces reassemble to the drilled part (the tongue moves from the lower to the upper piece)
    assert sum(p.manifold.volume() for p in pieces) == pytest.approx(drilled.volume(), rel=1e-6)
    lower = sum(p.manifold.volume() for p in pieces[:4])
    upper = sum(p.manifold.volume() for p in pieces[4:])
    ring = _polygon_area(50.0) - _polygon_area(35.0)
    assert lower < ring * 20 - t.groove.volume() * 0.99 and upper > ring * 20 - 0.5 * t.groove.volume()
    assert SP.make_tongues(tube, SP.SplitPlan(4, 1, 0.0, (0.0, 40.0)), PIN, None) == []
    assert SP.make_tongues(tube, SP.GridPlan((1.0,), ()), PIN, None) == []
    with pytest.raises(FabricationError, match=r"^band cut z 20\.0 mm: no tongue and groove fits \(no room for a "
                                               r"groove 2 mm deep\)$"):
        SP.make_tongues(_tube(r_out=36.3, h=40.0), plan, PIN, None)  # 1.3 mm: 0.6 mm walls leave 0.1, the tongue none
    # a mirror that is not round about the axis (a plane at y = 44, in front of the wall's outer 6 mm)
    # is not in the clear region (annuli about the axis): the groove is measured against it and refused
    wall = SimpleNamespace(signed_distance=lambda p: p[:, 1] - 44.0)
    with pytest.raises(FabricationError, match=r"^band cut z 20\.0 mm: no tongue and groove fits \(the groove comes "
                                               r"-5\.40 mm from the mirror\)$"):
        SP.make_tongues(tube, plan, PIN, wall)


def test_a_tongue_too_small_for_its_sectors_is_refused_naming_its_area():
    # a 2.5 mm wall: a tongue 1.1 mm wide on a 36.25 mm radius, 2 pi 36.25 x 1.1 / 64 = 3.9 mm^2 a sector
    tube = _tube(r_out=37.5, h=40.0)
    plan = SP.SplitPlan(64, 2, 0.0, (0.0, 20.0, 40.0))
    with pytest.raises(FabricationError, match=r"^band cut z 20\.0 mm: no tongue and groove fits \(a sector gets a "
                                               r"tongue of only 3\.[89] mm\^2 at 2 mm depth\)$"):
        SP.make_tongues(tube, plan, PIN, None)
    (t,) = SP.make_tongues(tube, SP.SplitPlan(16, 2, 0.0, (0.0, 20.0, 40.0)), PIN, None)  # 15.6 mm^2: kept
    assert t.depth == PIN.depth and t.min_clearance_to_mirror is None


def test_plan_grid_cuts_a_tall_part_across_its_height():
    column = m3d.Manifold.cube((50.0, 50.0, 300.0))
    zs = []

    def fits(c, plan, i, j):
        bb = _bbox(c)
        zs.append((round(bb[2], 6), round(bb[5], 6)))
        return bb[5] - bb[2] <= 110.0

    plan = SP.plan_grid(column, fits)
    assert (plan.x_cuts, plan.y_cuts) == ((), ()) and plan.z_cuts == pytest.approx((100.0, 200.0))
    assert zs[-3:] == [(0.0, 100.0), (100.0, 200.0), (200.0, 300.0)]  # each stacked slab tried


def _polygon_areas(r_in, r_out=None, n=720):
    """The region's closed form: a 4e4 mm square (or an inscribed n-gon of circumradius r_out) less a
    circumscribed n-gon about the circle r_in (area n tan(pi/n) r^2)."""
    outer = (4 * SP._BIG) ** 2 if r_out is None else 0.5 * n * r_out ** 2 * math.sin(2 * math.pi / n)
    return outer - (n * math.tan(math.pi / n) * r_in ** 2 if r_in > 0 else 0.0)


def test_the_mirror_region_is_its_sampled_annuli_as_polygons():
    r = np.arange(0.0, 60.0, 0.02)
    # behind a cone mirror r = 35 + z / 2 at every height asked: from its widest (z = 10, r = 40) + 1 mm
    cone = SimpleNamespace(signed_distance=lambda p: 35.0 + 0.5 * p[:, 2] - np.hypot(p[:, 0], p[:, 1]))
    k = int(np.argmax(40.0 - r < -1.02))
    region = SP._mirror_region(cone, np.array([10.0, 0.0]), 1.0, 60.0)
    assert region.area() == pytest.approx(_polygon_areas(r[k]), abs=1e-3)
    # a ring behind a mirror 16 .. 24 mm from the axis: the inscribed outer polygon, the circumscribed hole
    ring = SimpleNamespace(signed_distance=lambda p: np.abs(np.hypot(p[:, 0], p[:, 1]) - 20.0) - 5.0)
    ok = np.abs(r - 20.0) - 5.0 < -1.02
    idx = np.flatnonzero(ok)
    got = SP._mirror_region(ring, np.array([0.0]), 1.0, 60.0).area()
    assert got == pytest.approx(_polygon_areas(r[idx[0]], r[idx[-1]]), rel=1e-9)
    # a run starting under 1 mm from the axis (0.54 mm) still has its hole
    small = SimpleNamespace(signed_distance=lambda p: np.abs(np.hypot(p[:, 0], p[:, 1]) - 5.0) - 5.5)
    idx = np.flatnonzero(np.abs(r - 5.0) - 5.5 < -1.02)
    assert 0.0 < r[idx[0]] < 1.0
    got = SP._mirror_region(small, np.array([0.0]), 1.0, 60.0).area()
    assert got == pytest.approx(_polygon_areas(r[idx[0]], r[idx[-1]]), rel=1e-9)
    # nothing near: the whole plane, no hole at the axis
    far = SimpleNamespace(signed_distance=lambda p: np.full(len(p), -100.0))
    assert SP._mirror_region(far, np.array([0.0]), 1.0, 60.0).area() == pytest.approx((4 * SP._BIG) ** 2, abs=1e-3)


def test_a_tube_in_two_halves_or_three_bands_names_its_pieces():
    tube = _tube(h=40.0)
    pieces, pins, drilled = SP.split_part(tube, "ring", SP.SplitPlan(2, 1, 0.0, (0.0, 40.0)), PIN, Bore())
    assert [p.name for p in pieces] == ["ring_s1of2", "ring_s2of2"]
    assert [p.sector_range for p in pieces] == [pytest.approx((0.0, math.pi)), pytest.approx((math.pi, 2 * math.pi))]
    # three bands, one sector: two tongues, each carried by the piece above its cut; no pins
    tall = _tube(h=60.0)
    tongues = []
    pieces, pins, drilled = SP.split_part(tall, "ring", SP.SplitPlan(1, 3, 0.0, (0.0, 20.0, 40.0, 60.0)), PIN,
                                          Bore(), tongues)
    assert [p.name for p in pieces] == ["ring_b1of3", "ring_b2of3", "ring_b3of3"] and pins == []
    assert [(p.sector, p.band, p.sector_range) for p in pieces] == [(0, j, None) for j in range(3)]
    assert len(tongues) == 2
    vols = [p.manifold.volume() for p in pieces]
    assert sum(vols) == pytest.approx(drilled.volume(), rel=1e-6)
    ring = _polygon_area(50.0) - _polygon_area(35.0)
    for j in (1, 2):  # the band above a cut holds its tongue: more than its slab less the groove above
        assert vols[j] > ring * 20 - (tongues[j].groove.volume() if j < 2 else 0.0) - 1e-3 + \
            0.9 * tongues[j - 1].tongue.volume()


def test_band_0_holds_all_under_the_first_cut_even_past_its_start():
    # band 0 is everything under the first cut (cell trims no floor): a plan whose band_z[0] (16 mm) lies
    # above the part's bottom and inside the tongue's depth (15.2 .. 20 mm) still reassembles, the
    # tongue whole in band 1's piece
    tube = _tube(h=40.0)
    tongues = []
    pieces, pins, drilled = SP.split_part(tube, "ring", SP.SplitPlan(1, 2, 0.0, (16.0, 20.0, 40.0)), PIN, None,
                                          tongues)
    (t,) = tongues
    ring = _polygon_area(50.0) - _polygon_area(35.0)
    assert pieces[0].manifold.volume() == pytest.approx(ring * 20 - t.groove.volume(), rel=1e-6)
    assert pieces[1].manifold.volume() == pytest.approx(ring * 20 + t.tongue.volume(), rel=1e-6)
    assert sum(p.manifold.volume() for p in pieces) == pytest.approx(drilled.volume(), rel=1e-6)


def test_pins_keep_off_the_band_cuts_by_their_guard_and_the_tongue_faces_by_the_normal():
    tube = _tube(h=40.0)
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 20.0, 40.0))
    guard = PIN.hole_radius + SP.MIN_WALL
    # no tongues: pins on the band cut too, and the sector planes' pins come to the guard under the cut
    # (the eroded face sampled every 0.5 mm), no nearer
    pins = SP.place_pins(tube, plan, PIN, None)
    assert any(p.face.startswith("band cut") for p in pins)
    low = [p.centre[2] for p in pins if p.face.endswith("band 1")]
    assert max(low) <= 20.0 - guard + 1e-9 and max(low) > 20.0 - guard - 0.6
    # tongues on a band cut at z = 0 (the part from -20 to 20 mm): no pins on it, told by its normal
    shifted = _tube(h=40.0, z0=-20.0)
    low_plan = SP.SplitPlan(4, 2, 0.0, (-20.0, 0.0, 20.0))
    tg = SP.make_tongues(shifted, low_plan, PIN, None)
    assert all(p.face.startswith("sector plane") for p in SP.place_pins(shifted, low_plan, PIN, None, tg))


def _cone_shell(segments=360):
    # a wall leaning in by 1 in 4: outer radius 50 - z/4, inner 44 - z/4 (6 mm across), 40 mm tall
    outer = m3d.Manifold.cylinder(40.0, 50.0, 40.0, segments)
    inner = m3d.Manifold.cylinder(42.0, 44.25, 33.75, segments).translate((0, 0, -1))
    return outer - inner


def _radii(man):
    v = np.asarray(man.to_mesh().vert_properties)[:, :3]
    r = np.hypot(v[:, 0], v[:, 1])
    return r.min(), r.max(), v[:, 2].min(), v[:, 2].max()


def test_a_groove_in_a_leaning_wall_is_the_wall_common_to_its_depth_and_keeps_off_a_leaning_mirror():
    cone, plan = _cone_shell(), SP.SplitPlan(4, 2, 0.0, (0.0, 20.0, 40.0))
    # no mirror: the groove (5 mm, the pin's depth, under z = 20) is what every height from 20 down
    # to 20 - 5 - 0.6 has in common, eroded by the 0.6 mm wall: the inner surface's widest (z = 14.4:
    # 40.4 mm) + 0.6, to the outer's narrowest (z = 20: 45 mm) - 0.6 (the 360-gon's vertices)
    (t,) = SP.make_tongues(cone, plan, PIN, None)
    r_in, r_out, z_lo, z_hi = _radii(t.groove)
    assert t.depth == PIN.depth and (z_lo, z_hi) == pytest.approx((15.0, 20.0), abs=1e-9)
    assert 40.4 * math.cos(math.pi / 360) + SP.MIN_WALL - 1e-6 <= r_in <= 40.4 + SP.MIN_WALL
    assert r_out == pytest.approx((45.0 * math.cos(math.pi / 360) - SP.MIN_WALL) / math.cos(math.pi / 360), abs=1e-3)
    # the tongue is the groove less half the pin's clearance on each side
    assert _radii(t.tongue)[:2] == pytest.approx((r_in + PIN.clearance / 2, r_out - PIN.clearance / 2), abs=2e-3)
    # the cone as the mirror (exact distance, its normal 1 in 4 off the horizontal): 1 mm behind it
    # over the groove's depth is r > 44 - 15/4 + 1.02 / cos (0.02 mm the region's sampling), on the
    # region's 0.02 mm grid; the groove's nearest point to the mirror then 1.04 mm from it
    cos = 1 / math.hypot(1.0, 0.25)
    lean = SimpleNamespace(signed_distance=lambda p: (44.0 - p[:, 2] / 4 - np.hypot(p[:, 0], p[:, 1])) * cos)
    (m,) = SP.make_tongues(cone, plan, PIN, lean)
    r_in, r_out, _, _ = _radii(m.groove)
    assert m.depth == PIN.depth and r_out == pytest.approx(_radii(t.groove)[1], abs=1e-9)
    assert 40.25 + 1.02 / cos <= r_in <= 40.25 + 1.02 / cos + 0.021
    assert m.min_clearance_to_mirror == pytest.approx((r_in - 40.25) * cos, abs=1e-3)


def test_a_wide_wall_gets_a_groove_along_each_face_at_most_3_mm_wide():
    # the tube's 15 mm wall: the region 35.6-49.4 mm, the groove the 3 mm next to each of its edges
    (t,) = SP.make_tongues(_tube(h=40.0), SP.SplitPlan(4, 2, 0.0, (0.0, 20.0, 40.0)), PIN, None)
    rings = math.pi * (49.4 ** 2 - 46.4 ** 2 + 38.6 ** 2 - 35.6 ** 2)  # as circles: the 96-gon 0.02 % less
    assert t.groove.volume() == pytest.approx(PIN.depth * rings, rel=1e-3)


def test_pins_of_a_band_too_thin_for_them_are_refused_on_its_lower_cut():
    # bands 4 mm apart: a 5 mm pin on the lower cut (z = 20) comes out through the upper one; the lower
    # cut is refused, before the upper cut's pins (whose lower ends cross z = 20) are tried
    with pytest.raises(FabricationError, match=r"^band cut z 20\.0 mm, sector 1: no room for two 2 mm pins"):
        SP.place_pins(_tube(h=40.0), SP.SplitPlan(1, 3, 0.0, (0.0, 20.0, 24.0, 40.0)), PIN, None)


def test_a_face_gets_a_pin_per_60_mm_from_two_to_six():
    # faces 12 mm tall across a plate, less the 1.7 mm guard at each end: 296.6 mm -> 5, 416.6 -> 7 capped at 6
    for length, count in ((300.0, 5), (420.0, 6), (100.0, 2)):
        plate = m3d.Manifold.cube((40.0, length, 12.0))
        assert len(SP.place_pins(plate, SP.GridPlan((20.0,), ()), PIN, None)) == count, length


def test_a_cut_too_near_the_end_has_no_hole_with_its_wall():
    # a cut 3 mm from the plate's end: a hole 5 mm deep each way leaves the part whatever its place
    plate = m3d.Manifold.cube((120.0, 40.0, 12.0)).translate((100.0, 0.0, 0.0))
    with pytest.raises(FabricationError, match=r"^x cut 103\.0 mm, y slab 1, z slab 1: fewer than two pin positions "
                                               r"keep 0\.6 mm of wall around the hole"):
        SP.place_pins(plate, SP.GridPlan((103.0,), ()), PIN, None)


def _slotted_tube(z0, z1):
    # the 15 mm tube with a slot 1 mm deep into its outer face between z0 and z1
    ring = m3d.Manifold.cylinder(z1 - z0, 51.0, 51.0, SEG) - m3d.Manifold.cylinder(z1 - z0, 49.0, 49.0, SEG)
    return _tube(h=40.0) - ring.translate((0.0, 0.0, z0))


def test_a_slot_between_the_sampled_heights_is_caught_by_the_grooves_wall():
    # the groove's region is the part's slices at 9 heights; a 0.2 mm slot between them is not seen
    # there, but the groove widened by its wall would open into it. Between every depth's heights
    # (17.45-17.65 mm): no depth is kept, and the reason is the last one's wall
    plan = SP.SplitPlan(4, 2, 0.0, (0.0, 20.0, 40.0))
    with pytest.raises(FabricationError, match=r"^band cut z 20\.0 mm: no tongue and groove fits \(the groove 2 mm "
                                               r"deep leaves less than 0\.6 mm of wall\)$"):
        SP.make_tongues(_slotted_tube(17.45, 17.65), plan, PIN, None)
    # 19.35-19.55 mm, within the top 1.2 mm under the cut: between the 5 mm groove's heights (19.3, 20)
    # so refused by its wall, and seen by the 4 mm groove's (19.425), whose region keeps off it
    (t,) = SP.make_tongues(_slotted_tube(19.35, 19.55), plan, PIN, None)
    assert t.depth == 4.0
