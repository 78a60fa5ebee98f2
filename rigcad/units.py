"""Units at the boundary: parse ``"13.5 cm"``, ``"11 in"``, ``"5.5 mil"``, ``"20 deg"``.

Inside rigcad every length is in millimetres, every angle in radians and every mass in kilograms
(float64). Profiles must say their unit; a bare number is refused for a length, an angle or a mass
(except ``0``), because a silently assumed unit is how a 27 cm distance becomes 27 mm.
"""

from __future__ import annotations

import math
import re
import unicodedata

#: Radians per degree: the one conversion constant the code uses internally (reports say "_deg").
DEG = math.pi / 180.0

#: Millimetres per unit of length.
LENGTH_UNITS: dict[str, float] = {
    "nm": 1e-6,
    "um": 1e-3,
    "µm": 1e-3,
    "micron": 1e-3,
    "mm": 1.0,
    "cm": 10.0,
    "m": 1000.0,
    "mil": 0.0254,
    "thou": 0.0254,
    "in": 25.4,
    "inch": 25.4,
    "ft": 304.8,
}

#: Radians per unit of angle.
ANGLE_UNITS: dict[str, float] = {
    "deg": DEG,
    "°": DEG,
    "arcmin": DEG / 60.0,
    "rad": 1.0,
    "mrad": 1e-3,
    "urad": 1e-6,
}

#: Kilograms per unit of mass (an instrument's weight on the tower; internally kilograms).
MASS_UNITS: dict[str, float] = {
    "g": 1e-3,
    "kg": 1.0,
    "oz": 0.028349523125,
    "lb": 0.45359237,
}

KINDS = {"length": LENGTH_UNITS, "angle": ANGLE_UNITS, "mass": MASS_UNITS}
#: The unit an error's example shows, per kind.
EXAMPLE_UNIT = {"length": "mm", "angle": "deg", "mass": "kg"}

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_QUANTITY = re.compile(rf"^\s*(?P<num>{_NUMBER}|[-+]?inf(?:inity)?)\s*(?P<unit>[^\s\d.+-][^\s]*)?\s*$",
                       re.I | re.ASCII)
#: Longest number literal read (characters): float64 carries 17 significant digits.
MAX_NUMBER_CHARS = 40
#: The non-ASCII characters a quantity may hold: unit symbols only.
_UNIT_SYMBOLS = frozenset(ch for table in (LENGTH_UNITS, ANGLE_UNITS) for unit in table for ch in unit if ord(ch) > 127)


class UnitError(ValueError):
    """A quantity string that does not parse; the profile layer adds file and line."""


def parse_quantity(text: object, kind: str) -> float:
    """Parse ``text`` as a ``kind`` ("length" or "angle") quantity; return mm or rad.

    ``inf`` is accepted for lengths (a centre of projection at infinity). Raises
    :class:`UnitError` naming the valid units.
    """
    units = KINDS[kind]
    valid = ", ".join(sorted(units))
    if isinstance(text, bool):
        raise UnitError(f"expected a {kind} with a unit ({valid}), got {text!r}")
    if isinstance(text, (int, float)):
        if text == 0 or (kind == "length" and math.isinf(text)):
            return float(text)
        raise UnitError(f"a {kind} needs a unit, e.g. '{text} {EXAMPLE_UNIT[kind]}' (units: {valid})")
    if not isinstance(text, str):
        raise UnitError(f"expected a {kind} such as '13.5 cm' or '20 deg', got {text!r}")
    for i, ch in enumerate(text):
        if ord(ch) > 127 and ch not in _UNIT_SYMBOLS:
            name = unicodedata.name(ch, "unnamed").lower()
            raise UnitError(f"character {i + 1} of the value is U+{ord(ch):04X} ({name}): numbers take ASCII "
                            "digits, '.', 'e' and ASCII spaces, e.g. '13.5 cm'")
    match = _QUANTITY.match(text)
    if not match:
        raise UnitError(f"cannot read {text!r} as a {kind}: write a number and a unit, e.g. '13.5 cm' (units: {valid})")
    if len(match["num"]) > MAX_NUMBER_CHARS:
        raise UnitError(f"a number of {len(match['num'])} characters: write at most {MAX_NUMBER_CHARS} "
                        "(float64 keeps 17 significant digits), e.g. '1.5e3 mm'")
    number = float(match["num"])
    unit = match["unit"]
    literal_inf = "inf" in match["num"].lower()
    if math.isinf(number) and not literal_inf:
        raise UnitError(f"{match['num']} is beyond float64's range (~1.8e308); write 'inf' if you mean infinity")
    if math.isinf(number) and kind != "length":
        raise UnitError(f"an infinite {kind} makes no sense: {text!r}")
    if unit is None:
        if number == 0 or math.isinf(number):
            return number
        raise UnitError(f"{text!r} has no unit (units for a {kind}: {valid})")
    key = unit if unit in units else unit.lower()
    if key not in units:
        other = [k for k, table in KINDS.items() if k != kind and (unit in table or unit.lower() in table)]
        hint = f" ({unit!r} is a unit of {other[0]})" if other else ""
        raise UnitError(f"unknown {kind} unit {unit!r} in {text!r}{hint}; valid: {valid}")
    value = number * units[key]
    if math.isinf(value) and not literal_inf:
        raise UnitError(f"{text!r} is beyond float64's range once converted to {'mm' if kind == 'length' else 'rad'}")
    return value


def mm_to_in(value_mm: float) -> float:
    """Millimetres to inches."""
    return value_mm / 25.4


def hours_minutes(seconds: float) -> str:
    """A duration for people, to the nearest minute: ``3h05m`` (seconds rounded to whole first)."""
    s = int(round(seconds))
    return f"{s // 3600}h{(s % 3600) // 60:02d}m"
