"""``rigcad calibrate --images`` judges the rig (rigcad.calibrate.kit.verdict): one line per criterion, PASS
or FAIL with its figure against its bound, then the verdict; the same in calibration.json's ``verdict``; exit
1 on FAIL (its outputs still written), 0 on PASS. The captures are the small camera's synthetic ones
(tests/calibrate/test_simulate_fit.py's profile, rendered by rigcad.calibrate.simulate): a rig placed as
designed with an unblemished dome passes; the same rig with its paraboloid 0.3 mm off along x (three times
its 0.1 mm tolerance) fails on that placement, with what to do."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest
from PIL import Image

from rigcad.calibrate import kit
from rigcad.calibrate import model as M
from rigcad.calibrate import simulate as S
from rigcad.calibrate.patterns import Sequence
from rigcad.cli.calibrate import _print_verdict, cmd_calibrate
from rigcad.profile.schema import load_profile
from rigcad.rig import Rig
from tests.calibrate.test_simulate_fit import COARSE_FIT, SMALL


def _report(values: dict | None = None, se: float = 0.001, slope_p99: float = 1.0) -> dict:
    names = [n.replace("_rad", "_deg") for n in M.DOME_FRAME_NAMES]
    params = {n: {"value": (values or {}).get(n, 0.0), "standard_error": se} for n in names}
    return {"against_the_dome": {"parameters": params}, "residual_slopes": {"residual_slope_p99_mrad": slope_p99}}


def test_the_verdict_prints_each_criterion_against_its_bound_and_exits_by_it(table31_rig, capsys):
    good = kit.verdict(table31_rig, _report())
    assert good["passed"] and len(good["lines"]) == 11 and all(line.startswith("PASS ") for line in good["lines"])
    assert _print_verdict(good, simulated=False) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == "calibration: PASS (11 of 11 criteria)"
    # the figure held to the bound: |value| + 2 standard errors, in the bound's unit, with its profile key
    assert "  PASS paraboloid_dx_mm: |+0| + 2 x 0.001 = 0.002 mm within ±0.1 mm (tolerancing.paraboloid_offset)" in out
    bound = kit.pass_criterion(table31_rig)["residual_slope_p99_mrad"]
    assert f"  PASS residual_slope_p99_mrad: 1 mrad within {bound:.3g} mrad (tolerancing.max_spot_radius)" in out
    bad = kit.verdict(table31_rig, _report({"camera_dz_mm": 1.5}, slope_p99=2 * bound))
    assert not bad["passed"]
    assert _print_verdict(bad, simulated=False) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[-1].startswith("calibration: FAIL (2 of 11 criteria: camera_dz_mm, residual_slope_p99_mrad;")
    assert any(line.startswith("  FAIL camera_dz_mm: |+1.5| + 2 x 0.001 = 1.502 mm over ±1 mm") and kit.RESEAT in line
               for line in out)
    assert any(line.startswith("  FAIL residual_slope_p99_mrad") and kit.REFINISH in line for line in out)
    # a rehearsal (--simulate) says its verdict and exits 0 either way
    assert _print_verdict(bad, simulated=True) == 0
    assert "a rehearsal" in capsys.readouterr().out


def _capture(root, paraboloid_dx: float, fit: str):
    """The small camera's capture of a rig placed as designed but for ``paraboloid_dx`` (mm, the
    paraboloid along x against the dome), no dome error, written as --images reads it; its profile."""
    from rigcad.check.scene import analytic_optics

    path = root / "small.yaml"
    path.write_text(SMALL + fit)
    rig = Rig.from_profile(load_profile(path))
    plan, seq, cam = M.Plan.of(rig.profile), Sequence.from_profile(rig.profile.calibration), M.Camera.of(rig)
    rng = np.random.default_rng(1)
    theta = S.random_misalignment(rig, plan, rng)  # the screens as a hand lays them
    names = M.parameter_names(len(plan))
    for i, n in enumerate(names):
        if n.startswith(("paraboloid", "camera")):
            theta[i] = 0.0
    theta[names.index("paraboloid_dx_mm")] = paraboloid_dx
    images = S.render(analytic_optics(rig), rig, theta, None, cam, seq, plan, rng)
    folder = root / "capture"
    folder.mkdir()
    for label, frames in zip(plan.labels, images):
        for name, im in frames.items():
            Image.fromarray(im).save(folder / f"{label}_{name}.png")
    return path, folder


def _calibrate(tmp_path, paraboloid_dx: float, fit: str = ""):
    path, folder = _capture(tmp_path, paraboloid_dx, fit)
    code = cmd_calibrate(argparse.Namespace(profile=str(path), images=str(folder), simulate=False, seed=0,
                                            exports=str(tmp_path / "exports")))
    report = json.loads((tmp_path / "exports" / "small" / "calibrate" / "calibration.json").read_text())
    return code, report


@pytest.mark.e2e
def test_a_rig_placed_as_designed_passes(tmp_path, capsys):
    """Every placement fitted within its tolerance by two standard errors (the small camera, every pixel
    fitted: measured 0.02-0.23 mm and 0.01-0.06 deg off, standard errors 0.001-0.017), the slope p99
    0.3 mrad against 6.48: PASS, exit 0."""
    code, report = _calibrate(tmp_path, 0.0)
    out = capsys.readouterr().out.splitlines()
    assert code == 0 and report["verdict"]["passed"], report["verdict"]["lines"]
    assert out[-1] == report["verdict"]["line"] == "calibration: PASS (11 of 11 criteria)"
    assert [line.strip() for line in out[-12:-1]] == report["verdict"]["lines"]
    assert len(report["verdict"]["checks"]) == 11 and all(c["passed"] for c in report["verdict"]["checks"])


@pytest.mark.e2e
def test_a_paraboloid_out_of_tolerance_fails_with_what_to_do(tmp_path, capsys):
    """The paraboloid 0.3 mm off along x (its tolerance 0.1 mm; every 4th row and column fitted, standard
    errors ~0.05 mm): FAIL on paraboloid_dx_mm, re-seat it; exit 1, the outputs written all the same."""
    code, report = _calibrate(tmp_path, 0.3, COARSE_FIT)
    out = capsys.readouterr().out.splitlines()
    assert code == 1 and not report["verdict"]["passed"]
    dx = next(c for c in report["verdict"]["checks"] if c["check"] == "paraboloid_dx_mm")
    # the fit finds it within a few standard errors of the 0.3 mm planted, far past the bound
    assert not dx["passed"] and abs(dx["value"] - 0.3) < 0.1 and dx["action"] == kit.RESEAT, dx
    assert out[-1] == report["verdict"]["line"] and out[-1].startswith("calibration: FAIL (")
    assert "paraboloid_dx_mm" in out[-1]
    assert any(line.startswith("  FAIL paraboloid_dx_mm: |+0.") and "over ±0.1 mm" in line for line in out)
    assert (tmp_path / "exports" / "small" / "calibrate" / "corrected_map.npz").exists()
