"""The later stages' rules as constraints of the search (rigcad.optimize.problem.later_stages): a
design the closed-form constraints pass but the rig's layout refuses, or whose tolerance stack
`rigcad fab` refuses on the run's printer, is infeasible in the search itself, not only on the
certified path after it; the Table 3.1 design meets both."""

from __future__ import annotations

import pytest

from rigcad.errors import FabricationError
from rigcad.optimize import run as R
from rigcad.optimize.problem import evaluate
from rigcad.optimize.run import load_problem

#: Design 193 of `rigcad optimize achutha2006_optimize` (seed 2006) before the search knew the stack:
#: its dome (264.6 mm tall) takes a band cut on the MK3S, which the paraboloid's and the dome's
#: lateral stacks cannot absorb (the certified path refused it: fab.stack, 1.6 mm against 1.5 mm of
#: shim range, 1.17 mm against the register's 0.9 mm). x: cop_to_vertex, sample_to_rim, vertical_extent (mm), tau (rad).
TALL = [245.87767736648306, 171.87108937095448, 34.555419617943556, 0.24879069279850596]


@pytest.fixture(scope="module")
def problem():
    return load_problem("achutha2006_optimize")


def _closed_form_met(row) -> bool:
    return all(v <= 0 for k, v in row["constraints"].items() if not k.startswith("later."))


def test_table31_meets_the_later_stages(problem):
    row = evaluate(problem, problem.base_x)
    assert row["constraints"]["later.layout_and_parts"] == 0 and row["constraints"]["later.tolerance_stack"] == 0
    assert row["feasible"]


def test_a_design_whose_stack_fab_refuses_is_infeasible_in_the_search(problem):
    row = evaluate(problem, TALL)
    assert _closed_form_met(row)  # what the search judged before: feasible
    assert row["constraints"]["later.tolerance_stack"] >= 1 and not row["feasible"]
    # the certified path's exact stack (converged dome, the same code as fab) refuses it too
    rig, _ = R.certified_rig(problem, {"x": TALL})
    import dataclasses

    from rigcad.rig import Rig

    f = R.custom_focal_length(rig.profile, rig.geometry)
    if f is not None:
        rig = Rig.from_profile(dataclasses.replace(rig.profile, lens=dataclasses.replace(rig.profile.lens, focal_length=f)),
                               previous=rig)
    with pytest.raises(FabricationError, match="cannot hold or adjust"):
        R.tolerance_stack(problem, rig)


#: Design 257 of the search before it knew the calibration's screen (beat Table 3.1 by 47 %, passed the
#: stack, the gate, check and fab): `rigcad manual` refused it, the default tablet's corners 105.6 mm
#: from the axis where the dome's inside is 85.5 mm.
NARROW = [200.0, 170.495664293, 23.0637979711, 0.23057]


def test_a_design_whose_dome_cannot_hold_the_calibration_screen_is_infeasible_in_the_search(problem):
    row = evaluate(problem, NARROW)
    assert _closed_form_met(row) and row["constraints"]["later.tolerance_stack"] == 0
    # mm: the manual's refusal said 105.6 - 85.5; the closed-form dome agrees with the certified one to nm
    assert row["constraints"]["later.calibration_screen"] == pytest.approx(105.6 - 85.5, abs=0.1)
    assert not row["feasible"]
    assert evaluate(problem, problem.base_x)["constraints"]["later.calibration_screen"] < 0  # Table 3.1's holds it


def test_a_design_whose_layout_refuses_is_infeasible_in_the_search(write_profile):
    """A splitter 20 mm from the COP: the tower's layout refuses it (tests/manual/test_gate.py), which
    no closed-form constraint models."""
    path = write_profile("short", "tower:\n  splitter_distance: 20 mm\n" + OPTIMIZE)
    problem = load_problem(path)
    row = evaluate(problem, problem.base_x)
    assert _closed_form_met(row)
    assert row["constraints"]["later.layout_and_parts"] == 1 and not row["feasible"]
    off = evaluate(load_problem(write_profile("short_off", "tower:\n  splitter_distance: 20 mm\n"
                                              + OPTIMIZE.replace("raycheck: false", "raycheck: false\n    later_stages: false"))),
                   problem.base_x)
    assert "later.layout_and_parts" not in off["constraints"] and off["feasible"]  # the option turns them off


OPTIMIZE = """
optimize:
  parameters:
    paraboloid.tangent_angle: [15 deg, 25 deg]
  objectives:
    theta_min: minimize
  constraints:
    raycheck: false
  evaluations: 20
"""


def test_a_design_whose_theta_range_misses_the_targets_is_infeasible_in_the_search(write_profile):
    """The design's own theta range against targets.theta_min/theta_max themselves (what `rigcad check`,
    stl, fab and manual refuse on: rigcad.check.criteria), not within the traced rays' coverage
    tolerance: Table 3.1 starts at 6.92 deg, so a 6.5 deg target is missed by 0.42 deg, which the
    1.5 deg coverage tolerance alone would let through."""
    text = OPTIMIZE.replace("raycheck: false", "raycheck: true")
    row = evaluate(load_problem(write_profile("low", "targets:\n  theta_min: 6.5 deg\n" + text)),
                   load_problem(write_profile("base", text)).base_x)
    assert row["constraints"]["targets.theta_min"] == pytest.approx(6.9175 - 6.5, abs=1e-3)
    assert row["constraints"]["raycheck.theta_min_coverage"] < 0  # the coverage tolerance alone: feasible
    assert not row["feasible"]
    met = evaluate(load_problem(write_profile("met", text)), load_problem(write_profile("met2", text)).base_x)
    assert met["constraints"]["targets.theta_min"] < 0 and met["constraints"]["targets.theta_max"] <= 0
