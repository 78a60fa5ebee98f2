"""Print orientation and fit: a build direction D (a unit vector in the part's frame) becomes the
printer's +z; a spin about +z then fits the part's footprint on the bed.

The orientation is chosen to minimise the staircase on the part's mirror surface (area-weighted
mean cusp height, rigcad.fab.staircase), then the mirror area that would need support, then the
height; parts without a mirror minimise the overhang area that needs support, then the height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

#: A face is an overhang when its outward normal points down more than this from the horizontal
#: (the usual 45 deg rule of FDM: steeper overhangs sag without support).
OVERHANG_ANGLE = math.radians(45.0)
#: Spins tried to fit a footprint on the bed (rad): 1 deg steps over half a turn.
SPINS = np.radians(np.arange(0.0, 180.0, 1.0))


@dataclass(frozen=True)
class Orientation:
    """``name`` in words, ``direction`` the build direction in the part frame (unit), ``spin`` (rad)
    about the printer's +z after the tilt."""

    name: str
    direction: tuple[float, float, float]
    spin: float = 0.0

    def rotation(self) -> np.ndarray:
        """3x3 rotation taking the part frame to the printer frame (D -> +z, then the spin)."""
        return _rz(self.spin) @ tilt_to_z(np.asarray(self.direction, dtype=float))


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def tilt_to_z(d: np.ndarray) -> np.ndarray:
    """The rotation taking unit vector ``d`` to +z by the shortest arc (about x for d = -z)."""
    d = d / np.linalg.norm(d)
    z = np.array([0.0, 0.0, 1.0])
    c = float(d @ z)
    if c > 1 - 1e-12:
        return np.eye(3)
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    axis = np.cross(d, z)
    s = np.linalg.norm(axis)
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1 - c) * kx @ kx


def fit_spin(vertices: np.ndarray, direction, usable: tuple[float, float, float]) -> tuple[float | None, dict]:
    """The spin (rad) that fits the tilted part in the usable box (x, y, z mm), or None.

    Spin 0 when it fits; otherwise the spin with the largest smallest margin. Also returns the
    extents (mm) at the chosen (or unrotated) spin.
    """
    p = vertices @ tilt_to_z(np.asarray(direction, dtype=float)).T
    height = float(np.ptp(p[:, 2]))
    xy = p[:, :2]
    try:
        xy = xy[ConvexHull(xy).vertices]
    except Exception:  # degenerate footprint (a flat part): the points themselves will do
        pass
    c, s = np.cos(SPINS), np.sin(SPINS)
    w = (xy[:, 0, None] * c - xy[:, 1, None] * s)
    h = (xy[:, 0, None] * s + xy[:, 1, None] * c)
    wx, hy = np.ptp(w, axis=0), np.ptp(h, axis=0)
    margin = np.minimum(usable[0] - wx, usable[1] - hy)
    extents = {"x_mm": float(wx[0]), "y_mm": float(hy[0]), "z_mm": height}
    if height > usable[2] or margin.max() < 0:
        return None, extents
    i = 0 if margin[0] >= 0 else int(np.argmax(margin))
    return float(SPINS[i]), {"x_mm": float(wx[i]), "y_mm": float(hy[i]), "z_mm": height}


def fit_margin(vertices: np.ndarray, direction, usable: tuple[float, float, float]) -> float:
    """The room left (mm) when the part is tilted along ``direction`` and spun to its best spin of
    SPINS: the smallest of the three margins of the usable box (x, y, z mm), the spin chosen to make
    it largest. >= 0 exactly when :func:`fit_spin` finds a fit (the same extents); continuous in the
    part's size, for optimisers (rigcad.optimize)."""
    p = vertices @ tilt_to_z(np.asarray(direction, dtype=float)).T
    height = float(np.ptp(p[:, 2]))
    xy = p[:, :2]
    try:
        xy = xy[ConvexHull(xy).vertices]
    except Exception:  # degenerate footprint (a flat part): the points themselves will do
        pass
    c, s = np.cos(SPINS), np.sin(SPINS)
    wx = np.ptp(xy[:, 0, None] * c - xy[:, 1, None] * s, axis=0)
    hy = np.ptp(xy[:, 0, None] * s + xy[:, 1, None] * c, axis=0)
    return float(min(usable[2] - height, np.minimum(usable[0] - wx, usable[1] - hy).max()))


def place(vertices: np.ndarray, orientation: Orientation, bed_xy: tuple[float, float]) -> np.ndarray:
    """Vertices in the printer frame: rotated, lowest point on z = 0, footprint centred at ``bed_xy``."""
    p = vertices @ orientation.rotation().T
    lo, hi = p.min(axis=0), p.max(axis=0)
    return p - np.array([(lo[0] + hi[0]) / 2 - bed_xy[0], (lo[1] + hi[1]) / 2 - bed_xy[1], lo[2]])


def overhang_area(vertices: np.ndarray, faces: np.ndarray, direction, mask: np.ndarray | None = None) -> float:
    """Area (mm^2) of faces facing down more than OVERHANG_ANGLE from the horizontal when printed
    along ``direction``, excluding faces on the bed; ``mask`` restricts to some faces."""
    d = np.asarray(direction, dtype=float)
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cross, axis=1)
    nz = np.divide(cross @ d, area2, out=np.zeros_like(area2), where=area2 > 0)
    height = tri @ d
    on_bed = (height.max(axis=1) - (vertices @ d).min()) < 1e-6
    down = (nz < -math.sin(OVERHANG_ANGLE)) & ~on_bed
    if mask is not None:
        down &= mask
    return float(0.5 * area2[down].sum())


def generic_candidates() -> list[Orientation]:
    """Six axis-aligned build directions for parts without a mirror."""
    return [Orientation(n, d) for n, d in (("+z up (working position)", (0, 0, 1)), ("-z up", (0, 0, -1)),
                                           ("+x up", (1, 0, 0)), ("-x up", (-1, 0, 0)),
                                           ("+y up", (0, 1, 0)), ("-y up", (0, -1, 0)))]


def mirror_candidates(sector: tuple[float, float] | None) -> list[Orientation]:
    """Build directions for a part (or a piece of it) carrying a mirror of revolution about z:
    axis vertical (upright, as in the rig), upside down, axis horizontal; for a sector piece
    spanning angles ``sector`` (rad), axis horizontal with its back on the bed (mirror up), and
    lying on its first cut face."""
    out = [Orientation("upright", (0.0, 0.0, 1.0)), Orientation("upside_down", (0.0, 0.0, -1.0))]
    if sector is None:
        out.append(Orientation("axis_horizontal", (0.0, 1.0, 0.0)))
        return out
    a0, a1 = sector
    mid = (a0 + a1) / 2
    out.append(Orientation("axis_horizontal", (-math.cos(mid), -math.sin(mid), 0.0)))
    if a1 - a0 < 2 * math.pi - 1e-9:
        out.append(Orientation("on_cut_face", (-math.sin(a0), math.cos(a0), 0.0)))
    return out
