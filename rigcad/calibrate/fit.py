"""The misalignment fit, the dome's residual slope map and the corrected pixel -> incidence map.

Fit: scipy.optimize.least_squares (trust-region reflective) over the parameters of
:mod:`rigcad.calibrate.model`, scaled by their tolerances; residuals are the decoded screen points
minus the forward model's (mm, both screen axes, every capture) over every ``fit_stride``-th camera
pixel that decoded in every capture. The Jacobian is by forward differences with one trace per rig
parameter (the screens' columns reuse the base trace and recompute their own capture's points only:
the same columns to the last bit, a test holds it). After a first
solve, residuals beyond 5 robust sigmas (1.4826 MAD) of their path, and beyond a fifth of the finest
period (:data:`OUTLIER_PERIOD_FRACTION`), are dropped and the fit repeated. Each
pixel's residual component that a dome slope error makes (a turn about its dome point) is
down-weighted in the map's refit (:data:`SLOPE_PROJECTION`). Standard
errors: the posterior under the tolerances' prior (:func:`posterior_covariance`), s^2 (J^T J)^-1
where the data decide, s^2 the residual variance. The residual is dominated by the surface
error, which is correlated between neighbouring pixels and alike in every capture of a pixel, so
the reported fit's covariance is the cluster-robust sandwich over tiles of the camera window
(:data:`CLUSTER_PX`); the bench compares the standard errors with the errors (docs/calibrate.md;
what was tried, with its figures: docs/calibrate-notes.md).

Residual slopes: where the measured ray d (up, the raxel) differs from the fitted model's, the
difference is read as a tilt of the dome's normal at the model ray's dome point: for the
reflection v = u - 2 (u.n) n, a normal tilt dn in the tangent plane changes v by
-2 [(u.dn) n + (u.n) dn], whose tangential part gives grad_s h = dv_t / (2 u.n). Each camera ray
meets the paraboloid at one point and the dome at one point: the paraboloid's slope error at its
point and the dome's at the paired point make the same ray error, so they cannot be told apart, and
neither can a low-order figure error that a misalignment parameter mimics (a tilt, a shift); the
residual is attributed to the dome, the mirror sanded by hand."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.calibrate import model as M

#: Forward-difference steps of the Jacobian, as a fraction of each parameter's tolerance: 1e-3 of
#: 0.1 mm is 0.1 um, far above the tracer's Newton tolerance and far below the curvature scale.
JAC_STEP = 1e-3
#: The robust first solve's scale (mm on the screen): soft L1 above it. The dome's slope errors
#: move the screen points by ~0.2 mm (1 mrad over the ~200 mm from the dome): they stay quadratic.
ROBUST_SCALE_MM = 0.5
#: The tolerances as a Gaussian prior (each parameter ~ N(0, tolerance), but the half turn's pair:
#: :func:`rigcad.calibrate.model.prior_root`), one residual row per parameter of this weight (mm): a ridge that holds the near-null combinations (the camera's and
#: the paraboloid's lateral offsets with the camera's tilt: they move the rays alike) at their prior
#: instead of letting the surface error push them millimetres away; along every well-seen direction
#: the tens of thousands of data rows outweigh it.
PRIOR_MM = 0.2
#: The map's refit (:func:`fit` with ``slope_projection``): a dome slope error turns a pixel's ray
#: about its dome point, which moves the pixel's screen points by amounts proportional to their
#: distances t_k from the dome, along one direction per screen axis. That component of each pixel's
#: residual (its projection on (t_0, t_1, ...)) is scaled by 1 - this, so the unknown surface steers
#: the dome points (what the map's rays turn about: :func:`rigcad.calibrate.maps.pivot_rays`) less.
#: 1 would leave the dome's tilts to the prior alone; 0.9 gave the best map of 0.5-1 on seeded trials
#: kept out of the bench (docs/calibrate-notes.md, "The map's refit"). The misalignment reported is
#: the plain fit's: the refit's parameters are worse.
SLOPE_PROJECTION = 0.9
#: The direct view's pixels (:func:`seen_direct`) the fit reads: every this-many-th of the fit's rows
#: and columns (``calibration.fit_stride``). They fix the camera's pose against the screens with
#: the decoding's micrometres, free of the mirrors' surface error; every 2nd pixel put the camera's
#: offset within target where every 4th did not, at less CPU than every one (docs/calibrate-notes.md,
#: "The direct view").
DIRECT_STRIDE = 2
#: The most the direct view's rows are weighted against the mirrored ones (the ratio of their robust
#: sigmas after the first solve, ~30-60 in practice): a cap against a degenerate sigma, not a setting.
MAX_DIRECT_WEIGHT = 1000.0
#: Iterations of each solve (each costs a Jacobian: one trace per rig parameter).
MAX_ITERATIONS = 40
#: Outliers: residuals past this many robust sigmas are dropped before the second solve.
OUTLIER_SIGMAS = 5.0
#: ... and only those past this share of the finest period on the screen (mm: 0.25 mm for 16 px of
#: 0.0779 mm): what the test is for is a point decoded a period or a stripe away. On a rig with no
#: surface error the mirrored rows' robust sigma is the decoding's few micrometres, and the long
#: footprints near grazing decode ten times looser; 5 sigmas alone dropped thousands of them there
#: (2,486 on a flat-only capture of an aligned rig, one-off) as if they were wrong.
OUTLIER_PERIOD_FRACTION = 0.2
#: A correlation the report lists (:meth:`FitResult.strong_correlations`): beyond this ...
STRONG_CORRELATION = 0.9
#: ... between parameters whose standard errors are over this share of their recovery targets (two
#: standard errors span the target).
LOOSE_SHARE = 0.5
#: The reported fit's covariance treats the residuals of the camera pixels within one square tile
#: this many pixels wide, every capture of them, as one draw (:func:`posterior_covariance`'s
#: ``clusters``): the surface error's residual is smooth across the window and repeats in each
#: capture of a pixel (a turned capture sees the same rays), so rows are not independent. 32-128 px
#: gave alike (docs/calibrate-notes.md, "Rows that are not independent").
CLUSTER_PX = 64


@dataclass
class FitData:
    """What the fit reads: pixel indices (into the camera window), the decoded screen points
    (n, heights, 2) mm, and which pixels see the screens directly (:func:`seen_direct`)."""

    pixels: np.ndarray
    screen_uv: np.ndarray
    direct: np.ndarray


def in_report_units(names, values: np.ndarray, standard_error: np.ndarray) -> dict:
    """name -> value and standard error, angles in degrees (``_rad`` names become ``_deg``)."""
    out = {}
    for n, v, s in zip(names, values, standard_error):
        scale = 180 / math.pi if n.endswith("_rad") else 1.0
        out[n.replace("_rad", "_deg")] = {"value": float(v * scale), "standard_error": float(s * scale)}
    return out


def against_dome(rig, fit: FitResult) -> tuple[np.ndarray, np.ndarray]:
    """The fit's paraboloid and camera against the dome (:func:`rigcad.calibrate.model.in_dome_frame`,
    mm and rad, :data:`rigcad.calibrate.model.DOME_FRAME_NAMES`) and their standard errors: what a
    technician adjusts, free of the frame's tilt that only the priors fix (the fit's standard errors
    of the same parameters in the sample frame carry it)."""
    cov = M.in_dome_frame_covariance(rig, fit.theta, fit.covariance)
    return M.in_dome_frame(rig, fit.theta), np.sqrt(np.diag(cov))


def screens_against_dome(rig, plan: M.Plan, fit: FitResult) -> tuple[np.ndarray, np.ndarray]:
    """Each capture's screen tilt against the dome (:func:`rigcad.calibrate.model.screens_in_dome_frame`,
    (captures, 2) rad) and its standard errors: what the same rig's calibrations compare to
    measure how a screen settles (rigcad.calibrate.seating)."""
    names = M.parameter_names(len(plan))
    cov = M.covariance_through(lambda t: M.screens_in_dome_frame(rig, plan, t), fit.theta, fit.covariance, names)
    return M.screens_in_dome_frame(rig, plan, fit.theta), np.sqrt(np.diag(cov)).reshape(-1, 2)


def direct_ring_mm(design) -> float:
    """Where, on the sample plane, the camera's direct view past the paraboloid's rim begins (mm from
    O): its pinhole ray past the rim, cop_z tan(alpha_max) (24 mm on Table 3.1)."""
    return float(design.cop_z * math.tan(design.alpha_max))


def seen_direct(plan: M.Plan, screen_uv: np.ndarray, ring_mm: float) -> np.ndarray:
    """(n,) which pixels' decoded points (n, captures, 2) mm say the camera sees the screens
    directly, past the paraboloid (:func:`rigcad.calibrate.model.direct_view`), not off the mirrors.
    The line through a pixel's points on the lowest and the highest screen (each laid as planned),
    carried down to the sample plane, meets it near O for a ray off the dome, whatever the
    misalignment (a few mm), and at least ``ring_mm`` (:func:`direct_ring_mm`) out for a direct one:
    the split is at half of that. The hand's placement (``model.PLACEMENT_MM``, 1 deg) moves that
    point by well under a millimetre for a direct ray, about one for a grazing one. The fit reads
    each pixel along the path its points show: near the paraboloid's rim, where the design and the
    built rig see past the mirror at different pixels, the forward model's path at the current
    parameters may not be the camera's."""
    from rigcad.calibrate.raxel import to_global

    poses = M.screens(plan, np.zeros(len(M.RIG_NAMES) + len(plan.heights) * len(M.SCREEN_KEYS)))
    lo, hi = int(np.argmin(plan.heights)), int(np.argmax(plan.heights))
    a, b = (to_global(poses[k], screen_uv[:, k, 0], screen_uv[:, k, 1]).reshape(-1, 3) for k in (lo, hi))
    at_plane = a - (b - a) * (a[:, 2:3] / (b[:, 2:3] - a[:, 2:3]))
    return np.hypot(at_plane[:, 0], at_plane[:, 1]) > ring_mm / 2


@dataclass
class FitResult:
    theta: np.ndarray
    names: tuple[str, ...]
    standard_error: np.ndarray
    correlation: np.ndarray
    rms_residual_mm: float
    residuals_used: int
    outliers: int
    evaluations: int
    covariance: np.ndarray
    #: of ``residuals_used``, the direct view's (:func:`seen_direct`), their RMS (mm, unweighted) and
    #: the weight the fit gave them against the mirrored rows; ``rms_residual_mm`` is the mirrored rows'
    direct_residuals: int
    direct_rms_residual_mm: float
    direct_weight: float
    #: each parameter's recovery target (mm, rad; :func:`rigcad.calibrate.model.recovery_targets`)
    targets: np.ndarray | None = None

    #: the paraboloid's and the camera's placement against the dome: its covariance
    #: (:func:`rigcad.calibrate.model.in_dome_frame_covariance`, over
    #: :data:`rigcad.calibrate.model.DOME_FRAME_NAMES`), when the caller computed it
    dome_frame_covariance: np.ndarray | None = None

    def strong_correlations(self) -> list[tuple[str, str, float]]:
        """The pairs correlated beyond :data:`STRONG_CORRELATION` among the parameters a technician
        adjusts, the paraboloid's and the camera's placement against the dome
        (:attr:`dome_frame_covariance`; the fit's own parameters without it), whose parameters are
        both loosely fixed: each one's standard error over :data:`LOOSE_SHARE` of its target. Those
        trade off against each other within their targets. In the sample frame every part and
        screen shares the frame's tilt, which correlates dozens of pairs on any rig, and a parameter
        fixed well within its target is fixed whatever it correlates with."""
        names, cov, targets = self.names, self.covariance, self.targets
        if self.dome_frame_covariance is not None:
            names = M.DOME_FRAME_NAMES
            cov = self.dome_frame_covariance
            targets = None if targets is None else targets[[self.names.index(n) for n in names]]
        se = np.sqrt(np.diag(cov))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = np.nan_to_num(cov / np.outer(se, se))
        loose = se > LOOSE_SHARE * (targets if targets is not None else 0.0)
        n = len(names)
        return [(names[i], names[j], float(corr[i, j])) for i in range(n) for j in range(i + 1, n)
                if abs(corr[i, j]) > STRONG_CORRELATION and loose[i] and loose[j]]

    def as_dict(self) -> dict:
        out = in_report_units(self.names, self.theta, self.standard_error)
        strong = self.strong_correlations()
        return {"parameters": out, "rms_residual_mm": self.rms_residual_mm, "residuals_used": self.residuals_used,
                "direct_view_residuals": self.direct_residuals,
                "direct_view_rms_residual_mm": self.direct_rms_residual_mm, "direct_view_weight": self.direct_weight,
                "outliers_dropped": self.outliers, "evaluations": self.evaluations,
                "strong_correlations": {
                    "about": "the paraboloid's and the camera's placement against the dome: pairs correlated beyond "
                             f"{STRONG_CORRELATION:g} whose standard errors are both over {LOOSE_SHARE:g} of their "
                             "recovery targets (a tenth of the tolerance, at least 0.02 mm or 0.01 deg), which the "
                             "images fix only together; the sample frame's whole matrix is under 'correlation'",
                    "pairs": [{"a": a, "b": b, "correlation": c} for a, b, c in strong]},
                "correlation_order": list(self.names), "correlation": self.correlation.tolist()}


class Problem:
    """The residual function and its Jacobian (module docstring)."""

    def __init__(self, optics, rig, cam: M.Camera, plan: M.Plan, data: FitData,
                 slope_projection: float = 0.0) -> None:
        self.optics, self.rig, self.cam, self.plan, self.data = optics, rig, cam, plan, data
        self.slope_projection = slope_projection
        self.x, self.y = cam.x_px[data.pixels], cam.y_px[data.pixels]
        self.scale = M.tolerance_scale(rig, len(plan))
        self.n_rig = len(M.RIG_NAMES)
        self.keep = np.ones(len(data.pixels) * len(plan) * 2, bool)
        self.evaluations = 0
        #: the direct view's rows' weight against the mirrored ones (:func:`fit` sets it)
        self.direct_weight = 1.0
        #: the fitted parameters: all but the gauge (model.GAUGE)
        self.free = np.array([n not in M.GAUGE for n in M.parameter_names(len(plan))])
        #: the prior's residual rows over the free parameters (model.prior_root; mm)
        self.prior = PRIOR_MM * M.prior_root(rig, plan)[np.ix_(self.free, self.free)]

    def trace(self, theta: np.ndarray) -> M.Traced:
        self.evaluations += 1
        return M.trace_camera(self.optics, M.moved(self.rig, theta), self.x, self.y, self.cam.design)

    @staticmethod
    def on_capture(tr: M.Traced, pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each ray's point (u, v) mm on one capture's screen, and its reach there (mm from the dome
        along the ray; the slope projection's lever)."""
        su, sv = tr.screen(pose)
        return su, sv, (pose.translation[2] - tr.p2[:, 2]) / tr.v[:, 2]

    def residual_of(self, tr: M.Traced, theta: np.ndarray, captures: list | None = None) -> np.ndarray:
        """The residual rows at ``theta`` for the rays ``tr`` (traced at ``theta``'s rig part).
        ``captures``: :meth:`on_capture` of each capture's screen at ``theta``, when the caller has
        them (the Jacobian's screen columns change one capture's)."""
        out = np.full((len(self.x), len(self.plan), 2), np.nan)
        path = np.where(self.data.direct, tr.direct, tr.ok)  # the path the decoded points show
        reach = np.empty((len(self.x), len(self.plan)))
        poses = M.screens(self.plan, theta)
        if captures is None:
            captures = [self.on_capture(tr, pose) for pose in poses]
        for k, (su, sv, lever) in enumerate(captures):
            out[path, k, 0], out[path, k, 1] = su[path], sv[path]
            reach[:, k] = lever
        r = out - self.data.screen_uv
        r[self.data.direct] *= self.direct_weight
        if self.slope_projection:  # a direct view's point has no dome to turn about
            r = np.where(tr.ok[:, None, None], slope_projected(
                r, reach, np.stack([pose.rotation[:2, :2] for pose in poses]), self.slope_projection), r)
        return r.ravel()[self.keep]

    def clusters(self) -> np.ndarray:
        """Per kept data row, the tile of the camera window (:data:`CLUSTER_PX`) its pixel lies in."""
        pixel = self.data.pixels[np.nonzero(self.keep)[0] // (2 * len(self.plan))]
        row, col = np.divmod(pixel, self.cam.shape[1])
        return (row // CLUSTER_PX) * (self.cam.shape[1] // CLUSTER_PX + 1) + col // CLUSTER_PX

    def full(self, z: np.ndarray) -> np.ndarray:
        """The parameter vector (scaled) from the free ones (the gauge at 0)."""
        out = np.zeros(len(self.scale))
        out[self.free] = z
        return out

    def fun(self, z: np.ndarray) -> np.ndarray:
        theta = self.full(z) * self.scale
        r = self.residual_of(self.trace(theta), theta)
        return np.concatenate([np.where(np.isfinite(r), r, 0.0), self.prior @ z])

    def jac(self, z: np.ndarray) -> np.ndarray:
        """Forward differences over the free parameters, then the prior's rows. A rig parameter's
        column traces again; a screen parameter's reuses the base trace and every other capture's
        points (a screen's parameters move only its own pose: :func:`model.screens`)."""
        theta = self.full(z) * self.scale
        base_tr = self.trace(theta)
        poses = M.screens(self.plan, theta)
        captures = [self.on_capture(base_tr, pose) for pose in poses]
        base = self.residual_of(base_tr, theta, captures)
        free = np.nonzero(self.free)[0]
        J = np.empty((len(base) + len(self.prior), len(free)))
        for col, i in enumerate(free):
            t = theta.copy()
            t[i] += JAC_STEP * self.scale[i]
            if i < self.n_rig:
                r = self.residual_of(self.trace(t), t)
            else:
                k = (i - self.n_rig) // len(M.SCREEN_KEYS)
                moved = list(captures)
                moved[k] = self.on_capture(base_tr, M.screens(self.plan, t)[k])
                r = self.residual_of(base_tr, t, moved)
            diff = (r - base) / JAC_STEP
            J[:len(base), col] = np.where(np.isfinite(diff), diff, 0.0)  # a ray lost on either side: no slope
        J[len(base):] = self.prior
        return J


def slope_projected(r: np.ndarray, reach: np.ndarray, axes: np.ndarray, factor: float) -> np.ndarray:
    """Residuals (n pixels, k screens, 2) mm with their dome-slope component scaled by 1 - ``factor``
    (:data:`SLOPE_PROJECTION`): a turn of the pixel's ray about its dome point moves its point on
    screen k by reach[:, k] (mm from the dome) times one (x, y) vector in the sample frame, so the
    component is the projection on (reach_0, reach_1, ...) of the residuals turned into that frame by
    ``axes`` (k, 2, 2: each screen's (u, v) -> (x, y); a turned capture's axes point the other way)."""
    (xu, xv), (yu, yv) = axes[:, 0].T, axes[:, 1].T  # each (k,): written out, no einsum (FMA varies)
    ru, rv = r[..., 0], r[..., 1]
    norm = np.sum(reach * reach, axis=1)
    ax = np.sum(reach * (xu * ru + xv * rv), axis=1) / norm
    ay = np.sum(reach * (yu * ru + yv * rv), axis=1) / norm
    lever = factor * reach
    out = np.empty_like(r)
    out[..., 0] = ru - lever * (xu * ax[:, None] + yu * ay[:, None])
    out[..., 1] = rv - lever * (xv * ax[:, None] + yv * ay[:, None])
    return out


def posterior_covariance(jac: np.ndarray, fun: np.ndarray, root: np.ndarray,
                         clusters: np.ndarray | None = None) -> np.ndarray:
    """The free parameters' covariance (tolerance units) under the prior the tolerances state (each
    ~ N(0, 1) there, but for a turned capture's pair: ``root``, :func:`model.prior_root` over the
    free parameters) and the data rows' residual variance s^2: A^-1 = (J_d^T J_d / s^2 + R^T R)^-1,
    J_d the data rows of ``jac`` (its last rows are the prior's). Along what the data fix,
    s^2 (J_d^T J_d)^-1; along what they do not (the frame's tilt: docs/calibrate.md, "What the figures mean"), the prior
    itself, whatever the fit's ridge weight (:data:`PRIOR_MM`) did to the solve.

    ``clusters`` (an int per data row): rows that share one are not taken as independent. The
    covariance is then the cluster-robust sandwich A^-1 (sum_c g*_c g*_c^T / s^4 * (m - 1) / m +
    R^T R) A^-1 over m clusters (Liang and Zeger, Biometrika 73, 1986), each cluster's score
    g_c = J_c^T r_c over its rows with its own leverage taken out, g*_c = A (A - A_c)^-1 g_c, A_c =
    J_c^T J_c / s^2 (CR3, the jackknife's: Bell and McCaffrey, Survey Methodology 28, 2002; Cameron
    and Miller, J. Human Resources 50, 2015). With few clusters, each fixing a good share of the
    parameters, the plain scores miss what the fit absorbed of each cluster's residual (the window
    holds a few dozen tiles). With independent rows it tends to A^-1."""
    p = jac.shape[1]
    jd, rd = jac[:-p], fun[:-p]
    s2 = max(float(rd @ rd) / max(len(rd) - p, 1), 1e-300)
    prior = root.T @ root
    information = jd.T @ jd / s2 + prior
    inverse = np.linalg.inv(information)
    if clusters is None:
        return inverse
    _, index = np.unique(clusters, return_inverse=True)
    m = int(index.max()) + 1
    if m < 2:
        raise ValueError("the cluster-robust covariance needs at least two clusters of residuals")
    g = np.zeros((m, p))
    np.add.at(g, index, jd * rd[:, None])
    # each cluster's score with its own leverage taken out (CR3: Bell and McCaffrey, Survey
    # Methodology 28, 2002): the fit absorbs part of a cluster's residual into the parameters, the
    # more so the more the cluster alone fixes them, and the plain score misses that part. A_c its
    # rows' information: g*_c = A (A - A_c)^-1 g_c, the scores of the fit without the cluster
    for c in range(m):
        rows = index == c
        g[c] = information @ np.linalg.solve(information - jd[rows].T @ jd[rows] / s2, g[c])
    meat = g.T @ g / s2 ** 2 * ((m - 1) / m) + prior
    return inverse @ meat @ inverse


def fit(optics, rig, cam: M.Camera, plan: M.Plan, data: FitData, say=None, slope_projection: float = 0.0,
        start: np.ndarray | None = None, clustered: bool = True) -> FitResult:
    """Fit the misalignment (module docstring); ``say``: a callable told each stage;
    ``slope_projection``: :data:`SLOPE_PROJECTION` for the map's refit, 0 for the plain fit;
    ``start``: the parameters to start from (the design by default); ``clustered``: the covariance
    cluster-robust over the window's tiles (:data:`CLUSTER_PX`), or the plain posterior."""
    from scipy.optimize import least_squares

    prob = Problem(optics, rig, cam, plan, data, slope_projection)
    z0 = np.zeros(int(prob.free.sum())) if start is None else (start / prob.scale)[prob.free]
    # robust first solve from the design: pixels near the screen's edges or the shadows decode wrong,
    # and rays near grazing meet the screen far away; soft L1 at ROBUST_SCALE_MM keeps them from
    # steering the fit
    res = least_squares(prob.fun, z0, jac=prob.jac, method="trf", loss="soft_l1", f_scale=ROBUST_SCALE_MM,
                        xtol=1e-10, ftol=1e-10, max_nfev=MAX_ITERATIONS)
    # each path at its own scale: a direct view's residual is the decoding's (~um), a mirrored one's
    # the surface error's (~0.2 mm). Outliers by each one's robust sigma; then the direct rows
    # weighted by the ratio of the sigmas, so every row counts at its own precision (and the
    # posterior's s^2 is one scale)
    direct_rows = np.repeat(data.direct, 2 * len(plan))
    full = np.zeros(len(prob.keep))
    full[prob.keep] = res.fun[:int(prob.keep.sum())]
    cal = rig.profile.calibration
    floor = OUTLIER_PERIOD_FRACTION * min(cal.periods) * cal.screen_pitch
    drop, sigma = outlying_rows(full, prob.keep, direct_rows, floor)
    outliers = int(drop.sum())
    if outliers and say:
        say(f"dropping {outliers} outlying residuals (> {OUTLIER_SIGMAS:g} robust sigmas and > {floor:.2f} mm: "
            "points decoded a period or a stripe away); refitting")
    prob.keep &= ~drop
    if sigma[True] > 0 and sigma[False] > 0:
        prob.direct_weight = float(np.clip(sigma[False] / sigma[True], 1.0, MAX_DIRECT_WEIGHT))
    if outliers or data.direct.any():
        res = least_squares(prob.fun, res.x, jac=prob.jac, method="trf", xtol=1e-10, ftol=1e-10,
                            max_nfev=MAX_ITERATIONS)
    cov_z = np.zeros((len(prob.scale), len(prob.scale)))
    cov_z[np.ix_(prob.free, prob.free)] = posterior_covariance(res.jac, res.fun, prob.prior / PRIOR_MM,
                                                               prob.clusters() if clustered else None)
    cov = cov_z * np.outer(prob.scale, prob.scale)
    se = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    rows = res.fun[:int(prob.keep.sum())]
    direct = direct_rows[prob.keep]
    rms = lambda r: float(np.sqrt(np.mean(r ** 2))) if r.size else math.nan  # noqa: E731
    return FitResult(prob.full(res.x) * prob.scale, M.parameter_names(len(plan)), se, np.nan_to_num(corr),
                     rms(rows[~direct]), int(len(rows)), outliers, prob.evaluations, cov, int(direct.sum()),
                     rms(rows[direct] / prob.direct_weight), prob.direct_weight, M.recovery_targets(rig, len(plan)))


def outlying_rows(full: np.ndarray, keep: np.ndarray, direct_rows: np.ndarray,
                  floor: float = 0.0) -> tuple[np.ndarray, dict]:
    """Rows (of ``keep``) beyond :data:`OUTLIER_SIGMAS` robust sigmas (1.4826 MAD) of their own path's
    and beyond ``floor`` (the units of ``full``: :data:`OUTLIER_PERIOD_FRACTION` of the finest period),
    and each path's sigma in the units of ``full`` ({True: the direct view's, False: the mirrors'};
    0 for a path with no rows)."""
    drop = np.zeros(len(full), bool)
    sigma = {}
    for direct in (True, False):
        rows = keep & (direct_rows == direct)
        r = full[rows]
        sigma[direct] = 1.4826 * float(np.median(np.abs(r - np.median(r)))) if r.size else 0.0
        drop[rows] = np.abs(r) > max(OUTLIER_SIGMAS * sigma[direct], floor, 1e-12)
    return drop, sigma
