"""Zonal -> spherical harmonics through the dual basis (thesis eqs. 3.5-3.7) and extrapolation into the cap."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special as sp

from rigcad.basis.sh import conversion_residual, evaluate_sh, sh_basis, zonal_to_sh, zonal_to_sh_matrix
from rigcad.basis.zonal import Zone, basis_indices, zonal_basis
from rigcad.errors import BasisError

ZONE = Zone(math.pi / 20, math.pi / 2)  # thesis eq. 3.4
CAP = Zone(0.0, math.pi / 20)           # the directions the rig cannot reach


def rule(zone: Zone, n_polar: int = 400, n_az: int = 64):
    """Quadrature over a zone built here: Gauss-Legendre in theta (not cos theta, unlike rigcad's rule)
    with n_polar nodes times n_az equispaced azimuths; weights sin(theta) d theta d phi."""
    x, w = np.polynomial.legendre.leggauss(n_polar)
    th = zone.alpha_rad + 0.5 * (zone.beta_rad - zone.alpha_rad) * (x + 1)
    wt = 0.5 * (zone.beta_rad - zone.alpha_rad) * w * np.sin(th)
    phi = 2 * math.pi * np.arange(n_az) / n_az
    TH, PH = np.meshgrid(th, phi, indexing="ij")
    return TH.ravel(), PH.ravel(), np.broadcast_to(wt[:, None] * (2 * math.pi / n_az), TH.shape).ravel()


def test_real_sh_match_scipy():
    rng = np.random.default_rng(8)
    th, ph = rng.uniform(0, math.pi, 300), rng.uniform(0, 2 * math.pi, 300)
    Y = sh_basis(th, ph, 8)
    for l, m in basis_indices(8):
        c = sp.sph_harm_y(l, abs(m), th, ph)
        # scipy: complex, with the Condon-Shortley phase; ours: real form without it (module docstrings)
        ref = c.real if m == 0 else math.sqrt(2) * (-1) ** abs(int(m)) * (c.real if m > 0 else c.imag)
        # O(1) values through <= 8 recurrence steps: round-off only (measured 4e-16 at order 3)
        assert np.max(np.abs(Y[:, l * l + l + m] - ref)) < 1e-12, (l, m)
    # the zonal basis of the whole sphere is the SH basis
    assert np.max(np.abs(zonal_basis(th, ph, 8, Zone(0.0, math.pi)) - Y)) < 1e-13


@pytest.mark.parametrize("order", [2, 4, 6])
def test_dual_basis_is_biorthogonal_over_the_zone(order):
    conv = zonal_to_sh_matrix(ZONE, order)
    th, ph, w = rule(ZONE)
    Y = sh_basis(th, ph, order)
    dual = Y @ conv.dual.T                     # Yhat_p at the nodes, eq. 3.6
    B = Y.T @ (dual * w[:, None])              # eq. 3.5: int_zone Y_l Yhat_p = delta_lp
    err = np.max(np.abs(B - np.eye(B.shape[0])))
    # the dual is M^-1, so its error scales with cond(M) * eps: cond is 2.5e2, 1.6e5, 1.3e8 for orders 2, 4, 6
    # and the errors measured 4e-13, 3e-11, 3e-8 (the factor 1e3 covers the K-dimensional solve and quadrature)
    assert err < 1e3 * conv.condition * np.finfo(float).eps, (order, err, conv.condition)


def test_axially_symmetric_sh_function_is_recovered_exactly():
    rng = np.random.default_rng(1)
    f_true = np.zeros(16)
    f_true[[l * l + l for l in range(4)]] = rng.normal(size=4)       # m = 0 only, l <= 3
    th, ph, w = rule(ZONE)
    h = sh_basis(th, ph, 3) @ f_true
    z = zonal_basis(th, ph, 3, ZONE).T @ (h * w)                      # zonal coefficients by quadrature
    f = zonal_to_sh(z, zonal_to_sh_matrix(ZONE, 3))
    # Z_l^0 are polynomials of degree l in cos(theta), so the chain is exact: quadrature (~1e-14) times
    # the conversion's amplification (max |C| = 53 at order 3)
    assert np.max(np.abs(f - f_true)) < 1e-11, f - f_true


def test_general_sh_function_converges_slowly_with_zonal_order():
    # m != 0 zonal functions vanish on both zone edges, an SH function does not: its zonal expansion,
    # hence its conversion back to SH, converges only algebraically (module docstring of sh.py)
    rng = np.random.default_rng(0)
    f_true = rng.normal(size=9)                                      # every (l, m) with l <= 2
    th, ph, w = rule(ZONE)
    h = sh_basis(th, ph, 2) @ f_true
    errs = []
    for order_zonal in (2, 4, 8, 16):
        z = zonal_basis(th, ph, order_zonal, ZONE).T @ (h * w)
        f = zonal_to_sh(z, zonal_to_sh_matrix(ZONE, order_zonal, 2))
        errs.append(float(np.linalg.norm(f - f_true) / np.linalg.norm(f_true)))
    # measured 10.2 %, 3.4 %, 1.04 %, 0.29 %: decreasing, and about order^-1.8
    assert all(a > b for a, b in zip(errs, errs[1:])), errs
    assert errs[0] > 0.05, errs          # the limitation is real at the thesis's orders
    assert errs[-1] < 5e-3, errs         # and goes away as the zonal order grows


def test_lambertian_slice_extrapolates_into_the_cap_exactly():
    rho = 0.18                                                        # the gray card of thesis 4.1.2
    th, ph, w = rule(ZONE)
    z = zonal_basis(th, ph, 1, ZONE).T @ (rho / math.pi * np.cos(th) * w)   # orders 0 and 1 only
    f = zonal_to_sh(z, zonal_to_sh_matrix(ZONE, 1))
    tc, pc, wc = rule(CAP, 50, 16)
    # cos(theta) is in both spans (Z_1^0 and Y_1^0 are affine in it): the cap is filled in exactly,
    # to quadrature round-off
    assert np.max(np.abs(evaluate_sh(f, tc, pc) - rho / math.pi * np.cos(tc))) < 1e-13
    th_h, ph_h, w_h = rule(Zone(0.0, math.pi / 2))
    # hemispherical reflectance of the extrapolated slice: rho (thesis 4.1.2 recovers the card this way)
    assert abs(np.sum(evaluate_sh(f, th_h, ph_h) * w_h) - rho) < 1e-13


def test_extrapolation_of_a_lobe_that_is_not_in_the_sh_span():
    # a smooth lobe exp(4 w.v) peaking at 17 deg: its SH fit on the zone is continued into the cap
    v = np.array([math.sin(0.3) * math.cos(0.5), math.sin(0.3) * math.sin(0.5), math.cos(0.3)])

    def lobe(th, ph):
        return np.exp(4 * (np.sin(th) * np.cos(ph) * v[0] + np.sin(th) * np.sin(ph) * v[1] + np.cos(th) * v[2]))

    th, ph, w = rule(ZONE)
    tc, pc, wc = rule(CAP, 50, 64)
    cap_err = {}
    for order in (2, 4, 6):
        z = zonal_basis(th, ph, order, ZONE).T @ (lobe(th, ph) * w)
        f = zonal_to_sh(z, zonal_to_sh_matrix(ZONE, order))
        cap_err[order] = math.sqrt(np.sum((evaluate_sh(f, tc, pc) - lobe(tc, pc)) ** 2 * wc) / np.sum(lobe(tc, pc) ** 2 * wc))
    # measured 8.7 %, 0.44 %, 0.18 %: the cap is filled in sensibly for a smooth lobe, better than the
    # zonal expansion fits the zone (1.8 % at order 6, limited by the edge behaviour of m != 0 functions);
    # at order 8 the cap error rises again to 0.38 % (conditioning, cond(M) = 1.2e11), not asserted here
    assert cap_err[2] > cap_err[4] > cap_err[6], cap_err
    assert cap_err[6] < 5e-3, cap_err


def test_conversion_is_exact_for_m0_and_a_projection_otherwise():
    conv = zonal_to_sh_matrix(ZONE, 4)
    res = conversion_residual(conv)
    m = basis_indices(4)[:, 1]
    # Z_l^0 lie in the SH span of order l: residual is quadrature round-off amplified by |C| (<= 265)
    assert np.max(res[m == 0]) < 1e-10, res[m == 0]
    # every Z_l^m with m != 0 has a part outside any finite SH span (measured 1.3 % to 75 %)
    assert np.min(res[m != 0]) > 1e-3, res[m != 0]
    # the conversion's own quadrature error estimate (doubling the polar nodes): measured 1.3e-12 against
    # max |C| = 265, i.e. round-off; 1e-9 relative would still be far below any use of C
    assert conv.quadrature_error < 1e-9 * np.max(np.abs(conv.matrix))


def test_ill_conditioning_is_reported_and_refused():
    conds = [zonal_to_sh_matrix(ZONE, L).condition for L in (2, 4, 6)]
    # the SH restricted to a hemisphere-like zone lose independence quickly (measured 2.5e2, 1.6e5, 1.3e8)
    assert conds[0] < conds[1] < conds[2] and conds[2] > 1e7, conds
    with pytest.raises(BasisError, match="order_sh = 12 is numerically unidentifiable"):
        zonal_to_sh_matrix(Zone(1.2, 1.4), 2, 12)


def test_conversion_residual_against_the_tests_own_quadrature():
    """Each residual ||Z_k - sum_p C[p, k] Y_p||_zone against the same norm on this file's rule
    (Gauss-Legendre in theta, 400 x 64 nodes): the integrand is a trigonometric polynomial in phi
    of degree 2 (order_zonal + order_sh) = 16 < 64, so both rules are exact in phi and differ by
    the polar rules' error: measured 2.7e-7 (rigcad's 200 nodes against 400 here), bound 1e-6.
    An azimuthal grid too coarse for degree 16 aliases by far more."""
    conv = zonal_to_sh_matrix(ZONE, 4)
    th, ph, w = rule(ZONE)
    Z = zonal_basis(th, ph, conv.order_zonal, ZONE)
    ref = np.sqrt(np.sum((Z - sh_basis(th, ph, conv.order_sh) @ conv.matrix) ** 2 * w[:, None], axis=0))
    assert np.max(np.abs(conversion_residual(conv) - ref)) < 1e-6


def test_evaluate_sh_refuses_a_wrong_shape():
    th, ph = np.array([0.3]), np.array([0.1])
    for bad in (np.zeros(10), np.zeros((1, 9))):  # K not a square; a 2D array with a square K
        with pytest.raises(BasisError, match=rf"shape \({bad.shape[0]},"):
            evaluate_sh(bad, th, ph)


def test_zone_gram_and_condition_against_the_tests_own_quadrature():
    """M = the SH Gram matrix over the zone and cond(M), against M built here on the test's rule
    (Gauss-Legendre in theta): products of SH of order 4 are polynomials of degree 8 in cos and
    sin, integrated to round-off by both rules (1e-12); cond(M) = 1.6e5 amplifies that to ~1e-7
    relative in the condition number, 1e-6 allowed. The dual (M^-1) times M is the identity."""
    conv = zonal_to_sh_matrix(ZONE, 4)
    th, ph, w = rule(ZONE)
    Y = sh_basis(th, ph, 4)
    M = (Y * w[:, None]).T @ Y
    assert np.max(np.abs(conv.zone_gram - M)) < 1e-12
    assert conv.condition == pytest.approx(np.linalg.cond(M), rel=1e-6)
    assert np.max(np.abs(conv.dual @ M - np.eye(len(M)))) < 1e-6  # cond(M) x 1e-12


def test_zonal_to_sh_refuses_a_wrong_length():
    conv = zonal_to_sh_matrix(ZONE, 2)
    with pytest.raises(BasisError, match=r"have 10 entries on the last axis: need 9 \(order 2\)"):
        zonal_to_sh(np.zeros(10), conv)


def test_an_explicit_polar_node_count_is_used():
    # 8 polar nodes are too few for order 4: C moves by far more than the default's round-off
    coarse = zonal_to_sh_matrix(ZONE, 4, n_polar=8)
    fine = zonal_to_sh_matrix(ZONE, 4)
    assert np.max(np.abs(coarse.matrix - fine.matrix)) > 1e-6
