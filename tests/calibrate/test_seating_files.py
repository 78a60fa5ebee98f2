"""`rigcad calibrate --seating` reads each calibration.json as data (rigcad.export.readback): deep
nesting, huge integers, sparse or endless files, devices, figures past any rig's, a file of many keys
and one calibration given twice are each refused in one short line naming the file; nothing written."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

LABELS = ("h0", "h1", "h0r", "h1r")  # the default profile's plan


def _report(rng) -> dict:
    screens = {k: {f"tilt_{a}_deg": {"value": float(rng.normal(0, 0.1)), "standard_error": 0.001} for a in "xy"}
               for k in LABELS}
    params = {"camera_dx_mm": {"value": 0.1, "standard_error": 0.01}}
    return {"against_the_dome": {"parameters": params, "screens": screens}}


def _set_tilt(report: dict, value) -> dict:
    out = json.loads(json.dumps(report))
    out["against_the_dome"]["screens"]["h1"]["tilt_x_deg"]["value"] = value
    return out


def _run(tmp_path, capsys, *names) -> tuple[int, str]:
    from rigcad.cli.main import main

    rc = main(["calibrate", "achutha2006", "--seating", *names, "--exports", str(tmp_path / "exports")])
    err = capsys.readouterr().err.strip()
    assert rc == 0 or not (tmp_path / "exports" / "achutha2006").exists()  # a refusal writes nothing
    return rc, err


def _sparse(path, size: int) -> None:
    with open(path, "wb") as fh:
        fh.truncate(size)


CASES = {
    "nested brackets": (lambda p: p.write_text("[" * 100_000 + "]" * 100_000), "nested 100000 levels deep"),
    "an integer of 400 digits": (lambda p: p.write_text('{"a": 1' + "0" * 399 + "}"), "an integer of 400 digits"),
    "a sparse 1 GiB file": (lambda p: _sparse(p, 1 << 30), "1 GiB, more than the 4 MiB a calibration.json can be"),
    "/dev/zero": (lambda p: p.symlink_to("/dev/zero"), "a device, not a file"),
    "a FIFO": (lambda p: os.mkfifo(p), "a FIFO (named pipe), not a file"),
    "a tilt of 1.7e308": (lambda p: p.write_text(json.dumps(_set_tilt(_report(np.random.default_rng(1)), 1.7e308))),
                          "against_the_dome.screens.h1.tilt_x_deg.value is 1.7e+308, outside -90..90 deg"),
    "a tilt of -1.7e308": (lambda p: p.write_text(json.dumps(_set_tilt(_report(np.random.default_rng(1)), -1.7e308))),
                           "is -1.7e+308, outside -90..90 deg"),
    "100,000 captures": (lambda p: p.write_text(json.dumps({"against_the_dome": {"parameters": {}, "screens": {
        f"h{i}": {} for i in range(100_000)}}})), "(100000 in all)"),
    "300,000 captures": (lambda p: p.write_text(json.dumps({"against_the_dome": {"parameters": {}, "screens": {
        f"h{i}": {} for i in range(300_000)}}})), "more than the 4 MiB a calibration.json can be"),
    "a key twice": (lambda p: p.write_text('{"against_the_dome": {}, "against_the_dome": {}}'),
                    "the key 'against_the_dome' twice"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_a_file_that_is_no_calibration_is_one_short_line(tmp_path, capsys, name):
    make, words = CASES[name]
    good = tmp_path / "good.json"
    good.write_text(json.dumps(_report(np.random.default_rng(0))))
    bad = tmp_path / "bad.json"
    make(bad)
    rc, err = _run(tmp_path, capsys, str(good), str(bad))
    assert rc != 0 and "\n" not in err and words in err, err
    # one line a terminal shows whole: the file's name, its key and the reason (300,000 keys: 3.2 MB before)
    assert len(err) < 400, len(err)
    assert err.startswith(f"rigcad: error: {bad}"), err


def test_one_calibration_given_twice_is_refused(tmp_path, capsys):
    """The same file twice (once as its folder) or a copy of it would measure a seating of 0."""
    folder = tmp_path / "a" / "calibrate"
    folder.mkdir(parents=True)
    text = json.dumps(_report(np.random.default_rng(0)))
    (folder / "calibration.json").write_text(text)
    rc, err = _run(tmp_path, capsys, str(folder), str(folder / "calibration.json"))
    assert rc != 0 and "the same calibration as" in err and "(the same file)" in err, err
    (tmp_path / "copy.json").write_text(text)
    rc, err = _run(tmp_path, capsys, str(folder), str(tmp_path / "copy.json"))
    assert rc != 0 and "(the same bytes)" in err, err
    (tmp_path / "other.json").write_text(json.dumps(_report(np.random.default_rng(1))))
    rc, err = _run(tmp_path, capsys, str(folder), str(tmp_path / "other.json"))
    assert rc == 0 and err == "", err  # two calibrations of separate layings: measured
