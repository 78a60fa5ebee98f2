"""Zonal basis (thesis eqs. 3.1-3.4): orthonormality by exact quadrature, values against scipy and eq. 3.2-3.3."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from rigcad.basis.zonal import (Zone, basis_count, basis_index, basis_indices, normalized_legendre, zonal_basis,
                                zonal_moments, zone_quadrature, zone_rule)
from rigcad.errors import BasisError, RigcadError

#: The rig's zone, thesis eq. 3.4: theta in [pi/20, pi/2].
THESIS_ZONE = Zone(math.pi / 20, math.pi / 2)
ZONES = [THESIS_ZONE, Zone(math.radians(7.0), math.pi / 2), Zone(0.3, 1.2)]


def gauss_gram(zone: Zone, order: int) -> np.ndarray:
    """Gram matrix by a rule built here, independent of zone_quadrature: Gauss-Legendre in x = cos(theta)
    with order + 2 nodes (exact for the same-m products, polynomials of degree <= 2 order in t) times an
    equispaced azimuth rule with 2 order + 2 nodes (exact for trigonometric degree <= 2 order + 1)."""
    x, w = np.polynomial.legendre.leggauss(order + 2)
    a, b = math.cos(zone.beta_rad), math.cos(zone.alpha_rad)
    xx, wx = 0.5 * (a + b) + 0.5 * (b - a) * x, 0.5 * (b - a) * w
    n_az = 2 * order + 2
    phi = 2 * math.pi * np.arange(n_az) / n_az
    TH, PH = np.meshgrid(np.arccos(xx), phi, indexing="ij")
    W = np.broadcast_to(wx[:, None] * (2 * math.pi / n_az), TH.shape).ravel()
    B = zonal_basis(TH.ravel(), PH.ravel(), order, zone)
    return B.T @ (B * W[:, None])


@pytest.mark.parametrize("zone", ZONES, ids=["thesis_9deg", "7deg", "0.3-1.2rad"])
@pytest.mark.parametrize("order", [0, 1, 2, 4, 6, 8, 12])
def test_orthonormal_over_the_zone(zone, order):
    G = gauss_gram(zone, order)
    err = np.max(np.abs(G - np.eye(basis_count(order))))
    # the quadrature is exact for these integrands, so only round-off remains (measured <= 7e-15 up to
    # order 12); 1e-10 is the target and would catch any wrong normalisation or recurrence term
    assert err < 1e-10, f"order {order}: max |G - I| = {err:.3g}"


@settings(max_examples=30, deadline=None)
@given(alpha=st.floats(0.0, math.pi - 0.1), width=st.floats(0.05, math.pi))
def test_orthonormal_for_any_zone(alpha, width):
    zone = Zone(alpha, min(alpha + width, math.pi))
    err = np.max(np.abs(gauss_gram(zone, 6) - np.eye(49)))
    # exact quadrature again: round-off only, for zones from a thin band to the whole sphere
    assert err < 1e-10, f"{zone}: max |G - I| = {err:.3g}"


def test_normalised_legendre_matches_scipy():
    t = np.linspace(-1.0, 1.0, 201)
    N = normalized_legendre(t, 14)
    worst = 0.0
    for l in range(15):
        for m in range(l + 1):
            # scipy's lpmv carries the Condon-Shortley phase (-1)^m; ours does not (module docstring)
            ref = (-1) ** m * sp.lpmv(m, l, t) * math.sqrt((2 * l + 1) / 2 * math.factorial(l - m) / math.factorial(l + m))
            worst = max(worst, float(np.max(np.abs(N[:, l, m] - ref))))
    # values are O(1) to O(5); a few ulps per recurrence step over <= 14 steps (measured 4e-15)
    assert worst < 1e-12, worst


def test_low_orders_follow_equations_3_2_and_3_3():
    zone = THESIS_ZONE
    a, b = math.cos(zone.beta_rad), math.cos(zone.alpha_rad)
    rng = np.random.default_rng(5)
    theta = rng.uniform(zone.alpha_rad, zone.beta_rad, 50)
    phi = rng.uniform(0, 2 * math.pi, 50)
    t = (2 * np.cos(theta) - a - b) / (b - a)

    def K(l, m):  # eq. 3.2, written out here with factorials
        return math.sqrt((2 * l + 1) * math.factorial(l - abs(m)) / (2 * math.pi * (b - a) * math.factorial(l + abs(m))))

    Z = zonal_basis(theta, phi, 2, zone)
    expected = {
        (0, 0): K(0, 0) * np.ones_like(t),
        (1, 0): K(1, 0) * t,
        (1, 1): math.sqrt(2) * K(1, 1) * np.cos(phi) * np.sqrt(1 - t * t),
        (1, -1): math.sqrt(2) * K(1, 1) * np.sin(phi) * np.sqrt(1 - t * t),
        (2, 0): K(2, 0) * 0.5 * (3 * t * t - 1),
        (2, 2): math.sqrt(2) * K(2, 2) * np.cos(2 * phi) * 3 * (1 - t * t),
        (2, -2): math.sqrt(2) * K(2, 2) * np.sin(2 * phi) * 3 * (1 - t * t),
    }
    for (l, m), ref in expected.items():
        # closed forms of P_l^m (no Condon-Shortley phase): agreement to round-off of O(1) values
        assert np.max(np.abs(Z[:, basis_index(l, m)] - ref)) < 1e-13, (l, m)


def test_lambert_slice_lies_in_the_first_two_orders():
    # cos(theta) is affine in t, so it is exactly c0 Z_0^0 + c1 Z_1^0 (module docstring)
    zone = THESIS_ZONE
    th, ph, w = zone_quadrature(zone, 40, 8)
    c = zonal_basis(th, ph, 4, zone).T @ (np.cos(th) * w)
    rest = np.delete(c, [basis_index(0, 0), basis_index(1, 0)])
    # everything beyond Z_0^0, Z_1^0 vanishes up to quadrature round-off (coefficients are O(1))
    assert np.max(np.abs(rest)) < 1e-13, rest


def test_zone_quadrature_integrates_the_basis():
    th, ph, w = zone_quadrature(THESIS_ZONE, 30, 18)
    # weights sum to the zone's solid angle 2 pi (cos alpha - cos beta): round-off only
    assert abs(w.sum() - 2 * math.pi * math.cos(math.pi / 20)) < 1e-12
    B = zonal_basis(th, ph, 8, THESIS_ZONE)
    # the u-substituted rule converges geometrically; 30 nodes resolve degree-16 products (measured 3e-15)
    assert np.max(np.abs(B.T @ (B * w[:, None]) - np.eye(81))) < 1e-12


@pytest.mark.parametrize("zone", ZONES)
def test_separable_moments_equal_the_dense_sum(zone):
    # zonal_moments sums separably what values.ravel() @ zonal_basis(...) sums densely, on an uneven grid
    rng = np.random.default_rng(3)
    theta = np.sort(rng.uniform(zone.alpha_rad, zone.beta_rad, 23))
    phi = rng.uniform(0, 2 * math.pi, 17)
    values = rng.normal(size=(2, 23, 17))
    T, P = np.meshgrid(theta, phi, indexing="ij")
    dense = values.reshape(2, -1) @ zonal_basis(T.ravel(), P.ravel(), 8, zone)
    sep = zonal_moments(theta, phi, values, 8, zone)
    # two summation orders of ~400 terms of size O(10): round-off (measured 7e-14 against sums of O(50))
    assert np.max(np.abs(sep - dense)) < 1e-12 * max(1.0, np.max(np.abs(dense))), np.max(np.abs(sep - dense))
    with pytest.raises(BasisError, match=r"need values \(\.\.\., 23, n_phi\)"):
        zonal_moments(theta, phi, values[..., :5], 8, zone)


@pytest.mark.parametrize("order", [0, 1, 3])
def test_a_scalar_phi_is_one_azimuth(order):
    # values on a theta x one-azimuth grid: the same dense sum over zonal_basis at that azimuth, at every
    # order (order >= 1 reaches the cos/sin(m phi) factors, where a 0-d phi once failed)
    zone = THESIS_ZONE
    theta = np.linspace(zone.alpha_rad, zone.beta_rad, 9)
    values = np.random.default_rng(5).normal(size=(2, 9, 1))
    dense = values.reshape(2, -1) @ zonal_basis(theta, np.full(9, 0.7), order, zone)
    for phi in (0.7, np.float64(0.7), np.array(0.7), np.array([0.7])):
        sep = zonal_moments(theta, phi, values, order, zone)
        # two summation orders of 9 terms of O(1): round-off
        assert np.max(np.abs(sep - dense)) < 1e-12, (phi, np.max(np.abs(sep - dense)))


def test_zone_rule_is_the_factor_of_zone_quadrature():
    th, wt, ph, wp = zone_rule(THESIS_ZONE, 7, 5)
    t2, p2, w2 = zone_quadrature(THESIS_ZONE, 7, 5)
    # the flat rule is the outer product of the factors, bit for bit
    assert np.array_equal(np.repeat(th, 5), t2) and np.array_equal(np.tile(ph, 7), p2)
    assert np.array_equal(np.outer(wt, wp).ravel(), w2)


def test_indices_follow_the_sh_ordering():
    idx = basis_indices(2)
    assert idx.tolist() == [[0, 0], [1, -1], [1, 0], [1, 1], [2, -2], [2, -1], [2, 0], [2, 1], [2, 2]]
    assert [basis_index(l, m) for l, m in idx] == list(range(9))
    assert basis_count(8) == 81


def test_out_of_zone_directions_are_refused_with_the_value():
    with pytest.raises(BasisError, match=r"theta_rad = 0\.1 .*outside the zone"):
        zonal_basis(np.array([0.5, 0.1]), np.zeros(2), 2, THESIS_ZONE)


def test_zone_and_order_validation():
    with pytest.raises(BasisError, match="alpha_rad = 1.0, beta_rad = 0.5"):
        Zone(1.0, 0.5)
    with pytest.raises(BasisError, match="beta_rad = 4"):
        Zone(0.0, 4)
    with pytest.raises(BasisError, match="order = -1"):
        zonal_basis(np.array([0.5]), np.array([0.0]), -1, THESIS_ZONE)
    assert issubclass(BasisError, RigcadError)


def test_a_direction_on_a_zone_edge_is_inside_whichever_way_it_rounded():
    """The rig puts directions on the zone's edges (its theta range ends there); acos of a unit
    vector's z rounds them a few ulps either way, differently on different CPUs (numpy's SIMD
    loops, BLAS). Inside within ZONE_EDGE_SLACK_RAD (1e-9 rad), outside beyond it."""
    zone = THESIS_ZONE
    for edge, outward in ((zone.alpha_rad, -np.inf), (zone.beta_rad, np.inf)):
        near = [edge]
        for _ in range(4):  # 1-4 ulps outside the edge
            near.append(np.nextafter(near[-1], outward))
        assert zone.contains(np.array(near)).all()
        assert not zone.contains(np.array([edge + np.sign(outward) * 1e-8])).any()  # 10x the slack: outside
        zone.shifted_cosine(np.array(near))  # and the basis evaluates there (no BasisError)


# --- small cases with closed forms --------------------------------------------------------------

from rigcad.basis.zonal import (ZONE_EDGE_SLACK_RAD, angles_to_directions, check_order,  # noqa: E402
                                direction_angles)

UPPER = Zone(0.3, 1.2)  # cos(beta) != 0: b - a and b + a differ


def test_directions_and_angles_by_hand():
    s = math.sqrt(0.5)
    d = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, s], [0.0, -s, -s]])
    # theta from the normal +z, phi from the tangent +x towards +y, written down for each vector
    th_ref = [math.pi / 2, math.pi / 2, 0.0, math.pi / 4, 3 * math.pi / 4]
    ph_ref = [0.0, math.pi / 2, 0.0, math.pi / 4, -math.pi / 2]
    th, ph = direction_angles(d)
    assert np.allclose(th, th_ref, rtol=0, atol=1e-15) and np.allclose(ph, ph_ref, rtol=0, atol=1e-15)
    # back to unit vectors: round-off of sin/cos of O(1) angles
    assert np.allclose(angles_to_directions(th_ref, ph_ref), d, rtol=0, atol=1e-15)
    # a scalar theta broadcasts against many phi
    ring = angles_to_directions(math.pi / 2, np.array([0.0, math.pi]))
    assert ring.shape == (2, 3) and np.allclose(ring, [[1, 0, 0], [-1, 0, 0]], atol=1e-15)
    with pytest.raises(BasisError, match=r"directions have shape \(2, 2\): need \(\.\.\., 3\) unit vectors"):
        direction_angles(np.ones((2, 2)))
    v = angles_to_directions([0.4, 0.9, 1.1], [0.2, -2.0, 3.0])
    # unit vectors back to their angles (arctan2: round-off of O(1) angles)
    th, ph = direction_angles(v)
    assert np.allclose(th, [0.4, 0.9, 1.1], rtol=0, atol=1e-15) and np.allclose(ph, [0.2, -2.0, 3.0], rtol=0, atol=1e-15)


def test_one_node_rule_and_zone_rule_weights_on_an_upper_zone():
    th, wt, ph, wp = zone_rule(UPPER, 1, 1)
    a, b = math.cos(1.2), math.cos(0.3)
    # one Gauss node at u = pi/2: x = (a + b)/2, weight (b - a)/2 * sin(pi/2) * pi/2 * 2; phi 0, weight 2 pi
    assert np.allclose(np.cos(th), [(a + b) / 2], atol=1e-15) and np.allclose(wt, [(b - a) * math.pi / 2], atol=1e-15)
    assert ph.tolist() == [0.0] and np.allclose(wp, [2 * math.pi], atol=1e-15)
    th, wt, ph, wp = zone_rule(UPPER, 9, 4)
    # the weights integrate 1 and cos(theta) over the zone: 2 pi (b - a) and pi (b^2 - a^2) sr
    assert math.isclose(wt.sum() * wp.sum(), 2 * math.pi * (b - a), rel_tol=1e-13)
    assert math.isclose((wt * np.cos(th)).sum() * wp.sum(), math.pi * (b * b - a * a), rel_tol=1e-12)
    for n_p, n_a in ((0, 3), (3, 0)):
        with pytest.raises(BasisError, match=rf"quadrature sizes n_polar = {n_p}, n_azimuth = {n_a}: need >= 1 each"):
            zone_rule(UPPER, n_p, n_a)


def test_zone_edges_within_the_slack_are_inside_and_clipped():
    lo, hi = UPPER.alpha_rad - ZONE_EDGE_SLACK_RAD, UPPER.beta_rad + ZONE_EDGE_SLACK_RAD
    # the slack's own ends are inside (edges included), and one ulp beyond them is not
    assert UPPER.contains(np.array([lo, hi])).all()
    assert not UPPER.contains(np.array([np.nextafter(lo, -1.0), np.nextafter(hi, 4.0)])).any()
    # just outside the geometric edge, t = (2 cos theta - a - b)/(b - a) leaves [-1, 1] by ~1e-9: clipped,
    # so the Legendre recurrences see a valid argument
    t = UPPER.shifted_cosine(np.array([lo, hi, 0.75]))
    assert t[0] == 1.0 and t[1] == -1.0 and abs(t[2]) < 1.0
    with pytest.raises(BasisError, match=r"\(2 value\(s\)\) outside the zone .* before evaluating the zonal basis$"):
        UPPER.shifted_cosine(np.array([0.1, 0.5, 1.5]))


def test_zone_and_order_refusals_name_the_parameter():
    with pytest.raises(BasisError, match=r"need 0 <= alpha_rad < beta_rad <= pi \(polar angles from the sample "
                                         r"normal, in radians\)$") as e:
        Zone(0.5, 0.5)  # an empty zone
    assert e.value.param == "basis.zone"
    assert check_order(np.int64(3)) == 3
    for bad in (True, 2.0, -1):
        with pytest.raises(BasisError, match=rf"basis order = {bad!r}: need an integer >= 0") as e:
            check_order(bad)
        assert e.value.param == "basis.order"
    with pytest.raises(BasisError, match=r"\(l, m\) = \(1, 2\): need l >= 0 and -l <= m <= l"):
        basis_index(1, 2)


def test_normalised_legendre_shape():
    # (order + 1) x (order + 1) per argument: l down, m across
    assert normalized_legendre(np.zeros((4, 2)), 3).shape == (4, 2, 4, 4)


def test_moments_with_an_azimuth_rule_per_polar_row():
    zone = UPPER
    rng = np.random.default_rng(11)
    theta = np.sort(rng.uniform(zone.alpha_rad, zone.beta_rad, 7))
    phi = rng.uniform(0, 2 * math.pi, (7, 5))  # each polar row its own azimuths
    values = rng.normal(size=(3, 7, 5))
    T = np.repeat(theta[:, None], 5, axis=1)
    dense = values.reshape(3, -1) @ zonal_basis(T.ravel(), phi.ravel(), 6, zone)
    sep = zonal_moments(theta, phi, values, 6, zone)
    # two summation orders of 35 terms of O(1): round-off
    assert np.max(np.abs(sep - dense)) < 1e-12 * max(1.0, np.max(np.abs(dense))), np.max(np.abs(sep - dense))
    msg = r"need values \(\.\.\., 7, n_phi\) \(theta x phi\) and phi \(n_phi,\) or \(n_theta, n_phi\)$"
    with pytest.raises(BasisError, match=msg):
        zonal_moments(theta, phi[:6], values[:, :6], 6, zone)  # phi rows do not match theta
    with pytest.raises(BasisError, match=msg):
        zonal_moments(theta, phi[None], values, 6, zone)  # a 3-D phi


def test_directions_and_angles_keep_the_grid_shape():
    # a (2, 4) grid of angles gives (2, 4, 3) unit vectors, and back: the last axis holds x, y, z
    th, ph = np.meshgrid([0.4, 1.0], [0.0, 1.0, 2.0, 3.0], indexing="ij")
    d = angles_to_directions(th, ph)
    assert d.shape == (2, 4, 3)
    assert np.allclose(d[1, 2], [math.sin(1.0) * math.cos(2.0), math.sin(1.0) * math.sin(2.0), math.cos(1.0)],
                       rtol=0, atol=1e-15)
    th2, ph2 = direction_angles(d)
    # arctan2 of the components: round-off of O(1) angles
    assert np.allclose(th2, th, rtol=0, atol=1e-15) and np.allclose(ph2, ph, rtol=0, atol=1e-15)
