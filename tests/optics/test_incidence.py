"""The design's map from a COP ray (or a projector pixel) to its incidence direction at O
(rigcad.optics.incidence) against the thesis's geometry traced by hand: the COP ray meets the
paraboloid z = vertex_z - r^2 / 4f (closed-form root), is reflected about its normal (r / 2f, 1), and
lands on the equal-path dome: |CP| + |PD| + |DO| = L, with L the rim ray's path to the sample plane
(thesis 3.2: the dome starts where the rim ray meets z = 0), so |PD| = (R^2 - |P|^2) / 2(P.u + R)
with R = L - |CP|. Nothing here reads the dome's integration."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.optics.incidence import TABLE_CELLS, DesignMap, _arrival, _lookup, camera_focal_px
from rigcad.profile import derive, load_profile


@pytest.fixture(scope="module")
def rig(table31):
    from rigcad.rig import Rig

    return Rig.from_profile(table31)


@pytest.fixture
def dm(rig):
    """The map built afresh for each test (33 ms): mutation testing runs, for a mutant of
    from_design, only the tests that call it, and a shared map would be built by the first alone."""
    return DesignMap.from_design(rig.geometry, rig.dome)


def _paraboloid_hit(geo, alpha):
    """COP ray at angle alpha from the axis (meridional plane, r >= 0): the paraboloid point P
    (r, z), the reflected unit direction u, and |CP|."""
    f, v, c = geo.focal_length, geo.vertex_z, geo.cop_z
    sa, ca = np.sin(alpha), np.cos(alpha)
    # (sa^2 / 4f) t^2 - ca t + (c - v) = 0, the near root in its cancellation-free form
    t = 2 * (c - v) / (ca + np.sqrt(ca * ca - sa * sa * (c - v) / f))
    P = np.stack([t * sa, c - t * ca], axis=-1)
    d = np.stack([sa, -ca], axis=-1)
    n = np.stack([P[:, 0] / (2 * f), np.ones_like(sa)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    u = d - 2 * np.sum(d * n, axis=-1, keepdims=True) * n
    return P, u, t


def _theta(geo, alpha):
    """Incidence angle (rad from +z) of the COP ray at alpha, by the equal-path construction."""
    rim_alpha = math.atan2(geo.rim_radius, geo.cop_z - geo.rim_z)
    P0, u0, t0 = _paraboloid_hit(geo, np.array([rim_alpha]))
    land = -P0[0, 1] / u0[0, 1]  # the rim ray meets z = 0
    L = t0[0] + land + np.linalg.norm(P0[0] + land * u0[0])
    P, u, t = _paraboloid_hit(geo, alpha)
    R = L - t
    k = (R * R - np.sum(P * P, axis=-1)) / (2 * (np.sum(P * u, axis=-1) + R))
    D = P + k[:, None] * u
    return np.arctan2(D[:, 0], D[:, 1]), P


#: the map's error against the construction: 1.5e-11 rad measured (dome integrated to 1e-9 mm,
#: quintic spline, 2^16-cell table); the bound leaves 60x
THETA_TOL = 1e-9


def test_the_useful_annulus_runs_from_the_occlusion_limit_to_the_rim(rig, dm):
    geo = rig.geometry
    assert dm.alpha_max == pytest.approx(math.atan2(geo.rim_radius, geo.cop_z - geo.rim_z), rel=1e-12)
    assert dm.s_max == pytest.approx(geo.rim_radius, rel=1e-12)
    # the first row: the paraboloid point whose ray grazes the rim (theta = occlusion_theta), seen from the COP
    theta, P = _theta(geo, np.array([dm.alpha_min]))
    assert theta[0] == pytest.approx(geo.occlusion_theta, abs=THETA_TOL)
    assert P[0, 0] == pytest.approx(dm.s_min, rel=1e-9)
    assert dm.cop_z == geo.cop_z and dm.focal_px == geo.projector_focal_px == 1024 * 1.75
    assert 0 < dm.alpha_min < dm.alpha_max and 0 < dm.s_min < dm.s_max


def test_cop_rays_arrive_at_the_equal_path_incidence_in_their_azimuth(rig, dm):
    rng = np.random.default_rng(5)
    # the ends moved 1e-12 inside: arctan2 of the ray's components may round alpha by an ulp out
    ends = [dm.alpha_min * (1 + 1e-12), dm.alpha_max * (1 - 1e-12)]
    alpha = np.concatenate([ends, rng.uniform(dm.alpha_min, dm.alpha_max, 500)])
    phi = np.concatenate([[0.0, 0.5 * math.pi], rng.uniform(-math.pi, math.pi, 500)])
    theta, _ = _theta(rig.geometry, alpha)
    # the rim ray lands on the sample plane: 90 deg
    assert _theta(rig.geometry, np.array([dm.alpha_max]))[0][0] == pytest.approx(0.5 * math.pi, abs=1e-12)
    scale = rng.uniform(0.5, 3.0, alpha.size)[:, None]  # COP rays need not be unit
    dirs = scale * np.column_stack([np.sin(alpha) * np.cos(phi), np.sin(alpha) * np.sin(phi), -np.cos(alpha)])
    got = dm.direction(dirs)
    want = np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    assert np.max(np.abs(got - want)) < THETA_TOL


def test_paraboloid_points_arrive_at_the_same_directions_as_their_cop_rays(rig, dm):
    rng = np.random.default_rng(6)
    # the ends 1e-9 inside: P's radius here is the map's s_min, s_max to round-off only
    alpha = np.concatenate([[dm.alpha_min * (1 + 1e-9), dm.alpha_max * (1 - 1e-9)],
                            rng.uniform(dm.alpha_min, dm.alpha_max, 300)])
    phi = np.concatenate([[math.pi, -0.5 * math.pi], rng.uniform(-math.pi, math.pi, 300)])
    theta, P = _theta(rig.geometry, alpha)
    local = np.column_stack([P[:, 0] * np.cos(phi), P[:, 0] * np.sin(phi), P[:, 1]])
    got = dm.direction_at(local)
    want = np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    assert np.max(np.abs(got - want)) < THETA_TOL


def test_a_coarse_dome_is_mapped_to_a_quintic_splines_accuracy(rig):
    """On a 41-row dome the rows' spacing, not their integration, sets the map's error: the quintic
    spline through the rows is 9e-12 rad off the construction by COP angle and 1.6e-10 rad by
    paraboloid radius (measured); a cubic's are 1.2e-8 and 3.5e-8 rad, and a spline missing the
    first row is 5e-10 rad off near the occlusion limit."""
    from rigcad.optics.dome import build_dome

    geo = rig.geometry
    coarse = DesignMap.from_design(geo, build_dome(geo, "dop853", tolerance=1e-9, rows=41))
    alpha = np.linspace(coarse.alpha_min, coarse.alpha_max, 4001)[1:-1]  # the ends inside (arctan2's ulp)
    theta, P = _theta(geo, alpha)
    got = coarse.direction(np.column_stack([np.sin(alpha), np.zeros_like(alpha), -np.cos(alpha)]))
    assert np.max(np.abs(np.arccos(got[:, 2]) - theta)) < 1e-10
    got = coarse.direction_at(np.column_stack([P[:, 0], np.zeros_like(alpha), P[:, 1]]))
    assert np.max(np.abs(np.arctan2(got[:, 0], got[:, 2]) - theta)) < 1e-9


def test_outside_the_annulus_is_nan_and_its_ends_are_inside(dm):
    # alpha's ends 1e-12 inside (arctan2 of the components may round by an ulp), 1e-9 outside
    a = np.array([dm.alpha_min * (1 + 1e-12), dm.alpha_max * (1 - 1e-12), dm.alpha_min * (1 - 1e-9),
                  dm.alpha_max * (1 + 1e-9), 0.0, 0.5])
    dirs = np.column_stack([np.sin(a), np.zeros_like(a), -np.cos(a)])
    out = dm.direction(dirs)
    assert np.isfinite(out[:2]).all() and np.isnan(out[2:]).all()
    # the radius's ends exactly: hypot(0, s) is s
    s = np.array([dm.s_min, dm.s_max, dm.s_min * (1 - 1e-9), dm.s_max * (1 + 1e-9), 0.0, 30.0])
    out = dm.direction_at(np.column_stack([np.zeros_like(s), s, np.full_like(s, 150.0)]))
    assert np.isfinite(out[:2]).all() and np.isnan(out[2:]).all()
    # the ends: the design's extreme angles, at azimuth +y
    assert out[1] == pytest.approx([0.0, 1.0, 0.0], abs=THETA_TOL)


def test_table_lookup_is_the_spline_within_its_stated_error(dm):
    # "linear interpolation on 2^16 cells errs by under 3e-11 rad": the table is the spline sampled
    assert TABLE_CELLS == 1 << 16
    assert dm.alpha_table[0].size == dm.radius_table[0].size == TABLE_CELLS + 1
    a = np.linspace(dm.alpha_min, dm.alpha_max, 20011)
    theta = np.arccos(dm.direction(np.column_stack([np.sin(a), np.zeros_like(a), -np.cos(a)]))[:, 2])
    assert np.max(np.abs(theta - dm.spline(a))) < 3e-11
    s = np.linspace(dm.s_min, dm.s_max, 20011)
    d = dm.direction_at(np.column_stack([s, np.zeros_like(s), np.zeros_like(s)]))
    assert np.max(np.abs(np.arctan2(d[:, 0], d[:, 2]) - dm.by_radius(s))) < 3e-11
    # the two splines agree through the paraboloid (same rows)
    assert abs(float(dm.spline(dm.alpha_max)) - float(dm.by_radius(dm.s_max))) < 1e-12


def test_lookup_interpolates_linearly_clamps_its_ends_and_keeps_nan():
    grid = np.linspace(0.5, 2.5, 5)  # cells of 0.5
    values = np.array([1.0, 3.0, -1.0, 0.0, 4.0])
    x = np.array([0.5, 0.75, 1.0, 1.4, 2.25, 2.5, 2.4999999, 0.0, 3.0, np.nan, -np.inf, np.inf])
    want = np.array([1.0, 2.0, 3.0, -0.2, 2.0, 4.0, 4.0 - 8e-7, 1.0, 4.0, np.nan, 1.0, 4.0])
    got = _lookup(x, (grid, values))
    assert np.allclose(got, want, rtol=0, atol=1e-12, equal_nan=True)
    assert np.isnan(got[9]) and not np.isnan(got[:9]).any()
    rng = np.random.default_rng(2)
    g = np.linspace(-1.0, 3.0, 1001)
    v = np.cos(3 * g)
    x = rng.uniform(-2, 4, 3000)
    assert np.allclose(_lookup(x, (g, v)), np.interp(x, g, v), rtol=0, atol=1e-14)


def test_arrival_on_the_axis_takes_the_x_azimuth_without_a_floating_point_warning():
    with np.errstate(all="raise"):  # 0 / 0 on the axis is not an error to report
        out = _arrival(np.array([0.5, 0.5, 0.5]), np.array([0.0, 3.0, 0.0]), np.array([0.0, 4.0, -2.0]),
                       np.array([0.0, 5.0, 2.0]))
        _arrival(np.array([0.5]), np.array([1.0]), np.array([0.0]), np.array([0.0]))  # x / 0 likewise
    s, c = math.sin(0.5), math.cos(0.5)
    assert np.allclose(out, [[s, 0.0, c], [0.6 * s, 0.8 * s, c], [0.0, -s, c]], rtol=0, atol=1e-15)


def test_pixel_radius_is_the_focal_length_times_tan_alpha(dm):
    # pixel centres at (x, y) from the image centre look along (x, y, -f_px): alpha = atan(hypot / f)
    x, y = np.array([0.5, 30.5, -100.5]), np.array([0.5, -40.5, 7.5])
    alpha = np.arctan2(np.hypot(x, y), dm.focal_px)
    assert np.allclose(dm.pixel_radius(alpha), np.hypot(x, y), rtol=1e-13, atol=0)


def test_camera_focal_length_frames_the_paraboloid_as_the_projector(rig, dm):
    # f_camera = f_projector x camera height / projector height: 1792 x 1024 / 768 (thesis Table 3.1: 2389 px)
    assert camera_focal_px(rig) == pytest.approx(1792 * 1024 / 768, rel=1e-15)
    from rigcad.optics.camera import derived_focal_px

    # without a lens (no camera.focal_length, no camera.lens) the camera's is derived this way
    fake = SimpleNamespace(camera=SimpleNamespace(resolution=(640, 300)), projector=SimpleNamespace(resolution=(800, 600)))
    assert derived_focal_px(fake, SimpleNamespace(projector_focal_px=1000.0)) == pytest.approx(500.0, rel=1e-15)


def test_a_cop_at_infinity_has_no_projector_pixels(tmp_path, table31_text):
    path = tmp_path / "far.yaml"
    path.write_text(table31_text.replace("27 cm", "inf"))
    geo = derive(load_profile(path))
    with pytest.raises(GeometryError) as e:
        DesignMap.from_design(geo, None)
    assert str(e.value).startswith("projector pixels need a finite COP (layout.cop_to_vertex)")
    assert e.value.param == "layout.cop_to_vertex"
