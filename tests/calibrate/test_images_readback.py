"""A capture's frames read as data (images.read_image over rigcad.export.readback): what is not a
frame is named for what it is, a bomb is refused from its header, a frame with NaN or infinity is
refused naming that very file, and nothing a library says reaches the terminal."""

from __future__ import annotations

import io
import os

import numpy as np
import pytest
from PIL import Image

from rigcad.calibrate.images import CaptureError, capture_path, read_image

RES = (32, 24)  # (width, height) px


def _tiff(arr: np.ndarray, compression: str | None = None) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(arr).save(buf, format="TIFF", **({"compression": compression} if compression else {}))
    return buf.getvalue()


def _refusal(path, capfd) -> str:
    with pytest.raises(CaptureError) as info:
        read_image(path, RES)
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)  # no library line, no warning on the terminal
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path)), text
    return text


@pytest.mark.parametrize("make, words", [
    (lambda p: os.mkfifo(p), "a FIFO (named pipe), not a file"),
    (lambda p: p.mkdir(), "a folder, not a file"),
    (lambda p: p.symlink_to(p), "a loop of symbolic links"),
    (lambda p: p.symlink_to("/dev/zero"), "a device, not a file"),
])
def test_what_is_no_frame_is_named_for_what_it_is_not_missing(tmp_path, capfd, make, words):
    path = tmp_path / "h0_white.png"
    make(path)
    assert capture_path(tmp_path, "h0", "white") == path
    assert words in _refusal(path, capfd)


def test_a_missing_frame_says_the_naming_scheme(tmp_path, capfd):
    assert "missing; naming scheme h<spacer>_<frame>" in _refusal(tmp_path / "h0_white.png", capfd)


@pytest.mark.parametrize("mode, size", [("L", (100_000, 100_000)), ("RGBA", (13_375, 13_375))])
def test_a_bomb_is_refused_from_its_header(tmp_path, capfd, mode, size):
    """A PNG header of 10^10 px (past Pillow's error) or a 13375^2 RGBA one (past its warning, 716 MB
    decoded): one line before any pixel is decoded."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    colour = {"L": 0, "RGBA": 6}[mode]
    path = tmp_path / "h0_white.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", *size, 8, colour, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(b"\0" * 4096)) + chunk(b"IEND", b""))
    assert "the camera's is 32 x 24" in _refusal(path, capfd)


def test_a_corrupt_deflate_tiff_is_one_line_with_libtiffs_reason(tmp_path, capfd):
    data = bytearray(_tiff(np.full((24, 32), 200, np.uint8), "tiff_adobe_deflate"))
    start = data.index(b"\x78")  # the zlib stream: spoil its body
    data[start + 2: start + 12] = b"\xff" * 10
    path = tmp_path / "h0_white.tif"
    path.write_bytes(bytes(data))
    assert "not a readable PNG or TIFF" in _refusal(path, capfd)


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_a_float_frame_with_nan_or_inf_is_refused_naming_it(tmp_path, capfd, value):
    arr = np.full((24, 32), 0.5, np.float32)
    arr[3:6, 4:9] = value
    path = tmp_path / "h0_white.tif"
    path.write_bytes(_tiff(arr))
    assert "15 pixel value(s) NaN or infinite" in _refusal(path, capfd)


def test_a_frame_larger_than_any_of_the_camera_is_refused_from_its_size(tmp_path, capfd):
    path = tmp_path / "h0_white.png"
    with open(path, "wb") as fh:
        fh.truncate(1 << 30)  # sparse
    assert "1 GiB, more than the" in _refusal(path, capfd)


def test_a_good_frame_reads(tmp_path):
    arr = np.arange(24 * 32, dtype=np.uint16).reshape(24, 32)
    path = tmp_path / "h0_white.tif"
    path.write_bytes(_tiff(arr))
    assert np.array_equal(read_image(path, RES), arr / 65535.0)
