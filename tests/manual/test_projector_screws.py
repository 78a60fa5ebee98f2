"""The projector's screws in the manual: the step's screws and the hardware list follow the length
each shim stack needs (rigcad.parts.tower.projector_screws), one hardware row per length."""

from __future__ import annotations

from rigcad.manual import plan
from rigcad.manual.assembly import picture_meshes
from rigcad.parts.tower import projector_screws


def test_projector_screws_per_stack(table31_rig):
    rig = table31_rig
    per_stack = {r["shims"]: r["length_mm"] for r in projector_screws(rig.profile, rig.layout)}
    steps, _ = plan.steps(rig, picture_meshes(rig))
    step = next(s for s in steps if s.name == "projector_body")
    # the screws the check fits are those of the stacks as drawn (shims_nominal shims each)
    assert {f.length_mm for f in step.fasteners} == {per_stack[rig.layout.tower.shims_nominal]}
    rows = plan.projector_screw_rows(rig)
    # one row per length; together they serve every stack 0..shims_per_stack once
    assert sorted(r["length_mm"] for r in rows) == sorted(set(per_stack.values()))
    assert sorted(n for r in rows for n in r["stacks"]) == list(range(rig.layout.tower.shims_per_stack + 1))
    for r in rows:
        assert all(per_stack[n] == r["length_mm"] for n in r["stacks"])
    hw = {r["item"]: r for r in plan.hardware(steps, rig)}
    for r in rows:
        assert hw[r["item"]]["quantity"] == r["quantity"]
        assert f"{r['stacks'][0]}" in hw[r["item"]]["steps"]
    text = plan.projector_screw_text(rig)
    for r in rows:
        assert r["item"].split(" socket")[0] in text
    assert per_stack[0] != per_stack[rig.layout.tower.shims_per_stack]  # the default needs several lengths
