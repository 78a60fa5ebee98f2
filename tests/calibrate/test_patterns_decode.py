"""The maths core against closed forms: patterns, N-step phase, Gray code, unwrapping, raxel lines,
and the profile's calibration section."""

import math

import numpy as np
import pytest

from rigcad.calibrate.decode import decode, fringes, gray_to_index
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import on_screen, rays, screen_pose, to_global
from rigcad.errors import ProfileError
from rigcad.profile.schema import load_profile

SEQ = Sequence(periods=(64, 8), steps=4, gray_bits=5, resolution=(640, 400), pitch=0.1)


def test_sequence_names_and_images():
    names = SEQ.names()
    assert names[:2] == ["white", "black"] and len(names) == 2 + 2 * (5 + 2 * 4) and len(set(names)) == len(names)
    img = SEQ.image("x_p64_s0")
    assert img.shape == (400, 640) and img.dtype == np.uint8
    # cos(2 pi (i + 0.5) / 64) at the column nearest its peak and trough
    assert img[0, 0] == round(255 * (0.5 + 0.5 * math.cos(2 * math.pi * 0.5 / 64)))
    assert img[0, 32] == round(255 * (0.5 + 0.5 * math.cos(2 * math.pi * 32.5 / 64)))
    assert (SEQ.image("y_gray0")[:, 0] == SEQ.image("y_gray0")[:, 5]).all()


def test_footprint_mean_integrates_the_staircase():
    """Against brute force: the mean of the displayed pixels over a fine grid of the parallelogram."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        cx, cy = rng.uniform(1, 630), rng.uniform(1, 390)
        edges = rng.uniform(-3, 3, (2, 2))
        s = (np.arange(400) + 0.5) / 400 - 0.5
        a, b = np.meshgrid(s, s)
        px = cx + a * edges[0, 0] + b * edges[1, 0]
        py = cy + a * edges[0, 1] + b * edges[1, 1]
        for name in ("x_p8_s1", "y_p64_s3", "x_gray4"):
            brute = SEQ.sample(name, px, py).mean()
            assert SEQ.footprint_mean(name, np.array(cx), np.array(cy), edges) == pytest.approx(brute, abs=3e-3)


def test_gray_code_numbers_every_stripe():
    c = np.arange(640) + 0.5
    bits = [SEQ.sample(f"x_gray{b}", c, np.full_like(c, 1.0)) > 0.5 for b in range(5)]
    assert np.array_equal(gray_to_index(bits), np.floor(c / 32).astype(int))
    # neighbouring stripes differ in one bit only (the Gray property)
    codes = np.stack(bits, axis=1)[::32]
    assert (np.abs(np.diff(codes.astype(int), axis=0)).sum(axis=1) == 1).all()


@pytest.mark.parametrize("steps", [3, 4, 7])
def test_n_step_phase_is_exact_on_sinusoids(steps):
    phi = np.linspace(0.01, 2 * np.pi - 0.01, 50)
    frames = [3.0 + 2.0 * np.cos(phi - 2 * np.pi * n / steps) for n in range(steps)]
    f = fringes(frames)
    np.testing.assert_allclose(f.phase, phi, atol=1e-12)
    np.testing.assert_allclose(f.mean, 3.0, atol=1e-12)
    np.testing.assert_allclose(f.amplitude, 2.0, atol=1e-12)
    if steps > 3:
        assert np.nanmax(f.misfit) < 1e-12
        swapped = frames[:]
        swapped[0], swapped[1] = swapped[1], swapped[0]
        assert np.nanmedian(fringes(swapped).misfit) > 0.3  # frames out of order do not fit a sinusoid


def _camera(seq, cx, cy, footprint=1.5, noise=0.0, seed=0):
    """A synthetic capture: each 'camera pixel' sees screen point (cx, cy) px averaged over a
    footprint (4 x 4 sub-points), with additive noise (values 0..1)."""
    rng = np.random.default_rng(seed)
    edges = np.broadcast_to(np.array([[footprint, 0.0], [0.0, footprint]]), cx.shape + (2, 2))
    out = {}
    for name in seq.names():
        val = seq.footprint_mean(name, cx, cy, edges)
        out[name] = 0.05 + 0.9 * val + noise * rng.standard_normal(val.shape)
    return out


def test_decode_recovers_screen_points():
    rng = np.random.default_rng(3)
    cx = rng.uniform(2, 638, (30, 40))
    cy = rng.uniform(2, 398, (30, 40))
    d = decode(SEQ, _camera(SEQ, cx, cy, noise=0.002), 0.1)
    assert d.valid.all()
    # the fine period (8 px) with 0.2 % noise: ~0.01 px; pixelation of the screen adds < 0.05 px
    np.testing.assert_allclose(SEQ.from_mm(d.u, d.v)[0], cx, atol=0.1)
    np.testing.assert_allclose(SEQ.from_mm(d.u, d.v)[1], cy, atol=0.1)
    assert (d.axes["x"].level == 1).all()


def test_blurred_fine_period_falls_back_to_the_coarse_one():
    cx = np.linspace(10, 600, 200)[None, :]
    cy = np.full_like(cx, 200.0)
    d = decode(SEQ, _camera(SEQ, cx, cy, footprint=8.0), 0.1)  # a footprint of a whole fine period
    assert d.valid.all() and (d.axes["x"].level == 0).all()
    np.testing.assert_allclose(SEQ.from_mm(d.u, d.v)[0], cx, atol=0.6)


def test_the_paraboloids_image_is_lit_against_its_own_white():
    """The screen seen directly (left half, full light) beside the paraboloid's image (right half,
    at the mirrors' 0.36): in the right half, a column of pixels sees the screen over a tenth of its
    footprint (the rest past the screen's edge: black). Its contrast, 0.032 (a tenth of the right
    half's 0.324), is under the lit threshold taken from the direct view's white (0.05 x 0.9) and
    over the one taken from the mirrored image's own (0.05 x 0.324): with the paraboloid's image as
    the reference it is lit, without it it is not; the pixels that see no screen stay unlit."""
    rng = np.random.default_rng(5)
    cx, cy = rng.uniform(2, 638, (20, 40)), rng.uniform(2, 398, (20, 40))
    frames = _camera(SEQ, cx, cy)
    gain = np.ones((20, 40))
    gain[:, 20:] = 0.36
    gain[:, 30] *= 0.1  # a tenth of the footprint on the screen
    gain[:, 35] = 0.0  # no screen
    images = {n: 0.02 + gain * (im - 0.05) for n, im in frames.items()}
    core = np.zeros((20, 40), bool)
    core[:, 20:] = True
    plain, seen = decode(SEQ, images, 0.1), decode(SEQ, images, 0.1, core)
    assert not plain.lit[:, 30].any() and seen.lit[:, 30].all()
    assert plain.lit[:, :30].all() and seen.lit[:, :30].all()
    assert not seen.lit[:, 35].any()


def test_frames_out_of_order_tear_the_decoded_map():
    cx, cy = np.meshgrid(np.linspace(5, 630, 60), np.linspace(5, 390, 40))  # a smooth view of the screen
    images = _camera(SEQ, cx, cy)
    assert max(decode(SEQ, images, 0.1).jumps(SEQ.stripe).values()) == 0.0
    images["x_gray1"], images["x_gray3"] = images["x_gray3"], images["x_gray1"]
    d = decode(SEQ, images, 0.1)
    assert d.jumps(SEQ.stripe)["x"] > 0.05 and d.jumps(SEQ.stripe)["y"] == 0.0


def test_screen_pose_round_trip_and_raxel_lines():
    pose = screen_pose(7.0, 0.01, -0.02)
    u, v = np.array([1.0, -20.0, 30.0]), np.array([4.0, 5.0, -60.0])
    g = to_global(pose, u, v)
    assert abs(g[0, 2] - 7.0) > 0.01  # the tilt moves points off the untilted plane
    uu, vv = on_screen(pose, g - 3.0 * np.array([0.3, 0.1, 0.9]), np.tile([0.3, 0.1, 0.9], (3, 1)))
    np.testing.assert_allclose(uu, u, atol=1e-12)
    np.testing.assert_allclose(vv, v, atol=1e-12)
    # laid by hand: the screen's centre 0.7 mm along u and -0.4 along v, turned 0.5 deg about its
    # normal, within its tilted plane; untilted, by hand: (u, v) -> T (u, v) + (du, dv) at height 7
    t = np.radians(0.5)
    flat = to_global(screen_pose(7.0, 0.0, 0.0, 0.7, -0.4, t), u, v)
    np.testing.assert_allclose(flat[:, 0], np.cos(t) * u - np.sin(t) * v + 0.7, atol=1e-12)
    np.testing.assert_allclose(flat[:, 1], np.sin(t) * u + np.cos(t) * v - 0.4, atol=1e-12)
    np.testing.assert_allclose(flat[:, 2], 7.0, atol=1e-12)
    placed = screen_pose(7.0, 0.01, -0.02, 0.7, -0.4, t)
    # tilted: the placement moves the point within the tilted plane, by the same distance
    np.testing.assert_allclose(np.linalg.norm(to_global(placed, u, v) - g, axis=1),
                               np.linalg.norm(flat - to_global(screen_pose(7.0), u, v), axis=1), atol=1e-12)
    uu, vv = on_screen(placed, to_global(placed, u, v) - 3.0 * np.array([0.3, 0.1, 0.9]),
                       np.tile([0.3, 0.1, 0.9], (3, 1)))
    np.testing.assert_allclose(uu, u, atol=1e-12)
    np.testing.assert_allclose(vv, v, atol=1e-12)
    # lines through O with known directions, seen at 2 and at 3 heights
    d = np.array([[0.3, 0.1, 0.9], [-0.5, 0.2, 0.6], [0.0, 0.0, 1.0]])
    d /= np.linalg.norm(d, axis=1)[:, None]
    pts = [d * (z / d[:, 2])[:, None] for z in (5.0, 12.0, 20.0)]
    for use in (pts[:2], pts):
        _, got = rays(use)
        np.testing.assert_allclose(got, d, atol=1e-12)
    missing = [p.copy() for p in pts[:2]]
    missing[1][0] = np.nan
    _, got = rays(missing)
    assert np.isnan(got[0]).all() and np.isfinite(got[1:]).all()


def test_calibration_section_units_and_errors(write_profile, table31_text):
    p = load_profile(write_profile(table31_text + "calibration:\n  spacer_heights: [0.1 in, 1 cm, 15 mm]\n"
                                                  "  screen_tilt: 3 mrad\n"))
    assert p.calibration.spacer_heights == pytest.approx((2.54, 10.0, 15.0))
    assert p.calibration.screen_tilt == pytest.approx(0.003)
    for text, words in (("  spacer_heights: [3 mm, 3 mm]\n", ("spacer_heights", "distinct")),
                        ("  spacer_heights: [3 mm, 1 parsec]\n", ("spacer_heights[1]",)),
                        ("  periods: [16, 128]\n", ("periods", "coarse to fine")),
                        ("  gray_bits: 3\n", ("gray_bits", "need >= 6")),
                        ("  phase_steps: 2\n", ("phase_steps", ">= 3")),
                        ("  screen_tilt: 0 deg\n", ("screen_tilt", "> 0")),
                        ("  screen_tilt: 2 mm\n", ("screen_tilt",)),
                        ("  screen_seating: 0 deg\n", ("screen_seating", "> 0")),
                        ("  half_turn: both\n", ("half_turn", "every", "highest", "none"))):
        with pytest.raises(ProfileError) as info:
            load_profile(write_profile(table31_text + "calibration:\n" + text))
        msg = str(info.value)
        assert "p.yaml:" in msg and all(w in msg for w in words), msg
