"""Smoke test of the issue-7 bench scripts (and issue 16's basis.py): each runs in its --quick mode into tmp_path and writes
its JSON (units in keys, the run's load recorded) and PNG, and one accuracy figure of each JSON
matches its reference (CHECKS). Nothing here is timed: the benchmarks' figures are in
bench/results/, produced by `make bench`."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ("ray_count", "float32", "tessellation", "make_stl", "basis", "optimize", "refusals")


def _ray_count(data: dict) -> None:
    # each row's mean lost fraction against the pooled reference (all rays of the largest N), within
    # 4 standard errors of a mean of `seeds` binomial runs (the row's own predicted_std)
    ref = data["reference_all_rays_of_largest_n"]["lost_fraction"]
    for row in data["rows"]:
        se = row["predicted_std"]["lost_fraction"] / row["seeds"] ** 0.5
        assert abs(row["mean"]["lost_fraction"] - ref) < 4 * se, (row["rays"], row["mean"]["lost_fraction"], ref)


def _float32(data: dict) -> None:
    # the exact (float64) path converges on O: the 2D design's chief rays miss by <= 1.5e-8 mm
    assert data["analytic"]["max_spot_radius_mm"] < 1e-6


def _tessellation(data: dict) -> None:
    rows = sorted(data["stl"], key=lambda r: r["chord_error_mm"])
    for row in rows:
        # the beam is a box with its stop pin's small round hole: flat but for the hole, so its mesh
        # loses less volume than the curved parts' (measured 7.5e-5)
        others = max(abs(p["volume_rel_error"]) for n, p in row["parts"].items() if n != "beam")
        assert abs(row["parts"]["beam"]["volume_rel_error"]) <= others, row["chord_error_mm"]
    # an inscribed mesh loses ~ (2/3) chord x area of volume: first order in the chord error. The
    # worst part's error scales with the chord ratio, within 2x either way (measured 1.2x)
    fine, coarse = rows[0], rows[-1]
    worst = [max(abs(p["volume_rel_error"]) for p in r["parts"].values()) for r in (fine, coarse)]
    ratio = (worst[0] / worst[1]) / (fine["chord_error_mm"] / coarse["chord_error_mm"])
    assert 0.5 < ratio < 2.0, (worst, ratio)


def _make_stl(data: dict) -> None:
    # timings only (never asserted); every timed command succeeded
    assert all(set(c["exit_codes"]) == {0} for c in data["commands"].values() if "exit_codes" in c)


def _basis(data: dict) -> None:
    # after Loewdin orthonormalisation the 8-bit images' Gram matrix is the identity up to the
    # quantisation: under one 8-bit step (1/255) in every entry
    for order, g in data["gram"].items():
        assert g["lowdin_8bit_max_abs"] < 1 / 255, (order, g)


def _optimize(data: dict) -> None:
    # the fast design path's mean pixels per degree is the certified path's to rounding (same
    # formula on the same converged profile), whatever the node count
    for row in data["nodes"]:
        assert row["px_per_deg_mean_rel_error_vs_certified"] < 1e-12, row


def _refusals(data: dict) -> None:
    # every hostile count is refused (exit 2, one error line naming its argument) far under the
    # 2 GB that the refusals promise: a refusal allocates nothing of what it was asked for
    for row in data["rows"]:
        option = next(w for w in row["command"].split() if w.startswith("--"))
        assert row["exit_code"] == 2 and row["message"].startswith("rigcad: error: ") and option in row["message"], row
        assert "\n" not in row["message"], row
        assert row["peak_rss_kb"] < 2 * 1024 * 1024, row
    assert data["max_peak_rss_kb"] == max(r["peak_rss_kb"] for r in data["rows"])


CHECKS = {"ray_count": _ray_count, "float32": _float32, "tessellation": _tessellation, "make_stl": _make_stl,
          "basis": _basis, "optimize": _optimize,
          "refusals": _refusals}


@pytest.mark.parametrize("name", SCRIPTS)
def test_bench_script_quick_run_writes_json_and_png(name: str, tmp_path: Path) -> None:
    cmd = [sys.executable, str(ROOT / "bench" / f"{name}.py"), "--quick", "--out", str(tmp_path)]
    if name in ("ray_count", "float32"):
        cmd += ["--exports", str(tmp_path / "no_exports")]  # mirror meshes built from the profile
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    data = json.loads((tmp_path / f"{name}.json").read_text())
    assert "loadavg_1min" in data["run"], "every bench JSON records the machine's load"
    png = (tmp_path / f"{name}.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"Software" not in png, "PNG written without the Software metadata (same bytes every run)"
    CHECKS[name](data)


def test_hugepages_quick_run_measures_both_settings(tmp_path: Path) -> None:
    # bench/hugepages.py writes no picture: its JSON holds both settings of numpy's huge-page advice,
    # each run's outputs the same bytes under both (where memory comes from changes no number)
    cmd = [sys.executable, str(ROOT / "bench" / "hugepages.py"), "--quick", "--runs", "1", "--out", str(tmp_path)]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    data = json.loads((tmp_path / "hugepages.json").read_text())
    assert "loadavg_1min" in data["run"]
    assert {s["NUMPY_MADVISE_HUGEPAGE"] for s in data["settings"].values()} == {"0", "1"}
    assert data["same_outputs"] and all(data["same_outputs"].values()), data["same_outputs"]


def test_commands_quick_run_times_each_command_fresh_and_again(tmp_path: Path) -> None:
    # bench/commands.py writes no picture: every command ran (exit 0) fresh and again, the steps the
    # commands report were stamped (stl reports one per part), and stl's second run found nothing to do
    cmd = [sys.executable, str(ROOT / "bench" / "commands.py"), "--quick", "--out", str(tmp_path)]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    data = json.loads((tmp_path / "commands.json").read_text())
    assert "loadavg_1min" in data["run"]
    runs = [r for c in data["commands"].values() for r in c.values()]
    assert len(runs) == 4 and all(r["exit_code"] == 0 for r in runs), [r["output_tail"] for r in runs]
    stl = data["commands"]["stl"]
    assert len(stl["fresh"]["steps_s"]) > 10 and stl["fresh"]["dominating_step"] is not None
    assert "up to date" in stl["rerun"]["output_tail"]
