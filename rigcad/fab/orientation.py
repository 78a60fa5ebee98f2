"""Print orientation and fit: a build direction D (a unit vector in the part's frame) becomes the
printer's +z; a spin about +z then fits the part's footprint on the bed.

On a part with a mirror the orientation is chosen for the least support contact on the mirror
first (support scars on an optical surface are worse than the staircase: thesis 4.4, the grooves
and their polishing ruined the first rig), then the least staircase (area-weighted mean cusp
height, rigcad.fab.staircase), then the overhang, then the height. Support contact counts both
ways support touches a face (:func:`support_contact`): under an overhanging face, and standing on
a face below an overhang. Parts without a mirror minimise the overhang area that needs support,
then the height. Thin plates (:func:`plate_axis`) print flat, split where they do not fit.
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


def _spun_extents(vertices: np.ndarray, direction) -> tuple[float, np.ndarray, np.ndarray]:
    """Height (mm) of the part tilted along ``direction``, and its footprint's widths in x and y
    (mm, one per spin of SPINS), from the convex hull of its tilted footprint."""
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
    return height, wx, hy


def fit_spin(vertices: np.ndarray, direction, usable: tuple[float, float, float]) -> tuple[float | None, dict]:
    """The spin (rad) that fits the tilted part in the usable box (x, y, z mm), or None.

    Spin 0 when it fits; otherwise the spin with the largest smallest margin. Also returns the
    extents (mm) at the chosen (or unrotated) spin.
    """
    height, wx, hy = _spun_extents(vertices, direction)
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
    height, wx, hy = _spun_extents(vertices, direction)
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


#: A part is a thin plate when its smallest bounding-box side is under this fraction of the next:
#: on edge it is a fin (a 7.5 mm plate would stand 144 mm tall) that sways under the nozzle and levers
#: itself off the bed, so it prints flat.
THIN_PLATE_RATIO = 0.1


def plate_axis(vertices: np.ndarray) -> int | None:
    """The part-frame axis (0, 1, 2) of a thin plate's thickness (THIN_PLATE_RATIO), or None."""
    size = np.ptp(np.asarray(vertices, dtype=float), axis=0)
    order = np.argsort(size)
    return int(order[0]) if size[order[0]] <= THIN_PLATE_RATIO * size[order[1]] else None


def flat_candidates(axis: int) -> list[Orientation]:
    """A thin plate's two flat orientations (its thickness along the build direction)."""
    n = "xyz"[axis]
    e = [0.0, 0.0, 0.0]
    e[axis] = 1.0
    return [Orientation(f"flat (+{n} up)", tuple(e)), Orientation(f"flat (-{n} up)", tuple(-v for v in e))]


def support_contact(vertices: np.ndarray, faces: np.ndarray, direction, mirror: np.ndarray | None = None) -> dict:
    """Where support would touch the part printed along ``direction`` (the model's view; the
    slicer's own support is measured from its G-code, rigcad.fab.support): overhang faces
    (OVERHANG_ANGLE) take support from below, on their own area; that support stands on the bed
    or, when a ray straight down from the face meets the part first, on the face it meets (its
    footprint there: the overhang's projected area over the met face's |n . D|, at most 5x).
    ``mirror`` masks the mirror's faces. Returns mm2 on mirror and other faces, each split into
    ``under`` (the face overhangs) and ``on`` (support stands on it)."""
    import trimesh

    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cross, axis=1)
    ok = area2 > 0
    nz = np.divide(cross @ d, area2, out=np.zeros_like(area2), where=ok)
    area = 0.5 * area2
    height = tri @ d
    on_bed = (height.max(axis=1) - (vertices @ d).min()) < 1e-6
    down = (nz < -math.sin(OVERHANG_ANGLE)) & ~on_bed & ok
    is_m = np.zeros(len(faces), bool) if mirror is None else np.asarray(mirror, bool)
    out = {"mirror_under_mm2": float(area[down & is_m].sum()), "other_under_mm2": float(area[down & ~is_m].sum()),
           "mirror_on_mm2": 0.0, "other_on_mm2": 0.0, "support_envelope_mm3": 0.0}
    idx = np.nonzero(down)[0]
    if len(idx):
        mesh = trimesh.Trimesh(vertices, faces, process=False)
        centre, face, share = _subdivide(tri[idx], area[idx], SUPPORT_CELL_MM2)
        src = idx[face]
        origins = centre - 1e-3 * d  # just below the face: the ray must not meet the face itself
        locs, rays, hit_tri = mesh.ray.intersects_location(origins, np.repeat(-d[None, :], len(centre), axis=0),
                                                           multiple_hits=False)
        first = np.full(len(centre), -1)
        drop = (centre @ d) - (vertices @ d).min()  # to the bed, unless the part is met first
        first[rays] = hit_tri
        drop[rays] = (centre[rays] - locs) @ d
        proj = share * np.abs(nz[src])  # the column's cross-section (mm2)
        hit = first >= 0
        dst = first[hit]
        footprint = proj[hit] / np.maximum(np.abs(nz[dst]), 0.2)
        out["mirror_on_mm2"] = float(footprint[is_m[dst]].sum())
        out["other_on_mm2"] = float(footprint[~is_m[dst]].sum())
        # the columns under every overhang, down to what they stand on: what support would fill
        out["support_envelope_mm3"] = float((proj * np.maximum(drop, 0.0)).sum())
    out["mirror_mm2"] = out["mirror_under_mm2"] + out["mirror_on_mm2"]
    out["other_mm2"] = out["other_under_mm2"] + out["other_on_mm2"]
    return out


#: Overhang faces are cut into sub-triangles of at most about this area (mm2) for the columns of
#: support under them: a 2 mm grid, the support's own line spacing.
SUPPORT_CELL_MM2 = 4.0


def _subdivide(tri: np.ndarray, area: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle (n, 3, 3) cut into k^2 equal sub-triangles (k from ``cell``): their centroids
    (m, 3), the triangle each belongs to (m,) and their areas (m,)."""
    k = np.maximum(np.ceil(np.sqrt(area / cell)), 1).astype(int)
    pts, owner, share = [], [], []
    for n in np.unique(k):
        sel = np.nonzero(k == n)[0]
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        up = (i + j) <= n - 1
        dn = (i + j) <= n - 2
        bary = np.concatenate([np.column_stack([i[up] + 1 / 3, j[up] + 1 / 3]),
                               np.column_stack([i[dn] + 2 / 3, j[dn] + 2 / 3])]) / n  # (n^2, 2)
        a, b, c = tri[sel, 0], tri[sel, 1], tri[sel, 2]
        p = a[:, None] + bary[None, :, 0, None] * (b - a)[:, None] + bary[None, :, 1, None] * (c - a)[:, None]
        pts.append(p.reshape(-1, 3))
        owner.append(np.repeat(sel, len(bary)))
        share.append(np.repeat(area[sel] / (n * n), len(bary)))
    return np.concatenate(pts), np.concatenate(owner), np.concatenate(share)


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
