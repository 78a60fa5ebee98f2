"""Zonal to spherical-harmonic change of basis through the dual basis, and extrapolation into the cap.

Thesis 3.3 ("Projecting zonal basis to spherical harmonics", eqs. 3.5-3.7) and 4.2.3 ("Basis
Projection and Extrapolation"). Real spherical harmonics Y_p (same real form, ordering and sign
convention as the zonal basis; they are the zonal basis of the whole sphere, alpha = 0, beta = pi)
are not orthogonal over the zone. With the zone Gram matrix ``M[r, s] = int_zone Y_r Y_s d omega``,
the dual functions ``Yhat_p = sum_r c[p, r] Y_r`` (eq. 3.6) with ``c = M^-1`` satisfy
``int_zone Y_l Yhat_p d omega = delta_lp`` (eq. 3.5), and the change of basis is
``C[p, k] = int_zone Z_k Yhat_p d omega = (M^-1 A)[p, k]`` with ``A[r, k] = int_zone Y_r Z_k d omega``
(eq. 3.7). SH coefficients of a zonal expansion ``g = sum_k z_k Z_k`` are ``f = C z``.

What this computes: ``sum_p f_p Y_p`` is the least-squares fit of g *over the zone* by spherical
harmonics of the chosen order (``M f = A z`` are its normal equations). Consequences:
- if g restricted to the zone is itself a finite SH expansion of that order, f is exact;
- Z_l^0 is a polynomial of degree l in cos(theta), hence in the SH span of order l: axially
  symmetric content converts exactly; Z_l^m with m != 0 contains (1 - t^2)^(|m|/2), which is not
  sin^|m|(theta) unless the zone is the whole sphere, so it is *not* in any finite SH span and
  its conversion is a projection with a residual (reported by :func:`conversion_residual`);
- extrapolation (4.2.3, Figure 3.10 step 5) is evaluating ``sum_p f_p Y_p`` in the cap
  theta < alpha (and anywhere else): the polynomial fitted on the zone, continued. It is exact
  for functions in the SH span and otherwise unconstrained by data; its error grows with the
  SH order and the cap size, and M's condition number (reported) says how much the fit
  amplifies noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.basis.zonal import Zone, check_order, real_basis, zonal_basis, zone_quadrature
from rigcad.errors import BasisError


def sh_basis(theta_rad: np.ndarray, phi_rad: np.ndarray, order: int) -> np.ndarray:
    """Real spherical harmonics Y_l^m, l <= order, at (theta, phi) in radians: broadcast shape + (K,), 1/sqrt(sr).

    Y_l^0 = sqrt((2l+1)/(4 pi)) P_l(cos theta); m > 0: sqrt(2) K cos(m phi) P_l^m; m < 0:
    sqrt(2) K sin(|m| phi) P_l^|m|; no Condon-Shortley phase; index l*l + l + m. Orthonormal over
    the whole sphere.
    """
    L = check_order(order)
    th = np.asarray(theta_rad, dtype=float)
    return real_basis(np.cos(th), phi_rad, L, 1.0)


@dataclass(frozen=True)
class ZonalToSH:
    """The change of basis of eq. 3.7 for one zone and pair of orders.

    ``matrix`` C (K_sh, K_z): SH coefficients = C @ zonal coefficients. ``dual`` c (K_sh, K_sh):
    rows are the dual functions' SH coefficients (eq. 3.6). ``zone_gram`` M (K_sh, K_sh).
    ``condition`` = cond_2(M). ``quadrature_error``: max |C_n - C_2n| between the quadrature used
    and one with twice the polar nodes (an estimate of the error in C's entries).
    """

    zone: Zone
    order_zonal: int
    order_sh: int
    matrix: np.ndarray
    dual: np.ndarray
    zone_gram: np.ndarray
    condition: float
    quadrature_error: float


def _solve(zone: Zone, order_zonal: int, order_sh: int, n_polar: int, n_azimuth: int):
    """(C, R) with C = M^-1 A solved as weighted least squares by QR, and M = R^T R.

    Solving through the QR factor of W^1/2 Y instead of forming M squares the accuracy: the
    least-squares problem has condition sqrt(cond(M)), and cond(M) reaches 1e11 at order 8.
    """
    th, ph, w = zone_quadrature(zone, n_polar, n_azimuth)
    sw = np.sqrt(w)[:, None]
    Yw = sh_basis(th, ph, order_sh) * sw
    Zw = zonal_basis(th, ph, order_zonal, zone) * sw
    Q, R = np.linalg.qr(Yw)
    C = np.linalg.solve(R, Q.T @ Zw)
    return C, R


def zonal_to_sh_matrix(zone: Zone, order_zonal: int, order_sh: int | None = None,
                       n_polar: int | None = None) -> ZonalToSH:
    """Build C = M^-1 A (eq. 3.7) by product quadrature over the zone (:func:`zone_quadrature`).

    ``order_sh`` defaults to ``order_zonal`` (the thesis's pairing). The azimuthal rule is exact
    for the products involved (n_azimuth = 2 (order_zonal + order_sh) + 2); the polar rule
    (default n_polar = 4 (order_zonal + order_sh) + 40) converges geometrically; C's error is
    estimated by repeating with twice the polar nodes. Raises BasisError if M is numerically
    singular (cond(M) > 1e24, i.e. the QR factor's condition beyond 1e12).
    """
    Lz = check_order(order_zonal)
    Ls = Lz if order_sh is None else check_order(order_sh)
    n_az = 2 * (Lz + Ls) + 2
    n_pol = n_polar if n_polar is not None else 4 * (Lz + Ls) + 40
    C, R = _solve(zone, Lz, Ls, n_pol, n_az)
    cond_r = float(np.linalg.cond(R))
    if not cond_r < 1e12:
        raise BasisError(
            f"SH order_sh = {Ls} is numerically unidentifiable on the zone [{zone.alpha_rad:.4g}, "
            f"{zone.beta_rad:.4g}] rad (zone Gram condition number {cond_r**2:.3g}): use a lower order_sh")
    R_inv = np.linalg.inv(R)
    dual = R_inv @ R_inv.T
    C2, _ = _solve(zone, Lz, Ls, 2 * n_pol, n_az)
    return ZonalToSH(zone, Lz, Ls, C, 0.5 * (dual + dual.T), R.T @ R, cond_r**2, float(np.max(np.abs(C - C2))))


def zonal_to_sh(zonal_coefficients: np.ndarray, conversion: ZonalToSH) -> np.ndarray:
    """SH coefficients (..., K_sh) from zonal coefficients (..., K_z): f = C z along the last axis."""
    z = np.asarray(zonal_coefficients, dtype=float)
    K = conversion.matrix.shape[1]
    if z.shape[-1] != K:
        raise BasisError(f"zonal coefficients have {z.shape[-1]} entries on the last axis: need {K} "
                         f"(order {conversion.order_zonal})")
    return z @ conversion.matrix.T


def evaluate_sh(coefficients: np.ndarray, theta_rad: np.ndarray, phi_rad: np.ndarray) -> np.ndarray:
    """sum_p f_p Y_p(theta, phi) for coefficients (K_sh,) at any directions (radians): the extrapolant.

    Inside the zone this is the least-squares fit; in the cap theta < alpha (and below beta) it is
    its polynomial continuation (module docstring).
    """
    f = np.asarray(coefficients, dtype=float)
    L = int(round(math.sqrt(f.shape[-1]))) - 1
    if f.ndim != 1 or (L + 1) ** 2 != f.shape[-1]:
        raise BasisError(f"SH coefficients have shape {f.shape}: need (K,) with K = (order + 1)**2")
    return sh_basis(theta_rad, phi_rad, L) @ f


def conversion_residual(conversion: ZonalToSH, n_polar: int = 200) -> np.ndarray:
    """Per zonal function, ||Z_k - sum_p C[p, k] Y_p||_zone (relative, since ||Z_k|| = 1): the part not in the SH span.

    0 (to quadrature accuracy) for m = 0 functions with l <= order_sh; > 0 for every m != 0
    function on a zone other than the whole sphere.
    """
    zone = conversion.zone
    n_az = 2 * (conversion.order_zonal + conversion.order_sh) + 2
    th, ph, w = zone_quadrature(zone, n_polar, n_az)
    Z = zonal_basis(th, ph, conversion.order_zonal, zone)
    fit = sh_basis(th, ph, conversion.order_sh) @ conversion.matrix
    return np.sqrt(np.sum((Z - fit) ** 2 * w[:, None], axis=0))
