"""The optimiser's certified path takes a further check (``certify_also``; the command passes
rigcad.cli.optimize.assembly_gate: the gate lives on a floor rigcad.optimize cannot import): a
design the check refuses gives way to the next in preference, and the report names the refusal."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

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


def test_the_command_passes_the_assembly_gate_to_the_certified_path(monkeypatch, tmp_path):
    """`rigcad optimize` hands rigcad.cli.optimize.assembly_gate to run_optimize as certify_also."""
    from rigcad.cli import main
    from rigcad.cli import optimize as cli

    seen = {}

    class Stop(Exception):
        pass

    def fake_run(*args, certify_also=None, **kwargs):
        seen["also"] = certify_also
        raise Stop()

    monkeypatch.setattr(R, "run_optimize", fake_run)
    try:
        main(["optimize", "achutha2006_optimize", "--exports", str(tmp_path), "--workers", "1"])
    except Stop:
        pass
    assert seen["also"] is cli.assembly_gate


@pytest.mark.e2e  # the gate on two whole rigs: ~30 s
def test_the_real_gate_refuses_a_rig_that_cannot_go_together_and_the_next_design_is_taken(
        monkeypatch, tmp_path, table31_text, table31_rig):
    """The certified path with the command's own gate on real rigs: the first design is the low-pupil
    rig whose splitter cannot go in (tests/manual/test_gate.py), the second the default rig; the first
    gives way, naming the splitter, and the default is chosen."""
    from rigcad.cli.optimize import assembly_gate
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    path = tmp_path / "low.yaml"
    path.write_text(table31_text.lstrip("\n") + "projector:\n  pupil_height: 25 mm\n  lens_diameter: 25 mm\n")
    rigs = {1: Rig.from_profile(load_profile(path)), 2: table31_rig}
    rows = [{"index": 1}, {"index": 2}]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, f"preferred {r['index']}") for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None):
        also(rigs[row["index"]])
        return {"index": row["index"]}

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, assembly_gate)
    assert result.chosen is rows[1] and report["status"] == "ok"
    assert [r["index"] for r in rejected] == [1]
    assert "beam_splitter cannot go in" in rejected[0]["error"] and "projector.pupil_height" in rejected[0]["error"]
