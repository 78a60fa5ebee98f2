"""Section 5's step texts against the orders a lab can work in (rigcad.manual.document): a part the
found order puts inside a part already on its register pins (the paraboloid inside the bolted dome) is
put in with that part lifted off, not lowered through it; seat parts bonded to cure under a part of a
later step (the splitter seat under its holder) have that part prepared before the bonding."""

from __future__ import annotations

import pytest

from rigcad.manual import document as D
from rigcad.manual import plan
from rigcad.manual.assembly import picture_meshes


@pytest.fixture(scope="module")
def found(table31_rig):
    meshes = picture_meshes(table31_rig)
    steps, solids = plan.steps(table31_rig, meshes)
    order = D.assembly_order(table31_rig, steps, solids)
    by_name = {m.name: m for m in meshes}
    return order, by_name, D.preparations(table31_rig, order, by_name)


def test_the_paraboloid_goes_in_with_the_dome_lifted_off(found, table31_rig):
    order, by_name, _ = found
    names = [p.step.name for p in order]
    k = names.index("paraboloid")
    assert names.index("dome") < k, "the found order this text answers: the dome on its pins before the paraboloid"
    lifted = {p.step.name: D.lifted_encloser(p.step, names[:j], by_name, table31_rig) for j, p in enumerate(order)}
    assert lifted["paraboloid"] == "dome"
    # only a part the dome closes round is put in that way (the beam slides through its wall slots)
    assert {n for n, v in lifted.items() if v} == {"paraboloid"}
    text = D.step_text(order[k], by_name, None, None, "", lifted["paraboloid"])
    assert "lift it straight off its pins" in text and "open base" in text
    assert "from above" not in text, text


def test_the_splitter_holder_is_prepared_before_its_seat_is_bonded(found):
    order, _, prep = found
    number = {p.step.name: k + 1 for k, p in enumerate(order)}
    bonded, holder = D.cure_on_seat(order, prep)
    assert holder == "splitter_holder"
    assert set(bonded) == {"seat_cone_ball", "seat_flat_pad", "seat_vee_pin"}
    assert max(number[b] for b in bonded) < number[holder], "the bonds come before the holder's own step"
    first = D.cure_text((bonded, holder), bonded[0], number)
    assert f"before any bonding: do now what step {number[holder]} says" in first
    assert "inserts" in first and "push screws" in first
    for b in bonded[1:]:
        assert "prepared splitter holder" in D.cure_text((bonded, holder), b, number)
    assert f"Prepared before step {number[bonded[0]]}" in D.cure_text((bonded, holder), holder, number)
