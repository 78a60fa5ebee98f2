"""The meridians' one foot-point solver: a point's answer is its own, whichever points share the call."""

import pickle

import numpy as np
import pytest

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
