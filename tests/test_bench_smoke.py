"""Smoke test of the issue-7 bench scripts (and issue 16's basis.py): each runs in its --quick mode into tmp_path and writes
its JSON (units in keys, the run's load recorded) and PNG. Nothing here is timed or compared with
a number: the benchmarks' figures are in bench/results/, produced by `make bench`."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ("ray_count", "float32", "tessellation", "make_stl", "basis", "optimize", "refusals")


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
