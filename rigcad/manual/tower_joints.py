"""The COP tower's own joints as fasteners for the assembly check (rigcad.manual.assembly_check),
placed where the tower's parts put their holes (rigcad.parts.tower: ``_column_flange_points``,
``column_dowel_points``, ``seat_points``, ``_holder_flange_points``) and sized by its hardware rows
(``rigcad.parts.tower.hardware``), so the check verifies each head's way in, its tool's straight
path and the nut's room (and the spanner's way out where a hand holds the nut):

- the printed column's foot: four bolts down through the foot and the base plate's datum tongue,
  their nuts in the hexagonal traps under the tongue (put in before the plate stands on the bench:
  the trap holds the nut, no spanner);
- the shelf on the column's top flange: four bolts up from under the flange into inserts in the
  shelf's underside (nothing stands proud of the shelf's top, where the projector stands);
- the splitter holder on its seat: two spring bolts up from under the shelf through the holder's
  flanges, nut on the spring on top; three set screws in the holder's inserts, turned from above
  down onto their balls (drawn at the setting where they touch the balls).

A bought extrusion column: one M8 bolt into its tapped core at each end, the foot's up from the
counterbore under the tongue (``rigcad.parts.tower.CORE_HEAD_BORE``; put in with the rig lifted onto
the film test's blocks, ``rigcad.manual.calibration.film_setup``: the tongue stands on the bench), the
top's down through the shelf. The extrusion is drawn as a plain box: the bolts' threads run into it.
Frame: mm, rig frame.
"""

from __future__ import annotations

import numpy as np

from rigcad.manual.assembly_check import Fastener
from rigcad.manual.fasteners import DOWN, UP, driver, spanner
from rigcad.manual.fasteners import socket_head as _socket_head
from rigcad.standards import THREADS

#: The hardware rows' "joins" text (its start) that this module places as fasteners.
PLACED = ("the column's top flange to the shelf", "the column's foot to the base plate's datum tongue",
          "the splitter holder's seat", "from under the shelf up through the holder's flange")
#: The same for a bought extrusion column (its core bolts).
PLACED_BOUGHT = ("up through the base plate's tongue", "down through the shelf (its head flush in the countersink")


def placed(row: dict) -> bool:
    """Whether the tower's hardware ``row`` is placed here (the steps then carry it)."""
    return any(row["joins"].startswith(p) for p in PLACED + PLACED_BOUGHT)


def _row(rig, start: str) -> dict:
    from rigcad.parts.tower import hardware

    return next(h for h in hardware(rig.profile, rig.layout) if h["joins"].startswith(start))


def _nut_bolt(item: str, head, axis, length: float, thread: str, grip: float, passes, out_dir=None) -> Fastener:
    """A through bolt with a washer under its head and a nut at ``grip`` (mm) from the head's face;
    ``out_dir``: the spanner's way out, or None for a nut held in a trap."""
    nut_h = THREADS[thread].nut_height
    return _socket_head(item, head, axis, length, thread, thread_in="nut",
                        nut_size_mm=(THREADS[thread].nut_corner_radius, nut_h),
                        nut_tool=None if out_dir is None else spanner(thread, nut_h), nut_dir=out_dir,
                        passes=passes, grip_mm=grip)


def column_fasteners(rig) -> dict[str, tuple[Fastener, ...]]:
    """The printed column's joints: foot to the tongue (step tower_column), shelf to the top flange
    (step tower_shelf)."""
    from rigcad.parts.tower import _column_flange_points, nut_trap_depth

    t, tw = rig.layout.tower, rig.profile.tower
    if rig.profile.buy.column != "print":
        return extrusion_fasteners(rig)
    foot, top = _row(rig, PLACED[1]), _row(rig, PLACED[0])
    washer = foot.get("washer_mm", THREADS[foot["thread"]].washer_thickness)
    pts = _column_flange_points(t, rig.profile)
    z_foot = t.column_base_z + tw.wall + washer
    grip_foot = washer + tw.wall + (t.column_base_z - t.bench_z) - nut_trap_depth(rig.profile, t)
    item = ("{} x {:g} mm socket-head bolt (ISO 4762) with a conical spring washer (DIN 6796), a large washer "
            "(ISO 7093-1) and a nut (ISO 4032){}")
    feet = tuple(_nut_bolt(item.format(foot["thread"], foot["length_mm"], " in the trap under the tongue"),
                           (x, y, z_foot), DOWN, foot["length_mm"], foot["thread"], grip_foot,
                           ("base_plate", "tower_column")) for x, y in pts)
    z_top = t.shelf_top_z - t.shelf_thickness - tw.wall - top.get("washer_mm", washer)  # under the column's top flange
    into = "heat-set insert in" if rig.profile.buy.shelf == "print" else "thread tapped in"
    shelf = tuple(_socket_head(f"{top['thread']} x {top['length_mm']:g} mm socket-head bolt (ISO 4762) with a large washer, "
                               f"up into the {into} the shelf", (x, y, z_top), UP, top["length_mm"],
                               top["thread"], thread_in="insert",
                               passes=("tower_column", "tower_shelf")) for x, y in pts)
    return {"tower_column": feet, "tower_shelf": shelf}


def extrusion_fasteners(rig) -> dict[str, tuple[Fastener, ...]]:
    """The bought extrusion's two M8 core screws, no washers: the foot's ISO 4762 head sunk in the
    counterbore under the tongue (step tower_column, put in from below with the rig on the film
    test's blocks), the top's ISO 10642 countersunk head flush in the shelf's top (step tower_shelf)."""
    from rigcad.manual.calibration import film_setup
    from rigcad.parts.tower import CORE_HEAD_BORE, CORE_TOP_SCREW

    t = rig.layout.tower
    foot, top = _row(rig, PLACED_BOUGHT[0]), _row(rig, PLACED_BOUGHT[1])
    core = "into the extrusion's tapped core"
    head_d, head_h, key = CORE_TOP_SCREW
    bolt = _socket_head(f"{foot['thread']} x {foot['length_mm']:g} mm socket-head bolt (ISO 4762) {core}, up from the "
                        "counterbore under the tongue (the rig on blocks)", (t.column_x, 0.0, t.bench_z + CORE_HEAD_BORE[1]),
                        UP, foot["length_mm"], foot["thread"], thread_in="tapped",
                        passes=("base_plate", "tower_column"), pierces=("tower_column",),
                        lift_mm=film_setup(rig)["block_under_tongue_mm"])
    screw = Fastener(f"{top['thread']} x {top['length_mm']:g} mm countersunk socket screw (ISO 10642) {core}, down "
                     "from the shelf's countersink", (t.column_x, 0.0, t.shelf_top_z - head_h), DOWN,
                     top["length_mm"] - head_h, 4.0, head_d / 2, head_h, driver(top["thread"], (1.0, 0.0, 0.0), key),
                     thread_in="tapped", passes=("tower_shelf", "tower_column"), pierces=("tower_column",),
                     countersunk=True)
    return {"tower_column": (bolt,), "tower_shelf": (screw,)}


def _outward(dx: float, dy: float) -> tuple[float, float, float]:
    v = np.array([dx, dy, 0.0])
    return tuple(float(c) for c in v / np.linalg.norm(v))


def seat_fasteners(rig, meshes_by_name: dict) -> dict[str, tuple[Fastener, ...]]:
    """The splitter holder's spring bolts and set screws (step splitter_holder)."""
    from rigcad.parts.tower import _holder_flange_points, seat_gap, seat_points

    t, tw, a = rig.layout.tower, rig.profile.tower, rig.profile.adjusters
    spring, screw = _row(rig, PLACED[3]), _row(rig, PLACED[2])
    washer = THREADS[spring["thread"]].washer_thickness
    z_head = t.shelf_top_z - t.shelf_thickness - washer
    grip = 2 * washer + t.shelf_thickness + seat_gap(rig.profile) + tw.wall + spring["spring_mm"]["free_length"]
    sp = spring["spring_mm"]
    item = (f"{spring['thread']} x {spring['length_mm']:g} mm socket-head bolt (ISO 4762), 2 washers, nut and a "
            f"compression spring ({sp['wire']:g} mm wire, {sp['outer_diameter']:g} mm outside, {sp['free_length']:g} mm "
            "free, steel, EN 13906-1)")
    out = [_nut_bolt(item, (x, y, z_head), UP, spring["length_mm"], spring["thread"], grip,
                     ("tower_shelf", "splitter_holder"), (0.0, float(np.sign(y)), 0.0))
           for x, y in _holder_flange_points(t, rig.profile)]
    d = THREADS[screw["thread"]].major
    balls = sorted(n for n in meshes_by_name if n.startswith("seat_ball_"))
    for (x, y), ball in zip(seat_points(t, rig.profile).values(), balls):
        tip = float(meshes_by_name[ball].hi[2])  # the screw turned down onto its ball
        head = (x, y, tip + screw["length_mm"])
        out.append(Fastener(f"{screw['thread']} x {screw['length_mm']:g} mm {screw['item']}, in a heat-set insert",
                            head, DOWN, float(screw["length_mm"]), d / 2, d / 2, 0.5,
                            driver(screw["thread"], _outward(x, y) if abs(x) + abs(y) > 1e-9 else (1.0, 0.0, 0.0)),
                            thread_in="insert", passes=("splitter_holder", ball), washers=0))
    return {"splitter_holder": tuple(out)}


def breadboard_fasteners(rig) -> dict[str, tuple[Fastener, ...]]:
    """On a breadboard (``datum.mount``): the base plate's screws down into the board's tapped holes,
    on the grid (rigcad.parts.breadboard), a large washer under each head (step base_plate)."""
    from rigcad.parts import breadboard

    b = breadboard.board(rig.profile)
    if b is None:
        return {}
    row = breadboard.hardware(rig.profile, rig.layout)[0]
    pts = [q for qs in breadboard.anchor_points(rig.profile, rig.layout).values() for q in qs]
    return {"base_plate": tuple(_socket_head(row["item"] + " into the breadboard", (x, y, b.washer[1]), DOWN,
                                             row["length_mm"], b.thread, thread_in="bench",
                                             passes=("base_plate",)) for x, y in pts)}


def tower_fasteners(rig, meshes_by_name: dict) -> dict[str, tuple[Fastener, ...]]:
    """Step name -> the tower's own joints' fasteners (see the module docstring) and the base plate's
    screws into a breadboard."""
    if getattr(rig.layout, "tower", None) is None or "tower_column" not in meshes_by_name:
        return {}
    out = dict(column_fasteners(rig)) | breadboard_fasteners(rig)
    if "splitter_holder" in meshes_by_name and "tower_shelf" in meshes_by_name:
        out.update(seat_fasteners(rig, meshes_by_name))
    return out


__all__ = ["PLACED", "PLACED_BOUGHT", "breadboard_fasteners", "column_fasteners", "extrusion_fasteners", "placed", "seat_fasteners", "tower_fasteners"]
