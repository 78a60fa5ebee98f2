"""`basis --simulate` reads the corrected map as data: each way a map can be wrong is one line
naming the file and the array (CalibrationMapError), never a traceback and never the design map
silently in its place."""

from __future__ import annotations

import io
import os
import resource
import zipfile

import numpy as np
import pytest

from rigcad.calibrate import CORRECTED_MAP, CalibrationMapError, load_corrected_map

RES = (64, 48)  # camera (width, height) px


def _good() -> dict:
    d = np.full((10, 20, 3), np.nan)
    d[2:8, 3:15] = (0.0, 0.6, 0.8)
    return dict(direction=d, row0=np.int64(5), col0=np.int64(7), resolution=np.array(RES),
                uncertainty_rad=np.zeros((10, 20)))


def _write(tmp_path, arrays: dict | None = None, raw: bytes | None = None):
    path = tmp_path / "p" / CORRECTED_MAP
    path.parent.mkdir(parents=True, exist_ok=True)
    if raw is None:
        buf = io.BytesIO()
        np.savez_compressed(buf, **arrays)
        raw = buf.getvalue()
    path.write_bytes(raw)
    return path


def _pickled(tmp_path):
    buf = io.BytesIO()
    bad = {**_good(), "direction": np.array([[{"x": 1}]], dtype=object).reshape(1, 1, 1)}
    np.savez(buf, **bad, allow_pickle=True)
    return buf.getvalue()


CASES = {
    "garbage": (lambda t: _write(t, raw=b"garbage" * 100), "not a readable .npz"),
    "pickled object array": (lambda t: _write(t, raw=_pickled(t)), "holds Python objects"),
    "no direction": (lambda t: _write(t, {k: v for k, v in _good().items() if k != "direction"}), "no 'direction' array"),
    "1-D direction": (lambda t: _write(t, {**_good(), "direction": np.zeros(3)}), "'direction' has 1 dimensions"),
    "string direction": (lambda t: _write(t, {**_good(), "direction": np.full((2, 2, 3), "x")}), "not float"),
    "row0 an array": (lambda t: _write(t, {**_good(), "row0": np.arange(3)}), "'row0' has 1 dimensions"),
    "NaN in one component": (lambda t: _write(t, {**_good(), "direction": _spoil(np.nan, 1)}), "only partly NaN"),
    "1e300": (lambda t: _write(t, {**_good(), "direction": _spoil(1e300, None)}), "a component of 1e+300"),
    "short vectors": (lambda t: _write(t, {**_good(), "direction": _spoil(0.5, None)}), "not unit directions"),
    "inf": (lambda t: _write(t, {**_good(), "direction": _spoil(np.inf, 0)}), "infinite values"),
    "all NaN": (lambda t: _write(t, {**_good(), "direction": np.full((10, 20, 3), np.nan)}), "NaN at every pixel"),
    "window outside the camera": (lambda t: _write(t, {**_good(), "row0": np.int64(40)}), "does not lie inside"),
    "bigger than the camera": (lambda t: _write(t, {**_good(), "direction": np.zeros((49, 2, 3))}),
                               "need (rows <= 48, cols <= 64, 3)"),
    "another camera": (lambda t: _write(t, {**_good(), "resolution": np.array([1360, 1024])}),
                       "made for a 1360 x 1024 px camera, the profile's is 64 x 48"),
    "a link to /etc/passwd": (lambda t: _link(t, "/etc/passwd"), "not a readable .npz"),
    "a FIFO": (lambda t: _fifo(t), "a FIFO (named pipe), not a file"),
}


def _spoil(value, component):
    d = _good()["direction"].copy()
    if component is None:
        d[3, 4] = value
    else:
        d[3, 4, component] = value
    return d


def _link(tmp_path, target):
    path = tmp_path / "p" / CORRECTED_MAP
    path.parent.mkdir(parents=True, exist_ok=True)
    path.symlink_to(target)


def _fifo(tmp_path):
    path = tmp_path / "p" / CORRECTED_MAP
    path.parent.mkdir(parents=True, exist_ok=True)
    os.mkfifo(path)


@pytest.mark.parametrize("name", list(CASES))
def test_a_map_that_is_not_one_is_refused_in_one_line(tmp_path, name):
    make, words = CASES[name]
    make(tmp_path)
    with pytest.raises(CalibrationMapError) as info:
        load_corrected_map(tmp_path, "p", RES)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(tmp_path / "p" / CORRECTED_MAP)) and words in text, text
    assert "root:" not in text


def test_a_good_map_reads_back(tmp_path):
    _write(tmp_path, _good())
    m = load_corrected_map(tmp_path, "p", RES)
    assert (m.row0, m.col0) == (5, 7) and m.direction.shape == (10, 20, 3)
    assert np.array_equal(m.at(np.array([5 + 3]), np.array([7 + 4])), [[0.0, 0.6, 0.8]])
    assert load_corrected_map(tmp_path, "other", RES) is None


def test_a_header_claiming_100000_squared_is_refused_before_allocating(tmp_path):
    """The map's budget is the camera's window: a header of 100000 x 100000 x 3 is refused from its
    shape, without allocating the 224 GiB it claims."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (100_000, 100_000, 3)})
    path = tmp_path / "p" / CORRECTED_MAP
    path.parent.mkdir(parents=True)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("direction.npy", header.getvalue() + b"\0" * (1 << 20))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(CalibrationMapError, match=r"'direction' of shape \(100000, 100000, 3\): need"):
        load_corrected_map(tmp_path, "p", RES)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024  # KiB: nothing allocated


def test_a_map_that_covers_no_sampled_pixel_is_refused(table31_rig, tmp_path):
    """Directions only between the sampled pixels (stride 16): the simulation would run on the
    design map while saying it used the corrected one."""
    from rigcad.basis.acquire import camera_view
    from rigcad.basis.projector import zone_of
    from rigcad.errors import BasisError

    rig = table31_rig
    zone = zone_of(rig)
    design = camera_view(rig, zone, 16)
    rows, cols = design.pixels.row[design.keep], design.pixels.col[design.keep]
    row0, col0 = int(rows.min()), int(cols.min())
    h, w = int(rows.max()) - row0 + 1, int(cols.max()) - col0 + 1
    direction = np.full((h, w, 3), np.nan)
    direction[1::16, 1::16] = (0.0, 0.0, 1.0)  # off every sampled pixel by one
    res = tuple(rig.profile.camera.resolution)
    _write(tmp_path, dict(direction=direction, row0=np.int64(row0), col0=np.int64(col0)))
    corrected = load_corrected_map(tmp_path, "p", res)
    with pytest.raises(BasisError, match=r"has no direction at any of the \d+ camera pixels sampled \(every 16 px\)"):
        camera_view(rig, zone, 16, corrected=corrected)
    direction[::16, ::16] = (0.0, 0.0, 1.0)  # now on them: read
    _write(tmp_path, dict(direction=direction, row0=np.int64(row0), col0=np.int64(col0)))
    got = camera_view(rig, zone, 16, corrected=load_corrected_map(tmp_path, "p", res)).wo
    assert np.isin(got[:, 2], [1.0]).any()
