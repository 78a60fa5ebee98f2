"""The ray check with the beam splitter in place: the camera's view through the plate meets the
raycheck targets once compensated; without the compensation the spot moves as a camera moved by the
plate's closed-form shift would; no tower part enters the ray bundles."""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigcad.check.sources import annulus_rays
from rigcad.check.tower import bundle_clearance, camera_view
from rigcad.check.trace3d import convergence_point, trace
from rigcad.optics.splitter import lateral_shift
from rigcad.profile import load_profile
from rigcad.rig import Rig

RAYS = 20_000


def test_camera_through_the_compensated_splitter_meets_the_raycheck_targets(rig, analytic, design_map):
    rc = rig.profile.raycheck
    _, f = camera_view(analytic, rig, design_map, RAYS, 3)
    assert f["rays_outside_the_plate"] == 0
    assert f["max_spot_radius_mm"] <= rc.max_spot_radius  # 0.43 um measured against 10 um
    assert f["max_mirror_angle_error_rad"] <= rc.max_angle_error  # 3.9e-5 rad against 1.7e-4 rad
    # the lost fraction is the beam's, as for the projector's pinhole rays
    assert 1 - f["rays_ok"] / f["rays"] <= rc.max_lost_fraction


def test_without_compensation_the_spot_moves_by_the_predicted_amount(rig, analytic, design_map):
    # Prediction, independent of the splitter code: a camera moved across by the plate's closed-form
    # shift d = t sin i (1 - cos i / sqrt(n^2 - sin^2 i)) (no plate) -- the existing misaligned-rig tracer
    bs = rig.profile.beam_splitter
    d = lateral_shift(bs.thickness, bs.index, math.pi / 4)
    moved = rig.moved("camera", offset=(d, 0.0, 0.0))
    rays = annulus_rays(design_map, RAYS, 3, moved.pose("camera"))
    predicted = convergence_point(trace(analytic, rays.origins, rays.dirs))
    _, raw = camera_view(analytic, rig, design_map, RAYS, 3, compensate=False)
    _, comp = camera_view(analytic, rig, design_map, RAYS, 3, compensate=True)
    moved_by = np.array(raw["convergence_point_mm"])
    assert np.linalg.norm(predicted[:2]) > 0.01  # the plate does move the spot (15 um for 1 mm of glass)
    # the prediction ignores the bundle's spread of shifts and the axial part (3.2 deg cone: ~0.3 %)
    assert np.linalg.norm(moved_by[:2] - predicted[:2]) <= 0.01 * np.linalg.norm(predicted[:2])
    assert raw["max_spot_radius_mm"] > rig.profile.raycheck.max_spot_radius  # uncompensated: fails the target
    # compensated: the spot is back on O to under 1 % of the uncompensated move
    assert np.linalg.norm(comp["convergence_point_mm"]) < 0.01 * np.linalg.norm(moved_by)


def test_no_tower_part_enters_the_ray_bundles(rig, design_map):
    report = bundle_clearance(rig, design_map)
    for key in ("projector", "projector_widened", "camera"):
        assert report[key]["blocked"] == 0, (key, report[key]["blocked_by"])
        assert report[key]["segments"] > 1000 or key == "camera"


def test_a_lens_mount_that_cuts_the_bundle_is_caught(write_profile, table31_text):
    # a lens seat leaving a 6 mm clear aperture: the bundle (7.8 mm across at the lens) hits the mount
    rig = Rig.from_profile(load_profile(write_profile(table31_text + "lens:\n  rim: 22 mm\n")))
    report = bundle_clearance(rig, rig.incidence)
    assert report["projector"]["blocked_by"].get("lens_mount", 0) > 0


def test_raycheck_rows_include_the_tower(rig, optics_cache):
    res = rig.check(rays=4000, mode="analytic", monte_carlo=False, grid=False, optics_cache=optics_cache)
    names = {r.name: r for r in res.rows}
    for name in ("camera via splitter: spot radius (max)",
                 "camera via splitter: angle error, calibrated (max)",
                 "tower parts in the ray bundles (rays)"):
        assert names[name].ok, names[name]
    # the closed form for the profile's plate: 0.3345 mm per mm of N-BK7 at 45 deg (1.1 mm: 0.368 mm)
    bs = rig.profile.beam_splitter
    assert res.report["tower"]["splitter"]["chief_ray_shift_closed_form_mm"] == pytest.approx(
        0.3345 * bs.thickness, abs=1e-4)
