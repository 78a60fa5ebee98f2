"""rigcad.check.montecarlo's parts one at a time, in seconds: the builds drawn from a scripted random
generator, the batch sizes, the summary of hand-made columns, the rank correlations against scipy,
the plumbing of a run (with the tracing replaced), and the figures of one build on the Table 3.1 rig
(the worse of two light paths, rays lost, the aligned rays made once). The whole Monte Carlo, its
bits on every engine and its independent retrace, is tested in tests/tolerance/test_tolerance.py."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.check import montecarlo as MC
from rigcad.engine import Engine, child_seed
from rigcad.optics.frames import COMPONENTS, DOFS, Misalignment


class Script:
    """A random generator whose uniform draws are given fractions of their interval, recorded."""

    def __init__(self, fractions):
        self.fractions, self.calls = list(fractions), []

    def uniform(self, *args):
        self.calls.append(args)
        lo, hi = args if args else (0.0, 1.0)
        return lo + self.fractions.pop(0) * (hi - lo)


def _tol(**kw):
    base = {f"{c}_{k}": v for c, (o, h, t) in zip(COMPONENTS, [(0.5, 1.0, 0.01), (0.6, 2.0, 0.02),
                                                                 (0.7, 3.0, 0.03), (0.8, 4.0, 0.04)])
            for k, v in (("offset", o), ("height", h), ("tilt", t))}
    base.update(seed=7, builds=5, rays=300, max_spot_radius=0.2, max_angle_error=0.01, min_yield=0.9)
    base.update(kw)
    return SimpleNamespace(**base)


def test_a_build_is_drawn_in_a_disc_a_height_band_and_a_tilt_about_a_horizontal_axis():
    tol = _tol()
    # per component: sqrt-radius fraction, azimuth, tilt-axis azimuth, height, tilt
    fractions = [0.25, 0.125, 0.5, 0.75, 0.5] * 4
    rng = Script(fractions)
    m = MC.sample_build(rng, tol)
    for k, c in enumerate(COMPONENTS):
        lateral, height, tilt = tol.__dict__[f"{c}_offset"], tol.__dict__[f"{c}_height"], tol.__dict__[f"{c}_tilt"]
        assert rng.calls[5 * k:5 * k + 5] == [(), (0, 2 * np.pi), (0, 2 * np.pi), (-height, height), (0, tilt)]
        r, a = lateral * 0.5, 2 * math.pi * 0.125  # r = lateral sqrt(u): uniform over the disc's area
        assert m.offsets[c] == pytest.approx((r * math.cos(a), r * math.sin(a), 0.5 * height), abs=1e-15)
        assert m.tilts[c] == pytest.approx(0.5 * tilt, abs=1e-18)
        assert m.axes[c] == pytest.approx((-1.0, 0.0, 0.0), abs=1e-15)  # azimuth pi
    assert not rng.fractions


def test_declared_is_the_profiles_misalignment_section():
    mis = SimpleNamespace(camera_dx=1.0, camera_dz=2.0, camera_tilt=0.01, projector_dx=3.0, projector_dz=4.0,
                          projector_tilt=0.02, paraboloid_dx=5.0, paraboloid_tilt=0.03, dome_dx=6.0, dome_tilt=0.04)
    m = MC.declared(SimpleNamespace(misalignment=mis))
    assert m.offsets == {"camera": (1.0, 0.0, 2.0), "projector": (3.0, 0.0, 4.0), "paraboloid": (5.0, 0.0, 0.0),
                         "dome": (6.0, 0.0, 0.0)}
    assert m.tilts == {"camera": 0.01, "projector": 0.02, "paraboloid": 0.03, "dome": 0.04}
    assert m.axes == Misalignment.none().axes  # tilts about +y


def test_batch_size_is_about_task_rays_and_four_tasks_per_worker():
    assert MC.TASK_RAYS == 100_000
    assert MC.batch_size(1000, 1000, 1) == 50  # 100000 rays / (2 paths x 1000)
    assert MC.batch_size(40, 1000, 2) == 5  # 40 samples over 4 tasks x 2 workers
    assert MC.batch_size(41, 1000, 2) == 6  # rounded up: never more than 4 tasks a worker
    assert MC.batch_size(40, 1000, 0) == 10  # no worker counts as one
    assert MC.batch_size(10_000, 50_000, 1) == 1 and MC.batch_size(10_000, 49_999, 1) == 1
    assert MC.batch_size(10_000, 25_000, 1) == 2 and MC.batch_size(10_000, 10**6, 1) == 1
    assert MC.batch_size(1, 100, 8) == 1 and MC.batch_size(0, 100, 1) == 1


def test_the_summary_of_hand_made_columns():
    v = np.arange(101.0)[::-1]  # percentiles of 0..100 are their own ranks
    assert MC._stats(v) == {"mean": 50.0, "p50": 50.0, "p90": 90.0, "p99": 99.0, "max": 100.0}
    spot = np.array([0.1, 0.2, 0.2 + 1e-12, 0.05, 0.3])
    angle = np.array([0.01, 0.001, 0.0, 0.01 + 1e-12, 0.0])
    cols = {k: np.linspace(0.0, 1.0, 5) for k in MC.PATH_FIGURES}
    cols.update(max_spot_radius_mm=spot, max_mirror_angle_error_rad=angle)
    tol = _tol()
    assert MC.meets(cols, tol).tolist() == [True, True, False, False, False]  # targets met at equality
    s = MC.summarize(cols, tol, 5, 300, 8)
    assert s == {"samples": 5, "seed": 7, "rays_per_path": 300, "ray_seed": 8, "distribution": MC.DISTRIBUTION,
                 "figures": {k: MC._stats(cols[k]) for k in MC.PATH_FIGURES}, "yield": 0.4,
                 "samples_meeting_targets": 2, "target_max_spot_radius_mm": 0.2,
                 "target_max_mirror_angle_error_rad": 0.01, "min_yield": 0.9}
    assert s["figures"]["rms_spot_radius_mm"]["p90"] == pytest.approx(0.9)
    assert MC.DISTRIBUTION.startswith("per sample: offsets uniform in a disc (x-y) and in +-height (z)")


def test_rank_correlations_are_spearmans():
    from scipy.stats import spearmanr

    from rigcad.tolerance.montecarlo import rank_correlations
    from rigcad.tolerance.params import PARAMETERS

    rng = np.random.default_rng(3)
    n = 40
    cols = {}
    for c in COMPONENTS:
        for k in ("dx_mm", "dy_mm", "dz_mm", "tilt_rad"):
            cols[f"{c}_{k}"] = rng.normal(size=n)
    cols["projector_tilt_rad"] = np.full(n, 0.5)  # no spread: no correlation
    spot = np.hypot(cols["dome_dx_mm"], cols["dome_dy_mm"]) + 0.3 * rng.normal(size=n)
    angle = np.abs(cols["paraboloid_dz_mm"]) - 0.5 * cols["camera_tilt_rad"]
    out = rank_correlations({**cols, "max_spot_radius_mm": spot, "max_mirror_angle_error_rad": angle})
    assert set(out) == {p.name for p in PARAMETERS}
    mags = {"offset": lambda c: np.hypot(cols[f"{c}_dx_mm"], cols[f"{c}_dy_mm"]),
            "height": lambda c: np.abs(cols[f"{c}_dz_mm"]), "tilt": lambda c: cols[f"{c}_tilt_rad"]}
    for p in PARAMETERS:
        for k, fig in (("max_spot_radius_mm", spot), ("max_mirror_angle_error_rad", angle)):
            want = 0.0 if p.name == "projector_tilt" else spearmanr(mags[p.kind](p.component), fig)[0]
            assert out[p.name][k] == pytest.approx(want, abs=1e-12), (p.name, k)
    assert out["dome_offset"]["max_spot_radius_mm"] > 0.5 and out["camera_tilt"]["max_mirror_angle_error_rad"] < -0.3
    flat = rank_correlations({**cols, "max_spot_radius_mm": np.ones(n), "max_mirror_angle_error_rad": angle})
    assert all(v["max_spot_radius_mm"] == 0.0 for v in flat.values())


def test_the_job_key_names_the_rigs_parameters_in_any_order():
    def job(d):
        return MC.Job(SimpleNamespace(profile=SimpleNamespace(as_dict=lambda: d)), 10, 1, 0)

    key = job({"a": 1, "b": Path("x")}).key
    assert key == hashlib.sha256(b'{"a": 1, "b": "x"}').hexdigest()
    assert job({"b": Path("x"), "a": 1}).key == key and job({"a": 2, "b": Path("x")}).key != key


def test_a_run_is_its_seeded_batches_in_order(monkeypatch):
    """run_monte_carlo's plumbing with the tracing replaced: the job, the batches, the columns."""
    seen = {}

    def fake_run(fn, job, tasks, engine, progress=None, sizes=None):
        seen.update(fn=fn, job=job, tasks=tasks, sizes=sizes, progress=progress)
        return [[{"sample": i, **{k: float(i) for k in MC.PATH_FIGURES}, "max_spot_radius_mm": 0.1 * i,
                  "max_mirror_angle_error_rad": 0.0} for i in t] for t in tasks]

    monkeypatch.setattr(MC, "run", fake_run)
    tol = _tol(builds=9, rays=25_000)  # 2 samples a task by the rays
    rig = SimpleNamespace(profile=SimpleNamespace(tolerancing=tol))
    mc = MC.run_monte_carlo(rig, engine=Engine(1), progress=print)
    assert seen["fn"] is MC._batch and seen["progress"] is print
    assert (seen["job"].rig, seen["job"].rays, seen["job"].ray_seed, seen["job"].seed) == (rig, 25_000, 8, 7)
    assert seen["tasks"] == [range(0, 2), range(2, 4), range(4, 6), range(6, 8), range(8, 9)]
    assert seen["sizes"] == [2, 2, 2, 2, 1]
    assert mc.columns["sample"].tolist() == list(range(9))
    assert mc.columns["max_spot_radius_mm"].tolist() == pytest.approx([0.1 * i for i in range(9)])
    assert mc.summary["samples"] == 9 and mc.summary["rays_per_path"] == 25_000 and mc.summary["ray_seed"] == 8
    assert mc.summary["yield"] == pytest.approx(3 / 9)  # spots 0, 0.1, 0.2 meet 0.2
    small = MC.run_monte_carlo(rig, 3, 100, Engine(1))
    assert seen["tasks"] == [range(0, 1), range(1, 2), range(2, 3)] and seen["job"].rays == 100
    assert small.summary["samples"] == 3
    one = MC.run_monte_carlo(rig, 1, 100, Engine(1))  # a single sample: one row, its columns
    assert one.columns["sample"].tolist() == [0] and one.summary["samples"] == 1


def test_a_batch_records_each_samples_own_build(monkeypatch):
    tol = _tol()
    rig = SimpleNamespace(profile=SimpleNamespace(tolerancing=tol, as_dict=lambda: {"x": 1}))
    job = MC.Job(rig, 11, 12, 13)
    calls = []
    monkeypatch.setattr(MC, "worker_optics", lambda r, key: (calls.append(("optics", r, key)) or "optics", "design"))

    def fake_figures(optics, rig_, design, mis, rays, ray_seed, key=None):
        calls.append((optics, design, rays, ray_seed, key))
        return {"max_spot_radius_mm": mis.tilts["dome"]}

    monkeypatch.setattr(MC, "build_figures", fake_figures)
    rows = MC._batch(job, range(3, 5))
    assert [r["sample"] for r in rows] == [3, 4]
    assert calls == [("optics", rig, job.key)] + [("optics", "design", 11, 12, job.key)] * 2
    for row in rows:
        mis = MC.sample_build(np.random.default_rng(child_seed(13, row["sample"])), tol)
        assert row["max_spot_radius_mm"] == mis.tilts["dome"]
        for c in COMPONENTS:
            assert (row[f"{c}_dx_mm"], row[f"{c}_dy_mm"], row[f"{c}_dz_mm"]) == mis.offsets[c]
            assert row[f"{c}_tilt_rad"] == mis.tilts[c]
            az = row[f"{c}_tilt_axis_azimuth_rad"]
            assert (math.cos(az), math.sin(az)) == pytest.approx(mis.axes[c][:2], abs=1e-15)
    assert rows[0]["dome_dx_mm"] != rows[1]["dome_dx_mm"]


# -- figures of one build on the Table 3.1 rig ---------------------------------------------------
@pytest.fixture(scope="module")
def scene(table31_rig):
    from rigcad.check.scene import analytic_optics

    return analytic_optics(table31_rig), table31_rig, table31_rig.incidence


def test_a_builds_figures_are_the_worse_of_its_two_paths(scene):
    optics, rig, design = scene
    mis = Misalignment.none().with_("camera", offset=(0.3, 0.1, 0.2), tilt=0.004, axis=(0.6, 0.8, 0.0))
    mis = mis.with_("dome", offset=(0.1, -0.05, 0.0))
    out = MC.build_figures(optics, rig, design, mis, 200, 5)
    assert set(out) == {f"{d}{k}" for d in ("projector_", "camera_", "") for k in MC.PATH_FIGURES}
    for k in MC.PATH_FIGURES:
        assert out[k] == max(out[f"projector_{k}"], out[f"camera_{k}"]), k
    assert out["camera_max_spot_radius_mm"] != out["projector_max_spot_radius_mm"]
    assert min(out["camera_max_spot_radius_mm"], out["projector_max_spot_radius_mm"]) > 1e-3
    # the rays made once per worker (key) are the same rays, moved by the source's pose here
    cached = MC.build_figures(optics, rig, design, mis, 200, 5, key="test-key")
    for k, v in out.items():
        assert cached[k] == pytest.approx(v, rel=1e-9, abs=1e-15), k
    # one path asked for: its figures alone; the lost fraction is the trace's own
    only = MC.build_figures(optics, rig, design, mis, 200, 5, devices=("camera",))
    assert set(only) == {f"{p}{k}" for p in ("camera_", "") for k in MC.PATH_FIGURES}
    tr, _, _ = MC.trace_path(optics, rig, design, mis, "camera", 200, 5)
    assert only["lost_fraction"] == only["camera_lost_fraction"] == pytest.approx(1.0 - tr.ok.mean(), abs=1e-15)


def test_a_build_that_loses_every_ray_has_infinite_figures(scene):
    optics, rig, design = scene
    gone = Misalignment.none().with_("paraboloid", offset=(0.0, 0.0, 5000.0))
    out = MC.build_figures(optics, rig, design, gone, 100, 5, devices=("projector",))
    assert out["projector_lost_fraction"] == 1.0 == out["lost_fraction"]
    assert out["max_spot_radius_mm"] == math.inf == out["projector_rms_spot_radius_mm"]


def test_a_camera_move_is_traced_through_the_splitter_on_the_camera_path_only(scene):
    optics, rig, design = scene
    base = MC.build_figures(optics, rig, design, Misalignment.none(), 150, 9)
    moved = MC.build_figures(optics, rig, design, Misalignment.none().with_("camera", offset=(0.4, 0.0, 0.0)), 150, 9)
    assert all(moved[f"projector_{k}"] == base[f"projector_{k}"] for k in MC.PATH_FIGURES)
    assert moved["camera_max_spot_radius_mm"] > 20 * base["camera_max_spot_radius_mm"] > 0
    # aligned, the camera's rays still cross the splitter plate: its astigmatism, ~1e-4 mm; the
    # projector's path has none of it (~1e-8 mm)
    assert base["camera_max_spot_radius_mm"] > 1e-5 > 100 * base["projector_max_spot_radius_mm"]


def test_sensitivity_is_each_probe_divided_by_its_size(scene):
    optics, rig, design = scene
    small = MC.sensitivity(optics, rig, design, 0.01, 1e-4, 120, 3)
    twice = MC.sensitivity(optics, rig, design, 0.02, 2e-4, 120, 3)
    assert list(small) == [f"{c}_{d}" for c in COMPONENTS for d in DOFS]
    for name, row in small.items():
        unit = "mrad" if name.endswith("tilt") else "mm"
        amount = 0.1 if unit == "mrad" else 0.01
        assert row["probe"] == ("0.1 mrad" if unit == "mrad" else "0.01 mm")
        for k in ("max_spot_radius_mm", "max_angle_change_rad", "max_mirror_angle_error_rad"):
            assert row[f"{k}_per_{unit}"] == pytest.approx(row[k] / amount, rel=1e-12), (name, k)
        assert row[f"spot_shift_mm_per_{unit}"] == pytest.approx(row["convergence_offset_mm"] / amount, rel=1e-12)
        if name.startswith(("paraboloid", "dome")) or name in ("projector_dx", "projector_dz"):
            # first order in a small move: the spot per unit move is the same at twice the move
            # (the camera's path keeps the splitter's own spot, a tilt about the COP moves no ray)
            assert twice[name][f"max_spot_radius_mm_per_{unit}"] == pytest.approx(
                row[f"max_spot_radius_mm_per_{unit}"], rel=0.01), name
            assert row["max_spot_radius_mm"] > 1e-5, name
    # the projector turned about its COP: every ray still passes through it, the spot stays ~0
    assert small["projector_tilt"]["max_spot_radius_mm"] < 1e-6 < small["projector_dx"]["max_spot_radius_mm"] / 100
    # the change of each ray's arrival from the aligned rig's, traced on the same rays, is its error
    # against the design direction (the aligned rig arrives at its design to ~1e-8 rad), and small
    for name, row in small.items():
        assert row["max_angle_change_rad"] == pytest.approx(row["max_angle_error_rad"], abs=1e-7), name
        assert row["max_angle_change_rad"] < 0.01, name
    # the camera's probe is seen on the camera's path: its spot, not the projector's
    cam = MC.trace_path(optics, rig, design, Misalignment.none().with_("camera", offset=(0.01, 0, 0)),
                        "camera", 120, 3)[0]
    assert small["camera_dx"]["max_spot_radius_mm"] == pytest.approx(float(np.max(np.abs(cam.miss[cam.ok]))),
                                                                       rel=1e-12)


def test_the_check_report_is_the_monte_carlo_of_its_builds(table31_rig):
    rep = MC.check_report(table31_rig, 3, 100)
    mc = MC.run_monte_carlo(table31_rig, 3, 100, Engine(1))
    s, c, tol = mc.summary, mc.columns, table31_rig.profile.tolerancing
    assert rep == {
        "builds": 3, "seed": tol.seed, "rays_per_build_and_path": 100,
        "distribution": f"{MC.DISTRIBUTION}; the same pinhole rays (seed {tol.seed + 1}) for every build; camera "
                        "and projector paths traced on the exact surfaces, the worse kept",
        "max_spot_radius_mm": s["figures"]["max_spot_radius_mm"],
        "max_mirror_angle_error_rad": s["figures"]["max_mirror_angle_error_rad"],
        "max_pixel_angle_error_rad_uncalibrated": s["figures"]["max_angle_error_rad"],
        "convergence_offset_mm": s["figures"]["convergence_offset_mm"],
        "target_max_spot_radius_mm": tol.max_spot_radius, "target_max_mirror_angle_error_rad": tol.max_angle_error,
        "yield": s["yield"], "min_yield": tol.min_yield,
        "per_build": {"max_spot_radius_mm": c["max_spot_radius_mm"].tolist(),
                      "max_mirror_angle_error_rad": c["max_mirror_angle_error_rad"].tolist()}}
    assert len(set(rep["per_build"]["max_spot_radius_mm"])) == 3


def test_the_worker_caches_hold_the_optics_and_the_aligned_rays(scene, monkeypatch):
    """Each worker builds the analytic optics and the aligned rays once, under keys naming the rig
    (and the rays and their seed): a build reads them from there."""
    import rigcad.engine as E
    from rigcad.check.sources import annulus_rays

    optics, rig, design = scene
    monkeypatch.setattr(E, "_CACHE", {})
    o, d = MC.worker_optics(rig, "rig-key")
    assert o.mode == "analytic" and d is rig.incidence
    assert E._CACHE[("tolerance-optics", "rig-key")] == (o, d) and MC.worker_optics(rig, "rig-key")[0] is o
    rays, dirs = MC.aligned_rays(design, 50, 5, "rig-key")
    want = annulus_rays(design, 50, 5)
    assert np.array_equal(rays.origins, want.origins) and np.array_equal(rays.dirs, want.dirs)
    assert np.array_equal(dirs, design.direction(want.chief), equal_nan=True)
    assert E._CACHE[("tolerance-rays", "rig-key", 50, 5)][0] is rays
    # a build with the rig's key traces the cached rays (moved by each source's pose)
    seen = []
    real = MC.trace_path
    monkeypatch.setattr(MC, "trace_path", lambda *a: seen.append(a[-1]) or real(*a))
    MC.build_figures(optics, rig, design, Misalignment.none(), 60, 6, key="rig-key")
    assert len(seen) == 2 and all(a is E._CACHE[("tolerance-rays", "rig-key", 60, 6)] for a in seen)
    seen.clear()
    MC.build_figures(optics, rig, design, Misalignment.none(), 60, 7)
    assert seen == [None, None] and ("tolerance-rays", None, 60, 7) not in E._CACHE


def test_the_check_runs_its_monte_carlo_in_this_process(monkeypatch):
    got = []

    def fake(rig, builds, rays, engine):
        got.append((builds, rays, engine.n_workers))
        return MC.MonteCarlo({k: np.zeros(2) for k in ("max_spot_radius_mm", "max_mirror_angle_error_rad")},
                             {"samples": builds, "seed": 1, "rays_per_path": rays, "ray_seed": 2, "yield": 1.0,
                              "figures": {k: {} for k in MC.PATH_FIGURES}})

    monkeypatch.setattr(MC, "run_monte_carlo", fake)
    rig = SimpleNamespace(profile=SimpleNamespace(tolerancing=_tol()))
    assert MC.check_report(rig, 2, 50)["builds"] == 2 and got == [(2, 50, 1)]
