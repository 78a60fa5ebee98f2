"""rigcad.check.raycheck's parts in seconds: one reading's figures and its losses on a trace built by
hand, the run's overrides and stage timings, and small runs of the Table 3.1 rig (500 rays, analytic
and coarse smooth meshes) whose report fields are checked against what they are made from. Every
profile's full check, the CLI and the written files are tested in test_raycheck.py."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.check import montecarlo
from rigcad.check import raycheck as RC
from rigcad.check.result import STATUS_NAMES, Trace3D
from rigcad.units import DEG


def _trace(status, theta_deg, segment, miss, phi_deg=None):
    """Rays arriving at O from incidence angle theta (deg) in the x-z plane (or at azimuth phi)."""
    n = len(status)
    t = np.radians(theta_deg)
    p = np.radians(phi_deg if phi_deg is not None else np.zeros(n))
    arrival = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=1)
    pts = np.zeros((n, 3))
    return Trace3D(np.asarray(status, np.int64), np.asarray(segment, np.int8), pts, pts, -arrival, pts,
                   np.ones(n), np.asarray(miss, float))


def test_losses_by_cause_with_their_segment_azimuths_and_design_thetas():
    status = [0, 1, 1, 3, 3, 3, 0]
    tr = _trace(status, [10, 0, 0, 0, 0, 0, 20], [0, 1, 1, 2, 4, 4, 0], np.zeros(7))
    az = np.radians([0.0, 0.5, 29.0, 30.05, -0.5, 359.0, 200.0])  # -0.5 deg is 359.5 deg
    chief = np.stack([np.cos(az), np.sin(az), np.ones(7)], axis=1)
    design_theta = np.radians([5.0, 12.0, 40.0, 33.0, 35.0, 34.0, 6.0])
    ddirs = np.stack([np.sin(design_theta), np.zeros(7), np.cos(design_theta)], axis=1)
    out = RC._losses(tr, chief, ddirs)
    assert list(out) == [STATUS_NAMES[1], STATUS_NAMES[3]]  # no entry for ok rays nor absent causes
    missed, beam = out[STATUS_NAMES[1]], out[STATUS_NAMES[3]]
    assert missed["rays"] == 2 and missed["fraction"] == 2 / 7 and missed["segment"] == 1
    assert missed["phi_deg_counts_per_30deg"] == [2] + [0] * 11
    assert missed["design_theta_deg_range"] == pytest.approx([12.0, 40.0], abs=1e-12)
    assert beam["rays"] == 3 and beam["fraction"] == 3 / 7 and beam["segment"] == 4
    assert beam["phi_deg_counts_per_30deg"] == [0, 1] + [0] * 9 + [2]
    assert beam["design_theta_deg_range"] == pytest.approx([33.0, 35.0], abs=1e-12)
    # lost rays with no design direction (outside the design annulus): no theta range
    ddirs[1:3] = np.nan
    assert RC._losses(tr, chief, ddirs)[STATUS_NAMES[1]]["design_theta_deg_range"] is None
    ddirs[1] = [0.0, 0.0, 1.5]  # a z beyond 1 is clipped, not NaN: theta 0
    assert RC._losses(tr, chief, ddirs)[STATUS_NAMES[1]]["design_theta_deg_range"] == [0.0, 0.0]
    ddirs[1] = [0.0, 0.0, np.nextafter(-1.0, -2.0)]  # a unit vector's z rounded past -1: theta 180
    assert RC._losses(tr, chief, ddirs)[STATUS_NAMES[1]]["design_theta_deg_range"] == [180.0, 180.0]


def test_a_reading_against_the_exact_trace():
    tr = _trace([0, 0, 0, 3], [20.0, 30.0, 50.0, 0.0], [0, 0, 0, 2], [0.1, 0.3, 0.2, 9.0])
    exact = _trace([0, 0, 2, 0], [20.5, 31.0, 50.0, 7.0], [0, 0, 1, 0], [0.15, 0.1, 0.0, 0.0])
    chief = np.tile([1.0, 0.0, 1.0], (4, 1))
    ddirs = -tr.v
    f = RC.reading(tr, ddirs, exact, chief)
    assert (f["theta_min_deg"], f["theta_max_deg"]) == pytest.approx((20.0, 50.0), abs=1e-12)
    assert f["lost_fraction"] == 0.25 and list(f["losses"]) == [STATUS_NAMES[3]]
    # the rays ok in both: 0.5 and 1 deg apart, misses 0.05 and 0.2 mm apart
    assert f["mesh_minus_exact_angle_rad"]["max"] == pytest.approx(1.0 * DEG, rel=1e-9)
    assert f["mesh_minus_exact_angle_rad"]["rms"] == pytest.approx(math.sqrt((0.25 + 1) / 2) * DEG, rel=1e-9)
    assert f["mesh_minus_exact_spot_mm"] == {"max": pytest.approx(0.2, abs=1e-15)}
    assert f["max_angle_change_rad"] == pytest.approx(1.0 * DEG, rel=1e-9)  # the figures against the exact trace
    assert f["status_agreement_with_exact"] == 0.5
    assert f["max_spot_radius_mm"] == 0.3 and f["max_angle_error_rad"] == pytest.approx(0.0, abs=1e-7)
    alone = RC.reading(tr, ddirs, None, chief)
    assert not any(k.startswith(("mesh_minus", "status_agreement", "max_angle_change")) for k in alone)
    # nothing arrives: NaN figures, every ray lost
    gone = _trace([1, 1], [0.0, 0.0], [1, 1], [0.0, 0.0])
    g = RC.reading(gone, -gone.v, gone, chief[:2])
    assert math.isnan(g["theta_min_deg"]) and math.isnan(g["theta_max_deg"]) and g["lost_fraction"] == 1.0
    assert math.isnan(g["mesh_minus_exact_angle_rad"]["max"]) and math.isnan(g["mesh_minus_exact_angle_rad"]["rms"])
    assert math.isnan(g["mesh_minus_exact_spot_mm"]["max"]) and g["status_agreement_with_exact"] == 1.0


def test_overrides_replace_only_what_they_name(table31):
    p = RC._overridden(table31, None, None, None, None, None)
    assert p == table31
    p = RC._overridden(table31, 123, "mesh", None, None, 7)
    assert (p.raycheck.rays, p.raycheck.mode, p.tolerancing.builds) == (123, "mesh", 7)
    assert p.tessellation == table31.tessellation and p.raycheck.seed == table31.raycheck.seed
    tess = table31.tessellation
    p = RC._overridden(table31, None, None, 0.05, None, None)
    assert (p.tessellation.mirror_chord_error, p.tessellation.mirror_normal_error) == (0.05, tess.mirror_normal_error)
    assert tess.mirror_normal_error != 0.02
    p = RC._overridden(table31, None, None, None, 0.02, None)
    assert (p.tessellation.mirror_chord_error, p.tessellation.mirror_normal_error) == (tess.mirror_chord_error, 0.02)
    assert p.raycheck == table31.raycheck and p.tolerancing == table31.tolerancing


def test_a_stage_says_its_name_first_and_records_its_wall_time(monkeypatch):
    clock = iter([10.0, 12.5])
    monkeypatch.setattr(RC.time, "perf_counter", lambda: next(clock))
    seen, timings = [], {}
    with RC._timed(timings, "x_s", seen.append, "stage x"):
        assert seen == ["stage x"] and timings == {}
    assert timings == {"x_s": 2.5}


# One test per run: mutmut maps the code a module-scoped fixture runs to the first test that uses
# it only, so every claim on a run sits in the test that makes the run (helpers below).
def test_an_analytic_run_of_500_rays(table31_rig, tmp_path):
    steps = []
    res = RC.run_raycheck(table31_rig, rays=500, mode="analytic", builds=2, progress=steps.append)
    _analytic_report(res, steps, table31_rig)
    _thin_lens(res)
    _pixels(res, table31_rig)
    _written(res, tmp_path)


def _analytic_report(res, steps, table31_rig):
    rep, prof = res.report, res.profile
    assert steps == ["design", "pinhole", "tower", "pixels", "thin lens", "misalignment", "monte carlo"]
    assert set(res.timings_s) == {"design_s", "pinhole_s", "tower_s", "pixels_s", "thin_lens_s", "misalignment_s",
                                  "monte_carlo_s"}
    assert (rep["mode"], rep["rays"], rep["seed"], rep["backend"]) == ("analytic", 500, prof.raycheck.seed,
                                                                     rep["backends"]["analytic"])
    assert list(rep["backends"]) == ["analytic"] and rep["meshes"] is None
    assert rep["profile"] == {"name": prof.name, "sources": list(prof.sources)}
    assert rep["frame"] == "mm; sample point O at the origin; optical axis +z; projector pixel x to +x, rows to -y"
    assert list(rep["readings"]) == ["analytic"] and rep["readings"]["analytic"]["kernels"]
    assert res.trace.status.size == 500 and res.design_dirs.shape == (500, 3)
    # the readings are those of the profile's seeded pinhole rays
    from rigcad.check.sources import annulus_rays

    src = annulus_rays(table31_rig.incidence, 500, prof.raycheck.seed, table31_rig.pose("projector"))
    assert np.array_equal(res.design_dirs, table31_rig.incidence.direction(src.chief), equal_nan=True)
    assert rep["checks"] == [r.as_dict() for r in res.rows] and rep["passed"] is res.passed is True
    assert len(res.rows) >= 8 and rep["monte_carlo"]["builds"] == 2
    assert rep["monte_carlo"] == montecarlo.check_report(table31_rig, 2, prof.tolerancing.rays)
    mis = rep["misalignment"]
    assert (mis["probe_mm"], mis["probe_tilt_rad"], mis["declared"]) == (prof.misalignment.probe,
                                                                       prof.misalignment.probe_tilt, None)
    assert set(mis["sensitivity"]) == {"projector_dx", "projector_dz", "projector_tilt", "camera_dx", "camera_dz",
                                       "camera_tilt", "paraboloid_dx", "paraboloid_dz", "paraboloid_tilt",
                                       "dome_dx", "dome_dz", "dome_tilt"}
    assert rep["tower"]["camera_through_splitter"]["rays"] == 500


def _thin_lens(res):
    lens, prof = res.report["thin_lens"], res.profile
    # focused at the mean source-to-sample path of the exact pinhole trace (thesis 3.2.2)
    assert lens["focal_distance_mm"] == pytest.approx(float(np.nanmean(res.trace.path_length)), rel=1e-12)
    assert (lens["aperture_mm"], lens["chief_rays"], lens["edge_rays_per_chief"]) == (
        prof.projector.aperture, 500, prof.raycheck.lens_azimuths)
    assert 0 < lens["mean_abs_angular_offset_rad"] <= lens["max_abs_angular_offset_rad"] < 0.5
    assert 0 < lens["mean_miss_mm"] <= lens["max_miss_mm"] < 5.0 and 0 <= lens["edge_rays_lost_fraction"] < 0.5


def _pixels(res, table31_rig):
    fan, grid = res.report["pixels_per_degree"], res.report["pixel_grid"]
    assert fan["azimuth_deg"] == pytest.approx(45.0, rel=1e-12) and fan["fan_step_px"] == RC.FAN_STEP_PX == 0.05
    # the fan's pixel radius against theta: the finite differences bound their own mean slope
    r, th = res.fan["pixel_radius_px"], res.fan["theta_deg"]
    assert np.all(np.diff(r) == pytest.approx(0.05, abs=1e-9))
    assert fan["px_per_deg_mean"] == pytest.approx((r.max() - r.min()) / (th.max() - th.min()), rel=1e-12)
    assert fan["px_per_deg_min"] <= fan["px_per_deg_mean"] <= fan["px_per_deg_max"] < 2 * fan["px_per_deg_min"]
    assert fan["px_per_deg_min"] == pytest.approx(float(np.min(np.abs(np.gradient(r, th)))), rel=1e-12)
    # every pixel of the window traced: the paraboloid's image is a disc of the rim's pixel radius
    w, h = table31_rig.profile.projector.resolution
    assert grid["resolution"] == [w, h] and grid["pixels_total"] == w * h
    assert res.theta_map.shape == res.status_map.shape == tuple(grid["traced_window_px"][::-1])
    # the window: the paraboloid's image (the rim's pixel radius, from the profile's derived figures)
    # and a 4 px margin
    side = 2 * math.ceil(table31_rig.geometry.pixels_vertex_to_rim) + 8
    assert grid["traced_window_px"] == [side, side]
    r0, c0 = grid["window_origin_row_col"]
    assert (r0 + side / 2, c0 + side / 2) == pytest.approx((h / 2, w / 2), abs=1.0)
    assert grid["window_border_all_missed"] is True
    rim = table31_rig.geometry.pixels_vertex_to_rim
    assert abs(grid["pixels_on_paraboloid"] - math.pi * rim ** 2) < 2 * math.pi * rim
    lost = sum(grid["pixels_lost"].values())
    assert grid["pixels_on_paraboloid"] == grid["pixels_reaching_sample"] + lost
    assert set(grid["pixels_lost"]) == {v for k, v in STATUS_NAMES.items() if k > 1}
    assert grid["theta_min_deg"] == pytest.approx(float(np.nanmin(res.theta_map)))
    assert 0 < grid["theta_min_deg"] < grid["theta_max_deg"] < 90 and 0 < grid["max_spot_radius_mm"] < 1e-3
    assert 0 < grid["max_angle_error_rad"] < 1e-3


def test_a_declared_misalignment_is_traced_on_both_paths(tmp_path):
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    path = tmp_path / "moved.yaml"
    path.write_text("extends: achutha2006\nmisalignment:\n  dome_dx: 0.3 mm\n", encoding="utf-8")
    rig = Rig.from_profile(load_profile(path))
    res = RC.run_raycheck(rig, rays=300, mode="analytic", grid=False, monte_carlo=False)
    dec = res.report["misalignment"]["declared"]
    assert list(dec) == ["projector_path", "camera_path"] and res.report["monte_carlo"] is None
    assert res.theta_map is None and res.report["pixel_grid"] is None
    # the dome moved 0.3 mm: both paths' spots 0.3 x the sensitivity table's spot per mm of the dome's
    # move (first order; traced apart, with other rays)
    per_mm = res.report["misalignment"]["sensitivity"]["dome_dx"]["max_spot_radius_mm_per_mm"]
    for path_ in dec.values():
        assert path_["max_spot_radius_mm"] == pytest.approx(0.3 * per_mm, rel=0.01)
        assert path_["rays"] == rig.profile.tolerancing.rays and "max_mirror_angle_error_rad" in path_


def test_a_mesh_run_reads_every_mesh_against_the_exact_surfaces(table31_rig, tmp_path):
    import time

    cache, steps = {}, []
    t0 = time.perf_counter()
    res = RC.run_raycheck(table31_rig, rays=500, mode="smooth", chord_error=0.1, normal_error=0.1,
                          monte_carlo=False, grid=False, optics_cache=cache, progress=steps.append)
    wall = time.perf_counter() - t0
    # the stages' times are durations within the run's own (no speed claim: a consistency check)
    assert all(0.0 <= v <= wall for v in res.timings_s.values()), res.timings_s
    rep = res.report
    assert rep["mode"] == "smooth" and list(rep["backends"]) == ["analytic", "mesh"]
    assert steps == ["design", "meshes", "pinhole", "tower", "pixels", "thin lens", "misalignment"]
    # the tower, the fan, the grid, the thin lens and the misalignment table trace the meshes too
    assert rep["backend"] == rep["backends"]["mesh"] != rep["backends"]["analytic"]
    assert set(rep["readings"]) == {"analytic", "mesh", "smooth", "exact_normals", "mesh_float32", "smooth_float32",
                                    "mesh_paraboloid_mesh_only", "smooth_paraboloid_mesh_only",
                                    "mesh_dome_mesh_only", "smooth_dome_mesh_only"}
    r = rep["readings"]
    for name in ("exact_normals", "mesh_float32", "smooth_float32"):
        assert r[name]["rays_traced"] == 500 and r[name]["rays"] == 500
    # Embree's own float32 hits (no refinement) on the same 500 rays: not the refined readings' numbers
    assert r["mesh_float32"]["rms_spot_radius_mm"] != r["mesh"]["rms_spot_radius_mm"]
    assert r["smooth_float32"]["rms_spot_radius_mm"] != r["smooth"]["rms_spot_radius_mm"]
    for name in ("mesh", "smooth"):
        assert r[name]["kernels"] and r[name]["mesh_minus_exact_angle_rad"]["max"] > 0
        for part in ("paraboloid", "dome"):
            assert set(r[f"{name}_{part}_mesh_only"]) == {"max_spot_radius_mm", "rms_spot_radius_mm",
                                                          "mesh_minus_exact_angle_rad"}
            # one mirror meshed: an error of its own, at most about that of both together
            assert 0 < r[f"{name}_{part}_mesh_only"]["mesh_minus_exact_angle_rad"]["max"] <= \
                1.5 * r[name]["mesh_minus_exact_angle_rad"]["max"]
    # the checked trace is the smooth reading's (flat facets scatter more than interpolated normals)
    assert res.trace.miss[res.trace.ok].max() == pytest.approx(r["smooth"]["max_spot_radius_mm"], rel=1e-12)
    assert r["mesh"]["max_spot_radius_mm"] > r["smooth"]["max_spot_radius_mm"]
    assert rep["meshes"]["tolerances"] == {"chord_error_mm": 0.1, "normal_error_rad": 0.1}
    assert set(rep["meshes"]) == {"sources", "tolerances", "triangles"}
    assert set(rep["meshes"]["sources"]) == {"paraboloid", "dome", "paraboloid_mount", "beam"}
    assert rep["meshes"]["sources"]["dome"] == "mirror_mesh() at 0.1 mm / 0.1 rad (no matching exported PLY)"
    assert set(rep["meshes"]["triangles"]) == {"paraboloid", "dome", "paraboloid_mount", "beam"}
    assert all(v > 0 for v in rep["meshes"]["triangles"].values())
    assert {"meshes_s", "embree_build_s"} <= set(res.timings_s)
    # the meshes are kept by profile, tolerances and exports; a second run reuses them
    (key,) = cache
    assert key == (res.profile.name, 0.1, 0.1, "None")
    again = RC.run_raycheck(table31_rig, rays=100, mode="mesh", chord_error=0.1, normal_error=0.1, monte_carlo=False,
                            grid=False, optics_cache=cache)
    assert len(cache) == 1 and again.report["meshes"] == rep["meshes"] and again.report["mode"] == "mesh"
    assert again.trace.miss[again.trace.ok].max() == pytest.approx(
        again.report["readings"]["mesh"]["max_spot_radius_mm"], rel=1e-12)
    assert again.report["readings"]["exact_normals"]["rays_traced"] == 100
    # run without the pixel grid: no theta map written
    assert sorted(p.name for p in RC.write_raycheck(res, tmp_path / "b")) == ["raycheck.json", "spot.png"]


def _written(res, tmp_path):
    import json

    paths = RC.write_raycheck(res, tmp_path / "a", lock=tmp_path / "given.lock", made_from="0" * 64)
    assert (tmp_path / "given.lock").is_file() and not (tmp_path / ".a.lock").exists()  # the lock asked for
    assert sorted(p.name for p in paths) == ["raycheck.json", "spot.png", "theta_map.png"]
    assert json.loads((tmp_path / "a" / "raycheck.json").read_text()) == json.loads(json.dumps(res.report))
    assert all(p.parent == tmp_path / "a" and p.stat().st_size > 0 for p in paths)
    assert (tmp_path / "a.made_from.json").is_file()  # the profile digest recorded beside the folder


def test_a_moved_projector_is_traced_where_it_stands_in_the_pixel_grid_too(table31_rig, monkeypatch):
    moved = table31_rig.moved("projector", offset=(0.5, 0.0, 0.0))
    poses = {}
    real = RC.annulus_rays

    def spy(design, count, seed, pose=None):
        poses[seed] = pose
        return real(design, count, seed, pose)

    monkeypatch.setattr(RC, "annulus_rays", spy)
    rep = RC.run_raycheck(moved, rays=300, mode="analytic", grid=True, monte_carlo=False).report
    # the pinhole rays (seed) and the thin lens's chief rays (seed + 7) leave the moved projector
    seed = moved.profile.raycheck.seed
    assert set(poses) == {seed, seed + 7}
    assert all(p is not None and not p.is_identity for p in poses.values())
    assert np.allclose(poses[seed + 7].globalize_points(np.zeros((1, 3))) - np.zeros(3), [[0.5, 0.0, 0.0]])
    # the pinhole rays and every pixel of the grid leave the moved projector: spots of ~0.03 mm
    # (the aligned rig's are ~1e-8 mm), the same largest spot on both within a few per cent
    pin, grid = rep["readings"]["analytic"]["max_spot_radius_mm"], rep["pixel_grid"]["max_spot_radius_mm"]
    assert pin > 1e-2 and grid == pytest.approx(pin, rel=0.05)
    # pixels whose design direction is outside the design's map (the moved projector's edge pixels)
    # do not blank the grid's angle error: it is the largest over the pixels that have one, as the
    # pinhole reading's (figures.spot_figures) and of the same size
    ang_pin = rep["readings"]["analytic"]["max_angle_error_rad"]
    ang_grid = rep["pixel_grid"]["max_angle_error_rad"]
    assert np.isfinite(ang_grid) and ang_grid == pytest.approx(ang_pin, rel=0.5)
    # the fan that measures pixels per degree leaves it too: its thetas move with the projector
    aligned = RC.run_raycheck(table31_rig, rays=300, mode="analytic", grid=False, monte_carlo=False).report
    a, b = aligned["pixels_per_degree"]["px_per_deg_mean"], rep["pixels_per_degree"]["px_per_deg_mean"]
    assert abs(a - b) > 1e-6 * a
    # and the thin lens's chief rays: their edge rays miss by what the move adds
    assert rep["thin_lens"]["max_miss_mm"] != aligned["thin_lens"]["max_miss_mm"]


def test_mirror_meshes_exported_at_the_profiles_tolerances_are_read_back(tmp_path, monkeypatch):
    from rigcad.export.mirror_mesh import mirror_mesh, write_ply
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    path = tmp_path / "coarse.yaml"
    path.write_text("extends: achutha2006\ntessellation:\n  mirror_chord_error: 0.1 mm\n"
                    "  mirror_normal_error: 5 deg\n", encoding="utf-8")
    rig = Rig.from_profile(load_profile(path))
    tess = rig.profile.tessellation
    exports = tmp_path / "exports"
    plys = {}
    for name, meridian in (("paraboloid", rig.layout.design_paraboloid), ("dome", rig.layout.design_dome)):
        plys[name] = exports / rig.profile.name / "mirrors" / f"{name}.ply"
        plys[name].parent.mkdir(parents=True, exist_ok=True)
        write_ply(plys[name], mirror_mesh(meridian, name, tess.mirror_chord_error, tess.mirror_normal_error))
    cache = {}
    monkeypatch.setattr(RC, "EXACT_NORMAL_RAYS", 60)  # the costly readings on the first 60 of the 100 rays
    res = RC.run_raycheck(rig, exports, rays=100, mode="mesh", monte_carlo=False, grid=False, optics_cache=cache)
    for name in ("exact_normals", "mesh_float32", "smooth_float32"):
        r = res.report["readings"][name]
        assert r["rays_traced"] == 60 == r["rays"] and r["mesh_minus_exact_angle_rad"]["max"] > 0
    src = res.report["meshes"]["sources"]
    assert (src["paraboloid"], src["dome"]) == (str(plys["paraboloid"]), str(plys["dome"]))
    assert list(cache) == [(rig.profile.name, tess.mirror_chord_error, tess.mirror_normal_error, str(exports))]
    # one tolerance overridden: the exports (made at the profile's) are not read, the meshes are made
    over = RC.run_raycheck(rig, exports, rays=100, mode="mesh", normal_error=0.1, monte_carlo=False, grid=False)
    assert over.report["meshes"]["tolerances"] == {"chord_error_mm": tess.mirror_chord_error, "normal_error_rad": 0.1}
    assert over.report["meshes"]["sources"]["dome"].startswith("mirror_mesh() at 0.1 mm / 0.1 rad")
    over = RC.run_raycheck(rig, exports, rays=100, mode="mesh", chord_error=0.2, monte_carlo=False, grid=False)
    assert over.report["meshes"]["tolerances"]["chord_error_mm"] == 0.2
    assert over.report["meshes"]["sources"]["dome"].startswith("mirror_mesh() at 0.2 mm")
    # no cache given: the same meshes, made for this run alone
    alone = RC.run_raycheck(rig, exports, rays=100, mode="mesh", monte_carlo=False, grid=False)
    assert alone.report["meshes"] == res.report["meshes"]
    assert alone.report["readings"]["mesh"] == res.report["readings"]["mesh"]
