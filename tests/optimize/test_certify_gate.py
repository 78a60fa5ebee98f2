"""The optimiser's certified path takes a further check (``certify_also``; the command's
rigcad.cli.optimize.assembly_gate is meant for it: the gate lives on a floor rigcad.optimize cannot
import): a design the check refuses gives way to the next in preference, and the report names the
refusal. The command does not pass the gate yet (its order search backtracks for minutes on a
refused design)."""

from __future__ import annotations

from types import SimpleNamespace

from rigcad.errors import AssemblyError
from rigcad.optimize import run as R


def test_a_design_the_gate_refuses_gives_way_to_the_next(monkeypatch):
    rows = [{"index": 1}, {"index": 2}]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, f"preferred {r['index']}") for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None):  # the certified path without its rig: only the check passed in
        also(SimpleNamespace(index=row["index"]))
        return {"index": row["index"]}

    def gate(rig):
        if rig.index == 1:
            raise AssemblyError("beam_splitter cannot go in, it runs into splitter_holder")

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, gate)
    assert result.chosen is rows[1] and result.reason == "preferred 2"
    assert rejected == [{"index": 1, "error": "beam_splitter cannot go in, it runs into splitter_holder"}]
    assert report["certified_check"] == {"index": 2} and report["status"] == "ok"
    # every design refused: no design, and the report says so
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, lambda rig: gate(SimpleNamespace(index=1)))
    assert result.chosen is None and len(rejected) == 2 and report["status"] == "infeasible"
