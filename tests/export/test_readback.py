"""rigcad.export.readback: what rigcad reads back is data. Each reader refuses in one line naming the
file, before it allocates what a hostile header claims, and never quotes the content."""

from __future__ import annotations

import io
import json
import os
import resource
import zipfile

import numpy as np
import pytest

from rigcad.errors import ExportError
from rigcad.export import readback as R


def _error_line(info) -> str:
    text = str(info.value)
    assert "\n" not in text, text
    return text


# -- files ---------------------------------------------------------------------------------------------

def test_a_file_that_is_no_file_is_named_for_what_it_is(tmp_path):
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "folder").mkdir()
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    cases = {tmp_path / "fifo": "a FIFO (named pipe), not a file", tmp_path / "folder": "a folder, not a file",
             "/dev/zero": "a device, not a file", tmp_path / "loop": "a loop of symbolic links",
             tmp_path / "dangling": "missing (a symbolic link to nowhere)", tmp_path / "gone": "gone: missing"}
    for path, words in cases.items():
        with pytest.raises(ExportError) as info:
            R.read_bytes(path, "a test file", 1000)
        assert words in _error_line(info), (path, str(info.value))


def test_a_file_past_the_cap_is_refused_from_its_size_without_reading_it(tmp_path):
    """A sparse file of 1 GiB: refused from fstat; the process's peak memory does not grow by it."""
    path = tmp_path / "sparse"
    with open(path, "wb") as fh:
        fh.truncate(1 << 30)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ExportError) as info:
        R.read_bytes(path, "a test file", 1 << 20)
    assert "1 GiB, more than the 1 MiB a test file can be" in _error_line(info)
    # ru_maxrss in KiB: 100 MiB of slack for the test process's own noise, ten times under the file
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024
    path.write_bytes(b"x" * 10)
    assert R.read_bytes(path, "a test file", 10) == b"x" * 10  # the cap itself is allowed


# -- JSON ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, words", [
    ("[" * 100_000 + "]" * 100_000, "nested 100000 levels deep"),
    ('{"a": 1' + "0" * 400 + "}", "an integer of 401 digits"),
    ('{"a": 1e400}', "past the largest float"),
    ('{"a": NaN}', "NaN, not a number JSON allows"),
    ('{"a": -Infinity}', "-Infinity, not a number JSON allows"),
    ('{"a": 1, "a": 2}', "the key 'a' twice in one object"),
    ('{"a": 1', "Expecting"),
    (b'{"a": "\xff"}', "not UTF-8: byte 0xff at offset 7"),
])
def test_json_that_is_no_report_is_refused(tmp_path, text, words):
    path = tmp_path / "r.json"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(ExportError) as info:
        R.read_json(path, "a report", 1 << 20)
    line = _error_line(info)
    assert line.startswith(f"{path}: not a readable JSON file") and words in line, line
    assert len(line) < 400, len(line)  # one short line, whatever the file holds


def test_json_depth_leaves_strings_out():
    assert R.json_depth(b'["[[[", {"a": [1]}]') == 3
    assert R.json_depth(b'["\\\\", [[]]]') == 3  # an escaped backslash ends before the quote
    assert R.json_depth(b'["\\"[[[["]') == 1  # an escaped quote does not end the string
    deep = b"[" * 64 + b"]" * 64
    assert R.json_depth(deep) == 64 and R.parse_json(deep, "x") is not None  # the limit itself is read


def test_a_report_reads_back_as_written(tmp_path):
    data = {"a": [1, 2.5, None, True, "x"], "b": {"c": -3}}
    (tmp_path / "r.json").write_text(json.dumps(data))
    assert R.read_json(tmp_path / "r.json", "a report", 1000)[0] == data


def test_names_are_cut_in_a_refusal():
    many = R.names(f"k{i}" for i in range(300_000))
    assert many.endswith(", ... (300000 in all)]") and len(many) < 200, many
    assert R.names(["x" * 5000]) == "['" + "x" * 36 + "...]"  # 40 characters of its repr


# -- npz -----------------------------------------------------------------------------------------------

def _npz(tmp_path, **arrays) -> os.PathLike:
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    path = tmp_path / "m.npz"
    path.write_bytes(buf.getvalue())
    return path


SPEC = {"a": R.ArraySpec("f", 2), "n": R.ArraySpec("iu", 0)}


def test_npz_reads_only_what_is_asked(tmp_path):
    path = _npz(tmp_path, a=np.arange(6.0).reshape(2, 3), n=np.int64(4), other=np.zeros((2000, 2000)))
    got = R.read_npz(path, "a test map", SPEC, limit=1 << 20, budget=1000)  # 'other' (32 MB) never inflated
    assert np.array_equal(got["a"], np.arange(6.0).reshape(2, 3)) and int(got["n"]) == 4


@pytest.mark.parametrize("arrays, words", [
    (dict(a=np.array([{"x": 1}], dtype=object).reshape(1, 1), n=np.int64(1)), "Python objects"),
    (dict(a=np.zeros((2, 2), dtype="<U3"), n=np.int64(1)), "not float"),
    (dict(a=np.zeros(3), n=np.int64(1)), "1 dimensions"),
    (dict(a=np.zeros((2, 2))), "no 'n' array"),
    (dict(a=np.zeros((100, 100)), n=np.int64(1)), "would take 78.1 KiB"),
])
def test_npz_arrays_are_checked_from_their_headers(tmp_path, arrays, words):
    buf = io.BytesIO()
    np.savez(buf, **arrays, allow_pickle=True) if arrays["a"].dtype == object else np.savez(buf, **arrays)
    (tmp_path / "m.npz").write_bytes(buf.getvalue())
    with pytest.raises(ExportError) as info:
        R.read_npz(tmp_path / "m.npz", "a test map", SPEC, limit=1 << 20, budget=1 << 16)
    assert words in _error_line(info), str(info.value)


def test_a_header_claiming_224_gib_is_refused_before_allocating(tmp_path):
    """A .npy header that claims 100000 x 100000 x 3 float64 over a few bytes of data."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (100_000, 100_000, 3)})
    with zipfile.ZipFile(tmp_path / "m.npz", "w") as zf:
        zf.writestr("a.npy", header.getvalue() + b"\0" * 64)
        zf.writestr("n.npy", b"garbage")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ExportError) as info:
        R.read_npz(tmp_path / "m.npz", "a test map", {"a": R.ArraySpec("f", 3)}, limit=1 << 20, budget=1 << 30)
    assert "would take 224 GiB" in _error_line(info)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024  # KiB: nothing allocated


def test_garbage_and_truncated_npz_are_refused(tmp_path):
    (tmp_path / "g.npz").write_bytes(b"PK\x03\x04 not a zip at all")
    with pytest.raises(ExportError, match="not a readable .npz"):
        R.read_npz(tmp_path / "g.npz", "a test map", SPEC, limit=1 << 20, budget=1 << 20)
    buf = io.BytesIO()
    np.save(buf, np.zeros((4, 4)))
    with zipfile.ZipFile(tmp_path / "t.npz", "w") as zf:
        zf.writestr("a.npy", buf.getvalue()[:-8])  # a header that claims 128 bytes over 120
        zf.writestr("n.npy", b"")
    with pytest.raises(ExportError, match="'a' holds 120 bytes where its header says 128"):
        R.read_npz(tmp_path / "t.npz", "a test map", SPEC, limit=1 << 20, budget=1 << 20)


# -- images --------------------------------------------------------------------------------------------

def _png(width: int, height: int, mode: str = "L") -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new(mode, (width, height)).save(buf, format="PNG")
    return buf.getvalue()


def test_an_image_bigger_than_asked_is_refused_before_decoding(recwarn):
    """13375 x 13375 RGBA (just under Pillow's bomb error, over its warning): refused from the
    header, no warning left over, no pixel decoded (the image would be 716 MB)."""
    import struct
    import zlib as z

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", z.crc32(kind + body))

    side = 13375
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", side, side, 8, 6, 0, 0, 0))
           + chunk(b"IDAT", z.compress(b"\0" * 1000)) + chunk(b"IEND", b""))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(ExportError) as info:
        R.open_image(png, "big.png", lambda size: None if size == (64, 48) else "the camera's is 64 x 48")
    assert _error_line(info) == "big.png: 13375 x 13375 px, the camera's is 64 x 48"
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024
    assert not [w for w in recwarn.list if "DecompressionBomb" in str(w.category)]


def test_a_bomb_past_pillows_limit_is_one_line():
    import struct
    import zlib as z

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", z.crc32(kind + body))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 100_000, 100_000, 8, 0, 0, 0, 0))
           + chunk(b"IEND", b""))
    with pytest.raises(ExportError) as info:
        R.open_image(png, "bomb.png", lambda size: "the camera's is 64 x 48")
    assert _error_line(info) == "bomb.png: its header claims 10,000,000,000 px: the camera's is 64 x 48"


def test_an_image_of_the_asked_size_decodes():
    im = R.open_image(_png(64, 48), "ok.png", lambda size: None if size == (64, 48) else "no")
    assert np.asarray(im).shape == (48, 64)


@pytest.mark.parametrize("make", [
    lambda p: p.write_text("[" * 100_000 + "]" * 100_000),
    lambda p: os.mkfifo(p),
    lambda p: p.write_text('{"inputs_key": "k", "inputs_key": "k"}'),
    lambda p: p.symlink_to("/dev/zero"),
])
def test_a_manifest_that_is_no_manifest_means_rebuild(tmp_path, make):
    """rigcad's own manifests read back (export.manifest.up_to_date, the build's reuse): a nesting
    bomb (a RecursionError traceback from `rigcad stl` before), a FIFO or a device is no manifest."""
    from rigcad.export.manifest import up_to_date

    make(tmp_path / "manifest.json")
    assert R.own_json(tmp_path / "manifest.json") is None
    assert up_to_date(tmp_path, "k") is False


def test_a_made_from_record_that_is_a_nesting_bomb_is_no_record(tmp_path):
    """export.atomic.read_made_from reads 4096 bytes: 4096 brackets made json raise RecursionError."""
    from rigcad.export.atomic import made_from_path, read_made_from

    folder = tmp_path / "check"
    folder.mkdir()
    made_from_path(folder).write_bytes(b"[" * 4096)
    assert read_made_from(folder) is None
    made_from_path(folder).write_text(json.dumps({"profile_sha256": "a" * 64}))
    assert read_made_from(folder) == "a" * 64
