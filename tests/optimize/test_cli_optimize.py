"""`rigcad optimize achutha2006_optimize` as a user runs it: the issue's target (beat Table 3.1 on
the lowest measurable theta and the px/deg coefficient of variation, printing on the Prusa MK3S in
at most 4 dome pieces, within 300 evaluations), the outputs, and the written profile built and
passed through `rigcad check` (the smallest part, 50 000 rays, no Monte Carlo: kept light)."""

from __future__ import annotations

import json

import pytest
import yaml

from rigcad.cli import main

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def optimized(tmp_path_factory):
    out = tmp_path_factory.mktemp("opt") / "exports"
    code = main(["optimize", "achutha2006_optimize", "--exports", str(out), "--workers", "1"])
    assert code == 0
    folder = out / "achutha2006_optimize" / "optimize"
    return folder, json.loads((folder / "optimize.json").read_text())


def test_beats_table31_on_both_objectives_within_the_budget(optimized):
    _, rep = optimized
    base, chosen = rep["base"], rep["chosen"]
    assert base["parameters"] == {"layout.cop_to_vertex_mm": 270.0, "layout.sample_to_rim_mm": 135.0,
                                  "paraboloid.vertical_extent_mm": 22.5,
                                  "paraboloid.tangent_angle_deg": pytest.approx(20.0, abs=1e-12)}  # Table 3.1
    assert chosen["objectives"]["theta_min"] < base["objectives"]["theta_min"]
    assert chosen["objectives"]["px_per_deg_cv"] < base["objectives"]["px_per_deg_cv"]
    assert chosen["feasible"] and chosen["figures"]["dome_pieces"] <= 4
    assert len(rep["evaluations"]) <= 300
    assert rep["spec"]["constraints"]["printer"] == "prusa_mk3s"
    # the certified path (converged DOP853 dome) agrees with the evaluation the search trusted
    diff = rep["certified_check"]["fast_minus_certified"]
    assert abs(diff["theta_min_deg"]) < 1e-9 and abs(diff["px_per_deg_mean"]) < 1e-9  # deg, px/deg: both exact
    assert abs(diff["px_per_deg_min"]) < 1e-4  # px/deg: the certified one is np.gradient on its rows


def test_every_evaluation_is_recorded_with_units(optimized):
    folder, rep = optimized
    row = rep["evaluations"][1]
    assert set(row) >= {"parameters", "objectives", "constraints", "time_s", "feasible", "phase"}
    assert all(k.endswith(("_mm", "_deg")) for k in row["parameters"])
    assert {r["phase"] for r in rep["evaluations"]} == {"global", "polish"}
    for name in ("history.png", "pareto.png"):
        assert (folder / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_written_profile_extends_the_base_and_sets_only_what_changed(optimized):
    folder, rep = optimized
    path = folder / "achutha2006_optimize_design.yaml"
    data = yaml.safe_load(path.read_text())
    assert data["extends"] == "achutha2006_optimize"
    changed = {k for k, v in rep["chosen"]["parameters"].items() if v != rep["base"]["parameters"][k]}
    written = {f"{s}.{k}" for s, kv in data.items() if isinstance(kv, dict) for k in kv if s != "dome"}
    custom_lens = rep["certified_check"]["custom_focal_length_mm"]  # no stock lens focuses the design
    finer = rep["certified_check"]["ray_check"]["mirror_normal_error_rad"] < 0.01  # rad: the base's default meshes
    assert written == ({k.rsplit("_", 1)[0] for k in changed} | ({"lens.focal_length"} if custom_lens else set())
                       | ({"tessellation.mirror_normal_error"} if finer else set()))
    if custom_lens:
        assert data["lens"]["focal_length"] == f"{custom_lens:g} mm"


def test_written_profile_builds_and_passes_rigcad_check(optimized, tmp_path, capsys):
    folder, _ = optimized
    path = str(folder / "achutha2006_optimize_design.yaml")
    exports = str(tmp_path / "exports")
    assert main(["build", path, "--parts", "paraboloid", "--exports", exports]) == 0
    # 50 000 rays: the lost fraction's sampling error (0.12 %) is well inside the search's 3 % reserve
    # (the limit 8 %, held to 7.76 %; measured 7.65 % with 100 000 rays). The exact surfaces (analytic
    # reading): the optimiser designs surfaces, not their tessellation; with the default mirror meshes
    # the smooth reading of this design's camera-through-splitter row is 0.0106 deg against 0.01 (the
    # mesh's own 0.008 deg plus the plate), which a finer tessellation.mirror_normal_error removes.
    assert main(["check", path, "--exports", exports, "--rays", "50000", "--no-monte-carlo",
                 "--mode", "analytic"]) == 0, capsys.readouterr()


@pytest.mark.slow  # check with its Monte Carlo, fab and manual on the whole written design: 10+ minutes loaded
def test_the_written_design_passes_check_with_its_yield_fab_and_manual(optimized, tmp_path, capsys):
    """The issue's 'Done when': the design `rigcad optimize achutha2006_optimize` writes passes `rigcad
    check` as the profile declares it (smooth reading, its rays, the Monte Carlo yield against
    tolerancing.min_yield), `rigcad fab` on the MK3S (its tolerance stack included, no G-code) and
    `rigcad manual` (the assembly gate, the calibration kit in the dome)."""
    folder, rep = optimized
    path = str(folder / "achutha2006_optimize_design.yaml")
    exports = tmp_path / "exports"
    assert main(["check", path, "--exports", str(exports)]) == 0, capsys.readouterr()
    mc = json.loads((exports / "achutha2006_optimize_design" / "check" / "raycheck.json").read_text())["monte_carlo"]
    assert mc["yield"] >= mc["min_yield"] == 0.9  # the profile's own tolerancing.min_yield
    assert rep["certified_check"]["ray_check"]["monte_carlo_yield"] == mc["yield"]  # the same seeded check
    assert main(["fab", path, "--printer", "prusa_mk3s", "--exports", str(exports)]) == 0, capsys.readouterr()
    assert main(["manual", path, "--printer", "prusa_mk3s", "--exports", str(exports)]) == 0, capsys.readouterr()
