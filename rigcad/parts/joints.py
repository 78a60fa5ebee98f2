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
import math

from rigcad.parts.recipe import Cylinder, Solid, bounds
from rigcad.standards import (COMPRESSION_LIMITERS, CONICAL_SPRING_WASHERS, INSERTS, THREADS, Limiter, longest_screw,
                               shortest_screw)

#: What may take a joint's thread.
INTO = ("insert", "nut")

#: Which joints take compression limiters, the rule: every bolted joint on a datum chain (``datum``: it
#: locates a part that places an optical element, as the dome's flange on the base plate and the COP
#: tower's column on its tongue and under its shelf do). A preload worth having puts PLA's creep limit
#: under the washer (rigcad.fab.loads: half its yield, 13 MPa), so the clamped plastic creeps and the
#: joint relaxes; a conical spring washer follows only a few hundredths of a millimetre of that. A
#: steel sleeve through the clamped part (rigcad.standards.COMPRESSION_LIMITERS) carries the preload
#: instead, head to insert (or to the nut), and the plastic keeps only the squeeze below.
#:
#: The sleeve is faced this much (mm) under the clamped part's thickness measured at its hole, so that
#: the washer seats on the plastic and then on the sleeve (the compression limiter makers' rule: the
#: limiter equal to or slightly under its host). The squeeze strains the plastic by LIMITER_SQUEEZE_MM
#: over the part's span: PLA at its creep limit (13 MPa) and its stiffest modulus (3.04 GPa, Stratasys' XZ
#: figure) strains 0.43 %, 0.026 mm over the 6 mm dome flange, 0.021 mm over a 5 mm column wall; 0.02 mm keeps
#: a part of 5 mm or more under it (tests/parts/test_joints_limiters.py checks it against rigcad.fab.loads).
LIMITER_SQUEEZE_MM = 0.02


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
    #: The washer under each head as ordered (rigcad.parts.washers: large ones over an opened hole); a
    #: plain ISO 7089 washer when empty.
    washer_spec: str = ""
    #: That washer stack's thickness (mm); None: the plain ISO 7089 washer's.
    washer_mm: float | None = None
    #: A DIN 6796 conical spring washer under each head (creep would relax the joint: rigcad.fab.loads
    #: marks it): its free height counts in the grip (standards.CONICAL_SPRING_WASHERS).
    spring_washer: bool = False
    #: The joint is on a datum chain (see :data:`LIMITER_SQUEEZE_MM`): it must have a compression limiter.
    datum: bool = False
    #: A compression limiter (standards.COMPRESSION_LIMITERS) through ``upper`` at each screw: the preload
    #: runs head, washers, sleeve, insert (or nut), not through the plastic.
    limiter: bool = False

    def __post_init__(self) -> None:
        if self.thread not in THREADS:
            raise GeometryError(f"joint {self.name}: unknown thread {self.thread!r}", param=self.param or None)
        if self.datum and not self.limiter:
            raise GeometryError(f"joint {self.name}: it locates a datum, so its bolts need compression limiters "
                                f"(limiter=True: a steel sleeve through {self.upper} at each bolt); without them the "
                                "plastic under the washers creeps and the joint relaxes", param=self.param or None)
        if self.limiter:
            self._check_limiter()
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

    def _check_limiter(self) -> None:
        if self.thread not in COMPRESSION_LIMITERS:
            raise GeometryError(f"joint {self.name}: no compression limiter for {self.thread} (rigcad.standards."
                                f"COMPRESSION_LIMITERS has {', '.join(COMPRESSION_LIMITERS)})", param=self.param or None)
        lim = COMPRESSION_LIMITERS[self.thread]
        if lim.bore < THREADS[self.thread].clearance_fine - 1e-9:
            raise GeometryError(f"joint {self.name}: the {lim.name()} does not pass the {self.thread} bolt "
                                f"(bore under ISO 273 fine, {THREADS[self.thread].clearance_fine:g} mm)")
        if self.into == "insert" and lim.bore >= INSERTS[self.thread].outer:
            raise GeometryError(f"joint {self.name}: the {lim.name()} would bear on plastic around its insert "
                                f"({INSERTS[self.thread].outer:g} mm outside), not on the insert")
        if self.limiter_length <= 0:
            raise GeometryError(f"joint {self.name}: {self.upper} is too thin for a compression limiter "
                                f"({self.upper_z[1] - self.upper_z[0]:g} mm)", param=self.param or None)

    @property
    def count(self) -> int:
        return len(self.points)

    @property
    def limiter_part(self) -> Limiter | None:
        """The compression limiter at each screw (rigcad.standards), or None."""
        return COMPRESSION_LIMITERS[self.thread] if self.limiter else None

    @property
    def limiter_length(self) -> float:
        """The sleeve's finished length (mm): the upper part's span less :data:`LIMITER_SQUEEZE_MM` (as
        drawn; the shop faces it to the part's thickness measured at the hole less the squeeze)."""
        return (self.upper_z[1] - self.upper_z[0]) - LIMITER_SQUEEZE_MM

    def limiter_step(self) -> str:
        """The shop step that fits the limiters ("" without them)."""
        lim = self.limiter_part
        if lim is None:
            return ""
        upper, lower = self.upper.replace("_", " "), self.lower.replace("_", " ")
        seat = (f"the {self.thread} inserts pressed flush with the {lower}'s face (the sleeve's end bears on the "
                "insert's top)" if self.into == "insert" else "the sleeve's lower end on the part under it")
        return (f"Cut {self.count} sleeves from {lim.outer:g} x {lim.wall:g} mm steel tube ({lim.source}) and face "
                f"each on the lathe to the {upper}'s thickness measured with a micrometer at its hole less "
                f"{LIMITER_SQUEEZE_MM:g} mm ({self.limiter_length:.2f} mm as drawn), square and deburred; drop one "
                f"into each of the {upper}'s bolt holes, {seat}, and put each bolt through its sleeve; tightened to "
                "the torque table's figure, the washer seats on the plastic and then on the sleeve")

    @property
    def washer(self) -> float:
        """What stands under each head (mm): its washer stack (ISO 7089 unless ``washer_mm``) and the
        conical spring washer at its free height (DIN 6796 h, the most it can stand: the screw must
        still engage with it uncompressed)."""
        plain = THREADS[self.thread].washer_thickness if self.washer_mm is None else self.washer_mm
        return plain + (CONICAL_SPRING_WASHERS[self.thread][3] if self.spring_washer else 0.0)

    @property
    def head_z(self) -> float:
        """The heads' bearing face (mm): on the washer on the upper part's top face."""
        return self.upper_z[1] + self.washer

    @property
    def grip(self) -> float:
        """Head's bearing face to the lower part's top face (mm): the washers under the head (:attr:`washer`)
        and the upper part's clamped span, or the compression limiter's length through it (the plastic
        is squeezed to it)."""
        return self.washer + (self.limiter_length if self.limiter else self.upper_z[1] - self.upper_z[0])

    @property
    def engagement(self) -> float:
        """How far (mm) the screw runs into the insert (past the lower part's top face, where the insert's
        top sits); through a nut, what stands out past the nut."""
        if self.into == "insert":
            return self.length - self.grip
        th = THREADS[self.thread]
        return self.length - (self.grip + (self.lower_z[1] - self.lower_z[0]) + th.washer_thickness + th.nut_height)

    @property
    def length(self) -> int:
        """The screws' length (mm, ISO 4762 as sold): into an insert, the longest that ends inside it
        and engages it by at least one thread diameter; through a nut, the shortest that shows two
        pitches past it (the washers under the head as :attr:`washer`, a plain one under the nut)."""
        th = THREADS[self.thread]
        if self.into == "insert":
            found = longest_screw(self.thread, self.grip + INSERTS[self.thread].length)
            if found is not None and found - self.grip < th.major - 1e-9:
                raise GeometryError(f"joint {self.name}: the longest {self.thread} screw that ends inside its insert "
                                    f"({found} mm) engages it {found - self.grip:.1f} mm, under one diameter "
                                    f"({th.major:g} mm): {INSERTS[self.thread].length:g} mm insert under "
                                    f"{self.grip:.1f} mm of washers and {self.upper}", param=self.param or None)
        else:
            grip = self.grip + (self.lower_z[1] - self.lower_z[0])
            found = shortest_screw(self.thread, grip + th.washer_thickness + th.nut_height + 2 * th.pitch)
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
            spring = "a conical spring washer (DIN 6796) on " if self.spring_washer else ""
            sleeve = (f" through a steel compression limiter ({self.limiter_part.outer:g} x {self.limiter_part.wall:g} mm "
                      f"sleeve, {self.limiter_length:.2f} mm long)" if self.limiter else "")
            return (f"{self.thread} x {self.length} mm socket-head bolt (ISO 4762) with {spring}"
                    f"{self.washer_spec or 'a washer (ISO 7089)'}{sleeve} into a "
                    f"{self.thread} heat-set insert ({ins.length:g} mm long, in a {ins.hole:g} mm hole) melted into "
                    f"{self.lower}")
        sleeve = (f" through a steel compression limiter ({self.limiter_part.outer:g} x {self.limiter_part.wall:g} mm "
                  f"sleeve, {self.limiter_length:.2f} mm long)" if self.limiter else "")
        return (f"{self.thread} x {self.length} mm socket-head bolt (ISO 4762) with 2 washers (ISO 7089){sleeve} and "
                "a nut (ISO 4032)")

    def clearance_holes(self, diameter: float | None = None) -> tuple[Cylinder, ...]:
        """The holes through the upper part (the thread's medium clearance, ISO 273, unless
        ``diameter`` mm), 1 mm past each face. With a compression limiter, each is wider by the sleeve's
        two walls: the sleeve rides on the bolt and keeps the room around it that the bolt had (a float:
        it locates nothing, the joint's register does), however much the hole was opened."""
        d = THREADS[self.thread].clearance if diameter is None else diameter
        if self.limiter:
            d += self.limiter_part.outer - THREADS[self.thread].major
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


#: What a datum feature may be: a dowel's hole, a bore that locates a part (the sample holder's), a
#: seat (a kinematic contact's pocket), a heat-set insert's pocket, a register (a spigot, its recess).
DATUM_KINDS = ("dowel", "bore", "seat", "insert", "register")


@dataclass(frozen=True)
class Datum:
    """A locating feature of a part, declared as data where the part cuts it: ``name``, ``kind``
    (:data:`DATUM_KINDS`) and ``shape``, the solid it takes out of the part (a hole, a pocket;
    rig frame, mm). A split keeps its cut planes off the shape's bounds (rigcad.fab.split), so no
    glue seam runs through a dowel hole, a bore or a seat; the seams that remain between two datum
    features are listed by rigcad.fab.split.datum_seams."""

    name: str
    kind: str
    shape: Solid

    def __post_init__(self) -> None:
        if self.kind not in DATUM_KINDS:
            raise GeometryError(f"datum {self.name}: a datum feature is one of {DATUM_KINDS}, not {self.kind!r}")

    @property
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """The feature's axis-aligned box (lo, hi; mm)."""
        return bounds(self.shape)

    @property
    def centre(self) -> tuple[float, float, float]:
        lo, hi = self.bounds
        return tuple(0.5 * (a + b) for a, b in zip(lo, hi))

    def describe(self) -> dict:
        lo, hi = self.bounds
        return {"name": self.name, "kind": self.kind, "lo_mm": list(lo), "hi_mm": list(hi)}


def datums_of(kind: str, name: str, shapes) -> tuple[Datum, ...]:
    """One :class:`Datum` per shape, named ``name 1``, ``name 2``... (just ``name`` for one)."""
    shapes = tuple(shapes)
    return tuple(Datum(name if len(shapes) == 1 else f"{name} {k + 1}", kind, sh) for k, sh in enumerate(shapes))


@dataclass(frozen=True)
class Bought:
    """One bought item of a declared mechanism, as it is ordered: what it is (``item``: the standard
    and its size), how many, its size figures (mm, units in the keys) and what it does."""

    item: str
    standard: str
    quantity: int
    size_mm: dict
    role: str

    def describe(self) -> dict:
        return {"item": self.item, "standard": self.standard, "quantity": self.quantity,
                "size_mm": dict(self.size_mm), "role": self.role}


@dataclass(frozen=True)
class SeatContact:
    """One contact of a kinematic seat: ``kind`` "cone" (a ball on three balls: three constraints),
    "vee" (a ball between two parallel pins: two) or "flat" (a ball on a flat pad: one); where the
    moving part's ball stands (x, y; mm) and the height of its centre at the nominal setting (z, mm);
    ``axis``: the vee's direction (unit x, y) along its pins."""

    kind: str
    x: float
    y: float
    ball_z: float
    axis: tuple[float, float] = (0.0, 0.0)

    #: Constraints each contact takes away (Maxwell's count for Kelvin's clamp: 3 + 2 + 1 = 6).
    CONSTRAINTS = {"cone": 3, "vee": 2, "flat": 1}


@dataclass(frozen=True)
class KinematicSeat:
    """A kinematic mount (Kelvin's clamp) declared as data: ``moving`` part's three hard balls, each
    on the end of an adjusting screw (``thread``, ``pitch_mm``), on a cone (three balls), a vee (two
    dowel pins) and a flat (a steel pad) in ``fixed``; held down by ``springs`` compression springs of
    ``spring_rate`` N/mm compressed by ``spring_deflection`` mm. ``travel``: each screw's range each
    way from its nominal setting (mm); ``step``: the finest turn a hand sets (a fraction of a turn).
    ``bought``: every hard part, as ordered (the bill lists these)."""

    name: str
    moving: str
    fixed: str
    contacts: tuple[SeatContact, ...]
    thread: str
    travel: float
    step: float
    springs: int
    spring_rate: float
    spring_deflection: float
    bought: tuple[Bought, ...]

    def __post_init__(self) -> None:
        kinds = sorted(c.kind for c in self.contacts)
        if kinds != ["cone", "flat", "vee"]:
            raise GeometryError(f"seat {self.name}: a kinematic seat is a cone, a vee and a flat, not {kinds}")
        if self.constraints != 6:  # pragma: no cover - guarded by the kinds above
            raise GeometryError(f"seat {self.name}: {self.constraints} constraints, not 6")
        cone, vee = self.contact("cone"), self.contact("vee")
        to_cone = (cone.x - vee.x, cone.y - vee.y)
        n = math.hypot(*to_cone)
        # the vee's pins must point at the cone: then the seat's thermal growth leaves the cone fixed
        if abs(vee.axis[0] * to_cone[1] - vee.axis[1] * to_cone[0]) > 1e-9 * n:
            raise GeometryError(f"seat {self.name}: the vee's pins must point at the cone")

    @property
    def constraints(self) -> int:
        return sum(SeatContact.CONSTRAINTS[c.kind] for c in self.contacts)

    def contact(self, kind: str) -> SeatContact:
        return next(c for c in self.contacts if c.kind == kind)

    @property
    def pitch(self) -> float:
        return THREADS[self.thread].pitch

    @property
    def resolution(self) -> float:
        """The finest height step of one contact (mm): the screw's pitch times the finest turn."""
        return self.pitch * self.step

    @property
    def preload(self) -> float:
        """The springs' total force holding the seat down (N)."""
        return self.springs * self.spring_rate * self.spring_deflection

    def lever(self, kind: str) -> float:
        """Distance (mm) from contact ``kind`` to the line through the other two: its screw tilts the
        moving part about that line by (height change) / lever."""
        p = self.contact(kind)
        a, b = (c for c in self.contacts if c.kind != kind)
        return abs((b.x - a.x) * (a.y - p.y) - (a.x - p.x) * (b.y - a.y)) / math.hypot(b.x - a.x, b.y - a.y)

    def tilt(self, kind: str) -> dict:
        """The tilt contact ``kind``'s screw sets: range each way and resolution (rad)."""
        arm = self.lever(kind)
        return {"contact": kind, "lever_mm": arm, "range_rad": self.travel / arm, "resolution_rad": self.resolution / arm}

    def describe(self) -> dict:
        return {"name": self.name, "moving": self.moving, "fixed": self.fixed,
                "contacts": [{"kind": c.kind, "x_mm": c.x, "y_mm": c.y, "ball_z_mm": c.ball_z,
                              "constraints": SeatContact.CONSTRAINTS[c.kind]} for c in self.contacts],
                "screw": {"thread": self.thread, "pitch_mm": self.pitch, "travel_each_way_mm": self.travel,
                          "resolution_mm": self.resolution},
                "tilts": [self.tilt(k) for k in ("flat", "vee")],
                "preload_N": self.preload, "bought": [b.describe() for b in self.bought]}


__all__ = ["DATUM_KINDS", "INTO", "Bought", "Datum", "KinematicSeat", "ScrewJoint", "SeatContact", "datums_of"]
