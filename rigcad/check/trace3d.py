"""3D trace: source -> paraboloid -> dome -> sample plane z = 0, with the beam and the paraboloid's
mount as occluders (frame: mm, O at the origin, +z up; vectorised over rays (n, 3)).

Segments: (1) from the source to the paraboloid body (its mirror, or its mount = lost);
(2) from the mirror to the dome, blocked by the beam (which rests in the dome's slots and
moves with it); (3) from the dome to the plane z = 0,
blocked by the beam or the paraboloid (mirror or mount). A ray leaving the convex paraboloid does
not meet it again, and one leaving the concave dome inwards does not meet the dome again, so
those pairs are not traced (no self-intersection at the ray's origin either).
"""

from __future__ import annotations

import contextvars
from contextlib import contextmanager

import numpy as np

# the result type and status codes live in check.result (every tracer returns them); named here too,
# beside trace(), for its callers
from rigcad.check.result import (ESCAPED_AFTER_DOME, ESCAPED_TOP, MISSED_DOME, MISSED_PARABOLOID, OCCLUDED_BY_BEAM,  # noqa: F401
                                 OCCLUDED_BY_MOUNT, OCCLUDED_BY_PARABOLOID, OK, STATUS_NAMES, Trace3D)
from rigcad.check.scene import Optics
from rigcad.optics.vec import cross, dot, reflect_rows, unit


#: Called with the ray count after every trace inside :func:`counting` (a progress bar's feed).
_COUNTER: contextvars.ContextVar = contextvars.ContextVar("rigcad_rays_traced", default=None)


@contextmanager
def counting(callback):
    """Within the block, every :func:`trace` reports its ray count to ``callback(n)``."""
    token = _COUNTER.set(callback)
    try:
        yield
    finally:
        _COUNTER.reset(token)


def trace(optics: Optics, origins: np.ndarray, dirs: np.ndarray, vectorised: bool = False) -> Trace3D:
    """Trace rays (origins, unit dirs: (n, 3), global frame) through ``optics``: by the compiled
    analytic kernels when ``optics`` has them (``optics.fast``, analytic optics), by the compiled
    mesh passes for Embree meshes read with facet or vertex normals (rigcad.check.meshtrace),
    else (or with ``vectorised=True``) by the intersectors' numpy passes (:func:`_trace`)."""
    from rigcad.check import meshtrace

    if optics.fast is not None and not vectorised:
        out = optics.fast.trace(optics, origins, dirs)
    elif not vectorised and meshtrace.supports(optics):
        out = meshtrace.trace(optics, origins, dirs)
    else:
        out = _trace(optics, origins, dirs)
    report = _COUNTER.get()
    if report is not None:
        report(len(origins))
    return out


def _trace(optics: Optics, origins: np.ndarray, dirs: np.ndarray) -> Trace3D:
    n = len(origins)
    dirs = unit(np.asarray(dirs, float))
    origins = np.asarray(origins, float)
    status = np.full(n, OK)
    segment = np.zeros(n, dtype=np.int8)
    nan3 = np.full((n, 3), np.nan)
    p1, p2, v, landing = nan3.copy(), nan3.copy(), nan3.copy(), nan3.copy()
    path = np.full(n, np.nan)

    # 1: source -> paraboloid (mirror part 0, mount parts >= 1)
    pp = optics.paraboloid_pose
    lo, ld = pp.localize(origins, dirs)
    h1 = optics.paraboloid.intersect(lo, ld)
    on_mirror = h1.part == 0
    status[h1.part < 0] = MISSED_PARABOLOID
    status[h1.part > 0] = OCCLUDED_BY_MOUNT
    segment[~on_mirror] = 1
    i1 = np.nonzero(on_mirror)[0]
    t1 = h1.t[i1]
    q1 = pp.globalize_points(lo[i1] + t1[:, None] * ld[i1])
    n1 = pp.globalize_dirs(h1.normal[i1])
    p1[i1] = q1
    u = reflect_rows(dirs[i1], n1)

    # 2: paraboloid -> dome (part 0), the beam (part 1) in between
    dp = optics.dome_pose
    lo2, ld2 = dp.localize(q1, u)
    h2 = optics.dome.intersect(lo2, ld2)
    beam = h2.part == 1
    no_dome = h2.part < 0
    status[i1[beam]] = OCCLUDED_BY_BEAM
    status[i1[no_dome]] = np.where(u[no_dome, 2] > 0, ESCAPED_TOP, MISSED_DOME)
    segment[i1[beam | no_dome]] = 2
    keep = h2.part == 0
    i2 = i1[keep]
    t2 = h2.t[keep]
    q2 = dp.globalize_points(lo2[keep] + t2[:, None] * ld2[keep])
    n2 = dp.globalize_dirs(h2.normal[keep])
    p2[i2] = q2
    w = reflect_rows(u[keep], n2)

    # 3: dome -> plane z = 0, the paraboloid (mirror, mount) and the beam in between
    with np.errstate(divide="ignore", invalid="ignore"):
        t3 = np.where(w[:, 2] < 0, -q2[:, 2] / w[:, 2], np.inf)
    up = ~np.isfinite(t3)
    lo3, ld3 = pp.localize(q2, w)
    h3 = optics.paraboloid.intersect(lo3, ld3, t3)
    lb3, db3 = dp.localize(q2, w)
    hb3 = optics.beam.intersect(lb3, db3, t3)
    by_para = np.isfinite(h3.t) & ~up
    by_beam = np.isfinite(hb3.t) & ~up & ~(by_para & (h3.t < hb3.t))
    by_para &= ~by_beam
    status[i2[up]] = ESCAPED_AFTER_DOME
    status[i2[by_para]] = OCCLUDED_BY_PARABOLOID
    status[i2[by_beam]] = OCCLUDED_BY_BEAM
    segment[i2[up | by_para | by_beam]] = 3
    v[i2] = w
    ok = ~(up | by_para | by_beam)
    i3 = i2[ok]
    landing[i3] = q2[ok] + t3[ok, None] * w[ok]
    path[i3] = t1[keep][ok] + t2[ok] + t3[ok]
    miss = np.full(n, np.nan)
    miss[i3] = np.linalg.norm(cross(q2[ok], w[ok]), axis=1)  # |O - line|, O at the origin
    return Trace3D(status, segment, p1, p2, v, landing, path, miss, {"vectorised": n})


def convergence_point(tr: Trace3D) -> np.ndarray:
    """Least-squares point (3,) nearest to every returning ray's line (NaN if under two rays)."""
    ok = tr.ok
    if np.count_nonzero(ok) < 2:
        return np.full(3, np.nan)
    p, w = tr.p2[ok], tr.v[ok]
    # sum over rays of (I - w w^T) (x - p) = 0; sums by einsum's own loops, not BLAS, whose
    # threaded reductions may round differently with the thread count (tolerancing promises the
    # same bits on any number of workers)
    a = len(w) * np.eye(3) - np.einsum("ij,ik->jk", w, w)
    b = p.sum(axis=0) - np.einsum("ij,i->j", w, dot(w, p))
    return np.linalg.solve(a, b)
