"""The zonal basis on discrete illumination samples: Gram matrices, projector quantisation, re-orthonormalisation.

An illumination sampling is one entry per projector pixel (or any other discretisation): the
incidence direction of the light it sends onto the sample (theta, phi in the local frame, radians),
the solid angle it covers (steradians) and whether it reaches the zone at all. The discrete inner
product of two illumination patterns is ``<f, g> = sum_j valid_j w_j f_j g_j``; the *Gram matrix*
of the basis under it is ``G = B^T W B`` with ``B[j, k] = Z_k(theta_j, phi_j)``. The continuous
basis is orthonormal (G = I); the discrete one is not, and quantising the images (thesis 4.2.1)
moves it further. Re-orthonormalising the *quantised* vectors under the weights gives a set that
is exactly orthonormal on the samples; the rig projects the quantised images and applies the
re-orthonormalising transform to the measured responses afterwards (it is linear).

Thesis 4.2.1, reproduced by :func:`quantise_images`: one scale for all images (the largest |value|
over every image), positive and negative parts stored as separate non-negative integer images
(8-bit in the thesis), responses to the negative image subtracted from the positive one later.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.basis.zonal import Zone, angles_to_directions, check_order, zonal_basis
from rigcad.errors import BasisError


@dataclass(frozen=True)
class IlluminationSampling:
    """Illumination samples: per-sample incidence angles (radians), solid angles (sr) and a validity mask.

    Arrays are 1-D of one length n. ``valid`` marks samples that carry light into the zone (a
    projector pixel off the paraboloid, or one whose ray leaves the zone, is invalid).
    """

    theta_rad: np.ndarray
    phi_rad: np.ndarray
    weight_sr: np.ndarray
    valid: np.ndarray

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("theta_rad", "phi_rad", "weight_sr"):
            a = np.asarray(getattr(self, name), dtype=float)
            if a.ndim != 1:
                raise BasisError(f"sampling {name} has shape {a.shape}: need a 1-D array, one entry per sample")
            arrays[name] = a
        valid = np.asarray(self.valid, dtype=bool)
        n = arrays["theta_rad"].size
        if any(a.size != n for a in arrays.values()) or valid.shape != (n,):
            shapes = {k: v.shape for k, v in arrays.items()} | {"valid": valid.shape}
            raise BasisError(f"sampling arrays differ in length: {shapes}: need one entry per sample in each")
        w = arrays["weight_sr"]
        if not np.all(np.isfinite(w[valid])) or np.any(w[valid] < 0):
            raise BasisError("sampling weight_sr has negative or non-finite entries on valid samples: "
                             "solid angles must be finite and >= 0 steradians")
        for name, a in arrays.items():
            object.__setattr__(self, name, a)
        object.__setattr__(self, "valid", valid)

    @property
    def size(self) -> int:
        """Number of samples n (valid or not)."""
        return int(self.theta_rad.size)

    def directions(self) -> np.ndarray:
        """Unit incidence directions (n, 3) in the local frame."""
        return angles_to_directions(self.theta_rad, self.phi_rad)

    def valid_weights(self) -> np.ndarray:
        """Weights (n,) in sr with invalid samples set to 0."""
        return np.where(self.valid, self.weight_sr, 0.0)

    def pitch_rad(self) -> float:
        """Angular pitch: side of a square cell with the median valid solid angle, sqrt(median w) (rad)."""
        w = self.weight_sr[self.valid]
        if w.size == 0:
            raise BasisError("sampling has no valid sample: nothing illuminates the zone")
        return float(math.sqrt(np.median(w)))


def equal_area_sampling(zone: Zone, n_polar: int, n_azimuth: int) -> IlluminationSampling:
    """Synthetic projector: n_polar x n_azimuth cells equal in cos(theta) and phi, sampled at cell centres.

    Every cell covers (b - a)/n_polar * 2 pi/n_azimuth sr, so the cells tile the zone exactly and the
    discrete inner product is the midpoint rule in cos(theta) (error O(n_polar^-2) for smooth
    integrands) times the periodic trapezoid rule in phi (exact for trigonometric polynomials of
    degree < n_azimuth). All samples are valid.
    """
    if n_polar < 1 or n_azimuth < 1:
        raise BasisError(f"equal-area sampling n_polar = {n_polar}, n_azimuth = {n_azimuth}: need >= 1 each")
    a, b = zone.x_low, zone.x_high
    x = a + (b - a) * (np.arange(n_polar) + 0.5) / n_polar
    phi = 2.0 * math.pi * (np.arange(n_azimuth) + 0.5) / n_azimuth
    TH, PH = np.meshgrid(np.arccos(x), phi, indexing="ij")
    w = (b - a) / n_polar * 2.0 * math.pi / n_azimuth
    n = TH.size
    return IlluminationSampling(TH.ravel(), PH.ravel(), np.full(n, w), np.ones(n, dtype=bool))


def basis_images(sampling: IlluminationSampling, order: int, zone: Zone) -> np.ndarray:
    """Zonal basis values at the samples, (n, K); invalid samples are 0 (no light)."""
    L = check_order(order)
    out = np.zeros((sampling.size, (L + 1) ** 2))
    v = sampling.valid
    out[v] = zonal_basis(sampling.theta_rad[v], sampling.phi_rad[v], L, zone)
    return out


def gram(values: np.ndarray, sampling: IlluminationSampling) -> np.ndarray:
    """Discrete Gram matrix G = V^T W V (K, K) of sampled functions ``values`` (n, K) under the weights."""
    V = np.asarray(values, dtype=float)
    if V.ndim != 2 or V.shape[0] != sampling.size:
        raise BasisError(f"values have shape {V.shape}: need (n, K) with n = {sampling.size} samples")
    w = sampling.valid_weights()
    return V.T @ (V * w[:, None])


def discrete_gram(sampling: IlluminationSampling, order: int, zone: Zone) -> np.ndarray:
    """Gram matrix (K, K) of the analytic zonal basis on the samples (identity for exact quadrature)."""
    return gram(basis_images(sampling, order, zone), sampling)


@dataclass(frozen=True)
class OffIdentity:
    """How far a Gram matrix is from I: largest |G_ij| (i != j), largest |G_ii - 1|, and their max."""

    max_offdiag: float
    max_diag_deviation: float

    @property
    def max_abs(self) -> float:
        """max |G - I| over all entries."""
        return max(self.max_offdiag, self.max_diag_deviation)


def off_identity(G: np.ndarray) -> OffIdentity:
    """Distance of a square Gram matrix from the identity (see :class:`OffIdentity`)."""
    G = np.asarray(G, dtype=float)
    if G.ndim != 2 or G.shape[0] != G.shape[1]:
        raise BasisError(f"Gram matrix has shape {G.shape}: need a square (K, K) array")
    off = G - np.diag(np.diag(G))
    return OffIdentity(float(np.max(np.abs(off))) if G.size > 1 else 0.0,
                       float(np.max(np.abs(np.diag(G) - 1.0))))


@dataclass(frozen=True)
class QuantisedImages:
    """Projector images after thesis 4.2.1 preprocessing.

    ``positive`` and ``negative`` (K, n) hold integer levels 0..2**bits - 1 (uint8 or uint16) of the
    positive and negative parts; level q stands for the value ``q * scale / (2**bits - 1)``, with
    ``scale`` the largest |value| over all images (one scale for all, so relative brightness between
    images is kept).
    """

    positive: np.ndarray
    negative: np.ndarray
    scale: float
    bits: int

    @property
    def levels(self) -> int:
        """Largest integer level, 2**bits - 1."""
        return (1 << self.bits) - 1

    def values(self) -> np.ndarray:
        """Signed values the projector displays, (n, K): (positive - negative) * scale / levels."""
        q = self.positive.astype(np.int64) - self.negative.astype(np.int64)
        return (q.T * (self.scale / self.levels)).astype(float)


def quantise_images(values: np.ndarray, bits: int, rounding: str = "nearest") -> QuantisedImages:
    """Quantise basis images ``values`` (n, K) as thesis 4.2.1: one scale, split signs, ``bits``-bit levels.

    ``rounding`` is "nearest" (round half to even) or "truncate" (towards zero, as a C cast from
    float would do; the thesis does not say which it used). Error per sample: at most half a level
    (nearest) or one level (truncate) of ``scale / (2**bits - 1)``.
    """
    if bits not in (8, 16):
        raise BasisError(f"quantisation bits = {bits!r}: need 8 or 16 (projector image depth)")
    if rounding not in ("nearest", "truncate"):
        raise BasisError(f"quantisation rounding = {rounding!r}: need 'nearest' or 'truncate'")
    V = np.asarray(values, dtype=float)
    if V.ndim != 2 or not np.all(np.isfinite(V)):
        raise BasisError(f"basis images have shape {V.shape} or non-finite values: need finite (n, K)")
    scale = float(np.max(np.abs(V)))
    if scale == 0.0:
        raise BasisError("basis images are all zero: nothing to quantise (no valid sample?)")
    levels = (1 << bits) - 1
    r = np.abs(V) / scale * levels
    q = np.rint(r) if rounding == "nearest" else np.floor(r)
    q = np.minimum(q, levels)
    dtype = np.uint8 if bits == 8 else np.uint16
    pos = np.where(V > 0, q, 0).T.astype(dtype)
    neg = np.where(V < 0, q, 0).T.astype(dtype)
    return QuantisedImages(np.ascontiguousarray(pos), np.ascontiguousarray(neg), scale, bits)


@dataclass(frozen=True)
class Reorthonormalised:
    """A set re-orthonormalised over the samples.

    ``functions`` (n, K) = ``values @ transform``; ``transform`` (K, K) is what to apply to measured
    responses (row vector of K responses times ``transform``) to get coefficients in this set;
    ``gram_after`` is its discrete Gram matrix (identity to round-off); ``deviation`` (K,) is the
    weighted L2 distance of each new function from the reference (analytic) one, in units of the
    reference norm (1 for the orthonormal zonal functions), or None without a reference.
    """

    functions: np.ndarray
    transform: np.ndarray
    gram_after: np.ndarray
    deviation: np.ndarray | None
    method: str


def reorthonormalise(values: np.ndarray, sampling: IlluminationSampling, method: str = "lowdin",
                     reference: np.ndarray | None = None) -> Reorthonormalised:
    """Orthonormalise sampled functions ``values`` (n, K) under the sample weights.

    ``method``: "lowdin" (symmetric, T = G^-1/2: of all orthonormal sets spanning the same space,
    the closest to the input in the summed squared weighted L2 norm, so every function moves a
    little) or "cholesky" (T = L^-T with G = L L^T: Gram-Schmidt in basis order, low orders move
    least, high orders absorb the correction). ``reference`` (n, K), usually the analytic basis at
    the samples, is what ``deviation`` is measured against. Raises BasisError when G is not
    positive definite (the sampled functions are linearly dependent: too few valid samples for the
    order, or too coarse a quantisation).
    """
    if method not in ("lowdin", "cholesky"):
        raise BasisError(f"re-orthonormalisation method = {method!r}: need 'lowdin' or 'cholesky'")
    V = np.asarray(values, dtype=float)
    G = gram(V, sampling)
    evals, evecs = np.linalg.eigh(G)
    # relative floor: below it the smallest direction is round-off, not signal
    if evals[0] <= evals[-1] * 1e-12:
        raise BasisError(
            f"Gram matrix of the sampled functions is singular (eigenvalues {evals[0]:.3g} .. {evals[-1]:.3g}): "
            "the functions are linearly dependent on these samples; use more valid samples, a lower "
            "order or more quantisation bits")
    if method == "lowdin":
        T = (evecs / np.sqrt(evals)) @ evecs.T
    else:
        Lc = np.linalg.cholesky(G)
        T = np.linalg.inv(Lc).T
    F = V @ T
    dev = None
    if reference is not None:
        R = np.asarray(reference, dtype=float)
        if R.shape != V.shape:
            raise BasisError(f"reference has shape {R.shape}: need the shape of values {V.shape}")
        w = sampling.valid_weights()
        dev = np.sqrt(np.sum((F - R) ** 2 * w[:, None], axis=0) / np.sum(R**2 * w[:, None], axis=0))
    return Reorthonormalised(F, T, gram(F, sampling), dev, method)
