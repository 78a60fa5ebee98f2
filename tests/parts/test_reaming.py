"""The dowels' blind holes are makeable as the steps write them (rigcad.parts.locating): machine (chucking)
reamers with a short lead, each hole deep enough for the pin's engagement and that lead, checked with go and
no-go gauge pins; the register's return measured, not claimed; and the bill holds every tool a step names."""

from __future__ import annotations

import re

import pytest

import rigcad
from rigcad.errors import GeometryError
from rigcad.manual import bom as B
from rigcad.parts import locating
from rigcad.parts.dome import indicating_text, register
from rigcad.parts.tower import column_register
from rigcad.standards import REAMER_LEAD_MM, gauge_pins


@pytest.fixture(scope="module")
def rig():
    return rigcad.load("achutha2006")


def _registers(rig):
    t, tw, p = rig.layout.tower, rig.profile.tower, rig.profile
    return (register(p, rig.layout), column_register(t, p, t.column_base_z, tw.wall, "foot"),
            column_register(t, p, t.shelf_top_z - t.shelf_thickness - tw.wall, tw.wall, "top"))


def _steps(rig) -> list[str]:
    dome, foot, top = _registers(rig)
    return [indicating_text(rig.profile, rig.layout, dome), foot.shop_text(), top.shop_text()]


def test_every_blind_hole_holds_the_pin_and_the_reamer_lead(rig):
    """The dome's register (in the base plate), the column's foot (tongue) and top (shelf): each blind hole
    is at least the pin's press engagement (itself at least the pin's diameter) plus the machine reamer's
    lead, and its step states that depth."""
    for reg, text in zip(_registers(rig), _steps(rig), strict=True):
        assert reg.lower_engagement >= reg.diameter, reg.name
        assert reg.lower_depth >= reg.lower_engagement + REAMER_LEAD_MM - 1e-9, (reg.name, reg.lower_depth)
        assert f"{reg.lower_depth:.1f} mm deep" in text and f"{REAMER_LEAD_MM:g} mm lead" in text, reg.name


def test_a_blind_hole_shorter_than_engagement_and_lead_is_refused():
    """The old 0.5 mm past the pin's end under a 1 mm lead, and a lower part too thin to hold a pin by its
    diameter plus the lead, are refused naming the register and the key."""
    with pytest.raises(GeometryError, match=r"register shelf: .*1 mm lead"):
        locating.check_blind_hole("shelf", 8.5, 8.0, 4.0, "datum.dowel_diameter")
    locating.check_blind_hole("shelf", 9.0, 8.0, 4.0)  # engagement + lead exactly: made
    with pytest.raises(GeometryError, match=r"register thin: .*datum.dowel_diameter"):
        # a 5 mm lower part: its floor and the lead leave 3 mm of a 4 mm pin
        locating.DowelRegister("thin", "top", "bottom", 4.0, ((0.0, 0.0), (30.0, 0.0)), (5.0, 15.0), (0.0, 5.0),
                               0.2, param="datum.dowel_diameter")


def test_the_bill_holds_every_tool_the_reaming_steps_name(rig):
    """Each gauge pin a step names (go and no-go of N7 and F7), the machine reamers, the drill press and the
    dial test indicator are lines of the bill's tools."""
    lines = [line for line, _ in (*B.TOOLS, B.dowel_drills({"parts": {}}, rig), *B.register_tools(rig))]
    text = " ".join(_steps(rig))
    named = set(re.findall(r"the (\d\.\d{3}) mm (?:go |no-go )?pin", text))
    want = {f"{v:.3f}" for cls in ("N7", "F7") for v in gauge_pins(4.0, cls)}
    assert want <= named, named  # the steps name all four pins
    for pin in named:
        assert any(f"{pin} " in line for line in lines), f"gauge pin {pin} mm named by a step, not in the bill"
    for tool in ("machine (chucking) reamer", "gauge pin", "drill press", "dial test indicator"):
        assert tool in text.lower(), tool
        assert any(tool in line.lower() for line in lines), f"{tool} named by a step, not in the bill"


def test_the_return_is_measured_not_claimed(rig):
    """No step claims a return figure unmeasured: each says to lift and re-seat five times and record the
    readings, against the figure the tolerance stack takes (half the slip fit's largest clearance)."""
    for reg, text in zip(_registers(rig), _steps(rig), strict=True):
        assert "goes back to within" not in text, reg.name
        assert f"set them back together {locating.REPEAT_TRIALS} times" in text and "record" in text, reg.name
        assert f"takes {reg.repeatability[0]:.3f} mm each way" in text, reg.name


def test_the_gauge_pins_own_tolerance_is_a_tenth_of_the_zone_they_bracket_at_most():
    """DIN 2269 class 1 pins (rigcad.standards.GAUGE_PIN_TOLERANCE_MM, a maker's catalogue figure) against
    the press and slip holes' ISO 286 zones at every dowel size rigcad's ISO 286 table holds up to DIN 2269's
    20 mm (over 1 mm): each pin's own error at most a tenth of the zone, the gauge makers' rule."""
    from rigcad.standards import (DOWEL_DIAMETERS, DOWEL_PRESS_HOLE, DOWEL_SLIP_HOLE, GAUGE_PIN_SPEC,
                                  GAUGE_PIN_TOLERANCE_MM)

    assert GAUGE_PIN_SPEC == "DIN 2269, class 1"
    for d in (d for d in DOWEL_DIAMETERS if 1.0 < d <= 20.0):
        for hole in (DOWEL_PRESS_HOLE, DOWEL_SLIP_HOLE):
            go, no_go = gauge_pins(d, hole)
            # the zone the pins bracket (0.012 mm for 4 N7): the pins' own error at most a tenth of it
            assert GAUGE_PIN_TOLERANCE_MM <= (no_go - go) / 10 + 1e-12, (d, hole, no_go - go)
