"""The schedule's assembly stages follow the assembly plan (rigcad.manual.schedule against
rigcad.manual.plan): every step of the plan is put in place by exactly one stage, the tower's stage names
its steps from the plan (so a step the plan gains is scheduled), and the stages place the steps in an
order the assembly check accepts (manual.json: its schedule against its assembly_order)."""

from __future__ import annotations

from collections import Counter
from types import SimpleNamespace

import pytest

from rigcad.manual import schedule as S
from tests.manual.test_schedule import SPLIT


@pytest.fixture(scope="module")
def plan_steps(table31_rig):
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    return plan.steps(table31_rig, picture_meshes(table31_rig))[0]


def placed(stages) -> Counter:
    return Counter(n for st in stages for n in st.places)


def test_every_step_of_the_plan_is_placed_by_one_stage(table31_rig, plan_steps):
    stages = S.schedule(table31_rig, SPLIT, plan_steps)
    names = [st.name for st in plan_steps]
    assert placed(stages) == Counter(names), (placed(stages), names)
    S.check(stages)
    tower = next(st for st in stages if st.what.startswith("Build the tower"))
    for name in S.rest(plan_steps):  # the tower's stage says each step it places
        assert name.replace("_", " ") in tower.what, name
    # planted: a hand-declared stage that forgets one of its steps leaves that step unplaced
    forgetful = [S.Stage(st.what, st.where, st.needs, st.makes, st.ends, tuple(n for n in st.places if n != "beam"))
                 for st in stages]
    assert placed(forgetful) != Counter(names)


def test_a_step_the_plan_gains_is_scheduled(table31_rig, plan_steps):
    more = [*plan_steps, SimpleNamespace(name="tower_brace")]
    stages = S.schedule(table31_rig, SPLIT, more)
    assert placed(stages) == Counter(st.name for st in more)
    assert any("tower brace" in st.what for st in stages)


def stage_order_misfits(schedule: list[dict], order: list[str]) -> list[tuple[str, str]]:
    """Pairs (earlier stage's step, later stage's step) that the assembly order has the other way round."""
    pos = {name: k for k, name in enumerate(order)}
    out = []
    for i, a in enumerate(schedule):
        for b in schedule[i + 1:]:
            out += [(x, y) for x in a.get("places", ()) for y in b.get("places", ()) if pos[x] > pos[y]]
    return out


def test_the_misfit_finder_finds_a_swap():
    sched = [{"places": ["a"]}, {"places": ["b", "c"]}]
    assert stage_order_misfits(sched, ["a", "b", "c"]) == []
    assert stage_order_misfits(sched, ["b", "a", "c"]) == [("a", "b")]


@pytest.mark.e2e
def test_the_manuals_schedule_places_the_steps_in_the_order_the_check_found(tmp_path_factory, table31_rig):
    import json

    from rigcad.fab.printers import load_printer
    from rigcad.manual import document as D

    fab = table31_rig.fab("prusa_mk3s", tmp_path_factory.mktemp("fab") / "fab", parts=["base_plate"]).report
    out = tmp_path_factory.mktemp("manual") / "prusa_mk3s"
    D.write_manual(table31_rig, load_printer("prusa_mk3s"), fab, out)
    doc = json.loads((out / "manual.json").read_text(encoding="utf-8"))
    order = [s["step"] for s in doc["assembly_order"]]
    assert sorted(n for st in doc["schedule"] for n in st["places"]) == sorted(order)
    assert stage_order_misfits(doc["schedule"], order) == []
