"""The templates' material, cut and check (rigcad.manual.finishing.template_making): the edge tolerance is a
quarter of the smallest gap the template must show, the gaps are the recipe's own, and the check named (an
optical comparator's stage) is accurate enough over each shipped template's size, or the text says how to
split the check."""

from __future__ import annotations

import re

import pytest

import rigcad
from rigcad.manual import finishing as F

MIL = 0.0254  # mm


@pytest.fixture(scope="module")
def rig():
    return rigcad.load("achutha2006")


def test_the_gaps_are_the_recipes_and_the_edge_holds_a_quarter_of_the_smallest(rig):
    gaps = F.template_gaps(rig.profile)
    # the recipe's checks read the same gaps: "gap 0.114 mm", ..., "flush"
    said = [float(m) for r in F.recipe(rig.profile) for m in re.findall(r"gap (\d+\.\d+) mm", r[4])]
    assert said == pytest.approx([round(g, 3) for g in gaps if g > 1e-9], abs=5e-4), (said, gaps)
    assert gaps[-1] == 0.0  # the gauged layer: flush
    rows = F.template_making(rig.profile, F.template_datums(rig))
    assert {r["template"] for r in rows} == {"dome_template", "paraboloid_template"}
    for r in rows:
        # the thinnest coat (1.5 mil) is the smallest gap; a quarter of it, so an edge error cannot flip a reading
        assert r["smallest_gap_mm"] == pytest.approx(1.5 * MIL) and r["edge_tolerance_mm"] == pytest.approx(1.5 * MIL / 4)
        # the comparator's (3 + L/50) um over the template's larger size, L at most ~230 mm: under the tolerance
        assert r["comparator_accuracy_mm"] <= r["edge_tolerance_mm"] and r["checkable"], r
        # the cut alone (0.1 mm) could not show the smallest gap: the edge is finished after cutting
        assert r["cut_edge_mm"] > r["smallest_gap_mm"]


def test_a_template_too_large_for_the_comparator_is_checked_in_sections(rig):
    row = dict(F.template_datums(rig)[0], width_mm=600.0, height_mm=100.0)
    big = F.template_making(rig.profile, [row])[0]
    assert big["comparator_accuracy_mm"] > big["edge_tolerance_mm"] and not big["checkable"]
    text = F.template_making_text([big])
    travel = (big["edge_tolerance_mm"] * 1e3 - F.COMPARATOR_UM[0]) / F.COMPARATOR_UM[1]
    assert f"sections of at most {travel:.0f} mm" in text, text
    shipped = F.template_making_text(F.template_making(rig.profile, F.template_datums(rig)))
    assert "sections of" not in shipped and "stainless" in shipped and "0.0095 mm" in shipped, shipped


def test_a_tolerance_under_the_comparators_own_figure_is_said_to_be_uncheckable_not_given_a_negative_section():
    """A template's edge tolerance under the comparator's constant term (3 um) leaves no section short enough:
    the paragraph says so and names a way out, instead of 'sections of at most -N mm'; a tolerance over it gets
    the section length (tolerance - 3 um) x 50; the stated accuracy formula is the constant's."""
    from rigcad.manual import finishing as F

    base = {"template": "t", "material": F.TEMPLATE_MATERIAL, "thickness_mm": 1.0, "cut_edge_mm": F.CUT_EDGE_MM,
            "gaps_mm": [0.002], "smallest_gap_mm": 0.002, "span_mm": 300.0}
    tight = {**base, "edge_tolerance_mm": 0.0025, "comparator_accuracy_mm": 0.009, "checkable": False}
    text = F.template_making_text([tight])
    assert "sections of at most" not in text and "no comparator of this class can check it" in text
    assert "`coating.layers`" in text
    loose = {**base, "edge_tolerance_mm": 0.005, "comparator_accuracy_mm": 0.009, "checkable": False}
    assert "sections of at most 100 mm" in F.template_making_text([loose])  # (5 - 3) um x 50
    a, b = F.COMPARATOR_UM
    assert f"({a:g} + L/{1 / b:g}) um over L" in text
