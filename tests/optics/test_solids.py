"""Rays and segments against the convex stand-in solids (rigcad.optics.solids): entry and exit
distances written out by hand for rays along and across the axes, and a brute-force membership test
(points along each ray, inside the box or cylinder or not) for random rays, with margins."""

from __future__ import annotations

import math

import numpy as np

from rigcad.optics.solids import segments_hit_box, segments_hit_cylinder, slab, z_cylinder

LO, HI = np.array([-1.0, 2.0, 10.0]), np.array([3.0, 5.0, 12.0])


def _rays(*pairs):
    o = np.array([p[0] for p in pairs], float)
    d = np.array([p[1] for p in pairs], float)
    return o, d


def test_slab_distances_of_rays_along_and_across_the_axes():
    o, d = _rays(((-11.0, 3.0, 11.0), (1.0, 0.0, 0.0)),      # along +x through the box: x from -1 to 3
                 ((1.0, 3.0, 20.0), (0.0, 0.0, -2.0)),       # down -z, speed 2: z 12 at t 4, z 10 at t 5
                 ((1.0, 3.0, 11.0), (0.0, 1.0, 0.0)),        # from inside, along +y: y 2 at t -1, 5 at t 2
                 ((-11.0, 3.0, 11.0), (4.0, 1.0, 0.0)))      # oblique: x enters at 2.5, y leaves at 2
    lo, hi = slab(o, d, LO, HI)
    assert np.array_equal(lo, [10.0, 4.0, -1.0, 2.5])
    assert np.array_equal(hi, [14.0, 5.0, 2.0, 2.0])
    assert lo[3] > hi[3]  # the oblique ray misses: y leaves before x enters


def test_slab_with_a_zero_direction_component_inside_or_outside_its_slab():
    o, d = _rays(((-5.0, 3.0, 11.0), (1.0, 0.0, 0.0)),   # y and z in their slabs, never leave them
                 ((-5.0, 6.0, 11.0), (1.0, 0.0, 0.0)),   # y above the box: never in
                 ((-5.0, 1.0, 11.0), (1.0, 0.0, 0.0)),   # y below the box: never in
                 ((-5.0, 2.0, 12.0), (1.0, 0.0, 0.0)))   # on the faces y = lo, z = hi: in (closed box)
    with np.errstate(all="raise"):  # x / 0 and, on the faces, 0 / 0 are decided without a warning
        lo, hi = slab(o, d, LO, HI)
    assert np.array_equal(lo, [4.0, math.inf, math.inf, 4.0])
    assert np.array_equal(hi, [8.0, -math.inf, -math.inf, 8.0])
    # a ray that does not move at all: everywhere or nowhere; no floating-point warning for the
    # zero components (0 / 0 and x / 0 are decided without dividing)
    with np.errstate(all="raise"):
        lo, hi = slab(np.array([[0.0, 3.0, 11.0], [0.0, 3.0, 13.0]]), np.zeros((2, 3)), LO, HI)
    assert np.array_equal(lo, [-math.inf, math.inf]) and np.array_equal(hi, [math.inf, -math.inf])


def _inside_box(p, lo, hi, margin):
    return np.all((p >= lo + margin) & (p <= hi - margin), axis=-1)


def _outside_box(p, lo, hi, margin):
    return np.any((p < lo - margin) | (p > hi + margin), axis=-1)


def test_slab_against_points_along_random_rays():
    rng = np.random.default_rng(7)
    n = 400
    o = rng.uniform(-8, 12, (n, 3)) + [0, 0, 5]
    d = rng.normal(size=(n, 3))
    t_lo, t_hi = slab(o, d, LO, HI)
    hit = t_lo < t_hi
    assert 20 < hit.sum() < n - 20  # both kinds present
    eps = 1e-6
    for i in np.nonzero(hit)[0]:  # inside strictly between entry and exit, outside before and after
        ts = np.linspace(t_lo[i], t_hi[i], 9)[1:-1]
        assert _inside_box(o[i] + ts[:, None] * d[i], LO, HI, -1e-9).all()
        span = t_hi[i] - t_lo[i]
        if span > 1e-3:
            assert _outside_box(o[i] + (t_lo[i] - 1e-3 * span) * d[i], LO, HI, 0.0)
            assert _outside_box(o[i] + (t_hi[i] + 1e-3 * span) * d[i], LO, HI, 0.0)
    for i in np.nonzero(~hit)[0]:  # a miss: no point of the line is inside
        ts = np.linspace(-50, 50, 20001)
        assert not _inside_box(o[i] + ts[:, None] * d[i], LO, HI, eps).any()


def test_segments_through_a_box_but_not_touching_it_at_an_end():
    a = np.array([[-5.0, 3.0, 11.0], [-5.0, 3.0, 11.0], [-5.0, 3.0, 11.0], [3.0, 3.0, 11.0],
                  [-5.0, 3.0, 11.0], [0.0, 3.0, 11.0], [-5.0, 6.0, 11.0]])
    b = np.array([[8.0, 3.0, 11.0],    # through
                  [-1.0, 3.0, 11.0],   # ends on the face x = -1: touching does not count
                  [-1.0 + 1e-6, 3.0, 11.0],  # ends 1e-6 mm inside (2.5e-7 of its length)
                  [8.0, 3.0, 11.0],    # starts on the face x = 3 going out
                  [-2.0, 3.0, 11.0],   # stops short
                  [1.0, 3.0, 11.0],    # wholly inside
                  [8.0, 6.0, 11.0]])   # above it
    assert segments_hit_box(a, b, LO, HI).tolist() == [True, False, True, False, False, True, False]
    # the end-point allowance is 1e-9 of the length, not more
    a2 = np.array([[-5.0, 3.0, 11.0], [3.0 - 4e-8, 3.0, 11.0], [3.0 - 4e-10, 3.0, 11.0]])
    b2 = np.array([[-1.0 + 4e-8, 3.0, 11.0], [8.0, 3.0, 11.0], [8.0, 3.0, 11.0]])
    assert segments_hit_box(a2, b2, LO, HI).tolist() == [True, True, False]
    a3 = np.array([[-5.0, 3.0, 11.0]])
    assert segments_hit_box(a3, np.array([[-1.0 + 4e-10 * 4, 3.0, 11.0]]), LO, HI).tolist() == [False]


R, Z0, Z1, C = 2.0, 1.0, 4.0, (3.0, -1.0)


def test_cylinder_distances_of_rays_across_and_along_the_axis():
    o, d = _rays(((-7.0, 0.0, 2.0), (1.0, 0.0, 0.0)),          # across at y = 1 from the axis: x = 3 -+ sqrt(3)
                 ((3.0, -1.0, 10.0), (0.0, 0.0, -2.0)),        # down the axis: z 4 at t 3, z 1 at t 4.5
                 ((4.0, -1.0, 2.0), (0.0, 0.0, 1.0)),          # up, inside: z 1 at t -1, z 4 at t 2
                 ((-7.0, -1.0, 2.0), (2.0, 0.0, 0.0)))         # across through the axis, speed 2
    lo, hi = z_cylinder(o, d, R, Z0, Z1, C)
    s3 = math.sqrt(3.0)
    assert np.max(np.abs(lo - [10.0 - s3, 3.0, -1.0, 4.0])) < 1e-13 * 10
    assert np.max(np.abs(hi - [10.0 + s3, 4.5, 2.0, 6.0])) < 1e-13 * 10


def test_cylinder_misses_beside_above_and_parallel():
    o, d = _rays(((-7.0, 1.5, 2.0), (1.0, 0.0, 0.0)),   # passes 2.5 from the axis: disc < 0
                 ((-7.0, -1.0, 5.0), (1.0, 0.0, 0.0)),  # above z1, horizontal: never in z
                 ((-7.0, -1.0, 0.5), (1.0, 0.0, 0.0)),  # below z0
                 ((5.5, -1.0, 9.0), (0.0, 0.0, -1.0)),  # vertical outside the radius
                 ((-7.0, -1.0, 8.0), (1.0, 0.0, -1.0)))  # in z for t 4..7, in the radius for t 8..12
    lo, hi = z_cylinder(o, d, R, Z0, Z1, C)
    assert np.all(~(lo <= hi))
    assert lo[1] == math.inf and hi[1] == -math.inf
    assert lo[2] == math.inf and hi[2] == -math.inf
    assert lo[3] == math.inf and hi[3] == -math.inf
    assert lo[0] == math.inf and hi[0] == -math.inf


def test_cylinder_rays_parallel_to_the_axis_inside_and_on_the_wall_or_level_inside_the_slab():
    o, d = _rays(((3.0, -1.0, 9.0), (0.0, 0.0, -1.0)),   # the axis itself
                 ((5.0, -1.0, 9.0), (0.0, 0.0, -1.0)),   # on the wall (closed): in
                 ((3.0, -1.0, 4.0), (1.0, 0.0, 0.0)),    # level at the top face z = 4 (closed): in
                 ((3.0, -1.0, 1.0), (0.0, 1.0, 0.0)))    # level at the bottom face z = 1
    lo, hi = z_cylinder(o, d, R, Z0, Z1, C)
    assert np.array_equal(lo, [5.0, 5.0, -2.0, -2.0]) and np.array_equal(hi, [8.0, 8.0, 2.0, 2.0])


def test_cylinder_default_centre_is_the_axis():
    o, d = _rays(((-7.0, 0.0, 2.0), (1.0, 0.0, 0.0)))
    lo, hi = z_cylinder(o, d, R, Z0, Z1)
    assert np.array_equal(lo, [5.0]) and np.array_equal(hi, [9.0])
    lo, hi = z_cylinder(o, d, 3.0, Z0, Z1)  # radius 3: x from -3 to 3
    assert np.array_equal(lo, [4.0]) and np.array_equal(hi, [10.0])


def test_cylinder_vertical_rays_just_outside_the_radius_miss_without_a_warning():
    # 2.1 mm and 2.2 mm from the axis of a 2 mm cylinder: x^2 + y^2 - r^2 is 0.41 and 0.84 mm^2
    o, d = _rays(((3.0 + 2.1, -1.0, 9.0), (0.0, 0.0, -1.0)), ((3.0, -1.0 + 2.2, 9.0), (0.0, 0.0, 1.0)),
                 ((3.0, -1.0, 9.0), (1.0, 0.0, 0.0)))  # level, above the cylinder
    with np.errstate(all="raise"):  # the zero components are decided without dividing
        lo, hi = z_cylinder(o, d, R, Z0, Z1, C)
    assert np.array_equal(lo, [math.inf, math.inf, math.inf])
    assert np.array_equal(hi, [-math.inf, -math.inf, -math.inf])


def test_segments_grazing_an_edge_or_the_wall_count_as_hits():
    # the closed solids: a segment touching the box's edge x = -1, y = 2 (t = 0.5 exactly), or the
    # cylinder's wall tangentially (t = 0.625 exactly), enters and leaves at one t
    a, b = np.array([[-3.0, 4.0, 11.0]]), np.array([[1.0, 0.0, 11.0]])
    enter, leave = slab(a, b - a, LO, HI)
    assert enter[0] == leave[0] == 0.5
    assert segments_hit_box(a, b, LO, HI).tolist() == [True]
    a, b = np.array([[-7.0, 1.0, 2.0]]), np.array([[9.0, 1.0, 2.0]])
    enter, leave = z_cylinder(a, b - a, R, Z0, Z1, C)
    assert enter[0] == leave[0] == 0.625
    assert segments_hit_cylinder(a, b, R, Z0, Z1, C).tolist() == [True]


def _inside_cyl(p, margin):
    r = np.hypot(p[..., 0] - C[0], p[..., 1] - C[1])
    return (r <= R - margin) & (p[..., 2] >= Z0 + margin) & (p[..., 2] <= Z1 - margin)


def test_cylinder_against_points_along_random_rays():
    rng = np.random.default_rng(11)
    n = 400
    o = rng.uniform(-4, 8, (n, 3)) + [0, -1, 0]
    d = rng.normal(size=(n, 3))
    t_lo, t_hi = z_cylinder(o, d, R, Z0, Z1, C)
    hit = t_lo < t_hi
    assert 20 < hit.sum() < n - 20
    for i in np.nonzero(hit)[0]:
        ts = np.linspace(t_lo[i], t_hi[i], 9)[1:-1]
        assert _inside_cyl(o[i] + ts[:, None] * d[i], -1e-9).all()
        span = t_hi[i] - t_lo[i]
        if span > 1e-3:
            assert not _inside_cyl(o[i] + (t_lo[i] - 1e-3 * span) * d[i], 0.0)
            assert not _inside_cyl(o[i] + (t_hi[i] + 1e-3 * span) * d[i], 0.0)
    for i in np.nonzero(~hit)[0]:
        ts = np.linspace(-50, 50, 20001)
        assert not _inside_cyl(o[i] + ts[:, None] * d[i], 1e-6).any()


def test_segments_through_a_cylinder_but_not_touching_it_at_an_end():
    a = np.array([[-7.0, -1.0, 2.0], [-7.0, -1.0, 2.0], [-7.0, -1.0, 2.0], [5.0, -1.0, 2.0],
                  [3.0, -1.0, 2.0], [-7.0, 2.0, 2.0]])
    b = np.array([[9.0, -1.0, 2.0],   # through
                  [1.0, -1.0, 2.0],   # ends on the wall x = 1
                  [1.0 + 1e-6, -1.0, 2.0],  # ends just inside
                  [9.0, -1.0, 2.0],   # starts on the wall going out
                  [3.5, -1.0, 2.5],   # wholly inside
                  [9.0, 2.0, 2.0]])   # beside it
    assert segments_hit_cylinder(a, b, R, Z0, Z1, C).tolist() == [True, False, True, False, True, False]
    # the allowance is 1e-9 of the length (8 mm here): 4e-8 mm in counts, 4e-10 mm does not
    a2 = np.array([[-7.0, -1.0, 2.0], [5.0 - 4e-8, -1.0, 2.0], [5.0 - 4e-10, -1.0, 2.0]])
    b2 = np.array([[1.0 + 4e-8, -1.0, 2.0], [13.0, -1.0, 2.0], [13.0, -1.0, 2.0]])
    assert segments_hit_cylinder(a2, b2, R, Z0, Z1, C).tolist() == [True, True, False]
    assert segments_hit_cylinder(np.array([[-7.0, 0.0, 2.0]]), np.array([[9.0, 0.0, 2.0]]), R, Z0, Z1).tolist() == [True]
    assert segments_hit_cylinder(np.array([[-7.0, -1.0, 2.0]]), np.array([[1.0 + 3.2e-9, -1.0, 2.0]]), R, Z0, Z1,
                                 C).tolist() == [False]
