"""`rigcad fab` as a user runs it: progress for every part (and every piece sliced), and a
terminal summary with the slicer's time and filament (issue 14, item 5)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from .conftest import ROOT, have_slicer


def _fab(tmp_path, *args):
    env = dict(os.environ, RIGCAD_EVENTS="1", PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "rigcad", "fab", "achutha2006", "--exports", str(tmp_path), *args],
                          cwd=tmp_path, capture_output=True, text=True, env=env, timeout=600)


def test_fab_reports_progress_per_part_and_a_summary(tmp_path):
    proc = _fab(tmp_path, "--printer", "vantage_i", "--parts", "beam", "sample_holder", "dome_template")
    assert proc.returncode == 0, proc.stderr[-2000:]
    events = [ln.split(": ", 1)[1] for ln in proc.stderr.splitlines() if ln.startswith("rigcad-event: ")]
    assert events == ["beam", "sample_holder", "dome_template"]  # one progress step per part, in order
    # no slicer ran: rigcad's estimate, labelled with why and the rate it scales by
    assert "total (rigcad's estimate (vantage_i has no slicer rigcad runs, its volume terms at " \
           "deposition_rate_mm3_s 14.9); with quantities):" in proc.stdout, proc.stdout
    assert "beam: 1 piece(s)" in proc.stdout and "est. " in proc.stdout


@pytest.mark.skipif(not have_slicer(), reason="prusa-slicer is not installed")
def test_fab_gcode_reports_each_piece_sliced_and_the_slicers_figures(tmp_path):
    # two printed parts whatever the profile buys (the sample holder may be bought)
    proc = _fab(tmp_path, "--printer", "prusa_mk3s", "--gcode", "--parts", "beam", "tower_shim", "--jobs", "2")
    assert proc.returncode == 0, proc.stderr[-2000:]
    events = [ln.split(": ", 1)[1] for ln in proc.stderr.splitlines() if ln.startswith("rigcad-event: ")]
    assert events[:2] == ["beam", "tower_shim"]
    assert sorted(events[2:]) == ["sliced beam", "sliced tower_shim"]  # as each piece is done
    assert "total (prusa-slicer, with quantities):" in proc.stdout and " g filament" in proc.stdout
    assert "estimate" not in proc.stdout.split("total (prusa-slicer", 1)[1]  # the slicer ran: its time only
    assert "G-code with PrusaSlicer's presets Original Prusa i3 MK3S & MK3S+ (printer_model MK3S)" in proc.stdout
    assert "; slicer " in proc.stdout  # per part: the slicer's time and filament


@pytest.mark.skipif(not have_slicer(), reason="prusa-slicer is not installed")
def test_a_slicer_complaint_is_the_verdict_on_one_error_line_after_the_outputs(tmp_path):
    """A custom G-code line the slicer cannot read ('touch x' reads as a tool change) is allowed into
    the printer file (it is G-code, and nothing runs it); PrusaSlicer's complaint is fab's verdict:
    its detail on a `rigcad: fab:` line, then one `rigcad: error:` line, exit 1, the outputs written
    with the problem in fab.json."""
    import json

    shipped = (ROOT / "profiles" / "printers" / "prusa_mk3s.yaml").read_text()
    printer = tmp_path / "touchy.yaml"
    printer.write_text(shipped.replace("  overrides:\n", '  overrides:\n    start_gcode: "M117 hi\\ntouch x"\n', 1))
    proc = _fab(tmp_path, "--printer", str(printer), "--gcode", "--parts", "beam")
    assert proc.returncode == 1, proc.stderr[-2000:]
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not ln.startswith("rigcad-event: ")]
    errors = [ln for ln in lines if ln.startswith("rigcad: error: ")]
    assert len(errors) == 1 and "1 problem(s)" in errors[0] and "fab.json" in errors[0], lines
    assert any(ln.startswith("rigcad: fab: beam: slicer warnings:") and "toolchange" in ln for ln in lines), lines
    report = json.loads((tmp_path / "achutha2006" / "fab" / "touchy" / "fab.json").read_text())
    assert any("toolchange" in p for p in report["problems"]), report["problems"]
