"""Ray sources at the centre of projection (COP): pinhole pixel grid, seeded rays across the
paraboloid's useful annulus, thin-lens aperture rays (thesis 3.2.2). Pixels and the projector
frame as in :mod:`rigcad.optics.incidence` (which also maps each ray to its design incidence
direction); a source pose (misalignment) moves and tilts that frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.vec import unit
from rigcad.optics.frames import Pose
from rigcad.optics.incidence import DesignMap


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
