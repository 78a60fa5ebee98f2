"""How the screen settles when it is laid again on its spacer, measured from two or more
calibrations of one rig (``rigcad calibrate PROFILE --seating A.json B.json ...``; docs/calibrate.md,
"Measuring the seating").

With the half turns, the map's frame (the sample plane's tilt under the rig) is known to the
seating, ``calibration.screen_seating``, and no image shows it. This measures it. Each
calibration.json gives every flat capture's screen tilt against the dome (``against_the_dome``
``screens``: :func:`rigcad.calibrate.model.screens_in_dome_frame`). With the rig left as it is
between the calibrations and the screen laid anew for each, one label (``h<k>``, ``h<k>r``) is the
same spacer in the same turn, hence the same wedge: its tilts differ by how the screen settled,
and by the fit's noise between calibrations. Per axis, the spread about each label's mean, pooled
over labels and axes (``2 L (N - 1)`` degrees of freedom for L labels in N calibrations), is the
seating per axis, with a 95 % interval from the chi-squared distribution. The fit's noise is left
in it, so it errs high, the safe side: the fit's standard errors are not taken out, because most of
them is common to every calibration of one rig (the dome's figure steering its tilt) and cancels in
the spread. docs/calibrate.md has the one-off figures.

The profile's ``screen_seating`` is a bound: the simulation (rigcad.calibrate.simulate) lays each
screen with a tilt uniform in size within it, in any direction, whose spread per axis is
``screen_seating / sqrt 6``. The value to state is therefore ``sqrt 6`` times the interval's upper
end."""

from __future__ import annotations

import math

import numpy as np

from rigcad.calibrate.images import CaptureError
from rigcad.export.readback import names as listed, quoted

#: The largest figure a calibration.json states against the dome: a tilt (deg) or an offset (mm), and
#: its standard error. A screen or part tilted 90 deg, or off by a metre, is no rig's.
MAX_ANGLE_DEG = 90.0
MAX_OFFSET_MM = 1000.0

#: Two calibrations whose paraboloid or camera against the dome differ by more than this many
#: combined standard errors were not of one rig left as it is.
MOVED_SIGMAS = 5.0
#: The simulation's seating (uniform in size within the bound, any direction): bound / per-axis spread.
BOUND_OVER_SPREAD = math.sqrt(6.0)


def measure(runs: list[tuple[str, dict]], profile) -> dict:
    """``runs``: (name, calibration.json's content) of two or more calibrations of one rig, the
    screen laid anew for each; the seating they measure (module docstring), against ``profile``'s."""
    from scipy.stats import chi2

    from rigcad.calibrate.model import Plan

    if len(runs) < 2:
        raise CaptureError("--seating: give two or more calibration.json of one rig, left as it is, the screen "
                           f"laid anew for each (got {len(runs)})")
    labels = Plan.of(profile).labels
    read = [_figures(name, r, labels) for name, r in runs]
    _check_unmoved([name for name, _ in runs], [parts for _, _, parts in read])
    tilts, se = np.array([t for t, _, _ in read]), np.array([e for _, e, _ in read])  # (N, L, 2) deg
    dev = tilts - tilts.mean(axis=0)
    dof = 2 * len(labels) * (len(runs) - 1)
    spread2 = float(np.sum(dev ** 2) / dof)
    per_axis = [math.sqrt(spread2 * dof / v) for v in (dof, chi2.ppf(0.975, dof), chi2.ppf(0.025, dof))]
    stated = math.degrees(profile.calibration.screen_seating)
    suggested = BOUND_OVER_SPREAD * per_axis[2]
    return {"calibrations": [name for name, _ in runs], "labels": list(labels), "degrees_of_freedom": dof,
            "fit_standard_error_per_axis_deg": math.sqrt(float(np.mean(se ** 2))),
            "seating_per_axis_deg": per_axis[0], "seating_per_axis_95_deg": per_axis[1:],
            "largest_deviation_deg": float(np.max(np.linalg.norm(dev, axis=2))),
            "screen_seating_stated_deg": stated, "screen_seating_measured_deg": suggested,
            "verdict": _verdict(stated, BOUND_OVER_SPREAD * per_axis[1], suggested)}


def _verdict(stated: float, low: float, high: float) -> str:
    if stated < low:
        return (f"the profile's screen_seating ({stated:.4g} deg) is tighter than this seat settles (at least "
                f"{low:.4g} deg): the map's frame would be stated tighter than it is; set {high:.2g} deg")
    if stated < high:
        return (f"the profile's screen_seating ({stated:.4g} deg) is within this measurement's interval "
                f"({low:.4g}-{high:.4g} deg); {high:.2g} deg is the safe value")
    return (f"the profile's screen_seating ({stated:.4g} deg) covers this seat (at most {high:.4g} deg): "
            f"stating {high:.2g} deg would tighten the map's frame to what the seat does")


def line(result: dict) -> str:
    """One line of ``measure``'s result."""
    lo, hi = result["seating_per_axis_95_deg"]
    return (f"seating from {len(result['calibrations'])} calibrations ({len(result['labels'])} captures each, "
            f"{result['degrees_of_freedom']} degrees of freedom): {result['seating_per_axis_deg']:.4f} deg per axis "
            f"(95 %: {lo:.4f}-{hi:.4f}; the fit's noise left in), "
            f"screen_seating {result['screen_seating_measured_deg']:.4f} deg; {result['verdict']}")


def _figures(name: str, report, labels: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray, dict]:
    """One calibration.json's screen tilts against the dome and their standard errors ((labels, 2)
    deg, in ``labels``' order) and its parts against the dome (name -> (value, standard error));
    refuses, naming the file and the key, one that cannot measure the seating."""
    def pair(key: str, entry) -> tuple[float, float]:
        value, se = (entry.get(k) if isinstance(entry, dict) else None for k in ("value", "standard_error"))
        unit, bound = ("deg", MAX_ANGLE_DEG) if key.endswith("_deg") else ("mm", MAX_OFFSET_MM)
        for k, v in (("value", value), ("standard_error", se)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or (k != "value" and v < 0):
                raise CaptureError(f"{name}: {key}.{k} is {quoted(v)}, not a finite number"
                                   f"{' of 0 or more' if k != 'value' else ''}: not a calibration.json rigcad wrote")
            if abs(v) > bound:
                raise CaptureError(f"{name}: {key}.{k} is {v:.4g}, outside {'-' if k == 'value' else ''}{bound:g}.."
                                   f"{bound:g} {unit}: not a calibration.json rigcad wrote")
        return float(value), float(se)

    dome = report.get("against_the_dome") if isinstance(report, dict) else None
    screens, parts = (dome.get(k) if isinstance(dome, dict) else None for k in ("screens", "parameters"))
    if not isinstance(screens, dict) or not isinstance(parts, dict):
        raise CaptureError(f"{name}: no screen tilts against the dome (against_the_dome.screens): not a "
                           "calibration.json, or one an earlier rigcad wrote; calibrate that capture again")
    if set(screens) != set(labels):
        raise CaptureError(f"{name}: captures {listed(screens)}, the profile plans {listed(labels)} "
                           "(calibration.spacer_heights, calibration.half_turn): calibrated with another profile")
    tilts = np.array([[pair(f"against_the_dome.screens.{k}.tilt_{a}_deg",
                            screens[k].get(f"tilt_{a}_deg") if isinstance(screens[k], dict) else None)
                       for a in "xy"] for k in labels])  # (labels, 2 axes, value and standard error)
    return tilts[..., 0], tilts[..., 1], {k: pair(f"against_the_dome.parameters.{k}", v) for k, v in parts.items()}


def _check_unmoved(names: list[str], parts: list[dict]) -> None:
    """Refuses two runs whose paraboloid or camera against the dome differ by more than
    :data:`MOVED_SIGMAS` combined standard errors: the rig moved between them."""
    for name, other in zip(names[1:], parts[1:]):
        if set(other) != set(parts[0]):
            raise CaptureError(f"{name}: parts against the dome {listed(other)}, {names[0]}: {listed(parts[0])}: "
                               "not calibrations of one profile")
        for key, (a, a_se) in parts[0].items():
            b, b_se = other[key]
            if abs(a - b) > MOVED_SIGMAS * math.hypot(a_se, b_se):
                unit = "deg" if key.endswith("_deg") else "mm"
                raise CaptureError(
                    f"{name}: {key} against the dome {b:+.4f} {unit}, {names[0]}: {a:+.4f} (standard errors "
                    f"{b_se:.4f}, {a_se:.4f}): the rig moved between them; measure the seating with the rig left "
                    "as it is, only the screen laid again")
