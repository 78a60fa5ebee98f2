"""The dome profile (thesis 3.2, Figure 3.6): every ray from the centre of projection (COP),
reflected by the paraboloid and then by the dome, must reach the sample point O = (0, 0).

Parameter: ``s``, the radius at which a COP ray meets the paraboloid, from the rim inwards.
Reflected ray: P(s) + t u(s). The dome point is D(s) = P + t u with the dome's normal bisecting
the incoming ray and the direction to O. Three ways to get t(s), all in mm:

* ``euler``: the thesis's polyline, planar mirror segments built ray by ray (first order);
* ``dop853`` / ``rk45``: the same condition as an ODE, dt/ds = (P' + t u').(w - u) / (1 - u.w),
  w = unit(O - D), solved by scipy's adaptive integrators with an absolute tolerance in mm;
* ``equal_path``: the closed form. The reflected rays stay normal to a wavefront (Malus-Dupin), so
  the dome images the COP onto O exactly when the optical path |CP| + t + |DO| is the same for
  every ray: t = (K^2 - |P|^2) / (2 (K + P.u)) with K = L - |CP|. For a COP at infinity this is the
  ellipse with foci at the paraboloid's focus and at O.

The dome starts where the rim ray meets the sample plane z = 0 (grazing incidence) and ends where
the returning ray D -> O is occluded by the paraboloid (theta = atan(rim_radius / rim_z)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from rigcad.errors import GeometryError, IntegrationError
from rigcad.profile.derived import Derived


@dataclass(frozen=True)
class Rays:
    """COP rays after the paraboloid, at parabola radii ``s`` (n,). Points/directions (n, 2)."""

    s: np.ndarray
    P: np.ndarray  #: hit points on the paraboloid
    u: np.ndarray  #: unit reflected directions
    dP: np.ndarray  #: dP/ds
    du: np.ndarray  #: du/ds
    source: np.ndarray  #: optical path from the COP (or from the plane z = vertex_z at infinity) to P


def reflected_rays(geo: Derived, s: np.ndarray) -> Rays:
    """The aligned design's rays, with analytic derivatives in ``s`` (closed forms)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    f = geo.focal_length
    P = np.stack([s, geo.vertex_z - s * s / (4.0 * f)], axis=-1)
    dP = np.stack([np.ones_like(s), -s / (2.0 * f)], axis=-1)
    if geo.cop_at_infinity:
        d = np.tile([0.0, -1.0], (len(s), 1))
        dd = np.zeros_like(d)
        source = geo.vertex_z - P[:, 1]
    else:
        e = P - np.array([0.0, geo.cop_z])
        norm_e = np.linalg.norm(e, axis=-1, keepdims=True)
        d = e / norm_e
        dd = (dP - d * np.sum(d * dP, axis=-1, keepdims=True)) / norm_e
        source = norm_e[:, 0]
    m = np.stack([s / (2.0 * f), np.ones_like(s)], axis=-1)
    norm_m = np.linalg.norm(m, axis=-1, keepdims=True)
    n = m / norm_m
    dm = np.tile([1.0 / (2.0 * f), 0.0], (len(s), 1))
    dn = (dm - n * np.sum(n * dm, axis=-1, keepdims=True)) / norm_m
    dn_ = np.sum(d * n, axis=-1, keepdims=True)
    u = d - 2.0 * dn_ * n
    ddn = np.sum(dd * n, axis=-1, keepdims=True) + np.sum(d * dn, axis=-1, keepdims=True)
    du = dd - 2.0 * (ddn * n + dn_ * dn)
    return Rays(s=s, P=P, u=u, dP=dP, du=du, source=source)


@dataclass(frozen=True)
class Start:
    """Where the dome begins: the rim ray meets the sample plane at ``point`` after ``t`` mm."""

    s: float
    t: float
    point: np.ndarray
    path_length: float  #: |CP| + t + |DO|: the same for every ray of an exact design


def start(geo: Derived) -> Start:
    """The first dome point (thesis 3.2): the rim ray's intersection with z = 0."""
    rays = reflected_rays(geo, np.array([geo.rim_radius]))
    u = rays.u[0]
    P = rays.P[0]
    if u[1] >= -1e-12:
        raise GeometryError(
            f"the ray reflected at the paraboloid's rim goes upward (direction {u[1]:+.3f} in z) and never "
            "reaches the sample plane: lower paraboloid.tangent_angle (or raise focal_length / rim_radius)",
            param="paraboloid.tangent_angle")
    t0 = -P[1] / u[1]
    D0 = P + t0 * u
    if D0[0] <= geo.rim_radius:
        raise GeometryError(
            f"the rim ray reaches the sample plane at r = {D0[0]:.3f} mm, inside the paraboloid's rim "
            f"({geo.rim_radius:.3f} mm): the dome would meet the paraboloid; raise layout.sample_to_rim "
            "or paraboloid.tangent_angle", param="layout.sample_to_rim")
    return Start(s=geo.rim_radius, t=float(t0), point=D0, path_length=float(rays.source[0] + t0 + np.hypot(*D0)))


def dt_ds(geo: Derived, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Right-hand side of the dome ODE (mm per mm), vectorised over (s, t) of shape (n,)."""
    r = reflected_rays(geo, s)
    D = r.P + t[:, None] * r.u
    w = -D / np.linalg.norm(D, axis=-1, keepdims=True)
    num = np.sum((r.dP + t[:, None] * r.du) * (w - r.u), axis=-1)
    den = 1.0 - np.sum(r.u * w, axis=-1)
    return num / den


def scalar_rhs(geo: Derived):
    """:func:`dt_ds` for one (s, t) in plain float arithmetic: the integrators' hot path (numpy's
    per-call overhead on 1-element arrays is ~10x the arithmetic). Same formulas as
    :func:`reflected_rays` and :func:`dt_ds`; a test checks they agree."""
    f = geo.focal_length
    vz = geo.vertex_z
    inf = geo.cop_at_infinity
    cz = geo.cop_z
    half_f = 1.0 / (2.0 * f)
    sqrt = math.sqrt

    def rhs(s: float, y) -> list[float]:
        t = y[0]
        px, pz = s, vz - s * s / (4.0 * f)
        dpx, dpz = 1.0, -s * half_f
        if inf:
            dx, dz, ddx, ddz = 0.0, -1.0, 0.0, 0.0
        else:
            ex, ez = px, pz - cz
            ne = sqrt(ex * ex + ez * ez)
            dx, dz = ex / ne, ez / ne
            dd = dx * dpx + dz * dpz
            ddx, ddz = (dpx - dx * dd) / ne, (dpz - dz * dd) / ne
        mx, mz = s * half_f, 1.0
        nm = sqrt(mx * mx + 1.0)
        nx, nz = mx / nm, mz / nm
        dmx = half_f
        nd = nx * dmx
        dnx, dnz = (dmx - nx * nd) / nm, (-nz * nd) / nm
        dn = dx * nx + dz * nz
        ux, uz = dx - 2.0 * dn * nx, dz - 2.0 * dn * nz
        ddn = ddx * nx + ddz * nz + dx * dnx + dz * dnz
        dux = ddx - 2.0 * (ddn * nx + dn * dnx)
        duz = ddz - 2.0 * (ddn * nz + dn * dnz)
        Dx, Dz = px + t * ux, pz + t * uz
        nD = sqrt(Dx * Dx + Dz * Dz)
        wx, wz = -Dx / nD, -Dz / nD
        num = (dpx + t * dux) * (wx - ux) + (dpz + t * duz) * (wz - uz)
        den = 1.0 - (ux * wx + uz * wz)
        return [num / den]

    return rhs


def equal_path_t(geo: Derived, s: np.ndarray, path_length: float) -> np.ndarray:
    """Closed-form distance along each reflected ray for the constant optical path ``path_length``."""
    r = reflected_rays(geo, s)
    K = path_length - r.source
    return (K * K - np.sum(r.P * r.P, axis=-1)) / (2.0 * (K + np.sum(r.P * r.u, axis=-1)))


def theta_of(points: np.ndarray) -> np.ndarray:
    """Incidence angle at O (rad from the normal +z) of light arriving from dome points (n, 2)."""
    return np.arctan2(points[:, 0], points[:, 1])


@dataclass(frozen=True)
class DomeProfile:
    """An integrated dome profile, right half of the meridional section (mm).

    ``s`` runs from the rim inwards; ``points`` are the dome points D(s); ``t`` the distances
    along the reflected rays. ``kind`` is ``polyline`` (flat segments between the points, the
    thesis's mirror) or ``smooth`` (the points sample a smooth curve). ``error_estimate`` is the
    estimated global error in t (mm); ``error_vs_equal_path`` the measured one against the closed form.
    """

    method: str
    kind: str
    s: np.ndarray
    t: np.ndarray
    points: np.ndarray
    path_length: float
    occlusion_s: float
    tolerance: float | None
    error_estimate: float
    error_vs_equal_path: float
    stats: dict[str, int] = field(default_factory=dict)

    @property
    def theta(self) -> np.ndarray:
        return theta_of(self.points)

    @cached_property
    def spline(self):
        """The one smooth curve through this profile's rows: a quintic interpolating spline of the
        dome point (r, z) in mm against u = -s, so u increases from the dome's base (the rim ray,
        s = rim radius) to its top. Every smooth reading of the dome uses it: the 2D tracer
        (trace2d.DomeCurve), the 3D surfaces (surfaces.Meridian), and through them the solids,
        meshes, ray checks and fabrication. Built on first use and kept (smooth profiles only)."""
        if self.kind != "smooth":
            raise GeometryError(f"the {self.method} dome is a polyline of flat mirror segments: it has no smooth "
                                "curve (use dome.method dop853, rk45 or equal_path)", param="dome.method")
        from scipy.interpolate import make_interp_spline  # scipy is imported when a dome is read, not with rigcad

        order = np.argsort(self.s)[::-1]  # s decreases from the rim (bottom) to the top
        return make_interp_spline(-self.s[order], self.points[order], k=5)


def scalar_theta(geo: Derived, path_length: float):
    """theta(s) (rad) of the closed-form dome (:func:`equal_path_t`) in plain float arithmetic, for
    root finding (numpy's per-call overhead on 1-element arrays is ~10x the arithmetic). Same
    formulas as :func:`reflected_rays` and :func:`equal_path_t`; a test checks they agree."""
    f, vz, cz, inf = geo.focal_length, geo.vertex_z, geo.cop_z, geo.cop_at_infinity
    sqrt = math.sqrt

    def theta(s: float) -> float:
        px, pz = s, vz - s * s / (4.0 * f)
        if inf:
            dx, dz, source = 0.0, -1.0, vz - pz
        else:
            ex, ez = px, pz - cz
            source = sqrt(ex * ex + ez * ez)
            dx, dz = ex / source, ez / source
        mx = s / (2.0 * f)
        nm = sqrt(mx * mx + 1.0)
        nx, nz = mx / nm, 1.0 / nm
        dn = dx * nx + dz * nz
        ux, uz = dx - 2.0 * dn * nx, dz - 2.0 * dn * nz
        K = path_length - source
        t = (K * K - (px * px + pz * pz)) / (2.0 * (K + px * ux + pz * uz))
        return math.atan2(px + t * ux, pz + t * uz)

    return theta


def occlusion_s(geo: Derived, path_length: float) -> float:
    """Parabola radius whose dome point is seen from O exactly at the rim (closed form + brentq)."""
    from scipy.optimize import brentq

    theta = scalar_theta(geo, path_length)

    def g(s: float) -> float:
        return theta(s) - geo.occlusion_theta

    lo, hi = 1e-12 * geo.rim_radius, geo.rim_radius
    if g(lo) >= 0:
        return 0.0
    return brentq(g, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)


def _check_clear(geo: Derived, prof_points: np.ndarray) -> None:
    """Refuse a dome that would cut through the paraboloid."""
    inside_band = (prof_points[:, 1] >= geo.rim_z) & (prof_points[:, 1] <= geo.vertex_z)
    para_r = np.sqrt(np.clip(4 * geo.focal_length * (geo.vertex_z - prof_points[:, 1]), 0, None))
    if np.any(inside_band & (prof_points[:, 0] <= para_r)):
        raise GeometryError(
            "the dome profile passes through the paraboloid: move the paraboloid away from the sample "
            "(layout.sample_to_rim) or reduce its size (paraboloid.vertical_extent / rim_radius)",
            param="layout.sample_to_rim")
    if not np.all(np.isfinite(prof_points)):
        raise GeometryError("the dome profile is not finite: the paraboloid reflects rays back onto themselves; "
                            "check paraboloid.tangent_angle and layout", param="paraboloid.tangent_angle")


def rows_even_in_theta(geo: Derived, t_of_s, s_end: float, rows: int) -> np.ndarray:
    """Parabola radii (rows,) from the rim to ``s_end`` whose dome points are evenly spaced in the
    incidence angle theta: the dome point's speed in s varies by orders of magnitude on pointed
    paraboloids, so rows even in s would leave the top of the dome under-sampled."""
    fine = np.linspace(geo.rim_radius, s_end, 20001)
    r = reflected_rays(geo, fine)
    theta = theta_of(r.P + t_of_s(fine)[:, None] * r.u)
    targets = np.linspace(theta[0], theta[-1], rows)
    s = np.interp(targets, theta[::-1], fine[::-1])  # theta falls monotonically from the rim inwards
    s[0], s[-1] = geo.rim_radius, s_end
    return s


def build_equal_path(geo: Derived, rows: int) -> DomeProfile:
    """The closed-form dome sampled at ``rows`` points evenly spaced in theta."""
    st = start(geo)
    s_end = occlusion_s(geo, st.path_length)
    s = rows_even_in_theta(geo, lambda x: equal_path_t(geo, x, st.path_length), s_end, rows)
    t = equal_path_t(geo, s, st.path_length)
    r = reflected_rays(geo, s)
    pts = r.P + t[:, None] * r.u
    _check_clear(geo, pts)
    return DomeProfile("equal_path", "smooth", s, t, pts, st.path_length, s_end, None,
                       error_estimate=0.0, error_vs_equal_path=0.0, stats={"evaluations": rows})


def build_euler(geo: Derived, steps: int) -> DomeProfile:
    """The thesis's polyline: rays evenly spaced in s from the rim to the vertex, ``steps`` gaps in all,
    each planar segment's normal bisecting its incoming ray and the direction to O; stops before
    the first ray whose return to O is occluded. Written as a scalar loop: each point needs the last."""
    st = start(geo)
    s_all = np.linspace(geo.rim_radius, 0.0, steps + 1)
    r = reflected_rays(geo, s_all)
    Px, Pz = r.P[:, 0].tolist(), r.P[:, 1].tolist()
    ux, uz = r.u[:, 0].tolist(), r.u[:, 1].tolist()
    tan_occ = math.tan(geo.occlusion_theta)
    dx, dz = float(st.point[0]), float(st.point[1])
    xs, zs, ts = [dx], [dz], [st.t]
    for k in range(1, steps + 1):
        norm = math.hypot(dx, dz)
        nx, nz = -dx / norm - ux[k - 1], -dz / norm - uz[k - 1]
        den = ux[k] * nx + uz[k] * nz
        if den == 0.0:
            break
        lam = ((dx - Px[k]) * nx + (dz - Pz[k]) * nz) / den
        ndx, ndz = Px[k] + lam * ux[k], Pz[k] + lam * uz[k]
        if not (ndz > 0 and ndx > ndz * tan_occ) or lam <= 0:
            break
        dx, dz = ndx, ndz
        xs.append(dx)
        zs.append(dz)
        ts.append(lam)
    n = len(xs)
    pts = np.column_stack([xs, zs])
    s = s_all[:n]
    t = np.array(ts)
    _check_clear(geo, pts)
    exact = equal_path_t(geo, s, st.path_length)
    err = float(np.max(np.abs(t - exact)))
    h = geo.rim_radius / steps
    return DomeProfile("euler", "polyline", s, t, pts, st.path_length, float(s[-1]), None,
                       error_estimate=float("nan"), error_vs_equal_path=err,
                       stats={"steps": n - 1, "step_mm": h})  # type: ignore[dict-item]


def _solve(geo: Derived, method: str, tol: float, st: Start, s_end: float):
    """One solve_ivp run from the rim to s_end; raises IntegrationError when scipy reports failure."""
    from scipy.integrate import solve_ivp

    rtol = max(tol / (2.0 * st.t), 100 * np.finfo(float).eps)  # |t| <= 2 t_rim: allowance <= 2 tol

    rhs = scalar_rhs(geo)

    sol = solve_ivp(rhs, (geo.rim_radius, s_end), [st.t], method=method.upper(), rtol=rtol, atol=tol,
                    dense_output=True)
    if not sol.success:
        raise IntegrationError(f"dome integration ({method}, tolerance {tol:g} mm) failed: {sol.message}")
    return sol


#: Default global tolerance of the adaptive integrators, as a fraction of the optical path length
#: (6e-9 mm on the thesis's 579 mm path, ~30x above what float64 and DOP853's dense output can
#: certify there). When a profile leaves ``dome.tolerance`` unset and an extreme geometry cannot
#: reach it, the best certified result is kept and its estimate reported.
AUTO_RELATIVE_TOLERANCE = 1e-11


def build_adaptive(geo: Derived, method: str, tol: float | None, rows: int) -> DomeProfile:
    """The dome ODE solved by scipy (``dop853`` or ``rk45``), sampled through the dense output at
    ``rows`` points evenly spaced in theta.

    Contract: the *global* error in t on those rows is at most ``tol`` (mm), as estimated by a
    second solve at a 100x tighter tolerance. scipy controls only the local error per step, so the
    local tolerance starts at ``tol`` and is tightened tenfold until the estimate meets ``tol``;
    an explicit ``tol`` that float64 cannot certify raises IntegrationError. The error against the
    closed form is measured and reported beside the estimate.
    """
    st = start(geo)
    auto = tol is None
    if tol is None:
        tol = AUTO_RELATIVE_TOLERANCE * st.path_length
    s_end = occlusion_s(geo, st.path_length)
    first = _solve(geo, method, tol, st, s_end)
    s = rows_even_in_theta(geo, lambda x: first.sol(x)[0], s_end, rows)
    floor = 100 * np.finfo(float).eps * 2.0 * st.t  # scipy's smallest rtol, on the largest t
    local = tol
    evaluations = 0
    best: tuple[float, np.ndarray, float, int] | None = None  # (estimate, t, local, steps)
    while True:
        tight = max(local / 100.0, floor)
        if tight > local / 10.0:
            if auto and best is not None:
                break
            reachable = f"{best[0]:.1e}" if best is not None else f"{100 * floor:.0e}"
            raise IntegrationError(param="dome.tolerance", message=
                f"dome.tolerance = {tol:g} mm cannot be certified with {method}: estimating the global error "
                f"needs a reference solve 10x tighter than local tolerance {local:.0e} mm, below the "
                f"{floor:.1e} mm that float64 resolves on distances of {2 * st.t:.0f} mm; ask for {reachable} mm or more")
        sol = _solve(geo, method, local, st, s_end)
        ref_sol = _solve(geo, method, tight, st, s_end)
        evaluations += int(sol.nfev + ref_sol.nfev)
        t_local = sol.sol(s)[0]
        estimate = float(np.max(np.abs(t_local - ref_sol.sol(s)[0])))
        if best is None or estimate < best[0]:
            best = (estimate, t_local, local, len(sol.t) - 1)
        if estimate <= tol:
            break
        local = local / 10.0
    estimate, t, local, steps = best
    r = reflected_rays(geo, s)
    pts = r.P + t[:, None] * r.u
    _check_clear(geo, pts)
    exact = equal_path_t(geo, s, st.path_length)
    return DomeProfile(method, "smooth", s, t, pts, st.path_length, s_end, tol,
                       error_estimate=estimate,
                       error_vs_equal_path=float(np.max(np.abs(t - exact))),
                       stats={"evaluations": evaluations, "steps": int(steps),
                              "local_tolerance_mm": float(local)})  # type: ignore[dict-item]


def build_dome(geo: Derived, method: str, *, tolerance: float | None = None, euler_steps: int = 2000,
               rows: int = 2001) -> DomeProfile:
    """Build the dome profile by ``method`` (see the module docstring)."""
    if method == "euler":
        return build_euler(geo, euler_steps)
    if method == "equal_path":
        return build_equal_path(geo, rows)
    if method in ("dop853", "rk45"):
        return build_adaptive(geo, method, tolerance, rows)
    raise ValueError(f"unknown dome method {method!r}")
