"""Locating features declared as data beside the parts' geometry: where one part is put back.

A :class:`DowelRegister` is two ISO 8734 dowel pins (m6) pressed into the ``lower`` part, over which
the ``upper`` part drops: the first pin in a round hole, the second in a slot along the line between
them. The round hole fixes the upper part's place, the slot its turn, and the slot leaves it free
along that line, so a printed part's scale error between the two pins cannot bind it (two round holes
would, by the scale error over their distance). Lifted off and set back, the upper part returns to
within the pins' fit; its screws only clamp it (their holes are cleared for the print's scale and
position errors: :func:`bolt_hole`). The parts cut their holes from the declaration
(:meth:`DowelRegister.lower_holes`, :meth:`DowelRegister.upper_holes`); the manual's bill and steps
read the same declaration. Frame: mm, rig frame (pins vertical).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.parts.recipe import Box, Cylinder
from rigcad.standards import THREADS, longest_dowel

#: Worst-case diametral clearance (mm) of an ISO 8734 m6 pin (+0.004..+0.012 mm for 3..6 mm) in a
#: hole reamed H7 (0..+0.012 mm): 0.012 - 0.004 = 0.008 mm in the upper part's hole; the lower part
#: holds its pin by a press fit (the hole reamed a size under, or the pin glued: no play).
PIN_FIT_MM = 0.008
#: The slot across its pin (mm): printed at the pin's size and filed until the pin slides in it.
SLOT_FIT_MM = 0.05
#: The pin stops this far short of the upper part's top face (mm), and its hole in the lower part
#: this far past the pin's end (mm: room for the chips of reaming and for pressing it home).
PIN_SHORT_MM, PIN_BOTTOM_MM = 1.0, 0.5


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
    def lower_depth(self) -> float:
        """Depth (mm) of each pin's hole in the lower part, from its top face."""
        return self.length - self.upper_engagement + PIN_BOTTOM_MM

    @property
    def item(self) -> str:
        return f"dowel pin, ISO 8734 m6, {self.diameter:g} x {self.length} mm (hardened steel)"

    @property
    def repeatability(self) -> tuple[float, float]:
        """(lateral mm, turn rad) to which the upper part returns when set back on its pins, worst case:
        half the round hole's fit, and the slot's fit across its pin over the pins' spacing."""
        return PIN_FIT_MM / 2, SLOT_FIT_MM / self.spacing

    def lower_holes(self) -> tuple[Cylinder, ...]:
        """The pins' holes in the lower part, from its top face (printed at the pin's size, reamed)."""
        top = self.lower_z[1]
        return tuple(Cylinder((x, y, top - self.lower_depth), self.diameter / 2, self.lower_depth + 1.0)
                     for x, y in self.points)

    def upper_holes(self) -> tuple:
        """The round hole over the first pin and the slot over the second (along the line from the
        first, which runs along x or y), through the upper part."""
        z0, z1 = self.upper_z
        r = self.diameter / 2
        (x0, y0), (x1, y1) = self.points
        hole = Cylinder((x0, y0, z0 - 1.0), r, z1 - z0 + 2.0)
        along_x = abs(y1 - y0) < 1e-9
        dx, dy = (self.slot / 2, 0.0) if along_x else (0.0, self.slot / 2)
        ends = tuple(Cylinder((x1 + s * dx, y1 + s * dy, z0 - 1.0), r, z1 - z0 + 2.0) for s in (-1, 1))
        web = Box((x1 - dx - (0.0 if along_x else r), y1 - dy - (r if along_x else 0.0), z0 - 1.0),
                  (x1 + dx + (0.0 if along_x else r), y1 + dy + (r if along_x else 0.0), z1 + 1.0))
        return (hole, *ends, web)


def bolt_hole(thread: str, radius: float, position: float, scale: float) -> float:
    """A clamping bolt's hole (mm) in a part located by a register: the thread's clearance (ISO 273
    medium) and, each side, both parts' print position errors and the scale error at ``radius`` mm from
    the register's round pin, so that no bolt bears on its hole's side and fights the pins."""
    return THREADS[thread].clearance + 2 * (2 * position + scale * radius)


__all__ = ["DowelRegister", "PIN_FIT_MM", "SLOT_FIT_MM", "bolt_hole"]
