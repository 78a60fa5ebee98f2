"""`rigcad manual` and the fab report it follows: it keeps a report made with the slicer's G-code
(never replacing it with rigcad's estimate), and it exits non-zero when fab reports a problem (its
bill would glue a beam no glue holds)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from rigcad.cli import manual as M
from rigcad.fab.printers import load_printer
from rigcad.optics.frames import Misalignment

ROOT = Path(__file__).resolve().parents[1]


def _rigcad(*args: str, timeout: float = 1800) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rigcad", *args], capture_output=True, text=True, timeout=timeout)


class _Api:
    """A stand-in for rigcad.api: which fab run the manual asks for."""

    def __init__(self, published=None):
        self.published, self.calls = published, []

    def fab_published(self, profile, printer, folder, gcode=False, progress=None):
        self.calls.append(("published", gcode))
        return self.published if gcode else None

    def fab(self, rig, printer, folder, gcode=False, progress=None):
        self.calls.append(("fab", gcode))
        return "ran"


@pytest.mark.parametrize("old, kept_gcode", [
    ({"gcode": {"requested": True, "slicer": "prusa-slicer"}}, True),  # sliced before: sliced again, cached
    ({"gcode": {"requested": False, "slicer": "prusa-slicer"}}, False),
    (None, False),  # no report yet
])
def test_a_sliced_report_is_never_replaced_by_an_unsliced_one(tmp_path, old, kept_gcode):
    printer = load_printer(ROOT / "profiles" / "printers" / "prusa_mk3s.yaml")
    if old is not None:
        (tmp_path / "fab.json").write_text(json.dumps(old))
    rig = SimpleNamespace(misalignment=Misalignment.none())
    api = _Api()
    assert M._fab_report(api, rig, None, printer, tmp_path, False, None) == "ran"
    assert api.calls == [("published", True), ("fab", kept_gcode)], api.calls
    # a fresh published run with G-code is taken as it is: nothing runs
    api = _Api(published="kept")
    assert M._fab_report(api, rig, None, printer, tmp_path, False, None) == "kept" and api.calls == [("published", True)]
    # asked for G-code: the fab stage with it (which reads back its own run)
    api = _Api(published="kept")
    assert M._fab_report(api, rig, None, printer, tmp_path, True, None) == "ran" and api.calls == [("fab", True)]


@pytest.mark.e2e
def test_manual_after_fab_gcode_keeps_the_report(tmp_path):
    """fab --gcode, then manual without it: fab.json is the --gcode run's, byte for byte (the
    Vantage has no slicer rigcad runs, so nothing is sliced; the run's key is the --gcode one)."""
    fab = _rigcad("fab", "achutha2006", "--printer", "vantage_i", "--gcode", "--exports", str(tmp_path))
    assert fab.returncode == 0, fab.stderr[-2000:]
    report = tmp_path / "achutha2006" / "fab" / "vantage_i" / "fab.json"
    before = report.read_bytes()
    assert json.loads(before)["gcode"]["requested"] is True
    man = _rigcad("manual", "achutha2006", "--printer", "vantage_i", "--exports", str(tmp_path))
    assert man.returncode == 0, man.stderr[-2000:]
    assert report.read_bytes() == before  # not re-run without --gcode


@pytest.mark.e2e
def test_manual_exits_non_zero_when_fab_reports_a_problem(tmp_path):
    """The default rig on the Ender-3 V2's preset: its beam is split and its glue faces leave more
    than any glue fills; manual writes the manual but exits 1, naming the key that avoids it."""
    from rigcad.fab import vendor as V

    if "Creality" not in V.available_bundles():
        pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
    printer = "Creality Ender-3 V2 (0.4 mm nozzle)"
    man = _rigcad("manual", "achutha2006", "--printer", printer, "--exports", str(tmp_path))
    assert man.returncode == 1, man.stderr[-2000:]
    assert "rigcad: fab: beam: its glue faces" in man.stderr and "beam.overhang at most" in man.stderr, man.stderr
    assert man.stderr.splitlines()[-1].startswith("rigcad: error: fab found"), man.stderr[-1000:]
    assert (tmp_path / "achutha2006" / "manual" / load_printer(printer).name / "manual.md").is_file()
