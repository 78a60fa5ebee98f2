import math

import pytest

from rigcad.units import UnitError, parse_quantity


@pytest.mark.parametrize("text, mm", [
    ("13.5 cm", 135.0), ("11 in", 279.4), ("5.5 mil", 0.1397), ("1e-9 mm", 1e-9), ("2 um", 0.002),
    ("0.25in", 6.35), ("-3 mm", -3.0), (0, 0.0), ("inf", math.inf), ("1 m", 1000.0),
])
def test_lengths_parse_to_millimetres(text, mm):
    # 1e-12 relative: exact decimal scale factors, only float rounding remains
    assert parse_quantity(text, "length") == pytest.approx(mm, rel=1e-12)


@pytest.mark.parametrize("text, rad", [("20 deg", math.radians(20)), ("0.5 rad", 0.5), ("90°", math.pi / 2),
                                       ("30 arcmin", math.radians(0.5))])
def test_angles_parse_to_radians(text, rad):
    assert parse_quantity(text, "angle") == pytest.approx(rad, rel=1e-12)


@pytest.mark.parametrize("text, kind, fragment", [
    (13.5, "length", "needs a unit"),
    ("13.5", "length", "has no unit"),
    ("13.5 furlong", "length", "unknown length unit"),
    ("20 deg", "length", "is a unit of angle"),
    ("5 mm", "angle", "is a unit of length"),
    ("twenty deg", "angle", "cannot read"),
    ("inf deg", "angle", "infinite"),
    (True, "length", "expected a length"),
])
def test_bad_quantities_name_the_problem(text, kind, fragment):
    with pytest.raises(UnitError, match=fragment):
        parse_quantity(text, kind)
