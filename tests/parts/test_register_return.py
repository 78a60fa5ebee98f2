"""A locating register's return is read with an indicator that resolves the figure the tolerance stack takes
(half the slip fit's largest clearance, ISO 286: 0.009 mm for the dome's 4 mm pins), and its reamed blind holes are
gauged to the pin's engagement, not to the floor the reamer's lead leaves under size."""

from __future__ import annotations

import re

import pytest

from rigcad.errors import GeometryError
from rigcad.manual import bom as B
from rigcad.parts import locating
from rigcad.standards import REAMER_LEAD_MM


@pytest.fixture(scope="module")
def register(table31_rig):
    (reg,) = [j for p in table31_rig.recipes.values() for j in p.joints if isinstance(j, locating.DowelRegister)]
    return reg


def test_the_return_is_read_to_the_stacks_figure_with_an_indicator_that_resolves_it(register):
    lateral, _ = register.repeatability
    # ISO 286 F7 hole over an m6 pin of 4 mm: largest clearance 0.022 - 0.004 = 0.018 mm; half of it
    assert lateral == pytest.approx(0.009, abs=1e-9)
    text = register.repeat_step()
    graduation = float(re.search(r"indicator \(([\d.]+) mm graduation\)", text).group(1))
    assert graduation == locating.REPEAT_INDICATOR_MM and graduation <= lateral / 2
    assert f"within {lateral:.3f} mm of zero" in text and "graduation of zero" not in text


def test_the_bill_lists_the_indicator_that_reads_the_return(table31_rig):
    rows = [item for item, _ in B.register_tools(table31_rig)]
    assert any(f"{locating.REPEAT_INDICATOR_MM:g} mm graduation" in r for r in rows), rows


def test_an_indicator_too_coarse_for_the_return_is_refused_naming_the_pin_key(register, monkeypatch):
    monkeypatch.setattr(locating, "REPEAT_INDICATOR_MM", 0.005)  # 0.009 mm is under two of its graduations
    with pytest.raises(GeometryError, match=r"datum\.dowel_diameter"):
        register.repeat_step()


def test_the_go_pin_is_pushed_to_the_pins_engagement_not_the_floor(register):
    text = register.gauge_step()
    assert "to the floor" not in text
    assert f"enters {register.lower_engagement:g} mm deep" in text
    assert register.lower_depth >= register.lower_engagement + REAMER_LEAD_MM - 1e-9
