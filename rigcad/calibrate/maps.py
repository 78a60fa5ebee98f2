"""From the fit to the maps: each camera pixel's measured ray (through its fitted dome point and its
decoded points on the fitted screens: :func:`pivot_rays`), the dome's residual slopes
(:mod:`rigcad.calibrate.fit`'s docstring) and the corrected pixel -> incidence map.

The corrected map at a measured pixel combines the measurement with the fitted model's prediction
by their uncertainties (a Wiener filter, per pixel): the measured residual (measured minus model
direction, smoothed by a normalised Gaussian over the decoded pixels, sigma :data:`SMOOTH_PX`) is
kept in the share S / (S + N), N its noise variance (the spread of the pixel's rays between the
captures that measured it: :func:`capture_spread`) and S the residual's own local power (its mean
square over :data:`SIGNAL_PX`, less N). Where the dome has a slope error, S >> N and the
measurement is kept; on a rig with none, the residual is the decoding's noise and the model is kept,
so calibrating a well-built rig does not make its map worse. Pixels with no measured neighbourhood
are filled from the residual (the same at :data:`FILL_PX`), beyond that reach the model alone.

Its uncertainty per pixel (rad, an RMS angle), from what the fit cannot see as well as what it
can: where measured, the frame's tilt (the sample plane's, which no image shows: its variance from
how the screen settles, :func:`rigcad.calibrate.model.frame_tilt_variance`), the combination's own
variance (1 - w)^2 S + w^2 N (w = S / (S + N), S taken two of its estimate's standard errors high),
and :data:`BIAS_RESIDUAL` of the turn the decoding's bias correction gave
the ray; where filled or model only, the fit's covariance carried through the model's direction and
the residual's mean square over the measured pixels (the surface there is not seen). Directions are
unit vectors from O towards the light (+z)."""

from __future__ import annotations

import math

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.raxel import to_global
from rigcad.check.figures import _angles as angle_between  # noqa: F401  (the one home of the angle between rows)

#: The smoothing of the measured residual (camera px): the sanding ripple's rings are ~7 px apart on
#: Table 3.1's camera, which sigma 1.5 px would attenuate to 40 %, sigma 0.6 to 87 %, 0.3 to 97 %.
#: The rays through the dome points carry little noise (a screen point's ~3 um over ~150 mm), so
#: the least smoothing: 0.6 px took the recovered slope RMS to 0.83 of the planted (seed 1).
SMOOTH_PX = 0.3
#: A height's decoded pixels within this many of one it did not decode (steps along rows and
#: columns: binary erosions) are not used at that height, here nor in the fit
#: (:func:`rigcad.calibrate.run._fit_data`): their footprints see the screen's or a shadow's edge in
#: part, which pulls the decoded point. Measured against the tracer (Table 3.1, seeds 101, 102, 105):
#: 3 px from the edge the upper screen's points lie ~70 um outward on average, 4 px and more within
#: 3 um; with 2 in the fit, those points pulled the fitted upper screen 15-23 um low (seeds 101-106).
HEIGHT_EDGE_PX = 3
#: The Wiener weight's signal power (:func:`corrected_map`): the smoothed residual's mean square over a
#: normalised Gaussian of this sigma (camera px), a few of the sanding ripple's ~7 px rings wide.
SIGNAL_PX = 3.0
#: The captures' spread (:func:`capture_spread`) smoothed over this sigma (camera px): two to eight
#: captures a pixel give a variance too rough to weigh by alone.
SPREAD_PX = 2.0
#: The share of the turn the decoding's bias correction (:mod:`rigcad.calibrate.bias`) gave a pixel's
#: ray that its uncertainty keeps as the correction's residual. The correction is a model: on the
#: true rays it reproduces the decoded points to about a fifth of the bias (6-7 um of 30-37 um,
#: bias.py), and it is built on the measured map, not the true one; half is taken. A stated
#: assumption, not a fit: the bench measures the coverage it gives (bench/results/calibrate.json).
BIAS_RESIDUAL = 0.5
#: Measured pixels within this many of an unmeasured one are filled, not measured.
EDGE_PX = 1
FILL_PX = 6.0
#: A pixel counts as measured when the smoothing's weight there is at least this (of a fully
#: decoded neighbourhood); as filled when the fill's weight is.
MEASURED_WEIGHT = 0.5
FILLED_WEIGHT = 0.02


def away_from_edges(valid: np.ndarray, other_path: np.ndarray | None = None, steps: int = HEIGHT_EDGE_PX) -> np.ndarray:
    """(n,) the decoded pixels of one height (``valid`` (rows, cols)) at least :data:`HEIGHT_EDGE_PX`
    steps along rows and columns from any it did not decode: the ones the rays and the fit read.
    ``other_path`` ((n,) bool): pixels that see the screen along the other path (directly past the
    paraboloid, or off the mirrors: :func:`rigcad.calibrate.model.direct_view`) count as not
    decoded. Where the two meet at the paraboloid's rim, a pixel's footprint and the blur mix both
    views, as at a screen's edge: with a thin screen and a coarse period such pixels decode."""
    from scipy.ndimage import binary_erosion

    if other_path is not None:
        valid = valid & ~other_path.reshape(valid.shape)
    return binary_erosion(valid, iterations=steps).ravel() if steps else valid.ravel()


def pivot_rays(decoded: list, poses: list, model_tr: M.Traced, shape: tuple[int, int],
               steps: list[int] | None = None) -> np.ndarray:
    """Unit directions (n, 3), up, of each window pixel's ray through the fitted model's dome point
    and its decoded screen points: per height, from the screen point to the dome point, averaged
    over the heights that decoded the pixel away from their edges (NaN where none did).

    The residual is a tilt of the dome's normal (module docstring): it turns the ray about its dome
    point, which it does not move. So each screen point fixes the direction over the ~120-230 mm from
    the dome, not over the spacers' gap (8 mm): the decoded points' bias (~10-40 um) costs ~0.1-0.3
    mrad, not ~1-5. What the direction inherits instead is the fitted model's dome point, off the
    true ray by the fit's error (0.01-0.05 mm median on seeds 101-106 with 1/20 mm spacers: ~0.1-0.35
    mrad over the lever, smooth across the pixels), and a paraboloid slope error, which moves the
    dome point, is read as a dome tilt there. A pixel seen at one height (grazing rays past the
    upper screen's edge) is measured too. ``steps``: per capture, the edge rule's reach
    (:func:`away_from_edges`; :data:`HEIGHT_EDGE_PX` each by default)."""
    total = np.zeros((int(np.prod(shape)), 3))
    for inner, to_dome in _capture_rays(decoded, poses, model_tr, steps):
        total += np.where(inner[:, None], np.nan_to_num(to_dome), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / np.linalg.norm(total, axis=1)[:, None]


def _capture_rays(decoded: list, poses: list, model_tr: M.Traced, steps: list[int] | None):
    """Per capture: which pixels it measures (away from its edges, the model's ray lit) and their
    unit directions (n, 3), up, from its decoded screen points to the model's dome points."""
    for k, (d, pose) in enumerate(zip(decoded, poses)):
        inner = away_from_edges(d.valid, model_tr.direct, HEIGHT_EDGE_PX if steps is None else steps[k]) & model_tr.ok
        to_dome = model_tr.p2 - to_global(pose, d.u, d.v).reshape(-1, 3)
        with np.errstate(invalid="ignore", divide="ignore"):
            to_dome /= np.linalg.norm(to_dome, axis=1)[:, None]
        yield inner, to_dome


def capture_spread(decoded: list, poses: list, model_tr: M.Traced, shape: tuple[int, int],
                   steps: list[int] | None = None) -> np.ndarray:
    """(n,) the noise variance (rad^2, of the angle) of each pixel's measured direction
    (:func:`pivot_rays`, the mean over its captures): the squared spread of the captures' directions
    about their mean over (count - 1) count, smoothed over the pixels two or more captures measured
    (normalised Gaussian, :data:`SPREAD_PX`), so a pixel one capture measured takes its neighbours'.
    A dome slope error turns a ray about its dome point alike in every capture, so it does not add
    to the spread; the decoding's noise and bias, which differ between captures, do. 0 where no
    neighbour had two captures."""
    n = int(np.prod(shape))
    total, square, count = np.zeros((n, 3)), np.zeros(n), np.zeros(n)
    for inner, to_dome in _capture_rays(decoded, poses, model_tr, steps):
        d = np.where(inner[:, None], np.nan_to_num(to_dome), 0.0)
        total += d
        square += np.sum(d * d, axis=1)
        count += inner
    with np.errstate(invalid="ignore", divide="ignore"):
        spread = (square - np.sum(total * total, axis=1) / count) / ((count - 1) * count)
    two = count >= 2
    smooth, _ = _smooth(np.where(two, spread, 0.0)[:, None], two, shape, SPREAD_PX)
    return np.nan_to_num(np.maximum(smooth[:, 0], 0.0))


#: Why a pixel the fitted model lights (its ray reaches the sample) has no measured direction: the
#: first of these that applies (:func:`unmeasured_causes`; code = index, -1 where the model's ray is lost).
CAUSES = ("measured", "under_the_screens", "dark_in_every_capture", "lit_not_decoded",
          "within_the_edge_rule", "next_to_unmeasured")
CAUSE_NOTES = {
    "measured": "a measured direction (the corrected map's source 1)",
    "under_the_screens": "the fitted model's dome point lies below the lowest flat screen's surface: the ray passes "
                         "under every flat screen (a screen surface nearer the sample plane, or the upright display, "
                         "reaches it)",
    "dark_in_every_capture": "no capture lit the pixel: its ray meets the screens past their edges, or a shadow",
    "lit_not_decoded": "lit, but no height decoded it: too little modulation (a footprint too long for the "
                       "coarsest period) or a failed unwrapping check",
    "within_the_edge_rule": f"decoded, but within {HEIGHT_EDGE_PX} pixels of an undecoded one at every height that "
                            "decoded it (a screen's or a shadow's edge pulls its point)",
    "next_to_unmeasured": "a ray was measured, but the map fills the pixel from its neighbours: it borders an "
                          "unmeasured one, or too few measured neighbours surround it",
}


def unmeasured_causes(decoded: list, poses: list, model_tr: M.Traced, source: np.ndarray,
                      steps: list[int] | None = None) -> np.ndarray:
    """(n,) int8 index into :data:`CAUSES` per window pixel (-1 where the fitted model's ray is lost):
    from the captures' lit and decoded masks, the rays' edge rule (:func:`away_from_edges`), the
    corrected map's ``source`` and the fitted model's dome points against the lowest of ``poses``
    (the flat screens'). ``steps``: per capture of ``decoded``, the edge rule's reach."""
    lowest = min(poses, key=lambda pose: float(pose.translation[2]))
    q, _ = lowest.localize(np.nan_to_num(model_tr.p2), np.zeros_like(model_tr.p2))
    lit = np.any([d.lit.ravel() for d in decoded], axis=0)
    valid = np.any([d.valid.ravel() for d in decoded], axis=0)
    reach = [HEIGHT_EDGE_PX] * len(decoded) if steps is None else steps
    inner = np.any([away_from_edges(d.valid, model_tr.direct, r) for d, r in zip(decoded, reach)], axis=0)
    checks = (source == 1, q[:, 2] < 0, ~lit, ~valid, ~inner)
    out = np.full(len(source), len(CAUSES) - 1, dtype=np.int8)
    for code in range(len(checks) - 1, -1, -1):  # the first cause that applies wins
        out[checks[code]] = code
    return np.where(model_tr.ok, out, -1).astype(np.int8)


def cause_fractions(causes: np.ndarray) -> dict:
    """Each cause's share of the pixels the fitted model lights (:func:`unmeasured_causes`)."""
    lit = causes >= 0
    n = max(int(lit.sum()), 1)
    return {name: float(np.sum(causes == code)) / n for code, name in enumerate(CAUSES)}


def residual_slopes(tr: M.Traced, measured: np.ndarray) -> np.ndarray:
    """grad_s h (n, 3) rad at the model rays' dome points from the measured directions (up)."""
    n = tr.v - tr.u
    n /= np.linalg.norm(n, axis=1)[:, None]
    dv = -measured - tr.v
    dv_t = dv - np.sum(dv * n, axis=1)[:, None] * n
    return dv_t / (2 * np.sum(tr.u * n, axis=1))[:, None]


def _smooth(values: np.ndarray, weight: np.ndarray, shape: tuple[int, int], sigma: float):
    from scipy.ndimage import gaussian_filter

    w = gaussian_filter(weight.reshape(shape).astype(float), sigma)
    out = np.stack([gaussian_filter(np.where(weight, values[:, k], 0.0).reshape(shape), sigma)
                    for k in range(values.shape[1])], axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (out / w[..., None]).reshape(-1, values.shape[1]), w.ravel()


def direction_jacobian(optics, rig, cam: M.Camera, theta: np.ndarray) -> np.ndarray:
    """d(model direction)/d(rig parameter) (n, 3, 15) over the window, forward differences."""
    from rigcad.calibrate.fit import JAC_STEP

    scale = M.tolerance_scale(rig, 0)
    base = -M.trace_camera(optics, M.moved(rig, theta), cam.x_px, cam.y_px, cam.design).v
    out = np.empty(base.shape + (len(M.RIG_NAMES),))
    for i in range(len(M.RIG_NAMES)):
        t = theta.copy()
        t[i] += JAC_STEP * scale[i]
        out[:, :, i] = (-M.trace_camera(optics, M.moved(rig, t), cam.x_px, cam.y_px, cam.design).v - base) / (
            JAC_STEP * scale[i])
    return out


def corrected_map(model_tr: M.Traced, measured: np.ndarray, shape: tuple[int, int], dir_jac: np.ndarray,
                  cov_rig: np.ndarray, short: np.ndarray | None = None, spread: np.ndarray | None = None,
                  frame_variance: float = 0.0, bias_turn: np.ndarray | None = None) -> dict:
    """The corrected map (module docstring): ``direction`` (n, 3), ``uncertainty_rad`` (n,),
    ``source`` (n,: 0 none, 1 measured, 2 filled, 3 model only), ``measurement_weight`` (n,: the
    share of the measured residual kept, 0 where not measured). ``short`` (n,) bool: pixels
    measured where their footprints are short (the upright display's,
    :mod:`rigcad.calibrate.upright`), which :data:`EDGE_PX` does not fill. ``spread`` (n,): the
    measured directions' noise variance (rad^2, :func:`capture_spread`; None: the measurement kept
    whole, with no noise stated). ``frame_variance``: the frame's tilt per axis (rad^2,
    :func:`rigcad.calibrate.model.frame_tilt_variance`). ``bias_turn`` (n,): the angle (rad) the
    decoding's bias correction turned each pixel's ray (:func:`bias_turns`)."""
    from scipy.ndimage import binary_erosion

    model = -model_tr.v
    seen = np.all(np.isfinite(measured), axis=1) & model_tr.ok
    # a pixel next to an undecoded one sees the screen's or a shadow's edge in part of its footprint
    # (its decoded point is pulled towards the lit part): filled from the inner ones instead, but
    # where its footprint is short
    if EDGE_PX:
        kept = seen & short if short is not None else np.zeros_like(seen)
        seen = (seen & binary_erosion(seen.reshape(shape), iterations=EDGE_PX).ravel()) | kept
    resid = np.where(seen[:, None], measured - model, 0.0)
    sm, w1 = _smooth(resid, seen, shape, SMOOTH_PX)
    fill, w2 = _smooth(resid, seen, shape, FILL_PX)
    measured_px = model_tr.ok & (w1 >= MEASURED_WEIGHT)
    filled_px = model_tr.ok & ~measured_px & (w2 >= FILLED_WEIGHT)
    sm = np.nan_to_num(sm)
    # the Wiener weight: the smoothed residual's noise (the captures' spread over the smoothing's
    # effective pixel count) against its own local power less that noise
    n_eff = max(4 * np.pi * SMOOTH_PX ** 2, 1.0)  # the Gaussian's effective pixel count (at least the pixel)
    noise = np.zeros(len(model)) if spread is None else spread / n_eff
    power, _ = _smooth(np.sum(sm * sm, axis=1)[:, None], measured_px, shape, SIGNAL_PX)
    signal = np.maximum(np.nan_to_num(power[:, 0]) - noise, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        weight = np.where(noise > 0, signal / (signal + noise), 1.0)
    weight = np.where(measured_px, np.nan_to_num(weight), 0.0)
    delta = np.where(measured_px[:, None], weight[:, None] * sm, np.where(filled_px[:, None], np.nan_to_num(fill), 0.0))
    d = model + delta
    d /= np.linalg.norm(d, axis=1)[:, None]
    # measured: the frame (a common turn of the rays, which no image shows) + the combination's own
    # variance + the bias correction's residual; the fit's covariance moves a measured ray only
    # through its dome point and the screens, that is through the frame (the rest is micrometres over
    # the ~150 mm lever)
    frame = frame_variance * (1 + model[:, 2] ** 2)  # a turn (a, b, 0), each ~ N(0, frame_variance): E|w x d|^2
    # the combination's error, (1 - w) signal + w noise: the signal's variance taken at its estimate
    # plus two of the estimate's standard errors (a mean square over ~4 pi SIGNAL_PX^2 pixels of
    # noise: sqrt(2 / count) of it), so a pixel whose residual reads as pure noise (w = 0) still
    # states the signal it might hide
    count = 4 * np.pi * SIGNAL_PX ** 2
    signal_high = signal + 2 * noise * math.sqrt(2 / count)
    combined = (1 - weight) ** 2 * signal_high + weight ** 2 * noise
    bias = 0.0 if bias_turn is None else (BIAS_RESIDUAL * np.nan_to_num(bias_turn)) ** 2
    var_measured = frame + combined + bias
    var_model = np.einsum("nki,ij,nkj->n", np.nan_to_num(dir_jac), cov_rig, np.nan_to_num(dir_jac))
    surface_rms2 = float(np.mean(np.sum(resid[seen] ** 2, axis=1))) if seen.any() else 0.0
    var = np.where(measured_px, var_measured, var_model + surface_rms2)
    source = np.where(measured_px, 1, np.where(filled_px, 2, np.where(model_tr.ok, 3, 0)))
    return {"direction": np.where(model_tr.ok[:, None], d, np.nan), "uncertainty_rad": np.where(
        model_tr.ok, np.sqrt(var), np.nan), "source": source.astype(np.int8), "measurement_weight": weight}


def bias_turns(bias: np.ndarray, poses: list, model_tr: M.Traced) -> np.ndarray:
    """(n,) the angle (rad) the decoding's bias correction (``bias``: (n, captures, 2) mm,
    :func:`rigcad.calibrate.bias.map_bias`) turned each pixel's ray about its dome point: each
    capture's shift over the ray's reach from the dome to that screen, averaged over the captures
    that have one (0 where none)."""
    turns, count = np.zeros(len(bias)), np.zeros(len(bias))
    for k, pose in enumerate(poses):
        reach = np.linalg.norm(np.nan_to_num(model_tr.p2) - pose.translation, axis=1)
        shift = np.linalg.norm(bias[:, k], axis=1)
        ok = np.isfinite(shift) & (reach > 0)
        turns += np.where(ok, np.nan_to_num(shift) / np.where(reach > 0, reach, 1.0), 0.0)
        count += ok
    return np.where(count > 0, turns / np.maximum(count, 1), 0.0)
