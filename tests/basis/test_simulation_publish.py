"""A simulation published on its own (rigcad.api.write_simulation) is refused beside a basis of
another order: the folder would mix two runs (`rigcad basis --simulate` publishes both together)."""

from __future__ import annotations

import json

import pytest

from rigcad.basis.acquire import RigSimulation, write_simulation
from rigcad.errors import BasisError


@pytest.mark.parametrize("text, words", [
    (json.dumps({"order": 4, "files": []}), "a basis of order 4; a simulation of order 2 beside it would mix two runs"),
    ('{"order": 2, "order": 2}', "not a readable JSON file (the key 'order' twice"),
    ("[" * 10_000 + "]" * 10_000, "nested 10000 levels deep"),
])
def test_a_simulation_beside_another_run_is_refused_and_nothing_changes(tmp_path, text, words):
    out = tmp_path / "basis"
    out.mkdir()
    (out / "basis.json").write_text(text)
    sim = RigSimulation({"order": 2}, [])
    with pytest.raises(BasisError) as info:
        write_simulation(sim, out)
    assert words in str(info.value) and "\n" not in str(info.value), str(info.value)
    assert sorted(p.name for p in out.iterdir()) == ["basis.json"]
