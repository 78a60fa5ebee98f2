"""Rays against the convex solids that stand in for the rig's mounting hardware (kernel-free,
float64, vectorised over rays (n, 3)): the one slab test for boxes and the z-cylinder test. Each
returns every ray's entry and exit distances along its direction (``t_lo`` > ``t_hi``: no hit), so
the ray checker (rays that go on) and the occlusion report (segments of a light path) read the
same numbers. Frame: mm, sample point at the origin, optical axis +z.
"""

from __future__ import annotations

import numpy as np


def slab(origins: np.ndarray, dirs: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit distances (n,), in units of ``dirs``, of rays ``origins + t dirs`` (n, 3)
    through the axis-aligned box [lo, hi] (3,) mm. A direction component of zero keeps the ray in
    its slab for all t when the origin lies in it, else never (no division by zero)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - origins) / dirs
        t2 = (hi - origins) / dirs
    inside = (origins >= lo) & (origins <= hi)
    t_lo = np.where(dirs == 0, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2)).max(axis=1)
    t_hi = np.where(dirs == 0, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2)).min(axis=1)
    return t_lo, t_hi


def segments_hit_box(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Does each segment a[i] -> b[i] (n, 3) pass through the box [lo, hi]? Touching an end point
    within 1e-9 of the segment's length does not count (a light path starts and ends on a mirror)."""
    enter, leave = slab(a, b - a, lo, hi)
    return (enter <= leave) & (leave > 1e-9) & (enter < 1 - 1e-9)


def z_cylinder(origins: np.ndarray, dirs: np.ndarray, radius: float, z0: float, z1: float,
               centre: tuple[float, float] = (0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit distances (n,) of rays through the solid cylinder about the z axis through
    ``centre`` (x, y), ``radius`` mm, from z0 to z1 mm."""
    ox, oy = origins[:, 0] - centre[0], origins[:, 1] - centre[1]
    a = dirs[:, 0] ** 2 + dirs[:, 1] ** 2
    b = ox * dirs[:, 0] + oy * dirs[:, 1]
    c = ox * ox + oy * oy - radius ** 2
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        sq = np.sqrt(disc)
        r_in = np.where(a > 0, (-b - sq) / a, np.where(c <= 0, -np.inf, np.inf))
        r_out = np.where(a > 0, (-b + sq) / a, np.where(c <= 0, np.inf, -np.inf))
        z_a = (z0 - origins[:, 2]) / dirs[:, 2]
        z_b = (z1 - origins[:, 2]) / dirs[:, 2]
    inside_z = (origins[:, 2] >= z0) & (origins[:, 2] <= z1)
    zl = np.where(dirs[:, 2] == 0, np.where(inside_z, -np.inf, np.inf), np.minimum(z_a, z_b))
    zh = np.where(dirs[:, 2] == 0, np.where(inside_z, np.inf, -np.inf), np.maximum(z_a, z_b))
    t_lo = np.fmax(np.where(disc >= 0, r_in, np.inf), zl)
    t_hi = np.fmin(np.where(disc >= 0, r_out, -np.inf), zh)
    return t_lo, t_hi


def segments_hit_cylinder(a: np.ndarray, b: np.ndarray, radius: float, z0: float, z1: float,
                          centre: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Does each segment a[i] -> b[i] (n, 3) pass through the solid z-cylinder (``radius`` mm about
    ``centre``, z0..z1 mm)? End points touching within 1e-9 of the length do not count, as
    :func:`segments_hit_box`."""
    enter, leave = z_cylinder(a, b - a, radius, z0, z1, centre)
    return (enter <= leave) & (leave > 1e-9) & (enter < 1 - 1e-9)
