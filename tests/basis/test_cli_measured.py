"""`rigcad basis` reads the rig as measured: the calibration circle (--circle, or calibrate/circle.json
found beside) and rigcad calibrate's fit (--calibration, or calibrate/calibration.json found beside);
a wrong file is one line and nothing is written."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from rigcad.cli import main

pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]


def test_a_measured_circle_moves_the_images_and_basis_json_says_so(tmp_path, capsys):
    assert main(["basis", "achutha2006", "--order", "0", "--circle", "522", "384", "110", "--exports",
                 str(tmp_path)]) == 0
    report = json.loads((tmp_path / "achutha2006" / "basis" / "basis.json").read_text())
    assert report["measured"]["circle"] == {"centre_px_from_top_left": [522.0, 384.0], "radius_px": 110.0,
                                            "source": "--circle"}
    # the rim (the map's alpha_max, 3.205 deg for Table 3.1) on the circle: f = R / tan(alpha_max)
    assert report["projector"]["focal_length_px"] == pytest.approx(110.0 / math.tan(0.05593700620465977), rel=1e-9)
    assert "the measured circle (110.0 px about (522, 384), --circle)" in capsys.readouterr().out


def test_a_foreign_circle_file_beside_is_one_line_and_writes_nothing(tmp_path):
    folder = tmp_path / "achutha2006" / "calibrate"
    folder.mkdir(parents=True)
    (folder / "circle.json").write_text(json.dumps({"centre_px_from_top_left": [640, 400], "radius_px": 108,
                                                    "resolution_px": [1280, 800]}))
    res = subprocess.run([sys.executable, "-m", "rigcad", "basis", "achutha2006", "--order", "0", "--exports",
                          str(tmp_path)], cwd=ROOT, capture_output=True, text=True)
    assert res.returncode != 0
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert "circle.json: resolution_px [1280, 800]: measured on another projector" in lines[0], lines
    assert not (tmp_path / "achutha2006" / "basis").exists()
