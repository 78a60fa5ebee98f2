"""The optimiser says which placements its tolerance-stack constraint counts, and its report never
pairs "infeasible" with the search's reason for a chosen design."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from rigcad.errors import AssemblyError
from rigcad.optimize import run as R
from rigcad.optimize import search
from rigcad.optimize.problem import evaluate, stack_refusals
from rigcad.optimize.run import load_problem
from tests.optimize.test_later_stages import TALL


@pytest.fixture(scope="module")
def problem():
    return load_problem("achutha2006_optimize")


def test_the_stack_constraint_names_the_placements_it_counts(problem):
    row = evaluate(problem, TALL)
    count = row["constraints"]["later.tolerance_stack"]
    refused = stack_refusals(problem, TALL)
    assert count >= 1 and len(refused) == count  # the names are the ones counted
    assert all("(tolerancing." in r for r in refused)
    assert any(r.startswith("dome lateral") or r.startswith("paraboloid lateral") for r in refused)
    assert stack_refusals(problem, problem.base_x) == []  # Table 3.1 holds: nothing to name
    msg = search.infeasible_message(problem, [{**row, "index": 0}])
    assert "later.tolerance_stack" in msg and refused[0] in msg


def test_every_design_refused_leaves_no_reason_of_a_chosen_one(monkeypatch):
    rows = [{"index": 1}, {"index": 2}]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, "lowest merit of the feasible designs")
                                                                   for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None, check=True):
        raise AssemblyError("beam_splitter cannot go in")

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason="lowest merit of the feasible designs"), {}
    R._certify_choice(None, result, report, None)
    assert report["status"] == "infeasible" and result.chosen is None
    assert report["reason"] == "none of the 2 designs tried passed the later stages"


def test_a_loop_stopped_by_the_gates_budget_chooses_nothing_it_did_not_certify(monkeypatch):
    """Past MAX_CERTIFY assembly refusals the loop stops: the search's choice, never certified, is not kept."""
    rows = [{"index": k} for k in range(R.MAX_CERTIFY + 2)]
    monkeypatch.setattr(R, "preference", lambda problem, result: [(r, "preferred") for r in rows])
    monkeypatch.setattr(R, "_row_json", lambda problem, r: r)

    def certify(problem, row, also=None, check=True):
        if row["index"] < R.MAX_CERTIFY:
            raise AssemblyError("beam_splitter cannot go in")
        return {"index": row["index"]}

    monkeypatch.setattr(R, "certify", certify)
    result, report = SimpleNamespace(chosen=rows[0], reason="preferred"), {}
    R._certify_choice(None, result, report, None)
    assert result.chosen is None and report["status"] == "infeasible"
    assert "passed the later stages" in report["reason"]
