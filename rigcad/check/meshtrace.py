"""The compiled mesh reading: trace3d's source -> paraboloid -> dome -> z = 0 trace through Embree
meshes (modes ``mesh``: facet normals, ``smooth``: interpolated vertex normals) with the float64
glue between the casts in numba passes (rigcad/check/_mesh_kernels.py) instead of numpy array
passes. Frame: mm, sample point O at the origin, optical axis +z; poses as trace3d.

Four Embree casts per trace, each the intersector's own ``EmbreeMesh.raw`` (so its Timer sees
them, as bench/raycheck.py replays them): (1) the source rays in the paraboloid scene; (2) the
rays reflected by the mirror in the dome+beam scene; (3, 4) the rays reflected by the dome and
going down, in the paraboloid scene and in the beam scene, with tmax the distance to z = 0. Each
cast takes only the rays still alive (the numpy path also casts the rays going up after the dome,
whose fate is already known). Results equal trace3d._trace's, the reference (tests/check/
test_meshtrace.py: same status and segment; aligned, the same bits; misaligned, where numpy's
rotation runs in BLAS, points within 4e-11 mm and directions within 4e-13 rad).

Measured (bench/meshglue.py, 1 M annulus rays, achutha2006's exported meshes, 2-core VM, load
~0.7): the glue between the casts 0.22 s (smooth) and 0.19 s (mesh) per million rays, against
1.07 s and 0.84 s for the numpy passes; Embree itself ~1.2 s. What is left: the float64
re-intersection's face rows, gathered at random from a 150 MB table (prefetched), and the
dependent divisions and square roots of each ray's refinement and reflection.
"""

from __future__ import annotations

import threading

import numpy as np

from rigcad.check import _mesh_kernels as K
from rigcad.check.rays import EmbreeMesh
from rigcad.check.result import Trace3D
from rigcad.optics.vec import pose_arrays


def supports(optics) -> bool:
    """True when every intersector of ``optics`` is an EmbreeMesh read with the float64
    refinement and facet or vertex normals (exact_normals, float32 readings and mixed optics
    take the numpy passes)."""
    members = (optics.paraboloid, optics.dome, optics.beam)
    return all(isinstance(m, EmbreeMesh) and m.refine and m.normal_model in ("facet", "vertex") for m in members)


def _scene(mesh: EmbreeMesh):
    """(packed face table, offsets, per-geometry smooth flag) of an Embree intersector."""
    tri, offsets, has = mesh._packed()
    return tri, offsets, has & (mesh.normal_model == "vertex")


#: Rays per block: each block's scratch arrays (~150 bytes a ray) and Embree's result arrays stay
#: in cache and are reused block after block. Fresh memory is what costs here: a page first
#: touched costs more than the arithmetic done on it (measured on the 2-core VM: 240 MB of fresh
#: arrays took 0.07-1 s to fill, 0.02 s once the pages are mapped).
BLOCK = 1 << 16

_WORK = threading.local()


def _scratch(m: int) -> dict:
    """This thread's scratch arrays for blocks of up to m rays (reused; numba releases the GIL, so
    each thread has its own)."""
    work = getattr(_WORK, "arrays", None)
    if work is None or len(work["t1"]) < m:
        work = {"idx1": np.empty(m, np.int64), "t1": np.empty(m), "u": np.empty((m, 3)),
                "idx2": np.empty(m, np.int64), "t12": np.empty(m), "t3": np.empty(m)}
        work.update({k: np.empty((m, 3), np.float32) for k in ("o1", "d1", "o2", "d2", "o3", "d3", "o4", "d4")})
        work.update({k: np.empty(m, np.float32) for k in ("m3", "m4")})
        _WORK.arrays = work
    return work


def trace(optics, origins: np.ndarray, dirs: np.ndarray):
    """Trace rays (origins, dirs: (n, 3), global frame; dirs need not be unit) through Embree
    ``optics`` (:func:`supports`), in blocks of :data:`BLOCK` rays: a result.Trace3D with
    ``kernels = {"mesh_compiled": n}``."""

    origins = np.ascontiguousarray(origins, float)
    dirs = np.ascontiguousarray(dirs, float)
    n = len(origins)
    out = Trace3D.allocate(n, {"mesh_compiled": n})
    status, segment, p1, p2, v, landing, path, miss = out.arrays
    poses = pose_arrays(optics.paraboloid_pose) + pose_arrays(optics.dome_pose)
    work = _scratch(min(n, BLOCK))
    for a in range(0, n, BLOCK):
        b = min(a + BLOCK, n)
        _block(optics, poses, origins[a:b], dirs[a:b], status[a:b], segment[a:b], p1[a:b], p2[a:b], v[a:b],
               landing[a:b], path[a:b], miss[a:b], work)
    return out


def _block(optics, poses, origins, dirs, status, segment, p1, p2, v, landing, path, miss, work):
    """One block of rays: four casts, each followed by its compiled pass (module docstring)."""
    pR, pT, pid, dR, dT, did = poses
    para, dome, beam = optics.paraboloid, optics.dome, optics.beam
    n = len(origins)
    # the timer keeps the inputs of every cast for a replay (bench/raycheck.py): then they are new
    # arrays, not this thread's scratch
    keep = para.timer.keep_inputs or dome.timer.keep_inputs or beam.timer.keep_inputs
    w = {k: np.empty_like(work[k][:n]) for k in work if k[0] in "odm"} if keep else work
    o1, d1 = w["o1"][:n], w["d1"][:n]
    K.source_casts(origins, dirs, pR, pT, pid, o1, d1)
    r1 = para.raw(o1, d1, None)
    tri_p, off_p, smooth_p = _scene(para)
    idx1, t1, u = work["idx1"], work["t1"], work["u"]
    o2, d2 = w["o2"], w["d2"]
    k1 = K.after_paraboloid(r1["geomID"], r1["primID"], origins, dirs, pR, pT, pid, dR, dT, did, tri_p, off_p,
                            smooth_p, status, segment, p1, p2, v, landing, path, miss, idx1, t1, u, o2, d2)
    del r1
    if k1 == 0:
        return
    r2 = dome.raw(o2[:k1], d2[:k1], None)
    tri_d, off_d, smooth_d = _scene(dome)
    idx2, t12, t3 = work["idx2"], work["t12"], work["t3"]
    o3, d3, m3, o4, d4, m4 = (w[k] for k in ("o3", "d3", "m3", "o4", "d4", "m4"))
    k2 = K.after_dome(k1, r2["geomID"], r2["primID"], idx1, t1, u, pR, pT, pid, dR, dT, did, tri_d, off_d,
                      smooth_d, status, segment, p1, p2, v, landing, path, miss, idx2, t12, t3, o3, d3, m3, o4,
                      d4, m4)
    del r2
    if k2 == 0:
        return
    r3 = para.raw(o3[:k2], d3[:k2], m3[:k2])
    r4 = beam.raw(o4[:k2], d4[:k2], m4[:k2])
    tri_b, off_b, _ = _scene(beam)
    K.after_return(k2, r3["geomID"], r3["primID"], r4["geomID"], r4["primID"], idx2, t12, t3, pR, pT, pid,
                   dR, dT, did, tri_p, off_p, tri_b, off_b, status, segment, p2, v, landing, path, miss)
