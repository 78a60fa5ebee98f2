"""The tower joints' compression limiters are fitted in the step whose bolts go through them: the plan places
those bolts itself ("Fix it with ..." from the assembly), so the sleeves' shop step (part off, face to the
measured span less the squeeze, drop in before the bolt) is added to that step, once, and to no other."""

from __future__ import annotations

from types import SimpleNamespace

from rigcad.manual import bom as B
from rigcad.manual import document as D
from rigcad.manual import tower_joints


def test_each_limited_tower_joints_step_fits_its_sleeves(table31_rig):
    names = ["sample_holder", "base_plate", "dome", "tower_column", "tower_shelf", "lens_mount"]
    tower_at = D._tower_rows_by_step(table31_rig, [SimpleNamespace(name=n) for n in names])
    c = SimpleNamespace(rig=table31_rig, p=table31_rig.profile)
    texts = {n: D._step_extras(c, n, tower_at) for n in names}
    rows = [h for h in B.tower_hardware(table31_rig) if tower_joints.placed(h) and h.get("shop_steps")]
    assert {h["steps"][-1] for h in rows} == {"tower_column", "tower_shelf"}  # the column's foot and top
    for h in rows:
        (step,) = [n for n in h["steps"] if n in names]
        for shop in h["shop_steps"]:
            assert "compression limiters" in shop and "less 0.02 mm" in shop
            assert texts[step].count(shop) == 1, (step, texts[step])
            assert all(shop not in t for n, t in texts.items() if n != step)
