"""What a deflectometric calibration (``rigcad calibrate --images``) must show to pass
(rigcad.calibrate.kit.pass_criterion): each placement against the dome within its tolerance by two
standard errors, the dome's residual slope p99 within the slope the optical acceptance test holds;
the manual's calibration page states it, and judge() reads a calibration.json against it."""

from __future__ import annotations

import math

import pytest

from rigcad.calibrate import kit
from rigcad.calibrate import model as M
from rigcad.manual import finishing as F

TOLERANCING_KEY = {"dx_mm": "offset", "dy_mm": "offset", "dz_mm": "height", "tilt_x_deg": "tilt", "tilt_y_deg": "tilt"}


def _report(values: dict | None = None, se: float = 0.001, slope_p99: float = 1.0) -> dict:
    """A calibration.json's judged parts: every placement against the dome 0 (or ``values``) with
    standard error ``se``, the residual slope p99 ``slope_p99`` mrad."""
    names = [n.replace("_rad", "_deg") for n in M.DOME_FRAME_NAMES]
    params = {n: {"value": (values or {}).get(n, 0.0), "standard_error": se} for n in names}
    return {"against_the_dome": {"parameters": params}, "residual_slopes": {"residual_slope_p99_mrad": slope_p99}}


def test_the_bounds_are_the_profiles_tolerances_and_the_acceptance_tests_slope(table31_rig):
    crit = kit.pass_criterion(table31_rig)
    tol = table31_rig.profile.tolerancing
    # every placement the report gives against the dome is judged, against its own tolerancing key
    assert set(crit["placements"]) == {n.replace("_rad", "_deg") for n in M.DOME_FRAME_NAMES}
    for name, bound in crit["placements"].items():
        part, axis = name.split("_", 1)
        v = getattr(tol, f"{part}_{TOLERANCING_KEY[axis]}")
        assert bound == pytest.approx(math.degrees(v) if axis.endswith("deg") else v, rel=1e-12), name
    assert crit["placements"]["paraboloid_dx_mm"] == 0.1 and crit["placements"]["camera_tilt_x_deg"] == pytest.approx(0.5)
    # the slope bound is the optical acceptance test's (one figure in two homes, held equal here)
    assert crit["residual_slope_p99_mrad"] == pytest.approx(F.slope_acceptance(table31_rig)["dome_slope_tolerance_mrad"],
                                                            rel=1e-12)


def test_judge_passes_a_placed_rig_and_fails_each_way_it_can_fail(table31_rig):
    ok = kit.judge(table31_rig, _report())
    assert len(ok) == 11 and all(passed for _, passed, _ in ok)
    assert kit.verdict_line(table31_rig, _report()).startswith("calibration: PASS")
    # out by more than its bound: re-seat it
    out = dict((n, (p, t)) for n, p, t in kit.judge(table31_rig, _report({"paraboloid_dx_mm": 0.15}, se=0.01)))
    assert not out["paraboloid_dx_mm"][0] and "re-seat" in out["paraboloid_dx_mm"][1]
    # inside its bound, but not by two standard errors: unresolved, capture again (0.09 + 2 x 0.01 > 0.1)
    out = dict((n, (p, t)) for n, p, t in kit.judge(table31_rig, _report({"paraboloid_dx_mm": 0.09}, se=0.01)))
    assert not out["paraboloid_dx_mm"][0] and "capture again" in out["paraboloid_dx_mm"][1]
    out = dict((n, (p, t)) for n, p, t in kit.judge(table31_rig, _report({"paraboloid_dx_mm": 0.07}, se=0.01)))
    assert out["paraboloid_dx_mm"][0]
    # a tilt is judged in degrees: 0.3 deg is past the paraboloid's 0.2 deg, inside the camera's 0.5 deg
    out = dict((n, p) for n, p, _ in kit.judge(table31_rig, _report({"paraboloid_tilt_y_deg": -0.3,
                                                                     "camera_tilt_y_deg": -0.3})))
    assert not out["paraboloid_tilt_y_deg"] and out["camera_tilt_y_deg"]
    # the dome's slopes: p99 past the bound fails, with what to do
    bound = kit.pass_criterion(table31_rig)["residual_slope_p99_mrad"]
    line = kit.verdict_line(table31_rig, _report(slope_p99=1.01 * bound))
    assert line.startswith("calibration: FAIL") and "residual_slope_p99_mrad" in line and "sand the dome" in line


def test_the_calibration_page_states_what_passes_and_what_to_do(table31_rig):
    page = kit.manual_page(table31_rig)
    assert "## What passes" in page
    section = page.split("## What passes", 1)[1].split("\n## ", 1)[0]
    crit = kit.pass_criterion(table31_rig)
    for name, bound in crit["placements"].items():
        unit = "deg" if name.endswith("_deg") else "mm"
        assert f"`{name}`: within ±{bound:g} {unit}" in section, name
    assert f"at most {crit['residual_slope_p99_mrad']:.3g} mrad" in section
    assert f"by {crit['standard_errors']:g} standard errors" in section
    for what in ("re-seated", "captured again", "sand it back"):
        assert what in section, what

