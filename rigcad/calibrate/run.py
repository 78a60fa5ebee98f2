"""The calibration's stages on captured (or simulated) images: decode each capture, fit the
misalignment, the measured rays on the fitted screens, the dome's residual slopes, the corrected map;
and, for a simulation, the comparison with what was planted."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

import dataclasses

from rigcad.calibrate import bias as B, maps, model as M, upright as U
from rigcad.calibrate.decode import decode
from rigcad.calibrate.fit import (DIRECT_STRIDE, SLOPE_PROJECTION, FitData, against_dome, direct_ring_mm, fit,
                                  seen_direct)
from rigcad.calibrate.patterns import Sequence


#: The decoding's own bias (:mod:`rigcad.calibrate.bias`) is removed from the decoded points before
#: the fit: "map" (predicted from the measured map itself), or None (kept, for comparison).
DECODING_BIAS = "map"


@dataclass
class Calibration:
    """Everything one calibration computed (window arrays (n,) or (n, 3) row-major over ``cam.shape``)."""

    cam: M.Camera
    plan: M.Plan
    decoded: list
    fit: object
    map_fit: object
    model: M.Traced
    measured: np.ndarray
    slopes: np.ndarray
    corrected: dict
    design: np.ndarray
    #: per window pixel, why it has no measured direction (maps.unmeasured_causes)
    causes: np.ndarray
    timings_s: dict = field(default_factory=dict)
    #: the upright display's captures (rigcad.calibrate.upright): their plan, decodings and placements
    uprights: object = None
    upright_decoded: list = field(default_factory=list)
    placed: list = field(default_factory=list)

    def slope_figures(self) -> dict:
        """Residual slope RMS, p99 and worst (mrad) over the measured pixels. The slopes are read from
        the corrected map, which keeps a measured residual only in the share the noise allows
        (:func:`rigcad.calibrate.maps.corrected_map`): on a dome with no slope error they stay near
        0 rather than reading the decoding's noise, amplified near grazing, as slopes."""
        g = np.linalg.norm(self.slopes, axis=1)
        g = g[np.isfinite(g)]
        return {"residual_slope_rms_mrad": float(np.sqrt(np.mean(g ** 2)) * 1e3) if g.size else math.nan,
                "residual_slope_p99_mrad": float(np.percentile(g, 99) * 1e3) if g.size else math.nan,
                "residual_slope_worst_mrad": float(g.max() * 1e3) if g.size else math.nan,
                "pixels": int(g.size)}


def calibrate(optics, rig, images: list[dict[str, np.ndarray]], say=lambda msg: None, check=None,
              bias: str | None = DECODING_BIAS) -> Calibration:
    """Calibrate from ``images`` (per capture of :class:`model.Plan`, frame name -> full camera
    image as float, checked).
    ``check(decoded)``: called with the decoded captures before the fit (it raises to refuse them).
    ``bias``: how the decoding's own bias is removed (:data:`DECODING_BIAS`)."""
    cal = rig.profile.calibration
    seq = Sequence.from_profile(cal)
    cam = M.Camera.of(rig)
    plan = M.Plan.of(rig.profile)
    ups = U.Uprights.of(rig.profile)
    if len(images) != len(plan) + len(ups):
        raise ValueError(f"{len(images)} captures given, the plan has {len(plan) + len(ups)}: "
                         f"{', '.join(plan.labels + ups.labels)}")
    t0 = time.perf_counter()
    core = cam.mirrored_core(rig)
    decoded = [decode(seq if c < len(plan) else ups.seq, {n: cam.crop(im) for n, im in frames.items()},
                      cal.min_modulation, core) for c, frames in enumerate(images)]
    t1 = time.perf_counter()
    if check is not None:
        check(decoded)
    decoded, upright_decoded = decoded[:len(plan)], decoded[len(plan):]
    say(f"decoded {', '.join(str(d.stats()['decoded_pixels']) for d in decoded)} camera pixels per capture "
        f"({', '.join(plan.labels)})")
    applied = None
    if bias == "map":
        applied = B.map_bias(decoded, cam.shape, seq, cal.sim_blur)
        decoded = _unbiased(decoded, applied)
    data = _fit_data(cam, plan, decoded, cal.fit_stride)
    result = fit(optics, rig, cam, plan, data, say)
    result.dome_frame_covariance = M.in_dome_frame_covariance(rig, result.theta, result.covariance)
    say(f"fitted {len(result.theta)} parameters to {result.residuals_used} residuals (RMS off the mirrors "
        f"{result.rms_residual_mm * 1e3:.2f} um; {result.direct_residuals} of the screens seen directly, RMS "
        f"{result.direct_rms_residual_mm * 1e3:.2f} um)")
    # the map's rays turn about the model's dome points: refit with the surface's signature
    # down-weighted (fit.SLOPE_PROJECTION), from the plain fit. Its covariance, which the map's
    # uncertainty carries, stays the plain posterior: the bench measured its coverage (measured
    # pixels within 2 uncertainties: 99 %); the tiles' sandwich would state the rig's lateral offsets
    # and tilts looser still (median |error| / standard error 0.16-0.27 against 0.21-0.67, seeds
    # 200-209, where a Gaussian gives 0.67)
    for_map = fit(optics, rig, cam, plan, data, say, slope_projection=SLOPE_PROJECTION, start=result.theta,
                  clustered=False)
    t2 = time.perf_counter()
    poses = M.screens(plan, for_map.theta)
    fitted = M.moved(rig, for_map.theta)
    model_tr = M.trace_camera(optics, fitted, cam.x_px, cam.y_px, cam.design)
    measured = maps.pivot_rays(decoded, poses, model_tr, cam.shape)
    placed = [U.place(p0, U.placement_scale(rig.profile), d, model_tr, measured, cam.shape)
              for p0, d in zip(ups.nominal, upright_decoded)]
    on = [k for k, pl in enumerate(placed) if pl.placed]
    captures = decoded + [upright_decoded[k] for k in on]
    where = poses + (ups.poses(np.array([placed[k].placement for k in on]).reshape(-1, 6)) if on else [])
    steps = [maps.HEIGHT_EDGE_PX] * len(plan) + [U.EDGE_PX] * len(on)
    short = None
    if on:  # each placed upright capture's rays join the flat ones'
        short = np.any([maps.away_from_edges(upright_decoded[k].valid, model_tr.direct, U.EDGE_PX) for k in on],
                       axis=0) & model_tr.ok
        measured = maps.pivot_rays(captures, where, model_tr, cam.shape, steps)
    n_rig = len(M.RIG_NAMES)
    jac = maps.direction_jacobian(optics, rig, cam, for_map.theta)
    spread = maps.capture_spread(captures, where, model_tr, cam.shape, steps)
    frame = _frame_variance(rig, plan, say)
    corrected = maps.corrected_map(model_tr, measured, cam.shape, jac, for_map.covariance[:n_rig, :n_rig], short,
                                   spread, frame, None if applied is None else maps.bias_turns(applied, poses, model_tr))
    # the slopes from the smoothed measurement (the raw rays' noise, divided by 2 cos of the dome's
    # angle of incidence, would swamp them), where measured
    seen = (corrected["source"] == 1)[:, None]
    slopes = np.where(seen, maps.residual_slopes(model_tr, np.where(seen, corrected["direction"], np.nan)), np.nan)
    causes = maps.unmeasured_causes(decoded + upright_decoded, poses, model_tr, corrected["source"],
                                    [maps.HEIGHT_EDGE_PX] * len(plan) + [U.EDGE_PX] * len(upright_decoded))
    t3 = time.perf_counter()
    from rigcad.check.sources import pixel_rays

    design = cam.design.direction(pixel_rays(cam.design, cam.x_px, cam.y_px).dirs)
    return Calibration(cam, plan, decoded, result, for_map, model_tr, measured, slopes, corrected, design, causes,
                       {"decode_s": t1 - t0, "fit_s": t2 - t1, "maps_s": t3 - t2}, ups, upright_decoded, placed)


def _frame_variance(rig, plan: M.Plan, say) -> float:
    """The map's frame's tilt variance per axis (rad^2, :func:`rigcad.calibrate.model.frame_tilt_variance`),
    said: what it rests on, and with no half turn, that one would tie it to the seating."""
    frame = M.frame_tilt_variance(rig.profile, plan)
    say(f"the map's frame, the sample plane's tilt that no image shows, is known to "
        f"{math.degrees(math.sqrt(2 * frame)):.4f} deg RMS from how the screen lies on its spacers"
        + (" (calibration.screen_seating: each half turn cancels the spacer's wedge); every measured pixel's "
           "uncertainty includes it" if plan.repeats(len(plan) - 1) is not None else
           " (calibration.screen_tilt, the wedge: a half turn at each spacer, calibration.half_turn: every, would "
           "tie it to screen_seating instead); every measured pixel's uncertainty includes it"))
    return frame


def _unbiased(decoded: list, bias: np.ndarray) -> list:
    """The decoded points minus the decoding's bias (n, captures, 2) mm (unchanged where it is NaN)."""
    out = []
    for k, d in enumerate(decoded):
        du, dv = (np.nan_to_num(bias[:, k, a]).reshape(d.u.shape) for a in range(2))
        out.append(dataclasses.replace(d, u=d.u - du, v=d.v - dv))
    return out


def _fit_data(cam: M.Camera, plan: M.Plan, decoded: list, stride: int) -> FitData:
    """Every ``stride``-th row and column of the window that decoded in every capture."""
    rows, cols = np.meshgrid(np.arange(cam.shape[0]), np.arange(cam.shape[1]), indexing="ij")
    pick = ((rows % stride == 0) & (cols % stride == 0)).ravel()
    # pixels near an undecoded one see a screen edge or a shadow's edge in part of their footprint,
    # and pixels near the other path's (read from the points: fit.seen_direct) both views: the same
    # rule as the map's rays (maps.away_from_edges, maps.HEIGHT_EDGE_PX)
    every = np.nonzero(np.all([d.valid.ravel() for d in decoded], axis=0))[0]
    direct = np.zeros(rows.size, bool)
    direct[every] = seen_direct(plan, _points(decoded, every), direct_ring_mm(cam.design))
    inner = [np.where(direct, maps.away_from_edges(d.valid, ~direct), maps.away_from_edges(d.valid, direct))
             for d in decoded]
    ok = pick & np.all(inner, axis=0)
    idx = np.nonzero(ok)[0]
    coarse = stride * DIRECT_STRIDE  # the direct view's pixels: a coarser grid
    idx = idx[~direct[idx] | ((rows.ravel()[idx] % coarse == 0) & (cols.ravel()[idx] % coarse == 0))]
    return FitData(idx, _points(decoded, idx), direct[idx])


def _points(decoded: list, idx: np.ndarray) -> np.ndarray:
    """The decoded screen points (n, captures, 2) mm of window pixels ``idx``."""
    return np.stack([np.stack([d.u.ravel()[idx], d.v.ravel()[idx]], axis=-1) for d in decoded], axis=1)


def compare(optics, rig, result: Calibration, theta_true: np.ndarray, surface,
            placement: np.ndarray | None = None) -> dict:
    """A simulation's figures against what was planted: each parameter's error against its
    tolerance, and the paraboloid's and the camera's against the dome (``dome_frame``), the corrected
    and the design (uncorrected) map's incidence error (deg, p99 and more over the lit pixels), the
    residual slopes against the planted ones (mrad); with the upright captures' true ``placement``,
    their fitted placements' errors."""
    from rigcad.calibrate.simulate import surface_slopes, with_surface

    cam = result.cam
    true_rig = M.moved(rig, theta_true)
    base = M.trace_camera(optics, true_rig, cam.x_px, cam.y_px, cam.design)
    truth = with_surface(true_rig, surface, base)
    lit = truth.ok & np.isfinite(result.design[:, 0]) & np.isfinite(result.corrected["direction"][:, 0])
    up = -truth.v
    err_c = np.degrees(maps.angle_between(result.corrected["direction"][lit], up[lit]))
    err_d = np.degrees(maps.angle_between(result.design[lit], up[lit]))
    err_m = np.degrees(maps.angle_between(-result.model.v[lit], up[lit]))  # the fitted model alone
    planted = surface_slopes(true_rig, surface, base)
    seen = np.isfinite(result.slopes[:, 0]) & np.isfinite(planted[:, 0])
    g_p, g_r = planted[seen], result.slopes[seen]
    rms = lambda a: float(np.sqrt(np.mean(np.sum(a * a, axis=1))) * 1e3) if len(a) else math.nan  # noqa: E731
    names = M.parameter_names(len(result.plan))
    target = M.recovery_targets(rig, len(result.plan))
    in_dome = [names.index(n) for n in M.DOME_FRAME_NAMES]
    dome_fitted, dome_se = against_dome(rig, result.fit)
    dome_frame = _against(M.DOME_FRAME_NAMES, M.in_dome_frame(rig, theta_true), dome_fitted, target[in_dome], dome_se)
    return {
        **_against(names, theta_true, result.fit.theta, target, result.fit.standard_error),
        "dome_frame": {"about": "the paraboloid's and the camera's placement against the dome (model.in_dome_frame): "
                                "what the images fix apart from the frame's tilt", **dome_frame},
        "lit_pixels": int(lit.sum()),
        "corrected_incidence_error_deg": _stats(err_c), "design_incidence_error_deg": _stats(err_d),
        "fitted_model_incidence_error_deg": _stats(err_m),
        "corrected_incidence_error_deg_by_source": {
            name: _stats(err_c[result.corrected["source"][lit] == code])
            for code, name in ((1, "measured"), (2, "filled"), (3, "model_only"))},
        "unmeasured_causes": {name: {"fraction_of_lit": float(np.mean(result.causes[lit] == code)),
                                     **_stats(err_c[result.causes[lit] == code])}
                              for code, name in enumerate(maps.CAUSES)},
        "uncertainty_coverage": _coverage(err_c, result.corrected, lit),
        "frame": _frame(result.corrected, up, lit),
        "slope_pixels": int(seen.sum()), "planted_slope_rms_mrad": rms(g_p), "recovered_slope_rms_mrad": rms(g_r),
        "slope_difference_rms_mrad": rms(g_r - g_p),
        **({} if placement is None or not len(placement) else
           {"upright_placement": _placement_errors(result, placement)}),
    }


def _placement_errors(result: Calibration, placement: np.ndarray) -> dict:
    """The upright captures' fitted placements against the planted ones: the largest error over the
    captures of each parameter (mm, or rad for the tilts and the turn), NaN for an unplaced capture."""
    err = np.array([pl.placement for pl in result.placed]) - placement
    return {"about": "largest |fitted - planted| over the upright captures, per placement parameter",
            **{k: float(np.max(np.abs(err[:, i]))) for i, k in enumerate(M.SCREEN_KEYS)},
            "captures": len(result.placed), "captures_placed": int(sum(pl.placed for pl in result.placed))}


def _against(names, planted: np.ndarray, fitted: np.ndarray, target: np.ndarray, se: np.ndarray) -> dict:
    """Each named parameter's fitted value against the planted one, its target and its standard error."""
    err = fitted - planted
    z = np.abs(err) / np.maximum(se, 1e-300)
    return {"parameters": {n: {"planted": float(t), "fitted": float(f), "error": float(e), "target": float(g),
                               "met": bool(abs(e) <= g), "error_over_standard_error": float(zz)}
                           for n, t, f, e, g, zz in zip(names, planted, fitted, err, target, z)},
            "parameters_met": int(np.sum(np.abs(err) <= target)), "parameters_total": len(names)}


def _frame(corrected: dict, up: np.ndarray, lit: np.ndarray) -> dict:
    """The corrected map's frame against the truth's: the small rotation (rad vector w, d - up = w x
    up, least squares over the measured pixels) that best takes the true directions to the map's,
    as its tilt (the x and y parts) and turn (z), and the measured pixels' error once it is removed:
    what the images fix (the map's shape) apart from what only the priors fix (the tilt of the
    sample plane, which no image shows: ``calibration.screen_tilt``)."""
    m = lit & (corrected["source"] == 1)
    if not m.any():
        return {"pixels": 0}
    u, e = up[m], corrected["direction"][m] - up[m]
    z = np.zeros(len(u))
    a = np.stack([np.stack([z, u[:, 2], -u[:, 1]], 1), np.stack([-u[:, 2], z, u[:, 0]], 1),
                  np.stack([u[:, 1], -u[:, 0], z], 1)], axis=1)  # (n, 3 rows of w x u, 3)
    w = np.linalg.lstsq(a.reshape(-1, 3), e.ravel(), rcond=None)[0]
    rest = np.degrees(np.linalg.norm(e - a @ w, axis=1))
    return {"pixels": int(m.sum()), "tilt_deg": math.degrees(math.hypot(w[0], w[1])), "turn_deg": math.degrees(w[2]),
            "measured_error_without_it_deg": _stats(rest)}


def _coverage(err_deg: np.ndarray, corrected: dict, lit: np.ndarray) -> dict:
    """Per map source, how the stated uncertainty covers the error against the truth: the share
    of pixels within one and two of their uncertainties, and the median error over uncertainty
    (a calibrated RMS angle: ~63 %, ~98 %, ~0.83 for a round Gaussian error)."""
    ratio = np.radians(err_deg) / corrected["uncertainty_rad"][lit]
    out = {}
    for code, name in ((1, "measured"), (2, "filled"), (3, "model_only")):
        r = ratio[corrected["source"][lit] == code]
        out[name] = {"pixels": int(r.size)} if not r.size else {
            "pixels": int(r.size), "within_1": float(np.mean(r <= 1)), "within_2": float(np.mean(r <= 2)),
            "error_over_uncertainty_p50": float(np.median(r))}
    return out


def truth_maps(optics, rig, result: Calibration, theta_true: np.ndarray, surface, placement=None) -> dict:
    """Per window pixel, for a simulation's pictures: the planted slope magnitude (mrad, where the
    calibration measured slopes) and both maps' incidence errors (deg). (``placement``, the upright
    captures', changes none of them.)"""
    from rigcad.calibrate.simulate import surface_slopes, with_surface

    cam = result.cam
    true_rig = M.moved(rig, theta_true)
    base = M.trace_camera(optics, true_rig, cam.x_px, cam.y_px, cam.design)
    up = -with_surface(true_rig, surface, base).v
    planted = np.linalg.norm(surface_slopes(true_rig, surface, base), axis=1) * 1e3
    return {"planted_slope_mrad": np.where(np.isfinite(result.slopes[:, 0]), planted, np.nan),
            "corrected_error_deg": np.degrees(maps.angle_between(result.corrected["direction"], up)),
            "design_error_deg": np.degrees(maps.angle_between(result.design, up))}


def _stats(e: np.ndarray) -> dict:
    if not e.size:
        return {"pixels": 0}
    return {"pixels": int(e.size), "p50": float(np.percentile(e, 50)), "p99": float(np.percentile(e, 99)), "max": float(e.max()),
            "rms": float(np.sqrt(np.mean(e ** 2)))}
