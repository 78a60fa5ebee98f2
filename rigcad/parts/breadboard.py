"""The rig screwed down to an optical breadboard (``datum.mount``: ``breadboard_m6_25mm`` or
``breadboard_imperial_1in``), kernel-free; mm, rig frame.

The rig is one rigid piece (the base plate's datum tongue carries the COP tower, rigcad.parts.datum),
so the breadboard adds no link to the chain from the sample point O to the splitter: it fixes that
piece to the table. The rig stands with O over one of the board's tapped holes and its x axis (the
tongue, the tower over the paraboloid) along a row of holes, so every screw sits on a grid point
(i p, j p), p the board's pitch:

- two screws on a pad the tongue grows past the column's foot: the first grid column whose washers
  clear the foot, on the rows +-j p the tongue's width holds (one on the axis if none does);
- one screw through a boss under the disc on the -x axis (the disc stands on the sample holder's
  collar, ``sample_holder.stop_thickness`` above the board; the boss reaches down to it), at the
  largest grid radius that keeps its washer HAND_ROOM_MM inside the dome's flange (the screw goes in
  before the dome).

A printed hole is not where the board's is to better than the print's position error across the
screws' span (``datum.print_position`` + ``datum.print_scale`` x span) plus the board's own hole
position error (``datum.breadboard_hole_position``, assumed): each hole is the screw's clearance hole
opened by twice that sum, rounded up to 0.1 mm; a large ISO 7093 washer under each head covers it
(:func:`fit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.parts.recipe import Box, Cylinder
from rigcad.standards import INCH, INCH_SCREW_LENGTHS, LARGE_WASHERS, THREADS, screw_lengths


@dataclass(frozen=True)
class Breadboard:
    """One grid: its pitch (mm), the thread of its tapped holes, the screw's nominal diameter, its
    clearance hole (mm, normal fit), the washer under its head (outer diameter, thickness; mm), the
    stocked socket-head cap screw lengths (mm) and how each is named when ordered."""

    title: str
    pitch: float
    thread: str
    diameter: float
    clearance: float
    washer: tuple[float, float]
    lengths: tuple[tuple[float, str], ...]


def _grid(title: str, pitch: float, thread: str, lengths: tuple[tuple[float, str], ...]) -> Breadboard:
    """A grid's screws from rigcad.standards: the thread's medium (normal-fit) clearance and an ISO 7093-1
    large washer (it covers the opened hole)."""
    th = THREADS[thread]
    return Breadboard(title, pitch, thread, th.major, th.clearance, LARGE_WASHERS[thread], lengths)


BREADBOARDS = {
    "breadboard_m6_25mm": _grid("metric optical breadboard, M6 tapped holes on a 25 mm grid", 25.0, "M6",
                                tuple((float(n), f"{n} mm") for n in screw_lengths("M6") if 12 <= n <= 50)),
    "breadboard_imperial_1in": _grid("imperial optical breadboard, 1/4-20 UNC tapped holes on a 1 in grid", INCH,
                                     "1/4-20 UNC", tuple((n * INCH, label) for n, label in INCH_SCREW_LENGTHS
                                                         if 0.5 <= n <= 2.0)),
}
#: Room (mm) a hand and a hex key need between the disc screw's washer and the dome's flange.
HAND_ROOM_MM = 15.0
#: Thread a screw may engage in the board (mm): at least one diameter; at most ENGAGE_MAX_MM, what
#: every board's tapped holes give (assumed: a honeycomb board's ~5 mm steel skin has sealed cups
#: 12 mm deep or more under it; a solid 12.7 mm aluminium board is tapped through).
ENGAGE_MAX_MM = 12.0
#: The pad past the column's foot and the boss under the disc reach this far (mm) beyond the washer.
PAD_MARGIN_MM = 3.0


def board(profile) -> Breadboard | None:
    """The profile's breadboard, or None when the rig stands on its own base plate."""
    return BREADBOARDS.get(profile.datum.mount)


def anchor_points(profile, layout) -> dict[str, list[tuple[float, float]]]:
    """The screws' grid points (x, y; mm): "tongue" (on its pad past the column's foot) and "disc"
    (through the boss under the disc). Raises GeometryError when the disc has no grid radius between
    the sample holder's collar and the dome's flange."""
    b, t = board(profile), layout.tower
    p, washer_r = b.pitch, b.washer[0] / 2
    half = t.column_foot_half
    x = p * math.ceil((t.column_x + half + washer_r + 1.0) / p - 1e-9)
    rows = math.floor((half - washer_r - 1.0) / p + 1e-9)
    tongue = [(x, -rows * p), (x, rows * p)] if rows >= 1 else [(x, 0.0)]
    r = p * math.floor((layout.flange_inner_r - washer_r - HAND_ROOM_MM) / p + 1e-9)
    inner = profile.sample_holder.stop_radius + washer_r + PAD_MARGIN_MM + 1.0
    if r < inner:
        raise GeometryError(f"the disc has no {p:g} mm grid point between the sample holder's collar ({inner:.1f} mm) "
                            f"and the dome's flange ({layout.flange_inner_r:.1f} mm): choose datum.mount: base_plate",
                            where=profile.where("datum", "mount"))
    return {"tongue": tongue, "disc": [(-r, 0.0)]}


def fit(profile, layout) -> dict:
    """How the printed holes meet the board's (mm): the largest distance between two screws, the
    printed position error across it, the board's hole position error, the hole diameter that takes
    both (the clearance hole opened by twice their sum, rounded up to 0.1 mm), and where the rig then
    sits on the grid (each way: the board's error plus the screws' play in their holes)."""
    b, d = board(profile), profile.datum
    pts = [q for qs in anchor_points(profile, layout).values() for q in qs]
    span = max(math.dist(a, c) for a in pts for c in pts)
    printed = d.print_position + d.print_scale * span
    need = b.clearance + 2.0 * (printed + d.breadboard_hole_position)
    hole = math.ceil(need * 10.0 - 1e-9) / 10.0
    return {"board": b.title, "pitch_mm": b.pitch, "thread": b.thread, "span_mm": span, "printed_position_mm": printed,
            "board_hole_position_mm": d.breadboard_hole_position, "clearance_hole_mm": b.clearance,
            "hole_needed_mm": need, "hole_mm": hole, "washer_mm": b.washer[0],
            "rig_on_grid_mm": d.breadboard_hole_position + (hole - b.diameter) / 2}


def screw_length(profile, layout) -> tuple[float, str, float]:
    """The board's screw (length mm, its name, thread engaged mm): the longest stocked length that
    engages at most ENGAGE_MAX_MM through a washer and the tongue (the boss under the disc is as tall)."""
    b, t = board(profile), layout.tower
    grip = b.washer[1] - t.bench_z
    fits = [(L, name) for L, name in b.lengths if L - grip <= ENGAGE_MAX_MM + 1e-9]
    if not fits or fits[-1][0] - grip < b.diameter:
        raise GeometryError(f"no stocked {b.thread} screw engages {b.diameter:g}..{ENGAGE_MAX_MM:g} mm of the board "
                            f"through {grip:.1f} mm of washer and plate", where=profile.where("datum", "mount"))
    L, name = fits[-1]
    return L, name, L - grip


def pads(profile, layout) -> tuple:
    """What the base plate gains: the pad past the column's foot and the boss under the disc."""
    b, t = board(profile), layout.tower
    reach = b.washer[0] / 2 + PAD_MARGIN_MM
    pts = anchor_points(profile, layout)
    x_end = max(x for x, _ in pts["tongue"]) + reach
    half = t.column_foot_half
    pad = Box((t.column_x + half - 1.0, -half, t.bench_z), (x_end, half, 0.0))
    z_disc = -profile.base_plate.thickness
    return (pad, *(Cylinder((x, y, t.bench_z), reach, z_disc - t.bench_z + 1.0) for x, y in pts["disc"]))


def holes(profile, layout) -> tuple:
    """The screws' holes (:func:`fit`) through the pad and through the disc and its boss."""
    t = layout.tower
    r = fit(profile, layout)["hole_mm"] / 2
    return tuple(Cylinder((x, y, t.bench_z - 1.0), r, -t.bench_z + 2.0)
                 for qs in anchor_points(profile, layout).values() for x, y in qs)


def hardware(profile, layout) -> list[dict]:
    """The board's screws and washers, in the tower's hardware rows' form."""
    b = board(profile)
    if b is None:
        return []
    L, name, engaged = screw_length(profile, layout)
    n = sum(len(q) for q in anchor_points(profile, layout).values())
    std = "ISO 4762" if b.thread.startswith("M") else "ASME B18.3"
    return [{"item": f"{b.thread} x {name} socket-head cap screw ({std}) on a large washer (ISO 7093, {b.washer[0]:g} mm)",
             "thread": b.thread, "length_mm": L, "quantity": n,
             "joins": f"the base plate to the {b.title} ({engaged:.1f} mm of thread in the board)"}]


__all__ = ["BREADBOARDS", "Breadboard", "ENGAGE_MAX_MM", "HAND_ROOM_MM", "anchor_points", "board", "fit", "hardware",
           "holes", "pads", "screw_length"]
