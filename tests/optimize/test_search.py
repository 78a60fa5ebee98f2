"""The search: a planted optimum known in closed form, bit-for-bit determinism across worker
counts, and the message of an infeasible request."""

from __future__ import annotations

import math

import pytest

from rigcad.engine import Engine
from rigcad.optimize.run import load_problem
from rigcad.optimize.search import optimize

PLANTED = """
optimize:
  parameters:
    paraboloid.tangent_angle: [10 deg, 30 deg]
  objectives:
    theta_min: {target: 5 deg}
  constraints:
    raycheck: false
    later_stages: false   # the search's accuracy against a closed form, on the closed-form constraints alone
  evaluations: 120
"""


def test_planted_optimum_tangent_angle_for_a_given_occlusion_limit(write_profile):
    """theta_min = atan(rim radius / d_o), rim radius = 2 d_p tan(tau) (profile.derived): the tangent
    angle that puts the occlusion limit at 5 deg is atan(d_o tan(5 deg) / (2 d_p))."""
    pb = load_problem(write_profile("planted", PLANTED))
    result = optimize(pb)
    d_o, d_p = pb.base.layout.sample_to_rim, pb.base.paraboloid.vertical_extent
    truth = math.atan(d_o * math.tan(math.radians(5.0)) / (2 * d_p))
    (tau,) = result.chosen["x"]
    assert abs(tau - truth) / truth < 0.01, (math.degrees(tau), math.degrees(truth))  # the 1 %
    assert len(result.history) <= 120


TWO = """
optimize:
  parameters:
    layout.cop_to_vertex: [20 cm, 45 cm]
    layout.sample_to_rim: [10 cm, 20 cm]
    paraboloid.tangent_angle: [12 deg, 30 deg]
  objectives:
    theta_min: minimize
    px_per_deg_cv: minimize
  constraints:
    printer: prusa_mk3s
    max_pieces: 4
  evaluations: 40
  seed: 7
"""


@pytest.mark.parametrize("objectives", ["two", "one"])
def test_same_seed_same_result_bit_for_bit_with_one_and_two_workers(write_profile, objectives):
    text = TWO if objectives == "two" else TWO.replace("    px_per_deg_cv: minimize\n", "")
    pb = load_problem(write_profile("det", text))
    runs = [optimize(pb, Engine(workers=w)) for w in (1, 2, 1)]
    a, b, c = ([(r["x"], r["objectives"], r["constraints"]) for r in run.history] for run in runs)
    assert a == b == c  # floats compared exactly: the same points, the same numbers
    assert runs[0].chosen["x"] == runs[1].chosen["x"]


def test_a_ceiling_below_any_working_cop_names_the_constraint_and_its_best_value(write_profile, tmp_path, capsys):
    from rigcad.cli import main

    # the COP stands at least d_o + d_p + d_cp = 100 + 22.5 + 200 mm above the sample plane
    text = TWO.replace("    max_pieces: 4\n", "    max_pieces: 4\n    max_cop_height: 25 cm\n")
    path = write_profile("ceiling", text)
    code = main(["optimize", str(path), "--exports", str(tmp_path / "exports")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1 and err[0].startswith("rigcad: error: ceiling: no design meets the constraints")
    assert "max_cop_height (optimize.constraints.max_cop_height" in err[0]
    # the best value reached: the lowest COP the bounds allow is 100 + 22.5 + 200 = 322.5 mm, 72.5 mm over
    best = float(err[0].split("best value reached ")[1].split(" mm")[0])
    assert 72.5 <= best < 72.5 + 10.0, err[0]  # the search gets near the lower corner of the bounds
    assert (tmp_path / "exports" / "ceiling" / "optimize" / "optimize.json").exists()  # every evaluation kept


def test_design_profile_of_a_profile_off_the_search_path_is_written_where_it_resolves(write_profile, tmp_path):
    from rigcad.cli import main
    from rigcad.profile import load_profile

    text = PLANTED.replace("evaluations: 120", "evaluations: 30")
    path = write_profile("offpath", text)  # tmp_path is not ./profiles nor $RIGCAD_PROFILES
    assert main(["optimize", str(path), "--exports", str(tmp_path / "exports")]) == 0
    design = path.parent / "offpath_design.yaml"
    profile = load_profile(design)  # its `extends: offpath` resolves beside it
    assert profile.sources[1].endswith("offpath.yaml")
    assert profile.paraboloid.tangent_angle != load_profile(path).paraboloid.tangent_angle


def test_written_files_are_the_same_bytes_with_one_and_two_workers(write_profile, tmp_path):
    """Same profile, same bytes: the design profile and both figures; optimize.json differs only in
    its timings (keys ending in _s)."""
    import json

    from rigcad.optimize.run import run_optimize

    path = write_profile("files", TWO.replace("evaluations: 40", "evaluations: 24"))
    seen = []
    for w in (1, 2):
        out = tmp_path / f"exports{w}"
        run = run_optimize(path, out, Engine(workers=w), check=False)  # the bytes; the ray check is tested apart
        folder = out / "files" / "optimize"
        rep = json.loads((folder / "optimize.json").read_text())

        def strip(v):
            if isinstance(v, dict):
                return {k: strip(x) for k, x in v.items() if not k.endswith("_s") and k != "workers" and k != "engine"}
            return [strip(x) for x in v] if isinstance(v, list) else v

        seen.append((run.profile_path.read_bytes(), (folder / "history.png").read_bytes(),
                     (folder / "pareto.png").read_bytes(), strip(rep)))
    assert seen[0] == seen[1]
