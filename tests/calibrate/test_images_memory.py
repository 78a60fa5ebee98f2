"""``calibrate --simulate`` estimates its memory from the camera's resolution before any work and
refuses, naming camera.resolution and the largest camera that fits (the schema allows 16384 x 16384:
it grew to 4.45 GB before a MemoryError line)."""

from __future__ import annotations

import dataclasses

import pytest

from rigcad.cli.calibrate import (IMAGES_BYTES_PER_PIXEL, IMAGES_FIXED_BYTES, SIMULATE_BYTES_PER_PIXEL,
                                  SIMULATE_FIXED_BYTES, check_simulation_memory)
from rigcad.engine import ResourceError
from rigcad.profile.schema import load_profile


def _with(resolution):
    p = load_profile("achutha2006")
    return dataclasses.replace(p, camera=dataclasses.replace(p.camera, resolution=resolution))


def test_the_measured_runs_fit_their_estimates():
    """Each measured peak (MiB, the constants' comment) is under its estimate, and within 1.5x of it."""
    runs = [(True, 680 * 512, 657), (True, 1360 * 1024, 1192), (True, 2040 * 1536, 2047),
            (False, 680 * 512, 447), (False, 1360 * 1024, 843)]
    for simulate, pixels, measured_mib in runs:
        fixed, per = ((SIMULATE_FIXED_BYTES, SIMULATE_BYTES_PER_PIXEL) if simulate else
                      (IMAGES_FIXED_BYTES, IMAGES_BYTES_PER_PIXEL))
        est = fixed + per * pixels
        assert measured_mib * 2 ** 20 <= est < 1.5 * measured_mib * 2 ** 20, (simulate, pixels, est / 2 ** 20)


def test_images_are_refused_past_the_machine_too():
    with pytest.raises(ResourceError, match=r"calibrate --images would need about 112 GiB"):
        check_simulation_memory(_with((16384, 16384)), memory=24 << 30, simulate=False)
    check_simulation_memory(_with((1360, 1024)), memory=8 << 30, simulate=False)


def test_the_default_camera_fits_an_8_gib_machine():
    check_simulation_memory(_with((1360, 1024)), memory=8 << 30)  # 1.2 GiB measured, 1.2 GiB estimated


def test_a_camera_past_the_machine_is_refused_with_the_largest_that_fits():
    memory = 24 << 30
    with pytest.raises(ResourceError) as info:
        check_simulation_memory(_with((16384, 16384)), memory=memory)
    text = str(info.value)
    largest = int((memory - SIMULATE_FIXED_BYTES) / SIMULATE_BYTES_PER_PIXEL)
    assert text.startswith("camera.resolution [16384, 16384]: calibrate --simulate would need about 140 GiB"), text
    assert f"the largest camera that fits has {largest:,} px" in text, text
    side = int(largest ** 0.5)
    check_simulation_memory(_with((side, side)), memory=memory)  # the size it names fits
    with pytest.raises(ResourceError):
        check_simulation_memory(_with((side + 2, side + 2)), memory=memory)  # and just past it does not


def test_the_command_refuses_before_any_work(tmp_path, capsys, monkeypatch):
    from rigcad.cli.main import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "huge.yaml").write_text("extends: achutha2006\ncamera:\n  resolution: [16384, 16384]\n")
    assert main(["calibrate", "huge.yaml", "--simulate", "--exports", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rigcad: error: camera.resolution [16384, 16384]") and "\n" not in err, err
    assert not (tmp_path / "x").exists()
