"""Section 5's steps, the schedule and the step pictures tell one story about the dome: a step the schedule
does with the dome off its register (upside down on the bench, its open base up) says so and is drawn so;
the dome's own step, whose schedule stage leaves it off again, says to lift it off and puts its bolts off
until it goes back; the last step done with it off says how it goes back. The checker reads manual.md
against manual.json's schedule (rigcad.manual.schedule.placing_states), so a step text that has the dome
where the schedule does not fails it."""

from __future__ import annotations

import json
import re

import pytest

from rigcad.manual import document as D
from rigcad.manual import schedule as S
from tests.manual.test_schedule import SPLIT

#: What a step done with the dome off says, and what it must never say then (the dome still on the plate).
OFF_WORDS = "is off its register pins, upside down on the bench"
ON_WORDS = ("until it rests on the dome", "The dome is on its register pins now")
OFF_CAPTION = "the dome lifted off and upside down"


def step_sections(md: str) -> dict[int, str]:
    """Section 5's steps by number: each one's text and caption (up to the next heading)."""
    body = md.split("## 5. Assemble", 1)[1].split("\n## ", 1)[0]
    return {int(m.group(1)): m.group(2) for m in re.finditer(r"### Step (\d+): [^\n]*\n(.*?)(?=\n### |\Z)", body, re.S)}


def dome_contradictions(md: str, doc: dict) -> list[str]:
    """Where a step's words or picture disagree with the schedule (manual.json's ``schedule``) about the dome."""
    names = [s["step"] for s in doc["assembly_order"]]
    states = S.placing_states(doc["schedule"])
    texts = step_sections(md)
    dome = D.dome_steps(doc["schedule"], names)
    out = []
    if D.DOME not in names:
        return out
    after_dome = names[names.index(D.DOME) + 1:]
    for k, name in enumerate(names, 1):
        text = texts.get(k, "")
        if name not in states:
            continue
        _, before, left = states[name]
        off = name in after_dome and S.DOME_OFF in before
        if off and (OFF_WORDS not in text or OFF_CAPTION not in text):
            out.append(f"step {k} ({name}): the schedule has the dome off, the step or its picture does not")
        if off and any(w in text for w in ON_WORDS):
            out.append(f"step {k} ({name}): the schedule has the dome off, the step has it on its pins")
        if not off and OFF_CAPTION in text:
            out.append(f"step {k} ({name}): drawn with the dome off, which the schedule does not have")
        if name == D.DOME and S.DOME_OFF in left:
            if "lift the dome off its pins again" not in text or re.search(r"\. Fix it with", text):
                out.append(f"step {k} (dome): its stage leaves the dome off, the step bolts it down for good")
    if dome["off"]:
        last = names.index(dome["off"][-1]) + 1
        back = doc["schedule"][dome["back"] - 1]["what"].rstrip(".")
        if back.lower() not in texts.get(last, "").lower():
            out.append(f"step {last}: the last step with the dome off does not say how it goes back ({back!r})")
    return out


@pytest.fixture(scope="module")
def plan_steps(table31_rig):
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    steps, solids = plan.steps(table31_rig, picture_meshes(table31_rig))
    return steps, [p.step.name for p in D.assembly_order(table31_rig, steps, solids)]


def test_the_schedule_has_the_beam_and_the_paraboloid_go_in_with_the_dome_off(table31_rig, plan_steps):
    steps, names = plan_steps  # names: section 5's order, the one the assembly check found
    stages = S.schedule(table31_rig, SPLIT, steps)
    dome = D.dome_steps(stages, names)
    assert dome["off"] == ["beam", "paraboloid"] and dome["leaves_off"]
    back = stages[dome["back"] - 1]
    assert S.DOME_OFF in back.ends and S.DOME_ON in back.makes
    # what the paraboloid's step closes with: the schedule's stages after it, up to the dome set back
    assert dome["between"][-1] == back.what and any("Indicate the paraboloid" in w for w in dome["between"])
    # planted: a schedule that sets the dome back before the beam has no step done with the dome off
    moved = list(stages)
    i = next(k for k, st in enumerate(moved) if "beam" in st.places)
    j = dome["back"] - 1
    moved.insert(i, moved.pop(j))
    assert D.dome_steps(moved, names)["off"] == []


@pytest.mark.e2e
def test_the_steps_and_pictures_have_the_dome_where_the_schedule_has_it(written):
    md = (written / "manual.md").read_text(encoding="utf-8")
    doc = json.loads((written / "manual.json").read_text(encoding="utf-8"))
    assert dome_contradictions(md, doc) == []
    # planted: the beam's step as it read before (slid in while the dome stands on the plate) is caught
    names = [s["step"] for s in doc["assembly_order"]]
    k = names.index("beam") + 1
    old = step_sections(md)[k]
    planted = md.replace(old, re.sub(r"The dome is off its register pins.*?\.", "Slide it in level along -x, from "
                                     "the +x side until it rests on the dome.", old, count=1, flags=re.S))
    assert planted != md
    assert any(f"step {k} (beam)" in e for e in dome_contradictions(planted, doc))
    # planted: the dome's step bolting it down for good
    d = names.index("dome") + 1
    planted = md.replace(step_sections(md)[d], step_sections(md)[d].replace("When it goes back on its pins after "
                                                                            f"step {k + 1}, fix", "Fix"))
    assert any(f"step {d} (dome)" in e for e in dome_contradictions(planted, doc))


def camera_cross_contradictions(md: str, doc: dict) -> list[str]:
    """Section 6's camera crosses against the schedule's stage for them: the stage lifts the dome off to hang
    the cross on the beam and puts the paraboloid back after; the section must say both, in that order."""
    from rigcad.manual import calibration as C

    stage = next((s for s in doc["schedule"] if s["where"] == C.STEP_CAMERA), None)
    if stage is None:
        return []
    text = md.split(f"### {C.STEP_CAMERA}", 1)[1].split("\n### ", 1)[0]
    out = []
    hang = text.find("Hang the `camera_cross_hung`")
    if "Lift the dome off" in stage["what"] and not 0 <= text.find("lift the dome off its register pins") < hang:
        out.append("the schedule lifts the dome off to hang the camera cross; the section does not say so first")
    if "put the paraboloid back" in stage["what"] and "put the paraboloid back" not in text[hang:].lower():
        out.append("the schedule puts the paraboloid back after the camera cross; the section does not")
    stages = doc["schedule"]
    slope = next((k for k, s in enumerate(stages) if s["where"] == C.STEP_ACCEPTANCE and "Slope" in s["what"]), None)
    if slope is not None and any(s["where"] == C.STEP_CAMERA for s in stages[:slope]):
        if "First before the slope test" not in text:
            out.append("the schedule aligns the camera before the slope test; its section does not say so")
        test = md.split(f"### {C.STEP_ACCEPTANCE}", 1)[1].split("\n### ", 1)[0]
        if "the camera aligned on its two crosses" not in test:
            out.append("the schedule aligns the camera before the slope test; the test does not ask for it")
    return out


@pytest.mark.e2e
def test_section_6s_camera_crosses_take_the_dome_off_as_the_schedule_does(written):
    from rigcad.manual import calibration as C

    md = (written / "manual.md").read_text(encoding="utf-8")
    doc = json.loads((written / "manual.json").read_text(encoding="utf-8"))
    assert camera_cross_contradictions(md, doc) == []
    # planted: the section as it read before (the cross hung with the dome still bolted on, the paraboloid
    # never put back) is caught
    old = md.split(f"### {C.STEP_CAMERA}", 1)[1].split("\n### ", 1)[0]
    body = "\n\nHang the `camera_cross_hung` on the beam in place of the paraboloid."
    assert len(camera_cross_contradictions(md.replace(old, body), doc)) == 3
    # planted: the slope test's camera only 'in its place on the tower', as the lab technician read it
    planted = md.replace("the camera aligned on its two crosses", "the camera in its place on the tower")
    assert planted != md and len(camera_cross_contradictions(planted, doc)) == 1

