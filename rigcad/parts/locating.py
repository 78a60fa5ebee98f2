"""Locating features declared as data beside the parts' geometry: where one part is put back.

A :class:`DowelRegister` is two ISO 8734 dowel pins (m6) pressed into the ``lower`` part, over which
the ``upper`` part drops: the first pin in a round hole, the second in a slot along the line between
them. The fits are ISO 286's (rigcad.standards): the press end, the pin in the lower part's blind hole
reamed N7 (interference over the whole zones: the pin never works loose, and the hole's floor keeps it
from walking down); the slip end, the pin in the upper part's round hole reamed F7 (a sliding fit: the
upper part lifts off); the slot filed until the pin slides along it. Every pin hole is printed at the
twist drill's size before the reamer (the reamer's size less its reaming allowance, standards.pre_ream_drill):
whatever a printer's hole shrink, drilling it to that size leaves the reamer its stock. The round hole fixes the upper part's place, the slot its turn, and the slot leaves it free
along that line, so a printed part's scale error between the two pins cannot bind it (two round holes
would, by the scale error over their distance). Lifted off and set back, the upper part returns to
within the pins' fit; its screws only clamp it (their holes are cleared for the print's scale and
position errors: :func:`bolt_hole`). The parts cut their holes from the declaration
(:meth:`DowelRegister.lower_holes`, :meth:`DowelRegister.upper_holes`); the manual's bill and steps
read the same declaration. Frame: mm, rig frame (pins vertical).

A register may be *drilled in place* (``DowelRegister.drilled``): the lower part is printed solid
where its pins go, the upper part is indicated in (set against another datum with a dial test
indicator) and clamped, and the pins' holes in the lower part are drilled and reamed through the
upper part's round hole and slot, which guide the drill. The register then holds the upper part where
it was indicated, whatever the print errors and glue seams between that datum and the pins.

A :class:`ShimStop` is a stop a part is pressed onto by a set screw through a pack of bought shim foil
(rigcad.standards.SHIM_FOIL): taking foil out or adding it moves the part in steps of the thinnest
foil, up to the pack's nominal thickness each way. A screw only presses; the stop and the foil set
the place, so the setting does not creep with the screw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from rigcad.errors import GeometryError
from rigcad.parts.recipe import Box, Cylinder, Line, Prism, Revolve, Section, Translate
from rigcad.standards import (DOWEL_PRESS_HOLE, DOWEL_SHAFT, DOWEL_SLIP_HOLE, GAUGE_PIN, GAUGE_PIN_SPEC, INSERTS,
                               MACHINE_REAMER, MACHINE_REAMER_SPEC, REAMER_LEAD_MM, SHIM_FOIL, THREADS, Fit, gauge_pins,
                               longest_dowel, pre_ream_drill, shortest_set_screw)


def press_fit(diameter: float) -> Fit:
    """An ISO 8734 pin's press end (rigcad.standards.DOWEL_PRESS_HOLE over m6) at ``diameter`` mm."""
    return Fit(diameter, DOWEL_PRESS_HOLE, DOWEL_SHAFT, "press")


def slip_fit(diameter: float) -> Fit:
    """An ISO 8734 pin's slip end (rigcad.standards.DOWEL_SLIP_HOLE over m6) at ``diameter`` mm."""
    return Fit(diameter, DOWEL_SLIP_HOLE, DOWEL_SHAFT, "slip")


def reamers(diameter: float) -> str:
    """The tools a ``diameter`` mm pin's holes take, as the bill and the steps name them: the drill, the
    press and slip ends' machine reamers (rigcad.standards.MACHINE_REAMER: short lead, for blind holes) and
    the gauge pins that check each hole (:func:`gauge_text`)."""
    return (f"a {pre_ream_drill(diameter):g} mm twist drill (DIN 338), {diameter:g} mm {DOWEL_PRESS_HOLE} and "
            f"{diameter:g} mm {DOWEL_SLIP_HOLE} {MACHINE_REAMER}s ({MACHINE_REAMER_SPEC}), and "
            f"{gauge_text(diameter)}")


def gauge_text(diameter: float) -> str:
    """The go and no-go gauge pins (rigcad.standards.GAUGE_PIN) of a ``diameter`` mm pin's press and slip holes."""
    (pg, pn), (sg, sn) = gauge_pins(diameter, DOWEL_PRESS_HOLE), gauge_pins(diameter, DOWEL_SLIP_HOLE)
    return (f"{GAUGE_PIN}s ({GAUGE_PIN_SPEC}), go and no-go: {pg:.3f} and {pn:.3f} mm for {diameter:g} {DOWEL_PRESS_HOLE}, "
            f"{sg:.3f} and {sn:.3f} mm for {diameter:g} {DOWEL_SLIP_HOLE}")


def check_blind_hole(name: str, depth: float, engagement: float, diameter: float, param: str | None = None) -> None:
    """Refuse (GeometryError naming the register and ``param``) a pin's blind hole ``depth`` mm deep that
    does not hold the pin's ``engagement`` (at least its ``diameter``) and the machine reamer's lead under
    it (rigcad.standards.REAMER_LEAD_MM: the reamer leaves that much under size at the floor)."""
    if engagement < diameter - 1e-9 or depth < engagement + REAMER_LEAD_MM - 1e-9:
        raise GeometryError(f"register {name}: its pins' blind holes, {depth:.1f} mm deep, must hold the pin "
                            f"{max(engagement, diameter):g} mm (at least its {diameter:g} mm diameter) and the "
                            f"machine reamer's {REAMER_LEAD_MM:g} mm lead under it: a thicker lower part or "
                            "a smaller datum.dowel_diameter", param=param)

#: The slot across its pin (mm): printed at the pin's size and filed until the pin slides in it.
SLOT_FIT_MM = 0.05
#: The pin stops this far short of the upper part's top face (mm), and its hole in the lower part
#: this far past the pin's end (mm): the machine reamer's lead, which leaves the floor's last millimetre
#: under size (rigcad.standards.REAMER_LEAD_MM), and room for the chips and for pressing it home.
PIN_SHORT_MM, PIN_BOTTOM_MM = 1.0, REAMER_LEAD_MM
#: A register's return is measured by lifting the upper part off and setting it back this many times.
REPEAT_TRIALS = 5
#: A shim stop's pack at the design setting (mm): the part moves this far each way by taking foil out
#: or adding as much again (its range). It covers the paraboloid's placement stack from O on the
#: shipped printers (rigcad.fab.stack: 1.21 mm lateral and 0.64 mm in height worst case on the MK3S).
SHIM_PACK_MM = 1.5
#: A dial test indicator's graduation (mm): 0.01 mm, the common lever-type indicator (DIN 2270).
INDICATOR_MM = 0.01
#: The finer lever-type dial test indicator (DIN 2270) that reads a register's return (mm graduation):
#: the return the tolerance stack takes is a few micrometres (half a slip fit's largest clearance,
#: 0.009 mm for the dome's 4 mm pins), which a 0.01 mm graduation cannot resolve; a reading is
#: trusted to half a graduation, so the finer indicator's is at most half that figure
#: (DowelRegister.repeat_step refuses otherwise).
REPEAT_INDICATOR_MM = 0.002
#: How a register's dowel pins are pressed into their reamed N7 holes in a printed part: in retaining compound
#: by default, not only when a hole came out loose: an N7/m6 press holds by 0.008-0.028 mm of interference,
#: which relaxes as the plastic creeps round the pin (the machinist's review), and the cured compound fills
#: what it gives up.
PRESS_IN_COMPOUND = ("each with a film of retaining compound on it (the press's few micrometres of interference "
                     "relax as the plastic creeps; the cured compound keeps the pin from walking)")


#: The sample holder's fit in the base plate's bore (ISO 286, the preferred close running fit): the bore bored
#: (or reamed) H7 and the holder turned from bar f7, so that the sample point O sits on the bore's axis to half the
#: fit's largest clearance (a printed holder in a printed bore floats by their clearance and both prints'
#: errors). Not g6: the PLA bore shrinks onto the aluminium holder in a cold lab (40 mm x (PLA's - 6082's
#: expansion) x rigcad.fab.loads.LAB_SWING_K = 0.0094 mm at -3 K), more than H7/g6's 0.009 mm least clearance;
#: H7/f7 keeps 0.025 mm (tests/parts/test_holder_fit.py checks it against the loads' materials).
HOLDER_HOLE, HOLDER_SHAFT = "H7", "f7"


def holder_fit(diameter: float, param: str = "sample_holder.radius", where: str | None = None) -> Fit:
    """The sample holder's fit at its ``diameter`` mm (:data:`HOLDER_HOLE` over :data:`HOLDER_SHAFT`);
    GeometryError naming ``param`` when ISO 286's table in rigcad.standards does not reach it."""
    fit = Fit(diameter, HOLDER_HOLE, HOLDER_SHAFT, "sliding")
    try:
        fit.clearance
    except ValueError as err:
        raise GeometryError(f"the sample holder's {diameter:g} mm fit: {err}; a holder of at most 50 mm across",
                            param=param, where=where) from err
    return fit


@dataclass(frozen=True)
class DowelRegister:
    """Two ``diameter`` mm dowels pressed into ``lower`` at ``points`` (x, y; mm), standing up into
    ``upper``: the upper part's span ``upper_z`` (bottom, top; mm) rests on the lower part's top face
    (``lower_z``: bottom, top). ``slot``: the slot's extra length along the line between the pins (mm,
    the scale error it takes up). ``param``: the profile key that sizes the pins, for errors."""

    name: str
    upper: str
    lower: str
    diameter: float
    points: tuple[tuple[float, float], tuple[float, float]]
    upper_z: tuple[float, float]
    lower_z: tuple[float, float]
    slot: float
    param: str = ""
    #: Drilled in place (see the module): the lower part is printed without the pins' holes.
    drilled: bool = False
    #: How the register is made when it is drilled in place (the manual's shop step), from the part.
    procedure: str = ""

    def __post_init__(self) -> None:
        if len(self.points) != 2:
            raise GeometryError(f"register {self.name}: two pins, not {len(self.points)}", param=self.param or None)
        if self.spacing <= 2 * self.diameter:
            raise GeometryError(f"register {self.name}: its pins stand {self.spacing:.1f} mm apart, too close to "
                                "set a turn", param=self.param or None)
        (x0, y0), (x1, y1) = self.points
        if abs(x1 - x0) > 1e-9 and abs(y1 - y0) > 1e-9:
            raise GeometryError(f"register {self.name}: its pins' line must run along x or y (its slot is a box)",
                                param=self.param or None)
        if self.upper_engagement < self.diameter:
            raise GeometryError(f"register {self.name}: {self.upper} is too thin ({self.upper_z[1] - self.upper_z[0]:g} "
                                f"mm) to hold a {self.diameter:g} mm pin by its diameter", param=self.param or None)
        try:
            self.length
        except ValueError as err:
            raise GeometryError(f"register {self.name}: {err}", param=self.param or None) from err
        check_blind_hole(self.name, self.lower_depth, self.lower_engagement, self.diameter, self.param or None)

    @property
    def spacing(self) -> float:
        (x0, y0), (x1, y1) = self.points
        return math.hypot(x1 - x0, y1 - y0)

    @property
    def upper_engagement(self) -> float:
        """How far each pin stands up into the upper part (mm)."""
        return self.upper_z[1] - self.upper_z[0] - PIN_SHORT_MM

    @property
    def length(self) -> int:
        """The pins' length (mm, ISO 8734 as sold): the longest that stands ``upper_engagement`` proud
        and keeps its hole in the lower part ``PIN_BOTTOM_MM`` short of the lower part's underside
        (and a millimetre of floor under it)."""
        room = self.upper_engagement + (self.lower_z[1] - self.lower_z[0]) - PIN_BOTTOM_MM - 1.0
        return longest_dowel(room)

    @property
    def lower_engagement(self) -> float:
        """How far each pin stands down into the lower part, pressed (mm)."""
        return self.length - self.upper_engagement

    @property
    def lower_depth(self) -> float:
        """Depth (mm) of each pin's hole in the lower part, from its top face."""
        return self.length - self.upper_engagement + PIN_BOTTOM_MM

    @property
    def item(self) -> str:
        return (f"dowel pin, ISO 8734 m6, {self.diameter:g} x {self.length} mm (hardened steel; pressed in "
                f"{self.diameter:g} {DOWEL_PRESS_HOLE}, slides in {self.diameter:g} {DOWEL_SLIP_HOLE})")

    @property
    def press(self) -> Fit:
        """The press end: a pin in the lower part's hole (ISO 286)."""
        return press_fit(self.diameter)

    @property
    def slip(self) -> Fit:
        """The slip end: a pin in the upper part's round hole (ISO 286)."""
        return slip_fit(self.diameter)

    @property
    def drill(self) -> float:
        """The holes' printed size and the twist drill before the reamers (mm): standards.pre_ream_drill."""
        return pre_ream_drill(self.diameter)

    @property
    def repeatability(self) -> tuple[float, float]:
        """(lateral mm, turn rad) to which the upper part returns when set back on its pins, worst case:
        half the round hole's slip fit at its loosest, and the slot's fit across its pin over the pins'
        spacing."""
        return self.slip.clearance[1] / 2, SLOT_FIT_MM / self.spacing

    def shop_text(self) -> str:
        """The manual's shop step for a register whose holes are printed (one paragraph, the fits and
        tools by name); a register drilled in place has its part's own (``procedure``)."""
        if self.procedure:
            return self.procedure
        lower, upper = self.lower.replace("_", " "), self.upper.replace("_", " ")
        return (f"The {lower}'s two pin holes and the {upper}'s round hole print at {self.drill:g} mm: drill each "
                f"{self.drill:g} mm in the drill press (a hole that printed small), then, in the drill press at low "
                f"speed, ream the {lower}'s holes {self.diameter:g} {DOWEL_PRESS_HOLE} to the depth stop "
                f"({self.reaming_text()}) and the {upper}'s round hole {self.diameter:g} {DOWEL_SLIP_HOLE}; "
                f"{self.gauge_step()} File its slot until a pin slides along it but not across. Press the pins "
                f"({self.item}) into the {lower} with a vise, {PRESS_IN_COMPOUND}, until {self.upper_engagement:g} mm "
                "stands proud: "
                f"{self.press.describe()}; the {upper} slides on them, {self.slip.describe()}. {self.repeat_step()}")

    def reaming_text(self) -> str:
        """The blind holes' depth and what it holds: the pin's engagement and the machine reamer's lead."""
        return (f"blind, {self.lower_depth:.1f} mm deep: the pin's {self.lower_engagement:g} mm and the "
                f"{MACHINE_REAMER}'s {REAMER_LEAD_MM:g} mm lead under it; hold the bought reamer's chamfer against "
                f"that figure: a longer lead leaves the pin's end in an under-size hole")

    def gauge_step(self) -> str:
        """The check of each reamed hole with its go and no-go gauge pins (rigcad.standards.gauge_pins)."""
        (pg, pn), (sg, sn) = self.press_gauges, gauge_pins(self.diameter, DOWEL_SLIP_HOLE)
        return (f"check each hole with the {GAUGE_PIN}s: in the {self.diameter:g} {DOWEL_PRESS_HOLE} holes the "
                f"{pg:.3f} mm go pin enters {self.lower_engagement:g} mm deep (the pin's engagement: the reamer's "
                f"{REAMER_LEAD_MM:g} mm lead leaves the hole's floor under size) and the {pn:.3f} mm no-go pin does "
                "not start; in the "
                f"{self.diameter:g} {DOWEL_SLIP_HOLE} hole the {sg:.3f} mm pin goes through and the {sn:.3f} mm "
                "pin does not (a hole that takes the no-go pin is drilled out and the part reprinted, or its pin "
                "set in retaining compound).")

    @property
    def press_gauges(self) -> tuple[float, float]:
        return gauge_pins(self.diameter, DOWEL_PRESS_HOLE)

    def repeat_step(self) -> str:
        """The measurement of the register's return that the tolerance stack's figure stands on: indicate the
        upper part, lift it off and set it back REPEAT_TRIALS times, and record each reading."""
        lateral, _ = self.repeatability
        if REPEAT_INDICATOR_MM > lateral / 2 + 1e-12:
            raise GeometryError(f"the {self.upper}'s register returns to {lateral:.4f} mm (half its "
                                f"{self.diameter:g} mm pin's slip fit clearance), under two graduations of the "
                                f"{REPEAT_INDICATOR_MM:g} mm indicator that must read it: a larger pin "
                                f"({self.param or 'its diameter'}; a larger pin's slip fit is looser)",
                                param=self.param or None)
        upper = self.upper.replace("_", " ")
        return (f"Measure its return: a dial test indicator ({REPEAT_INDICATOR_MM:g} mm graduation) on the "
                f"{self.lower.replace('_', ' ')}, its tip on a side of the {upper} square to the line between "
                f"the pins, zeroed; part the two off the pins and set them back together {REPEAT_TRIALS} times, reading "
                f"the indicator each time, and record the {REPEAT_TRIALS} readings. The tolerance stack takes "
                f"{lateral:.3f} mm each way (half the slip fit's largest clearance): each reading must be within "
                f"{lateral:.3f} mm of zero; a larger one means a hole is over size (check it with the gauge pins).")

    def lower_holes(self) -> tuple[Cylinder, ...]:
        """The pins' blind holes in the lower part, from its top face, printed at :attr:`drill`'s size
        (drilled, then reamed to the press fit); none for a register drilled in place (its holes are
        drilled through the upper part's)."""
        if self.drilled:
            return ()
        return tuple(replace(c, radius=self.drill / 2) for c in self.lower_zones())

    @property
    def hangs(self) -> bool:
        """True when the ``lower`` part (the one the pins are pressed into) is above the upper one (a
        shelf on a column's top flange): its holes then run up from its underside."""
        return self.lower_z[0] >= self.upper_z[1] - 1e-9

    def lower_zones(self) -> tuple[Cylinder, ...]:
        """Where the pins' blind holes are (or will be drilled) in the lower part, from the face it shares
        with the upper part (its top face, or its underside when it :attr:`hangs`), at the nominal places:
        a split keeps its cuts off them either way."""
        if self.hangs:
            face = self.lower_z[0]
            return tuple(Cylinder((x, y, face - 1.0), self.diameter / 2, self.lower_depth + 1.0) for x, y in self.points)
        top = self.lower_z[1]
        return tuple(Cylinder((x, y, top - self.lower_depth), self.diameter / 2, self.lower_depth + 1.0)
                     for x, y in self.points)

    def upper_holes(self) -> tuple:
        """The round hole over the first pin (printed at :attr:`drill`'s size, drilled and reamed to the
        slip fit) and the slot over the second (along the line from the first, which runs along x or y;
        printed at the pin's width and filed until it slides), through the upper part."""
        z0, z1 = self.upper_z
        r = self.diameter / 2
        (x0, y0), (x1, y1) = self.points
        hole = Cylinder((x0, y0, z0 - 1.0), self.drill / 2, z1 - z0 + 2.0)
        along_x = abs(y1 - y0) < 1e-9
        dx, dy = (self.slot / 2, 0.0) if along_x else (0.0, self.slot / 2)
        # the slot's round ends (revolved: the bill does not take them for bolts' holes)
        ends = tuple(stepped_hole(x1 + s * dx, y1 + s * dy, z0 - 1.0, ((r, z1 - z0 + 2.0),)) for s in (-1, 1))
        web = Box((x1 - dx - (0.0 if along_x else r), y1 - dy - (r if along_x else 0.0), z0 - 1.0),
                  (x1 + dx + (0.0 if along_x else r), y1 + dy + (r if along_x else 0.0), z1 + 1.0))
        return (hole, *ends, web)


def bolt_hole(thread: str, radius: float, position: float, scale: float) -> float:
    """A clamping bolt's hole (mm) in a part located by a register: the thread's clearance (ISO 273
    medium) and, each side, both parts' print position errors and the scale error at ``radius`` mm from
    the register's round pin, so that no bolt bears on its hole's side and fights the pins."""
    return THREADS[thread].clearance + 2 * (2 * position + scale * radius)


@dataclass(frozen=True)
class ShimStop:
    """A shim stop as the tolerance stack reads it: the optical ``element`` it places and the ``axis``
    it sets ("x", "y", "vertical" or "tilt"), its ``range`` each way and its ``resolution`` (mm, or
    rad for a tilt: the thinnest foil, through the stop's lever on the element), the nominal ``pack``
    (mm of foil at the design setting) and ``how`` it is set (for the bill, the steps, the stack)."""

    name: str
    element: str
    axis: str
    range: float
    resolution: float
    pack: float
    how: str


def set_screw_length(thread: str, wall: float, near: float, far: float) -> int:
    """A set screw's length (mm, ISO 4026) in a heat-set insert through a ``wall`` mm thick, pressing on a
    face ``near`` to ``far`` mm past the wall as its stop's pack is set: the shortest that stands no more
    than a millimetre proud of the wall at the near setting; GeometryError when at the far one it would
    keep under two millimetres of thread in the insert."""
    length = shortest_set_screw(thread, wall + near)
    ins = INSERTS[thread]
    if length is None or length - wall - near > 1.0 or ins.length - (wall + far - length) < 2.0:
        raise GeometryError(f"no {thread} set screw (ISO 4026) both stays within a millimetre of the {wall:g} mm "
                            f"wall and keeps two millimetres in its insert over its {far - near:g} mm of travel: a "
                            "smaller shim pack")
    return length


def foil_step() -> float:
    """The thinnest bought shim foil (mm): a shim stop's step."""
    return min(SHIM_FOIL)


def stepped_hole(x: float, y: float, z0: float, steps: tuple[tuple[float, float], ...]) -> Translate:
    """A vertical hole (mm) of ``steps`` (radius, height) from ``z0`` up, one on the other (an insert's
    pocket over a screw's bore, a pin's hole), drawn as one revolved section: a blind or stepped hole
    that is not a through bolt's (the bill finds bolts by their plain vertical cylinders)."""
    pts, z = [(0.0, 0.0)], 0.0
    for r, h in steps:
        pts += [(r, z), (r, z + h)]
        z += h
    pts.append((0.0, z))
    segs = tuple(Line(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts)) if pts[k] != pts[(k + 1) % len(pts)])
    return Translate(Revolve(Section(segs)), (float(x), float(y), float(z0)))


def teardrop_along_y(centre: tuple[float, float, float], radius: float, length: float, n: int = 16) -> Translate:
    """A hole along y (mm) with a printable profile: the circle of ``radius`` (its polygon of ``n``
    sides drawn about it, so the hole is never under size) closed above by two 45 deg flanks meeting
    at a point (a teardrop: a horizontal hole prints without support and does not droop into its
    bore); ``length`` along y, centred on ``centre``."""
    r = radius / math.cos(math.pi / n)
    pts = [(r * math.cos(2 * math.pi * (k + 0.5) / n), r * math.sin(2 * math.pi * (k + 0.5) / n)) for k in range(n)]
    ring = [p for p in pts if p[1] < radius * math.sqrt(0.5)] + [(0.0, radius * math.sqrt(2.0))]
    ring.sort(key=lambda p: math.atan2(p[1], p[0]) % (2 * math.pi))
    segs = tuple(Line(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring)))
    return Translate(Prism(Section(segs), length), tuple(float(v) for v in centre))


__all__ = ["DowelRegister", "REPEAT_TRIALS", "check_blind_hole", "gauge_text", "HOLDER_HOLE", "HOLDER_SHAFT", "holder_fit", "INDICATOR_MM", "SHIM_PACK_MM", "press_fit", "reamers", "slip_fit", "SLOT_FIT_MM", "ShimStop", "bolt_hole",
           "foil_step", "set_screw_length", "stepped_hole", "teardrop_along_y"]
