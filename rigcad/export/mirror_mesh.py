"""Mirror meshes for the ray checker: each mirror as a structured triangle grid of its exact surface
of revolution, exact unit normals at the vertices, and a binary PLY writer and reader.

Frame: mm, sample point O at the origin, optical axis +z. Ring ``i`` is the meridian parameter
``ring_parameters[i]`` with (r, z) = ``meridian.points(u)``; sector ``j`` is the azimuth
``phi_j = 2 pi j / sectors`` (rad, counter-clockwise about +z from +x). The vertex of ring i,
sector j is (r cos phi_j, r sin phi_j, z); a ring on the axis (the paraboloid's vertex) is one apex
vertex closed by a triangle fan.

What is controlled, for every facet (both measured against the exact meridian, not the grid):

* chord error (mm): the largest distance from a point of a facet to the exact surface;
* facet-normal error (rad): the largest angle between a facet's normal and the exact surface
  normal at the foot point of any point of that facet.

The density comes from the second-order model of a surface near a point, z = (k1 x^2 + k2 y^2)/2
with x along the meridian (k1 = meridian curvature) and y along the parallel (k2 = |n_r| / r, the
normal curvature of a circle of radius r whose surface normal has radial part n_r). A grid cell
h mm long along the meridian and dphi rad wide, cut into two triangles along a diagonal, has

    chord error  ~ (k1 h^2 + r |n_r| dphi^2) / 8       (largest at the diagonal's midpoint)
    normal error ~ sqrt((k1 h)^2 + (n_r dphi)^2) / 2   (largest at the vertices)

(the sum is exact for synclastic surfaces such as both mirrors and an upper bound otherwise).
``dphi`` is one value for the whole grid, so its share of each budget is set by the largest
r |n_r| and |n_r| on the meridian (the largest radius, for the dome); the rings are then placed
along the arc length so that the rest of the budget is spent evenly (equidistribution of
1 / h_allowed(s)). The split between azimuth and meridian that gives the fewest triangles is
searched on a grid. The mesh is then measured; if a bound is missed (the model is second order)
the budgets are tightened by the measured ratio and the grid rebuilt.

Every sector of the grid is the same strip of facets rotated by a multiple of 2 pi / sectors, and
the nearest point of a surface of revolution to any point lies in that point's meridional
half-plane, so errors measured on one strip hold for every strip (up to rounding, ~1e-13 mm).
:func:`mirror_mesh` measures one strip by default; ``every_facet=True`` measures them all (the
tests check the two agree).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from rigcad.errors import CheckError, ExportError
from rigcad.export.atomic import write_with
from rigcad.optics.surfaces import Meridian

#: Dense samples of the meridian used to plan the grid and to seed projections. The same count
#: Meridian.arc_length_parameters uses; at 20001 the dome's samples are 0.014 mm apart, so the
#: polyline's arc length is exact to ~1e-9 relative and a nearest sample is well inside Newton's
#: basin of convergence (the curve's radius of curvature is >= 5.9 mm).
DENSE_SAMPLES = 20001

#: Fraction of each declared bound the model aims at. The measured error lands within a few per
#: cent of the model (second-order terms, cells not quite rectangles near the apex), so 0.9 keeps
#: one build enough in practice; a miss is caught by the measurement and rebuilt tighter.
TARGET_FRACTION = 0.9

#: Builds tried before giving up; each retry tightens a missed budget by the measured ratio, which
#: converges in one step when the miss is a model error of a few per cent.
MAX_BUILDS = 4

#: A measured error above this multiple of its bound is not the second-order model's error (a few
#: per cent): no retry, CheckError at once (a wrong normal side gives ~pi rad).
MODEL_MISS = 2.0

#: A meridian end closer than this to the axis (mm) is the axis: the ring becomes one apex vertex.
#: One nanometre is far below any printed or optical scale, and a ring that small would give
#: triangles too thin to have a well-defined normal.
AXIS_MM = 1e-9

#: Barycentric lattice order for the measurement: (order+1)(order+2)/2 points per facet. Order 12
#: (91 points, 1/12 of an edge apart) contains the vertices (where the normal error peaks, it is
#: linear in position), the edge midpoints and the centroid, and comes within ~1 % of the peak of a
#: quadratic chord-error function anywhere in the facet.
MEASURE_ORDER = 12

#: Hausdorff check: reference grid refinement (per cell, in u and in azimuth) and lattice order of
#: the points sampled on this mesh's facets. A reference 4x finer has ~1/16 of this mesh's chord
#: error, which bounds how much the mesh-to-reference distance can differ from mesh-to-surface.
HAUSDORFF_REFINE = 4
HAUSDORFF_ORDER = 6
#: Sectors in the wedge sent to pymeshlab: one strip (its two side edges are the edges every sector
#: shares with its neighbours).
HAUSDORFF_SECTORS = 1

#: Candidate shares of the budgets given to the azimuth step (the rest goes to the ring spacing).
_AZIMUTH_SHARES = np.linspace(0.02, 0.98, 49)

PLY_FRAME = "mm, sample point at origin, optical axis +z"
_FACE_DTYPE = np.dtype([("count", "u1"), ("index", "<u4", (3,))])  # packed: 13 bytes per face
_VERTEX_PROPS = ("x", "y", "z", "nx", "ny", "nz")


@dataclass(frozen=True)
class MirrorMesh:
    """A mirror as a triangle mesh, mm, frame of the module docstring; arrays are read-only.

    ``vertices`` (n, 3) float64 points of the exact surface; ``faces`` (m, 3) int64, counter-
    clockwise seen from the reflecting side (right-hand normal points to the side light comes
    from); ``normals`` (n, 3) float64 exact unit surface normals on the reflecting side (the
    meridian's normal rotated to the vertex's azimuth). ``rings`` counts the meridian parameters
    ``ring_parameters`` (an apex ring is one vertex), ``sectors`` the azimuth steps.
    ``report``: declared and measured errors, counts, PLY size, Hausdorff distance (see
    :func:`mirror_mesh`).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    rings: int
    sectors: int
    ring_parameters: np.ndarray
    report: dict = field(default_factory=dict)


class PlyMesh(NamedTuple):
    """Arrays read back from a mirror PLY: vertices (n, 3), faces (m, 3) int64, normals (n, 3), and
    the header's comment lines."""

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    comments: tuple[str, ...]


# -- the meridian, densely sampled -------------------------------------------------------------------
@dataclass(frozen=True)
class _Dense:
    """The meridian at DENSE_SAMPLES parameters: u, points (r, z) mm, unit normals, curvature 1/mm,
    arc length s mm from the bottom, ds/du, and the sign that makes (n_z, -n_r) point along +u."""

    u: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    curvature: np.ndarray
    s: np.ndarray
    dsdu: np.ndarray
    tangent_sign: float


def _dense(meridian: Meridian) -> _Dense:
    u = meridian.sample(DENSE_SAMPLES)
    p = meridian.points(u)
    n = meridian.normals(u)
    k = meridian.curvature(u)
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(n)) and np.all(np.isfinite(k))):
        raise ExportError(f"the {meridian.kind} meridian (offset {meridian.offset} mm) has non-finite points, "
                          "normals or curvature on its u range: cannot mesh it")
    if np.any(k < 0):
        i = int(np.argmax(k < 0))
        raise ExportError(
            f"the {meridian.kind} meridian offset {meridian.offset} mm behind its mirror passes its centre of "
            f"curvature near u = {u[i]:.6g} (curvature {k[i]:.4g} 1/mm): the parallel curve folds over; "
            "use a smaller offset")
    if np.any(p[1:-1, 0] <= AXIS_MM) or np.any(p[:, 0] < -AXIS_MM):
        raise ExportError(f"the {meridian.kind} meridian reaches the axis (r <= 0) away from its ends: "
                          "only an end may lie on the axis (it becomes the apex)")
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    # tangent along +u (finite differences) against the left normal (-t_z, t_r): one sign everywhere
    t = np.gradient(p, u, axis=0)
    side = np.sign(t[:, 0] * n[:, 1] - t[:, 1] * n[:, 0])
    if not (np.all(side > 0) or np.all(side < 0)):
        raise ExportError(f"the {meridian.kind} meridian's normals change side along the curve: "
                          "cannot orient the mesh to the reflecting side")
    return _Dense(u, p, n, k, s, np.gradient(s, u), float(side[0]))


# -- planning the grid -------------------------------------------------------------------------------
def _plan(d: _Dense, target_chord: float, target_normal: float, apex_ends: int):
    """Ring parameters and sector count for the fewest triangles meeting the model's budgets.

    Returns (ring_u (rings,), sectors, azimuth share, model chord error mm, model normal error rad)."""
    r = np.abs(d.points[:, 0])
    nr = np.abs(d.normals[:, 0])
    k = np.abs(d.curvature)
    a_chord = float(np.max(r * nr))  # chord error of the parallel per dphi^2 / 8, mm
    a_normal = float(np.max(nr))  # normal error of the parallel per dphi / 2
    f = _AZIMUTH_SHARES[:, None]
    with np.errstate(divide="ignore"):
        dphi = np.minimum(np.sqrt(8.0 * f * target_chord / a_chord) if a_chord > 0 else np.inf,
                          2.0 * f * target_normal / a_normal if a_normal > 0 else np.inf)
    sectors = np.maximum(np.ceil(2.0 * np.pi / np.minimum(dphi, 2.0 * np.pi / 3)), 3).astype(np.int64)
    dphi = 2.0 * np.pi / sectors  # (shares, 1)
    rest_chord = target_chord - r * nr * dphi**2 / 8.0
    rest_normal2 = (2.0 * target_normal) ** 2 - (nr * dphi) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.minimum(np.sqrt(8.0 * rest_chord / k), np.sqrt(rest_normal2) / k)  # allowed spacing, mm
    # a floor of one cell per meridian length keeps the cumulative density strictly increasing
    # (invertible) where the curve is straight and the allowed spacing is infinite
    density = np.maximum(1.0 / h, 1.0 / d.s[-1])
    cum = np.concatenate([np.zeros((len(f), 1)),
                          np.cumsum(0.5 * (density[:, 1:] + density[:, :-1]) * np.diff(d.s), axis=1)], axis=1)
    # at least one cell, and two when both ends are apexes (a ring must lie between them)
    cells = np.maximum(np.ceil(cum[:, -1]), 1 + apex_ends // 2).astype(np.int64)
    triangles = sectors[:, 0] * (2 * cells - apex_ends)
    best = int(np.argmin(triangles))  # first minimum: deterministic
    s_rings = np.interp(np.linspace(0.0, cum[best, -1], cells[best] + 1), cum[best], d.s)
    ring_u = np.interp(s_rings, d.s, d.u)
    ring_u[0], ring_u[-1] = d.u[0], d.u[-1]
    spacing = cum[best, -1] / cells[best] / density[best]  # the rings' spacing (mm) at each dense sample
    model_chord = float(np.max(k * spacing**2 / 8.0 + r * nr * dphi[best, 0] ** 2 / 8.0))
    model_normal = float(np.max(0.5 * np.hypot(k * spacing, nr * dphi[best, 0])))
    return ring_u, int(sectors[best, 0]), float(_AZIMUTH_SHARES[best]), model_chord, model_normal


# -- building the grid -------------------------------------------------------------------------------
class _Grid(NamedTuple):
    """A grid's arrays and its face layout: cell c (between rings c and c+1) owns the faces from
    ``cell_start[c]``, ``per_sector[c]`` (1 at an apex, else 2) per sector, sector by sector."""

    vertices: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    cell_start: np.ndarray
    per_sector: np.ndarray

    def sector_faces(self, sectors: int) -> np.ndarray:
        """Indices into ``faces`` of the faces of sectors 0 .. sectors-1 (a wedge), cell by cell."""
        k = np.arange(2 * sectors)[None, :]
        idx = self.cell_start[:, None] + k
        return idx[k < self.per_sector[:, None] * sectors]


def _grid(meridian: Meridian, ring_u: np.ndarray, angles: np.ndarray, closed: bool, tangent_sign: float) -> _Grid:
    """The grid of rings ``ring_u`` (rings,) and azimuths ``angles`` (c,) rad; ``closed``: the last
    column joins the first (full rings), else a wedge from angles[0] to angles[-1]. Vertices are
    ring by ring (an apex ring is one vertex); each array is written in one broadcast."""
    p = meridian.points(ring_u)
    n = meridian.normals(ring_u)
    apex_lo, apex_hi = bool(p[0, 0] <= AXIS_MM), bool(p[-1, 0] <= AXIS_MM)
    cols = len(angles)
    cos, sin = np.cos(angles), np.sin(angles)
    full = slice(int(apex_lo), len(ring_u) - int(apex_hi))  # the rings that are not an apex
    n_full = full.stop - full.start
    n_vertices = n_full * cols + apex_lo + apex_hi

    vertices = np.empty((n_vertices, 3))
    normals = np.empty((n_vertices, 3))
    for out, val in ((vertices, p), (normals, n)):
        block = out[int(apex_lo):int(apex_lo) + n_full * cols].reshape(n_full, cols, 3)
        np.multiply(val[full, 0, None], cos, out=block[..., 0])
        np.multiply(val[full, 0, None], sin, out=block[..., 1])
        block[..., 2] = val[full, 1, None]
    if apex_lo:  # on the axis (it was within AXIS_MM of it); normal: the meridian's at azimuth 0
        vertices[0], normals[0] = (0.0, 0.0, p[0, 1]), (n[0, 0], 0.0, n[0, 1])
    if apex_hi:
        vertices[-1], normals[-1] = (0.0, 0.0, p[-1, 1]), (n[-1, 0], 0.0, n[-1, 1])

    # cell between ring i and i+1, sector j: a, b on ring i (columns j, j+1), d, c on ring i+1.
    # Reflecting side left of +u: (d - a) x (b - a) points to it, so the triangles are (a, d, b),
    # (b, d, c); on the right, the reverse.
    j = np.arange(cols if closed else cols - 1)
    j1 = (j + 1) % cols
    a, b, d, c = j, j1, cols + j, cols + j1  # for a cell whose lower ring starts at vertex 0
    first, second = ((a, d, b), (b, d, c)) if tangent_sign > 0 else ((a, b, d), (b, c, d))
    quad = np.stack([np.stack(first, -1), np.stack(second, -1)], axis=1)  # (sectors, 2, 3)
    ring_start = int(apex_lo) + cols * np.arange(n_full - 1)
    fan = len(j)
    faces = np.empty((fan * (apex_lo + apex_hi) + 2 * fan * len(ring_start), 3), dtype=np.int64)
    mid = faces[fan * apex_lo:len(faces) - fan * apex_hi]
    np.add(ring_start[:, None, None, None], quad[None], out=mid.reshape(len(ring_start), fan, 2, 3))
    if apex_lo:  # fan around vertex 0: only the second triangle survives (a == b == 0)
        faces[:fan] = np.where(quad[:, 1] < cols, 0, quad[:, 1] - cols + 1)
    if apex_hi:  # fan around the last vertex: only the first triangle survives (c == d == apex)
        top = int(apex_lo) + cols * (n_full - 1)
        faces[len(faces) - fan:] = np.where(quad[:, 0] < cols, top + quad[:, 0], n_vertices - 1)
    per_sector = np.array([1] * apex_lo + [2] * (n_full - 1) + [1] * apex_hi)
    cell_start = np.concatenate([[0], np.cumsum(per_sector * len(j))[:-1]])
    return _Grid(vertices, normals, faces, cell_start, per_sector)


def _readonly(*arrays: np.ndarray) -> None:
    for arr in arrays:
        arr.flags.writeable = False


# -- measuring against the exact meridian ------------------------------------------------------------
def barycentric_lattice(order: int) -> np.ndarray:
    """Barycentric weights (k, 3) of the points i/order, j/order, l/order with i + j + l = order."""
    i, j = np.meshgrid(np.arange(order + 1), np.arange(order + 1), indexing="ij")
    m = i + j <= order
    i, j = i[m], j[m]
    return np.stack([i, j, order - i - j], axis=-1) / order


def surface_distance(points: np.ndarray, meridian: Meridian, near: float = 0.05) -> np.ndarray:
    """Distance (n,) mm of points (n, 3) from the surface of revolution of ``meridian`` (a point
    beyond an end of the meridian is measured to that end). Points farther than ``near`` mm from
    every dense sample of the meridian get that sample distance (exact to its spacing); nearer
    ones are projected onto the exact curve."""
    rz = np.stack([np.hypot(points[:, 0], points[:, 1]), points[:, 2]], axis=-1)
    coarse, _ = meridian._table.tree.query(rz)  # the foot-point solver's own samples
    close = coarse < near
    if np.any(close):
        u = meridian.foot_points(rz[close])
        coarse[close] = np.linalg.norm(rz[close] - meridian.points(u), axis=1)
    return coarse


def facet_errors(vertices: np.ndarray, faces: np.ndarray, meridian: Meridian,
                 order: int = MEASURE_ORDER) -> tuple[np.ndarray, np.ndarray]:
    """Per-facet chord error (m,) mm and facet-normal error (m,) rad against the exact surface.

    Each facet of ``faces`` (m, 3) into ``vertices`` (n, 3) (mm, frame of the module) is sampled at
    the barycentric lattice of ``order``; a sample's distance to the surface is its distance in the
    (r, z) half-plane to its foot point on the meridian; its normal error is the angle between the
    facet's right-hand normal and the exact normal there, rotated to the sample's azimuth. Both are
    maxima over the samples (a lower bound of the facet's true maximum, within ~1 % at order 12).
    Vectorised, in chunks of about two million samples."""
    w = barycentric_lattice(order)
    chunk = max(1, 2_000_000 // len(w))
    chord = np.empty(len(faces))
    normal = np.empty(len(faces))
    for lo in range(0, len(faces), chunk):  # loop over chunks of facets, not over facets
        tri = vertices[faces[lo:lo + chunk]]  # (mc, 3, 3)
        fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        fn /= np.linalg.norm(fn, axis=1, keepdims=True)
        pts = np.einsum("kv,mvc->mkc", w, tri).reshape(-1, 3)
        rz = np.stack([np.hypot(pts[:, 0], pts[:, 1]), pts[:, 2]], axis=-1)
        u = meridian.foot_points(rz)
        dist = np.linalg.norm(rz - meridian.points(u), axis=1)
        n2 = meridian.normals(u)
        phi = np.arctan2(pts[:, 1], pts[:, 0])
        exact = np.stack([n2[:, 0] * np.cos(phi), n2[:, 0] * np.sin(phi), n2[:, 1]], axis=-1)
        fnk = np.repeat(fn, len(w), axis=0)
        angle = np.arctan2(np.linalg.norm(np.cross(fnk, exact), axis=1), np.sum(fnk * exact, axis=1))
        chord[lo:lo + chunk] = dist.reshape(-1, len(w)).max(axis=1)
        normal[lo:lo + chunk] = angle.reshape(-1, len(w)).max(axis=1)
    return chord, normal


def _hausdorff(meridian: Meridian, ring_u: np.ndarray, sectors: int, tangent_sign: float,
               grid: _Grid) -> dict:
    """Symmetric Hausdorff distance (mm) by pymeshlab between a wedge of HAUSDORFF_SECTORS sectors
    of the mesh and the exact surface over the same azimuths (by rotational symmetry, and because
    a point's nearest surface point lies in its own meridional half-plane, the wedge stands for the
    whole mesh). Surface -> mesh: from the vertices of a reference grid HAUSDORFF_REFINE times finer
    in u and azimuth, which lie on the exact surface. Mesh -> surface: from a barycentric lattice of
    order HAUSDORFF_ORDER on each wedge facet to that reference grid, whose own chord error is about
    1/HAUSDORFF_REFINE^2 of this mesh's. Deterministic (no random sampling)."""
    try:
        import pymeshlab
    except ImportError as err:
        raise ExportError("the mirror mesh's Hausdorff check needs pymeshlab: pip install -e '.[cad]'") from err
    wedge = min(HAUSDORFF_SECTORS, sectors)
    sel = grid.faces[grid.sector_faces(wedge)]
    used, inverse = np.unique(sel, return_inverse=True)
    wedge_v, wedge_f = grid.vertices[used], inverse.reshape(-1, 3)

    refine = HAUSDORFF_REFINE
    t = np.arange(refine) / refine
    ref_u = np.concatenate([(ring_u[:-1, None] + t[None, :] * np.diff(ring_u)[:, None]).ravel(), ring_u[-1:]])
    ref_angles = np.linspace(0.0, 2.0 * np.pi * wedge / sectors, wedge * refine + 1)
    ref = _grid(meridian, ref_u, ref_angles, closed=False, tangent_sign=tangent_sign)
    ref_v, ref_f = ref.vertices, ref.faces

    w = barycentric_lattice(HAUSDORFF_ORDER)
    samples = np.einsum("kv,mvc->mkc", w, wedge_v[wedge_f]).reshape(-1, 3)
    samples = np.unique(samples, axis=0)  # shared edges and vertices once: a sorted, deterministic set

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=samples), "mesh_samples")  # id 0
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=ref_v, face_matrix=ref_f), "reference")  # id 1
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=wedge_v, face_matrix=wedge_f), "mesh")  # id 2
    # maxdist: pymeshlab ignores samples farther than this; the wedge's bounding-box diagonal is
    # more than any distance between two meshes of the same surface patch
    far = pymeshlab.PureValue(float(np.linalg.norm(np.ptp(ref_v, axis=0))))
    to_surface = ms.get_hausdorff_distance(sampledmesh=0, targetmesh=1, samplevert=True, sampleedge=False,
                                           sampleface=False, samplenum=len(samples), maxdist=far)
    to_mesh = ms.get_hausdorff_distance(sampledmesh=1, targetmesh=2, samplevert=True, sampleedge=False,
                                        sampleface=False, samplenum=len(ref_v), maxdist=far)
    return {
        "hausdorff_mm": max(to_surface["max"], to_mesh["max"]),
        "hausdorff_mesh_to_surface_mm": to_surface["max"],
        "hausdorff_surface_to_mesh_mm": to_mesh["max"],
        "hausdorff_sampling": (
            f"pymeshlab get_hausdorff_distance on a {wedge}-sector wedge (every sector is the same up to "
            f"rotation): surface->mesh from the {len(ref_v)} vertices of a reference grid {refine}x finer in u "
            f"and azimuth (points of the exact surface); mesh->surface from {len(samples)} points (barycentric "
            f"lattice of order {HAUSDORFF_ORDER} on {len(wedge_f)} facets) to that reference grid, whose chord "
            f"error is ~1/{refine * refine} of this mesh's"),
    }


# -- the builder ------------------------------------------------------------------------------------
def mirror_mesh(meridian: Meridian, name: str, chord_error: float, normal_error: float,
                every_facet: bool = False) -> MirrorMesh:
    """Mesh the surface of revolution of ``meridian`` about +z (mm) so that every facet is within
    ``chord_error`` mm of the exact surface and its normal within ``normal_error`` rad of the exact
    normal anywhere on it (see the module docstring for the model and the measurement).

    ``every_facet``: measure every facet instead of one sector's strip (same result, by symmetry;
    slower in proportion to the sector count). Raises ExportError for bad arguments or a meridian
    that cannot be meshed, CheckError if the bounds are still missed after MAX_BUILDS builds or
    missed by more than MODEL_MISS times (not a model error: no retry).

    ``report`` (units in the keys): chord_error_mm, facet_normal_error_rad (declared),
    measured_chord_error_mm, measured_facet_normal_error_rad, model_* (predicted), binding (which
    bound sets the density), measured_on, triangles, vertices, rings, sectors, apex_vertices,
    azimuth_share, sector_angle_rad, ring_spacing_min_mm / _max_mm, bytes (PLY size), builds,
    hausdorff_mm (+ its two directions and hausdorff_sampling)."""
    chord_error, normal_error = _checked_bounds(name, chord_error, normal_error)
    d = _dense(meridian)
    ends_on_axis = int(d.points[0, 0] <= AXIS_MM) + int(d.points[-1, 0] <= AXIS_MM)
    b = _build_within(meridian, d, name, chord_error, normal_error, ends_on_axis, every_facet)
    grid, ring_u, sectors = b.grid, b.ring_u, b.sectors
    vertices, normals, faces = grid.vertices, grid.normals, grid.faces
    spacing = np.linalg.norm(np.diff(meridian.points(ring_u), axis=0), axis=1)  # chords between rings, mm
    ratio_c, ratio_n = b.measured_chord / chord_error, b.measured_normal / normal_error
    report = {
        "name": name,
        "meridian_kind": meridian.kind,
        "meridian_offset_mm": float(meridian.offset),
        "frame": PLY_FRAME,
        "chord_error_mm": float(chord_error),
        "facet_normal_error_rad": float(normal_error),
        "measured_chord_error_mm": b.measured_chord,
        "measured_facet_normal_error_rad": b.measured_normal,
        "model_chord_error_mm": b.model_chord,
        "model_facet_normal_error_rad": b.model_normal,
        "binding": "chord" if ratio_c >= ratio_n else "facet_normal",
        "measured_on": (f"{b.measured_facets} facets" + ("" if every_facet else
                        f" of sector 0 (every sector is this strip rotated by a multiple of 2 pi/{sectors})"))
                       + f", {len(barycentric_lattice(MEASURE_ORDER))} barycentric samples each, foot points on "
                       "the exact meridian by Newton",
        "triangles": int(len(faces)),
        "vertices": int(len(vertices)),
        "rings": int(len(ring_u)),
        "sectors": int(sectors),
        "apex_vertices": ends_on_axis,
        "azimuth_share": b.share,
        "sector_angle_rad": 2.0 * np.pi / sectors,
        "ring_spacing_min_mm": float(spacing.min()),
        "ring_spacing_max_mm": float(spacing.max()),
        "bytes": len(_ply_header(name, len(vertices), len(faces), chord_error, normal_error, len(ring_u), sectors))
        + len(vertices) * 8 * len(_VERTEX_PROPS) + len(faces) * _FACE_DTYPE.itemsize,
        "builds": b.builds,
    }
    report.update(_hausdorff(meridian, ring_u, sectors, d.tangent_sign, grid))
    _readonly(vertices, normals, faces, ring_u)
    return MirrorMesh(name, vertices, faces, normals, len(ring_u), sectors, ring_u, report)


def _checked_bounds(name: str, chord_error, normal_error) -> tuple[float, float]:
    """The declared bounds as floats (one repr in report and PLY header); ExportError for a bound
    that is not a positive number, or a facet-normal bound too coarse for the error model."""
    _check_name(name)
    for label, value, unit in (("chord_error", chord_error, "mm"), ("normal_error", normal_error, "rad")):
        if isinstance(value, bool) or not (isinstance(value, numbers.Real) and math.isfinite(value) and value > 0):
            raise ExportError(f"mirror mesh {name!r}: {label} must be a positive number of {unit}, got {value!r}")
    chord_error, normal_error = float(chord_error), float(normal_error)
    # the error model linearises angles (tan x ~ x to 1 % below 0.17 rad); a coarser facet-normal
    # bound is not a mesh anyone should trace rays on
    if normal_error > 0.17:
        raise ExportError(f"mirror mesh {name!r}: normal_error {normal_error} rad is too coarse for the "
                          "small-angle model; use at most 0.17 rad (about 10 deg)")
    return chord_error, normal_error


@dataclass(frozen=True)
class _Built:
    """The last build of :func:`_build_within`: the grid, its rings (meridian parameters) and
    sectors, the azimuth share and the model's errors of its plan, the errors measured on it (mm,
    rad) over ``measured_facets`` facets, and how many builds it took."""
    grid: object
    ring_u: np.ndarray
    sectors: int
    share: float
    model_chord: float
    model_normal: float
    measured_chord: float
    measured_normal: float
    measured_facets: int
    builds: int


def _build_within(meridian: Meridian, d, name: str, chord_error: float, normal_error: float, ends_on_axis: int,
                  every_facet: bool) -> _Built:
    """Plan, build and measure the mesh, tightening the model's targets by the measured misses,
    until both bounds hold (at most MAX_BUILDS builds). CheckError when they still do not, or are
    missed by more than MODEL_MISS times (not a model error: no retry)."""
    target_chord, target_normal = TARGET_FRACTION * chord_error, TARGET_FRACTION * normal_error
    for build in range(1, MAX_BUILDS + 1):
        ring_u, sectors, share, model_chord, model_normal = _plan(d, target_chord, target_normal, ends_on_axis)
        angles = 2.0 * np.pi * np.arange(sectors) / sectors
        grid = _grid(meridian, ring_u, angles, True, d.tangent_sign)
        measured = grid.faces if every_facet else grid.faces[grid.sector_faces(1)]
        chord, normal = facet_errors(grid.vertices, measured, meridian)
        measured_chord, measured_normal = float(chord.max()), float(normal.max())
        if measured_chord <= chord_error and measured_normal <= normal_error:
            break
        if measured_chord > MODEL_MISS * chord_error or measured_normal > MODEL_MISS * normal_error:
            break  # not a model error: refining would not help, report it below
        if measured_chord > chord_error:
            target_chord *= TARGET_FRACTION * chord_error / measured_chord
        if measured_normal > normal_error:
            target_normal *= TARGET_FRACTION * normal_error / measured_normal
    if measured_chord > chord_error or measured_normal > normal_error:
        raise CheckError(
            f"mirror mesh {name!r}: after {build} build(s) the measured chord error {measured_chord:.4g} mm / "
            f"facet-normal error {measured_normal:.4g} rad exceed the declared {chord_error} mm / {normal_error} rad; "
            "the meridian's curvature or normals may not describe its points (a kink, a wrong normal side)")
    return _Built(grid, ring_u, sectors, share, model_chord, model_normal, measured_chord, measured_normal,
                  len(measured), build)


# -- PLY ------------------------------------------------------------------------------------------
def _check_name(name: str) -> None:
    if not (isinstance(name, str) and name and name.isascii() and name.isprintable()):
        raise ExportError(f"mirror mesh name {name!r} must be non-empty printable ASCII (it goes into a PLY header)")


def _ply_header(name: str, n_vertices: int, n_faces: int, chord_error: float, normal_error: float,
                rings: int, sectors: int) -> bytes:
    lines = [
        "ply",
        "format binary_little_endian 1.0",
        f"comment rigcad mirror mesh {name}",
        f"comment frame: {PLY_FRAME}",
        "comment vertex normals: exact unit surface normals on the reflecting side; faces counter-clockwise "
        "seen from it",
        f"comment rings {rings} sectors {sectors} chord_error_mm {chord_error!r} "
        f"facet_normal_error_rad {normal_error!r}",
        f"element vertex {n_vertices}",
        *(f"property double {p}" for p in _VERTEX_PROPS),
        f"element face {n_faces}",
        "property list uchar uint vertex_indices",
        "end_header",
    ]
    return ("\n".join(lines) + "\n").encode("ascii")


def write_ply(path: Path, mesh: MirrorMesh) -> Path:
    """Write ``mesh`` as binary little-endian PLY (x, y, z, nx, ny, nz as double per vertex, mm; faces
    as uchar count + uint32 indices), atomically; the same mesh gives the same bytes. Returns the path."""
    return write_with(Path(path), ply_writer(mesh, path))


def ply_writer(mesh: MirrorMesh, path: Path | str = "<mirror mesh>"):
    """A writer(tmp_path) for :func:`write_ply`'s format, for staged writes."""
    _check_name(mesh.name)
    v = np.asarray(mesh.vertices, dtype=float)
    n = np.asarray(mesh.normals, dtype=float)
    f = np.asarray(mesh.faces)
    if v.ndim != 2 or v.shape[1] != 3 or n.shape != v.shape or f.ndim != 2 or f.shape[1] != 3:
        raise ExportError(f"{path}: mirror mesh {mesh.name!r} needs vertices and normals (n, 3) and faces (m, 3), "
                          f"got {v.shape}, {n.shape}, {f.shape}")
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(n))):
        raise ExportError(f"{path}: mirror mesh {mesh.name!r} has non-finite vertices or normals")
    if len(f) and (f.min() < 0 or f.max() >= len(v) or len(v) > np.iinfo(np.uint32).max):
        raise ExportError(f"{path}: mirror mesh {mesh.name!r} has face indices outside 0..{len(v) - 1} "
                          "or too many vertices for uint32 indices")
    header = _ply_header(mesh.name, len(v), len(f), mesh.report.get("chord_error_mm", float("nan")),
                         mesh.report.get("facet_normal_error_rad", float("nan")), mesh.rings, mesh.sectors)
    vertex_block = np.ascontiguousarray(np.hstack([v, n]), dtype="<f8")
    face_block = np.empty(len(f), dtype=_FACE_DTYPE)
    face_block["count"] = 3
    face_block["index"] = f

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            fh.write(header)
            fh.write(memoryview(vertex_block).cast("B"))
            fh.write(face_block.tobytes())

    return writer


def read_ply(path: Path) -> PlyMesh:
    """Read a PLY written by :func:`write_ply` (exactly that layout; anything else raises ExportError)."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ExportError(f"cannot read {path}: {err.strerror}") from err
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise ExportError(f"{path}: not a PLY file (no 'ply' magic or no end_header)")
    lines = data[:end].decode("ascii", errors="replace").splitlines()
    comments = tuple(line[len("comment "):] for line in lines if line.startswith("comment "))
    body = [line for line in lines if not line.startswith("comment ")]
    try:
        n_vertices = int(body[2].split()[2])
        n_faces = int(body[3 + len(_VERTEX_PROPS)].split()[2])
    except (IndexError, ValueError) as err:
        raise ExportError(f"{path}: PLY header is not a rigcad mirror mesh header") from err
    expected = ["ply", "format binary_little_endian 1.0", f"element vertex {n_vertices}",
                *(f"property double {p}" for p in _VERTEX_PROPS), f"element face {n_faces}",
                "property list uchar uint vertex_indices"]
    if body != expected:
        raise ExportError(f"{path}: PLY header {body} is not the rigcad mirror mesh layout {expected}")
    offset = end + len(b"end_header\n")
    size = n_vertices * 8 * len(_VERTEX_PROPS) + n_faces * _FACE_DTYPE.itemsize
    if len(data) - offset != size:
        raise ExportError(f"{path}: PLY body has {len(data) - offset} bytes, the header says {size}")
    vert = np.frombuffer(data, dtype="<f8", count=n_vertices * len(_VERTEX_PROPS), offset=offset).reshape(-1, 6)
    face = np.frombuffer(data, dtype=_FACE_DTYPE, count=n_faces, offset=offset + vert.nbytes)
    if np.any(face["count"] != 3):
        raise ExportError(f"{path}: PLY has faces that are not triangles")
    return PlyMesh(vert[:, :3].astype(float), face["index"].astype(np.int64), vert[:, 3:].astype(float), comments)


__all__ = ["MirrorMesh", "PlyMesh", "mirror_mesh", "facet_errors", "barycentric_lattice", "write_ply", "read_ply"]
