"""The adjusters: range and resolution against the tolerances they serve, recomputed here from
their definitions (pitch x fraction of a turn over a lever; the law of reflection's factor 2)."""

import math

import pytest

from rigcad.parts.adjusters import adjusters, camera_mount_tilt, projector_screws, splitter_adjusters
from rigcad.parts.tower import seat_points
from rigcad.profile import load_profile
from rigcad.rig import Rig


def test_every_default_adjuster_covers_its_tolerance(table31_rig):
    rows = adjusters(table31_rig.profile, table31_rig.layout)
    assert len(rows) == 9
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
    # 1/8 turn of M3 on a ~46 mm lever: ~0.16 deg of the projector's axis, inside its 0.5 deg
    assert math.degrees(flat.resolution) < math.degrees(p.tolerancing.projector_tilt)


def test_a_coarse_seat_screw_fails_its_tolerance(write_profile, table31_text):
    # a 3/8-16 screw (1.59 mm pitch) set to a quarter turn: ~1 deg of the axis, twice the 0.5 deg allowed
    rig = Rig.from_profile(load_profile(write_profile(
        table31_text + "adjusters:\n  seat_thread: 3/8-16 UNC\n  turn_fraction: 0.25\n")))
    flat = splitter_adjusters(rig.profile, rig.layout)[0]
    assert not flat.ok and flat.resolution > rig.profile.tolerancing.projector_tilt


def test_camera_screws_too_close_let_it_tilt(write_profile, table31_text):
    # 0.1 mm of hand error over 5 mm: 1.1 deg, past the 0.5 deg camera tilt tolerance
    p = load_profile(write_profile(table31_text + "camera:\n  mount_spacing: 5 mm\n"))
    a = camera_mount_tilt(p)
    assert a.resolution == pytest.approx(0.1 / 5.0, rel=1e-12) and not a.ok


def test_projector_screws_suit_every_stack(table31_rig):
    p, t = table31_rig.profile, table31_rig.layout.tower
    for row in projector_screws(p, table31_rig.layout):
        assert row["ok"]
        # its thread engages the projector by 5 mm to mount_depth, through washer + shelf + stack + extra
        # washers, each an ISO 7089 M4 washer 0.8 mm thick (the standard's figure, not rigcad's table)
        assert p.projector.mount_thread == "M4"
        reach = row["length_mm"] - (0.8 + t.shelf_thickness + row["shims"] * p.tower.shim_thickness) \
            - row["extra_washers"] * 0.8
        assert reach == pytest.approx(row["engagement_mm"]) and 5.0 - 1e-9 <= reach <= p.projector.mount_depth + 1e-9


def test_a_shallow_projector_thread_has_no_screw(write_profile, table31_text):
    # 2 mm of thread cannot take the 5 mm engagement
    rig = Rig.from_profile(load_profile(write_profile(table31_text + "projector:\n  mount_depth: 2 mm\n")))
    assert not any(r["ok"] for r in projector_screws(rig.profile, rig.layout))
