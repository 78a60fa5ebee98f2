"""The analytic tracer at speed: the exact surfaces (closed-form paraboloid, the dome's meridian
spline) traced by compiled kernels (rigcad/check/_kernels.py), float64 throughout.

Two kernels, and the one that ran is recorded per trace (``Trace3D.kernels``):

* ``pinhole_aligned`` - an aligned rig (identity poses) and rays from the COP. The rig is a surface
  of revolution, so a ray's path lies in its meridional plane and, but for the occluders, depends
  on one number: the sine x of the ray's angle from the axis. When the tracer is built, the exact
  path (``general_newton`` below: the paraboloid's quadratic, Newton on the dome's meridian
  spline) is traced at the nodes of PINHOLE_CELLS uniform cells of x, and its meridional values
  (PINHOLE_COLUMNS) are fitted by a cubic spline; a ray then costs a cell lookup, nine cubics and
  its turn to its azimuth. The table is measured against the exact path at every cell's midpoint
  (``table_error``; past PINHOLE_POINT_TOL / PINHOLE_DIRECTION_TOL the kernel is not used). The
  beam and the mount are tested per ray (they break the symmetry), only where per-cell flags of
  the paraboloid radius say a leg can reach them.
* ``general_newton`` - any rig and any rays (misaligned components, thin-lens rays): Newton on
  (t, u) against the spline, started at the correspondence; a ray whose Newton does not land on
  the mirror (a miss past its ends, a stray ray) takes the bracketing path of
  :class:`rigcad.check.rays.ExactDome`, compiled (``bracketed_fallback``).

Accuracy (tests/check/test_analytic.py, against the vectorised reference that brackets every ray
and polishes by Newton): aligned within 1e-9 mm and 1e-12 rad ray for ray, misaligned within 1e-7
mm.
Frame: mm, O at the origin, +z up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PPoly

from rigcad.check import rays as R
from rigcad.check.result import Trace3D
from rigcad.optics.vec import pose_arrays

#: Uniform cells of x (the sine of a COP ray's angle from the axis) of the aligned kernel's table.
#: The cubic spline's error falls as h^4 (bench/raycheck.py's table sweep on Table 3.1:
#: 4096 cells 2e-12 mm, 8192 cells ~1e-13 mm, then float64 round-off); 8192 cells x 9 cubics are
#: 2.4 MB.
PINHOLE_CELLS = 8192
#: What the table holds per x: the paraboloid hit (radius s, height z1) and the distance t1 to it
#: from the COP, the dome hit (r2, z2) and the distance t2 to it, the return direction (wr, wz)
#: and the signed miss r2 wz - z2 wr (mm; its absolute value is the distance from O to the return
#: ray's line, which lies in the meridional plane through O). Kept in step with _kernels.T_*.
PINHOLE_COLUMNS = ("s_mm", "z1_mm", "t1_mm", "r2_mm", "z2_mm", "t2_mm", "wr", "wz", "miss_signed_mm")
#: The aligned kernel runs only if the table lands within this of the exact path at every cell's
#: midpoint (mm: points and distances; rad: the return direction). Measured on Table 3.1: ~3e-13
#: mm, ~3e-15 rad (the required agreement of the compiled kernels with the exact path: 1e-9 mm,
#: 1e-12 rad).
PINHOLE_POINT_TOL = 1e-11
PINHOLE_DIRECTION_TOL = 1e-13
#: Uniform cells of the dome parameter that seed the spline-piece search (~4 per piece).
PIECE_CELLS = 8192
#: Newton steps of the general kernel: from the correspondence (within ~1 mm for a mm-scale
#: misalignment) quadratic convergence reaches rounding in ~5; 12 leaves margin, the loop stops
#: when a step is under NEWTON_STEP_TOL.
NEWTON_STEPS = 12
#: A Newton step (mm of t, units of u: mm of paraboloid radius) below this ends the iteration:
#: convergence is quadratic with a constant of about the dome's curvature (< 0.02 / mm), so the
#: iterate after a 1e-6 mm step is within ~1e-14 mm; the residual check (RESIDUAL_TOL) still
#: sends any ray that did not land to the bracketing path.
NEWTON_STEP_TOL = 1e-6
#: The general kernel's hit counts as on the dome within this residual (mm), as rays.FAST_PATH_RESIDUAL.
RESIDUAL_TOL = R.FAST_PATH_RESIDUAL
#: Margin (mm of paraboloid radius) kept inside the dome's ends by the aligned kernel: rays within it of an
#: end (where the hit may fall off the mirror) take the general kernel.
TABLE_MARGIN = 1e-6


def _occluder_rows(members) -> np.ndarray:
    """Box / ZCylinder intersectors as the kernels' (k, 11) rows: the solid, then a bounding sphere
    (centre, radius; 1e-6 relative margin so rounding never rejects a ray that grazes the solid)."""
    rows = []
    for m in members:
        if isinstance(m, R.Box):
            c, r = 0.5 * (m.lo + m.hi), 0.5 * float(np.linalg.norm(m.hi - m.lo))
            rows.append([0.0, *m.lo, *m.hi, *c, r * (1 + 1e-6) + 1e-9])
        elif isinstance(m, R.ZCylinder):
            r = float(np.hypot(m.r, 0.5 * (m.z1 - m.z0)))
            rows.append([1.0, m.r, m.z0, m.z1, m.c[0], m.c[1], 0.0, m.c[0], m.c[1], 0.5 * (m.z0 + m.z1),
                         r * (1 + 1e-6) + 1e-9])
        elif isinstance(m, R.Group):
            rows.extend(_occluder_rows(m.members).tolist())
        else:  # pragma: no cover - analytic_optics builds only these
            raise TypeError(f"not an occluder: {m!r}")
    return np.array(rows, float).reshape(-1, 11)


@dataclass
class AnalyticTracer:
    """Arrays the kernels read (pickles as plain arrays; built once per rig)."""

    focal_length: float
    vertex_z: float
    rim_radius: float
    cop_z: float
    para_occ: np.ndarray
    beam_occ: np.ndarray
    breaks: np.ndarray
    coef_r: np.ndarray
    coef_z: np.ndarray
    u_lo: float
    u_hi: float
    s0: float
    s1: float
    beam_y: np.ndarray
    mount_shadowed: bool
    body_sphere: np.ndarray
    piece_of: np.ndarray
    piece_scale: float
    dome: R.ExactDome
    #: the aligned kernel's table (PINHOLE_CELLS, 9, 4), its cells' occlusion flags and beam radii
    #: (_cell_flags), x0, cells per unit x, and the table's measured error
    table: np.ndarray | None = None
    flags: np.ndarray | None = None
    beam_rho: np.ndarray | None = None
    x0: float = 0.0
    x_inv_h: float = 0.0
    table_error: dict | None = None
    pinhole: bool = False

    backend = "analytic float64, numba kernels (pinhole_aligned: table of the exact meridional trace; general_newton)"

    @classmethod
    def build(cls, rig, paraboloid, dome_group, beam) -> "AnalyticTracer":
        """From the rig's geometry and the intersectors of :func:`rigcad.check.scene.analytic_optics`."""
        geo = rig.geometry
        exact_dome = dome_group.members[0]
        para_occ = _occluder_rows(paraboloid.members[1:])
        beam_occ = _occluder_rows([beam])
        spl = exact_dome.m._spline
        u_lo, u_hi = exact_dome.m.u_range
        pr = PPoly.from_spline((spl.t, spl.c[:, 0], spl.k))
        pz = PPoly.from_spline((spl.t, spl.c[:, 1], spl.k))
        keep = np.nonzero(np.diff(pr.x) > 0)[0]  # drop the zero-length pieces at the repeated end knots
        breaks = np.concatenate([pr.x[keep], [pr.x[keep[-1] + 1]]])
        coef_r = np.ascontiguousarray(pr.c[:, keep].T)
        coef_z = np.ascontiguousarray(pz.c[:, keep].T)
        # Newton's first guess of the spline piece: the piece at each of PIECE_CELLS uniform cells of u
        piece_scale = PIECE_CELLS / (u_hi - u_lo)
        cell_u = u_lo + (np.arange(PIECE_CELLS) + 0.5) / piece_scale
        piece_of = np.clip(np.searchsorted(breaks, cell_u, side="right") - 1, 0, len(breaks) - 2).astype(np.int64)
        s0 = -u_hi + TABLE_MARGIN
        s1 = min(-u_lo, geo.rim_radius) - TABLE_MARGIN
        beam_y = np.array([beam_occ[:, 2].min() - FLAG_MARGIN_MM, beam_occ[:, 5].max() + FLAG_MARGIN_MM])
        shadowed = _mount_shadowed(geo, para_occ)
        out = cls(geo.focal_length, geo.vertex_z, geo.rim_radius, geo.cop_z, para_occ, beam_occ, breaks, coef_r,
                  coef_z, float(u_lo), float(u_hi), float(s0), float(s1), beam_y, shadowed,
                  _body_sphere(geo, para_occ), piece_of,
                  float(piece_scale), exact_dome)
        out._build_table(geo)
        return out

    def _build_table(self, geo, cells: int = PINHOLE_CELLS) -> None:
        """The aligned kernel's table: the exact trace (:func:`_kernels.general`, no occluders) of
        COP rays at the nodes of ``cells`` uniform cells of x = sin(angle from the axis) over
        the paraboloid radii [s0, s1], fitted by a cubic spline per PINHOLE_COLUMNS, then measured
        against the exact trace at every cell's midpoint; and each cell's occlusion flags."""
        from scipy.interpolate import CubicSpline

        f, zv, cz = self.focal_length, self.vertex_z, self.cop_z
        x0, x1 = (s / np.hypot(s, cz - (zv - s * s / (4 * f))) for s in (self.s0, self.s1))
        nodes = np.linspace(x0, x1, cells + 1)
        vals, lost = self._meridional(nodes)
        mids = 0.5 * (nodes[1:] + nodes[:-1])
        exact, lost_mid = self._meridional(mids)
        self.x0, self.x_inv_h = float(x0), float(cells / (x1 - x0))
        self.table, self.pinhole = None, False
        if lost or lost_mid:  # pragma: no cover - the radii are the dome's own
            self.table_error = {"cells": cells, "unusable": f"{lost + lost_mid} table rays miss the dome"}
            return
        self.flags, self.beam_rho = _cell_flags(geo, vals[:, 0], _correspondence(self.dome, vals[:, 0]),
                                                self.para_occ, self.beam_occ)
        cs = CubicSpline(nodes, vals, axis=0)
        h = (x1 - x0) / cells
        # local coordinate t = (x - node) / h in [0, 1]: coefficient of t^p is c_p h^p
        self.table = np.ascontiguousarray(np.transpose(cs.c, (1, 2, 0)) * (h ** np.arange(3, -1, -1)))
        got = _eval_table(self.table, np.full(cells, 0.5))
        point = [k for k, name in enumerate(PINHOLE_COLUMNS) if name.endswith("_mm")]
        wr, wz = got[:, 6], got[:, 7]
        dir_err = np.abs(np.arctan2(wr * exact[:, 7] - wz * exact[:, 6], wr * exact[:, 6] + wz * exact[:, 7]))
        self.table_error = {"cells": cells, "checked": "every cell's midpoint, against the exact trace",
                            "max_point_error_mm": float(np.max(np.abs(got[:, point] - exact[:, point]))),
                            "max_direction_error_rad": float(np.max(dir_err)),
                            "max_direction_norm_error": float(np.max(np.abs(np.hypot(wr, wz) - 1.0)))}
        self.pinhole = (self.table_error["max_point_error_mm"] < PINHOLE_POINT_TOL
                        and self.table_error["max_direction_error_rad"] < PINHOLE_DIRECTION_TOL
                        and self.table_error["max_direction_norm_error"] < PINHOLE_DIRECTION_TOL)

    def _meridional(self, x: np.ndarray) -> tuple[np.ndarray, int]:
        """PINHOLE_COLUMNS of the exact trace of the COP rays at sines ``x`` (m,) in the x-z plane
        (no occluders), and how many of them do not reach the dome."""
        from rigcad.check import _kernels as K

        m = len(x)
        origins = np.tile([0.0, 0.0, self.cop_z], (m, 1))
        dirs = np.column_stack([x, np.zeros(m), -np.sqrt(1.0 - x * x)])
        tr = Trace3D.allocate(m)
        status, segment, p1, p2, v = tr.status, tr.segment, tr.p1, tr.p2, tr.v
        none = np.zeros((0, 11))
        ident, zero = np.eye(3), np.zeros(3)
        K.general(np.arange(m), origins, dirs, ident, zero, True, ident, zero, True, self.focal_length,
                  self.vertex_z, self.rim_radius, none, True, np.zeros(4), none, self.breaks, self.coef_r,
                  self.coef_z, self.u_lo, self.u_hi, self.piece_of, self.piece_scale, self.dome.u_tab,
                  self.dome.r_tab, self.dome.z_tab, self.dome.r_max, NEWTON_STEPS, RESIDUAL_TOL, NEWTON_STEP_TOL,
                  *tr.arrays)
        reached = (status == K.OK) | ((status == K.ESCAPED_AFTER_DOME) & (segment == 3))
        t1 = np.hypot(p1[:, 0], p1[:, 2] - self.cop_z)
        t2 = np.hypot(p2[:, 0] - p1[:, 0], p2[:, 2] - p1[:, 2])
        signed = p2[:, 0] * v[:, 2] - p2[:, 2] * v[:, 0]
        cols = np.column_stack([p1[:, 0], p1[:, 2], t1, p2[:, 0], p2[:, 2], t2, v[:, 0], v[:, 2], signed])
        return cols, int(np.count_nonzero(~reached))

    def trace(self, optics, origins: np.ndarray, dirs: np.ndarray):
        """Trace rays (n, 3) through ``optics`` (its poses) with the kernels: a Trace3D with
        ``kernels`` = rays per kernel."""
        from rigcad.check import _kernels as K

        origins = np.ascontiguousarray(origins, float)
        dirs = np.ascontiguousarray(dirs, float)
        n = len(origins)
        result = Trace3D.allocate(n)
        out = result.arrays
        pp, dp = optics.paraboloid_pose, optics.dome_pose
        aligned = pp.is_identity and dp.is_identity
        kernels = {"pinhole_aligned": 0, "general_newton": 0, "bracketed_fallback": 0}
        rest = None
        if n and aligned and self.pinhole and np.all(origins[:, 0] == 0.0) and np.all(origins[:, 1] == 0.0) \
                and np.all(origins[:, 2] == self.cop_z):
            handled = np.empty(n, np.bool_)
            K.pinhole_aligned(self.cop_z, dirs, self.focal_length, self.vertex_z, self.rim_radius, self.para_occ,
                              self.beam_occ, self.mount_shadowed, self.x0, self.x_inv_h, self.table, self.flags,
                              self.beam_rho, self.beam_y, *out, handled)
            rest = np.nonzero(~handled)[0]
            kernels["pinhole_aligned"] = n - len(rest)
        elif n:
            rest = np.arange(n)
        if rest is not None and len(rest):
            kernels["general_newton"] = len(rest)
            kernels["bracketed_fallback"] = self._general(K, rest, origins, dirs, pp, dp, out)
        result.kernels = kernels
        return result

    def _general(self, K, idx, origins, dirs, pp, dp, out) -> int:
        R1, T1, id1 = pose_arrays(pp)
        R2, T2, id2 = pose_arrays(dp)
        return int(K.general(idx, origins, dirs, R1, T1, id1, R2, T2, id2, self.focal_length, self.vertex_z,
                             self.rim_radius, self.para_occ, self.mount_shadowed, self.body_sphere, self.beam_occ,
                             self.breaks, self.coef_r, self.coef_z, self.u_lo, self.u_hi, self.piece_of,
                             self.piece_scale, self.dome.u_tab, self.dome.r_tab, self.dome.z_tab, self.dome.r_max,
                             NEWTON_STEPS, RESIDUAL_TOL, NEWTON_STEP_TOL, *out))


#: Margin (mm) of the per-cell flags: a leg counts as clear of a solid's bounding shape only by at
#: least this much; a table cell spans ~2 um of paraboloid radius on Table 3.1, over which a leg
#: moves < 0.05 mm.
FLAG_MARGIN_MM = 0.5


def _cell_flags(geo, s: np.ndarray, values: np.ndarray, para_occ: np.ndarray, beam_occ: np.ndarray):
    """Per cell of s: ``flags`` (int8) and ``beam_rho`` ((cells, 4) mm). Bit 0: the aligned leg
    paraboloid -> dome may cross the beam's heights, at radii beam_rho[:, 0..1]; bit 2: the return
    leg dome -> O may, at radii beam_rho[:, 2..3]; bit 1: the return leg may pass within
    FLAG_MARGIN_MM of the cylinder that bounds the paraboloid and its mount. Both legs lie in the
    ray's meridional plane (an aligned rig, rays from the axis), so a leg meets the beam only where
    radius x sin(azimuth) falls in the beam's y extent: the kernel tests that before the box. From
    the exact node values (s (m+1,), values (m+1, 4)) at both ends of each cell, with the margin."""
    f, zv = geo.focal_length, geo.vertex_z
    m = FLAG_MARGIN_MM
    zp = zv - s * s / (4 * f)
    r2, z2, nr, nz = values.T
    bz0, bz1 = beam_occ[:, 3].min() - m, beam_occ[:, 6].max() + m
    # the leg to the dome: a straight segment (s, zp) -> (r2, z2) in the meridional plane
    lo_z, hi_z = np.minimum(zp, z2), np.maximum(zp, z2)
    beam = (hi_z >= bz0) & (lo_z <= bz1)
    with np.errstate(divide="ignore", invalid="ignore"):
        za, zb = np.maximum(lo_z, bz0), np.minimum(hi_z, bz1)
        slope = (r2 - s) / (z2 - zp)
        leg = np.stack([s + (za - zp) * slope, s + (zb - zp) * slope], axis=-1)
    # the return leg: the incoming direction u reflected about the dome normal (exact per node)
    n1 = np.stack([s / (2 * f), np.ones_like(s)], axis=-1)
    n1 /= np.linalg.norm(n1, axis=1)[:, None]
    d = np.stack([s, zp - geo.cop_z], axis=-1)
    d /= np.linalg.norm(d, axis=1)[:, None]
    u = d - 2 * np.sum(d * n1, axis=1)[:, None] * n1
    n2 = np.stack([nr, nz], axis=-1)
    w = u - 2 * np.sum(u * n2, axis=1)[:, None] * n2
    down = w[:, 1] < 0
    ret_beam = down & (z2 >= bz0)
    with np.errstate(divide="ignore", invalid="ignore"):
        za, zb = np.maximum(0.0, bz0), np.minimum(z2, bz1)
        ret = np.stack([r2 + (za - z2) * w[:, 0] / w[:, 1], r2 + (zb - z2) * w[:, 0] / w[:, 1]], axis=-1)
    radius = [geo.rim_radius]
    zs = [geo.rim_z, geo.vertex_z]
    for row in para_occ:
        if row[0] == 0.0:
            radius.append(float(np.max(np.hypot([row[1], row[4]], [[row[2]], [row[5]]]))))
            zs += [row[3], row[6]]
        else:
            radius.append(float(np.hypot(row[4], row[5]) + row[1]))
            zs += [row[2], row[3]]
    r_body, z_lo, z_hi = max(radius) + m, min(zs) - m, max(zs) + m
    with np.errstate(divide="ignore", invalid="ignore"):
        za, zb = np.full_like(z2, z_lo), np.minimum(z_hi, z2)
        ra = r2 + (za - z2) * w[:, 0] / w[:, 1]
        rb = r2 + (zb - z2) * w[:, 0] / w[:, 1]
    body = ~((z2 < z_lo) | (down & (np.minimum(ra, rb) > r_body)))
    node = beam.astype(np.int8) | (body.astype(np.int8) << 1) | (ret_beam.astype(np.int8) << 2)
    flags = np.ascontiguousarray(node[:-1] | node[1:])
    rho = np.empty((len(flags), 4))
    for k, arr in ((0, leg), (2, ret)):
        both = np.concatenate([arr[:-1], arr[1:]], axis=1)
        rho[:, k] = np.maximum(np.nanmin(np.where(np.isfinite(both), both, np.inf), axis=1) - m, 0.0)
        rho[:, k + 1] = np.nanmax(np.where(np.isfinite(both), both, -np.inf), axis=1) + m
    # a cell whose legs' radii are not finite keeps the exact tests (no radius bound)
    rho[~np.isfinite(rho[:, 0]) | ~np.isfinite(rho[:, 1]), 0:2] = (0.0, np.inf)
    rho[~np.isfinite(rho[:, 2]) | ~np.isfinite(rho[:, 3]), 2:4] = (0.0, np.inf)
    return flags, np.ascontiguousarray(rho)


def _body_sphere(geo, para_occ: np.ndarray) -> np.ndarray:
    """A sphere (centre x, y, z, radius; mm, the paraboloid's frame) around the mirror's bounding
    sphere (the kernels' _paraboloid_bounded) and every mount row's: the box around those spheres,
    circumscribed (with the rows' 1e-6 relative margin)."""
    sag = geo.rim_radius ** 2 / (4 * geo.focal_length)
    spheres = [[0.0, 0.0, geo.vertex_z - 0.5 * sag, np.hypot(geo.rim_radius, 0.5 * sag)]] + para_occ[:, 7:11].tolist()
    sp = np.array(spheres)
    lo, hi = (sp[:, :3] - sp[:, 3:]).min(axis=0), (sp[:, :3] + sp[:, 3:]).max(axis=0)
    return np.array([*(0.5 * (lo + hi)), 0.5 * np.linalg.norm(hi - lo) * (1 + 1e-6) + 1e-9])


def _mount_shadowed(geo, para_occ: np.ndarray) -> bool:
    """Does every mount solid lie under the mirror surface within its rim (in the convex solid
    r <= rim, z <= vertex_z - r^2 / (4 f)), so that a ray from above that hits the mirror cannot
    meet the mount first? Checked at the solids' outermost corners / top rims, with a margin
    (1e-9 of the rig's size) so that a mount touching the mirror takes the exact tests on every CPU."""
    f, zv, rim = geo.focal_length, geo.vertex_z, geo.rim_radius
    for row in para_occ:
        if row[0] == 0.0:
            corners = [(x, y, row[6]) for x in (row[1], row[4]) for y in (row[2], row[5])]
            r = [np.hypot(x, y) for x, y, _ in corners]
            top = row[6]
        else:
            r = [np.hypot(row[4], row[5]) + row[1]]
            top = row[3]
        rmax = max(r)
        tol = 1e-9 * max(rim, abs(zv), 1.0)
        if rmax > rim - tol or top > zv - rmax * rmax / (4 * f) - tol:
            return False
    return True


def _correspondence(dome: R.ExactDome, s: np.ndarray) -> np.ndarray:
    """The meridian's point (r, z) and normal (n_r, n_z) at u = -s (m, 4)."""
    return np.column_stack([dome.m._spline(-s), dome.m.normals(-s)])


def _eval_table(table: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Every column of each cell of ``table`` (cells, k, 4) at its local coordinate t (cells,):
    (cells, k) (the kernel's Horner, vectorised)."""
    t = t[:, None]
    return ((table[:, :, 0] * t + table[:, :, 1]) * t + table[:, :, 2]) * t + table[:, :, 3]
