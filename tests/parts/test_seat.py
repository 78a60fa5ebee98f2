"""The splitter's kinematic seat (rigcad.parts.tower.splitter_seat): a cone, a vee and a flat of bought
hard parts under three ball-ended push screws, preloaded by two springs. Checked from the drawn
solids, not from the seat's own figures: each screw's ball touches its seat's hard parts (the cone's
three balls, the vee's two pins, the gauge block) at the nominal setting, the holder's underside
clears every seat part over the screws' whole travel, the springs' rate follows EN 13906-1, and
every insert in the holder has its boss."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.export import mesh as M
from rigcad.parts import tower as T
from rigcad.parts.joints import KinematicSeat, SeatContact
from rigcad.standards import INSERTS


def _centres(part):
    """A drawn ball's or pin's centre from its mesh's box (mm)."""
    v, _ = M.mesh_arrays(M.build(part.solid, 0.001))
    return (v.min(axis=0) + v.max(axis=0)) / 2


def test_the_seat_is_a_cone_a_vee_and_a_flat_of_bought_hard_parts(table31_rig):
    p, L = table31_rig.profile, table31_rig.layout
    seat = T.splitter_seat(p, L)
    assert seat.constraints == 6 and sorted(c.kind for c in seat.contacts) == ["cone", "flat", "vee"]
    standards = {b.standard.split(" ")[0] for b in seat.bought}
    assert {"ISO", "EN"} <= standards  # every hard part ordered by its standard
    assert [b.quantity for b in seat.bought] == [3, 6, 2, 1, 2]  # screws, balls, pins, gauge block, springs
    parts = {q.name: q for q in T.instruments(p, L)}
    r = p.adjusters.seat_ball / 2
    ball = {c.kind: _centres(parts[f"seat_ball_{i + 1}"]) for i, c in enumerate(seat.contacts)}
    # the cone: the screw's ball touches each of the three balls in the pocket (centres one diameter apart)
    for k in range(3):
        c = _centres(parts[f"seat_cone_ball_{k + 1}"])
        assert np.linalg.norm(ball["cone"] - c) == pytest.approx(2 * r, abs=2e-3)  # the mesh's chord
    # the vee: it touches both pins (their axes (ball + pin) / 2 from its centre, in the x-z plane)
    g = T.seat_geometry(p)
    for k in range(2):
        c = _centres(parts[f"seat_vee_pin_{k + 1}"])
        assert math.hypot(*(ball["vee"] - c)[[0, 2]]) == pytest.approx((2 * r + g.pin) / 2, abs=2e-3)
    # the flat: it stands on the gauge block's top
    pad = M.mesh_arrays(M.build(parts["seat_flat_pad"].solid, 0.001))[0]
    assert ball["flat"][2] - r == pytest.approx(pad[:, 2].max(), abs=1e-9)
    # the vee's pins point at the cone: the seat grows about the cone and its ball stays put
    vee = seat.contact("vee")
    assert abs(vee.axis[0]) < 1e-12 and abs(abs(vee.axis[1]) - 1) < 1e-12


def test_the_holder_clears_the_seat_over_the_screws_travel(table31_rig):
    p, L = table31_rig.profile, table31_rig.layout
    holder = M.mesh_arrays(M.build(table31_rig.recipes["splitter_holder"].solid, 0.018))[0]
    tops = [M.mesh_arrays(M.build(q.solid, 0.018))[0][:, 2].max() for q in T.instruments(p, L)
            if q.name.startswith(("seat_cone_ball", "seat_vee_pin", "seat_flat_pad"))]
    # at its lowest setting (every screw in by its travel) the holder's underside is still above them all
    lowest = holder[:, 2].min() - p.adjusters.seat_travel
    assert lowest - max(tops) >= T.SEAT_SCREW_CLEAR, (lowest, max(tops))


def test_the_seat_screws_range_and_resolution(table31_rig):
    p, L = table31_rig.profile, table31_rig.layout
    seat = T.splitter_seat(p, L)
    # M3 x 0.5 mm, an eighth of a turn: 0.0625 mm a step, +-1.5 mm
    assert seat.resolution == pytest.approx(0.5 / 8) and seat.travel == 1.5
    flat = seat.tilt("flat")
    pts = T.seat_points(L.tower, p)
    lever = pts["cone"][0] - pts["flat"][0]  # the cone and the vee share x: the lever is along x
    assert flat["lever_mm"] == pytest.approx(lever) and flat["resolution_rad"] == pytest.approx(0.0625 / lever)


def test_the_springs_rate_and_preload(table31_rig):
    sp = T.SEAT_SPRING
    # EN 13906-1: R = G d^4 / (8 D^3 n), G = 81.5 GPa: 1.4 mm wire, 7.6 mm mean diameter, 4 coils
    rate = 81500 * 1.4 ** 4 / (8 * 7.6 ** 3 * 4)
    assert T.spring_force(1)["rate_N_per_mm"] == pytest.approx(rate)
    seat = T.splitter_seat(table31_rig.profile, table31_rig.layout)
    assert seat.preload == pytest.approx(2 * rate * (sp["free_length"] - sp["installed_length"]))
    # the bolt passes inside the spring: its inner diameter over the M4 bolt's
    assert sp["outer_diameter"] - 2 * sp["wire"] > 4.0


def test_every_insert_in_the_holder_has_its_boss(table31_rig):
    p = table31_rig.profile
    ins = INSERTS[p.adjusters.seat_thread]
    _, boss = T._seat_boss(p)
    # the M3 insert (5.7 mm, pocket 6.2) sat 0.7 mm proud of the 5 mm flange: the boss takes it and a floor
    assert p.tower.wall + boss >= ins.pocket_depth + T.SEAT_BOSS_FLOOR - 1e-9
    assert T.seat_screw_length(p) >= p.tower.wall + boss + 2 * p.adjusters.seat_travel


def test_a_seat_that_is_not_kinematic_is_refused():
    c = SeatContact("cone", 0.0, 0.0, 0.0)
    v = SeatContact("vee", 0.0, 10.0, 0.0, (0.0, -1.0))
    f = SeatContact("flat", 10.0, 5.0, 0.0)
    kw = dict(thread="M3", travel=1.0, step=0.125, springs=2, spring_rate=1.0, spring_deflection=1.0, bought=())
    KinematicSeat("s", "a", "b", (c, v, f), **kw)
    with pytest.raises(GeometryError, match="cone, a vee and a flat"):
        KinematicSeat("s", "a", "b", (c, c, f), **kw)
    with pytest.raises(GeometryError, match="point at the cone"):
        KinematicSeat("s", "a", "b", (c, SeatContact("vee", 0.0, 10.0, 0.0, (1.0, 0.0)), f), **kw)


def test_a_ball_that_falls_into_its_screws_cup_is_refused(write_profile, table31_text):
    from rigcad.profile import load_profile

    p = load_profile(write_profile(table31_text + "adjusters:\n  seat_ball: 1.5 mm\n"))
    with pytest.raises(GeometryError, match="seat_ball .* cannot sit on the M3 cup-point"):
        T.seat_geometry(p)
