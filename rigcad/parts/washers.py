"""Washers over slots and opened holes: which washer a bolt needs so that it bears on printed plastic
at least as well as a plain washer on its clearance hole, and the bearing area it really has
(kernel-free; mm, mm2).

A washer bears on the annulus between its bore and its outside diameter, less whatever opening the
bolt passes through: a clearance hole, a hole opened past it, or an adjuster's slot (a rectangle the
bolt moves in). The bolt is taken at the slot's middle, where the opening covers most of the
washer. When the plain washer (ISO 7089; ASME B18.22.1 for an inch thread) bears less than it would
on its own clearance hole, a large washer (ISO 7093-1) of the bolt's size is tried, then larger
ISO 7093-1 sizes, each under a large washer of the bolt's own size (the head bears on that one, the
big one on the plastic; a washer between when the big one's bore is too wide for the small one to
cover by a millimetre a side): the first that bears as much is chosen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.standards import ISO_7089_BORE, ISO_7093, THREADS

#: The large washer a thread takes (its own size, or the one whose bore passes it).
OWN_SIZE = {"1/4-20 UNC": "M6", "3/8-16 UNC": "M10"}


@dataclass(frozen=True)
class Washer:
    """One washer: its standard and size, bore, outside diameter and thickness (mm)."""

    standard: str
    size: str
    bore: float
    outer: float
    thickness: float

    def name(self) -> str:
        return f"{self.size} washer ({self.standard}, {self.outer:g} mm outside, {self.thickness:g} mm)"


@dataclass(frozen=True)
class WasherStack:
    """The washers under one bolt's head, head side first: the last bears on the plastic over
    ``opening`` (("round", diameter) or ("slot", width_x, width_y), mm); ``area_mm2``: its bearing
    area there; ``target_mm2``: a plain washer's on the bolt's clearance hole."""

    washers: tuple[Washer, ...]
    opening: tuple
    area_mm2: float
    target_mm2: float

    @property
    def thickness(self) -> float:
        return sum(w.thickness for w in self.washers)

    @property
    def bearing(self) -> Washer:
        return self.washers[-1]

    def describe(self) -> str:
        kind = "hole" if self.opening[0] == "round" else "slot"
        size = (f"{self.opening[1]:.2f} mm" if kind == "hole" else f"{self.opening[1]:.1f} x {self.opening[2]:.1f} mm")
        return (" on ".join(w.name() for w in self.washers) + f": bears {self.area_mm2:.0f} mm2 over the {size} {kind}")


def plain(thread: str) -> Washer:
    """The plain washer of ``thread`` (rigcad.standards: ISO 7089, or ASME B18.22.1 for UNC)."""
    th = THREADS[thread]
    std = "ISO 7089" if thread.startswith("M") else "ASME B18.22.1"
    return Washer(std, thread, th.clearance if not thread.startswith("M") else _iso7089_bore(thread), th.washer_od,
                  th.washer_thickness)


def _iso7089_bore(thread: str) -> float:
    """ISO 7089's bore: the fine clearance hole (rigcad.standards.ISO_7089_BORE)."""
    return ISO_7089_BORE.get(thread, THREADS[thread].clearance)


def large(size: str) -> Washer:
    d1, d2, h = ISO_7093[size]
    return Washer("ISO 7093-1", size, d1, d2, h)


def _disc_in_rect(r: float, a: float, b: float) -> float:
    """Area (mm2) of a disc of radius ``r`` inside the centred rectangle |x| <= a, |y| <= b."""
    if r <= 0 or a <= 0 or b <= 0:
        return 0.0
    x1 = min(a, r)
    x0 = math.sqrt(r * r - b * b) if r > b else 0.0
    x0 = min(x0, x1)

    def prim(x: float) -> float:  # the integral of sqrt(r^2 - x^2)
        return 0.5 * (x * math.sqrt(max(r * r - x * x, 0.0)) + r * r * math.asin(min(x / r, 1.0)))

    return 4.0 * (b * x0 + prim(x1) - prim(x0))


def bearing_area(washer: Washer, opening: tuple) -> float:
    """The bearing area (mm2) of ``washer`` centred on ``opening``: its annulus less the opening."""
    ring = math.pi / 4 * (washer.outer ** 2 - washer.bore ** 2)
    if opening[0] == "round":
        d = max(opening[1], washer.bore)
        return max(0.0, math.pi / 4 * (washer.outer ** 2 - d ** 2))
    a, b = opening[1] / 2, opening[2] / 2
    covered = _disc_in_rect(washer.outer / 2, a, b) - _disc_in_rect(washer.bore / 2, a, b)
    return max(0.0, ring - covered)


def washers_over(thread: str, opening: tuple) -> WasherStack:
    """The washers a ``thread`` bolt needs over ``opening`` (see the module docstring); GeometryError
    when no ISO 7093-1 size bears as much as a plain washer on its clearance hole."""
    target = bearing_area(plain(thread), ("round", THREADS[thread].clearance))
    own = large(OWN_SIZE.get(thread, thread)) if OWN_SIZE.get(thread, thread) in ISO_7093 else None
    candidates = [(plain(thread),)] + ([(own,)] if own else [])
    if own is not None:
        sizes = [large(k) for k in ISO_7093]
        for big in (w for w in sizes if w.outer > own.outer):
            chain = [own]
            while chain[-1] is not big:
                # the largest size up to the big one whose bore the washer above still covers by 1 mm a side
                nxt = [w for w in sizes if chain[-1].outer < w.outer <= big.outer and w.bore + 2.0 < chain[-1].outer]
                if not nxt:
                    break
                chain.append(max(nxt, key=lambda w: w.outer))
            if chain[-1] is big:
                candidates.append(tuple(chain))
    for stack in candidates:
        area = bearing_area(stack[-1], opening)
        if area >= target - 1e-9:
            return WasherStack(stack, opening, area, target)
    raise GeometryError(f"no ISO 7093-1 washer under a {thread} bolt bears {target:.0f} mm2 over a {opening} mm "
                        "opening: make the slot narrower (tower.travel_across)", param="tower.travel_across")


def seat_edge(washer: Washer, major: float, limiter) -> float:
    """How far (mm) from a compression limiter's axis the washer's bore edge can stand, the washer slid
    on the bolt (``major`` mm) as far as its bore lets it one way and the sleeve (rigcad.standards.Limiter)
    the other way: the sleeve's end is seated out from there to its outside."""
    return washer.bore / 2 + (washer.bore - major) / 2 + (limiter.bore - major) / 2


def on_limiter(thread: str, hole: float, limiter, param: str = "") -> WasherStack:
    """The washer under a ``thread`` bolt's head that runs through a compression limiter (``limiter``:
    rigcad.standards.Limiter) in a ``hole`` mm across. The preload runs head, washer, sleeve, insert, so
    the washer must seat on the sleeve's end all round wherever the bolt's clearance lets it slide: its
    bore edge (:func:`seat_edge`) no farther out than the middle of the sleeve's wall. A larger washer,
    which would bear more on the plastic, has a wider bore and floats off the sleeve on one side (an ISO
    7093-1 M5 washer on an M4 bolt: its bore edge 3.5 mm out, past the 6 mm sleeve's 3 mm), and the plastic
    needs no more: under the washer it carries only the squeeze the sleeve leaves (rigcad.parts.joints
    .LIMITER_SQUEEZE_MM), which clamps it. So: the thread's own large washer (ISO 7093-1), else its plain
    one, whichever seats; it must overlap the plastic round the hole. ``target_mm2`` is a plain washer's
    bearing on its clearance hole, for comparison only. GeometryError (naming ``param``, the key that sizes
    the hole) when none seats or overlaps."""
    own = OWN_SIZE.get(thread, thread)
    major = THREADS[thread].major
    for w in ([large(own)] if own in ISO_7093 else []) + [plain(thread)]:
        if seat_edge(w, major, limiter) <= (limiter.outer - limiter.wall) / 2 + 1e-9 and w.outer > hole:
            target = bearing_area(plain(thread), ("round", THREADS[thread].clearance))
            return WasherStack((w,), ("round", hole), bearing_area(w, ("round", hole)), target)
    raise GeometryError(f"no washer under a {thread} bolt both seats on its {limiter.name()} and covers a "
                        f"{hole:.2f} mm hole: a smaller hole or a larger limiter", param=param or None)


__all__ = ["ISO_7093", "Washer", "WasherStack", "bearing_area", "large", "on_limiter", "plain", "seat_edge",
           "washers_over"]
