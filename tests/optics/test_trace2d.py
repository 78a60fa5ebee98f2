"""The integrated dome, traced as a geometric curve, returns every ray to the sample point."""

import numpy as np
import pytest

from rigcad.optics.dome import build_dome
from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.trace2d import OK, DomeCurve, cop_rays, trace


@pytest.fixture(scope="module")
def system(table31_geometry):
    g = table31_geometry
    dome = build_dome(g, "dop853", tolerance=1e-9, rows=2001)
    return g, Paraboloid(g.focal_length, g.vertex_z, g.rim_radius), dome


def test_table31_rays_converge_on_the_sample_point(system):
    g, para, dome = system
    curve = DomeCurve.from_profile(dome)
    rng = np.random.default_rng(7)
    # Random aim points: almost none coincide with a profile node, so the trace exercises the
    # curve between nodes (not the construction), on both halves of the section.
    x = rng.uniform(dome.occlusion_s, g.rim_radius, 3000) * rng.choice([-1.0, 1.0], 3000)
    origins, dirs = cop_rays(np.array([0.0, g.cop_z]), x, para)
    tr = trace(para, curve, origins, dirs)
    assert np.all(tr.status == OK), np.bincount(tr.status)
    worst = np.max(np.abs(tr.miss))
    assert worst < 1e-6, worst  # the bound: every ray within 1e-6 mm of O
    # Equal optical paths (Fermat) as an independent check of the same fact.
    assert np.ptp(tr.path_length) < 1e-5  # plane-landing path; spread bounded by miss x grazing slope


def test_euler_polyline_traced_as_flat_mirrors_converges_at_first_order(table31_geometry):
    g = table31_geometry
    para = Paraboloid(g.focal_length, g.vertex_z, g.rim_radius)
    misses = []
    for steps in (500, 1000, 2000):
        dome = build_dome(g, "euler", euler_steps=steps)
        x = np.linspace(dome.occlusion_s + 0.2, g.rim_radius - 0.2, 4001)
        tr = trace(para, DomeCurve.from_profile(dome), *cop_rays(np.array([0.0, g.cop_z]), x, para))
        misses.append(np.nanmax(np.abs(tr.miss)))
    ratios = [misses[i] / misses[i + 1] for i in range(2)]
    # halving the step halves the worst miss (first order); 1.6..2.4 allows for which facet is worst
    assert all(1.6 < r < 2.4 for r in ratios), (misses, ratios)


def test_a_ray_off_the_paraboloid_is_reported_missed(system):
    g, para, dome = system
    curve = DomeCurve.from_profile(dome)
    origins, dirs = cop_rays(np.array([0.0, g.cop_z]), np.array([g.rim_radius * 1.5, 0.3]), para)
    tr = trace(para, curve, origins, dirs)
    assert tr.status[0] != OK and np.isnan(tr.miss[0])
    # A ray near the vertex reflects back through the top opening: lost, not silently counted.
    assert tr.status[1] != OK


def _first_crossing_every_segment(P, o, d):
    """The polyline's first crossing along each ray, by solving o + t d = P_j + f (P_j+1 - P_j) on
    every segment: the reference the screened search must reproduce."""
    lam = np.full(len(o), np.nan)
    e = P[1:] - P[:-1]
    for k in range(len(o)):
        det = e[:, 0] * d[k, 1] - e[:, 1] * d[k, 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            f = ((o[k, 0] - P[:-1, 0]) * d[k, 1] - (o[k, 1] - P[:-1, 1]) * d[k, 0]) / det
            t = ((P[:-1, 0] - o[k, 0]) * e[:, 1] - (P[:-1, 1] - o[k, 1]) * e[:, 0]) / -det
        t = t[(f >= -1e-12) & (f <= 1 + 1e-12) & (t > 1e-9)]  # a node hit: f rounds to either side of it
        lam[k] = t.min() if t.size else np.nan
    return lam


def test_screened_crossing_search_finds_every_first_crossing(system):
    g, _, dome = system
    curve = DomeCurve.from_profile(dome)
    flat = DomeCurve("polyline", curve.s, curve.points, None)
    P = curve.points
    rng = np.random.default_rng(3)
    o = rng.uniform(-1, 1, (300, 2)) * np.abs(P).max()
    a = rng.uniform(0, 2 * np.pi, 300)
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    # and rays aimed exactly at nodes, where the crossing sits on the screen's rounding margin
    v = P[::40] - [0.0, g.cop_z / 3]
    o = np.vstack([o, np.tile([0.0, g.cop_z / 3], (len(v), 1))])
    d = np.vstack([d, v / np.linalg.norm(v, axis=1)[:, None]])
    # and rays aimed at the polyline's two end nodes (no segment beyond them), each direction turned
    # by 0-3 ulps either way: the crossing stays within the reference's f window, the end node's cross
    # product takes both signs, so a search that needs a strict sign change loses some on any CPU (on
    # some BLAS kernels it lost the unturned one too) -- from above, and from 1 um above O, an origin
    # far smaller than the nodes
    # (the screen's margin must scale with the nodes too, not only with the origin)
    for src in (np.array([0.0, g.cop_z / 3]), np.array([0.0, 1e-3])):
        for end in (P[0], P[-1]):
            u = (end - src) / np.linalg.norm(end - src)
            for k in range(-3, 4):
                turned = u.copy()
                for _ in range(abs(k)):
                    turned = np.nextafter(turned, turned + np.sign(k) * np.array([1.0, -1.0]))
                o = np.vstack([o, src])
                d = np.vstack([d, turned])
    ref = np.fmin(_first_crossing_every_segment(P, o, d), _first_crossing_every_segment(P * [-1, 1], o, d))  # both halves
    lam, _ = flat.intersect(o, d)
    hit = np.isfinite(ref)
    assert np.all(hit[-28:]), "the reference finds every end-aimed ray"
    assert 100 < hit.sum() < len(o) and np.array_equal(np.isfinite(lam), hit), np.nonzero(np.isfinite(lam) != hit)
    # 1e-9 mm: both sides solve the same 2x2 system in float64 at |P| ~ 300 mm (rounding ~1e-13 mm);
    # the bound is the self-hit threshold along the ray, far above rounding, far below a facet
    assert np.max(np.abs(lam[hit] - ref[hit])) < 1e-9


def _cross(a, b):
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def test_trace_fields_are_the_geometry_of_each_ray(system):
    """Each returning ray's recorded points and angle, checked by the geometry they must satisfy
    (not by the trace's own sums): the paraboloid point on the parabola z = z_v - x^2 / 4f and on
    the ray from the COP; the arrival angle that of the line from the dome point to O; the landing
    point where that line meets z = 0; the path COP -> P -> D -> O the same for every ray (Fermat).
    A ray off the paraboloid is reported as missing it, the first cause, with no figure."""
    from rigcad.optics.trace2d import MISSED_PARABOLOID

    g, para, dome = system
    curve = DomeCurve.from_profile(dome)
    rng = np.random.default_rng(5)
    x = rng.uniform(dome.occlusion_s, g.rim_radius, 400) * rng.choice([-1.0, 1.0], 400)
    cop = np.array([0.0, g.cop_z])
    origins, dirs = cop_rays(cop, np.append(x, g.rim_radius * 1.5), para)
    tr = trace(para, curve, origins, dirs)
    ok = tr.ok
    assert ok[:-1].all() and tr.status[-1] == MISSED_PARABOLOID
    P, D = tr.paraboloid_point[ok], tr.dome_point[ok]
    assert np.max(np.abs(P[:, 1] - (g.vertex_z - P[:, 0] ** 2 / (4 * g.focal_length)))) < 1e-9
    assert np.max(np.abs(_cross(P - cop, dirs[ok]))) < 1e-9  # on the ray (|P - COP| ~ 300 mm)
    # O is within |miss| < 1e-6 mm of the returning line, so the line's angle is that of D seen from O
    # to |miss| / |D| < 1e-8 rad, and it meets z = 0 at -miss / cos(theta) (|landing| ~ 1e-6 mm)
    assert np.max(np.abs(tr.theta[ok] - np.arctan2(D[:, 0], D[:, 1]))) < 1e-8
    assert np.max(np.abs(tr.landing_x[ok] + tr.miss[ok] / np.cos(tr.theta[ok]))) < 1e-9
    fermat = np.linalg.norm(P - cop, axis=1) + np.linalg.norm(D - P, axis=1) + np.linalg.norm(D, axis=1)
    assert np.ptp(fermat) < 1e-5  # the bound of test_table31_rays_converge_on_the_sample_point
    for field in (tr.paraboloid_point, tr.dome_point, tr.miss, tr.landing_x, tr.theta, tr.path_length):
        assert field.dtype == float and np.all(np.isnan(field[-1])), field[-1]


def test_a_shifted_dome_is_the_same_curve_moved_sideways(system):
    g, _, dome = system
    curve = DomeCurve.from_profile(dome)
    src = np.array([0.0, g.cop_z / 3])
    nodes = curve.points[::50]
    v = np.vstack([nodes, nodes * [-1.0, 1.0]]) - src  # dome nodes on both halves
    d = v / np.linalg.norm(v, axis=1)[:, None]
    o = np.tile(src, (len(d), 1))
    lam0, n0 = curve.intersect(o, d)
    moved = curve.shifted(1.5).shifted(-0.25)  # 1.25 mm to +x in all
    lam1, n1 = moved.intersect(o + [1.25, 0.0], d)
    hit = np.isfinite(lam0)
    assert hit.sum() > 10 and np.array_equal(np.isfinite(lam1), hit) and moved.kind == curve.kind
    # the same crossing, found in a frame moved by 1.25 mm: rounding of the shift at ~300 mm
    assert np.max(np.abs(lam1[hit] - lam0[hit])) < 1e-9 and np.max(np.abs(n1[hit] - n0[hit])) < 1e-9
    # built shifted from the profile: the same curve
    lam2, _ = DomeCurve.from_profile(dome, 1.25).intersect(o + [1.25, 0.0], d)
    assert np.max(np.abs(lam2[hit] - lam0[hit])) < 1e-9


def test_rays_parallel_to_the_axis_reflect_through_the_focus(system):
    from rigcad.optics.trace2d import parallel_rays

    g, para, dome = system
    x = np.linspace(dome.occlusion_s + 1.0, g.rim_radius - 1.0, 50)
    o, d = parallel_rays(list(np.concatenate([x, -x])), g.vertex_z + 1.0)
    assert np.array_equal(o[:, 1], np.full(100, g.vertex_z + 1.0)) and np.array_equal(d, np.tile([0.0, -1.0], (100, 1)))
    tr = trace(para, DomeCurve.from_profile(dome), o, d)
    P, D = tr.paraboloid_point, tr.dome_point
    assert np.array_equal(P[:, 0], np.concatenate([x, -x]))  # straight down
    # integer abscissae are positions like any other: the start height is not rounded to an integer
    assert np.array_equal(parallel_rays([0, 5], 10.5)[0], [[0.0, 10.5], [5.0, 10.5]])
    # the parabola's focal property: every reflected ray passes through the focus (0, z_v - f), so the
    # dome point lies on the line from P through it
    hit = np.isfinite(D[:, 0])
    F = np.array([0.0, g.vertex_z - g.focal_length])
    assert hit.sum() > 50
    assert np.max(np.abs(_cross(D[hit] - P[hit], F - P[hit])) / np.linalg.norm(D[hit] - P[hit], axis=1)) < 1e-9


def test_side_flags_points_on_the_line_within_their_rounding_and_no_others():
    """_side's margin: a point built on the ray's line (o + t d, rounded) is within the rounding of
    cross(p - o, d) and flagged; a point 1e-6 mm off the line never is, whatever the ray's direction
    (near horizontal or vertical, where one of the two products vanishes) or the operands' sizes."""
    from rigcad.optics.trace2d import _side

    rng = np.random.default_rng(9)
    n, eps = 20000, np.finfo(float).eps
    o = rng.uniform(-300, 300, (n, 2))
    o[: n // 4, 1] *= 1e-3  # origins far out along x only
    o[n // 4: n // 2, 0] *= 1e-3  # and along z only
    a = rng.uniform(0, 2 * np.pi, n)
    a[: n // 8] = rng.choice([0.0, np.pi], n // 8) + rng.uniform(-1e-9, 1e-9, n // 8)  # near horizontal
    a[n // 8: n // 4] = np.pi / 2 + rng.uniform(-1e-9, 1e-9, n // 8)  # near vertical
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    p = o + rng.uniform(-400, 400, n)[:, None] * d
    _, on = _side(p, o, d, eps)
    assert on.all(), np.count_nonzero(~on)
    _, off = _side(p + 1e-6 * np.stack([-d[:, 1], d[:, 0]], axis=1), o, d, eps)
    assert not off.any(), np.count_nonzero(off)
    # the ray's own origin: the cross product is exactly 0, and so is its scale
    assert _side(np.zeros((1, 2)), np.zeros((1, 2)), np.array([[1.0, 0.0]]), eps)[1].all()


def test_a_moved_dome_sends_rays_up_or_back_through_the_paraboloid(system):
    """With the dome 5 mm off the axis some rays leave it going up (ESCAPED: they never reach the
    sample plane) and some go down through the paraboloid (OCCLUDED). The classification is checked
    against the outgoing direction rebuilt here from the parabola's closed-form normal and the dome
    normal at the hit; both kinds record where they left the dome and no figure."""
    from rigcad.optics.trace2d import ESCAPED, OCCLUDED
    from rigcad.optics.vec import reflect

    g, para, dome = system
    curve = DomeCurve.from_profile(dome).shifted(5.0)
    x = np.linspace(-g.rim_radius, g.rim_radius, 2001)
    o, d = cop_rays(np.array([0.0, g.cop_z]), x, para)
    tr = trace(para, curve, o, d)
    esc, occ = tr.status == ESCAPED, tr.status == OCCLUDED
    assert esc.sum() > 5 and occ.sum() > 5 and tr.ok.sum() > 1000, np.bincount(tr.status)
    P = tr.paraboloid_point
    n_p = np.stack([P[:, 0] / (2 * g.focal_length), np.ones(len(P))], axis=1)  # z = z_v - x^2/4f: (x/2f, 1)
    u = reflect(d, n_p / np.linalg.norm(n_p, axis=1)[:, None])
    lam, n_d = curve.intersect(P, u)
    v = reflect(u, np.nan_to_num(n_d))
    assert np.all(v[esc, 1] > 0) and np.all(v[tr.ok | occ, 1] < 0)  # up, or down towards z = 0
    D = P + lam[:, None] * u
    for k in (esc, occ):
        assert np.allclose(tr.dome_point[k], D[k], rtol=0, atol=1e-9)
        for field in (tr.miss, tr.landing_x, tr.theta, tr.path_length):
            assert np.all(np.isnan(field[k]))
    # an occluded ray meets the paraboloid on its way down, before the sample plane
    back = para.intersect(D[occ], v[occ])
    assert np.all(np.isfinite(back) & (back < -D[occ, 1] / v[occ, 1]))


def test_the_first_of_two_crossings_and_a_hit_close_to_the_start(system):
    """A chord of the (convex) polyline through the midpoints A and B of two of its segments crosses it
    at A and at B only: from 10 mm before A the first crossing is A, at 10 mm, not B. From 0.5 mm in
    front of a segment's midpoint, along its normal, the hit is at 0.5 mm (the self-hit threshold
    along the ray is 1e-9 mm, not more). Each hit's normal is the unit normal of the segment hit."""
    _, _, dome = system
    curve = DomeCurve.from_profile(dome)
    flat = DomeCurve("polyline", curve.s, curve.points, None)
    P = curve.points
    mid = 0.5 * (P[:-1] + P[1:])
    a, b = np.arange(100, 1500, 200), np.arange(300, 1700, 200)
    u = (mid[b] - mid[a]) / np.linalg.norm(mid[b] - mid[a], axis=1)[:, None]
    lam, normal = flat.intersect(mid[a] - 10.0 * u, u)
    assert np.allclose(lam, 10.0, rtol=0, atol=1e-9), lam  # rounding at ~300 mm
    t = P[a + 1] - P[a]
    n_seg = np.stack([-t[:, 1], t[:, 0]], axis=1) / np.linalg.norm(t, axis=1)[:, None]
    assert np.allclose(np.abs(np.sum(normal * n_seg, axis=1)), 1.0, rtol=0, atol=1e-12)
    # 0.5 mm in front of each midpoint, aimed back at it along the segment's normal
    lam2, normal2 = flat.intersect(mid[a] + 0.5 * n_seg, -n_seg)
    assert np.allclose(lam2, 0.5, rtol=0, atol=1e-9), lam2
    assert np.allclose(np.abs(np.sum(normal2 * n_seg, axis=1)), 1.0, rtol=0, atol=1e-12)
    # the first segment too (a hit there is a hit like any other, with its normal), on the polyline and
    # on the smooth curve (which passes within far less than 1 um of the polyline's midpoint there)
    n0 = _unit_normal(P, 0)
    lam3, normal3 = flat.intersect(mid[:1] + 0.5 * n0, -n0)
    assert np.allclose(lam3, 0.5, rtol=0, atol=1e-9) and np.allclose(np.abs(normal3 @ n0[0]), 1.0, atol=1e-12)
    lam4, normal4 = curve.intersect(mid[:1] + 0.5 * n0, -n0)
    assert abs(lam4[0] - 0.5) < 1e-3 and np.allclose(np.abs(normal4 @ n0[0]), 1.0, atol=1e-6), (lam4, normal4)


def _unit_normal(P, j):
    t = P[j + 1] - P[j]
    return (np.array([-t[1], t[0]]) / np.linalg.norm(t))[None, :]
