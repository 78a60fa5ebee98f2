"""The fit's standard errors (rigcad.calibrate.fit.posterior_covariance): with residuals that are
correlated within groups of rows (the surface error across neighbouring camera pixels, and in every
capture of a pixel), the cluster-robust covariance against the spread of the estimate over many
seeded replicates of a linear model, a ground truth that does not use the formula; the plain
posterior's understatement it corrects; the prior where the data see nothing; and the fit's
clusters, tiles of the camera window holding every row of a pixel."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.calibrate.fit import CLUSTER_PX, Problem, posterior_covariance

CLUSTERS, ROWS_EACH, PARAMETERS, REPLICATES = 150, 16, 3, 300


def _replicates(shared_sd: float, white_sd: float, seed: int = 3, clusters: int = CLUSTERS,
                rows_each: int = ROWS_EACH):
    """The least-squares estimate of a linear model whose true parameters are 0, over seeded
    replicates of a residual that is a per-cluster shared draw plus white noise, with the plain and
    the cluster-robust standard errors of each replicate. A weak prior (1e-3 per parameter) stands
    for the tolerances, as in the fit."""
    rng = np.random.default_rng(seed)
    count = clusters
    clusters = np.repeat(np.arange(count), rows_each)
    # columns that vary within a cluster and between clusters, as the screen points' slopes do
    jd = rng.normal(size=(len(clusters), PARAMETERS)) + rng.normal(size=(count, PARAMETERS))[clusters]
    root = 1e-3 * np.eye(PARAMETERS)
    jac = np.vstack([jd, root])
    estimates, plain, robust = [], [], []
    for _ in range(REPLICATES):
        y = shared_sd * rng.normal(size=count)[clusters] + white_sd * rng.normal(size=len(clusters))
        z = np.linalg.solve(jac.T @ jac, jd.T @ y)
        fun = np.concatenate([jd @ z - y, root @ z])
        estimates.append(z)
        plain.append(np.sqrt(np.diag(posterior_covariance(jac, fun, root))))
        robust.append(np.sqrt(np.diag(posterior_covariance(jac, fun, root, clusters))))
    return np.std(estimates, axis=0), np.mean(plain, axis=0), np.mean(robust, axis=0)


def test_correlated_residuals_the_clusters_hold_the_spread():
    """Rows of a cluster share most of their residual: the plain posterior states the estimate
    ~2.6 times too tightly (the square root of Kish's design effect 1 + (16 - 1) * 0.5 * 0.8: 16
    rows a cluster, the columns' share within clusters 0.5, the residual's 0.8); the
    cluster-robust one states its spread over the replicates."""
    spread, plain, robust = _replicates(shared_sd=1.0, white_sd=0.5)
    assert plain == pytest.approx(spread / np.sqrt(1 + 15 * 0.5 * 0.8), rel=0.15)
    assert robust == pytest.approx(spread, rel=0.15)


def test_few_clusters_the_leverage_is_taken_out():
    """Twelve clusters, as the camera window's tiles are few: each cluster fixes a good share of
    the three parameters, so the fit absorbs part of its shared residual and the plain scores
    (Liang and Zeger's sandwich) state the spread low (here 0.86 of it, the three parameters'
    mean); with each cluster's leverage taken out (the scores of the fit without it) the spread
    is held (1.00). The bound: 300 replicates estimate a standard deviation to ~4 %, the mean of
    three to ~2.5 %; 10 % lies between the two formulas' figures."""
    spread, plain, robust = _replicates(shared_sd=1.0, white_sd=0.5, seed=4, clusters=12, rows_each=40)
    assert np.mean(robust / spread) == pytest.approx(1.0, abs=0.1), robust / spread


def test_independent_residuals_the_clusters_change_little():
    spread, plain, robust = _replicates(shared_sd=0.0, white_sd=1.0)
    assert plain == pytest.approx(spread, rel=0.15)
    assert robust == pytest.approx(spread, rel=0.15)


def test_what_the_data_do_not_see_keeps_the_prior():
    """A parameter no data row moves: its variance is the prior's, clusters or not."""
    rng = np.random.default_rng(5)
    jd = np.hstack([rng.normal(size=(200, 2)), np.zeros((200, 1))])
    root = np.diag([1.0, 1.0, 2.0])
    fun = np.concatenate([rng.normal(size=200), np.zeros(3)])
    cov = posterior_covariance(np.vstack([jd, root]), fun, root, np.arange(200) // 10)
    assert cov[2, 2] == pytest.approx(0.25, rel=1e-9)
    assert np.allclose(cov[2, :2], 0.0, atol=1e-12)


def test_one_cluster_is_refused():
    jac = np.vstack([np.ones((10, 1)), np.eye(1)])
    with pytest.raises(ValueError, match="two clusters"):
        posterior_covariance(jac, np.ones(11), np.eye(1), np.zeros(10, int))


def test_the_fit_clusters_tiles_of_the_window_with_every_row_of_a_pixel():
    """Each kept residual row (pixel, capture, axis) falls in its pixel's tile; the rows an
    outlier cut dropped are skipped."""
    shape = (3 * CLUSTER_PX, 2 * CLUSTER_PX + 5)
    pixels = np.array([0, CLUSTER_PX - 1, CLUSTER_PX, shape[1] * CLUSTER_PX, shape[1] * CLUSTER_PX + CLUSTER_PX + 1])
    captures = 3
    keep = np.ones(len(pixels) * captures * 2, bool)
    keep[7] = False  # pixel 1, capture 0, axis 1
    prob = SimpleNamespace(data=SimpleNamespace(pixels=pixels), keep=keep, plan=[None] * captures,
                           cam=SimpleNamespace(shape=shape))
    tiles = Problem.clusters(prob)
    per_row = np.repeat([0, 0, 1, 3, 4], captures * 2)[keep]
    assert np.array_equal(tiles, per_row)


def _placement_coverage(run: dict) -> tuple[int, float, float, float]:
    """The placements against the dome over a bench run's trials: how many values, the share within
    one and two standard errors, and the binomial standard error of the first at 68 %."""
    z = np.array([p["error_over_standard_error"] for t in run["per_trial"]
                  for p in t["dome_frame"]["parameters"].values()])
    return len(z), float(np.mean(z <= 1)), float(np.mean(z <= 2)), float(np.sqrt(0.68 * 0.32 / len(z)))


def test_the_bench_placements_standard_errors_cover_their_errors():
    """bench/results/calibrate_standard_errors.json (bench/calibrate.py on the code that states
    them, docs/calibrate-notes.md, "The placements' standard errors"): the paraboloid's and the
    camera's placements against the dome within one standard error for about 68 % of the values,
    within 2.5 binomial standard errors of it (the ten values of one trial share its surface, so
    the binomial error is a floor), and within two for at least 85 %; and docs/calibrate.md's
    standard-error table is this run's (bench/calibrate.py --standard-errors carries it into
    bench/results/calibrate.json, whose rendering tests/test_docs.py holds the page to)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    run = json.loads((root / "bench" / "results" / "calibrate_standard_errors.json").read_text(encoding="utf-8"))
    n, within_1, within_2, sd = _placement_coverage(run)
    assert n == 10 * run["trials"] and run["trials"] >= 6, n
    assert abs(within_1 - 0.68) <= 2.5 * sd, (within_1, sd)
    assert within_2 >= 0.85, within_2
    page = (root / "docs" / "calibrate.md").read_text(encoding="utf-8")
    z = np.array([p["error_over_standard_error"] for t in run["per_trial"] for p in t["dome_frame"]["parameters"].values()])
    stated = (f"| the paraboloid and the camera against the dome | {np.median(z):.2f} | {100 * within_1:.0f} % | "
              f"{100 * within_2:.0f} % |")
    assert stated in page, stated
    carried = json.loads((root / "bench" / "results" / "calibrate.json").read_text(encoding="utf-8"))["standard_errors"]
    assert [t["seed"] for t in carried["per_trial"]] == [t["seed"] for t in run["per_trial"]]
    assert carried["source"] == "bench/results/calibrate_standard_errors.json"
