"""The paraboloid's and the camera's placement against the dome (model.in_dome_frame) against
closed forms that know nothing of its pose algebra: a whole rig turned and shifted together (which
no image shows) reads zero; a component moved alone reads its own parameters; the dome tilted alone
moves the others' pivots by the rotation's exact sines and cosines; the covariance is the first-order
sum of the variances."""

import math

import numpy as np
import pytest

from rigcad.calibrate import model as M


def _pivot_z(rig, component: str) -> float:
    g = rig.geometry
    return {"paraboloid": g.vertex_z, "camera": g.cop_z, "dome": 0.0}[component]


def _rodrigues(w: np.ndarray) -> np.ndarray:
    angle = float(np.linalg.norm(w))
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / angle
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def _whole_rig_turned(rig, w_xy, shift) -> np.ndarray:
    """The rig's parameters for every component turned by the rotation vector (w_x, w_y, 0) about O
    and shifted by ``shift``: each pivot P goes to R P + shift, each tilt becomes w."""
    rot = _rodrigues(np.array([*w_xy, 0.0]))
    theta = np.zeros(len(M.RIG_NAMES) + 2 * len(M.SCREEN_KEYS))
    for i, c in enumerate(M.COMPONENTS):
        p = np.array([0.0, 0.0, _pivot_z(rig, c)])
        theta[5 * i: 5 * i + 5] = [*(rot @ p + shift - p), *w_xy]
    return theta


@pytest.mark.parametrize("w_xy, shift", [((2e-3, -1e-3), (0.0, 0.0, 0.0)), ((-4e-3, 3e-3), (0.3, -0.2, 0.5))])
def test_the_whole_rig_turned_and_shifted_together_reads_zero(table31_rig, w_xy, shift):
    rel = M.in_dome_frame(table31_rig, _whole_rig_turned(table31_rig, w_xy, np.array(shift)))
    # a camera pivot 427.5 mm up turned 5 mrad moves 2 mm: zero to the rotation's roundoff
    assert np.abs(rel).max() < 1e-12, rel


def test_a_component_moved_alone_reads_its_own_parameters(table31_rig):
    theta = np.zeros(len(M.RIG_NAMES) + 2 * len(M.SCREEN_KEYS))
    own = {"paraboloid": [0.08, -0.05, 0.12, 1.5e-3, -2e-3], "camera": [-0.3, 0.4, 0.7, -4e-3, 6e-3]}
    for i, c in enumerate(M.COMPONENTS):
        if c in own:
            theta[5 * i: 5 * i + 5] = own[c]
    np.testing.assert_allclose(M.in_dome_frame(table31_rig, theta), own["paraboloid"] + own["camera"],
                               rtol=0, atol=1e-12)


def test_the_dome_tilted_alone_moves_the_others_by_the_rotations_sines(table31_rig):
    """The dome turned by t about x (pivot O): in its frame, a pivot (0, 0, z) at rest stands at
    (0, z sin t, z cos t) and is turned by -t."""
    t = 3e-3
    theta = np.zeros(len(M.RIG_NAMES) + 2 * len(M.SCREEN_KEYS))
    theta[M.RIG_NAMES.index("dome_tilt_x_rad")] = t
    rel = M.in_dome_frame(table31_rig, theta)
    want = []
    for c in ("paraboloid", "camera"):
        z = _pivot_z(table31_rig, c)
        want += [0.0, z * math.sin(t), z * (math.cos(t) - 1), -t, 0.0]
    np.testing.assert_allclose(rel, want, rtol=0, atol=1e-12)


def test_the_covariance_is_the_first_order_sum_of_the_variances(table31_rig):
    """With independent parameters, the paraboloid's lateral offset against the dome varies as its
    own offset, the dome's and the dome's tilt times the pivot's height: var = s_p^2 + s_d^2 + z^2 s_t^2."""
    n = len(M.RIG_NAMES) + 2 * len(M.SCREEN_KEYS)
    sd = np.linspace(0.01, 0.05, n)  # a different standard error per parameter
    cov = np.diag(sd ** 2)
    rel = M.in_dome_frame_covariance(table31_rig, np.zeros(n), cov)
    i = {name: M.RIG_NAMES.index(name) for name in M.RIG_NAMES}
    for c in ("paraboloid", "camera"):
        z = _pivot_z(table31_rig, c)
        k = M.DOME_FRAME_NAMES.index(f"{c}_dx_mm")
        want = sd[i[f"{c}_dx_mm"]] ** 2 + sd[i["dome_dx_mm"]] ** 2 + (z * sd[i["dome_tilt_y_rad"]]) ** 2
        assert rel[k, k] == pytest.approx(want, rel=1e-6)
        k = M.DOME_FRAME_NAMES.index(f"{c}_tilt_x_rad")
        assert rel[k, k] == pytest.approx(sd[i[f"{c}_tilt_x_rad"]] ** 2 + sd[i["dome_tilt_x_rad"]] ** 2, rel=1e-6)
        k2 = M.DOME_FRAME_NAMES.index(f"{c}_dy_mm")  # the dome turned by t about x: dy + z t, tilt x - t
        assert rel[k2, k] == pytest.approx(-z * sd[i["dome_tilt_x_rad"]] ** 2, rel=1e-6)


def _one_screen(dome_tilt, screen_tilt, turn=0.0) -> tuple[M.Plan, np.ndarray]:
    """One capture at 30 mm, its screen tilted by the rotation vector ``screen_tilt`` and turned by
    ``turn`` about its normal; the dome tilted by ``dome_tilt``."""
    plan = M.Plan(np.array([30.0]), np.array([0.0]), ("h0",), (0,))
    theta = np.zeros(len(M.RIG_NAMES) + len(M.SCREEN_KEYS))
    theta[M.RIG_NAMES.index("dome_tilt_x_rad"): M.RIG_NAMES.index("dome_tilt_y_rad") + 1] = dome_tilt
    s = M.screen_index(0)
    theta[s + 1: s + 3] = screen_tilt
    theta[s + 5] = turn
    return plan, theta


@pytest.mark.parametrize("turn", [0.0, math.pi, 0.4])
def test_a_screen_against_the_dome_about_one_axis_is_the_difference_of_their_tilts(table31_rig, turn):
    """Dome and screen tilted about x: the screen against the dome is the difference, whatever the
    screen's turn about its normal (a half turn included)."""
    plan, theta = _one_screen((2e-3, 0.0), (-3e-3, 0.0), turn)
    np.testing.assert_allclose(M.screens_in_dome_frame(table31_rig, plan, theta), [[-5e-3, 0.0]], atol=1e-15)


def test_a_screen_against_the_dome_about_crossed_axes_reads_the_exact_rotation(table31_rig):
    """The dome turned a about x, the screen b about y: the screen's normal in the dome's frame is
    (sin b, cos b sin a, cos b cos a), a turn of arccos(cos a cos b) about (-cos b sin a, sin b) / its
    length (rotations written out here, not the model's)."""
    a, b = 4e-3, -7e-3
    plan, theta = _one_screen((a, 0.0), (0.0, b))
    axis = np.array([-math.cos(b) * math.sin(a), math.sin(b)])
    want = axis / np.linalg.norm(axis) * math.acos(math.cos(a) * math.cos(b))
    np.testing.assert_allclose(M.screens_in_dome_frame(table31_rig, plan, theta)[0], want, rtol=1e-9)


def test_a_screen_against_the_dome_has_the_variance_of_the_difference(table31_rig):
    """Near zero the screen against the dome is the screen's tilt less the dome's: its variance per
    axis is theirs summed, less twice their covariance (the central differences' Jacobian, first order)."""
    plan, theta = _one_screen((1e-3, -2e-3), (2e-3, 1e-3))
    names = M.parameter_names(1)
    cov = np.eye(len(names)) * 1e-12
    d, s = names.index("dome_tilt_x_rad"), names.index("screen0_tilt_x_rad")
    cov[d, d], cov[s, s], cov[d, s], cov[s, d] = 1e-8, 4e-8, 1e-8, 1e-8
    got = M.covariance_through(lambda t: M.screens_in_dome_frame(table31_rig, plan, t), theta, cov, names)
    assert got[0, 0] == pytest.approx(1e-8 + 4e-8 - 2e-8, rel=1e-3)
