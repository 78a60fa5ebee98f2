"""2D ray trace in the meridional plane: COP -> paraboloid -> dome -> sample plane z = 0.

The dome is traced as a geometric curve, independent of how it was built: a smooth profile as its
one quintic interpolating spline (``DomeProfile.spline``, shared with the 3D surfaces; normals from
its derivative), the thesis's polyline as its flat segments. Both halves of the section are traced (x < 0 mirrored),
so horizontal misalignments that break the symmetry are handled. Vectorised over rays (n, 2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.dome import DomeProfile
from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.vec import reflect, unit

#: Ray status codes in :class:`Trace`.
OK, MISSED_PARABOLOID, MISSED_DOME, OCCLUDED, ESCAPED = 0, 1, 2, 3, 4
STATUS_NAMES = {OK: "ok", MISSED_PARABOLOID: "missed_paraboloid", MISSED_DOME: "missed_dome",
                OCCLUDED: "occluded_by_paraboloid", ESCAPED: "escaped"}

_CHUNK = 2_000_000  # rays x segments per block in the vectorised crossing search (memory bound)


def _side(p: np.ndarray, o: np.ndarray, d: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """cross(p - o, d) for (k, 2) points, origins and directions, and whether it lies within its own
    rounding of zero: |error| <= 3 u (|p_x - o_x| |d_y| + |p_y - o_y| |d_x|) + u (|p| + |o|) |d|
    (u = eps / 2, one rounding per operation), bounded here by 8 eps (|p| + |o|) . |d|, a margin scaled
    to the operands so that no hit at a node rests on the last bits of the products."""
    c = (p[:, 0] - o[:, 0]) * d[:, 1] - (p[:, 1] - o[:, 1]) * d[:, 0]
    scale = (np.abs(p[:, 0]) + np.abs(o[:, 0])) * np.abs(d[:, 1]) + (np.abs(p[:, 1]) + np.abs(o[:, 1])) * np.abs(d[:, 0])
    return c, np.abs(c) <= 8 * eps * scale


@dataclass(frozen=True)
class DomeCurve:
    """Right half of the dome section (mm), shifted sideways by ``dx``; parameter: the design's s."""

    kind: str
    s: np.ndarray  #: increasing node parameters
    points: np.ndarray  #: (m, 2) node points
    spline: object | None  #: the profile's spline in u = -s (DomeProfile.spline); None for a polyline
    dx: float = 0.0

    @classmethod
    def from_profile(cls, profile: DomeProfile, dx: float = 0.0) -> "DomeCurve":
        order = np.argsort(profile.s)
        s, pts = profile.s[order], profile.points[order]
        spline = profile.spline if profile.kind == "smooth" else None
        return cls(profile.kind, s, pts, spline, dx)

    def _at(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Point D (n, 2) and derivative dD/ds (n, 2) at design parameters ``sigma`` (the spline runs in u = -s)."""
        return self.spline(-sigma), -self.spline(-sigma, 1)

    def shifted(self, dx: float) -> "DomeCurve":
        return DomeCurve(self.kind, self.s, self.points, self.spline, self.dx + dx)

    def _intersect_right(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """First hit of rays (in the unshifted frame) on the right half: (distance (n,), normal (n, 2))."""
        n = len(o)
        P = self.points
        lam = np.full(n, np.nan)
        seg = np.full(n, -1)
        frac = np.zeros(n)
        # Screen every (ray, node) pair with one matrix product, cross(P - o, d) = P x d - o x d, then
        # evaluate the exact crossing only on the segments where that sign changes or comes within its
        # rounding (|error| < 64 eps (|P| + |o|) for unit d): the same numbers as testing every segment.
        # The matrix product runs in BLAS, whose kernel (and so the last bits) the CPU chooses: only the
        # per-segment numbers below decide, and the screen's margin covers both roundings.
        eps = np.finfo(float).eps
        reach = np.abs(P).max() if len(P) else 0.0
        block = max(1, _CHUNK // max(len(P), 1))
        for a in range(0, n, block):
            oo, dd = o[a:a + block], d[a:a + block]
            screen = P @ np.stack([dd[:, 1], -dd[:, 0]]) - (oo[:, 0] * dd[:, 1] - oo[:, 1] * dd[:, 0])
            near = np.abs(screen) <= 64 * eps * (reach + np.abs(oo).max(axis=1)) * np.abs(dd).sum(axis=1)
            pos = screen > 0
            cand = (pos[:-1] != pos[1:]) | near[:-1] | near[1:]
            j, i = np.nonzero(cand)  # segment, ray within the block
            c0, on0 = _side(P[j], oo[i], dd[i], eps)
            c1, on1 = _side(P[j + 1], oo[i], dd[i], eps)
            # A crossing within rounding of a node is a crossing AT that node (f exactly 0 or 1, the
            # node's own coordinates): the node ending the polyline counts whichever side its cross
            # product rounded to, and the two segments sharing an inner node give bit-identical
            # candidates, so the lower segment wins the tie on every machine. c1 of segment j and c0
            # of segment j + 1 are the same floating-point operations, so both segments agree on it.
            change = on0 | on1 | ((c0 > 0) & (c1 < 0)) | ((c0 < 0) & (c1 > 0))
            with np.errstate(invalid="ignore", divide="ignore"):
                f = np.clip(c0 / (c0 - c1), 0.0, 1.0)
            f = np.where(on0, 0.0, np.where(on1, 1.0, np.where(np.isfinite(f), f, 0.0)))
            hit = np.where(on0[:, None], P[j], np.where(on1[:, None], P[j + 1], P[j] + f[:, None] * (P[j + 1] - P[j])))
            along = np.sum((hit - oo[i]) * dd[i], axis=-1)
            ok = change & (along > 1e-9)
            i, j, f, along = i[ok], j[ok], f[ok], along[ok]
            first = np.lexsort((j, along, i))  # per ray: the nearest crossing, the lowest segment on a tie
            keep = first[np.r_[True, i[first][1:] != i[first][:-1]]] if len(first) else first
            rows = a + i[keep]
            lam[rows], seg[rows], frac[rows] = along[keep], j[keep], f[keep]
        found = seg >= 0
        normal = np.full((n, 2), np.nan)
        if self.kind == "polyline":
            tangent = P[seg[found] + 1] - P[seg[found]]
            normal[found] = unit(np.stack([-tangent[:, 1], tangent[:, 0]], axis=-1))
            return lam, normal
        # Smooth: Newton on g(sigma) = cross(D(sigma) - o, d), kept inside the bracketing segment.
        idx = np.nonzero(found)[0]
        lo, hi = self.s[seg[idx]], self.s[seg[idx] + 1]
        sig = lo + frac[idx] * (hi - lo)
        oo, dd = o[idx], d[idx]
        for _ in range(8):
            D, T = self._at(sig)
            g = (D[:, 0] - oo[:, 0]) * dd[:, 1] - (D[:, 1] - oo[:, 1]) * dd[:, 0]
            dg = T[:, 0] * dd[:, 1] - T[:, 1] * dd[:, 0]
            with np.errstate(invalid="ignore", divide="ignore"):
                step = np.where(dg != 0, g / dg, 0.0)
            sig = np.clip(sig - step, lo, hi)
        D, T = self._at(sig)
        lam[idx] = np.sum((D - oo) * dd, axis=-1)
        normal[idx] = unit(np.stack([-T[:, 1], T[:, 0]], axis=-1))
        return lam, normal

    def intersect(self, origins: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """First hit on either half of the section: distances (n,) (NaN = miss) and unit normals (n, 2)."""
        o = origins - np.array([self.dx, 0.0])
        lam_r, n_r = self._intersect_right(o, dirs)
        flip = np.array([-1.0, 1.0])
        lam_l, n_l = self._intersect_right(o * flip, dirs * flip)
        n_l = n_l * flip
        use_left = np.isfinite(lam_l) & ~(lam_r <= lam_l)
        lam = np.where(use_left, lam_l, lam_r)
        normal = np.where(use_left[:, None], n_l, n_r)
        return lam, normal


@dataclass(frozen=True)
class Trace:
    """Result of :func:`trace`, one entry per ray (mm, rad).

    ``miss``: signed distance from the sample point O to the returning ray's line (the
    convergence error, well conditioned at grazing incidence); ``landing_x``: where the ray crosses
    the sample plane (ill-conditioned near grazing); ``theta``: signed incidence angle there
    (positive when light arrives from +x); ``path_length``: source -> paraboloid -> dome -> plane;
    ``status``: codes in :data:`STATUS_NAMES`.
    """

    status: np.ndarray
    paraboloid_point: np.ndarray
    dome_point: np.ndarray
    miss: np.ndarray
    landing_x: np.ndarray
    theta: np.ndarray
    path_length: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        return self.status == OK


def trace(paraboloid: Paraboloid, dome: DomeCurve, origins: np.ndarray, dirs: np.ndarray) -> Trace:
    """Trace rays (origins, unit dirs: (n, 2)) through paraboloid and dome to z = 0."""
    n = len(origins)
    status = np.full(n, OK)
    l1 = paraboloid.intersect(origins, dirs)
    status[~np.isfinite(l1)] = MISSED_PARABOLOID
    P = origins + np.nan_to_num(l1)[:, None] * dirs
    u = reflect(dirs, paraboloid.normal(P[:, 0]))
    l2, nd = dome.intersect(P, u)
    status[(status == OK) & ~np.isfinite(l2)] = MISSED_DOME
    D = P + np.nan_to_num(l2)[:, None] * u
    v = reflect(u, np.nan_to_num(nd))
    with np.errstate(invalid="ignore", divide="ignore"):
        l3 = np.where(v[:, 1] < 0, -D[:, 1] / v[:, 1], np.nan)
    status[(status == OK) & ~np.isfinite(l3)] = ESCAPED
    blocked = paraboloid.blocks(D, v, np.nan_to_num(l3, nan=0.0))
    status[(status == OK) & blocked] = OCCLUDED
    landing = D[:, 0] + np.nan_to_num(l3) * v[:, 0]
    ok = status == OK
    nan = np.nan
    return Trace(
        status=status,
        paraboloid_point=np.where(np.isfinite(l1)[:, None], P, nan),
        dome_point=np.where((status == OK)[:, None] | (status >= OCCLUDED)[:, None], D, nan),
        miss=np.where(ok, D[:, 0] * v[:, 1] - D[:, 1] * v[:, 0], nan),
        landing_x=np.where(ok, landing, nan),
        theta=np.where(ok, np.arctan2(-v[:, 0], -v[:, 1]), nan),
        path_length=np.where(ok, l1 + l2 + l3, nan),
    )


def cop_rays(cop: np.ndarray, targets_x: np.ndarray, paraboloid: Paraboloid) -> tuple[np.ndarray, np.ndarray]:
    """Rays from a point COP (2,) aimed at the aligned paraboloid's points at abscissae ``targets_x``."""
    aim = paraboloid.point(targets_x) - cop
    return np.tile(cop, (len(targets_x), 1)), unit(aim)


def parallel_rays(x: np.ndarray, z_start: float) -> tuple[np.ndarray, np.ndarray]:
    """Rays parallel to the axis, travelling down from height ``z_start`` (a COP at infinity)."""
    x = np.asarray(x, dtype=float)
    return np.column_stack([x, np.full_like(x, z_start)]), np.tile([0.0, -1.0], (len(x), 1))
