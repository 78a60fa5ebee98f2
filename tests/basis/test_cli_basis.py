"""`rigcad basis` as a user runs it: the files it writes, the same bytes on a second run, stale images
removed, a bad order refused in one line with nothing written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from rigcad.cli import main

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]


def run(*args):
    return subprocess.run([sys.executable, "-m", "rigcad", *args], cwd=ROOT, capture_output=True, text=True)


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """Order 2 written twice into two folders (with the re-orthonormalised images)."""
    roots = []
    for name in ("a", "b"):
        root = tmp_path_factory.mktemp(name)
        assert main(["basis", "achutha2006", "--order", "2", "--lowdin", "--exports", str(root)]) == 0
        roots.append(root / "achutha2006" / "basis")
    return roots


def test_writes_images_sheets_and_report(two_runs):
    out = two_runs[0]
    report = json.loads((out / "basis.json").read_text())
    files = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    # 9 functions x (positive, negative) x (8, 16 bit) x (projector, Loewdin projector, lat-long maps),
    # the float lat-long maps, two sheets and the report
    assert len(files) == 9 * 2 * 2 * 3 + 1 + 2 + 1, files
    assert sorted(report["files"] + ["basis.json"]) == files  # the report lists what is there
    for name in ("projector/8bit/z_2_-1_pos.png", "projector/16bit/z_0_+0_neg.png", "projector_lowdin/8bit/z_1_+1_neg.png",
                 "latlong/16bit/z_2_+2_pos.png", "latlong/latlong_float32.npy", "contact_sheet.png", "latlong_sheet.png"):
        assert (out / name).is_file(), name
    assert all((out / f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for f in files if f.endswith(".png"))
    assert report["order"] == 2 and report["zone"]["alpha_deg"] > 6.9  # the rig's range, not 9 deg
    for key in ("solid_angle_sr", "alpha_deg"):  # units in the keys
        assert key in report["zone"]
    g = report["gram"]
    assert set(k for k in g if k.startswith("order_")) == {"order_2"}  # only the orders written
    assert len(report["gram_matrix_8bit"]) == 9 and len(report["lowdin_transform"]) == 9


def test_two_runs_give_the_same_bytes(two_runs):
    a, b = two_runs
    names = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert names == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    different = [str(n) for n in names if (a / n).read_bytes() != (b / n).read_bytes()]
    assert not different, different


def test_a_lower_order_removes_the_images_it_does_not_write(tmp_path):
    out = tmp_path / "achutha2006" / "basis"
    assert main(["basis", "achutha2006", "--order", "1", "--lowdin", "--exports", str(tmp_path)]) == 0
    assert (out / "projector_lowdin" / "8bit" / "z_1_-1_pos.png").is_file()
    assert main(["basis", "achutha2006", "--order", "0", "--exports", str(tmp_path)]) == 0
    pngs = sorted(p.name for p in out.rglob("z_*.png"))
    # order 0: Z_0^0 only, positive and negative, 8 and 16 bit, projector and lat-long; no Loewdin set
    assert pngs == ["z_0_+0_neg.png"] * 4 + ["z_0_+0_pos.png"] * 4, pngs
    assert not any((out / "projector_lowdin").rglob("*.png"))


@pytest.mark.parametrize("order", ["-1", "13", "six", "2.5"])
def test_a_bad_order_is_one_line_and_writes_nothing(tmp_path, order):
    res = run("basis", "achutha2006", "--order", order, "--exports", str(tmp_path / "x"))
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert "basis order = " in lines[0] and "need an integer from 0 to 12" in lines[0], lines
    assert not (tmp_path / "x").exists()


def test_simulate_writes_its_report(tmp_path, capsys):
    # a sparse camera (every 120th pixel: 4 exitant directions) keeps this run to seconds
    assert main(["basis", "achutha2006", "--order", "1", "--simulate", "--camera-stride-px", "120",
                 "--exports", str(tmp_path)]) == 0
    out = tmp_path / "achutha2006" / "basis"
    sim = json.loads((out / "simulation.json").read_text())
    assert sim["camera"]["exitant_directions"] == 4
    assert list(sim["rigs"]) == ["as_designed", "moved_1", "moved_2"]  # the tolerancing section's two moves
    assert (out / "simulation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = capsys.readouterr().out
    assert "gray card" in text and "paraboloid moved by (0.1, 0, 0) mm" in text


def test_one_run_is_one_publication(tmp_path):
    """The images and the simulation of one run are published together and listed together in
    basis.json; a later run without --simulate leaves no simulation of the earlier one beside its
    images (the folder never mixes two runs)."""
    out = tmp_path / "achutha2006" / "basis"
    assert main(["basis", "achutha2006", "--order", "1", "--simulate", "--camera-stride-px", "120",
                 "--exports", str(tmp_path)]) == 0
    listed = json.loads((out / "basis.json").read_text())["files"]
    assert {"simulation.json", "simulation.png"} <= set(listed), listed
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(listed + ["basis.json"])
    assert main(["basis", "achutha2006", "--order", "0", "--exports", str(tmp_path)]) == 0
    report = json.loads((out / "basis.json").read_text())
    assert report["order"] == 0
    assert not (out / "simulation.json").exists() and not (out / "simulation.png").exists()
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(
        report["files"] + ["basis.json"])
