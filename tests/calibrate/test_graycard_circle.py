"""The gray card's projector images are drawn for the calibration circle as measured, as ``rigcad basis``
reads it: ``--circle CX CY R`` or ``calibrate/circle.json`` found beside (``--design-circle`` ignores the
file); the circle used is recorded in capture_plan.json; a bad circle is one line and nothing is written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rig_and_design():
    from rigcad.manual.calibration import circle_image
    from rigcad.rig import load

    rig = load("achutha2006")
    _, info = circle_image(rig)
    return rig, info


def test_a_measured_circle_moves_and_scales_the_lit_pixels(rig_and_design):
    from rigcad.basis.card_light import card_light
    from rigcad.basis.measured import check_circle

    rig, info = rig_and_design
    (cx, cy), r = info["centre_px_from_top_left"], info["radius_px"]
    design = card_light(rig)
    moved = card_light(rig, circle=check_circle(rig, (cx + 10, cy - 6), 1.03 * r, "test"))
    # pixel (col, row) spans [col, col + 1): the lit disc's mean pixel centre is the circle's centre
    assert design.col.mean() + 0.5 == pytest.approx(cx, abs=0.05)
    assert moved.col.mean() + 0.5 == pytest.approx(cx + 10, abs=0.05)
    assert moved.row.mean() + 0.5 == pytest.approx(cy - 6, abs=0.05)
    span = lambda light: light.col.max() - light.col.min() + 1
    assert span(moved) / span(design) == pytest.approx(1.03, abs=0.01)


def _kit(tmp_path: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rigcad", "calibrate", "achutha2006", "--gray-card-kit", "--exports",
                           str(tmp_path), *extra], cwd=ROOT, capture_output=True, text=True)


def _white(tmp_path: Path) -> np.ndarray:
    from PIL import Image

    path = tmp_path / "achutha2006" / "calibrate_graycard_kit" / "projector" / "white.png"
    return np.asarray(Image.open(path))


@pytest.mark.e2e
def test_the_kit_reads_circle_json_beside_and_design_circle_ignores_it(tmp_path):
    folder = tmp_path / "achutha2006" / "calibrate"
    folder.mkdir(parents=True)
    (folder / "circle.json").write_text(json.dumps({"centre_px_from_top_left": [522, 380], "radius_px": 110,
                                                    "resolution_px": [1024, 768]}))
    res = _kit(tmp_path)
    assert res.returncode == 0, res.stderr
    assert "the measured circle (110.0 px about (522, 380)" in res.stdout
    plan = json.loads((tmp_path / "achutha2006" / "calibrate_graycard_kit" / "capture_plan.json").read_text())
    assert plan["projector_circle"]["centre_px_from_top_left"] == [522.0, 380.0]
    assert plan["projector_circle"]["radius_px"] == 110.0
    rows, cols = np.nonzero(_white(tmp_path))
    assert cols.mean() + 0.5 == pytest.approx(522, abs=0.1) and rows.mean() + 0.5 == pytest.approx(380, abs=0.1)
    res = _kit(tmp_path, "--design-circle")
    assert res.returncode == 0, res.stderr
    rows, cols = np.nonzero(_white(tmp_path))
    assert cols.mean() + 0.5 == pytest.approx(512, abs=0.1) and rows.mean() + 0.5 == pytest.approx(384, abs=0.1)


@pytest.mark.e2e
@pytest.mark.parametrize("extra, words", [
    (("--circle", "512", "384", "300"), "--circle radius is 300, outside"),
    (("--circle", "1000", "384", "108"), "runs off the 1024 x 768 px projector image"),
])
def test_a_bad_circle_is_one_line_and_writes_nothing(tmp_path, extra, words):
    res = _kit(tmp_path, *extra)
    lines = res.stderr.strip().splitlines()
    assert res.returncode != 0 and len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert words in lines[0], lines
    assert not (tmp_path / "achutha2006" / "calibrate_graycard_kit").exists()


def test_circle_without_the_gray_card_is_refused(tmp_path, capsys):
    from rigcad.cli import main

    assert main(["calibrate", "achutha2006", "--kit", "--circle", "512", "384", "108", "--exports",
                 str(tmp_path)]) != 0
    assert "--circle: only with --gray-card" in capsys.readouterr().err
    assert not (tmp_path / "achutha2006").exists()
