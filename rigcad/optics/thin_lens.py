"""Thin-lens check of the design (thesis 3.2.2, Figure 3.7).

The projector (or camera) is a thin lens of diameter ``aperture`` at the COP, focused at the mean
optical path length of the chief rays (the thesis's "focal distance"). For each chief ray the two
meridional aperture-edge rays aim at the chief ray's point at that distance (unfolded, before any
mirror) and are traced through the system. They arrive at slightly different angles and miss O by
a little: the angular offsets alpha_l, alpha_r (rad) and the miss distances (mm) are reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.vec import unit
from rigcad.optics.trace2d import DomeCurve, trace


@dataclass(frozen=True)
class ThinLensResult:
    """Per chief ray (n,): the edge rays' angular offsets (rad) and miss distances from O (mm)."""

    focal_distance: float
    chief_x: np.ndarray  #: where the chief rays meet the paraboloid (mm)
    alpha_left: np.ndarray
    alpha_right: np.ndarray
    miss_left: np.ndarray
    miss_right: np.ndarray

    def summary(self) -> dict[str, float | int | None]:
        """Means and maxima over the edge rays that reach the sample (None when none do)."""
        a = np.abs(np.concatenate([self.alpha_left, self.alpha_right]))
        m = np.abs(np.concatenate([self.miss_left, self.miss_right]))
        ok = np.isfinite(a) & np.isfinite(m)
        a, m = a[ok], m[ok]
        return {
            "focal_distance_mm": self.focal_distance,
            "mean_abs_angular_offset_rad": float(a.mean()) if a.size else None,
            "max_abs_angular_offset_rad": float(a.max()) if a.size else None,
            "mean_abs_miss_mm": float(m.mean()) if m.size else None,
            "max_abs_miss_mm": float(m.max()) if m.size else None,
            "edge_rays_lost": int(np.count_nonzero(~ok)),
            "edge_rays": int(ok.size),
        }


def thin_lens_check(paraboloid: Paraboloid, dome: DomeCurve, cop: np.ndarray, chief_dirs: np.ndarray,
                    aperture: float) -> ThinLensResult:
    """Trace chief rays from ``cop`` (2,) along ``chief_dirs`` (n, 2) and their aperture-edge rays.
    The lens lies in the plane z = cop_z, perpendicular to the optical axis."""
    origins = np.tile(cop, (len(chief_dirs), 1))
    chief = trace(paraboloid, dome, origins, chief_dirs)
    focal = float(np.nanmean(chief.path_length))  # thesis: projector to sample surface, averaged
    Q = origins + focal * chief_dirs
    result = {}
    for side, sign in (("left", -1.0), ("right", 1.0)):
        E = origins + np.array([sign * aperture / 2.0, 0.0])
        edge = trace(paraboloid, dome, E, unit(Q - E))
        result[side] = (edge.theta - chief.theta, edge.miss)
    return ThinLensResult(focal, chief.paraboloid_point[:, 0], result["left"][0], result["right"][0],
                          result["left"][1], result["right"][1])
