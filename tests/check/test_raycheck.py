"""The check stage: every profile passes its declared tolerances at its default tessellation, a too
coarse tessellation fails naming the key, the CLI writes its files and exits 1 on a failure."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from rigcad.cli import check as check_cli
from rigcad.check.raycheck import run_raycheck, write_raycheck
from rigcad.check.tolerances import raise_if_failed, table
from rigcad.errors import CheckError, RigcadError
from rigcad.profile import load_profile
from rigcad.rig import Rig

ROOT = Path(__file__).resolve().parents[2]
#: rig profiles (profiles/printers/ holds printer definitions, not rigs)
PROFILES = sorted((ROOT / "profiles").glob("*.yaml"))


def test_there_are_profiles():
    assert PROFILES, "no profile found: the parametrised check below would pass vacuously"


@pytest.mark.parametrize("path", PROFILES, ids=[p.stem for p in PROFILES])
def test_every_profile_meets_its_declared_tolerances(path, optics_cache):
    """Default tessellation, the profile's mode; fewer rays and builds than `rigcad check` for speed
    (maxima over 20000 rays come within a few per cent of those over 100000: smooth error fields)."""
    profile = load_profile(path)
    result = run_raycheck(Rig.from_profile(profile), rays=20000, builds=20, grid=True, optics_cache=optics_cache)
    assert len(result.rows) >= 8, "the table has every declared tolerance"
    raise_if_failed(result.rows, profile.name)  # the failure message is the readable table's content
    rep = result.report
    if rep["mode"] != "analytic":
        # mesh minus exact is reported with the tessellation that caused it
        assert rep["meshes"]["tolerances"]["normal_error_rad"] == profile.tessellation.mirror_normal_error
        assert "mesh_minus_exact_angle_rad" in rep["readings"][rep["mode"]]
        assert rep["backend"].startswith("embreex")


def test_a_too_coarse_tessellation_fails_naming_it(table31, table31_rig, optics_cache):
    result = run_raycheck(table31_rig, rays=5000, chord_error=0.1, normal_error=0.1, monte_carlo=False,
                          grid=False, optics_cache=optics_cache)
    assert not result.passed
    with pytest.raises(CheckError) as err:
        raise_if_failed(result.rows, table31.name)
    msg = str(err.value)
    assert "raycheck.max_mesh_angle_error" in msg and "tessellation.mirror_normal_error" in msg, msg
    assert "achutha2006.yaml:" in msg, "the failing key's file:line is named"
    assert err.value.exit_code == 1
    assert "FAIL" in table(result.rows)


def _parser():
    parser = argparse.ArgumentParser(prog="rigcad")
    check_cli.register(parser.add_subparsers(dest="command"))
    return parser


def test_cli_writes_the_report_and_figures(tmp_path, capsys):
    args = _parser().parse_args(["check", "achutha2006", "--exports", str(tmp_path), "--mode", "analytic",
                                 "--rays", "3000", "--builds", "5"])
    assert args.func(args) == 0
    out = tmp_path / "achutha2006" / "check"
    rep = json.loads((out / "raycheck.json").read_text())
    assert rep["passed"] and rep["backend"].startswith("analytic")
    a = rep["readings"]["analytic"]
    assert a["rays"] == 3000 and a["rays_ok"] == round(3000 * (1 - a["lost_fraction"]))
    # the exact surfaces converge on O: the 2D design's chief rays miss by <= 1.5e-8 mm
    # (tests/optics, 1e-6 bound there too); float64 rounding at ~300 mm is ~1e-13 mm
    assert a["max_spot_radius_mm"] < 1e-6 and a["max_angle_error_rad"] < 1e-8
    # the beam's shadow, two independent samplings of it: the 3000 random rays of the reading and the
    # whole pixel grid (every pixel that lands on the paraboloid). The rays' fraction is binomial:
    # 4 sigma = 4 sqrt(p (1 - p) / 3000) ~ 0.015 at p ~ 0.045 (a beam twice as wide doubles both)
    grid = rep["pixel_grid"]
    p_grid = grid["pixels_lost"]["occluded_by_beam"] / grid["pixels_on_paraboloid"]
    p_rays = a["losses"]["occluded_by_beam"]["fraction"]
    assert 0.01 < p_grid < 0.2, p_grid  # a shadow at all, and not the whole annulus
    assert abs(p_rays - p_grid) < 4 * (p_grid * (1 - p_grid) / 3000) ** 0.5, (p_rays, p_grid)
    assert (out / "spot.png").stat().st_size > 1000 and (out / "theta_map.png").stat().st_size > 1000
    assert "spot radius" in capsys.readouterr().out


def test_cli_exits_nonzero_with_a_table_on_failure(tmp_path, write_profile, capsys):
    path = write_profile(f"""
        extends: {ROOT / "profiles" / "achutha2006.yaml"}
        raycheck:
          mode: analytic
          max_lost_fraction: 0.01
        """, name="strict")
    args = _parser().parse_args(["check", str(path), "--exports", str(tmp_path), "--rays", "3000",
                                 "--no-monte-carlo"])
    with pytest.raises(RigcadError) as err:
        args.func(args)
    assert err.value.exit_code == 1  # rigcad.cli.main turns this into exit status 1
    assert "raycheck.max_lost_fraction" in str(err.value) and "strict.yaml:" in str(err.value)
    assert "FAIL" in capsys.readouterr().out
    assert (tmp_path / "strict" / "check" / "raycheck.json").is_file(), "the report is written before failing"


def test_write_raycheck_is_deterministic(tmp_path, table31):
    """The same files from two interpreters (one with another PYTHONHASHSEED), not two calls in one
    process: a second call could share the first one's caches and state."""
    import os
    import subprocess
    import sys

    def run_in(folder: Path, seed: str) -> None:
        code = ("import sys; from pathlib import Path; from rigcad.profile import load_profile; "
                "from rigcad.rig import Rig; from rigcad.check.raycheck import run_raycheck, write_raycheck; "
                "r = run_raycheck(Rig.from_profile(load_profile(sys.argv[1])), mode='analytic', rays=2000, "
                "monte_carlo=False); write_raycheck(r, Path(sys.argv[2]))")
        env = {**os.environ, "PYTHONHASHSEED": seed}
        res = subprocess.run([sys.executable, "-c", code, str(table31.sources[0]), str(folder)], env=env,
                             capture_output=True, text=True, timeout=600)
        assert res.returncode == 0, res.stderr[-2000:]

    a = run_raycheck(Rig.from_profile(table31), mode="analytic", rays=2000, monte_carlo=False)
    assert a.timings_s["pinhole_s"] > 0 and "timings_s" not in a.report  # the run's times stay out of the file
    pa = write_raycheck(a, tmp_path / "a")
    run_in(tmp_path / "b", "7")
    pb = [tmp_path / "b" / p.name for p in pa]
    assert [p.read_bytes() for p in pa] == [p.read_bytes() for p in pb]


def test_the_table_is_fixed_width_with_a_verdict_per_row():
    """The printed check table: a header, one line per row, columns at fixed offsets (the CLI prints
    it and people read it against the report), ok or FAIL at the end."""
    from rigcad.check.tolerances import Row

    rows = [Row("spot radius", "raycheck.max_spot_radius", 1.5e-8, 0.05, "<=", "mm", None),
            Row("pixels per degree", "raycheck.min_px_per_deg", 0.5, 1.0, ">=", "px/deg", "p.yaml:3")]
    lines = table(rows).split("\n")
    assert lines == [
        "check" + " " * 45 + "     measured" + "    " + "     limit" + " unit   " + "     ",
        "spot radius" + " " * 39 + "      1.5e-08 <=       0.05 mm      ok",
        "pixels per degree" + " " * 33 + "          0.5 >=          1 px/deg  FAIL",
    ]
