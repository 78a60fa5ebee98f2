"""The assembly order searched once per process: the gate's verdict (found, or read back from
assembly.json) is what the manual's section 5 places, step by step with the check's own test
(rigcad.manual.gate.order: its steps and their directions), not a second search
(assembly_check.find_order, about 11 s of CPU on the default rig, 40 % of `rigcad manual`). The
order handed on is the search's, Placed for Placed, through assembly.json's JSON too; an order whose
steps or directions are not the assembly's, a rig moved from its design, or a profile the gate has
not judged is searched."""

from __future__ import annotations

import pytest

from rigcad.manual import assembly_check, gate, plan
from rigcad.manual.assembly import picture_meshes
from rigcad.rig import Rig


@pytest.fixture(scope="module")
def searched(table31_rig):
    """The default rig's meshes, its assembly searched once (its placements memoised in it: searched
    again, it answers at once) and the order the search found."""
    meshes = picture_meshes(table31_rig)
    assembly = plan.assembly(table31_rig, meshes)
    return meshes, assembly, assembly_check.find_order(assembly)


@pytest.fixture
def searches(monkeypatch) -> dict:
    calls = {"n": 0}
    real = assembly_check.find_order

    def counted(assembly):
        calls["n"] += 1
        return real(assembly)

    monkeypatch.setattr(assembly_check, "find_order", counted)
    monkeypatch.setattr(gate, "_ORDERS", {})  # this process has judged nothing yet
    return calls


def test_the_gates_order_is_placed_without_a_second_search(table31_rig, searched, searches, tmp_path, monkeypatch):
    from rigcad.manual import document

    meshes, _, found = searched
    monkeypatch.setattr(gate, "_order", lambda rig, meshes: found)  # the gate's search, done once (the fixture)
    v = gate.checked(table31_rig, tmp_path)  # the gate, as `rigcad manual` calls it first
    assert v.ok and v.order == tuple(p.step.name for p in found)
    steps, solids = plan.steps(table31_rig, meshes)  # a fresh assembly, as the manual's section 5 makes it
    placed = document.assembly_order(table31_rig, steps, solids)
    assert searches["n"] == 0  # no second search
    assert placed == found  # the search's own steps and directions, to the bits
    gate._ORDERS.clear()  # another process: the verdict read back from assembly.json (through JSON)
    monkeypatch.setattr(gate, "_order", None)  # not searched again
    assert gate.checked(table31_rig, tmp_path).order == v.order
    assert gate.order(table31_rig, plan.assembly(table31_rig, meshes)) == found and searches["n"] == 0


def _verdict(rig, found, names=None, directions=None) -> gate.Verdict:
    return gate.Verdict(rig.name, order=tuple(p.step.name for p in found) if names is None else tuple(names),
                        directions=tuple(p.direction for p in found) if directions is None else tuple(directions))


def test_an_order_that_is_not_the_assemblys_is_searched(table31_rig, searched, searches):
    _, assembly, found = searched
    gate._remember(table31_rig, _verdict(table31_rig, found[:-1]))  # a step short
    assert gate.order(table31_rig, assembly) == found and searches["n"] == 1
    odd = [p.direction for p in found]
    k = next(i for i, p in enumerate(found) if p.direction != (0.0, 0.0, 1.0))
    odd[k] = (0.0, 0.0, 1.0) if (0.0, 0.0, 1.0) not in [tuple(map(float, d)) for d in found[k].step.directions] \
        else (0.6, 0.0, 0.8)  # a direction the step does not declare
    gate._remember(table31_rig, _verdict(table31_rig, found, directions=odd))
    assert gate.order(table31_rig, assembly) == found and searches["n"] == 2
    gate._remember(table31_rig, _verdict(table31_rig, found))
    assert gate.order(table31_rig, assembly) == found and searches["n"] == 2  # the verdict itself: handed on


def test_a_moved_rig_or_another_profile_is_searched(table31_rig, searched, searches, write_profile):
    from rigcad.profile import load_profile

    _, assembly, found = searched
    gate._remember(table31_rig, _verdict(table31_rig, found))
    assert gate.order(table31_rig, assembly) == found and searches["n"] == 0  # judged: handed on
    gate.order(table31_rig.moved("camera", offset=(0.0, 0.0, 0.01)), assembly)
    assert searches["n"] == 1
    other = Rig.from_profile(load_profile(write_profile("extends: achutha2006\nraycheck:\n  min_px_per_deg: 0.7\n")))
    gate.order(other, assembly)  # judged by no gate in this process
    assert searches["n"] == 2
