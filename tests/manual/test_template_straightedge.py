"""The straightedge a template's datum is read against is in the bill at the length its step names
(rigcad.manual.finishing.straightedge, one home): the default dome's 300 mm, the lapping straightedge's
length, shares it; a wider dome's step and bill both name the next length sold."""

from __future__ import annotations

import re

from rigcad.manual import bom as B
from rigcad.manual import finishing as F


def _corner(rig):
    return max((r for r in F.template_datums(rig) if r["datum"] == "corner"), key=lambda r: r["datum_r_mm"])


def test_the_default_domes_straightedge_is_the_lapping_one(table31_rig):
    row = _corner(table31_rig)
    rule, reach = F.straightedge(row)
    assert reach == 2 * row["datum_r_mm"] + 2 * F.STRAIGHTEDGE_OVERHANG_MM and reach <= 300.0 == rule
    assert f"a {rule:g} mm steel straightedge" in F.template_text(row)
    item, qty = B.template_straightedge(table31_rig)
    assert qty == "(same)" and f"({B.LAPPING_STRAIGHTEDGE_MM:g} mm, above)" in item and "`dome_template`" in item
    assert any(f"steel straightedge {B.LAPPING_STRAIGHTEDGE_MM:g} mm" in t for t, _ in B.TOOLS)


def test_a_wider_domes_step_and_bill_name_the_same_longer_straightedge(table31_rig, monkeypatch):
    row = _corner(table31_rig)
    wide = {**row, "datum_r_mm": 200.0}  # 420 mm across its base with the overhangs: the 500 mm rule
    monkeypatch.setattr(F, "template_datums", lambda rig: [wide])
    step = re.search(r"a (\d+) mm steel straightedge", F.template_text(wide)).group(1)
    item, qty = B.template_straightedge(table31_rig)
    assert step == "500" and item.startswith("Steel straightedge 500 mm") and qty == "1"
    huge = {**row, "datum_r_mm": 600.0}  # past every length sold
    monkeypatch.setattr(F, "template_datums", lambda rig: [huge])
    assert "at least 1220 mm long" in B.template_straightedge(table31_rig)[0]
