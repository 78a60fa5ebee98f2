"""Joints declared as data beside the parts' geometry: two parts held by screws.

A :class:`ScrewJoint` states which part the screws' heads bear on (``upper``) and which takes their
thread (``lower``), the thread by name (its figures: rigcad.standards), where the screws stand, the
faces they run between and what takes the thread: a heat-set insert in the lower part (its pocket at
the maker's hole and depth) or a nut under it. The parts cut their holes from the joint
(:meth:`ScrewJoint.clearance_holes`, :meth:`ScrewJoint.thread_holes`), the assembly plan fits its
screws from it and the bill counts them from the plan, so the solid, the bill and the steps cannot
disagree. Frame: mm, rig frame (screw axes vertical, heads on top).
"""

from __future__ import annotations

from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.parts.recipe import Cylinder
from rigcad.standards import INSERTS, THREADS, longest_screw, shortest_screw

#: What may take a joint's thread.
INTO = ("insert", "nut")


@dataclass(frozen=True)
class ScrewJoint:
    """Screws down through ``upper`` (its clamped span ``upper_z``: bottom, top; mm) into ``lower``
    (its span ``lower_z``), one at each ``points`` (x, y; mm), of ``thread``, the thread taken by
    ``into``: "insert" (a heat-set insert pressed into ``lower`` from its top face) or "nut" (a nut
    under ``lower``). ``param``: the profile key that sizes the joint's holes, for errors."""

    name: str
    upper: str
    lower: str
    thread: str
    points: tuple[tuple[float, float], ...]
    upper_z: tuple[float, float]
    lower_z: tuple[float, float]
    into: str = "insert"
    param: str = ""

    def __post_init__(self) -> None:
        if self.thread not in THREADS:
            raise GeometryError(f"joint {self.name}: unknown thread {self.thread!r}", param=self.param or None)
        if self.into not in INTO:
            raise GeometryError(f"joint {self.name}: a thread goes into one of {INTO}, not {self.into!r}")
        if self.into == "insert":
            if self.thread not in INSERTS:
                raise GeometryError(f"joint {self.name}: no heat-set insert for {self.thread} (they are made for "
                                    f"{', '.join(INSERTS)})", param=self.param or None)
            depth = self.lower_z[1] - self.lower_z[0]
            if INSERTS[self.thread].pocket_depth > depth + 1e-9:
                raise GeometryError(f"joint {self.name}: the {self.thread} insert's pocket "
                                    f"({INSERTS[self.thread].pocket_depth:g} mm) is deeper than {self.lower} "
                                    f"({depth:g} mm)", param=self.param or None)

    @property
    def count(self) -> int:
        return len(self.points)

    @property
    def washer(self) -> float:
        """The washer under each head (mm, ISO 7089)."""
        return THREADS[self.thread].washer_thickness

    @property
    def head_z(self) -> float:
        """The heads' bearing face (mm): on the washer on the upper part's top face."""
        return self.upper_z[1] + self.washer

    @property
    def length(self) -> int:
        """The screws' length (mm, ISO 4762 as sold): into an insert, the longest that ends inside it;
        through a nut, the shortest that shows two pitches past it (washers under head and nut)."""
        th = THREADS[self.thread]
        if self.into == "insert":
            reach = self.washer + (self.upper_z[1] - self.upper_z[0]) + INSERTS[self.thread].length
            found = longest_screw(self.thread, reach)
        else:
            grip = (self.upper_z[1] - self.upper_z[0]) + (self.lower_z[1] - self.lower_z[0])
            found = shortest_screw(self.thread, grip + 2 * th.washer_thickness + th.nut_height + 2 * th.pitch)
        if found is None:
            raise GeometryError(f"joint {self.name}: no ISO 4762 {self.thread} screw suits it "
                                f"(lengths {', '.join(map(str, self.lengths_sold))} mm)", param=self.param or None)
        return found

    @property
    def lengths_sold(self) -> tuple[int, ...]:
        from rigcad.standards import screw_lengths

        return screw_lengths(self.thread)

    @property
    def item(self) -> str:
        """The screw as it is ordered, with what takes its thread."""
        if self.into == "insert":
            ins = INSERTS[self.thread]
            return (f"{self.thread} x {self.length} mm socket-head bolt (ISO 4762) with a washer (ISO 7089) into a "
                    f"{self.thread} heat-set insert ({ins.length:g} mm long, in a {ins.hole:g} mm hole) melted into "
                    f"{self.lower}")
        return (f"{self.thread} x {self.length} mm socket-head bolt (ISO 4762) with 2 washers (ISO 7089) and a nut "
                "(ISO 4032)")

    def clearance_holes(self, diameter: float | None = None) -> tuple[Cylinder, ...]:
        """The holes through the upper part (the thread's medium clearance, ISO 273, unless
        ``diameter`` mm), 1 mm past each face."""
        d = THREADS[self.thread].clearance if diameter is None else diameter
        z0, z1 = self.upper_z
        return tuple(Cylinder((x, y, z0 - 1.0), d / 2, z1 - z0 + 2.0) for x, y in self.points)

    def thread_holes(self) -> tuple[Cylinder, ...]:
        """What the lower part is cut with: an insert's pocket from its top face down (the maker's
        hole, the insert's length and 0.5 mm), or the clearance hole through it for a nut."""
        z0, z1 = self.lower_z
        if self.into == "insert":
            ins = INSERTS[self.thread]
            return tuple(Cylinder((x, y, z1 - ins.pocket_depth), ins.hole / 2, ins.pocket_depth + 1.0)
                         for x, y in self.points)
        d = THREADS[self.thread].clearance
        return tuple(Cylinder((x, y, z0 - 1.0), d / 2, z1 - z0 + 2.0) for x, y in self.points)


__all__ = ["INTO", "ScrewJoint"]
