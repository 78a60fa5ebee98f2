"""The simulation's figures of the corrected map against the truth (rigcad.calibrate.run.compare):
the frame's rotation and the uncertainty's coverage, on directions built from known rotations and
errors (closed forms), not from a calibration."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.calibrate.run import _coverage, _frame


def _directions(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    up = rng.normal(size=(n, 3))
    up[:, 2] = np.abs(up[:, 2]) + 0.3
    return up / np.linalg.norm(up, axis=1)[:, None]


def _turned(up: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``up`` turned by the rotation vector ``w`` (Rodrigues, exact)."""
    angle = np.linalg.norm(w)
    k = w / angle
    return (up * math.cos(angle) + np.cross(k, up) * math.sin(angle)
            + np.outer(up @ k, k) * (1 - math.cos(angle)))


def test_the_frame_is_the_rotation_between_the_maps():
    up = _directions(2000, 0)
    w = np.array([1e-3, -2e-3, 5e-4])  # 0.13 deg of tilt, 0.03 of turn
    source = np.ones(len(up), np.int8)
    source[:300] = 2  # filled pixels: left out (their error is the surface's, not the frame's)
    d = _turned(up, w)
    d[:300] += 0.05
    f = _frame({"direction": d, "source": source}, up, np.ones(len(up), bool))
    assert f["pixels"] == 1700
    assert f["tilt_deg"] == pytest.approx(math.degrees(math.hypot(w[0], w[1])), rel=1e-4)
    assert f["turn_deg"] == pytest.approx(math.degrees(w[2]), rel=1e-3)
    # what is left is the small-angle model's second order: (2.3 mrad)^2 ~ 5e-6 rad
    assert f["measured_error_without_it_deg"]["max"] < 1e-3


def test_a_map_off_its_frame_and_noisy_keeps_the_noise():
    up = _directions(4000, 1)
    rng = np.random.default_rng(2)
    noisy = up + rng.normal(scale=1e-4, size=up.shape)  # ~0.14 mrad RMS across the direction
    d = _turned(noisy / np.linalg.norm(noisy, axis=1)[:, None], np.array([0.0, 3e-3, 0.0]))
    f = _frame({"direction": d, "source": np.ones(len(up), np.int8)}, up, np.ones(len(up), bool))
    assert f["tilt_deg"] == pytest.approx(math.degrees(3e-3), rel=0.02)
    # the noise's own angle: Rayleigh with sigma 1e-4 rad per axis, median sigma sqrt(2 ln 2)
    assert f["measured_error_without_it_deg"]["p50"] == pytest.approx(
        math.degrees(1e-4 * math.sqrt(2 * math.log(2))), rel=0.1)


def test_coverage_counts_errors_within_their_uncertainty():
    ratio = np.array([0.5, 0.9, 1.5, 2.5, 0.2, 3.0, 1.0, 0.1])
    unc = np.full(8, 1e-3)
    source = np.array([1, 1, 1, 1, 2, 2, 2, 1], np.int8)
    got = _coverage(np.degrees(ratio * unc), {"uncertainty_rad": unc, "source": source}, np.ones(8, bool))
    assert got["measured"] == {"pixels": 5, "within_1": 0.6, "within_2": 0.8,
                               "error_over_uncertainty_p50": pytest.approx(0.9)}
    assert got["filled"]["within_1"] == pytest.approx(2 / 3) and got["filled"]["within_2"] == pytest.approx(2 / 3)
    assert got["model_only"] == {"pixels": 0}
