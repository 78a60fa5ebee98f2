"""Dome profile accuracy against truth from outside the integrators.

Far COP: the reflected rays share the virtual point F (the paraboloid's focus), so the exact dome
is the ellipse with foci F and O: |DF| + |DO| is constant along it. Finite COP: every ray must
return to O (checked by the 2D tracer in test_trace2d.py).
"""

import math

import numpy as np
import pytest

from rigcad.errors import IntegrationError
from rigcad.optics.dome import build_dome, build_euler
from rigcad.profile import derive, load_profile


@pytest.fixture(scope="module")
def far_geometry(tmp_path_factory, table31_text):
    path = tmp_path_factory.mktemp("far") / "far.yaml"
    path.write_text(table31_text.replace("27 cm", "inf"))
    return derive(load_profile(path))


def ellipse_sums(points, focus_z):
    return np.hypot(points[:, 0], points[:, 1] - focus_z) + np.hypot(points[:, 0], points[:, 1])


def test_far_cop_dop853_is_the_ellipse_to_1e9_relative(far_geometry):
    dome = build_dome(far_geometry, "dop853", tolerance=1e-9, rows=4001)
    sums = ellipse_sums(dome.points, far_geometry.focus_z)
    spread = (sums.max() - sums.min()) / sums.mean()
    assert spread < 1e-9, spread  # the bound
    assert dome.points[0, 1] == pytest.approx(0.0, abs=1e-12)  # starts on the sample plane


def test_far_cop_rk45_is_the_ellipse_within_its_tolerance(far_geometry):
    dome = build_dome(far_geometry, "rk45", tolerance=1e-7, rows=1001)
    sums = ellipse_sums(dome.points, far_geometry.focus_z)
    # local tolerance 1e-7 mm per step; global error measured well under 100x that
    assert sums.max() - sums.min() < 1e-5


@pytest.mark.parametrize("method, tol", [("dop853", 1e-5), ("dop853", 1e-7), ("dop853", 1e-9),
                                         ("rk45", 1e-5), ("rk45", 1e-7)])
def test_global_error_meets_the_tolerance_against_the_ellipse(far_geometry, tol, method):
    dome = build_dome(far_geometry, method, tolerance=tol, rows=501)
    sums = ellipse_sums(dome.points, far_geometry.focus_z)
    # The distance t along each ray moves the point along the ray: the ellipse sum changes by at
    # most 2x the error in t. The contract is a global error <= tol, certified by an estimate,
    # so the true error may exceed tol by the estimate's own error: allow 2x on top.
    err = np.max(np.abs(sums - sums[0]))
    assert err <= 2 * 2 * tol, (tol, err)
    assert dome.error_estimate <= tol


def test_error_estimate_tracks_the_true_error(table31_geometry):
    dome = build_dome(table31_geometry, "dop853", tolerance=1e-7, rows=501)
    # The estimate (second solve at tol/100) must be within a factor 3 of the error measured
    # against the closed form: it is what the design report quotes.
    assert dome.error_vs_equal_path / 3 <= dome.error_estimate <= 3 * dome.error_vs_equal_path


def test_euler_polyline_converges_at_first_order(far_geometry):
    g = far_geometry
    errors = []
    for steps in (1000, 2000, 4000):
        dome = build_euler(g, steps)
        k = steps // 2  # vertex at s = rim_radius / 2, shared by all three step sizes
        assert dome.s[k] == pytest.approx(g.rim_radius / 2, rel=1e-12)
        sums = ellipse_sums(dome.points, g.focus_z)
        errors.append(abs(sums[k] - sums[0]))  # sums[0] is exact: the start point is closed form
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert all(0.9 < p < 1.1 for p in orders), (errors, orders)  # first order, with some slack


def test_methods_agree_on_the_table31_design(table31_geometry):
    from rigcad.optics.dome import equal_path_t, reflected_rays

    exact = build_dome(table31_geometry, "equal_path", rows=1001)
    ode = build_dome(table31_geometry, "dop853", tolerance=1e-9, rows=1001)
    # The ODE and the equal-path closed form are independent derivations of one condition:
    # at the ODE's own rows they agree to its certified 1e-9 mm (x2 for the estimate's own error).
    r = reflected_rays(table31_geometry, ode.s)
    closed = r.P + equal_path_t(table31_geometry, ode.s, exact.path_length)[:, None] * r.u
    assert np.max(np.linalg.norm(closed - ode.points, axis=1)) < 2e-9
    assert ode.occlusion_s == pytest.approx(exact.occlusion_s, abs=1e-12)
    # both place their rows evenly in theta: the same rows to the integration error
    assert np.max(np.abs(np.degrees(exact.theta - ode.theta))) < 1e-6


def test_dome_ends_at_the_occlusion_limit(table31_geometry):
    dome = build_dome(table31_geometry, "dop853", rows=501)
    end = dome.points[-1]
    assert math.atan2(end[0], end[1]) == pytest.approx(table31_geometry.occlusion_theta, abs=1e-10)
    assert dome.theta[0] == pytest.approx(math.pi / 2, abs=1e-12)  # grazing at the start


def test_tolerance_below_float64_is_refused(table31_geometry):
    with pytest.raises(IntegrationError, match=r"dome.tolerance = 1e-15 mm cannot be certified.*ask for"):
        build_dome(table31_geometry, "dop853", tolerance=1e-15)


@pytest.mark.parametrize("cop", ["finite", "infinite"])
def test_scalar_theta_agrees_with_the_vectorised_closed_form(table31_geometry, far_geometry, cop):
    from rigcad.optics.dome import equal_path_t, reflected_rays, scalar_theta, start, theta_of

    g = table31_geometry if cop == "finite" else far_geometry
    L = start(g).path_length
    s = np.linspace(0.5, g.rim_radius, 13)
    r = reflected_rays(g, s)
    vec = theta_of(r.P + equal_path_t(g, s, L)[:, None] * r.u)
    sca = np.array([scalar_theta(g, L)(a) for a in s])
    assert np.max(np.abs(vec - sca)) < 1e-13  # rad: same formulas, round-off only


@pytest.mark.parametrize("cop", ["finite", "infinite"])
def test_scalar_rhs_agrees_with_the_vectorised_one(table31_geometry, far_geometry, cop):
    from rigcad.optics.dome import dt_ds, scalar_rhs

    g = table31_geometry if cop == "finite" else far_geometry
    rhs = scalar_rhs(g)
    s = np.linspace(0.5, g.rim_radius, 13)
    t = np.linspace(80.0, 170.0, 13)
    vec = dt_ds(g, s, t)
    sca = np.array([rhs(a, [b])[0] for a, b in zip(s, t)])
    assert np.max(np.abs(vec - sca)) < 1e-12 * np.max(np.abs(vec))  # same formulas, round-off only


def test_a_dome_through_the_paraboloid_or_not_finite_is_refused(table31_geometry):
    """_check_clear against the paraboloid's closed form r(z) = sqrt(4 f (z_v - z)) between its rim and
    vertex: a dome point just inside it is refused naming layout.sample_to_rim, one just outside (or
    above the vertex, or below the rim) is not; a non-finite point is refused naming
    paraboloid.tangent_angle."""
    from rigcad.errors import GeometryError
    from rigcad.optics.dome import _check_clear

    g = table31_geometry
    z = np.array([g.rim_z, 0.5 * (g.rim_z + g.vertex_z), g.vertex_z - 1e-3])
    r = np.sqrt(4 * g.focal_length * (g.vertex_z - z))
    clear = np.column_stack([r * (1 + 1e-9) + 1e-12, z])
    _check_clear(g, clear)  # outside the paraboloid at its rim, middle and near its vertex
    _check_clear(g, np.array([[0.0, g.vertex_z + 1e-6], [0.0, g.rim_z - 1e-6]]))  # on the axis, out of its band
    for k in range(3):
        inside = clear.copy()
        inside[k, 0] = r[k] * (1 - 1e-9)
        with pytest.raises(GeometryError) as info:
            _check_clear(g, inside)
        assert info.value.param == "layout.sample_to_rim" and "passes through the paraboloid" in str(info.value)
    bad = np.vstack([clear, [np.nan, 0.0]])
    with pytest.raises(GeometryError) as info:
        _check_clear(g, bad)
    assert info.value.param == "paraboloid.tangent_angle" and "not finite" in str(info.value)
