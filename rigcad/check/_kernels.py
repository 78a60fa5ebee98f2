"""Compiled (numba) kernels of the analytic tracer (rigcad.check.analytic): one loop per ray in
float64, the same arithmetic as the vectorised reference in rays.py / trace3d.py.

Frame: mm, sample point O at the origin, optical axis +z. Poses are (R (3, 3), T (3,)) with
global = R @ local + T (rigcad.optics.frames.Pose). Occluders are rows of an (k, 11) array:
``[0, lo_x, lo_y, lo_z, hi_x, hi_y, hi_z]`` for a box, ``[1, radius, z0, z1, cx, cy, 0]`` for a
z-cylinder (rigcad.optics.solids gives the same entry distances, vectorised), each followed by
a bounding sphere ``[cx, cy, cz, radius]`` (columns 7..10) that lets most rays skip the test.

Statuses are trace3d's codes (kept in step by tests/check/test_analytic.py).

Why numba: a ray costs ~100 float64 operations and a few branches; as numpy array passes that is
~100 trips through memory per ray (the vectorised path: 0.14 M rays/s on one core), fused in one
compiled loop it is 12 M rays/s aligned (the table kernel) and 2.6 M rays/s misaligned (Newton)
through trace3d.trace (bench/raycheck.py measures them against raw Embree on the same rays).
``cache=True`` keeps the machine code on disk (``__pycache__``) so worker processes do not
recompile (the first compile on a machine: ~22 s).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_JIT = dict(cache=True, nogil=True, error_model="numpy")
#: Helpers that take arrays are inlined by numba itself (not left to LLVM): called per ray, they
#: otherwise pay a reference count increment and decrement per array per call; inlined, numba
#: prunes them (the misaligned kernel: 0.65 -> 0.39 s per 1 M rays). Scalar helpers are left to
#: LLVM, which inlines them as well: the same speed, and half the first compile (~22 s, then cached).
_INLINE = dict(_JIT, inline="always")

# trace3d status codes (duplicated for the compiled code; test_analytic checks they agree)
OK, MISSED_PARABOLOID, OCCLUDED_BY_MOUNT, OCCLUDED_BY_BEAM, OCCLUDED_BY_PARABOLOID, ESCAPED_TOP, \
    MISSED_DOME, ESCAPED_AFTER_DOME = range(8)

#: Distance (mm) a ray must travel before it can hit the paraboloid (rays.ExactParaboloid's eps).
PARABOLOID_EPS = 1e-9
#: optics.paraboloid.RIM_RTOL (a hit within 1e-12 of the rim radius counts), restated here because
#: numba's cache keeps a value read from another file; tests/check assert that the two are equal.
RIM_RTOL = 1e-12


@nb.njit(**_JIT)
def _slab(o, d, lo, hi, tlo, thi):
    """One axis of the slab test: the interval (tlo, thi) narrowed (tlo > thi: no hit)."""
    if d == 0.0:
        if o < lo or o > hi:
            return np.inf, -np.inf
        return tlo, thi
    t1 = (lo - o) / d
    t2 = (hi - o) / d
    if t1 > t2:
        t1, t2 = t2, t1
    return max(tlo, t1), min(thi, t2)


@nb.njit(**_JIT)
def _box(ox, oy, oz, dx, dy, dz, lx, ly, lz, hx, hy, hz):
    """Entry distance of a ray into the box [l, h] (0 from inside, inf for none): solids.slab."""
    tlo, thi = _slab(ox, dx, lx, hx, -np.inf, np.inf)
    tlo, thi = _slab(oy, dy, ly, hy, tlo, thi)
    tlo, thi = _slab(oz, dz, lz, hz, tlo, thi)
    if tlo <= thi and thi > 0.0:
        return max(tlo, 0.0)
    return np.inf


@nb.njit(**_JIT)
def _cylinder(ox, oy, oz, dx, dy, dz, r, z0, z1, cx, cy):
    """Entry distance into a solid z-cylinder (0 from inside, inf for none): solids.z_cylinder."""
    ox = ox - cx
    oy = oy - cy
    a = dx * dx + dy * dy
    b = ox * dx + oy * dy
    c = ox * ox + oy * oy - r * r
    disc = b * b - a * c
    if a > 0.0:
        if disc >= 0.0:
            sq = math.sqrt(disc)
            r_in = (-b - sq) / a
            r_out = (-b + sq) / a
        else:
            r_in, r_out = np.inf, -np.inf
    elif disc >= 0.0:
        r_in = -np.inf if c <= 0.0 else np.inf
        r_out = np.inf if c <= 0.0 else -np.inf
    else:
        r_in, r_out = np.inf, -np.inf
    if dz == 0.0:
        inside = z0 <= oz <= z1
        zl = -np.inf if inside else np.inf
        zh = np.inf if inside else -np.inf
    else:
        za = (z0 - oz) / dz
        zb = (z1 - oz) / dz
        zl, zh = (za, zb) if za < zb else (zb, za)
    tlo = max(r_in, zl)
    thi = min(r_out, zh)
    if tlo <= thi and thi > 0.0:
        return max(tlo, 0.0)
    return np.inf


@nb.njit(**_JIT)
def _reaches_sphere(cx, cy, cz, radius, ox, oy, oz, dx, dy, dz, tmax):
    """Can the ray o + t d (unit d), 0 <= t <= tmax, meet the sphere (centre c)? False only when
    its line passes outside the sphere or meets it wholly behind the origin or beyond tmax."""
    wx, wy, wz = cx - ox, cy - oy, cz - oz
    b = wx * dx + wy * dy + wz * dz
    h = radius * radius - (wx * wx + wy * wy + wz * wz - b * b)  # (half chord)^2 of the sphere on the line
    return not (h < 0.0 or (b < 0.0 and b * b > h) or (b > tmax and (b - tmax) * (b - tmax) > h))


@nb.njit(**_INLINE)
def _occluders(occ, ox, oy, oz, dx, dy, dz, tmax):
    """Nearest entry distance (<= tmax) into any occluder row of ``occ`` (inf for none). Columns
    7..10 of a row hold a sphere around the solid (centre, radius): a ray that cannot reach it
    (:func:`_reaches_sphere`) skips the exact test."""
    best = np.inf
    for k in range(occ.shape[0]):
        if not _reaches_sphere(occ[k, 7], occ[k, 8], occ[k, 9], occ[k, 10], ox, oy, oz, dx, dy, dz, tmax):
            continue
        if occ[k, 0] == 0.0:
            t = _box(ox, oy, oz, dx, dy, dz, occ[k, 1], occ[k, 2], occ[k, 3], occ[k, 4], occ[k, 5], occ[k, 6])
        else:
            t = _cylinder(ox, oy, oz, dx, dy, dz, occ[k, 1], occ[k, 2], occ[k, 3], occ[k, 4], occ[k, 5])
        if t <= tmax and t < best:
            best = t
    return best


@nb.njit(**_JIT)
def _paraboloid(ox, oy, oz, dx, dy, dz, f, zv, rim, tmax):
    """Nearest hit beyond PARABOLOID_EPS of z = zv - r^2 / (4 f), r <= rim (ExactParaboloid)."""
    i4f = 0.25 / f
    a = (dx * dx + dy * dy) * i4f
    b = (ox * dx + oy * dy) * (2.0 * i4f) + dz
    c = (ox * ox + oy * oy) * i4f + oz - zv
    disc = b * b - 4.0 * a * c
    if not disc >= 0.0:
        return np.inf
    sq = math.sqrt(disc)
    q = -0.5 * (b + math.copysign(sq, b))
    best = np.inf
    r1 = q / a if abs(a) > 1e-300 else np.nan
    r2 = c / q
    for r in (r1, r2):
        if math.isfinite(r) and r > PARABOLOID_EPS:
            px = ox + r * dx
            py = oy + r * dy
            if px * px + py * py <= (rim * (1.0 + RIM_RTOL)) * (rim * (1.0 + RIM_RTOL)) and r < best:
                best = r
    return best if best <= tmax else np.inf


@nb.njit(**_JIT)
def _paraboloid_bounded(ox, oy, oz, dx, dy, dz, f, zv, rim, tmax):
    """:func:`_paraboloid`, skipped when the ray cannot reach the mirror's bounding sphere (centre
    on the axis halfway between vertex and rim plane). The rim lies ON that sphere, so its radius
    gets the occluder rows' margin (1e-6 relative + 1e-9 mm): rounding never skips a ray that
    :func:`_paraboloid` would find at the rim."""
    sag = rim * rim / (4.0 * f)
    radius = math.sqrt(rim * rim + 0.25 * sag * sag) * (1.0 + 1e-6) + 1e-9
    if not _reaches_sphere(0.0, 0.0, zv - 0.5 * sag, radius, ox, oy, oz, dx, dy, dz, tmax):
        return np.inf
    return _paraboloid(ox, oy, oz, dx, dy, dz, f, zv, rim, tmax)


@intrinsic
def _fma(typingctx, a, b, c):
    """a * b + c rounded once (llvm.fma.f64)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        f = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(f, [f, f, f]), "llvm.fma.f64")
        return builder.call(fn, args)

    return sig, codegen


# The rotations below are summed as fma(z, R_z, fma(y, R_y, x R_x)): the order numpy's (n, 3) @ (3, 3)
# takes through OpenBLAS's dgemm on this x86-64 (measured: the same bits on every row), so that the
# compiled path and the numpy reference (Pose.localize / globalize_*) agree to the bit; with
# another BLAS they agree to rounding (~1e-13 mm at ~400 mm).
@nb.njit(**_INLINE)
def _dir_to_local(R, ident, x, y, z):
    """Direction from the global frame into a body's: R^T d."""
    if ident:
        return x, y, z
    return (_fma(z, R[2, 0], _fma(y, R[1, 0], x * R[0, 0])), _fma(z, R[2, 1], _fma(y, R[1, 1], x * R[0, 1])),
            _fma(z, R[2, 2], _fma(y, R[1, 2], x * R[0, 2])))


@nb.njit(**_INLINE)
def _to_local(R, T, ident, px, py, pz):
    """Point from the global frame into a body's: R^T (p - T)."""
    if ident:
        return px, py, pz
    return _dir_to_local(R, False, px - T[0], py - T[1], pz - T[2])


@nb.njit(**_INLINE)
def _dir_to_global(R, ident, x, y, z):
    """Direction from a body's frame into the global one: R d."""
    if ident:
        return x, y, z
    return (_fma(z, R[0, 2], _fma(y, R[0, 1], x * R[0, 0])), _fma(z, R[1, 2], _fma(y, R[1, 1], x * R[1, 0])),
            _fma(z, R[2, 2], _fma(y, R[2, 1], x * R[2, 0])))


@nb.njit(**_INLINE)
def _to_global(R, T, ident, x, y, z):
    """Point from a body's frame into the global one: R p + T."""
    if ident:
        return x, y, z
    gx, gy, gz = _dir_to_global(R, False, x, y, z)
    return gx + T[0], gy + T[1], gz + T[2]


@nb.njit(**_INLINE)
def _piece(brk, u, hint):
    """Index of the spline piece holding u (the last whose left breakpoint is <= u), walking from
    ``hint`` (Newton moves u by little, so this is a step or two; a far hint costs a binary search)."""
    m = brk.shape[0] - 1
    lo = min(max(hint, 0), m - 1)
    for _ in range(4):
        if brk[lo] > u and lo > 0:
            lo -= 1
        elif lo < m - 1 and brk[lo + 1] <= u:
            lo += 1
        else:
            return lo
    lo, hi = 0, m - 1
    while lo < hi:
        mid = (lo + hi + 1) >> 1
        if brk[mid] <= u:
            lo = mid
        else:
            hi = mid - 1
    return lo


@nb.njit(**_INLINE)
def _spline(brk, cr, cz, u, hint):
    """Dome meridian (r, z), d/du at parameter u and the piece used: piecewise quintic (PPoly
    coefficients, highest power first) on breakpoints ``brk``."""
    lo = _piece(brk, u, hint)
    x = u - brk[lo]
    r = cr[lo, 0]
    z = cz[lo, 0]
    dr = 0.0
    dz = 0.0
    for k in range(1, 6):
        dr = dr * x + r
        dz = dz * x + z
        r = r * x + cr[lo, k]
        z = z * x + cz[lo, k]
    return r, z, dr, dz, lo


@nb.njit(**_JIT)
def _reflect(dx, dy, dz, nx, ny, nz):
    k = 2.0 * (dx * nx + dy * ny + dz * nz)
    return dx - k * nx, dy - k * ny, dz - k * nz


@nb.njit(**_INLINE)
def _return_leg(i, q2x, q2y, q2z, wx, wy, wz, t1, t2, R1, T1, id1, R2, T2, id2, f, zv, rim, para_occ, body_sphere,
                beam_occ, status, segment, p1, p2, v, landing, path, miss):
    """Segment 3 (dome -> plane z = 0, blocked by the paraboloid body or the beam): trace3d.
    ``body_sphere`` (centre, radius; the paraboloid's frame) holds the mirror and its mount: a ray
    that cannot reach it skips their tests."""
    v[i, 0], v[i, 1], v[i, 2] = wx, wy, wz
    t3 = -q2z / wz if wz < 0.0 else np.inf
    if not math.isfinite(t3):
        _lost(i, ESCAPED_AFTER_DOME, 3, status, segment, p1, p2, v, landing, path, miss)
        return
    hp = np.inf
    lx, ly, lz = _to_local(R1, T1, id1, q2x, q2y, q2z)
    ldx, ldy, ldz = _dir_to_local(R1, id1, wx, wy, wz)
    if _reaches_sphere(body_sphere[0], body_sphere[1], body_sphere[2], body_sphere[3], lx, ly, lz, ldx, ldy, ldz, t3):
        hp = _paraboloid_bounded(lx, ly, lz, ldx, ldy, ldz, f, zv, rim, t3)
        ho = _occluders(para_occ, lx, ly, lz, ldx, ldy, ldz, t3)
        if ho < hp:
            hp = ho
    bx, by, bz = _to_local(R2, T2, id2, q2x, q2y, q2z)
    bdx, bdy, bdz = _dir_to_local(R2, id2, wx, wy, wz)
    hb = _occluders(beam_occ, bx, by, bz, bdx, bdy, bdz, t3)
    by_para = math.isfinite(hp)
    by_beam = math.isfinite(hb) and not (by_para and hp < hb)
    if by_beam:
        _lost(i, OCCLUDED_BY_BEAM, 3, status, segment, p1, p2, v, landing, path, miss)
        return
    if by_para:
        _lost(i, OCCLUDED_BY_PARABOLOID, 3, status, segment, p1, p2, v, landing, path, miss)
        return
    status[i] = OK
    segment[i] = 0
    landing[i, 0], landing[i, 1], landing[i, 2] = q2x + t3 * wx, q2y + t3 * wy, q2z + t3 * wz
    path[i] = t1 + t2 + t3
    cx = q2y * wz - q2z * wy
    cy = q2z * wx - q2x * wz
    cz = q2x * wy - q2y * wx
    miss[i] = math.sqrt(cx * cx + cy * cy + cz * cz)


@nb.njit(**_INLINE)
def _blank(i, status, segment, p1, p2, v, landing, path, miss):
    for a in (p1, p2, v, landing):
        a[i, 0] = np.nan
        a[i, 1] = np.nan
        a[i, 2] = np.nan
    path[i] = np.nan
    miss[i] = np.nan
    status[i] = OK
    segment[i] = 0


@nb.njit(**_INLINE)
def _mirror_leg(ox, oy, oz, dx, dy, dz, f, zv, rim, para_occ, shadowed):
    """Segment 1 in the paraboloid's frame: (t, part) with part 0 the mirror, 1 its mount, -1 none.
    ``shadowed`` (analytic._mount_shadowed): the mount lies in the convex solid under the mirror
    (r <= rim, z <= the surface), which a ray enters once; a ray that enters it through the mirror
    (going down through the surface) meets the mirror before any of the mount."""
    tm = _paraboloid(ox, oy, oz, dx, dy, dz, f, zv, rim, np.inf)
    if shadowed and math.isfinite(tm) and ((ox + tm * dx) * dx + (oy + tm * dy) * dy) / (2.0 * f) + dz < 0.0:
        return tm, 0
    to = _occluders(para_occ, ox, oy, oz, dx, dy, dz, tm)  # only a mount nearer than the mirror counts
    if to < tm:
        return to, 1
    if math.isfinite(tm):
        return tm, 0
    return np.inf, -1


@nb.njit(**_INLINE)
def _lost(i, code, seg, status, segment, p1, p2, v, landing, path, miss):
    """Row i lost on segment ``seg``: its status, NaN where the path did not reach."""
    status[i] = code
    segment[i] = seg
    if seg <= 1:
        p1[i, 0] = p1[i, 1] = p1[i, 2] = np.nan
    if seg <= 2:
        p2[i, 0] = p2[i, 1] = p2[i, 2] = np.nan
        v[i, 0] = v[i, 1] = v[i, 2] = np.nan
    landing[i, 0] = landing[i, 1] = landing[i, 2] = np.nan
    path[i] = np.nan
    miss[i] = np.nan


@nb.njit(**_INLINE)
def _y_meets(rho_lo, rho_hi, sphi, beam_y):
    """Can a point at radius rho_lo..rho_hi of azimuth sine ``sphi`` have y in beam_y[0]..beam_y[1]?
    (An unbounded radius range: always.)"""
    if not math.isfinite(rho_hi):
        return True
    a, b = rho_lo * sphi, rho_hi * sphi
    if a > b:
        a, b = b, a
    return b >= beam_y[0] and a <= beam_y[1]


@nb.njit(**_INLINE)
def _cubic(tab, c, k, t):
    """Function ``k`` of table cell ``c`` at local coordinate t in [0, 1] (a cubic, highest power first)."""
    return ((tab[c, k, 0] * t + tab[c, k, 1]) * t + tab[c, k, 2]) * t + tab[c, k, 3]


#: Columns of the aligned kernel's table (analytic.PINHOLE_COLUMNS names them).
T_S, T_Z1, T_T1, T_R2, T_Z2, T_T2, T_WR, T_WZ, T_MISS = range(9)


@nb.njit(**_JIT)
def pinhole_aligned(cop_z, dirs, f, zv, rim, para_occ, beam_occ, mount_shadowed, x0, x_inv_h, table, flags, beam_rho,
                    beam_y, status, segment, p1, p2, v, landing, path, miss, handled):
    """Aligned rig, every ray from the COP (0, 0, cop_z). The rig is a surface of revolution, so a
    ray's path lies in its meridional plane and, but for the occluders, depends on one number: the
    sine x of its angle from the axis. ``table`` (cells, 9, 4) holds that path's meridional values
    (analytic.PINHOLE_COLUMNS: paraboloid radius s and height, t1, dome hit r2, z2, t2, the return
    direction (wr, wz) and the signed miss) as cubics on uniform cells of x from ``x0``
    (``x_inv_h`` cells per unit x), fitted to the exact trace (Newton on the dome spline) and
    measured against it when the tracer is built; the kernel turns them to the ray's azimuth.
    The beam and the mount break the symmetry: they are tested per ray, in 3D, only where the
    table cell's ``flags[cell]`` (analytic._cell_flags) say a leg can reach them: bit 0 (bit 2),
    the leg to the dome (the return leg) may cross the beam's heights at radii
    ``beam_rho[cell]`` and is tested only if radius x sin(azimuth) can fall in the beam's y extent
    ``beam_y``; bit 1, the return leg may pass the paraboloid's body.
    ``mount_shadowed``: the mount lies under the mirror, so a ray from the COP that reaches the
    mirror cannot meet it first. Rays outside the table (``handled`` False) are left for the
    general kernel."""
    n = dirs.shape[0]
    ncells = table.shape[0]
    for i in range(n):
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        rho2 = dx * dx + dy * dy
        if not (dz < 0.0 and rho2 > 0.0):
            handled[i] = False
            continue
        rho = math.sqrt(rho2)
        w = (rho / math.sqrt(rho2 + dz * dz) - x0) * x_inv_h
        if not (0.0 <= w <= ncells):
            handled[i] = False
            continue
        handled[i] = True
        c = min(int(w), ncells - 1)
        t = w - c
        s = _cubic(table, c, T_S, t)
        z1 = _cubic(table, c, T_Z1, t)
        t1 = _cubic(table, c, T_T1, t)
        inv = 1.0 / rho
        cphi, sphi = dx * inv, dy * inv
        ax, ay = s * cphi, s * sphi
        if not mount_shadowed:
            nd = 1.0 / math.sqrt(rho2 + dz * dz)
            if _occluders(para_occ, 0.0, 0.0, cop_z, dx * nd, dy * nd, dz * nd, t1) < t1:
                _lost(i, OCCLUDED_BY_MOUNT, 1, status, segment, p1, p2, v, landing, path, miss)
                continue
        p1[i, 0], p1[i, 1], p1[i, 2] = ax, ay, z1
        r2 = _cubic(table, c, T_R2, t)
        z2 = _cubic(table, c, T_Z2, t)
        t2 = _cubic(table, c, T_T2, t)
        fl = flags[c]
        if fl & 1 and _y_meets(beam_rho[c, 0], beam_rho[c, 1], sphi, beam_y):
            ur, uz = (r2 - s) / t2, (z2 - z1) / t2
            if _occluders(beam_occ, ax, ay, z1, ur * cphi, ur * sphi, uz, t2) < t2:
                _lost(i, OCCLUDED_BY_BEAM, 2, status, segment, p1, p2, v, landing, path, miss)
                continue
        q2x, q2y = r2 * cphi, r2 * sphi
        p2[i, 0], p2[i, 1], p2[i, 2] = q2x, q2y, z2
        wr = _cubic(table, c, T_WR, t)
        wz = _cubic(table, c, T_WZ, t)
        wx, wy = wr * cphi, wr * sphi
        v[i, 0], v[i, 1], v[i, 2] = wx, wy, wz
        if not wz < 0.0:
            _lost(i, ESCAPED_AFTER_DOME, 3, status, segment, p1, p2, v, landing, path, miss)
            continue
        t3 = -z2 / wz
        if fl & 2:
            hp = _paraboloid_bounded(q2x, q2y, z2, wx, wy, wz, f, zv, rim, t3)
            ho = _occluders(para_occ, q2x, q2y, z2, wx, wy, wz, t3)
            hp = min(hp, ho)
        else:
            hp = np.inf
        hb = np.inf
        if fl & 4 and _y_meets(beam_rho[c, 2], beam_rho[c, 3], sphi, beam_y):
            hb = _occluders(beam_occ, q2x, q2y, z2, wx, wy, wz, t3)
        if math.isfinite(hb) and not hp < hb:
            _lost(i, OCCLUDED_BY_BEAM, 3, status, segment, p1, p2, v, landing, path, miss)
            continue
        if math.isfinite(hp):
            _lost(i, OCCLUDED_BY_PARABOLOID, 3, status, segment, p1, p2, v, landing, path, miss)
            continue
        status[i] = OK
        segment[i] = 0
        lr = r2 + t3 * wr
        landing[i, 0], landing[i, 1], landing[i, 2] = lr * cphi, lr * sphi, z2 + t3 * wz
        path[i] = t1 + t2 + t3
        miss[i] = abs(_cubic(table, c, T_MISS, t))


@nb.njit(**_INLINE)
def _interp(x, xs, ys):
    """np.interp(x, xs, ys) for increasing xs (ends clamped), by binary search."""
    n = xs.shape[0]
    if x <= xs[0]:
        return ys[0]
    if x >= xs[n - 1]:
        return ys[n - 1]
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    w = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] * (1.0 - w) + ys[hi] * w


@nb.njit(**_INLINE)
def _bracketed(ox, oy, oz, dx, dy, dz, tab_u, tab_r, tab_z, r_max, brk, cr, cz, u_lo, u_hi, newton_steps,
               piece_of, piece_scale):
    """The general dome hit (rays.ExactDome._bracketed, per ray): bracket the crossing on the
    tabulated meridian between the ray's start and where it leaves the cylinder r_max + 1 mm or
    the mirror's heights (bisection, 30 steps), then Newton on the spline. (t, u); t inf for none."""
    dxy2 = dx * dx + dy * dy
    oxy_d = ox * dx + oy * dy
    oxy2 = ox * ox + oy * oy
    big = (r_max + 1.0) * (r_max + 1.0)
    z_lo, z_hi = tab_z[0], tab_z[tab_z.shape[0] - 1]
    t_cyl = (-oxy_d + math.sqrt(max(oxy_d * oxy_d - dxy2 * (oxy2 - big), 0.0))) / dxy2
    t_top = (z_hi - oz) / dz if dz > 0.0 else np.inf
    t_bot = (z_lo - oz) / dz if dz < 0.0 else np.inf
    t_end = min(t_cyl, t_top, t_bot) if not math.isnan(t_cyl) else min(t_top, t_bot)
    if not math.isfinite(t_end):
        return np.inf, 0.0
    h0 = math.sqrt(oxy2) - _interp(oz, tab_z, tab_r)
    he = math.sqrt(max(oxy2 + 2 * t_end * oxy_d + t_end * t_end * dxy2, 0.0)) - _interp(oz + t_end * dz, tab_z, tab_r)
    if not (h0 < 0.0 and he >= 0.0):
        return np.inf, 0.0
    lo, hi = 0.0, t_end
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        h = math.sqrt(max(oxy2 + 2 * mid * oxy_d + mid * mid * dxy2, 0.0)) - _interp(oz + mid * dz, tab_z, tab_r)
        if h >= 0.0:
            hi = mid
        else:
            lo = mid
    t = 0.5 * (lo + hi)
    u = _interp(oz + t * dz, tab_z, tab_u)
    piece = piece_of[min(int((u - u_lo) * piece_scale), piece_of.shape[0] - 1)]
    for _ in range(newton_steps):
        dt, du, piece = _newton_step(brk, cr, cz, ox, oy, oz, dx, dy, dz, t, u, piece)
        t = t - dt
        u = min(max(u - du, u_lo), u_hi)
    return t, u


@nb.njit(**_INLINE)
def _newton_step(brk, cr, cz, ox, oy, oz, dx, dy, dz, t, u, piece):
    """One Newton step on (t, u) for the ray o + t d meeting the revolved meridian (r(u), z(u)):
    residuals rho(t) - r(u), z(t) - z(u); returns (dt, du, piece) to subtract."""
    cr_, cz_, dcr, dcz, piece = _spline(brk, cr, cz, u, piece)
    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
    rho = math.sqrt(px * px + py * py)
    f1 = rho - cr_
    f2 = pz - cz_
    a11 = (px * dx + py * dy) / rho
    inv = 1.0 / (a11 * (-dcz) + dcr * dz)
    return ((-dcz) * f1 + dcr * f2) * inv, (-dz * f1 + a11 * f2) * inv, piece


@nb.njit(**_JIT)
def general(idx, origins, dirs, R1, T1, id1, R2, T2, id2, f, zv, rim, para_occ, mount_shadowed, body_sphere, beam_occ,
            brk, cr, cz, u_lo, u_hi, piece_of, piece_scale, tab_u, tab_r, tab_z, r_max, newton_steps, residual_tol,
            step_tol, status, segment, p1, p2, v, landing, path, miss):
    """Any rig, any rays (rows ``idx``): the paraboloid in its frame (closed form), the dome hit by
    Newton on (t, u) against the meridian spline, started at the design's correspondence (u = -s
    of the paraboloid radius s the ray reflects at); a ray whose Newton does not land on the mirror
    (residual >= residual_tol mm, or u at an end) takes :func:`_bracketed`. ``piece_of``: the spline
    piece at each of its uniform cells of u (``piece_scale`` cells per unit u), the first guess of
    the piece search. Returns the number of rays that took the bracketing path."""
    fallbacks = 0
    npo = piece_of.shape[0]
    for k in range(idx.shape[0]):
        i = idx[k]
        _blank(i, status, segment, p1, p2, v, landing, path, miss)
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        norm = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
        dx, dy, dz = dx * norm, dy * norm, dz * norm
        lx, ly, lz = _to_local(R1, T1, id1, origins[i, 0], origins[i, 1], origins[i, 2])
        ldx, ldy, ldz = _dir_to_local(R1, id1, dx, dy, dz)
        t1, part = _mirror_leg(lx, ly, lz, ldx, ldy, ldz, f, zv, rim, para_occ, mount_shadowed)
        if part != 0:
            _lost(i, MISSED_PARABOLOID if part < 0 else OCCLUDED_BY_MOUNT, 1, status, segment, p1, p2, v, landing,
                  path, miss)
            continue
        ax, ay, az = lx + t1 * ldx, ly + t1 * ldy, lz + t1 * ldz
        s = math.sqrt(ax * ax + ay * ay)
        nx, ny = ax / (2.0 * f), ay / (2.0 * f)
        nn = 1.0 / math.sqrt(nx * nx + ny * ny + 1.0)
        nx, ny, nz = _dir_to_global(R1, id1, nx * nn, ny * nn, nn)
        gx, gy, gz = _to_global(R1, T1, id1, ax, ay, az)
        p1[i, 0], p1[i, 1], p1[i, 2] = gx, gy, gz
        ux, uy, uz = _reflect(dx, dy, dz, nx, ny, nz)
        # dome frame; Newton from the correspondence u = -s
        ox, oy, oz = _to_local(R2, T2, id2, gx, gy, gz)
        ex, ey, ez = _dir_to_local(R2, id2, ux, uy, uz)
        u = min(max(-s, u_lo), u_hi)
        piece = piece_of[min(int((u - u_lo) * piece_scale), npo - 1)]
        r0, z0, _, _, piece = _spline(brk, cr, cz, u, piece)
        if abs(ez) > 1e-3:
            t = (z0 - oz) / ez
        else:
            t = (r0 - math.sqrt(ox * ox + oy * oy)) / max(math.sqrt(ex * ex + ey * ey), 1e-12)
        if not (math.isfinite(t) and t > 0.0):
            t = 1.0
        for _ in range(newton_steps):
            dt, du, piece = _newton_step(brk, cr, cz, ox, oy, oz, ex, ey, ez, t, u, piece)
            t = t - dt
            u = min(max(u - du, u_lo), u_hi)
            if abs(dt) < step_tol and abs(du) < step_tol:
                break
        cr_, cz_, dcr, dcz, piece = _spline(brk, cr, cz, u, piece)
        px, py, pz = ox + t * ex, oy + t * ey, oz + t * ez
        res = math.hypot(math.sqrt(px * px + py * py) - cr_, pz - cz_)
        if not (res < residual_tol and math.isfinite(t) and t > 0.0 and u_lo < u < u_hi):
            fallbacks += 1
            t, u = _bracketed(ox, oy, oz, ex, ey, ez, tab_u, tab_r, tab_z, r_max, brk, cr, cz, u_lo, u_hi,
                              newton_steps, piece_of, piece_scale)
            if not (math.isfinite(t) and t > 0.0):
                t = np.inf
            else:
                _, _, dcr, dcz, piece = _spline(brk, cr, cz, u, piece)
        # segment 2: the beam between the mirrors (it moves with the dome)
        tb = _occluders(beam_occ, ox, oy, oz, ex, ey, ez, t)
        if tb < t:
            _lost(i, OCCLUDED_BY_BEAM, 2, status, segment, p1, p2, v, landing, path, miss)
            continue
        if not math.isfinite(t):
            _lost(i, ESCAPED_TOP if uz > 0.0 else MISSED_DOME, 2, status, segment, p1, p2, v, landing, path, miss)
            continue
        px, py, pz = ox + t * ex, oy + t * ey, oz + t * ez
        m = 1.0 / math.sqrt(dcr * dcr + dcz * dcz)
        nr, nzz = -dcz * m, dcr * m  # the left normal of the rising meridian: towards the axis
        rho = math.sqrt(px * px + py * py)
        cphi, sphi = (px / rho, py / rho) if rho > 0.0 else (1.0, 0.0)
        nx, ny, nz = _dir_to_global(R2, id2, nr * cphi, nr * sphi, nzz)
        q2x, q2y, q2z = _to_global(R2, T2, id2, px, py, pz)
        p2[i, 0], p2[i, 1], p2[i, 2] = q2x, q2y, q2z
        wx, wy, wz = _reflect(ux, uy, uz, nx, ny, nz)
        _return_leg(i, q2x, q2y, q2z, wx, wy, wz, t1, t, R1, T1, id1, R2, T2, id2, f, zv, rim, para_occ, body_sphere,
                    beam_occ, status, segment, p1, p2, v, landing, path, miss)
    return fallbacks


@nb.njit(**_JIT)
def refine_mesh_hits(geom, prim, origins, dirs, tri, offsets, has_normals, vertex_model, tmax, t_out, part_out,
                     normal_out):
    """Embree's hits (geometry ``geom``, triangle ``prim``; -1 none) re-intersected in float64
    (Moller-Trumbore on that triangle, rays.EmbreeMesh) with their normals: the facet's, or the
    vertex normals interpolated with the barycentric weights (``vertex_model``, meshes that have
    them). ``tri[offsets[g] + prim]``: v0, e1 = v1 - v0, e2 = v2 - v0, the unit facet normal and
    the three vertex normals (21 values, then 3 of padding: EmbreeMesh._packed). Hits beyond
    ``tmax`` (if its length is the rays') are dropped."""
    n = geom.shape[0]
    ng = offsets.shape[0] - 1
    limited = tmax.shape[0] == n
    for i in range(n):
        g = geom[i]
        p = prim[i]
        if p < 0 or g < 0 or g >= ng:
            t_out[i] = np.inf
            part_out[i] = -1
            normal_out[i, 0] = np.nan
            normal_out[i, 1] = np.nan
            normal_out[i, 2] = np.nan
            continue
        r = offsets[g] + p
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        e1x, e1y, e1z = tri[r, 3], tri[r, 4], tri[r, 5]
        e2x, e2y, e2z = tri[r, 6], tri[r, 7], tri[r, 8]
        px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
        inv = 1.0 / (e1x * px + e1y * py + e1z * pz)
        sx, sy, sz = origins[i, 0] - tri[r, 0], origins[i, 1] - tri[r, 1], origins[i, 2] - tri[r, 2]
        b1 = (sx * px + sy * py + sz * pz) * inv
        qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
        b2 = (dx * qx + dy * qy + dz * qz) * inv
        t = (e2x * qx + e2y * qy + e2z * qz) * inv
        if limited and t > tmax[i]:
            t_out[i] = np.inf
            part_out[i] = -1
            normal_out[i, 0] = np.nan
            normal_out[i, 1] = np.nan
            normal_out[i, 2] = np.nan
            continue
        t_out[i] = t
        part_out[i] = g
        if vertex_model and has_normals[g]:
            w0 = 1.0 - b1 - b2
            nx = w0 * tri[r, 12] + b1 * tri[r, 15] + b2 * tri[r, 18]
            ny = w0 * tri[r, 13] + b1 * tri[r, 16] + b2 * tri[r, 19]
            nz = w0 * tri[r, 14] + b1 * tri[r, 17] + b2 * tri[r, 20]
            m = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
            normal_out[i, 0], normal_out[i, 1], normal_out[i, 2] = nx * m, ny * m, nz * m
        else:
            normal_out[i, 0], normal_out[i, 1], normal_out[i, 2] = tri[r, 9], tri[r, 10], tri[r, 11]
