"""The adjusters: range and resolution against the tolerances they serve, recomputed here from
their definitions (pitch x fraction of a turn over a lever; the law of reflection's factor 2)."""

import math

import pytest

import numpy as np

from rigcad.errors import GeometryError
from rigcad.parts.adjusters import adjusters, camera_mount_tilt, projector_screws, reflected_turn, splitter_adjusters
from rigcad.parts.tower import camera_socket_depth, camera_stack_screws, fine_shims, joint_washers, seat_points
from rigcad.profile import load_profile
from rigcad.rig import Rig


def test_every_default_adjuster_covers_its_tolerance(table31_rig):
    rows = adjusters(table31_rig.profile, table31_rig.layout)
    assert len(rows) == 12  # with the camera's tilt (the seat's flat screw), the projector's (its feet's shims) and the paraboloid's roll
    bad = [a.describe() for a in rows if not a.ok]
    assert not bad, bad


def test_splitter_tilt_is_pitch_times_turn_over_the_lever_doubled(table31_rig):
    p, t = table31_rig.profile, table31_rig.layout.tower
    pts = seat_points(t, p)
    # the flat's screw turns the holder about the cone-vee line (both at the same x): lever = x distance
    lever = pts["cone"][0] - pts["flat"][0]
    flat = splitter_adjusters(p, table31_rig.layout)[0]
    step = 0.5 * p.adjusters.turn_fraction  # M3: 0.5 mm pitch
    assert flat.resolution == pytest.approx(2 * step / lever, rel=1e-12)
    assert flat.range == pytest.approx(2 * p.adjusters.seat_travel / lever, rel=1e-12)
    # the flat stands far enough back that 1/8 turn of M3 is within a quarter of the 0.5 deg tolerance
    assert flat.resolution <= 0.25 * p.tolerancing.projector_tilt


def test_the_reflected_axis_turns_by_the_law_of_reflection():
    # the plate at 45 deg (normal (1, 0, -1)/sqrt 2), the projector's axis along -x: turned about y (in the
    # plate, across the plane of incidence) the reflection turns twice; about x, once (checked by
    # reflecting the axis in the turned plate)
    n = np.array([1.0, 0.0, -1.0]) / math.sqrt(2.0)
    d = np.array([-1.0, 0.0, 0.0])

    def turned(axis, delta):
        u = np.asarray(axis, float) / np.linalg.norm(axis)
        m = n * math.cos(delta) + np.cross(u, n) * math.sin(delta) + u * (u @ n) * (1 - math.cos(delta))
        r0, r1 = d - 2 * (d @ n) * n, d - 2 * (d @ m) * m
        return math.acos(np.clip(r0 @ r1, -1, 1)) / delta

    for axis in ((0, 1, 0), (1, 0, 0), (1, 1, 0), (0.3, -1, 0)):
        assert reflected_turn(n, axis) == pytest.approx(turned(axis, 1e-5), rel=1e-4)
    assert reflected_turn(n, (0, 1, 0)) == pytest.approx(2.0) and reflected_turn(n, (1, 0, 0)) == pytest.approx(1.0)


def test_a_coarse_seat_screw_is_refused_naming_the_thread(write_profile, table31_text):
    # a 3/8-16 screw (1.59 mm pitch) set to a quarter turn would need a ~360 mm lever for 1/4 of 0.5 deg
    rig = Rig.from_profile(load_profile(write_profile(
        table31_text + "adjusters:\n  seat_thread: 3/8-16 UNC\n  turn_fraction: 0.25\n")))
    with pytest.raises(GeometryError) as err:
        splitter_adjusters(rig.profile, rig.layout)
    assert "adjusters.seat_thread" in str(err.value) and "p.yaml" in str(err.value)


def test_camera_screws_too_close_let_it_tilt(write_profile, table31_text):
    # 0.1 mm of hand error over 5 mm: 1.1 deg, past the 0.5 deg camera tilt tolerance
    p = load_profile(write_profile(table31_text + "camera:\n  mount_spacing: 5 mm\n"))
    a = camera_mount_tilt(p)
    assert a.resolution == pytest.approx(0.1 / 5.0, rel=1e-12) and not a.ok


def test_projector_screws_suit_every_stack(table31_rig):
    p, t = table31_rig.profile, table31_rig.layout.tower
    washers = joint_washers(p, table31_rig.layout)["projector"]
    fine = sum(fine_shims(p))
    for row in projector_screws(p, table31_rig.layout):
        assert row["ok"]
        # its thread engages the projector by 5 mm to mount_depth, through the washers over the slot (an ISO
        # 7093-1 M4, 1 mm, on an M5, 1.2 mm), the shelf, the printed stack and the whole bought set (those not
        # in the stack go under the washers), and extra ISO 7089 M4 washers, 0.8 mm each
        assert p.projector.mount_thread == "M4" and washers.thickness == pytest.approx(2.2)
        reach = row["length_mm"] - (2.2 + t.shelf_thickness + row["shims"] * p.tower.shim_thickness + fine) \
            - row["extra_washers"] * 0.8
        assert reach == pytest.approx(row["engagement_mm"]) and 5.0 - 1e-9 <= reach <= p.projector.mount_depth + 1e-9


def test_camera_screws_never_bottom_out(table31_rig, write_profile, table31_text):
    p = table31_rig.profile
    for row in camera_stack_screws(p, table31_rig.layout):
        assert row["ok"] and row["engagement_mm"] <= camera_socket_depth(p) + 1e-9
        assert row["engagement_mm"] >= row["least_engagement_mm"] - 1e-9
    # an M3 camera's 2.5 mm holes (FLIR's M3x2.5): every stack still has a screw, none past 2.5 mm
    rig = Rig.from_profile(load_profile(write_profile(table31_text + "camera:\n  mount_thread: M3\n")))
    rows = camera_stack_screws(rig.profile, rig.layout)
    assert all(r["ok"] and 2.0 - 1e-9 <= r["engagement_mm"] <= 2.5 + 1e-9 for r in rows)


def test_a_shallow_projector_thread_has_no_screw(write_profile, table31_text):
    # 2 mm of thread cannot take the 5 mm engagement
    rig = Rig.from_profile(load_profile(write_profile(table31_text + "projector:\n  mount_depth: 2 mm\n")))
    assert not any(r["ok"] for r in projector_screws(rig.profile, rig.layout))
