"""The design's map from a ray of the centre of projection (COP), or a projector pixel, to the
incidence direction at the sample point O (rotational symmetry: the 2D design turned to the ray's
azimuth). Frame: mm, O at the origin, +z up; angles in radians.

Projector frame: the COP at (0, 0, cop_z), looking down -z. Pixel (column i, row j) of a W x H
image has its centre at image coordinates x = i + 0.5 - W/2 (towards +x), y = H/2 - j - 0.5
(rows run towards -y), and the direction (x, y, -f_px) with f_px = W x throw_ratio
(``derived.projector_focal_px``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import make_interp_spline

from rigcad.errors import GeometryError
from rigcad.optics.design import profile_table
from rigcad.optics.dome import DomeProfile
from rigcad.profile.derived import Derived

#: Cells of the dense lookup tables (see DesignMap.alpha_table).
TABLE_CELLS = 1 << 16


def _lookup(x: np.ndarray, table: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Linear interpolation in an evenly spaced table (np.interp's result without its binary
    search: the cell index is arithmetic). Values outside the table take its end values; NaN stays NaN."""
    grid, values = table
    h = (grid[-1] - grid[0]) / (len(grid) - 1)
    f = np.clip((x - grid[0]) / h, 0.0, len(grid) - 1.0)
    bad = np.isnan(f)
    f = np.where(bad, 0.0, f)
    i = np.minimum(f.astype(np.int64), len(grid) - 2)
    w = f - i
    return np.where(bad, np.nan, values[i] * (1.0 - w) + values[i + 1] * w)


def _arrival(theta: np.ndarray, x: np.ndarray, y: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """Unit vectors (n, 3) at polar angle theta in the azimuth of (x, y) (rho = hypot(x, y))."""
    with np.errstate(invalid="ignore", divide="ignore"):
        c, s = np.where(rho > 0, x / rho, 1.0), np.where(rho > 0, y / rho, 0.0)
    st = np.sin(theta)
    return np.stack([st * c, st * s, np.cos(theta)], axis=-1)


@dataclass(frozen=True)
class DesignMap:
    """The design's incidence angle theta (rad) as a function of the angle alpha (rad) between a
    COP ray and the axis, from the 2D design's profile table (quintic spline through its rows):
    valid for alpha_min <= alpha <= alpha_max (the useful annulus: occlusion limit to rim)."""

    alpha_min: float
    alpha_max: float
    spline: object
    cop_z: float
    focal_px: float
    s_min: float = 0.0
    s_max: float = 0.0
    by_radius: object = None  #: theta (rad) of the paraboloid point at radius s (mm), quintic spline
    #: Dense tables of both splines for per-ray lookups (np.interp: ~30x cheaper than evaluating a
    #: quintic spline on a million rays; linear interpolation on 2^16 cells errs by under 3e-11 rad, measured).
    alpha_table: tuple = ()
    radius_table: tuple = ()

    @classmethod
    def from_design(cls, geo: Derived, dome: DomeProfile) -> "DesignMap":
        """The map of the design ``dome`` (its profile table); raises GeometryError for a COP at
        infinity (no projector pixels)."""
        if geo.cop_at_infinity:
            raise GeometryError("projector pixels need a finite COP (layout.cop_to_vertex)", param="layout.cop_to_vertex")
        table = profile_table(geo, dome)
        alpha = np.radians(table["cop_angle_deg"])
        theta = np.radians(table["incidence_theta_deg"])
        order = np.argsort(alpha)
        a, t = alpha[order], theta[order]
        keep = np.concatenate([[True], np.diff(a) > 0])
        s = table["paraboloid_r_mm"]
        so = np.argsort(s)
        by_alpha = make_interp_spline(a[keep], t[keep], k=5)
        by_radius = make_interp_spline(s[so], theta[so], k=5)
        a_tab = np.linspace(a[0], a[-1], TABLE_CELLS + 1)
        s_tab = np.linspace(s[so][0], s[so][-1], TABLE_CELLS + 1)
        return cls(float(a[0]), float(a[-1]), by_alpha, geo.cop_z, geo.projector_focal_px, float(s[so][0]),
                   float(s[so][-1]), by_radius, (a_tab, by_alpha(a_tab)), (s_tab, by_radius(s_tab)))

    def direction_at(self, local_points: np.ndarray) -> np.ndarray:
        """Design arrival directions (n, 3) for rays that hit the paraboloid at ``local_points``
        (n, 3) in its own frame (the 'calibrated' reference: which paraboloid point a pixel lights
        is what calibration measures); NaN outside the useful annulus."""
        s = np.hypot(local_points[:, 0], local_points[:, 1])
        inside = (s >= self.s_min) & (s <= self.s_max)
        theta = np.where(inside, _lookup(s, self.radius_table), np.nan)
        return _arrival(theta, local_points[:, 0], local_points[:, 1], s)

    def direction(self, dirs: np.ndarray) -> np.ndarray:
        """Design arrival directions (n, 3) (unit, from O towards the light) for COP rays ``dirs``
        (n, 3) of the aligned projector; NaN outside the useful annulus."""
        rho = np.hypot(dirs[:, 0], dirs[:, 1])
        alpha = np.arctan2(rho, -dirs[:, 2])
        inside = (alpha >= self.alpha_min) & (alpha <= self.alpha_max)
        theta = np.where(inside, _lookup(alpha, self.alpha_table), np.nan)
        return _arrival(theta, dirs[:, 0], dirs[:, 1], rho)

    def pixel_radius(self, alpha: np.ndarray) -> np.ndarray:
        return self.focal_px * np.tan(alpha)


def camera_focal_px(rig) -> float:
    """The camera's focal length in its own pixels (rigcad.optics.camera): the profile's
    ``camera.focal_length`` or its lens file's over ``camera.pixel_pitch``; without either, the lens
    that frames the paraboloid as the projector does, f_camera = f_projector x camera height /
    projector height (2389 px for Table 3.1: the rim 134 px from the image centre). ``rig``: a
    :class:`rigcad.rig.Rig` (its profile and derived geometry)."""
    from rigcad.optics.camera import camera_model

    return camera_model(rig.profile, rig.geometry).focal_px


def camera_principal_point(rig) -> tuple[float, float]:
    """Where the camera's optical axis meets its sensor: (x, y) px from the image's top-left corner
    (``camera.principal_point``; default the centre)."""
    from rigcad.optics.camera import camera_model

    return camera_model(rig.profile, rig.geometry).principal_point
