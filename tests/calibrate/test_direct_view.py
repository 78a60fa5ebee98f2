"""The camera sees the screen directly, past the paraboloid, through the dome's top opening: the
forward model's direct view against closed forms that know nothing of the tracer, and the fit's
rule for which path a decoded pixel shows."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.calibrate import model as M
from rigcad.calibrate.fit import seen_direct


@pytest.fixture(scope="module")
def seen(table31_rig):
    from rigcad.check.scene import analytic_optics

    return table31_rig, analytic_optics(table31_rig), M.Camera.of(table31_rig).design


def _along(rig, optics, design, phi_deg: float, radii: np.ndarray) -> M.Traced:
    phi = math.radians(phi_deg)
    return M.trace_camera(optics, rig, radii * math.cos(phi), radii * math.sin(phi), design)


def test_the_direct_ring_runs_from_the_paraboloid_s_rim_to_the_dome_s_opening(seen):
    """Inner edge: the rim, where the 2D design's incidence map ends (alpha_max). Outer edge: the
    pinhole's image of the coated mirror's top edge, f r / (z_cop - z). The splitter's plate shifts
    the camera's rays by well under a pixel here (measured 0.05-0.3 px), hence the bounds."""
    rig, optics, design = seen
    radii = np.arange(100.0, 360.0, 0.05)
    rim = float(design.pixel_radius(np.array([design.alpha_max]))[0])
    mer = rig.layout.design_dome
    r_open, z_open = mer.points(np.array([mer.u_range[1]]))[0]
    opening = design.focal_px * r_open / (design.cop_z - z_open)
    assert 100 < rim < opening < 360
    for phi in (30, 45, 90, 135, 270, 315):  # clear of the beam, which runs along x
        tr = _along(rig, optics, design, phi, radii)
        ring = radii[tr.direct]
        assert not np.any(tr.ok & tr.direct)
        assert abs(ring.min() - rim) < 0.25, (phi, ring.min(), rim)
        assert abs(ring.max() - opening) < 0.5, (phi, ring.max(), opening)
        assert np.all(np.diff(np.nonzero(tr.direct)[0]) == 1)  # one unbroken ring
        assert np.all(np.isnan(tr.u[tr.direct]))


def test_the_beam_hides_the_direct_view_along_its_length(seen):
    rig, optics, design = seen
    radii = np.arange(140.0, 330.0, 0.5)
    assert not _along(rig, optics, design, 0, radii).direct.any()
    assert not _along(rig, optics, design, 180, radii).direct.any()
    # the beam is 6 mm wide, 114-124 mm above O, ~300 mm below the COP: its shadow at radius r px is
    # ~2 * f * 3 / 304 px wide, about 47 px at any radius
    cross = np.arange(-60.0, 60.0, 0.5)
    tr = M.trace_camera(optics, rig, np.full(cross.size, 250.0), cross, design)
    hidden = cross[~tr.direct]
    half = design.focal_px * rig.profile.beam.width / 2 / (design.cop_z - rig.layout.beam_z[1])
    assert hidden.min() == pytest.approx(-half, abs=1.5) and hidden.max() == pytest.approx(half, abs=1.5)


def test_direct_rays_meet_the_screen_where_a_pinhole_puts_them(seen):
    """A direct ray is a straight line from the COP (the plate shifts it by well under 0.1 mm)."""
    rig, optics, design = seen
    radii = np.arange(150.0, 320.0, 10.0)
    tr = _along(rig, optics, design, 45, radii)
    assert tr.direct.all()
    h = 6.0
    su, sv = tr.screen(M.screens(SimpleNamespace(heights=np.array([h]), turns=np.zeros(1)), np.zeros(
        len(M.RIG_NAMES) + len(M.SCREEN_KEYS)))[0])
    expect = (design.cop_z - h) * radii / design.focal_px
    assert np.allclose(np.hypot(su, sv), expect, atol=0.1)


def test_the_decoded_points_tell_the_path():
    """Lines through a direct ray's points on the lowest and highest screen (6 and 25 mm up, the
    second pair turned a half turn) meet the sample plane 24-60 mm out, a mirrored ray's within a
    few mm of O (a misaligned rig's focus), with each screen laid by hand: up to 1 mm off centre
    along u and v and turned up to 1 deg, as the simulation lays them. (A ray within a degree of
    grazing meets the upper screen's plane over a metre out, where a turn moves its point by
    centimetres; no tablet shows it.)"""
    from rigcad.calibrate.raxel import on_screen

    plan = SimpleNamespace(heights=np.array([6.0, 25.0, 6.0, 25.0]), turns=np.array([0, 0, math.pi, math.pi]))
    rng = np.random.default_rng(3)
    n = 4000
    phi = rng.uniform(0, 2 * math.pi, n)
    direct = rng.random(n) < 0.5
    cop = np.array([0.0, 0.0, 427.5])
    r0 = rng.uniform(24, 60, n)
    focus = np.c_[rng.uniform(-3, 3, (n, 2)), np.zeros(n)]
    theta = np.radians(rng.uniform(7, 89, n))
    out = np.c_[np.cos(phi), np.sin(phi), np.zeros(n)]
    at_plane = np.where(direct[:, None], r0[:, None] * out, focus)
    dirs = np.where(direct[:, None], at_plane - cop, np.sin(theta)[:, None] * out - np.cos(theta)[:, None] * [0, 0, 1.0])
    params = np.zeros(len(M.RIG_NAMES) + 4 * len(M.SCREEN_KEYS))
    for k in range(4):
        j = len(M.RIG_NAMES) + k * len(M.SCREEN_KEYS)
        params[j + 3: j + 5] = rng.uniform(-1, 1, 2)
        params[j + 5] = math.radians(rng.uniform(-1, 1))
    uv = np.stack([np.stack(on_screen(pose, at_plane, dirs), axis=-1) for pose in M.screens(plan, params)], axis=1)
    # what a tablet of 176.5 x 115.9 mm shows at both heights (the profile's default screen)
    shown = np.all((np.abs(uv[..., 0]) < 88.2) & (np.abs(uv[..., 1]) < 57.9), axis=1)
    assert shown.sum() > 3000 and np.degrees(theta[shown & ~direct]).max() > 70
    assert np.array_equal(seen_direct(plan, uv[shown], 24.0), direct[shown])
