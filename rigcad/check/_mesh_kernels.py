"""Compiled (numba) passes of the mesh reading (rigcad.check.meshtrace): the float64 glue between
the four Embree casts of a trace, one loop per segment, the same arithmetic as the numpy
reference (trace3d._trace with rays.EmbreeMesh): Moller-Trumbore on Embree's triangle in
float64, facet or interpolated vertex normals, reflections, the poses, the statuses.

Frame: mm, sample point O at the origin, optical axis +z. Poses are (R (3, 3), T (3,)) with
global = R @ local + T (rigcad.optics.frames.Pose). ``tri`` is EmbreeMesh._packed's table: per
face v0, e1 = v1 - v0, e2 = v2 - v0, the unit facet normal, the three vertex normals and 3 zeros
(24 values: 3 cache lines), row ``offsets[g] + prim`` for geometry g. Each pass writes the
float32 origins and directions (and tmax: 1e37 for inf) of the next casts straight from the loop,
for the rays still alive only.

Why: the numpy glue between the casts (float32 conversions, localize/globalize, masks, gathers,
reflections, Hits.closer, result arrays) cost ~1.1 s per million rays, as much as Embree itself;
fused it is a few memory passes.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from rigcad.check._kernels import (ESCAPED_AFTER_DOME, ESCAPED_TOP, MISSED_DOME, MISSED_PARABOLOID,
                                   OCCLUDED_BY_BEAM, OCCLUDED_BY_MOUNT, OCCLUDED_BY_PARABOLOID, OK, _dir_to_global,
                                   _dir_to_local, _reflect, _to_global, _to_local)

_JIT = dict(cache=True, nogil=True, error_model="numpy")
#: The per-ray helpers are inlined by numba itself (its IR): as separate functions each call
#: returns a status that the caller checks, which cost 2-3x on these short loops (measured).
_INLINE = dict(_JIT, inline="always")

#: Embree's tmax for a ray without one (float32; rays.EmbreeMesh.intersect uses the same).
FAR = 1e37
#: Rays ahead whose face rows are prefetched: Embree's hits land on faces in no useful order, so
#: each row (3 cache lines of a table of 13-150 MB) is a cache miss; a few rays ahead hides most
#: of it (measured: 2-3x on the passes; 4 to 32 rays ahead all give the same).
PREFETCH_AHEAD = 8


def _prefetcher(lines: int):
    """An intrinsic that prefetches (llvm.prefetch: a hint, never a fault) the first ``lines``
    64-byte lines of a row of a C-contiguous 2D array (EmbreeMesh._packed's rows are 3 lines,
    aligned; facet normals read the first 2)."""

    @intrinsic
    def prefetch(typingctx, arr, row):
        if not (isinstance(arr, types.Array) and arr.ndim == 2 and arr.layout == "C"):
            return None
        sig = types.void(arr, types.intp)

        def codegen(context, builder, signature, args):
            aryty = signature.args[0]
            ary = context.make_array(aryty)(context, builder, args[0])
            zero = context.get_constant(types.intp, 0)
            ptr = cgutils.get_item_pointer(context, builder, aryty, ary, [args[1], zero], wraparound=False)
            i8p = ir.IntType(8).as_pointer()
            i32 = ir.IntType(32)
            fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]),
                                                "llvm.prefetch.p0i8")
            base = builder.bitcast(ptr, i8p)
            for k in range(lines):  # read, keep in all cache levels, data cache
                builder.call(fn, [builder.gep(base, [ir.Constant(ir.IntType(64), 64 * k)]), ir.Constant(i32, 0),
                                  ir.Constant(i32, 3), ir.Constant(i32, 1)])
            return context.get_dummy_value()

        return sig, codegen

    return prefetch


_prefetch_3_lines = _prefetcher(3)
_prefetch_2_lines = _prefetcher(2)


@nb.njit(**_INLINE)
def _prefetch_hit(geom, prim, offsets, tri, j, smooth):
    """Prefetch the face row of hit j (if it is one) of an Embree result: the lines the normal
    model reads (vertex normals: 3, facet: 2)."""
    if j < geom.shape[0]:
        g = geom[j]
        p = prim[j]
        if p >= 0 and 0 <= g < offsets.shape[0] - 1:
            if smooth:
                _prefetch_3_lines(tri, offsets[g] + p)
            else:
                _prefetch_2_lines(tri, offsets[g] + p)


@nb.njit(**_INLINE)
def _mt(tri, r, ox, oy, oz, dx, dy, dz):
    """Moller-Trumbore in float64 on the plane of face row r: t and barycentrics b1, b2 (as
    _kernels.refine_mesh_hits: NaN / inf for a ray parallel to the face)."""
    e1x, e1y, e1z = tri[r, 3], tri[r, 4], tri[r, 5]
    e2x, e2y, e2z = tri[r, 6], tri[r, 7], tri[r, 8]
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    inv = 1.0 / (e1x * px + e1y * py + e1z * pz)
    sx, sy, sz = ox - tri[r, 0], oy - tri[r, 1], oz - tri[r, 2]
    b1 = (sx * px + sy * py + sz * pz) * inv
    qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    b2 = (dx * qx + dy * qy + dz * qz) * inv
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    return t, b1, b2


@nb.njit(**_INLINE)
def _normal(tri, r, b1, b2, smooth):
    """The face's unit normal (local frame): vertex normals interpolated (``smooth``) or the facet's."""
    if smooth:
        w0 = 1.0 - b1 - b2
        nx = w0 * tri[r, 12] + b1 * tri[r, 15] + b2 * tri[r, 18]
        ny = w0 * tri[r, 13] + b1 * tri[r, 16] + b2 * tri[r, 19]
        nz = w0 * tri[r, 14] + b1 * tri[r, 17] + b2 * tri[r, 20]
        m = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        return nx * m, ny * m, nz * m
    return tri[r, 9], tri[r, 10], tri[r, 11]


@nb.njit(**_INLINE)
def _lost(i, seg, p2, v, landing, path, miss):
    """NaN in what ray i, lost on segment ``seg``, does not reach: p2 and v (lost before the dome
    reflects it: seg 2), the landing point, path length and miss."""
    nan = np.nan
    if seg <= 2:
        p2[i, 0] = p2[i, 1] = p2[i, 2] = nan
        v[i, 0] = v[i, 1] = v[i, 2] = nan
    landing[i, 0] = landing[i, 1] = landing[i, 2] = nan
    path[i] = nan
    miss[i] = nan


@nb.njit(**_JIT)
def source_casts(origins, dirs, pR, pT, pid, o32, d32):
    """Cast 1's float32 inputs: the source rays (n, 3) in the paraboloid's frame (dirs made unit)."""
    for i in range(origins.shape[0]):
        x, y, z = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        m = math.sqrt(x * x + y * y + z * z)
        x, y, z = x / m, y / m, z / m
        ox, oy, oz = _to_local(pR, pT, pid, origins[i, 0], origins[i, 1], origins[i, 2])
        dx, dy, dz = _dir_to_local(pR, pid, x, y, z)
        o32[i, 0], o32[i, 1], o32[i, 2] = ox, oy, oz
        d32[i, 0], d32[i, 1], d32[i, 2] = dx, dy, dz


@nb.njit(**_JIT)
def after_paraboloid(geom, prim, origins, dirs, pR, pT, pid, dR, dT, did, tri, offsets, smooth_g,
                     status, segment, p1, p2, v, landing, path, miss, idx1, t1, u, o32, d32):
    """Segment 1 for every ray (n,): Embree's paraboloid-scene hit (geometry 0 the mirror, >= 1
    its mount) refined in float64, the status of the lost, p1 and the reflected direction u of
    the rest, and cast 2's float32 inputs (dome frame) for them, compacted. Each pass writes each
    output of a ray once (NaN for what a lost ray does not reach). Returns the rays alive, k;
    their indices in idx1[:k], distances t1[:k], directions u[:k]."""
    n = origins.shape[0]
    nan = np.nan
    smooth = smooth_g[0]
    k = 0
    for i in range(n):
        _prefetch_hit(geom, prim, offsets, tri, i + PREFETCH_AHEAD, smooth)
        g = geom[i]
        p = prim[i]
        none = p < 0 or g < 0 or g >= offsets.shape[0] - 1
        if none or g > 0:
            status[i] = MISSED_PARABOLOID if none else OCCLUDED_BY_MOUNT
            segment[i] = 1
            p1[i, 0] = p1[i, 1] = p1[i, 2] = nan
            _lost(i, 2, p2, v, landing, path, miss)
            continue
        x, y, z = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        m = math.sqrt(x * x + y * y + z * z)
        x, y, z = x / m, y / m, z / m
        ox, oy, oz = _to_local(pR, pT, pid, origins[i, 0], origins[i, 1], origins[i, 2])
        dx, dy, dz = _dir_to_local(pR, pid, x, y, z)
        r = offsets[0] + p
        t, b1, b2 = _mt(tri, r, ox, oy, oz, dx, dy, dz)
        nx, ny, nz = _normal(tri, r, b1, b2, smooth)
        qx, qy, qz = _to_global(pR, pT, pid, ox + t * dx, oy + t * dy, oz + t * dz)
        nx, ny, nz = _dir_to_global(pR, pid, nx, ny, nz)
        ux, uy, uz = _reflect(x, y, z, nx, ny, nz)
        status[i] = OK
        segment[i] = 0
        p1[i, 0], p1[i, 1], p1[i, 2] = qx, qy, qz
        idx1[k] = i
        t1[k] = t
        u[k, 0], u[k, 1], u[k, 2] = ux, uy, uz
        lx, ly, lz = _to_local(dR, dT, did, qx, qy, qz)
        ex, ey, ez = _dir_to_local(dR, did, ux, uy, uz)
        o32[k, 0], o32[k, 1], o32[k, 2] = lx, ly, lz
        d32[k, 0], d32[k, 1], d32[k, 2] = ex, ey, ez
        k += 1
    return k


@nb.njit(**_JIT)
def after_dome(k1, geom, prim, idx1, t1, u, pR, pT, pid, dR, dT, did, tri, offsets, smooth_g,
               status, segment, p1, p2, v, landing, path, miss, idx2, t12, t3, o3, d3, m3, o4, d4, m4):
    """Segment 2 for the k1 rays alive: Embree's dome-scene hit (geometry 0 the dome, 1 the beam)
    refined in float64, the status of the lost (beam; none: escaped through the top if going
    up, else below the base), p2 and the reflected direction v of the rest, the distance t3 to
    z = 0 (inf going up: escaped), and the float32 inputs of casts 3 (paraboloid frame) and 4
    (dome frame, the beam) with tmax t3, for the rays that go down. Returns k2: idx2[:k2],
    t1 + t2 in t12[:k2], t3[:k2]."""
    smooth = smooth_g[0]
    k = 0
    for j in range(k1):
        _prefetch_hit(geom, prim, offsets, tri, j + PREFETCH_AHEAD, smooth)
        i = idx1[j]
        g = geom[j]
        p = prim[j]
        ux, uy, uz = u[j, 0], u[j, 1], u[j, 2]
        if p < 0 or g < 0 or g >= offsets.shape[0] - 1:
            status[i] = ESCAPED_TOP if uz > 0 else MISSED_DOME
            segment[i] = 2
            _lost(i, 2, p2, v, landing, path, miss)
            continue
        if g != 0:
            status[i] = OCCLUDED_BY_BEAM
            segment[i] = 2
            _lost(i, 2, p2, v, landing, path, miss)
            continue
        ox, oy, oz = _to_local(dR, dT, did, p1[i, 0], p1[i, 1], p1[i, 2])
        dx, dy, dz = _dir_to_local(dR, did, ux, uy, uz)
        r = offsets[0] + p
        t, b1, b2 = _mt(tri, r, ox, oy, oz, dx, dy, dz)
        nx, ny, nz = _normal(tri, r, b1, b2, smooth)
        qx, qy, qz = _to_global(dR, dT, did, ox + t * dx, oy + t * dy, oz + t * dz)
        nx, ny, nz = _dir_to_global(dR, did, nx, ny, nz)
        wx, wy, wz = _reflect(ux, uy, uz, nx, ny, nz)
        p2[i, 0], p2[i, 1], p2[i, 2] = qx, qy, qz
        v[i, 0], v[i, 1], v[i, 2] = wx, wy, wz
        tz = -qz / wz if wz < 0 else np.inf
        if not math.isfinite(tz):
            status[i] = ESCAPED_AFTER_DOME
            segment[i] = 3
            _lost(i, 3, p2, v, landing, path, miss)
            continue
        idx2[k] = i
        t12[k] = t1[j] + t
        t3[k] = tz
        tm = min(tz, FAR)
        ax, ay, az = _to_local(pR, pT, pid, qx, qy, qz)
        bx, by, bz = _dir_to_local(pR, pid, wx, wy, wz)
        o3[k, 0], o3[k, 1], o3[k, 2] = ax, ay, az
        d3[k, 0], d3[k, 1], d3[k, 2] = bx, by, bz
        m3[k] = tm
        ax, ay, az = _to_local(dR, dT, did, qx, qy, qz)
        bx, by, bz = _dir_to_local(dR, did, wx, wy, wz)
        o4[k, 0], o4[k, 1], o4[k, 2] = ax, ay, az
        d4[k, 0], d4[k, 1], d4[k, 2] = bx, by, bz
        m4[k] = tm
        k += 1
    return k


@nb.njit(**_INLINE)
def _return_hit(geom, prim, tri, offsets, ox, oy, oz, dx, dy, dz, tmax):
    """A return cast's Embree hit refined in float64: t (inf for none or beyond tmax)."""
    if prim < 0 or geom < 0 or geom >= offsets.shape[0] - 1:
        return np.inf
    t, _, _ = _mt(tri, offsets[geom] + prim, ox, oy, oz, dx, dy, dz)
    if t > tmax:
        return np.inf
    return t


@nb.njit(**_JIT)
def after_return(k2, geom3, prim3, geom4, prim4, idx2, t12, t3, pR, pT, pid, dR, dT, did, tri_p, off_p,
                 tri_b, off_b, status, segment, p2, v, landing, path, miss):
    """Segment 3 for the k2 rays going down from the dome: Embree's paraboloid-scene (mirror or
    mount) and beam hits before z = 0, refined in float64; the nearer occludes (the beam on a
    tie); the rest land: landing point, total path and miss = |p2 x v| (the distance from O to
    the returning ray's line)."""
    for j in range(k2):
        i = idx2[j]
        qx, qy, qz = p2[i, 0], p2[i, 1], p2[i, 2]
        wx, wy, wz = v[i, 0], v[i, 1], v[i, 2]
        tz = t3[j]
        ox, oy, oz = _to_local(pR, pT, pid, qx, qy, qz)
        dx, dy, dz = _dir_to_local(pR, pid, wx, wy, wz)
        tp = _return_hit(geom3[j], prim3[j], tri_p, off_p, ox, oy, oz, dx, dy, dz, tz)
        ox, oy, oz = _to_local(dR, dT, did, qx, qy, qz)
        dx, dy, dz = _dir_to_local(dR, did, wx, wy, wz)
        tb = _return_hit(geom4[j], prim4[j], tri_b, off_b, ox, oy, oz, dx, dy, dz, tz)
        by_para = math.isfinite(tp)
        if math.isfinite(tb) and not (by_para and tp < tb):
            status[i] = OCCLUDED_BY_BEAM
            segment[i] = 3
            _lost(i, 3, p2, v, landing, path, miss)
            continue
        if by_para:
            status[i] = OCCLUDED_BY_PARABOLOID
            segment[i] = 3
            _lost(i, 3, p2, v, landing, path, miss)
            continue
        landing[i, 0], landing[i, 1], landing[i, 2] = qx + tz * wx, qy + tz * wy, qz + tz * wz
        path[i] = t12[j] + tz
        cx, cy, cz = qy * wz - qz * wy, qz * wx - qx * wz, qx * wy - qy * wx
        miss[i] = math.sqrt(cx * cx + cy * cy + cz * cz)
