"""Captures read as `rigcad calibrate --images` reads them: only the camera's window is made floats
(images.read_image), with the same values, pixel for pixel, as the whole frame made floats and then
cut, for 8-bit grey, 16-bit grey and 8-bit colour files; the exposure checks still see the whole
white and black frames."""

import numpy as np
import pytest
from PIL import Image

from rigcad.calibrate.images import CaptureError, read_capture
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.model import Camera

RES = (64, 48)  # width, height
WINDOW = (slice(10, 30), slice(20, 44))  # rows, cols
SEQ = Sequence(steps=3, periods=(16,), gray_bits=1, resolution=(32, 32), pitch=0.1)


def _crop(a):
    return a if a.shape[:2] == (20, 24) else a[WINDOW]


def _write(folder, mode, rng):
    for n in SEQ.names():
        if mode == "L":
            a = rng.integers(0, 256, (RES[1], RES[0]), dtype=np.uint8)
        elif mode == "I;16":
            a = rng.integers(0, 65536, (RES[1], RES[0]), dtype=np.uint16)
        else:
            a = rng.integers(0, 256, (RES[1], RES[0], 3), dtype=np.uint8)
        if n == "white":
            a = np.full_like(a, 200 if a.dtype == np.uint8 else 51000)
            a[0, 0] = 0
        if n == "black":
            a = np.full_like(a, 10 if a.dtype == np.uint8 else 2600)
        Image.fromarray(a).save(folder / f"h0_{n}.png")


@pytest.mark.parametrize("mode", ["L", "I;16", "RGB"])
def test_the_window_read_is_the_whole_frame_cut(tmp_path, mode):
    _write(tmp_path, mode, np.random.default_rng(3))
    whole = read_capture(tmp_path, SEQ, ("h0",), RES)[0]
    cut = read_capture(tmp_path, SEQ, ("h0",), RES, window=_crop)[0]
    for n in SEQ.names():
        assert cut[n].shape == (20, 24) and cut[n].dtype == np.float64
        assert np.array_equal(cut[n], whole[n][WINDOW]), n
    assert 0.0 <= min(f.min() for f in cut.values()) and max(f.max() for f in cut.values()) <= 1.0


def test_the_exposure_is_checked_on_the_whole_frame(tmp_path):
    """A white frame saturated outside the window only is still refused."""
    _write(tmp_path, "L", np.random.default_rng(4))
    a = np.full((RES[1], RES[0]), 255, np.uint8)
    a[WINDOW] = 200
    Image.fromarray(a).save(tmp_path / "h0_white.png")
    with pytest.raises(CaptureError, match="saturated"):
        read_capture(tmp_path, SEQ, ("h0",), RES, window=_crop)


def test_a_window_sized_image_is_the_window():
    cam = Camera((64, 48), (20, 24), 10, 20, np.zeros(1), np.zeros(1), None)
    frame = np.arange(48 * 64, dtype=float).reshape(48, 64)
    assert np.array_equal(cam.crop(frame), frame[WINDOW])
    assert cam.crop(cam.crop(frame)) is not None and np.array_equal(cam.crop(cam.crop(frame)), frame[WINDOW])
