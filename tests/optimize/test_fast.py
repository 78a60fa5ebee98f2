"""The optimiser's fast evaluation against the certified path (Rig.from_profile + the 2D design),
closed forms and an independent tracer (the 3D ray check's analytic surfaces)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.optimize.fast import fast_design, mount_boxes
from rigcad.optimize.problem import apply
from rigcad.parts.occlusion import blocked_solid_angle
from rigcad.optics.design import profile_table
from rigcad.profile import derive
from rigcad.rig import Rig

KEYS = ["layout.cop_to_vertex", "layout.sample_to_rim", "paraboloid.vertical_extent", "paraboloid.tangent_angle"]
#: Table 3.1 and two designs far from it (a near COP with a pointed paraboloid; a far sample). The
#: near COP is 215 mm: at 200 mm the COP tower's projector shelf would stand in the dome's top.
DESIGNS = [None, (215.0, 200.0, 25.0, math.radians(13.0)), (380.0, 110.0, 15.0, math.radians(27.0))]


@pytest.fixture(scope="module", params=range(len(DESIGNS)))
def pair(request, table31):
    x = DESIGNS[request.param]
    profile = table31 if x is None else apply(table31, KEYS, x)
    rig = Rig.from_profile(profile)
    return profile, rig, fast_design(profile, derive(profile)).figures


def test_theta_range_is_the_closed_form(pair):
    profile, rig, f = pair
    g = rig.geometry
    # the occlusion limit is atan(rim radius / rim height) (optics.dome: the dome ends where the
    # paraboloid's rim hides O); the rim ray is grazing
    assert f["theta_min_deg"] == pytest.approx(math.degrees(math.atan2(g.rim_radius, g.rim_z)), abs=1e-9)
    assert f["theta_max_deg"] == pytest.approx(90.0, abs=1e-9)


def test_pixels_per_degree_agree_with_the_certified_design(pair):
    profile, rig, f = pair
    px = rig.design.report["pixels"]
    # the mean is exact in both (pixel span / theta span); the certified minimum is read by
    # np.gradient on 2001+ rows (second order, ~1e-6 relative on these designs)
    assert f["px_per_deg_mean"] == pytest.approx(px["px_per_deg_mean"], rel=1e-10)
    assert f["px_per_deg_min"] == pytest.approx(px["px_per_deg_min"], rel=2e-5)
    assert f["useful_px"] == pytest.approx(px["useful_px"], rel=1e-10)


def test_px_per_degree_cv_against_the_certified_profile_table(pair):
    profile, rig, f = pair
    t = rig.design.table
    theta = t["incidence_theta_deg"]  # rows evenly spaced in theta: a theta-uniform sample
    d = np.abs(np.gradient(t["projector_pixel"], theta))
    cv = d.std() / d.mean()
    # the table's rows are a discrete, second-order sample of the same function: they agree to the
    # rows' own error (measured ~1e-5 relative with 2001 rows)
    assert f["px_per_deg_cv"] == pytest.approx(cv, rel=1e-3)


def test_envelope_and_top_opening_agree_with_the_certified_design(pair):
    profile, rig, f = pair
    r = rig.design.report
    assert f["dome_width_mm"] == pytest.approx(r["envelope"]["width_mm"], abs=2e-3)  # peak between samples
    assert f["dome_height_mm"] == pytest.approx(r["envelope"]["height_mm"], abs=1e-8)
    assert f["top_clearance_mm"] == pytest.approx(r["top_aperture"]["clearance_mm"], abs=1e-8)


def test_printed_outline_agrees_with_the_part_layout(pair):
    profile, rig, f = pair
    lay = rig.layout
    # flange outer radius and the outer wall: the layout's meridians (offset curves of the spline)
    assert f["dome_outer_width_mm"] / 2 == pytest.approx(
        max(lay.flange_outer_r, float(lay.dome_outer.points(lay.dome_outer.sample(4001))[:, 0].max())), abs=0.05)


def test_mount_boxes_are_the_part_recipes_occluders(pair):
    profile, rig, f = pair
    _, boxes = mount_boxes(profile, rig.geometry)
    occ = {name: solid for group in rig.occluders.values() for name, solid in group}
    beam, clamp, stem = occ["beam"], occ["clamp"], occ["stem"]
    assert boxes[0][1:] == pytest.approx((beam.hi[1], beam.lo[2], beam.hi[2]), abs=1e-9)
    assert boxes[1] == pytest.approx((clamp.hi[0], clamp.hi[1], clamp.lo[2], clamp.hi[2]), abs=1e-9)
    assert boxes[2] == pytest.approx((stem.radius, stem.radius, stem.base[2], stem.base[2] + stem.height), abs=1e-9)


def test_occluded_solid_angle_agrees_with_the_occlusion_report(pair):
    profile, rig, f = pair
    ref = blocked_solid_angle(rig.occluders, profile_table(rig.geometry, rig.dome), n_theta=400, n_phi=1440)
    # the report counts grid cells (400 x 1440): its own error is about a cell row's share
    assert f["occluded_solid_angle_sr"] == pytest.approx(ref["blocked_solid_angle_sr"], rel=0.01, abs=2e-3)


def test_quadrature_converges(table31):
    g = derive(table31)
    a, b = fast_design(table31, g, 24).figures, fast_design(table31, g, 128).figures
    for k in ("px_per_deg_cv", "px_per_deg_mean", "px_per_deg_min"):
        assert a[k] == pytest.approx(b[k], rel=1e-9), k  # spectral convergence: 24 nodes already exact to 1e-9
    # the occluded share has kinks (a path entering a box): it converges, slowly
    assert a["occluded_fraction"] == pytest.approx(b["occluded_fraction"], rel=0.01)


def test_occluded_fraction_is_what_the_3d_check_loses(table31):
    """Independent truth: the ray checker's analytic 3D trace through the exact surfaces and the
    mount's boxes and cylinder, rays uniform over the pixel annulus (what raycheck.max_lost_fraction counts)."""
    x = DESIGNS[1]
    profile = apply(table31, KEYS, x)
    f = fast_design(profile, derive(profile)).figures
    rays = 60_000
    check = Rig.from_profile(profile).check(rays=rays, mode="analytic", monte_carlo=False, grid=False)
    lost = check.report["readings"]["analytic"]["lost_fraction"]
    sigma = math.sqrt(lost * (1 - lost) / rays)
    assert abs(f["occluded_fraction"] - lost) < 4 * sigma + 1e-3, (f["occluded_fraction"], lost)  # 4 sigma of the rays


@pytest.mark.parametrize("key, value", [("paraboloid.tangent_angle", math.radians(60.0)),  # rim ray goes up
                                        ("paraboloid.tangent_angle", math.radians(85.0)),
                                        ("paraboloid.vertical_extent", 1.0)])  # < 10 px vertex to rim
def test_refuses_what_the_certified_path_refuses(table31, key, value):
    bad = apply(table31, [key], [value])
    with pytest.raises(GeometryError) as fast_err:
        fast_design(bad, derive(bad))
    with pytest.raises(GeometryError) as rig_err:
        Rig.from_profile(bad)
    assert fast_err.value.message == rig_err.value.message  # the same check, the same words
