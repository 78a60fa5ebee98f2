"""The meridians' one foot-point solver: a point's answer is its own, whichever points share the call.

And the meridians against closed forms: the paraboloid z = v - r^2 / 4f (its normal (r / 2f, 1),
curvature (1 / 2f) / (1 + (r / 2f)^2)^1.5, arc length f (x sqrt(1 + x^2) + asinh x) with x = r / 2f),
parallel curves (radius of curvature -+ the offset), a polyline's sagitta measured point by point, and
the parameters a chord error needs (the integral of sqrt(k / 8e) ds, by quad)."""

import math
import pickle

import numpy as np
import pytest
from scipy.integrate import quad

from rigcad.errors import GeometryError
from rigcad.optics.dome import build_dome
from rigcad.optics.surfaces import FOOT_POINT_TOL_MM, dome_meridian, paraboloid_meridian

#: The coating offset of the Table 3.1 profile (mm): the printed surfaces sit this far behind.
COATING = 0.1397
#: Distances (mm, along the normal: negative = behind) of points that Newton does not settle.
FAR_BEHIND_MM = {"dome": (-400.0, -150.0), "paraboloid": (-20.0, -5.0)}


@pytest.fixture(scope="module")
def meridians(table31_geometry):
    dome = dome_meridian(build_dome(table31_geometry, "dop853", tolerance=1e-9, rows=2001))
    para = paraboloid_meridian(table31_geometry)
    return {(kind, off): (m.behind(off) if off else m) for kind, m in (("dome", dome), ("paraboloid", para))
            for off in (0.0, COATING)}


def _points(meridian, rng, count, lo_mm, hi_mm):
    """``count`` points (n, 2) at distances lo_mm..hi_mm along the normal of random points of the curve."""
    u = rng.uniform(*meridian.u_range, count)
    d = rng.uniform(lo_mm, hi_mm, count)
    return meridian.points(u) + d[:, None] * meridian.normals(u)


def _tangential_residual(meridian, rz, u):
    """|t . (q - c(u))| (n,) mm: zero at a foot point inside the range."""
    t = meridian.tangents(u)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    return np.abs(np.einsum("ij,ij->i", rz - meridian.points(u), t))


@pytest.mark.parametrize("kind", ["dome", "paraboloid"])
@pytest.mark.parametrize("offset", [0.0, COATING])
def test_a_points_foot_parameter_does_not_depend_on_its_batch(meridians, kind, offset):
    m = meridians[(kind, offset)]
    rng = np.random.default_rng(7)
    near = _points(m, rng, 300, -0.5, 0.5)  # converge in a few steps
    # far behind the mirror (past the convex paraboloid's centre of curvature, ~6 mm at its
    # vertex; far outside the dome, radius >= 120 mm): Newton's rate there is curvature x
    # distance ~ 1, so many take every step and stay unsettled
    far = _points(m, rng, 300, *FAR_BEHIND_MM[kind])
    u_far = m.foot_points(far)
    lo, hi = m.u_range
    inside = (u_far > lo) & (u_far < hi)
    # the batch really holds unsettled points: their result is no foot point (residual >> tolerance)
    assert np.max(_tangential_residual(m, far[inside], u_far[inside])) > 1e6 * FOOT_POINT_TOL_MM
    alone = np.array([m.foot_points(p[None])[0] for p in near])
    mixed = np.concatenate([far[:150], near, far[150:]])
    perm = rng.permutation(len(mixed))
    u_mixed = np.empty(len(mixed))
    u_mixed[perm] = m.foot_points(mixed[perm])
    # the same bits: each point iterates until its own step is under the tolerance, and every
    # operation on it is elementwise (the old stopping rule, on the largest step of the batch,
    # kept the near points iterating with the far ones and moved their last bits)
    assert np.array_equal(u_mixed[150:450], alone)
    assert np.array_equal(u_mixed[:150], u_far[:150]) and np.array_equal(u_mixed[450:], u_far[150:])
    # and they are foot points: the tangential residual at rounding level (1e-9 mm, ~1e5 x the
    # rounding of 100 mm coordinates; a real miss would be of the step size, >> 1e-9)
    assert np.max(_tangential_residual(m, near, alone)) < 1e-9


def test_a_pickled_meridian_gives_the_same_bits(meridians):
    m = meridians[("dome", COATING)]
    rz = _points(m, np.random.default_rng(3), 500, -5.0, 1.0)
    u = m.foot_points(rz)  # builds the caches (sample table, derivative splines) ...
    clone = pickle.loads(pickle.dumps(m))
    assert "_table" not in clone.__dict__ and "_dome_derivatives" not in clone.__dict__  # ... dropped from the pickle
    assert np.array_equal(clone.foot_points(rz), u)
    assert np.array_equal(clone.distance(rz), m.distance(rz))
    assert np.array_equal(clone.curvature(u), m.curvature(u))



@pytest.fixture(scope="module")
def geo(table31_geometry):
    return table31_geometry


@pytest.fixture(scope="module")
def dome(geo):
    return build_dome(geo, "dop853", tolerance=1e-9, rows=2001)


def _para(geo, r):
    """Closed-form points (n, 2), unit normals on the reflecting side (up and out), curvature."""
    f, v = geo.focal_length, geo.vertex_z
    x = r / (2 * f)
    p = np.stack([r, v - r * r / (4 * f)], axis=-1)
    n = np.stack([x, np.ones_like(r)], axis=-1) / np.sqrt(1 + x * x)[:, None]
    k = (1 / (2 * f)) / (1 + x * x) ** 1.5
    return p, n, k


def _arc(geo, r):
    f = geo.focal_length
    x = r / (2 * f)
    return f * (x * np.sqrt(1 + x * x) + np.arcsinh(x))


def test_the_paraboloid_meridian_runs_from_the_rim_to_the_vertex(geo):
    m = paraboloid_meridian(geo)
    assert (m.kind, m.u_range, m.offset) == ("paraboloid", (-geo.rim_radius, 0.0), 0.0)
    assert m._focal_length == geo.focal_length and m._vertex_z == geo.vertex_z


@pytest.mark.parametrize("offset", [0.0, COATING, 1.0])
def test_paraboloid_points_normals_and_curvature_are_the_closed_forms(geo, offset):
    m = paraboloid_meridian(geo).behind(offset) if offset else paraboloid_meridian(geo)
    u = np.linspace(-geo.rim_radius, 0.0, 101)
    p, n, k = _para(geo, -u)
    tol = 1e-12 * geo.vertex_z
    assert np.max(np.abs(m.points(u) - (p - offset * n))) < tol
    assert np.max(np.abs(m.normals(u) - n)) < 1e-14
    # convex: moving behind shrinks the radius of curvature by the offset
    assert np.max(np.abs(m.curvature(u) - 1.0 / (1.0 / k - offset)) / k) < 1e-12
    pts, nrm = m._points_normals(u)
    assert np.array_equal(pts, m.points(u)) and np.array_equal(nrm, m.normals(u))
    # scalars are taken as one parameter
    assert m.points(-1.0).shape == (1, 2) and m.curvature(-1.0).shape == (1,)


@pytest.mark.parametrize("kind", ["paraboloid", "dome"])
@pytest.mark.parametrize("offset", [0.0, COATING])
def test_tangents_are_the_derivative_of_the_points(geo, dome, kind, offset):
    m = paraboloid_meridian(geo) if kind == "paraboloid" else dome_meridian(dome)
    m = m.behind(offset) if offset else m
    lo, hi = m.u_range
    h = 1e-4 * (hi - lo)
    u = np.linspace(lo + 2 * h, hi - 2 * h, 41)
    central = (m.points(u + h) - m.points(u - h)) / (2 * h)  # error ~ h^2 |p'''| / 6
    t = m.tangents(u)
    assert np.max(np.abs(t - central)) < 1e-6 * np.max(np.abs(t))
    assert m.tangents(lo).shape == (1, 2)


def test_dome_normals_point_inwards_and_curvature_grows_behind(dome):
    m = dome_meridian(dome)
    assert (m.kind, m.u_range, m.offset) == ("dome", (-float(dome.s.max()), -float(dome.s.min())), 0.0)
    u = np.linspace(*m.u_range, 51)
    p, n = m.points(u), m.normals(u)
    # the inside of the dome: O (the origin) and the axis lie on the normal's side
    assert np.all(np.einsum("ij,ij->i", -p, n) > 0) and np.all(n[:, 0] < 0)
    assert np.max(np.abs(np.linalg.norm(n, axis=1) - 1)) < 1e-14
    # concave: moving behind grows the radius of curvature by the offset
    k0 = m.curvature(u)
    assert np.max(np.abs(m.behind(COATING).curvature(u) - 1 / (1 / k0 + COATING)) / k0) < 1e-12
    # the curvature of the points: |x' z'' - z' x''| / |p'|^3 by central differences
    h = 1e-3 * (m.u_range[1] - m.u_range[0])
    v = u[2:-2]
    d1 = (m.points(v + h) - m.points(v - h)) / (2 * h)
    d2 = (m.points(v + h) - 2 * m.points(v) + m.points(v - h)) / h ** 2
    k_fd = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
    assert np.max(np.abs(k_fd - k0[2:-2]) / k0[2:-2]) < 1e-5


def test_an_offset_past_the_centre_of_curvature_is_refused(geo):
    # the vertex's radius of curvature is 2f = 5.96 mm
    m = paraboloid_meridian(geo).behind(7.0)
    with pytest.raises(GeometryError) as e:
        m.curvature(np.array([0.0]))
    assert str(e.value) == (f"an offset of 7 mm behind the paraboloid passes its centre of curvature (radius "
                            f"{2 * geo.focal_length:.3g} mm): no regular parallel surface")
    assert m.behind(-1.5).curvature(np.array([0.0]))[0] == pytest.approx(1 / (2 * geo.focal_length + 1.5 - 7.0), rel=1e-12)
    # a nanometre past the centre is refused as well
    with pytest.raises(GeometryError):
        paraboloid_meridian(geo).behind(2 * geo.focal_length + 1e-6).curvature(np.array([0.0]))


def test_behind_adds_offsets_and_keeps_the_curve(geo, dome):
    p = paraboloid_meridian(geo).behind(0.25).behind(0.5)
    assert (p.kind, p.u_range, p.offset, p._focal_length, p._vertex_z) == \
        ("paraboloid", (-geo.rim_radius, 0.0), 0.75, geo.focal_length, geo.vertex_z)
    d = dome_meridian(dome).behind(0.25)
    assert np.array_equal(d.points(np.array([-5.0])), dome_meridian(dome).points(np.array([-5.0])) -
                          0.25 * dome_meridian(dome).normals(np.array([-5.0])))


def test_a_polyline_dome_has_no_meridian(geo):
    euler = build_dome(geo, "euler", euler_steps=200)
    with pytest.raises(GeometryError) as e:
        dome_meridian(euler)
    assert str(e.value).startswith("3D surfaces need a smooth dome profile (dome.method dop853, rk45 or "
                                   "equal_path), not the euler polyline")
    assert e.value.param == "dome.method"


@pytest.mark.parametrize("offset", [-0.5, 0.0, 0.8])
def test_signed_distance_along_the_paraboloid_normal(geo, offset):
    m = paraboloid_meridian(geo).behind(COATING)
    r = np.linspace(0.5, geo.rim_radius - 0.5, 40)
    p, n, _ = _para(geo, r)
    q = p - COATING * n + offset * n  # offset in front (+) or behind (-) the coated curve
    assert np.max(np.abs(m.distance(q) - offset)) < 1e-9
    assert m.distance(q[0]).shape == (1,)


def test_a_pickle_drops_the_caches_and_keeps_the_curve(dome):
    m = dome_meridian(dome).behind(COATING)
    u = m.foot_points(m.points(np.linspace(*m.u_range, 7)))
    m.curvature(u)
    state = m.__getstate__()
    assert "_table" not in state and "_dome_derivatives" not in state
    assert "_table" in m.__dict__ and "_dome_derivatives" in m.__dict__  # the live object keeps them
    clone = pickle.loads(pickle.dumps(m))
    assert clone.offset == COATING and clone.u_range == m.u_range
    assert np.array_equal(clone.points(u), m.points(u))
    # a fresh meridian (no cache built yet) pickles too
    assert pickle.loads(pickle.dumps(dome_meridian(dome))).kind == "dome"


def test_sample_spans_the_range_evenly(geo):
    m = paraboloid_meridian(geo)
    u = m.sample(5)
    assert np.allclose(u, np.linspace(-geo.rim_radius, 0.0, 5), rtol=0, atol=1e-15)


@pytest.mark.parametrize("spacing", [0.5, 1.3, 100.0])
def test_arc_length_parameters_are_evenly_spaced_in_arc_length(geo, spacing):
    m = paraboloid_meridian(geo)
    u = m.arc_length_parameters(spacing)
    total = _arc(geo, geo.rim_radius)
    n = max(math.ceil(total / spacing), 1)
    assert len(u) == n + 1 and u[0] == -geo.rim_radius and u[-1] == 0.0
    s = total - _arc(geo, -u)  # arc length from the rim (u = -rim_radius) to each point
    # interpolated in the arc length of 20001 chords: ~1e-7 mm off the exact arc
    assert np.max(np.abs(np.diff(s) - total / n)) < 1e-6
    assert np.all(np.diff(u) > 0)


@pytest.mark.parametrize("offset", [0.0, COATING])
@pytest.mark.parametrize("chord_error", [0.01, 0.002])
def test_chord_parameters_meet_the_chord_error_and_no_more(geo, offset, chord_error):
    m = paraboloid_meridian(geo).behind(offset) if offset else paraboloid_meridian(geo)
    u = m.chord_parameters(chord_error)
    assert u[0] == -geo.rim_radius and u[-1] == 0.0 and np.all(np.diff(u) > 0)
    # the points needed: the integral of sqrt(k / 8e) ds along the (offset) curve
    f = geo.focal_length

    def density(r):
        x = r / (2 * f)
        k = (1 / (2 * f)) / (1 + x * x) ** 1.5
        ds = math.sqrt(1 + x * x) * (1 - offset * k)  # a parallel curve's arc shrinks by (1 - d k)
        return math.sqrt(1 / (1 / k - offset) / (8 * chord_error)) * ds

    need = quad(density, 0.0, geo.rim_radius, epsabs=1e-12)[0]
    assert math.ceil(need) <= len(u) - 1 <= math.ceil(need * 1.001)
    # and the polyline stays within the chord error: each segment's sagitta, measured on 200 points
    assert 0.9 * chord_error < _worst_sagitta(m, u) <= chord_error * (1 + 1e-3)


def test_a_straight_enough_curve_takes_one_chord(geo):
    # a chord error above the whole curve's sagitta: the two ends alone
    u = paraboloid_meridian(geo).chord_parameters(1e3)
    assert np.array_equal(u, [-geo.rim_radius, 0.0])


def test_no_negative_zeros_and_the_same_bits_from_points_normals(geo):
    # at the vertex (u = 0, r = -0.0) the normal's r is a negative zero before the + 0.0
    m = paraboloid_meridian(geo)
    u = np.array([-geo.rim_radius, -1.0, 0.0])
    assert not np.any(np.signbit(m.normals(u)[:, 0])) and m.normals(u)[2, 0] == 0.0
    pts, nrm = m._points_normals(u)
    assert np.array_equal(np.signbit(pts), np.signbit(m.points(u)))  # the same bits, zeros' signs included
    assert np.array_equal(pts, m.points(u)) and np.array_equal(nrm, m.normals(u))


def test_arc_length_parameters_count_the_whole_curve(geo):
    # a spacing that fits the arc 10.00001 times: 11 steps, though 10 fit all but its last 1e-6
    m = paraboloid_meridian(geo)
    spacing = _arc(geo, geo.rim_radius) / 10.00001
    assert len(m.arc_length_parameters(spacing)) == 12


def test_foot_points_beyond_an_end_are_that_end(geo):
    m = paraboloid_meridian(geo)
    # near the parabola past the rim (r = rim + 2) and past the vertex on the other side (r = -3),
    # 0.1 mm in front: the half-meridian's nearest points are its ends
    r = np.array([geo.rim_radius + 2.0, -3.0])
    p, n, _ = _para(geo, r)
    u = m.foot_points(p + 0.1 * n)
    assert u[0] == -geo.rim_radius and u[1] == 0.0


@pytest.mark.parametrize("kind", ["paraboloid", "dome"])
def test_unsettled_foot_points_are_no_farther_than_the_nearest_sample(geo, dome, kind):
    # far behind (see test_a_points_foot_parameter_does_not_depend_on_its_batch) Newton does not
    # settle; the result is the nearer of the seed (the nearest of the samples) and the last iterate
    m = (paraboloid_meridian(geo) if kind == "paraboloid" else dome_meridian(dome)).behind(COATING)
    rng = np.random.default_rng(9)
    far = _points(m, rng, 300, *FAR_BEHIND_MM[kind])
    got = np.linalg.norm(far - m.points(m.foot_points(far)), axis=1)
    samples = m.points(m.sample(20001))
    nearest = np.array([np.min(np.linalg.norm(samples - q, axis=1)) for q in far])
    assert np.all(got <= nearest * (1 + 1e-12))


def test_dome_chord_parameters_meet_the_chord_error_and_no_more(dome):
    m = dome_meridian(dome)
    chord_error = 0.01
    u = m.chord_parameters(chord_error)
    assert u[0] == m.u_range[0] and u[-1] == m.u_range[1]
    # the points needed: the integral of sqrt(k / 8e) |dp/du| du (curvature and tangents measured
    # against central differences above)
    need = quad(lambda v: math.sqrt(m.curvature(v)[0] / (8 * chord_error)) * np.linalg.norm(m.tangents(v)[0]),
                *m.u_range, epsabs=1e-10, limit=200)[0]
    assert math.ceil(need) <= len(u) - 1 <= math.ceil(need * 1.001)
    assert 0.9 * chord_error < _worst_sagitta(m, u) <= chord_error * (1 + 1e-3)


def _worst_sagitta(m, u) -> float:
    """The largest distance (mm) from a chord of the polyline through m.points(u) to the meridian
    between its ends, measured on 200 points of each segment."""
    t = np.linspace(0.0, 1.0, 200)
    worst = 0.0
    for a, b in zip(u[:-1], u[1:]):
        p0, p1 = m.points(np.array([a, b]))
        c = m.points(a + t * (b - a))
        e = (p1 - p0) / np.linalg.norm(p1 - p0)
        worst = max(worst, float(np.max(np.abs((c[:, 0] - p0[0]) * e[1] - (c[:, 1] - p0[1]) * e[0]))))
    return worst
