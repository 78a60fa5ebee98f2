"""The half turn (calibration.half_turn): the highest spacer captured again with it and the screen
turned a half turn, so their wedge flips and the pair's mean tilt is the seating's alone. The
capture plan, the prior's square root and its posterior against closed forms, and the planted
tilts against the wedge and the seating they were drawn within."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.calibrate import model as M, simulate as S
from rigcad.calibrate.fit import posterior_covariance, slope_projected
from rigcad.profile.schema import load_profile
from rigcad.rig import Rig


@pytest.fixture(scope="module")
def rigs(tmp_path_factory):
    out = {}
    for mode in ("highest", "every", "none"):
        path = tmp_path_factory.mktemp("half") / f"{mode}.yaml"
        path.write_text("extends: achutha2006\ncalibration:\n  spacer_heights: [1 mm, 10 mm, 20 mm]\n"
                        f"  half_turn: {mode}\n  screen_tilt: 0.3 deg\n  screen_seating: 0.03 deg\n")
        out[mode] = Rig.from_profile(load_profile(path))
    return out


def test_the_plan_repeats_the_highest_spacer_turned(rigs):
    plan = M.Plan.of(rigs["highest"].profile)
    assert plan.labels == ("h0", "h1", "h2", "h2r") and plan.spacers == (0, 1, 2, 2)
    assert plan.turns.tolist() == [0.0, 0.0, 0.0, math.pi]
    assert plan.heights[3] == plan.heights[2] and plan.heights[0] < plan.heights[1] < plan.heights[2]
    assert [plan.repeats(c) for c in range(4)] == [None, None, None, 2]
    none = M.Plan.of(rigs["none"].profile)
    assert none.labels == ("h0", "h1", "h2") and not none.turns.any()
    every = M.Plan.of(rigs["every"].profile)
    assert every.labels == ("h0", "h1", "h2", "h0r", "h1r", "h2r")
    assert [every.repeats(c) for c in range(6)] == [None, None, None, 0, 1, 2]


def _covariance_by_hand(rig, plan) -> np.ndarray:
    """The prior's covariance in tolerance units: independent, unit variance, but the turned pair's
    tilts, w + e and -w + e' per axis: covariance -W^2 / (W^2 + E^2)."""
    cal = rig.profile.calibration
    c = np.eye(len(M.RIG_NAMES) + len(M.SCREEN_KEYS) * len(plan))
    rho = -cal.screen_tilt ** 2 / (cal.screen_tilt ** 2 + cal.screen_seating ** 2)
    for axis in (1, 2):
        i, j = M.screen_index(2) + axis, M.screen_index(3) + axis
        c[i, j] = c[j, i] = rho
    return c


def test_the_prior_root_whitens_the_pair(rigs):
    rig = rigs["highest"]
    plan = M.Plan.of(rig.profile)
    root = M.prior_root(rig, plan)
    assert np.allclose(root.T @ root, np.linalg.inv(_covariance_by_hand(rig, plan)), rtol=0, atol=1e-9)
    # a half turn at every spacer: each pair whitened alike
    every = M.Plan.of(rigs["every"].profile)
    c = np.eye(len(M.RIG_NAMES) + len(M.SCREEN_KEYS) * len(every))
    cal = rig.profile.calibration
    for k in range(3):
        for axis in (1, 2):
            i, j = M.screen_index(k) + axis, M.screen_index(3 + k) + axis
            c[i, j] = c[j, i] = -cal.screen_tilt ** 2 / (cal.screen_tilt ** 2 + cal.screen_seating ** 2)
    root = M.prior_root(rigs["every"], every)
    assert np.allclose(root.T @ root, np.linalg.inv(c), rtol=0, atol=1e-9)
    # without the half turn, the prior is the tolerances' alone
    assert np.array_equal(M.prior_root(rigs["none"], M.Plan.of(rigs["none"].profile)), np.eye(15 + 6 * 3))


def test_with_no_data_the_posterior_is_the_prior_and_the_mean_tilt_the_seatings(rigs):
    """Data rows that see nothing: the posterior is the prior's covariance, and the pair's mean
    tilt per axis (the frame's, through the first screen) is known to the seating / sqrt 2."""
    rig = rigs["highest"]
    plan = M.Plan.of(rig.profile)
    root = M.prior_root(rig, plan)
    p = len(root)
    jac = np.vstack([np.zeros((50, p)), root])
    cov = posterior_covariance(jac, np.ones(50 + p), root)
    assert np.allclose(cov, _covariance_by_hand(rig, plan), rtol=0, atol=1e-9)
    scale = M.tolerance_scale(rig, len(plan))
    i, j = M.screen_index(2) + 1, M.screen_index(3) + 1
    mean = np.zeros(p)
    mean[[i, j]] = 0.5 * scale[[i, j]]
    assert math.sqrt(mean @ cov @ mean) == pytest.approx(rig.profile.calibration.screen_seating / math.sqrt(2),
                                                          rel=1e-9)


def test_the_planted_pair_shares_its_wedge(rigs):
    """Over 200 seeds: the turned capture's tilt is its spacer's wedge turned with the screen (half a
    turn and the hand's two turns, each within 1 deg) plus two seatings; so the pair's mean lies within
    the seating plus the wedge times the turn's error, and never near the wedge's own size."""
    rig = rigs["highest"]
    plan = M.Plan.of(rig.profile)
    cal = rig.profile.calibration
    means, halves = [], []
    for seed in range(200):
        theta = S.random_misalignment(rig, plan, np.random.default_rng(seed))
        a = theta[M.screen_index(2) + 1: M.screen_index(2) + 3]
        b = theta[M.screen_index(3) + 1: M.screen_index(3) + 3]
        means.append(np.hypot(*(a + b)) / 2)
        halves.append(np.hypot(*(a - b)) / 2)
        assert theta[M.screen_index(3)] == theta[M.screen_index(2)]  # the same spacer's height
    bound = cal.screen_seating + cal.screen_tilt * 2 * M.PLACEMENT_TURN_RAD / 2
    assert max(means) <= bound
    assert max(halves) <= cal.screen_tilt + cal.screen_seating
    assert np.median(halves) > 10 * np.median(means)


def test_the_slope_projection_works_in_the_sample_frame():
    """A turn of a pixel's ray about its dome point moves its points on every screen along one
    sample-frame vector, by each screen's reach: the projection takes it all out at factor 1, for
    screens square and turned a half turn alike, and leaves a residual across it untouched. Read in
    each screen's own axes (the projection before the half turn), the turned screen's signature
    points the other way and most of it stays."""
    rng = np.random.default_rng(3)
    n = 200
    reach = rng.uniform(100, 250, (n, 3))
    turns = np.array([0.01, -0.02, math.pi + 0.015])
    axes = np.stack([[[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]] for t in turns])
    delta = rng.normal(size=(n, 2)) * 1e-3
    signature = np.einsum("kji,nkj->nki", axes, reach[:, :, None] * delta[:, None, :])
    assert np.abs(slope_projected(signature, reach, axes, 1.0)).max() < 1e-15
    half = slope_projected(signature, reach, axes, 0.9)
    assert np.allclose(half, 0.1 * signature, rtol=0, atol=1e-15)
    # a residual orthogonal to every signature (per pixel, per axis: along (reach_1, -reach_0, 0))
    across = np.zeros((n, 3, 2))
    across[:, 0], across[:, 1] = reach[:, 1:2] * delta, -reach[:, 0:1] * delta
    across = np.einsum("kji,nkj->nki", axes, across)
    assert np.allclose(slope_projected(across, reach, axes, 1.0), across, rtol=0, atol=1e-15)
    square = np.broadcast_to(np.eye(2), (3, 2, 2))
    assert np.abs(slope_projected(signature, reach, square, 1.0)).max() > 0.3 * np.abs(signature).max()
