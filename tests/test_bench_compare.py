"""bench/compare.py, make bench's verdict: a ratio measured more than 10 % below its committed
figure is a regression (exit 1), one within 10 % is not; a ratio not measured is said so; the
committed results change only with --refresh. Pure JSON, nothing timed."""

from __future__ import annotations

import importlib.util
import json
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def compare():
    spec = importlib.util.spec_from_file_location("bench_compare", ROOT / "bench" / "compare.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_listed_ratio_is_in_the_committed_results(compare):
    rows = compare.compare(ROOT / "bench" / "results", ROOT / "bench" / "results")
    assert [r["name"] for r in rows if r["committed"] is None] == []  # no path that reads nothing
    assert {r["verdict"] for r in rows} == {"ok"}  # the committed figures against themselves


def _results(tmp_path: Path, name: str, smooth: float) -> Path:
    """A results folder holding raycheck.json with the smooth reading's ratio ``smooth``."""
    folder = tmp_path / name
    folder.mkdir()
    doc = json.loads((ROOT / "bench" / "results" / "raycheck.json").read_text())
    doc["readings"]["smooth"]["raw_over_reading"] = smooth
    (folder / "raycheck.json").write_text(json.dumps(doc))
    (folder / "raycheck.png").write_bytes(b"png of " + name.encode())
    return folder


def _row(rows, name):
    return next(r for r in rows if r["name"] == name)


def test_a_drop_of_more_than_ten_percent_is_a_regression(compare, tmp_path, capsys):
    committed = _results(tmp_path, "committed", 0.84)
    before = {p.name: p.read_bytes() for p in committed.iterdir()}
    low = _results(tmp_path, "low", 0.84 * 0.899)  # 10.1 % below
    assert compare.main([str(low), "--results", str(committed)]) == 1
    out = capsys.readouterr()
    assert "raycheck.smooth" in out.err and "REGRESSION" in out.out
    rows = json.loads((low / "compare.json").read_text())["ratios"]
    assert _row(rows, "raycheck.smooth")["verdict"] == "regression"
    assert _row(rows, "raycheck.mesh")["verdict"] == "ok"  # the same figure as committed
    assert _row(rows, "dome.table31")["verdict"] == "not measured"  # no dome.json in the run
    assert {p.name: p.read_bytes() for p in committed.iterdir()} == before  # nothing refreshed


def test_a_drop_within_ten_percent_passes(compare, tmp_path):
    committed = _results(tmp_path, "committed", 0.84)
    near = _results(tmp_path, "near", 0.84 * 0.901)  # 9.9 % below
    assert compare.main([str(near), "--results", str(committed)]) == 0
    assert _row(compare.compare(near, committed), "raycheck.smooth")["verdict"] == "ok"


def test_only_a_refreshing_run_writes_the_committed_figures(compare, tmp_path):
    committed = _results(tmp_path, "committed", 0.84)
    low = _results(tmp_path, "low", 0.5)
    assert compare.main([str(low), "--results", str(committed), "--refresh"]) == 0
    assert json.loads((committed / "raycheck.json").read_text())["readings"]["smooth"]["raw_over_reading"] == 0.5
    assert (committed / "raycheck.png").read_bytes() == b"png of low"
    assert not (committed / "compare.json").exists()  # the comparison is the run's record, not a result
    # the run's folder may not be the committed one: it would compare the figures with themselves
    assert compare.main([str(committed), "--results", str(committed)]) == 2


def test_a_missing_or_unreadable_figure_is_not_a_pass(compare, tmp_path):
    committed = _results(tmp_path, "committed", 0.84)
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "raycheck.json").write_text("{not json")
    rows = compare.compare(broken, committed)
    assert {r["verdict"] for r in rows} == {"not measured"}
    shutil.rmtree(broken)
    broken.mkdir()
    (broken / "raycheck.json").write_text(json.dumps({"readings": {"smooth": {"raw_over_reading": "fast"}}}))
    assert _row(compare.compare(broken, committed), "raycheck.smooth")["verdict"] == "not measured"


def test_a_figure_committed_on_another_cpu_is_said_so(compare, tmp_path):
    committed = _results(tmp_path, "committed", 0.84)
    measured = _results(tmp_path, "measured", 0.84)
    for folder, cpu in ((committed, "Intel Xeon"), (measured, "AMD EPYC")):
        doc = json.loads((folder / "raycheck.json").read_text())
        doc["run"]["cpu_model"] = cpu
        (folder / "raycheck.json").write_text(json.dumps(doc))
    notes = compare.cpu_notes(compare.compare(measured, committed))
    assert len(notes) == 1 and "Intel Xeon" in notes[0] and "AMD EPYC" in notes[0]  # one line per file
    assert compare.cpu_notes(compare.compare(measured, measured)) == []  # the same CPU: nothing to say
