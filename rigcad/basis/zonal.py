"""Zonal basis Z_l^m over a spherical zone (thesis 3.3, eqs. 3.1-3.4; Ghosh & Heidrich TR-2006-12).

Frame: the sample's local frame, normal +z, tangent +x; ``theta`` is the polar angle from the normal,
``phi`` the azimuth from +x towards +y, both in radians. The zone is
``alpha <= theta <= beta, 0 <= phi < 2 pi`` (the rig measures alpha = pi/20, beta = pi/2; thesis 3.4).

Mapping (eq. 3.1): ``x = cos(theta)`` runs over ``[a, b] = [cos beta, cos alpha]`` and the shifted
Legendre argument is the affine map ``t = (2 x - a - b) / (b - a)`` onto ``[-1, 1]``, so
``P^_l^m(x) = P_l^m(t)``. Because ``d omega = sin(theta) d theta d phi = dx d phi`` and
``dx = (b - a)/2 dt``, the normalisation of eq. 3.2,
``K_l^m = sqrt((2l+1)(l-|m|)! / (2 pi (b-a) (l+|m|)!))``, makes the set orthonormal under the
solid-angle measure over the zone.

Real form (eq. 3.3): ``Z_l^0 = K_l^0 P_l^0(t)``, ``Z_l^m = sqrt(2) K_l^m cos(m phi) P_l^m(t)`` for
m > 0 and ``Z_l^m = sqrt(2) K_l^|m| sin(|m| phi) P_l^|m|(t)`` for m < 0, with m in -l..l (the thesis
writes m in 0..l but uses negative m in eq. 3.3; its third case "m < 0" is a typo for m = 0).
Sign convention: no Condon-Shortley phase (P_l^m >= 0 near t = 1), as in real spherical harmonics
used for rendering; it changes signs only, not orthonormality.

Consequences worth knowing: for m != 0 the factor ``(1 - t^2)^(|m|/2)`` vanishes on *both* zone
edges (theta = alpha and theta = beta); for m = 0, Z_l^0 is a polynomial of degree l in cos(theta),
so ``cos(theta)`` (a Lambertian slice, eq. 4.1) lies exactly in span{Z_0^0, Z_1^0}. With
``alpha = 0, beta = pi`` the zonal basis *is* the real spherical-harmonic basis (used by sh.py).

Basis index k of (l, m) is ``l*l + l + m`` (the usual SH ordering); order L means l <= L, that is
``(L + 1)**2`` functions. Evaluation uses the three-term recurrences of the fully normalised
associated Legendre functions (no explicit polynomial coefficients, no factorials), which are
stable for the orders used here (tested to 1e-10 orthonormality up to order 12 and against
scipy.special.lpmv).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.errors import BasisError

#: Slack (radians) allowed outside the zone before evaluation is refused: round-off in callers'
#: angle computations (acos of a unit vector's z), far below any pixel's angular size.
ZONE_EDGE_SLACK_RAD = 1e-9


@dataclass(frozen=True)
class Zone:
    """The measurable zone ``alpha_rad <= theta <= beta_rad`` (full azimuth), polar angles in radians."""

    alpha_rad: float
    beta_rad: float

    def __post_init__(self) -> None:
        a, b = self.alpha_rad, self.beta_rad
        if not (math.isfinite(a) and math.isfinite(b)) or not (0.0 <= a < b <= math.pi):
            raise BasisError(
                f"zone alpha_rad = {a!r}, beta_rad = {b!r}: need 0 <= alpha_rad < beta_rad <= pi "
                "(polar angles from the sample normal, in radians)", param="basis.zone")

    @property
    def x_low(self) -> float:
        """a = cos(beta) of eq. 3.1: the lower end of x = cos(theta) over the zone."""
        return math.cos(self.beta_rad)

    @property
    def x_high(self) -> float:
        """b = cos(alpha) of eq. 3.1: the upper end of x = cos(theta) over the zone."""
        return math.cos(self.alpha_rad)

    @property
    def solid_angle_sr(self) -> float:
        """Solid angle of the zone, 2 pi (b - a), in steradians."""
        return 2.0 * math.pi * (self.x_high - self.x_low)

    def contains(self, theta_rad: np.ndarray) -> np.ndarray:
        """Boolean mask of polar angles (radians) inside the zone, edges included, with the
        ZONE_EDGE_SLACK_RAD that :meth:`shifted_cosine` accepts: a direction the rig puts on an edge
        (the design's theta range ends on it) is in on every CPU, whichever way its acos rounded."""
        th = np.asarray(theta_rad, dtype=float)
        return (th >= self.alpha_rad - ZONE_EDGE_SLACK_RAD) & (th <= self.beta_rad + ZONE_EDGE_SLACK_RAD)

    def shifted_cosine(self, theta_rad: np.ndarray) -> np.ndarray:
        """t = (2 cos(theta) - a - b) / (b - a) in [-1, 1] (eq. 3.1's shift), same shape as ``theta_rad``.

        Raises BasisError if any angle lies outside the zone by more than ZONE_EDGE_SLACK_RAD.
        """
        th = np.asarray(theta_rad, dtype=float)
        bad = ~((th >= self.alpha_rad - ZONE_EDGE_SLACK_RAD) & (th <= self.beta_rad + ZONE_EDGE_SLACK_RAD))
        if np.any(bad):
            worst = float(th[bad].flat[0])
            raise BasisError(
                f"theta_rad = {worst!r} ({int(np.count_nonzero(bad))} value(s)) outside the zone "
                f"[{self.alpha_rad!r}, {self.beta_rad!r}] rad: mask samples outside the zone before "
                "evaluating the zonal basis")
        a, b = self.x_low, self.x_high
        t = (2.0 * np.cos(th) - a - b) / (b - a)
        return np.clip(t, -1.0, 1.0)


def check_order(order: int) -> int:
    """``order`` as an int >= 0, or BasisError naming the value."""
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
        raise BasisError(f"basis order = {order!r}: need an integer >= 0 (the largest l)", param="basis.order")
    return int(order)


def basis_count(order: int) -> int:
    """Number of functions with l <= order: (order + 1)**2."""
    return (check_order(order) + 1) ** 2


def basis_index(l: int, m: int) -> int:
    """Position k = l*l + l + m of Z_l^m in the basis arrays (|m| <= l)."""
    if not (0 <= abs(m) <= l):
        raise BasisError(f"(l, m) = ({l}, {m}): need l >= 0 and -l <= m <= l")
    return l * l + l + m


def basis_indices(order: int) -> np.ndarray:
    """(K, 2) int array of (l, m) in basis order: l = 0..order, m = -l..l."""
    L = check_order(order)
    return np.array([(l, m) for l in range(L + 1) for m in range(-l, l + 1)], dtype=int).reshape(-1, 2)


def normalized_legendre(t: np.ndarray, order: int) -> np.ndarray:
    """Fully normalised associated Legendre functions N_l^m(t), shape t.shape + (order+1, order+1).

    ``N_l^m(t) = sqrt((2l+1)/2 (l-m)!/(l+m)!) P_l^m(t)`` without the Condon-Shortley phase, for
    0 <= m <= l <= order (entries with m > l are 0); orthonormal on [-1, 1] under dt for each m.
    Three-term recurrences on the normalised functions (sectoral seed, then in l); ``t`` must lie in
    [-1, 1]. Error: a few ulps per recurrence step (checked against scipy.special.lpmv in tests).
    """
    L = check_order(order)
    t = np.asarray(t, dtype=float)
    s = np.sqrt(np.maximum((1.0 - t) * (1.0 + t), 0.0))
    out = np.zeros(t.shape + (L + 1, L + 1))
    pmm = np.full(t.shape, math.sqrt(0.5))
    for m in range(L + 1):
        if m > 0:
            pmm = pmm * (math.sqrt((2.0 * m + 1.0) / (2.0 * m)) * s)
        out[..., m, m] = pmm
        if m == L:
            break
        p_prev, p = pmm, math.sqrt(2.0 * m + 3.0) * t * pmm
        out[..., m + 1, m] = p
        for l in range(m + 2, L + 1):
            ll, mm = float(l * l), float(m * m)
            a = math.sqrt((4.0 * ll - 1.0) / (ll - mm))
            b = math.sqrt(((l - 1.0) ** 2 - mm) * (2.0 * l + 1.0) / ((2.0 * l - 3.0) * (ll - mm)))
            p_prev, p = p, a * t * p - b * p_prev
            out[..., l, m] = p
    return out


def real_basis(t: np.ndarray, phi: np.ndarray, order: int, radial_scale: float) -> np.ndarray:
    """Real-form basis values (..., K) from Legendre arguments t in [-1, 1] and azimuths phi (radians).

    ``radial_scale * N_l^m(t)`` times 1/sqrt(2 pi) (m = 0) or cos/sin(|m| phi)/sqrt(pi) (m != 0):
    with t the zone's shifted cosine and radial_scale = sqrt(2/(b - a)) this is the zonal basis;
    with t = cos(theta) and radial_scale = 1, the real spherical harmonics.
    """
    t, phi = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(phi, dtype=float))
    N = normalized_legendre(t, order)
    out = np.empty(t.shape + ((order + 1) ** 2,))
    c0 = radial_scale / math.sqrt(2.0 * math.pi)
    cm = radial_scale / math.sqrt(math.pi)
    for m in range(order + 1):
        if m == 0:
            for l in range(order + 1):
                out[..., l * l + l] = c0 * N[..., l, 0]
            continue
        cos_m, sin_m = cm * np.cos(m * phi), cm * np.sin(m * phi)
        for l in range(m, order + 1):
            out[..., l * l + l + m] = cos_m * N[..., l, m]
            out[..., l * l + l - m] = sin_m * N[..., l, m]
    return out


def zonal_basis(theta_rad: np.ndarray, phi_rad: np.ndarray, order: int, zone: Zone) -> np.ndarray:
    """All Z_l^m with l <= order at directions (theta_rad, phi_rad): shape broadcast(theta, phi) + (K,).

    Units: radians in, values in 1/sqrt(sr) (so that sum_k of squares integrates to K over the zone).
    Orthonormal over ``zone`` under d omega = sin(theta) d theta d phi (eqs. 3.1-3.3). Directions
    outside the zone raise BasisError (mask them first: the projector sends no light there).
    """
    L = check_order(order)
    t = zone.shifted_cosine(theta_rad)
    return real_basis(t, phi_rad, L, math.sqrt(2.0 / (zone.x_high - zone.x_low)))


def direction_angles(directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(theta_rad, phi_rad) of unit vectors (..., 3) in the local frame (normal +z, tangent +x)."""
    d = np.asarray(directions, dtype=float)
    if d.shape[-1] != 3:
        raise BasisError(f"directions have shape {d.shape}: need (..., 3) unit vectors")
    theta = np.arctan2(np.hypot(d[..., 0], d[..., 1]), d[..., 2])
    return theta, np.arctan2(d[..., 1], d[..., 0])


def angles_to_directions(theta_rad: np.ndarray, phi_rad: np.ndarray) -> np.ndarray:
    """Unit vectors (..., 3) in the local frame from polar/azimuth angles in radians."""
    th, ph = np.broadcast_arrays(np.asarray(theta_rad, dtype=float), np.asarray(phi_rad, dtype=float))
    st = np.sin(th)
    return np.stack([st * np.cos(ph), st * np.sin(ph), np.cos(th)], axis=-1)


def zone_rule(zone: Zone, n_polar: int, n_azimuth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The factors of :func:`zone_quadrature`'s product rule: (theta_rad (n_polar,), polar weights
    (n_polar,), phi_rad (n_azimuth,), azimuth weights (n_azimuth,)); node (i, j) has weight
    w_theta[i] * w_phi[j] sr."""
    if n_polar < 1 or n_azimuth < 1:
        raise BasisError(f"quadrature sizes n_polar = {n_polar}, n_azimuth = {n_azimuth}: need >= 1 each")
    g, w = np.polynomial.legendre.leggauss(int(n_polar))
    u = 0.5 * math.pi * (g + 1.0)
    t = np.cos(u)
    a, b = zone.x_low, zone.x_high
    x = 0.5 * (a + b) + 0.5 * (b - a) * t
    theta = np.arccos(np.clip(x, -1.0, 1.0))
    w_polar = 0.5 * (b - a) * np.sin(u) * (0.5 * math.pi * w)
    phi = 2.0 * math.pi * np.arange(int(n_azimuth)) / n_azimuth
    return theta, w_polar, phi, np.full(int(n_azimuth), 2.0 * math.pi / n_azimuth)


def zone_quadrature(zone: Zone, n_polar: int, n_azimuth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product rule over the zone: (theta_rad, phi_rad, weight_sr), each flat of n_polar * n_azimuth.

    Polar: t = cos(u) (so d omega = (b - a)/2 sin(u) du d phi) with Gauss-Legendre in u over [0, pi];
    this absorbs the sqrt(1 - t^2) edge factors of the m != 0 zonal functions, so integrands mixing
    zonal and spherical functions (sh.py) converge geometrically in n_polar instead of algebraically.
    Azimuth: equispaced nodes (periodic trapezoid rule), exact for trigonometric polynomials of
    degree < n_azimuth. Weights sum to the zone's solid angle to round-off.
    """
    theta, w_polar, phi, w_az = zone_rule(zone, n_polar, n_azimuth)
    TH, PH = np.meshgrid(theta, phi, indexing="ij")
    W = np.broadcast_to(w_polar[:, None] * w_az[None, :], TH.shape)
    return TH.ravel(), PH.ravel(), np.ascontiguousarray(W).ravel()


def zonal_moments(theta_rad: np.ndarray, phi_rad: np.ndarray, values: np.ndarray, order: int, zone: Zone) -> np.ndarray:
    """sum_ij values[..., i, j] Z_k(theta_i, phi_j) for every k (shape values.shape[:-2] + (K,)): the
    zonal coefficients of a function sampled on a product grid theta (n_t,) x phi (n_p,) with its
    quadrature weights already multiplied in; ``phi_rad`` (n_t, n_p) gives each polar row its own
    azimuths instead, and a scalar ``phi_rad`` is a single azimuth (values (..., n_t, 1)). Separable (Legendre factors on theta, cos/sin(m phi)
    on phi, as :func:`real_basis`), so it costs O(n_t n_p order) instead of O(n_t n_p K) for the
    dense ``values.ravel() @ zonal_basis(...)``, which it equals to round-off (tested)."""
    L = check_order(order)
    g = np.asarray(values, dtype=float)
    th = np.asarray(theta_rad, dtype=float)
    ph = np.atleast_1d(np.asarray(phi_rad, dtype=float))  # a scalar phi is a rule of one azimuth
    rows = ph.ndim == 2  # an azimuth rule of its own per polar row
    n_p = ph.shape[-1]
    if g.shape[-2:] != (th.size, n_p) or (rows and ph.shape != (th.size, n_p)) or ph.ndim > 2:
        raise BasisError(f"values have shape {g.shape}, phi {ph.shape}: need values (..., {th.size}, n_phi) "
                         "(theta x phi) and phi (n_phi,) or (n_theta, n_phi)")
    N = normalized_legendre(zone.shifted_cosine(th), L)  # (n_t, L+1, L+1)
    radial = math.sqrt(2.0 / (zone.x_high - zone.x_low))
    out = np.empty(g.shape[:-2] + ((L + 1) ** 2,))
    ls = np.arange(L + 1)

    def azimuthal(trig):  # sum over phi of g times trig(phi), shape (..., n_t)
        return (g * trig).sum(axis=-1) if rows else g @ trig

    for m in range(L + 1):
        if m == 0:
            a = g.sum(axis=-1) * (radial / math.sqrt(2.0 * math.pi))  # (..., n_t)
            out[..., ls * ls + ls] = a @ N[:, :, 0]
            continue
        lm = ls[m:]
        c = radial / math.sqrt(math.pi)
        out[..., lm * lm + lm + m] = azimuthal(c * np.cos(m * ph)) @ N[:, m:, m]
        out[..., lm * lm + lm - m] = azimuthal(c * np.sin(m * ph)) @ N[:, m:, m]
    return out
