"""The splitter seat's adjustment in section 6 (rigcad.manual.calibration.splitter_seat): which way and how
far each push screw turns the projector's axis, checked against a direct construction (the holder turned
by a rotation matrix about the line through the other two balls, the projector's axis reflected off the
turned plate), and the circle's shift per step from the projector's focal length through the lens."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rigcad.manual import calibration as C
from rigcad.parts.tower import seat_points
from rigcad.standards import THREADS


def _direct(rig, screw: str) -> tuple[np.ndarray, float]:
    """The axis's lean (unit, x-y) and its turn (rad) when ``screw``'s ball rises by one step: the holder
    rotated (scipy) about the line through the other two balls by step / lever, the ray (-x) reflected."""
    p = rig.profile
    pts = {k: np.array([*v, 0.0]) for k, v in seat_points(rig.layout.tower, p).items()}
    a, b = [pts[k] for k in {"flat": ("cone", "vee"), "vee": ("cone", "flat")}[screw]]
    u = (b - a) / np.linalg.norm(b - a)
    arm = pts[screw] - a
    lever = np.linalg.norm(arm - (arm @ u) * u)
    step = THREADS[p.adjusters.seat_thread].pitch * p.adjusters.turn_fraction
    for sign in (1.0, -1.0):
        rot = Rotation.from_rotvec(sign * u * step / lever)
        if (rot.apply(arm) - arm)[2] > 0:  # the ball rises
            break
    n = np.asarray(rig.layout.tower.plate.normal, float)
    d = np.array([-1.0, 0.0, 0.0])
    before, after = (d - 2 * (d @ m) * m for m in (n, rot.apply(n)))
    lean = (after - before)[:2]
    return lean / np.linalg.norm(lean), float(np.arccos(np.clip(before @ after, -1, 1)))


def test_each_screw_leans_the_axis_as_a_direct_construction_does(table31_rig):
    seat = C.splitter_seat(table31_rig)
    for screw in ("flat", "vee"):
        lean, turn = _direct(table31_rig, screw)
        s = seat["screws"][screw]
        # first order (the code) against the exact rotation (here): a step turns by ~2 mrad, so they agree to 1e-3
        assert np.allclose(s["lean_xy"], lean, atol=1e-3), (screw, s["lean_xy"], lean)
        assert abs(s["axis_turn_per_step_mrad"] - 1e3 * turn) < 1e-3 * 1e3 * turn, (screw, s, turn)
        # the circle's shift: the projector's focal length in pixels (through the lens) times the turn
        assert abs(s["circle_shift_per_step_px"] - seat["px_per_mrad"] * 1e3 * turn) < 1e-3 * s["circle_shift_per_step_px"]
        assert np.hypot(s["rows_px_per_step"], s["columns_px_per_step"]) == pytest.approx(s["circle_shift_per_step_px"])
    # the flat tilts in the plane of incidence only (the image's rows), towards -x when screwed in
    assert seat["screws"]["flat"]["leans"] == "-x" and seat["screws"]["flat"]["columns_px_per_step"] < 1e-9
    # a step is finer than a quarter of the tolerance on both screws: what the adjuster is sized for
    for s in seat["screws"].values():
        assert s["circle_shift_per_step_px"] <= 0.25 * seat["tolerance_px"] + 1e-9, s


def test_a_wrong_lean_is_caught(table31_rig):
    """Planted: the plate's normal mirrored in x (the coated face the wrong way round) leans the axis the
    other way; the direct construction, on the true normal, disagrees."""
    import dataclasses
    from types import SimpleNamespace

    true, _ = _direct(table31_rig, "flat")
    t = table31_rig.layout.tower
    n = t.plate.normal
    flipped = dataclasses.replace(t, plate=dataclasses.replace(t.plate, normal=(-n[0], n[1], n[2])))
    rig = SimpleNamespace(layout=SimpleNamespace(tower=flipped), profile=table31_rig.profile)
    assert np.allclose(C.seat_lean(table31_rig, "flat"), true, atol=1e-3)
    assert not np.allclose(C.seat_lean(rig, "flat"), true, atol=1e-3)
