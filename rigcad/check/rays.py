"""Ray-surface intersection behind one interface, float64 results whatever the backend.

Frame: mm, sample point O at the origin, optical axis +z (the rig's). Every intersector takes
``origins`` (n, 3) and unit ``dirs`` (n, 3) float64 and an optional ``tmax`` (n,) and returns
:class:`Hits`: distance ``t`` (n,) (``inf`` for no hit before ``tmax``), the index of the geometry
hit (``part``, -1 for none) and, for mirrors, the unit normal on the reflecting side.

Backends (the one that ran is in ``backend`` and goes into every report):

* :class:`EmbreeMesh` - Intel Embree through embreex, called directly (``EmbreeScene.run``): a
  float32 BVH finds the triangle, then the hit is recomputed in float64 on that triangle
  (Moller-Trumbore), which takes the float32 error (~1e-5 mm at 400 mm) out of the hit point and
  of the reflected direction. The normal is the facet's (``facet``: what an STL says), the vertex
  normals interpolated with the barycentric weights (``vertex``: a smooth reading), or the exact
  surface normal at the foot point on the meridian (``exact``).
* :class:`NumpyMesh` - brute force in float64 over every triangle: the reference the Embree path
  is tested against hit for hit, for small meshes only (cost n_rays x n_triangles).
* :class:`ExactParaboloid`, :class:`ExactDome`, :class:`Box`, :class:`ZCylinder` - the analytic
  surfaces (closed form; the dome by Newton on its meridian spline) and occluder primitives.

No silent fallback: if embreex cannot be imported, :func:`require_embree` raises CheckError with
an install hint.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rigcad.errors import CheckError
from rigcad.optics.paraboloid import RIM_RTOL
from rigcad.optics.solids import slab, z_cylinder
from rigcad.optics.surfaces import Meridian
# unit: also read as rays.unit by the tracers' callers; _cross, _dot: the names the check modules use
from rigcad.optics.vec import cross as _cross, dot as _dot, unit  # noqa: F401

#: Dense meridian samples that bracket the dome intersection (as mirror_mesh).
DENSE_SAMPLES = 20001
#: Newton steps of the dome intersection. Quadratic convergence from
#: a seed within ~0.01 mm reaches rounding in 3-4 steps; 8 leaves margin.
NEWTON_STEPS = 8
#: Bisection steps of the dome intersection on the tabulated meridian before Newton: the bracket
#: starts below ~500 mm and 2^-30 of it is 5e-7 mm, well inside Newton's basin.
BISECTION_STEPS = 30
#: The fast path's Newton counts as landed on the dome within this distance (mm): float64 round-off
#: on ~300 mm coordinates is ~1e-13; anything above 1e-9 takes the bracketing path instead.
FAST_PATH_RESIDUAL = 1e-9
#: Newton steps from the design correspondence: it starts within ~1e-3 mm on an aligned rig and
#: converges quadratically (1e-3 -> 1e-6 -> 1e-12); a ray that needs more takes the general path.
FAST_PATH_NEWTON_STEPS = 3


@dataclass
class Hits:
    """First hits of n rays: t (n,) mm (inf = none), part (n,) int (-1 = none), normal (n, 3) (NaN
    where none or not a mirror)."""

    t: np.ndarray
    part: np.ndarray
    normal: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "Hits":
        return cls(np.full(n, np.inf), np.full(n, -1, dtype=np.int64), np.full((n, 3), np.nan))

    def closer(self, other: "Hits", part_offset: int = 0) -> "Hits":
        """Per ray the nearer of self and ``other`` (whose parts are shifted by ``part_offset``)."""
        take = other.t < self.t
        return Hits(np.where(take, other.t, self.t),
                    np.where(take, other.part + part_offset, self.part),
                    np.where(take[:, None], other.normal, self.normal))


@dataclass
class Timer:
    """Seconds spent inside the accelerator (``embree_s``) and rays it traced."""

    embree_s: float = 0.0
    embree_rays: int = 0
    calls: list = field(default_factory=list)
    keep_inputs: bool = False


def require_embree():
    """The embreex modules (rtcore_scene, mesh_construction), or CheckError with the install hint."""
    try:
        from embreex import mesh_construction, rtcore_scene
    except ImportError as err:  # pragma: no cover - embreex is a pinned dependency
        raise CheckError("the 3D ray checker needs embreex (Embree): pip install -e '.[cad]'; "
                         "or use --mode analytic") from err
    return rtcore_scene, mesh_construction


def embree_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("embreex")
    except PackageNotFoundError:  # pragma: no cover
        return "unknown"


# -- meshes --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TriMesh:
    """A triangle mesh (mm): vertices (n, 3) float64, faces (m, 3) int64, optional vertex normals
    (n, 3) on the reflecting side and the meridian of the exact surface (mirrors only)."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray | None = None
    meridian: Meridian | None = None
    source: str = ""


def _moller_trumbore(o: np.ndarray, d: np.ndarray, tri: np.ndarray):
    """float64 ray-plane hits on triangles tri (n, 3, 3): t (n,), barycentrics b1, b2 (n,), the
    unnormalised right-hand facet normal (n, 3)."""
    v0 = tri[:, 0]
    e1 = tri[:, 1] - v0
    e2 = tri[:, 2] - v0
    p = _cross(d, e2)
    det = _dot(e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0
        b1 = _dot(s, p) * inv
        q = _cross(s, e1)
        b2 = _dot(d, q) * inv
        t = _dot(e2, q) * inv
    return t, b1, b2, _cross(e1, e2)


def _refine(c: dict, pi: np.ndarray, o: np.ndarray, d: np.ndarray):
    """Moller-Trumbore in float64 on faces ``pi`` (per-face component arrays ``c`` from
    EmbreeMesh._triangles): distance t and barycentrics b1, b2 (k,) of rays o, d (k, 3)."""
    v0x, v0y, v0z = c["vx"][pi], c["vy"][pi], c["vz"][pi]
    e1x, e1y, e1z = c["ex"][pi], c["ey"][pi], c["ez"][pi]
    e2x, e2y, e2z = c["fx"][pi], c["fy"][pi], c["fz"][pi]
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x  # d x e2
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / (e1x * px + e1y * py + e1z * pz)
        sx, sy, sz = o[:, 0] - v0x, o[:, 1] - v0y, o[:, 2] - v0z
        b1 = (sx * px + sy * py + sz * pz) * inv
        qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x  # s x e1
        b2 = (dx * qx + dy * qy + dz * qz) * inv
        t = (e2x * qx + e2y * qy + e2z * qz) * inv
    return t, b1, b2


def foot_normals(meridian: Meridian, points: np.ndarray) -> np.ndarray:
    """Exact unit normals (n, 3) on the reflecting side at the foot points of ``points`` (n, 3) on
    the surface of revolution of ``meridian`` (the meridian's one foot-point solver)."""
    rz = np.stack([np.hypot(points[:, 0], points[:, 1]), points[:, 2]], axis=-1)
    n = meridian.normals(meridian.foot_points(rz))
    cphi, sphi = _azimuth(points)
    return np.stack([n[:, 0] * cphi, n[:, 0] * sphi, n[:, 1]], axis=-1)


def _azimuth(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rho = np.hypot(points[:, 0], points[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(rho > 0, points[:, 0] / rho, 1.0)
        s = np.where(rho > 0, points[:, 1] / rho, 0.0)
    return c, s


class EmbreeMesh:
    """Triangle meshes in one Embree scene (float32 BVH), hits refined in float64.

    ``normal_model``: ``facet``, ``vertex`` or ``exact`` (see the module docstring); occluders (no
    vertex normals) always report facet normals. ``refine=False`` keeps Embree's float32 distance
    and facet normal (to measure what the refinement buys)."""

    def __init__(self, meshes: list[TriMesh], normal_model: str = "vertex", refine: bool = True,
                 timer: Timer | None = None) -> None:
        rtcore_scene, mesh_construction = require_embree()
        if normal_model not in ("facet", "vertex", "exact"):
            raise ValueError(f"normal_model {normal_model!r}: expected facet, vertex or exact")
        self.meshes = meshes
        self.normal_model = normal_model
        self.refine = refine
        self.timer = timer or Timer()
        self.backend = f"embreex {embree_version()} (Embree float32 BVH, EmbreeScene.run)" + (
            " + float64 re-intersection of the hit triangle" if refine else " (float32 hits, not refined)")
        self.scene = rtcore_scene.EmbreeScene()
        self._tri_cache = {}  # shared by the copies share_scenes makes
        self._keep = []
        for m in meshes:
            v = np.ascontiguousarray(m.vertices, dtype=np.float32)
            f = np.ascontiguousarray(m.faces, dtype=np.int32)
            self._keep.append((v, f))
            mesh_construction.TriangleMesh(self.scene, v, f)
        t0 = time.perf_counter()
        # Embree builds its BVH on the first query: do it now so that ray timings are rays only
        self.scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32), output=1)
        self.build_s = time.perf_counter() - t0

    def _triangles(self, g: int) -> dict:
        """Per-face float64 data, gathered once so that each hit costs 1D gathers only: vertex v0,
        edges e1 = v1 - v0, e2 = v2 - v0 and the unit right-hand normal as component arrays (m,),
        and the vertex normals (m, 3, 3) when the mesh has them."""
        if g not in self._tri_cache:
            m = self.meshes[g]
            tri = m.vertices[m.faces]
            e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
            n = unit(np.cross(e1, e2))
            c = {f"{k}{a}": np.ascontiguousarray(arr[:, i]) for k, arr in (("v", tri[:, 0]), ("e", e1), ("f", e2), ("n", n))
                 for i, a in enumerate("xyz")}
            c["vertex_normals"] = None if m.normals is None else np.ascontiguousarray(m.normals[m.faces])
            self._tri_cache[g] = c
        return self._tri_cache[g]

    def _packed(self):
        """Every geometry's per-face float64 data in one table for the compiled passes
        (_kernels.refine_mesh_hits, _mesh_kernels), one row of 24 per face: v0, e1 = v1 - v0,
        e2 = v2 - v0, the unit facet normal, then the three vertex normals (zeros for meshes
        without), 3 zeros; the first row of each geometry; which have vertex normals. One row of
        192 bytes per face starting on a 64-byte cache line: a hit gathers 3 whole lines at
        random (2 for facet normals), not 3-4 straddled ones. Built once, shared by the copies
        share_scenes makes."""
        if "packed" not in self._tri_cache:
            rows, offsets, has = [], [0], []
            for m in self.meshes:
                tri = m.vertices[m.faces]
                e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
                vn = np.zeros((len(m.faces), 9)) if m.normals is None else m.normals[m.faces].reshape(-1, 9)
                rows.append(np.hstack([tri[:, 0], e1, e2, unit(np.cross(e1, e2)), vn, np.zeros((len(m.faces), 3))]))
                offsets.append(offsets[-1] + len(m.faces))
                has.append(m.normals is not None)
            table = np.vstack(rows)
            buf = np.empty(table.size + 8)
            start = (-buf.ctypes.data % 64) // 8  # first float64 on a 64-byte boundary
            packed = buf[start:start + table.size].reshape(table.shape)
            packed[:] = table
            self._tri_cache["packed"] = (packed, np.array(offsets, np.int64), np.array(has, np.bool_))
        return self._tri_cache["packed"]

    @property
    def triangles(self) -> int:
        return int(sum(len(m.faces) for m in self.meshes))

    def raw(self, origins32: np.ndarray, dirs32: np.ndarray, tmax32: np.ndarray | None):
        """One raw EmbreeScene.run (float32 in, Embree's dict out), timed into ``timer``. With
        ``timer.keep_inputs`` the inputs are recorded for a replay (tmax copied before the call:
        Embree writes the hit distances into it)."""
        if self.timer.keep_inputs:
            self.timer.calls.append((self, origins32, dirs32, None if tmax32 is None else tmax32.copy()))
        t0 = time.perf_counter()
        out = self.scene.run(origins32, dirs32, dists=tmax32, output=1)
        dt = time.perf_counter() - t0
        self.timer.embree_s += dt
        self.timer.embree_rays += len(origins32)
        return out

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        n = len(origins)
        hits = Hits.empty(n)
        if n == 0:
            return hits
        o32 = np.ascontiguousarray(origins, dtype=np.float32)
        d32 = np.ascontiguousarray(dirs, dtype=np.float32)
        t32 = None
        if tmax is not None:
            # Embree writes the hit distance into this array; float32 of a finite tmax, 1e37 for inf
            t32 = np.ascontiguousarray(np.minimum(tmax, 1e37), dtype=np.float32)
        res = self.raw(o32, d32, t32)
        geom = res["geomID"]
        prim = res["primID"]
        if self.refine and self.normal_model in ("facet", "vertex"):
            # the float64 re-intersection and the normals in one compiled pass over the hits
            from rigcad.check._kernels import refine_mesh_hits

            tri, offsets, has = self._packed()
            refine_mesh_hits(geom, prim, np.ascontiguousarray(origins, float), np.ascontiguousarray(dirs, float), tri,
                             offsets, has, self.normal_model == "vertex",
                             np.empty(0) if tmax is None else np.ascontiguousarray(tmax, float),
                             hits.t, hits.part, hits.normal)
            return hits
        found = (prim >= 0) & (geom >= 0) & (geom < len(self.meshes))
        for g, mesh in enumerate(self.meshes):  # a handful of geometries, not rays
            idx = np.nonzero(found & (geom == g))[0] if len(self.meshes) > 1 else np.nonzero(found)[0]
            if len(idx) == 0:
                continue
            face = mesh.faces[prim[idx]]
            if not self.refine:
                hits.t[idx] = res["tfar"][idx].astype(float)
                hits.part[idx] = g
                if mesh.normals is None or self.normal_model == "facet":
                    # Embree 2's Ng is our right-hand normal, the reflecting side (same sign:
                    # tests/check/test_rays.py checks it)
                    hits.normal[idx] = unit(res["Ng"][idx].astype(float))
                else:  # Embree's float32 barycentrics: p = (1 - u - v) v0 + u v1 + v v2
                    b1, b2 = res["u"][idx].astype(float), res["v"][idx].astype(float)
                    nv = mesh.normals[face]
                    hits.normal[idx] = unit((1 - b1 - b2)[:, None] * nv[:, 0] + b1[:, None] * nv[:, 1]
                                            + b2[:, None] * nv[:, 2])
                continue
            c = self._triangles(g)
            pi = prim[idx]
            t, b1, b2 = _refine(c, pi, origins[idx], dirs[idx])
            hits.t[idx] = t
            hits.part[idx] = g
            if mesh.normals is None or self.normal_model == "facet":
                hits.normal[idx, 0], hits.normal[idx, 1], hits.normal[idx, 2] = c["nx"][pi], c["ny"][pi], c["nz"][pi]
            elif self.normal_model == "vertex":
                nv = c["vertex_normals"][pi]
                w0 = 1.0 - b1 - b2
                hits.normal[idx] = unit(w0[:, None] * nv[:, 0] + b1[:, None] * nv[:, 1] + b2[:, None] * nv[:, 2])
            else:
                hits.normal[idx] = foot_normals(mesh.meridian, origins[idx] + t[:, None] * dirs[idx])
        if tmax is not None:
            beyond = hits.t > tmax
            hits.t[beyond], hits.part[beyond] = np.inf, -1
        return hits


class NumpyMesh:
    """Brute-force float64 intersection of every ray with every triangle (reference backend; cost
    n_rays x n_triangles, for small meshes in tests). Facet normals, or vertex normals
    interpolated as :class:`EmbreeMesh` does."""

    backend = "numpy brute force, float64 (reference)"

    def __init__(self, meshes: list[TriMesh], normal_model: str = "vertex") -> None:
        self.meshes = meshes
        self.normal_model = normal_model

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        n = len(origins)
        hits = Hits.empty(n)
        tlim = np.full(n, np.inf) if tmax is None else np.asarray(tmax, dtype=float)
        for g, mesh in enumerate(self.meshes):
            tri_all = mesh.vertices[mesh.faces]
            block = max(1, 4_000_000 // max(len(tri_all), 1))
            for a in range(0, n, block):  # blocks of rays x all triangles
                o, d = origins[a:a + block], dirs[a:a + block]
                k = len(o)
                oo = np.repeat(o, len(tri_all), axis=0)
                dd = np.repeat(d, len(tri_all), axis=0)
                tt = np.tile(tri_all, (k, 1, 1))
                t, b1, b2, _ = _moller_trumbore(oo, dd, tt)
                ok = (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1) & (t > 0)
                t = np.where(ok, t, np.inf).reshape(k, len(tri_all))
                j = np.argmin(t, axis=1)
                best = t[np.arange(k), j]
                better = (best < hits.t[a:a + block]) & (best <= tlim[a:a + block])
                rows = np.nonzero(better)[0] + a
                if len(rows) == 0:
                    continue
                jj = j[better]
                face = mesh.faces[jj]
                tri = mesh.vertices[face]
                t1, c1, c2, ng = _moller_trumbore(origins[rows], dirs[rows], tri)
                hits.t[rows] = t1
                hits.part[rows] = g
                if mesh.normals is None or self.normal_model == "facet":
                    hits.normal[rows] = unit(ng)
                else:
                    nv = mesh.normals[face]
                    w0 = 1.0 - c1 - c2
                    hits.normal[rows] = unit(w0[:, None] * nv[:, 0] + c1[:, None] * nv[:, 1] + c2[:, None] * nv[:, 2])
        return hits


# -- exact surfaces --------------------------------------------------------------------------------
class ExactParaboloid:
    """The paraboloid z = vertex_z - r^2 / (4 f), r <= rim_radius, in closed form (float64)."""

    backend = "analytic float64 (closed-form paraboloid)"

    def __init__(self, focal_length: float, vertex_z: float, rim_radius: float) -> None:
        self.f, self.zv, self.rim = focal_length, vertex_z, rim_radius

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        f, o, d = self.f, origins, dirs
        a = (d[:, 0] ** 2 + d[:, 1] ** 2) / (4 * f)
        b = (o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]) / (2 * f) + d[:, 2]
        c = (o[:, 0] ** 2 + o[:, 1] ** 2) / (4 * f) + o[:, 2] - self.zv
        disc = b * b - 4 * a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
            q = -0.5 * (b + np.copysign(sq, b))  # stable roots q / a and c / q
            r1 = np.where(np.abs(a) > 1e-300, q / a, np.nan)
            r2 = c / q
        hits = Hits.empty(len(o))
        eps = 1e-9  # mm: a ray starting on the surface does not re-hit it at its origin
        best = np.full(len(o), np.inf)
        for r in (r1, r2):
            p = o + np.nan_to_num(r)[:, None] * d
            ok = np.isfinite(r) & (r > eps) & (p[:, 0] ** 2 + p[:, 1] ** 2 <= (self.rim * (1 + RIM_RTOL)) ** 2)
            best = np.where(ok & (r < best), r, best)
        if tmax is not None:
            best = np.where(best <= tmax, best, np.inf)
        hit = np.isfinite(best)
        p = o[hit] + best[hit, None] * d[hit]
        hits.t = best
        hits.part[hit] = 0
        hits.normal[hit] = unit(np.stack([p[:, 0] / (2 * f), p[:, 1] / (2 * f), np.ones(len(p))], axis=-1))
        return hits


class ExactDome:
    """The dome's surface of revolution r = R(z) from its meridian spline (float64).

    The dome's interior is convex (its meridian is, towards the axis), so a ray from inside crosses
    it once: bracketed on the densely tabulated meridian (bisection), then polished by Newton on
    (t, u) against the spline itself, so the result is the spline's, not the table's. A ray that
    leaves the z range [bottom, top] of the mirror first does not hit it."""

    backend = "analytic float64 (dome meridian spline, Newton)"

    def __init__(self, meridian: Meridian, correspondence: bool = True) -> None:
        #: False: every ray takes the bracketing path (the reference the kernels are tested against)
        self.correspondence = correspondence
        self.m = meridian
        u = meridian.sample(DENSE_SAMPLES)
        p = meridian.points(u)
        if not np.all(np.diff(p[:, 1]) > 0):
            raise CheckError("the dome meridian's height is not monotonic: ExactDome needs r = R(z)")
        self.u_tab, self.r_tab, self.z_tab = u, p[:, 0], p[:, 1]
        self.z_lo, self.z_hi, self.r_max = float(p[0, 1]), float(p[-1, 1]), float(p[:, 0].max())

    def _newton(self, o: np.ndarray, d: np.ndarray, t: np.ndarray, u: np.ndarray, steps: int = NEWTON_STEPS):
        """Polish (t, u) so that o + t d lies on the spline's surface; returns t, u, residual (mm)."""
        spline, deriv = self.m._spline, self.m._spline.derivative()
        if self.m.offset != 0.0:  # pragma: no cover - the checker traces design surfaces
            raise CheckError("ExactDome traces the design surface (offset 0)")
        u_lo, u_hi = self.m.u_range
        for _ in range(steps):
            c = spline(u)
            dc = deriv(u)
            px = o + t[:, None] * d
            rho = np.hypot(px[:, 0], px[:, 1])
            f1 = rho - c[:, 0]
            f2 = px[:, 2] - c[:, 1]
            a11 = (px[:, 0] * d[:, 0] + px[:, 1] * d[:, 1]) / rho
            a12 = -dc[:, 0]
            a21 = d[:, 2]
            a22 = -dc[:, 1]
            det = a11 * a22 - a12 * a21
            t = t - (a22 * f1 - a12 * f2) / det
            u = np.clip(u - (-a21 * f1 + a11 * f2) / det, u_lo, u_hi)
        c = spline(u)
        px = o + t[:, None] * d
        residual = np.hypot(np.hypot(px[:, 0], px[:, 1]) - c[:, 0], px[:, 2] - c[:, 1])
        return t, u, residual

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        """First hit of rays from inside the dome.

        Fast path first: a ray leaving the paraboloid at radius s meets the aligned, axisymmetric
        design dome at its profile point for s (the design's own correspondence, u = -s), so Newton
        starts there; rays whose Newton does not land on the surface inside the mirror's range
        (misaligned rigs, stray rays) take the general bracketing path. Tests check both agree."""
        o, d = origins, dirs
        n = len(o)
        hits = Hits.empty(n)
        u_lo, u_hi = self.m.u_range
        if not self.correspondence:
            idx, t, u = self._bracketed(o, d)
            return self._hits(hits, o, d, idx, t, u, tmax)
        u0 = np.clip(-np.hypot(o[:, 0], o[:, 1]), u_lo, u_hi)
        c0 = self.m._spline(u0)
        # seed t: where the ray reaches the seed point's height (or, for a level ray, its radius)
        with np.errstate(invalid="ignore", divide="ignore"):
            t0 = np.where(np.abs(d[:, 2]) > 1e-3, (c0[:, 1] - o[:, 2]) / d[:, 2],
                          (c0[:, 0] - np.hypot(o[:, 0], o[:, 1])) / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-12))
        t, u, res = self._newton(o, d, np.where(np.isfinite(t0) & (t0 > 0), t0, 1.0), u0, FAST_PATH_NEWTON_STEPS)
        fast = (res < FAST_PATH_RESIDUAL) & np.isfinite(t) & (t > 0) & (u > u_lo) & (u < u_hi)
        rest = np.nonzero(~fast)[0]
        idx = np.nonzero(fast)[0]
        t_all, u_all = t[idx], u[idx]
        if len(rest):
            r_idx, r_t, r_u = self._bracketed(o[rest], d[rest])
            idx = np.concatenate([idx, rest[r_idx]])
            t_all = np.concatenate([t_all, r_t])
            u_all = np.concatenate([u_all, r_u])
        return self._hits(hits, o, d, idx, t_all, u_all, tmax)

    def _hits(self, hits: Hits, o, d, idx, t_all, u_all, tmax) -> Hits:
        ok = np.isfinite(t_all) & (t_all > 0)
        if tmax is not None:
            ok &= t_all <= tmax[idx]
        idx, t, u = idx[ok], t_all[ok], u_all[ok]
        hits.t[idx] = t
        hits.part[idx] = 0
        n2 = self.m.normals(u)
        cphi, sphi = _azimuth(o[idx] + t[:, None] * d[idx])
        hits.normal[idx] = np.stack([n2[:, 0] * cphi, n2[:, 0] * sphi, n2[:, 1]], axis=-1)
        return hits

    def _bracketed(self, o: np.ndarray, d: np.ndarray):
        """General path: bracket the crossing on the tabulated meridian (bisection), then Newton."""
        n = len(o)
        dxy2 = d[:, 0] ** 2 + d[:, 1] ** 2
        oxy_d = o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]
        oxy2 = o[:, 0] ** 2 + o[:, 1] ** 2
        # where the ray leaves the cylinder r = r_max (+1 mm) and the slab z_lo..z_hi
        big = (self.r_max + 1.0) ** 2
        with np.errstate(invalid="ignore", divide="ignore"):
            t_cyl = (-oxy_d + np.sqrt(np.maximum(oxy_d ** 2 - dxy2 * (oxy2 - big), 0))) / dxy2
            t_top = np.where(d[:, 2] > 0, (self.z_hi - o[:, 2]) / d[:, 2], np.inf)
            t_bot = np.where(d[:, 2] < 0, (self.z_lo - o[:, 2]) / d[:, 2], np.inf)
        t_end = np.fmin(np.fmin(t_cyl, t_top), t_bot)

        def h(t):  # > 0 outside the mirror (tabulated meridian)
            z = o[:, 2] + t * d[:, 2]
            rho = np.sqrt(oxy2 + 2 * t * oxy_d + t * t * dxy2)
            return rho - np.interp(z, self.z_tab, self.r_tab)

        inside0 = h(np.zeros(n)) < 0
        cross = inside0 & np.isfinite(t_end) & (h(t_end) >= 0)
        lo, hi = np.zeros(n), np.where(np.isfinite(t_end), t_end, 0.0)
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (lo + hi)
            out = h(mid) >= 0
            hi = np.where(out, mid, hi)
            lo = np.where(out, lo, mid)
        idx = np.nonzero(cross)[0]
        t = 0.5 * (lo[idx] + hi[idx])
        u = np.interp(o[idx, 2] + t * d[idx, 2], self.z_tab, self.u_tab)
        t, u, _ = self._newton(o[idx], d[idx], t, u)
        return idx, t, u


class Box:
    """Axis-aligned box [lo, hi] (mm), an occluder (the slab test, float64)."""

    backend = "analytic float64 (box)"

    def __init__(self, lo, hi) -> None:
        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)

    def intersect(self, origins, dirs, tmax=None) -> Hits:
        return _solid_hits(*slab(origins, dirs, self.lo, self.hi), tmax)


def _solid_hits(t_lo: np.ndarray, t_hi: np.ndarray, tmax) -> "Hits":
    """Hits on a convex solid from each ray's entry/exit distances (a ray starting inside hits at 0)."""
    t = np.where((t_lo <= t_hi) & (t_hi > 0), np.maximum(t_lo, 0.0), np.inf)
    if tmax is not None:
        t = np.where(t <= tmax, t, np.inf)
    hits = Hits.empty(len(t))
    hits.t = t
    hits.part[np.isfinite(t)] = 0
    return hits


class ZCylinder:
    """Solid cylinder about the z axis through (cx, cy): radius, z from z0 to z1 (mm); an occluder."""

    backend = "analytic float64 (cylinder)"

    def __init__(self, radius: float, z0: float, z1: float, cx: float = 0.0, cy: float = 0.0) -> None:
        self.r, self.z0, self.z1, self.c = radius, z0, z1, np.array([cx, cy])

    def intersect(self, origins, dirs, tmax=None) -> Hits:
        return _solid_hits(*z_cylinder(origins, dirs, self.r, self.z0, self.z1, tuple(self.c)), tmax)


class Group:
    """Several intersectors as one: the nearest hit, ``part`` numbered in order of the members (each
    member's own parts offset by the parts before it; ``sizes`` gives each member's part count)."""

    def __init__(self, members: list, sizes: list[int] | None = None) -> None:
        self.members = members
        self.sizes = sizes or [1] * len(members)
        self.backend = "; ".join(sorted({m.backend for m in members}))

    def intersect(self, origins, dirs, tmax=None) -> Hits:
        hits = Hits.empty(len(origins))
        offset = 0
        for m, size in zip(self.members, self.sizes):
            hits = hits.closer(m.intersect(origins, dirs, tmax), offset)
            offset += size
        return hits
