"""The capture conventions docs/calibrate.md states ("Capture conventions") against the code that
applies them (rigcad.calibrate.conventions reads them from it), and each reading against an
independent computation: a capture script written from the page must produce what the decoder
and the fit expect."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rigcad.calibrate import conventions as C
from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import screen_pose, to_global

PAGE = Path(__file__).resolve().parents[2] / "docs" / "calibrate.md"


@pytest.fixture(scope="module")
def facts(table31_rig):
    return C.facts(table31_rig)


def _section() -> str:
    text = PAGE.read_text(encoding="utf-8")
    start = text.index("## Capture conventions")
    return " ".join(text[start:text.index("\n## ", start + 5)].split())


def test_the_camera_image_axes_and_pixel_centres(table31_rig, facts):
    """Column -> rig +x, row -> rig -y, pixel centres at +0.5, the principal point at the centre: a
    ray traced through the aligned rig from a pixel right of the centre meets the sample plane's
    side at +x, one below it at -y (an independent reading: the ray check's tracer)."""
    from rigcad.check.sources import pixel_rays

    cam = M.Camera.of(table31_rig)
    w, h = cam.resolution
    assert facts["camera"]["column_axis"] == "+x" and facts["camera"]["row_axis"] == "-y"
    # the window's first pixel is (row0, col0): its centre by the page's formula
    assert cam.x_px[0] == cam.col0 + 0.5 - w / 2 and cam.y_px[0] == h / 2 - cam.row0 - 0.5
    assert facts["camera"]["first_pixel_centre_px"] == [0.5 - w / 2, h / 2 - 0.5]
    rays = pixel_rays(cam.design, np.array([50.0, 0.0]), np.array([0.0, -50.0]))
    assert rays.dirs[0, 0] > 0 and abs(rays.dirs[0, 1]) < 1e-12  # right of the centre: towards +x
    assert rays.dirs[1, 1] < 0 and abs(rays.dirs[1, 0]) < 1e-12  # below the centre (a larger row): -y
    assert facts["camera"]["principal_point_px"] == [w / 2, h / 2]
    # 2389 px for Table 3.1, as the page says (the projector's field across the sensor's height)
    assert round(facts["camera"]["focal_px"]) == 2389


def test_the_window_is_centred_on_the_paraboloid_image(table31_rig, facts):
    win = facts["camera"]["window"]
    w, h = facts["camera"]["resolution_px"]
    # centred: as many columns left of the window as right of it, within the one an odd side leaves
    assert abs(win["col0"] - (w - win["col0"] - win["cols"])) <= 1
    assert abs(win["row0"] - (h - win["row0"] - win["rows"])) <= 1
    page = _section()
    assert (f"rows {win['row0']}-{win['row0'] + win['rows'] - 1} and columns "
            f"{win['col0']}-{win['col0'] + win['cols'] - 1} on a {w} x {h} camera") in page


def test_the_screen_axes_at_each_turn(table31_rig, facts):
    """u along the columns, rows towards -v, the centre at (0, 0); at turn 0 u = +x, v = +y; after
    the half turn u = -x, v = -y; du, dv along the rig's x and y at both turns."""
    seq = Sequence.from_profile(table31_rig.profile.calibration)
    w, h = seq.resolution
    p = seq.pitch
    # pixel (0, 0)'s centre by the page's formula, and the decoder's own conversion
    assert seq.to_mm("x", np.array(0.5)) == pytest.approx(0.5 * p - w * p / 2)
    assert seq.to_mm("y", np.array(0.5)) == pytest.approx(h * p / 2 - 0.5 * p)
    assert np.allclose(seq.from_mm(np.array(0.0), np.array(0.0)), (w / 2, h / 2))
    assert facts["screen"]["turn 0"] == {"u": "+x", "v": "+y", "du": "+x", "dv": "+y"}
    assert facts["screen"]["half turn"] == {"u": "-x", "v": "-y", "du": "+x", "dv": "+y"}
    # independently: the half-turned screen's point (u, v) lies at (-u, -v) of the rig, its placement
    # (du, dv) at (+du, +dv)
    got = to_global(screen_pose(10.0, du=0.3, dv=-0.2, turn=math.pi), np.array(5.0), np.array(2.0))
    assert np.allclose(got, [-5.0 + 0.3, -2.0 - 0.2, 10.0])


def test_the_patterns_and_the_gray_code(table31_rig, facts):
    """Sinusoids at the pixel centre c = index + 0.5; the Gray code k XOR (k >> 1), most significant
    bit first, white = 1, stripe S = half the coarsest period: the frames as the kit writes them."""
    seq = Sequence.from_profile(table31_rig.profile.calibration)
    c = np.arange(seq.resolution[0]) + 0.5
    p, n, steps = seq.periods[-1], 1, seq.steps
    want = np.round(255 * (0.5 + 0.5 * np.cos(2 * np.pi * c / p - 2 * np.pi * n / steps)))
    assert np.array_equal(seq.profile(f"x_p{p}_s{n}"), want.astype(np.uint8))
    k = np.floor(c / (seq.periods[0] / 2)).astype(int)
    for b in range(seq.gray_bits):
        bit = ((k ^ (k >> 1)) >> (seq.gray_bits - 1 - b)) & 1
        assert np.array_equal(seq.profile(f"x_gray{b}"), np.where(bit, 255, 0))
    assert facts["gray"]["codes_of_stripes_0_7"] == [0, 1, 3, 2, 6, 7, 5, 4]
    assert seq.names()[:2] == ["white", "black"]


def test_the_tilts_sign(facts):
    """A rotation vector (tilt_x, tilt_y, 0), right-handed: tilt_x > 0 lifts +y, tilt_y > 0 lifts -x
    (closed form: R_x(a) (0, 1, 0) = (0, cos a, sin a); R_y(a) (1, 0, 0) = (cos a, 0, -sin a))."""
    assert facts["tilt"] == {"tilt_x_lifts": "+y", "tilt_y_lifts": "-x"}
    a = 0.01
    assert np.allclose(screen_pose(0.0, tilt_x=a).rotation @ [0, 1, 0], [0, math.cos(a), math.sin(a)])
    assert np.allclose(screen_pose(0.0, tilt_y=a).rotation @ [1, 0, 0], [math.cos(a), 0, -math.sin(a)])


def test_the_page_states_what_the_code_does(facts):
    """Each convention as the page words it, from the facts the code gives: a change in the code
    that is not written into the page fails here."""
    page = _section()
    cam, scr = facts["camera"], facts["screen"]
    assert f"a column further right is further towards rig {cam['column_axis']}" in page
    assert f"a row further down further towards rig {cam['row_axis']}" in page
    assert "x = i + 0.5 - W / 2, y = H / 2 - j - 0.5" in page
    assert f"({round(cam['focal_px'])} px for Table 3.1)" in page
    assert "c = (i + 0.5, j + 0.5)" in page and "u = c_x p - W p / 2" in page and "v = H p / 2 - c_y p" in page
    assert (f"Laid at turn 0, u is rig {scr['turn 0']['u']} and v rig {scr['turn 0']['v']}") in page
    assert f"after the half turn, u is rig {scr['half turn']['u']} and v rig {scr['half turn']['v']}" in page
    assert f"along rig x and y" in page and scr["half turn"]["du"] == "+x"
    assert "k XOR (k >> 1), white (255) where the bit is 1" in page
    assert (f"tilt_x > 0 lifts the {facts['tilt']['tilt_x_lifts']} side, tilt_y > 0 lifts the "
            f"{facts['tilt']['tilt_y_lifts']} side") in page


def test_the_figure_is_drawn_from_the_facts(facts):
    """The kit's figure: a PNG, the same bytes for the same facts, other bytes for other facts."""
    a, b = C.figure(facts), C.figure(facts)
    assert a[:8] == b"\x89PNG\r\n\x1a\n" and a == b
    other = {**facts, "tilt": {"tilt_x_lifts": "-y", "tilt_y_lifts": "+x"}}
    assert C.figure(other) != a
