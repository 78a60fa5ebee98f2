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

    def certify(problem, row, also=None, check=True):  # the certified path without its rig: only the check passed in
        also(SimpleNamespace(index=row["index"]))
        return {"index": row["index"]}

    def gate(rig):
        if rig.index == 1:
            raise AssemblyError("beam_splitter cannot go in, it runs into splitter_holder")

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, gate)
    assert result.chosen is rows[1] and result.reason == "preferred 2"
    assert rejected == [{"index": 1, "error": "beam_splitter cannot go in, it runs into splitter_holder",
                         "stage": "assembly gate (rigcad stl, fab, manual)"}]
    assert report["certified_check"] == {"index": 2} and report["status"] == "ok"
    # every design refused: no design, and the report says so
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, lambda rig: gate(SimpleNamespace(index=1)))
    assert result.chosen is None and len(rejected) == 2 and report["status"] == "infeasible"


def test_a_design_whose_tolerance_stack_fab_refuses_gives_way_without_counting_against_the_gate(monkeypatch):
    """fab's tolerance stack refuses the first designs (FabricationError from the certified path):
    each gives way to the next and is recorded with the stage that refused it; it does not use up
    the MAX_CERTIFY designs the costly assembly gate may judge."""
    from rigcad.errors import FabricationError

    rows = [{"index": k} for k in range(R.MAX_CERTIFY + 3)]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, f"preferred {r['index']}") for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None, check=True):
        if row["index"] < R.MAX_CERTIFY + 2:  # more refusals than the gate's budget: all by the stack
            raise FabricationError("on prusa_mk3s, 1 placement(s) the printed rig cannot hold or adjust: dome lateral")
        return {"index": row["index"]}

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, None)
    assert result.chosen is rows[-1] and report["status"] == "ok"
    assert {r["stage"] for r in rejected} == {"tolerance stack (rigcad fab)"} and len(rejected) == R.MAX_CERTIFY + 2


def test_the_certified_path_refuses_a_design_whose_stack_the_printer_cannot_hold(monkeypatch):
    """optimize.run.tolerance_stack is fab's stack (rigcad.fab.stack) on the run's printer: the
    default rig is held or adjusted on the MK3S; the same rig on a process 5x less accurate in scale
    (as tests/fab refuses) is refused with fab's own FabricationError."""
    from rigcad.errors import FabricationError
    from rigcad.fab import printers, stack as ST
    from rigcad.optimize.run import load_problem

    problem = load_problem("achutha2006_optimize")
    import rigcad

    rig = rigcad.load("achutha2006")
    ok = R.tolerance_stack(problem, rig)
    assert ok["printer"] == "prusa_mk3s" and "paraboloid lateral" in ok["adjusted"]
    mk3s = printers.load_printer("prusa_mk3s")
    worse = ST.with_process(mk3s, scale=5 * mk3s.process_errors.scale)
    monkeypatch.setattr(printers, "load_printer", lambda name: worse)
    with pytest.raises(FabricationError, match="cannot hold or adjust"):
        R.tolerance_stack(problem, rig)


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
    """The certified path with the command's own gate on real rigs: the first design is the rig whose
    splitter holder cannot go in (the splitter 55 mm under the COP: tests/manual/test_gate.py), the
    second the default rig; the first gives way, naming the holder, and the default is chosen."""
    from rigcad.cli.optimize import assembly_gate
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    path = tmp_path / "blocked.yaml"
    path.write_text(table31_text.lstrip("\n") + "tower:\n  splitter_distance: 55 mm\n")
    rigs = {1: Rig.from_profile(load_profile(path)), 2: table31_rig}
    rows = [{"index": 1}, {"index": 2}]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, f"preferred {r['index']}") for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None, check=True):
        also(rigs[row["index"]])
        return {"index": row["index"]}

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason=None), {}
    rejected = R._certify_choice(None, result, report, assembly_gate)
    assert result.chosen is rows[1] and report["status"] == "ok"
    assert [r["index"] for r in rejected] == [1]
    assert "splitter_holder cannot go in" in rejected[0]["error"] and "tower.splitter_distance" in rejected[0]["error"]
