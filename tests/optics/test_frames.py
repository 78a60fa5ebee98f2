"""Rigid placements (rigcad.optics.frames) against rotations written out by hand: the rotation
matrices about the coordinate axes, a pivot that stays put, and the component pivots of the thesis's
rig (COP for projector and camera, the paraboloid's vertex, the sample point O for the dome)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.optics.frames import COMPONENTS, DOFS, Misalignment, Pose


def _rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


#: round-off on rotations of unit size and translations of a few hundred mm
TOL = 1e-12


def test_default_pose_is_the_identity():
    p = Pose()
    assert np.array_equal(p.rotation, np.eye(3)) and np.array_equal(p.translation, np.zeros(3))
    assert p.rotation.shape == (3, 3) and p.translation.shape == (3,)
    assert p.is_identity
    # each default is its own array (a frozen value shares nothing)
    assert Pose().rotation is not p.rotation and Pose().translation is not p.translation


@pytest.mark.parametrize("axis, hand", [((1.0, 0.0, 0.0), _rot_x), ((0.0, 1.0, 0.0), _rot_y),
                                        ((0.0, 0.0, 1.0), _rot_z)])
@pytest.mark.parametrize("tilt", [0.3, -1.1, 2.5])
def test_tilt_about_a_coordinate_axis_is_the_right_handed_rotation(axis, hand, tilt):
    p = Pose.misaligned(tilt=tilt, tilt_axis=axis)
    assert np.max(np.abs(p.rotation - hand(tilt))) < TOL
    assert np.max(np.abs(p.translation)) < TOL  # pivot at the origin, no offset


def test_the_default_tilt_axis_is_y_and_the_axis_need_not_be_unit():
    assert np.max(np.abs(Pose.misaligned(tilt=0.7).rotation - _rot_y(0.7))) < TOL
    assert np.max(np.abs(Pose.misaligned(tilt=0.7, tilt_axis=(0.0, 0.0, 5.0)).rotation - _rot_z(0.7))) < TOL


def test_tilt_about_an_oblique_axis_keeps_the_axis_and_turns_its_normal_plane():
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    tilt = 0.4
    R = Pose.misaligned(tilt=tilt, tilt_axis=(1.0, 2.0, 2.0)).rotation
    assert np.max(np.abs(R @ axis - axis)) < TOL
    # a vector normal to the axis turns by tilt, towards axis x vector (right hand)
    v = np.array([2.0, -1.0, 0.0]) / math.sqrt(5.0)
    w = np.cross(axis, v)
    assert np.max(np.abs(R @ v - (math.cos(tilt) * v + math.sin(tilt) * w))) < TOL
    assert np.max(np.abs(R.T @ R - np.eye(3))) < TOL and abs(np.linalg.det(R) - 1.0) < TOL


def test_tilt_pivots_about_the_pivot_then_shifts_by_the_offset():
    pivot = np.array([3.0, -2.0, 150.0])
    offset = np.array([0.5, -0.25, 1.5])
    tilt = 0.2
    p = Pose.misaligned(offset, tilt, (1.0, 0.0, 0.0), pivot)
    assert np.max(np.abs(p.rotation - _rot_x(tilt))) < TOL
    # the pivot moves by the offset only; any point turns about the pivot, then shifts
    assert np.max(np.abs(p.globalize_points(pivot[None]) - (pivot + offset))) < 1e-12 * 200
    q = np.array([[10.0, 4.0, 120.0], [-7.0, 1.0, 0.0]])
    hand = (q - pivot) @ _rot_x(tilt).T + pivot + offset
    assert np.max(np.abs(p.globalize_points(q) - hand)) < 1e-12 * 200
    assert np.max(np.abs(p.translation - (pivot + offset - _rot_x(tilt) @ pivot))) < 1e-12 * 200


def test_an_offset_alone_translates():
    p = Pose.misaligned((1.0, 2.0, 3.0))
    assert np.array_equal(p.rotation, np.eye(3))
    assert np.array_equal(p.translation, [1.0, 2.0, 3.0])
    assert not p.is_identity


def test_is_identity_needs_both_rotation_and_translation():
    assert Pose(np.eye(3), np.zeros(3)).is_identity
    assert not Pose(np.eye(3), np.array([0.0, 0.0, 1e-9])).is_identity
    assert not Pose(np.eye(3), np.array([1e-9, 0.0, 0.0])).is_identity
    assert not Pose(_rot_z(1e-9), np.zeros(3)).is_identity
    assert not Pose(_rot_z(0.3), np.array([1.0, 0.0, 0.0])).is_identity
    assert isinstance(Pose().is_identity, bool) and isinstance(Pose(_rot_z(0.3)).is_identity, bool)


def test_localize_is_the_inverse_of_globalize():
    p = Pose(_rot_z(0.3) @ _rot_x(-0.2), np.array([4.0, -1.0, 7.0]))
    rng = np.random.default_rng(3)
    pts = rng.uniform(-100, 100, (20, 3))
    dirs = rng.normal(size=(20, 3))
    g_pts, g_dirs = p.globalize_points(pts), p.globalize_dirs(dirs)
    # by hand: global = R local + t for points, R local for directions
    assert np.max(np.abs(g_pts - (pts @ p.rotation.T + p.translation))) < 1e-13 * 100
    assert np.max(np.abs(g_pts[0] - (p.rotation @ pts[0] + p.translation))) < 1e-13 * 100
    assert np.max(np.abs(g_dirs - np.einsum("ij,nj->ni", p.rotation, dirs))) < 1e-13 * 10
    l_pts, l_dirs = p.localize(g_pts, g_dirs)
    assert np.max(np.abs(l_pts - pts)) < 1e-12 * 100
    assert np.max(np.abs(l_dirs - dirs)) < 1e-12 * 10
    # localize by hand: R^T (x - t)
    x = np.array([[1.0, 2.0, 3.0]])
    lx, ld = p.localize(x, x)
    assert np.max(np.abs(lx[0] - p.rotation.T @ (x[0] - p.translation))) < 1e-13 * 10
    assert np.max(np.abs(ld[0] - p.rotation.T @ x[0])) < 1e-13 * 10


def test_a_pure_translation_moves_points_not_directions():
    p = Pose(np.eye(3), np.array([1.0, -2.0, 3.0]))
    pts = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    dirs = np.array([[0.0, 0.0, -1.0], [0.6, 0.8, 0.0]])
    assert np.array_equal(p.globalize_points(pts), pts + [1.0, -2.0, 3.0])
    assert np.array_equal(p.globalize_dirs(dirs), dirs)
    lp, ld = p.localize(pts, dirs)
    assert np.array_equal(lp, pts - [1.0, -2.0, 3.0]) and np.array_equal(ld, dirs)


def test_the_identity_returns_its_inputs_untouched():
    p = Pose()
    pts, dirs = np.ones((2, 3)), np.ones((2, 3))
    lp, ld = p.localize(pts, dirs)
    assert lp is pts and ld is dirs
    assert p.globalize_points(pts) is pts and p.globalize_dirs(dirs) is dirs


def test_misalignment_none_and_with_():
    assert COMPONENTS == ("projector", "camera", "paraboloid", "dome")
    assert DOFS == ("dx", "dz", "tilt")
    none = Misalignment.none()
    m = none.with_("camera", offset=[0.1, 0.0, -0.2], tilt=1, axis=[1.0, 0.0, 0.0])
    assert m.offsets["camera"] == (0.1, 0.0, -0.2) and isinstance(m.offsets["camera"], tuple)
    assert m.tilts["camera"] == 1.0 and isinstance(m.tilts["camera"], float)
    assert m.axes["camera"] == (1.0, 0.0, 0.0) and isinstance(m.axes["camera"], tuple)
    for c in ("projector", "paraboloid", "dome"):  # the others kept
        assert (m.offsets[c], m.tilts[c], m.axes[c]) == ((0.0, 0.0, 0.0), 0.0, (0.0, 1.0, 0.0))
    # the original is not changed (a new value)
    assert none.offsets["camera"] == (0.0, 0.0, 0.0) and none.tilts["camera"] == 0.0
    assert none.axes["camera"] == (0.0, 1.0, 0.0)
    # None keeps the component's current value, field by field
    assert m.with_("camera", tilt=0.5).offsets["camera"] == (0.1, 0.0, -0.2)
    assert m.with_("camera", tilt=0.5).axes["camera"] == (1.0, 0.0, 0.0)
    assert m.with_("camera", offset=(1.0, 1.0, 1.0)).tilts["camera"] == 1.0
    assert m.with_("camera", offset=(1.0, 1.0, 1.0)).axes["camera"] == (1.0, 0.0, 0.0)
    assert m.with_("camera", axis=(0.0, 0.0, 1.0)).offsets["camera"] == (0.1, 0.0, -0.2)
    assert m.with_("camera", axis=(0.0, 0.0, 1.0)).tilts["camera"] == 1.0
    assert m.with_("camera", offset=(1.0, 1.0, 1.0)).offsets["camera"] == (1.0, 1.0, 1.0)
    assert m.with_("camera", axis=(0.0, 0.0, 1.0)).axes["camera"] == (0.0, 0.0, 1.0)


GEO = SimpleNamespace(cop_z=427.5, vertex_z=157.5)


@pytest.mark.parametrize("component, pivot_z", [("projector", 427.5), ("camera", 427.5), ("paraboloid", 157.5),
                                                ("dome", 0.0)])
def test_each_component_tilts_about_its_own_pivot(component, pivot_z):
    tilt, offset = 0.01, (0.3, -0.1, 0.2)
    pivot = np.array([0.0, 0.0, pivot_z])
    for axis, hand_rot in (((1.0, 0.0, 0.0), _rot_x), ((0.0, 1.0, 0.0), _rot_y)):
        pose = Misalignment.none().with_(component, offset, tilt, axis).pose(component, GEO)
        assert np.max(np.abs(pose.rotation - hand_rot(tilt))) < TOL
        hand = pivot + np.array(offset) - hand_rot(tilt) @ pivot
        assert np.max(np.abs(pose.translation - hand)) < 1e-12 * 500
        # and the pivot, seen from the global frame, moved by the offset alone
        assert np.max(np.abs(pose.globalize_points(pivot[None])[0] - (pivot + offset))) < 1e-12 * 500


def test_a_component_left_alone_stands_at_the_identity():
    m = Misalignment.none().with_("dome", (1.0, 0.0, 0.0), 0.2)
    for c in ("projector", "camera", "paraboloid"):
        assert m.pose(c, GEO).is_identity
    # an offset alone, or a tilt alone, moves it
    assert not Misalignment.none().with_("camera", (0.0, 0.0, 0.5)).pose("camera", GEO).is_identity
    # a tilt of exactly 1 rad with no offset is a tilt too
    one = Misalignment.none().with_("paraboloid", tilt=1.0).pose("paraboloid", GEO)
    assert np.max(np.abs(one.rotation - _rot_y(1.0))) < TOL
    tilted = Misalignment.none().with_("camera", tilt=0.001).pose("camera", GEO)
    assert np.max(np.abs(tilted.rotation - _rot_y(0.001))) < TOL
    assert np.max(np.abs(tilted.translation - (GEO.cop_z * np.array([0, 0, 1.0]) - _rot_y(0.001) @ [0, 0, GEO.cop_z])))\
        < 1e-12 * 500
