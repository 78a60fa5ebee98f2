"""Ray sources at the centre of projection (COP): pinhole pixel grid, seeded rays across the
paraboloid's useful annulus, thin-lens aperture rays (thesis 3.2.2); and the design's incidence
direction for any ray from the COP (the 2D design, rotated to the ray's azimuth).

Projector frame: the COP at (0, 0, cop_z), looking down -z. Pixel (column i, row j) of a W x H
image has its centre at image coordinates x = i + 0.5 - W/2 (towards +x), y = H/2 - j - 0.5
(rows run towards -y), and the direction (x, y, -f_px) with f_px = W x throw_ratio
(``derived.projector_focal_px``). A source pose (misalignment) moves and tilts that frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import make_interp_spline

from rigcad.check.rays import unit
from rigcad.check.scene import Pose, RigGeometry
from rigcad.errors import CheckError
from rigcad.optics.design import profile_table


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
    def from_rig(cls, rig: RigGeometry) -> "DesignMap":
        geo = rig.geometry
        if geo.cop_at_infinity:
            raise CheckError("the 3D ray check needs a finite COP (layout.cop_to_vertex)")
        table = profile_table(geo, rig.dome)
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


@dataclass(frozen=True)
class Rays:
    """Rays from a source: origins and unit dirs (n, 3) in the global frame; ``chief`` (n, 3) the
    aligned pinhole direction each stands for (for the design's direction); ``pixel`` (n, 2) image
    coordinates (px) or NaN."""

    origins: np.ndarray
    dirs: np.ndarray
    chief: np.ndarray
    pixel: np.ndarray


def _place(pose: Pose | None, origins: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if pose is None or pose.is_identity:
        return origins, dirs
    return pose.globalize_points(origins), pose.globalize_dirs(dirs)


def pixel_grid(design: DesignMap, resolution: tuple[int, int], pose: Pose | None = None,
               window: int | None = None) -> tuple[Rays, tuple[int, int], tuple[int, int]]:
    """One pinhole ray per pixel centre (row-major, rows j then columns i). ``window``: only the
    centred square of that many pixels a side (the paraboloid's image is ~200 px across; the rest
    of the image misses it). Returns the rays, the traced (height, width) and the (row, column) of
    the first traced pixel."""
    width, height = resolution
    w = min(width, window) if window else width
    h = min(height, window) if window else height
    c0, r0 = (width - w) // 2, (height - h) // 2
    jj, ii = np.meshgrid(np.arange(r0, r0 + h), np.arange(c0, c0 + w), indexing="ij")
    x = ii.ravel() + 0.5 - width / 2
    y = height / 2 - jj.ravel() - 0.5
    d = unit(np.stack([x, y, np.full_like(x, -design.focal_px)], axis=-1))
    o = np.tile([0.0, 0.0, design.cop_z], (len(d), 1))
    go, gd = _place(pose, o, d)
    return Rays(go, gd, d, np.stack([x, y], axis=-1)), (h, w), (r0, c0)


def annulus_rays(design: DesignMap, count: int, seed: int, pose: Pose | None = None) -> Rays:
    """``count`` pinhole rays uniform in image area over the useful annulus (pixel radius from the
    occlusion limit to the rim), seeded."""
    rng = np.random.default_rng(seed)
    r_in, r_out = design.pixel_radius(np.array([design.alpha_min, design.alpha_max]))
    rho = np.sqrt(rng.uniform(r_in ** 2, r_out ** 2, count))
    phi = rng.uniform(0.0, 2 * np.pi, count)
    return pixel_rays(design, rho * np.cos(phi), rho * np.sin(phi), pose)


def pixel_rays(design: DesignMap, x: np.ndarray, y: np.ndarray, pose: Pose | None = None) -> Rays:
    """Pinhole rays through image points (x, y) px (frame of the module docstring)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    d = unit(np.stack([x, y, np.full_like(x, -design.focal_px)], axis=-1))
    o = np.tile([0.0, 0.0, design.cop_z], (len(d), 1))
    go, gd = _place(pose, o, d)
    return Rays(go, gd, d, np.stack([x, y], axis=-1))


def thin_lens_rays(chief: Rays, focal_distance: float, aperture: float, azimuths: int) -> Rays:
    """Aperture-edge rays of a thin lens of diameter ``aperture`` (mm) in the plane of the COP,
    perpendicular to the axis, focused at ``focal_distance`` mm along each chief ray (unfolded,
    thesis 3.2.2): ``azimuths`` rays per chief ray, from edge points at angles 2 pi k / azimuths,
    aimed at the chief ray's point at the focal distance. Ray k of chief ray i is row i*azimuths+k."""
    beta = 2 * np.pi * np.arange(azimuths) / azimuths
    edge = 0.5 * aperture * np.stack([np.cos(beta), np.sin(beta), np.zeros_like(beta)], axis=-1)
    q = chief.origins + focal_distance * chief.dirs  # (n, 3)
    e = (chief.origins[:, None, :] + edge[None]).reshape(-1, 3)
    d = unit(np.repeat(q, azimuths, axis=0) - e)
    return Rays(e, d, np.repeat(chief.chief, azimuths, axis=0), np.repeat(chief.pixel, azimuths, axis=0))
