"""Simulated acquisition on the rig (thesis 3.3.1, eq. 4.3): the rig's own projector and camera pixels
against Gauss quadrature of eq. 4.3, as designed and with the paraboloid moved by its tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.basis.acquire import camera_view, models, simulate_on_rig
from rigcad.basis.projector import zone_of
from rigcad.errors import BasisError

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

#: Every 48th camera pixel: 26 exitant directions over the zone (the CLI's default, 32, gives 49).
STRIDE = 48


@pytest.fixture(scope="module")
def rig(table31_rig):
    return table31_rig


@pytest.fixture(scope="module")
def sim(rig):
    tol = rig.profile.tolerancing
    return simulate_on_rig(rig, 6, moved=[rig.moved("paraboloid", offset=(tol.paraboloid_offset, 0.0, 0.0))],
                           camera_stride_px=STRIDE).report


def test_camera_pixels_see_the_zone_from_the_same_cop(rig):
    zone = zone_of(rig)
    cam = camera_view(rig, zone, STRIDE)
    theta = np.arccos(cam.wo[:, 2])
    assert len(cam.wo) >= 15  # enough exitant directions for the figures below to mean something
    # every kept camera pixel looks at O from inside the zone, and they spread over it (measured 18..88 deg)
    assert theta.min() >= zone.alpha_rad and theta.max() <= zone.beta_rad
    assert np.degrees(theta.max() - theta.min()) > 60
    # the camera's ray through a pixel and the projector's through the same image point (scaled by
    # the focal lengths) reach O from the same direction: one map, one COP
    px = cam.pixels
    k = np.nonzero(cam.keep)[0]
    f_ratio = rig.incidence.focal_px / px.focal_px
    proj = rig.incidence.direction(np.stack([px.x_px[k] * f_ratio, px.y_px[k] * f_ratio,
                                             np.full(len(k), -rig.incidence.focal_px)], axis=1))
    assert np.max(np.abs(proj - cam.wo)) < 1e-12  # the same spline lookup: round-off


def test_recovers_eq_4_3_over_what_the_rig_lights_within_one_percent(sim):
    rigs = sim["rigs"]["as_designed"]
    for name in models():
        ref_err = sim["reference"]["error_estimate_lit_zone"][name]
        # the reference's own error estimate (refined panels) stays below the 1 % being tested: at most
        # 9e-4 absolute against coefficients of 0.2 .. 0.37 (3.3e-3 relative, AS Phong). It is first
        # order: the lit part of a polar row jumps where the beam's shadow ends (its far end, ~51 deg),
        # and the polar panels are not split there (the azimuth panels are split at the shadow's edges)
        assert ref_err < 5e-3 * sim["reference"]["max_abs_coefficient"][name], (name, ref_err)
        for o in (2, 4, 6):
            err = rigs["models"][name][f"order_{o}"]["coefficients_vs_lit_zone_rel_l2"]["none"]
            # the target, 1 % relative L2 over all exitant directions and coefficients, for
            # eq. 4.3 over the part of the zone the rig lights (the beam hides 4.4 %); measured
            # 4.3e-4 .. 2.8e-3 (pixel quadrature at a 0.79 deg pitch, 8-bit images)
            assert err < 1e-2, (name, o, err)


def test_the_beams_shadow_costs_a_few_percent_of_the_whole_zone(sim):
    rigs = sim["rigs"]["as_designed"]
    for name in models():
        err = rigs["models"][name]["order_2"]["coefficients_vs_zone_rel_l2"]["none"]
        # against the whole zone the missing 4.4 % of directions shows (measured 5.2 .. 8.5 %)
        assert 0.02 < err < 0.15, (name, err)
    # a Lambertian slice lies in the span of the displayed images: least squares over the lit pixels
    # fills the shadow (measured 4.3e-4, against 5.2 % without the correction)
    lam = rigs["models"]["lambert"]["order_2"]["coefficients_vs_zone_rel_l2"]["gram"]
    assert lam < 1e-2, lam


def test_lambertian_from_two_orders(sim):
    # thesis 4.1.2: the 18 % gray card measured with orders 0 and 1, through SH and the cap
    card = sim["rigs"]["as_designed"]["gray_card_order_1"]
    # the 1 % target, on the hemispherical reflectance and the reconstructed slice (measured
    # 1.5e-3 and 1.3e-3 with the Gram correction; 3.8 % without it: the beam's shadow)
    assert card["gram"]["albedo_max_rel_error"] < 1e-2, card
    assert card["gram"]["slice_rel_l2"] < 1e-2, card
    assert card["none"]["albedo_max_rel_error"] > 1e-2, card  # the uncorrected card does see the shadow


def test_exact_coefficients_show_the_orders_own_limit(sim):
    exact = sim["exact_coefficients"]
    for o in (2, 4, 6):
        # cos(theta) is in span{Z_0^0, Z_1^0}: the Lambertian slice, its cap and albedo are exact (round-off)
        assert exact["lambert"][f"order_{o}"]["slice_rel_l2"] < 1e-12
        assert exact["lambert"][f"order_{o}"]["albedo_max_rel_error"] < 1e-12
    for name in ("ward", "cook_torrance"):
        cap = [exact[name][f"order_{o}"]["cap_rel_l2"] for o in (2, 4, 6)]
        # extrapolation into the cap improves with the order for these lobes (measured 0.38, 0.21, 0.065
        # for Ward; 0.29, 0.11, 0.033 for Cook-Torrance)
        assert cap[0] > cap[1] > cap[2], (name, cap)


def test_moving_the_paraboloid_by_its_tolerance(sim):
    aligned, moved = sim["rigs"]["as_designed"], sim["rigs"]["moved_1"]
    assert moved["rig"] == "paraboloid moved by (0.1, 0, 0) mm"
    g = moved["geometry"]
    # projector and camera share the optics, so their pixels' directions move alike (measured rms
    # 0.0084 rad both, ~0.5 deg); the exact figure depends on the pixels sampled
    p, c = g["projector_direction_change_rad"]["rms"], g["camera_direction_change_rad"]["rms"]
    assert 1e-3 < p < 0.05 and abs(p / c - 1) < 0.2, (p, c)
    for name in models():
        a = aligned["models"][name]["order_6"]["coefficients_vs_lit_zone_rel_l2"]["none"]
        m = moved["models"][name]["order_6"]["coefficients_vs_lit_zone_rel_l2"]["none"]
        # half a degree of misalignment is larger than the rig's own error (measured 1.2 % .. 6.7 %
        # moved against 0.15 % .. 0.28 % aligned)
        assert m > 3 * a, (name, a, m)


def test_lobe_width_study_on_the_rigs_pixels(sim):
    rows = sim["lobe_width_study"]["rows"]
    pitch = rows[0]["pitch_rad"]
    # the rig's pitch: sqrt of the median lit pixel's solid angle, ~0.8 deg (thesis: about 1 px/deg)
    assert 0.5 < math.degrees(pitch) < 1.2
    narrow = [r["rel_l2_error"] for r in rows if r["width_over_pitch"] < 1.5]
    # below ~1.5 pitches the pixels alias the lobe: the error rises as it narrows (measured 8e-5 at
    # 1.4 pitches, 15 % at 0.72, 77 % at 0.36)
    assert all(x < y for x, y in zip(narrow, narrow[1:])) and narrow[-1] > 0.3, narrow
    # lobes 2-8 pitches wide, inside the zone, are integrated to round-off level (measured <= 3e-10)
    assert all(r["rel_l2_error"] < 1e-6 for r in rows if 2 < r["width_over_pitch"] < 8), rows


def test_bad_arguments_are_refused(rig):
    with pytest.raises(BasisError, match="bits = 12"):
        simulate_on_rig(rig, 2, bits=12)
    with pytest.raises(BasisError, match="camera stride = 2000 px leaves"):
        simulate_on_rig(rig, 1, camera_stride_px=2000, moved=[], lobe_study=False)
