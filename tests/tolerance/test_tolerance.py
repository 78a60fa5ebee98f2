"""rigcad.tolerance: bit-identical Monte Carlo on every engine, inverse limits checked by tracing at
the limit with the vectorised exact path, sweeps, and the command line."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest

from rigcad.check import montecarlo as MC
from rigcad.check.scene import analytic_optics
from rigcad.check.trace3d import trace
from rigcad.engine import LOCAL_DASK, Engine, EngineError
from rigcad.errors import ProfileError
from rigcad.tolerance.limits import run_limits
from rigcad.check.montecarlo import Job, run_monte_carlo
from rigcad.tolerance.params import PARAMETERS

#: A small run for the engine comparisons: 12 builds x 300 rays per path, batched 3 to a task
SAMPLES, RAYS = 12, 300


@pytest.fixture(scope="module")
def serial_mc(table31_rig):
    return run_monte_carlo(table31_rig, SAMPLES, RAYS, Engine(1))


def _same(a, b):
    assert a.summary == b.summary  # every summary figure, bit for bit (floats compared exactly)
    assert list(a.columns) == list(b.columns)
    for k in a.columns:
        assert np.array_equal(a.columns[k], b.columns[k]), k


def test_monte_carlo_is_not_vacuous(serial_mc, table31_rig):
    c = serial_mc.columns
    assert len(c["sample"]) == SAMPLES and np.array_equal(c["sample"], np.arange(SAMPLES))
    tol = table31_rig.profile.tolerancing
    # every build is perturbed within its tolerances, and builds differ
    assert np.all(np.hypot(c["dome_dx_mm"], c["dome_dy_mm"]) <= tol.dome_offset)
    assert np.all(c["paraboloid_tilt_rad"] <= tol.paraboloid_tilt)
    assert len(set(c["max_spot_radius_mm"].tolist())) == SAMPLES
    # the summary's percentiles are those of the column (numpy's median, not the summary's code)
    fig = serial_mc.summary["figures"]["max_spot_radius_mm"]
    assert fig["p50"] == pytest.approx(float(np.median(c["max_spot_radius_mm"])), rel=1e-12)
    assert fig["max"] == float(np.max(c["max_spot_radius_mm"]))


def test_monte_carlo_spots_match_an_independent_retrace(serial_mc, table31_rig):
    """Each sample's projector spot radius, re-traced from the perturbation the table records
    (offsets, tilt, tilt axis) through the vectorised exact path (numpy passes, not the compiled
    kernel the Monte Carlo runs) and measured here as max |miss| of the rays that return.
    Replaces a 60x window (0.05 < p50 < 3 mm) around the median."""
    from rigcad.check.sources import annulus_rays
    from rigcad.optics.frames import Misalignment

    rig, c = table31_rig, serial_mc.columns
    tol = rig.profile.tolerancing
    optics, design = analytic_optics(rig), rig.incidence
    ray_seed = int(tol.seed) + 1  # the Monte Carlo's ray seed: tolerancing.seed + 1 (run_monte_carlo)
    spots = []
    for i in range(SAMPLES):
        mis = Misalignment.none()
        for comp in ("projector", "camera", "paraboloid", "dome"):
            az = c[f"{comp}_tilt_axis_azimuth_rad"][i]
            mis = mis.with_(comp, offset=(c[f"{comp}_dx_mm"][i], c[f"{comp}_dy_mm"][i], c[f"{comp}_dz_mm"][i]),
                            tilt=c[f"{comp}_tilt_rad"][i], axis=(math.cos(az), math.sin(az), 0.0))
        rays_ = annulus_rays(design, RAYS, ray_seed, mis.pose("projector", rig.geometry))
        placed = optics.placed(mis.pose("paraboloid", rig.geometry), mis.pose("dome", rig.geometry))
        tr = trace(placed, rays_.origins, rays_.dirs, vectorised=True)
        spots.append(float(np.max(np.abs(tr.miss[tr.ok]))))
    # the two paths solve the same float64 intersections with different operation orders (and the
    # tilt axis passes through atan2 and back): agreement to rounding at ~300 mm, 1e-9 mm
    assert np.max(np.abs(np.array(spots) - c["projector_max_spot_radius_mm"])) < 1e-9
    # the build is the spot's cause: the aligned rig's spot is under 1e-6 mm (tests/check), these
    # are 1e5x that, and differ from sample to sample
    assert min(spots) > 1e-3 and len(set(spots)) == SAMPLES


def test_workers_and_batching_give_the_same_bits(serial_mc, table31_rig):
    seen = []
    two = run_monte_carlo(table31_rig, SAMPLES, RAYS, Engine(2), progress=lambda *a: seen.append(a))
    _same(serial_mc, two)
    assert seen and seen[-1][2:] == (SAMPLES, SAMPLES), seen  # the progress callback counts samples


def test_local_dask_gives_the_same_bits(serial_mc, table31_rig):
    pytest.importorskip("distributed")  # the dask extra, installed by `make test`
    _same(serial_mc, run_monte_carlo(table31_rig, SAMPLES, RAYS, Engine(2, LOCAL_DASK)))


def test_a_sample_does_not_depend_on_the_run_size(serial_mc, table31_rig):
    # sample i draws from SeedSequence child i: the first 5 of 12 are the first 5 of a 5-sample run
    few = run_monte_carlo(table31_rig, 5, RAYS, Engine(1))
    for k in ("dome_dx_mm", "max_spot_radius_mm", "max_mirror_angle_error_rad"):
        assert np.array_equal(few.columns[k], serial_mc.columns[k][:5])


def test_the_check_and_tolerance_report_one_monte_carlo(table31_rig):
    # `rigcad check` runs the Monte Carlo in-process on its small sample, `rigcad tolerance` on the
    # engine's process pool at scale: the same seed and sample count must give the same builds,
    # so the same per-build figures bit for bit and the same yield (a user compares the two)
    from rigcad.check.raycheck import run_raycheck

    tol = table31_rig.profile.tolerancing
    check = run_raycheck(table31_rig, mode="analytic", rays=2000, grid=False, builds=SAMPLES).report["monte_carlo"]
    scale = run_monte_carlo(table31_rig, SAMPLES, tol.rays, Engine(2))
    assert (check["builds"], check["seed"], check["rays_per_build_and_path"]) == (SAMPLES, tol.seed, tol.rays)
    for k in ("max_spot_radius_mm", "max_mirror_angle_error_rad"):
        assert check["per_build"][k] == scale.columns[k].tolist(), k
        assert check[k] == scale.summary["figures"][k], k
    assert check["max_pixel_angle_error_rad_uncalibrated"] == scale.summary["figures"]["max_angle_error_rad"]
    assert check["yield"] == scale.summary["yield"]
    # not vacuous: every build differs, and the yield is the share of the listed builds that meet
    # both targets, counted here from the per-build figures themselves
    spot, angle = check["per_build"]["max_spot_radius_mm"], check["per_build"]["max_mirror_angle_error_rad"]
    assert len(set(spot)) == SAMPLES
    met = sum(s <= tol.max_spot_radius and a <= tol.max_angle_error for s, a in zip(spot, angle))
    assert check["yield"] == met / SAMPLES


@pytest.mark.parametrize("name", ["dome_offset", "paraboloid_tilt"])
def test_inverse_limit_holds_at_the_limit_and_fails_at_twice_it(table31_rig, name):
    rig = table31_rig
    tol = rig.profile.tolerancing
    p = next(q for q in PARAMETERS if q.name == name)
    rays = 2000
    [row] = run_limits(rig, Job(rig, rays, 0, 0).key, rays, int(tol.seed) + 1, Engine(1), parameters=[p])
    limit = row[f"limit_{p.unit}"]
    assert row["limit_found"] and limit > p.tolerance(tol)  # the profile's tolerance is inside its limit

    # independent check: the same rays through the vectorised exact path (numpy passes, every dome
    # hit bracketed), at the limit and at twice it, worst of the two directions
    optics = analytic_optics(rig)
    design = rig.incidence

    def worst(amount):
        out = 0.0
        for mis in p.moves(amount):
            rays_ = MC.annulus_rays(design, rays, int(tol.seed) + 1, mis.pose("projector", rig.geometry))
            placed = optics.placed(mis.pose("paraboloid", rig.geometry), mis.pose("dome", rig.geometry))
            tr = trace(placed, rays_.origins, rays_.dirs, vectorised=True)
            local, _ = placed.paraboloid_pose.localize(tr.p1, tr.p1)
            mdirs = placed.paraboloid_pose.globalize_dirs(design.direction_at(local))
            out = max(out, MC.figures(tr, design.direction(rays_.chief), None, mdirs)["max_mirror_angle_error_rad"])
        return out

    # the figures at the profile's tolerance, and the share of the target they use, against the
    # same independent trace (compiled kernel against numpy passes: rounding, 1e-9 relative)
    at_tol = worst(p.tolerance(tol))
    assert row["max_mirror_angle_error_rad_at_tolerance"] == pytest.approx(at_tol, rel=1e-9)
    assert row["angle_budget_used"] == pytest.approx(at_tol / tol.max_angle_error, rel=1e-9)
    at = worst(limit)
    # within 5 % of the declared error at the limit (the bound; bisection stops at 1e-3 of the move)
    assert 0.95 * tol.max_angle_error <= at <= tol.max_angle_error, (at, tol.max_angle_error)
    assert worst(2 * limit) > tol.max_angle_error  # and twice the limit fails


def test_sweep_rows_and_refusals(table31):
    from rigcad.profile.loader import load_raw
    from rigcad.tolerance.sweep import parse_set, run_sweep

    spec = parse_set("layout.cop_to_vertex=25cm..35cm:3")
    assert spec.values == (250.0, 300.0, 350.0) and spec.unit == "mm"
    rows = run_sweep(load_raw(table31.sources[0]), spec, 3000, 1, None, Engine(1))
    assert [r["value"] for r in rows] == [250.0, 300.0, 350.0]
    # at 25 cm the profile's dome.tolerance (1e-9 mm) is below what float64 certifies: a refused row
    # naming the key, not a failed sweep
    assert not rows[0]["ok"] and "dome.tolerance" in rows[0]["error"]
    assert rows[1]["ok"] and rows[2]["ok"]
    # a farther COP sees the paraboloid under a smaller angle: fewer pixels from vertex to rim
    assert rows[1]["pixels_vertex_to_rim"] > rows[2]["pixels_vertex_to_rim"]
    assert all(r["check_max_spot_radius_mm"] < 1e-6 for r in rows[1:])  # each design converges on O
    for bad, words in (("layout.cop_to_vertx=1cm..2cm:3", "unknown key layout.cop_to_vertx"),
                       ("layout.cop_to_vertex=25..35:3", "cop_to_vertex"),
                       ("layout.cop_to_vertex=25cm..35cm:1", "at least 2"),
                       ("beam.width=-1mm..2mm:3", "beam.width")):
        with pytest.raises(ProfileError, match=words):
            parse_set(bad)


def test_cli_tolerance_writes_its_files(tmp_path, capsys):
    from rigcad.cli import main

    code = main(["tolerance", "achutha2006", "--samples", "6", "--rays", "200", "--workers", "1", "--no-limits",
                 "--exports", str(tmp_path)])
    assert code == 0
    out = tmp_path / "achutha2006" / "tolerance"
    names = sorted(p.name for p in out.iterdir())
    assert names == ["histograms.png", "run.json", "samples.csv", "samples.parquet", "summary.json", "tolerance.md"]
    import pyarrow.parquet as pq

    table = pq.read_table(out / "samples.parquet")
    assert table.num_rows == 6 and "dome_tilt_rad" in table.column_names and "meets_targets" in table.column_names
    header = [c.strip('"') for c in (out / "samples.csv").read_text().splitlines()[0].split(",")]
    # every number written names its unit in its header (or is a count / flag)
    assert all(c.endswith(("_mm", "_rad", "_fraction")) for c in header if c not in ("sample", "meets_targets")), header
    summary = json.loads((out / "summary.json").read_text())
    assert summary["samples"] == 6 and 0 <= summary["yield"] <= 1
    assert "Yield" in (out / "tolerance.md").read_text()


def test_scheduler_without_dask_says_what_to_install(table31_rig, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(EngineError, match=r"pip install 'rigcad\[dask\]'"):
        run_monte_carlo(table31_rig, 2, 100, Engine(1, LOCAL_DASK))


def test_limit_search_at_its_two_ends(table31_rig):
    """The inverse-limit search where the doubling never brackets the target (SEARCH_CAP: no limit
    there) and where the very first move already exceeds it (the limit lies between 0 and the
    start), and the light path each component's move is traced on."""
    from rigcad.tolerance.limits import LimitJob, _search, worst_figures
    from rigcad.tolerance.params import SEARCH_CAP

    rig, rays = table31_rig, 200
    job = LimitJob(rig, rays, int(rig.profile.tolerancing.seed) + 1, Job(rig, rays, 0, 0).key)
    p = next(q for q in PARAMETERS if q.name == "dome_offset")
    # an unreachable target: the search stops at the cap and says so, with the error there
    capped = _search(job, p, "max_spot_radius_mm", math.inf, 0.1)
    assert capped["limit"] == SEARCH_CAP["offset"] and capped["reached"] is False
    at_cap = worst_figures(job, p, SEARCH_CAP["offset"])["max_spot_radius_mm"]
    assert capped["error_at_limit"] == at_cap and at_cap > 1.0  # a 50 mm move misses by far more
    # a target the first move (0.1 mm) already exceeds: 1e-4 mm, above the aligned rig's own spot
    # (~1.5e-8 mm): the bracket is [0, start] and the limit lies inside it, meeting the target
    tight = _search(job, p, "max_spot_radius_mm", 1e-4, 0.1)
    assert tight["reached"] is True and 0.0 < tight["limit"] < 0.1
    assert tight["error_at_limit"] <= 1e-4
    # the camera's move is seen on the camera's path only; the dome's on the projector's
    cam = worst_figures(job, next(q for q in PARAMETERS if q.name == "camera_offset"), 0.1)
    assert any(k.startswith("camera_") for k in cam) and not any(k.startswith("projector_") for k in cam)
    dome = worst_figures(job, p, 0.1)
    assert any(k.startswith("projector_") for k in dome) and not any(k.startswith("camera_") for k in dome)


def test_limit_rows_ranked_by_budget_and_a_zero_tolerance(table31_rig, monkeypatch):
    """run_limits' rows: the share of each target a parameter uses at its tolerance (its figures there
    over the target), the limit over the tolerance, the ranking by the larger share; a parameter
    toleranced at 0 has no figures at its tolerance, uses none of the budget, and its limit is still
    searched (from the default probe) and found. The row's keys are those tolerance.md and the
    command line read."""
    import dataclasses

    from rigcad.tolerance.limits import LimitJob, worst_figures
    from rigcad.tolerance.params import SEARCH_CAP

    tol = dataclasses.replace(table31_rig.profile.tolerancing, dome_height=0.0)
    rig = dataclasses.replace(table31_rig, profile=dataclasses.replace(table31_rig.profile, tolerancing=tol))
    rays, seed = 200, int(tol.seed) + 1
    key = Job(rig, rays, 0, 0).key
    params = [next(q for q in PARAMETERS if q.name == n) for n in ("dome_height", "dome_offset", "paraboloid_tilt")]
    seen = []
    rows = run_limits(rig, key, rays, seed, Engine(1), progress=lambda *a: seen.append(a), parameters=params)
    assert seen == [(1, 3, 1, 3), (2, 3, 2, 3), (3, 3, 3, 3)]  # one task per parameter
    job = LimitJob(rig, rays, seed, key)
    by = {r["parameter"]: r for r in rows}
    common = {"parameter", "profile_key", "unit", "limit_found", "max_mirror_angle_error_rad_at_limit",
              "spot_limit_found", "max_spot_radius_mm_at_spot_limit", "spot_budget_used", "angle_budget_used",
              "limit_over_tolerance", "rank"}
    at_tolerance = {"max_spot_radius_mm_at_tolerance", "max_mirror_angle_error_rad_at_tolerance",
                    "lost_fraction_at_tolerance"}
    for p in params[1:]:
        r, u, value = by[p.name], p.unit, p.tolerance(tol)
        assert set(r) == common | at_tolerance | {f"tolerance_{u}", f"limit_{u}", f"spot_limit_{u}"}, set(r)
        assert (r["profile_key"], r["unit"], r[f"tolerance_{u}"]) == (f"tolerancing.{p.name}", u, value)
        f = worst_figures(job, p, value)  # the same rays and operations in this process: the same bits
        assert r["max_spot_radius_mm_at_tolerance"] == f["max_spot_radius_mm"]
        assert r["lost_fraction_at_tolerance"] == f["lost_fraction"]
        assert r["spot_budget_used"] == f["max_spot_radius_mm"] / tol.max_spot_radius
        assert r["angle_budget_used"] == f["max_mirror_angle_error_rad"] / tol.max_angle_error
        assert r["limit_over_tolerance"] == r[f"limit_{u}"] / value
        # each limit meets its target; a spot limit not found below the search cap is the cap
        assert r["limit_found"] and r["max_mirror_angle_error_rad_at_limit"] <= tol.max_angle_error
        if r["spot_limit_found"]:
            assert r["max_spot_radius_mm_at_spot_limit"] <= tol.max_spot_radius
        else:
            assert r[f"spot_limit_{u}"] == SEARCH_CAP[p.kind]
    zero = by["dome_height"]
    assert set(zero) == common | {"tolerance_mm", "limit_mm", "spot_limit_mm"}, set(zero)
    assert zero["spot_budget_used"] == 0.0 and zero["angle_budget_used"] == 0.0
    assert zero["limit_over_tolerance"] == math.inf
    assert zero["limit_found"] and 0.0 < zero["limit_mm"] < 50.0, zero  # SEARCH_CAP["height"]
    assert worst_figures(job, params[0], zero["limit_mm"])["max_mirror_angle_error_rad"] <= tol.max_angle_error
    # ranked by the larger share, largest first, ranks from 1; the zero tolerance uses nothing: last
    share = [max(r["spot_budget_used"], r["angle_budget_used"]) for r in rows]
    assert [r["rank"] for r in rows] == [1, 2, 3] and share == sorted(share, reverse=True) and share[0] > share[1]
    assert rows[-1]["parameter"] == "dome_height"
    # and the limits run on the engine they are given: a dask engine without dask says so
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(EngineError, match="dask"):
        run_limits(rig, key, 50, seed, Engine(1, LOCAL_DASK), parameters=params[1:2])
