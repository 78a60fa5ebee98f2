"""The convex paraboloid mirror in closed form: the truth the numerical stages are tested against.

Meridional section, frame of the design (mm): z(x) = vertex_z - (x - dx)^2 / (4 f) for
|x - dx| <= rim_radius, vertex up. ``dx`` shifts the mirror sideways (misalignment). Arrays of
points and directions have shape ``(n, 2)`` holding ``(x, z)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.vec import unit

#: Relative margin (of the rim radius) within which a hit at the rim counts: a ray the design aims
#: at the rim meets it at |x| = rim up to rounding, which differs between CPUs (numpy's SIMD loops,
#: BLAS); 1e-12 is ~5000 ulps, 1e-10 mm at a 100 mm rim. The 3D tracers use the same (check.rays,
#: check._kernels.RIM_RTOL).
RIM_RTOL = 1e-12


@dataclass(frozen=True)
class Paraboloid:
    """Meridional section of the mirror. Lengths in mm."""

    focal_length: float
    vertex_z: float
    rim_radius: float
    dx: float = 0.0

    @property
    def rim_z(self) -> float:
        return self.vertex_z - self.rim_radius**2 / (4.0 * self.focal_length)

    @property
    def focus(self) -> np.ndarray:
        return np.array([self.dx, self.vertex_z - self.focal_length])

    def z(self, x: np.ndarray) -> np.ndarray:
        """Height of the surface at abscissa ``x`` (mm)."""
        r = np.asarray(x, dtype=float) - self.dx
        return self.vertex_z - r * r / (4.0 * self.focal_length)

    def point(self, x: np.ndarray) -> np.ndarray:
        """Surface points (n, 2) at abscissae ``x``."""
        x = np.asarray(x, dtype=float)
        return np.stack([x, self.z(x)], axis=-1)

    def normal(self, x: np.ndarray) -> np.ndarray:
        """Outward unit normals (n, 2) at abscissae ``x`` (pointing up and away from the axis)."""
        r = np.asarray(x, dtype=float) - self.dx
        return unit(np.stack([r / (2.0 * self.focal_length), np.ones_like(r)], axis=-1))

    def intersect(self, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
        """Distance along each ray to its first hit on the mirror surface (|x - dx| <= rim).

        ``origins``, ``dirs``: (n, 2), ``dirs`` unit. Returns (n,) distances, NaN for a miss.
        Solves (X + l dx)^2 + 4 f (z0 + l dz - vertex_z) = 0 with the cancellation-free root formula.
        """
        f = self.focal_length
        X = origins[:, 0] - self.dx
        a = dirs[:, 0] ** 2
        b = 2.0 * X * dirs[:, 0] + 4.0 * f * dirs[:, 1]
        c = X * X + 4.0 * f * (origins[:, 1] - self.vertex_z)
        disc = b * b - 4.0 * a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
            q = -0.5 * (b + np.copysign(sq, b))
            r1 = q / a
            r2 = c / q
            linear = np.abs(a) < 1e-300
            r_lin = -c / b
            r1 = np.where(linear, r_lin, r1)
            r2 = np.where(linear, np.nan, r2)
            eps = 1e-9
            cand = np.stack([r1, r2], axis=-1)
            hit_x = X[:, None] + cand * dirs[:, :1]
            ok = (cand > eps) & (np.abs(hit_x) <= self.rim_radius * (1 + RIM_RTOL))
            cand = np.where(ok, cand, np.inf)
            best = cand.min(axis=-1)
        return np.where(np.isfinite(best), best, np.nan)

    def blocks(self, origins: np.ndarray, dirs: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """True where the segment origin + l dir, 0 < l < length, crosses the mirror's body.

        The body is the region between the surface and the rim chord z = rim_z, |x - dx| <= rim.
        """
        hit_surface = self.intersect(origins, dirs)
        crosses = np.isfinite(hit_surface) & (hit_surface < lengths)
        with np.errstate(invalid="ignore", divide="ignore"):
            l_chord = (self.rim_z - origins[:, 1]) / dirs[:, 1]
            x_chord = origins[:, 0] + l_chord * dirs[:, 0] - self.dx
        chord = (l_chord > 1e-9) & (l_chord < lengths) & (np.abs(x_chord) <= self.rim_radius * (1 + RIM_RTOL))
        return crosses | chord
