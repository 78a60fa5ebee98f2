"""The analytic tracer at speed: the exact surfaces (closed-form paraboloid, the dome's meridian
spline) traced by compiled kernels (rigcad/check/_kernels.py), float64 throughout.

Two kernels, and the one that ran is recorded per trace (``Trace3D.kernels``):

* ``pinhole_aligned`` - an aligned rig (identity poses) and rays from the COP. The paraboloid hit
  is the quadratic's root; the rest of the path depends on the paraboloid radius s alone (the rig
  is a surface of revolution), and the design's correspondence gives the dome hit: the ray
  reflected at radius s lands on the dome's meridian at u = -s (the dome was built along those
  rays), so the hit and its normal are the spline's point and derivative there (a lookup of the
  piece and a quintic), turned to the ray's azimuth. The correspondence is measured against
  Newton when the tracer is built (``table_error``; past CORRESPONDENCE_TOL the kernel is not
  used). The beam and the mount are tested per ray (they break the symmetry), only where per-cell
  flags of s say a leg can reach them.
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
from rigcad.optics.frames import Pose

#: Cells of paraboloid radius of the per-cell occlusion flags (16 mm / 2^16 = 0.23 um; 64 KB).
FLAG_CELLS = 1 << 16
#: Radii at which the correspondence is measured against Newton when the tracer is built.
CHECK_RADII = 4097
#: The aligned kernel runs only if the correspondence lands within this of Newton's hit (mm); the
#: Table 3.1 dome's measures ~1e-13 mm (its spline interpolates rows built on the design's rays).
CORRESPONDENCE_TOL = 1e-11
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


def _pose(p: Pose) -> tuple[np.ndarray, np.ndarray, bool]:
    return (np.ascontiguousarray(p.rotation, float), np.ascontiguousarray(p.translation, float),
            bool(p.is_identity))


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
    flag_inv_h: float
    flags: np.ndarray
    beam_rho: np.ndarray
    beam_y: np.ndarray
    mount_shadowed: bool
    piece_of: np.ndarray
    piece_scale: float
    pinhole: bool
    table_error: dict
    dome: R.ExactDome

    backend = "analytic float64, numba kernels (pinhole_aligned: design correspondence; general_newton)"

    @classmethod
    def build(cls, rig, paraboloid, dome_group, beam) -> "AnalyticTracer":
        """From the rig's geometry and the intersectors of :func:`rigcad.check.scene.analytic_optics`."""
        geo = rig.geometry
        exact_para = paraboloid.members[0]
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
        s0, s1 = -u_hi + TABLE_MARGIN, -u_lo - TABLE_MARGIN
        # the design correspondence (the aligned ray reflected at paraboloid radius s meets the
        # meridian at u = -s), measured against Newton on the spline at CHECK_RADII radii
        s_check = np.linspace(s0, s1, CHECK_RADII)
        exact = _aligned_hits(exact_para, exact_dome, geo.cop_z, s_check)
        corr = _correspondence(exact_dome, s_check)
        nerr = np.abs(np.arctan2(corr[:, 2] * exact[:, 3] - corr[:, 3] * exact[:, 2],
                                 np.sum(corr[:, 2:] * exact[:, 2:], axis=1)))
        table_error = {"radii_checked": CHECK_RADII,
                       "max_dome_point_error_mm": float(np.max(np.hypot(*(corr[:, :2] - exact[:, :2]).T))),
                       "max_dome_normal_error_rad": float(np.max(nerr)),
                       "measured": "the meridian at u = -s against Newton on the spline, aligned COP rays"}
        pinhole = table_error["max_dome_point_error_mm"] < CORRESPONDENCE_TOL
        s_flags = np.linspace(s0, s1, FLAG_CELLS + 1)
        flags, beam_rho = _cell_flags(geo, s_flags, _correspondence(exact_dome, s_flags), para_occ, beam_occ)
        beam_y = np.array([beam_occ[:, 2].min() - FLAG_MARGIN_MM, beam_occ[:, 5].max() + FLAG_MARGIN_MM])
        shadowed = _mount_shadowed(geo, para_occ)
        return cls(geo.focal_length, geo.vertex_z, geo.rim_radius, geo.cop_z, para_occ, beam_occ, breaks, coef_r,
                   coef_z, float(u_lo), float(u_hi), float(s0), float(s1), float(FLAG_CELLS / (s1 - s0)), flags,
                   beam_rho, beam_y, shadowed, piece_of, float(piece_scale), pinhole, table_error, exact_dome)

    def trace(self, optics, origins: np.ndarray, dirs: np.ndarray):
        """Trace rays (n, 3) through ``optics`` (its poses) with the kernels: a Trace3D with
        ``kernels`` = rays per kernel."""
        from rigcad.check import _kernels as K
        from rigcad.check.trace3d import Trace3D

        origins = np.ascontiguousarray(origins, float)
        dirs = np.ascontiguousarray(dirs, float)
        n = len(origins)
        status = np.empty(n, np.int64)
        segment = np.empty(n, np.int8)
        p1, p2, v, landing = (np.empty((n, 3)) for _ in range(4))
        path, miss = np.empty(n), np.empty(n)
        out = (status, segment, p1, p2, v, landing, path, miss)
        pp, dp = optics.paraboloid_pose, optics.dome_pose
        aligned = pp.is_identity and dp.is_identity
        kernels = {"pinhole_aligned": 0, "general_newton": 0, "bracketed_fallback": 0}
        rest = None
        if n and aligned and self.pinhole and np.all(origins[:, 0] == 0.0) and np.all(origins[:, 1] == 0.0) \
                and np.all(origins[:, 2] == self.cop_z):
            handled = np.empty(n, np.bool_)
            K.pinhole_aligned(self.cop_z, dirs, self.focal_length, self.vertex_z, self.rim_radius, self.para_occ,
                              self.beam_occ, self.mount_shadowed, self.s0, self.s1, self.breaks, self.coef_r,
                              self.coef_z, self.piece_of, self.piece_scale, self.u_lo, self.flag_inv_h, self.flags,
                              self.beam_rho, self.beam_y, *out, handled)
            rest = np.nonzero(~handled)[0]
            kernels["pinhole_aligned"] = n - len(rest)
        elif n:
            rest = np.arange(n)
        if rest is not None and len(rest):
            kernels["general_newton"] = len(rest)
            kernels["bracketed_fallback"] = self._general(K, rest, origins, dirs, pp, dp, out)
        return Trace3D(*out, kernels=kernels)

    def _general(self, K, idx, origins, dirs, pp, dp, out) -> int:
        R1, T1, id1 = _pose(pp)
        R2, T2, id2 = _pose(dp)
        return int(K.general(idx, origins, dirs, R1, T1, id1, R2, T2, id2, self.focal_length, self.vertex_z,
                             self.rim_radius, self.para_occ, self.beam_occ, self.breaks, self.coef_r, self.coef_z,
                             self.u_lo, self.u_hi, self.piece_of, self.piece_scale, self.dome.u_tab, self.dome.r_tab,
                             self.dome.z_tab, self.dome.r_max, NEWTON_STEPS, RESIDUAL_TOL, NEWTON_STEP_TOL, *out))


#: Margin (mm) of the per-cell flags: a leg counts as clear of a solid's bounding shape only by at
#: least this much; a cell spans 0.23 um of paraboloid radius, over which a leg moves < 0.01 mm.
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


def _mount_shadowed(geo, para_occ: np.ndarray) -> bool:
    """Does every mount solid lie under the mirror surface within its rim (in the convex solid
    r <= rim, z <= vertex_z - r^2 / (4 f)), so that a ray from above that hits the mirror cannot
    meet the mount first? Checked at the solids' outermost corners / top rims."""
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
        if rmax > rim or top > zv - rmax * rmax / (4 * f):
            return False
    return True


def _correspondence(dome: R.ExactDome, s: np.ndarray) -> np.ndarray:
    """The meridian's point (r, z) and normal (n_r, n_z) at u = -s (m, 4)."""
    return np.column_stack([dome.m._spline(-s), dome.m.normals(-s)])


def _aligned_hits(para: R.ExactParaboloid, dome: R.ExactDome, cop_z: float, s: np.ndarray) -> np.ndarray:
    """(r, z) of the dome hit and the dome normal (n_r, n_z) of the aligned COP ray that reflects at
    paraboloid radius s (m,), in the x-z plane: (m, 4). Newton on the spline from the design's
    correspondence (u = -s); every ray must land (the radii are the dome's own)."""
    f, zv = para.f, para.zv
    p = np.stack([s, np.zeros_like(s), zv - s * s / (4 * f)], axis=-1)
    d = R.unit(p - np.array([0.0, 0.0, cop_z]))
    h = para.intersect(np.tile([0.0, 0.0, cop_z], (len(s), 1)), d)
    q = np.array([0.0, 0.0, cop_z]) + h.t[:, None] * d
    u = d - 2 * np.sum(d * h.normal, axis=1)[:, None] * h.normal
    c0 = dome.m._spline(-s)
    t0 = (c0[:, 1] - q[:, 2]) / u[:, 2]
    t, uu, res = dome._newton(q, u, t0, -s.copy(), R.NEWTON_STEPS)
    bad = ~(res < 1e-11)  # mm: Newton at rounding; the bracketing path otherwise
    if np.any(bad):
        idx, tb, ub = dome._bracketed(q[bad], u[bad])
        rows = np.nonzero(bad)[0][idx]
        t[rows], uu[rows] = tb, ub
        if len(idx) < bad.sum():  # pragma: no cover - the radii are inside the dome's
            raise R.CheckError("the aligned correspondence has radii whose ray misses the dome")
    hit = q + t[:, None] * u
    n2 = dome.m.normals(uu)
    return np.column_stack([hit[:, 0], hit[:, 2], n2[:, 0], n2[:, 1]])
