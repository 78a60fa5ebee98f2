"""3D trace: convergence of the exact design, agreement with the 2D tracer in the meridional plane,
a known misalignment moving the spot as the analytic trace predicts, mesh error against tessellation."""

from __future__ import annotations

import numpy as np
import pytest

from rigcad.check import montecarlo as MC
from rigcad.check.scene import share_scenes
from rigcad.optics.frames import Pose
from rigcad.check.sources import annulus_rays, pixel_rays
from rigcad.check.trace3d import OCCLUDED_BY_BEAM, convergence_point, trace
from rigcad.optics.misalignment import Offsets, misaligned_trace
from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.vec import unit as unit2
from rigcad.optics.trace2d import DomeCurve


def test_pose_round_trip():
    pose = Pose.misaligned((0.3, -0.2, 1.0), 0.01, (1.0, 1.0, 0.0), (0, 0, 150))
    p = np.random.default_rng(0).normal(size=(10, 3))
    lp, ld = pose.localize(p, p)
    # rotation matrices in float64: rounding, 1e-13
    assert np.max(np.abs(pose.globalize_points(lp) - p)) < 1e-12
    assert np.max(np.abs(pose.globalize_dirs(ld) - p)) < 1e-12


def test_exact_design_converges_on_o(analytic, design_map):
    rays = annulus_rays(design_map, 20000, 5)
    tr = trace(analytic, rays.origins, rays.dirs)
    assert tr.ok.mean() > 0.9, "the beam hides ~5 %; nothing else is lost"
    # the 2D design's own bound (tests/optics/test_trace2d.py): 1e-6 mm (measured 1.5e-8 mm)
    assert np.nanmax(tr.miss) < 1e-6
    err = np.arccos(np.clip(np.sum(tr.arrival[tr.ok] * design_map.direction(rays.chief)[tr.ok], axis=1), -1, 1))
    # the 2D profile table interpolated by a quintic spline: ~1e-10 rad measured; 1e-6 is far below a pixel
    assert np.max(err) < 1e-6
    # every loss is the beam (or, at the occlusion limit, the paraboloid), in the beam's azimuths
    lost = ~tr.ok
    phi = np.degrees(np.arctan2(rays.chief[lost, 1], rays.chief[lost, 0])) % 180
    beam = tr.status[lost] == OCCLUDED_BY_BEAM
    assert beam.mean() > 0.95
    assert np.all((phi[beam] < 30) | (phi[beam] > 150)), "the beam runs along x"


@pytest.mark.parametrize("dx", [0.0, 1.0])
def test_meridional_rays_match_the_2d_tracer(rig, analytic, design_map, dx):
    """Rays in the y-z plane (the beam runs along x and would hide the x-z plane) through the 3D
    analytic tracer and through rigcad.optics.trace2d (an independent implementation, its x = our
    y), aligned and with the paraboloid shifted by dx mm across."""
    geo = rig.geometry
    x = np.linspace(-15.5, 15.5, 301)
    x = x[np.abs(x) > 3.0]
    para2 = Paraboloid(geo.focal_length, geo.vertex_z, geo.rim_radius)
    cop2 = np.array([0.0, geo.cop_z])
    d2 = unit2(para2.point(x) - cop2)
    o2 = np.tile(cop2, (len(x), 1))
    t2 = misaligned_trace(para2, DomeCurve.from_profile(rig.dome), o2, d2, Offsets(paraboloid_dx=dx))
    o3 = np.column_stack([np.zeros(len(x)), o2[:, 0], o2[:, 1]])
    d3 = np.column_stack([np.zeros(len(x)), d2[:, 0], d2[:, 1]])
    placed = analytic.placed(Pose.misaligned((0, dx, 0)) if dx else None)
    t3 = trace(placed, o3, d3)
    both = t2.ok & t3.ok
    assert both.sum() > 0.9 * len(x)
    # signed 2D miss vs 3D distance to O: the two tracers' float64 Newton solutions, measured ~1e-9 mm
    assert np.max(np.abs(np.abs(t2.miss[both]) - t3.miss[both])) < 1e-6
    theta2 = np.abs(t2.theta[both])
    assert np.max(np.abs(theta2 - t3.theta[both])) < 1e-7  # rad, same reason


def test_shifted_paraboloid_moves_the_spot_as_the_analytic_trace_predicts(rig, analytic, fine, design_map):
    mis = MC.Misalignment.none().with_("paraboloid", offset=(1.0, 0.0, 0.0))
    spots = {}
    for name, optics in (("analytic", analytic), ("smooth", fine), ("mesh", share_scenes(fine, "mesh"))):
        tr, _, _ = MC.trace_path(optics, rig, design_map, mis, "projector", 20000, 9)
        spots[name] = convergence_point(tr)
    shift = np.linalg.norm(spots["analytic"])
    # the 1 mm shift moves the convergence point by ~0.8 mm (sensitivity table): not a null test
    assert 0.3 < shift < 3.0, shift
    # smooth mesh at 0.003 mm / 0.003 rad: its aligned spot is < 1 um, so it predicts the shift to 1 um
    assert np.linalg.norm(spots["smooth"] - spots["analytic"]) < 1e-3
    # flat facets at 0.003 rad scatter rays by ~0.5 mm but average out over 20000 rays: 0.05 mm
    assert np.linalg.norm(spots["mesh"] - spots["analytic"]) < 0.05


def test_mesh_error_shrinks_with_the_tessellation(analytic, coarse, fine, design_map):
    rays = annulus_rays(design_map, 20000, 3)
    exact = trace(analytic, rays.origins, rays.dirs)
    errs = {}
    for name, optics in (("coarse", coarse), ("fine", fine)):
        for mode in ("mesh", "smooth"):
            tr = trace(share_scenes(optics, mode), rays.origins, rays.dirs)
            both = tr.ok & exact.ok
            errs[name, mode] = np.max(np.arccos(np.clip(np.sum(tr.arrival[both] * exact.arrival[both], axis=1), -1, 1)))
    # flat facets: the arrival error follows the facet-normal error, ~linear (0.01 -> 0.003 rad: 3.3x);
    # at least 2x smaller
    assert errs["fine", "mesh"] < errs["coarse", "mesh"] / 2
    # smooth reading: second order in the facet size, ~10x for 3.3x; at least 4x
    assert errs["fine", "smooth"] < errs["coarse", "smooth"] / 4
    # and the smooth reading is far better than the flat one at the same mesh (measured ~100x)
    assert errs["coarse", "smooth"] < errs["coarse", "mesh"] / 20


def test_pixel_rays_follow_the_convention(design_map):
    r = pixel_rays(design_map, np.array([10.0, 0.0]), np.array([0.0, 10.0]))
    assert r.dirs[0, 0] > 0 and abs(r.dirs[0, 1]) < 1e-15 and r.dirs[1, 1] > 0
