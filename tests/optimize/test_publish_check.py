"""optimize publishes its check of the written design where `rigcad fab`, `stl` and `manual` read
the last `rigcad check` of a profile (rigcad.check.criteria.written_check): under the design's own
name, made from the design as its file reads back, so fab judges the full-trace rows optimize ran."""

import dataclasses
import json

from rigcad import api
from rigcad.check.criteria import written_check
from rigcad.export.manifest import profile_digest
from rigcad.optimize.run import publish_check
from rigcad.profile import load_profile
from rigcad.rig import Rig

#: A check small enough for a unit test (the analytic tracer, a few rays and builds): what is tested
#: is where its verdict is published and for which profile, not the check itself.
SMALL = {"rays": 2000, "mode": "analytic", "builds": 8}


def _design(tmp_path):
    path = tmp_path / "lab_design.yaml"
    path.write_text("extends: achutha2006\nlayout:\n  cop_to_vertex: 301.123456789012 mm\n")
    return path


def test_the_certified_check_is_published_for_the_design_as_written(tmp_path):
    path, exports = _design(tmp_path), tmp_path / "exports"
    design = load_profile(path)
    assert written_check(exports, design).state == "none"  # nothing before
    rig = Rig.from_profile(design)
    result = api.check(rig, **SMALL)

    def never(_):  # the file reads back to the checked parameters: no second check
        raise AssertionError("checked again although the design reads back to the checked profile")

    publish_check(exports, path, rig, result, recheck=never)
    seen = written_check(exports, load_profile(path))  # what fab reads for the design
    assert seen.state == ("passed" if result.passed else "failed"), seen
    assert json.loads(seen.path.read_text())["checks"] == json.loads(json.dumps(result.report["checks"]))


def test_a_design_whose_file_rounds_its_figures_is_checked_again_as_written(tmp_path):
    path, exports = _design(tmp_path), tmp_path / "exports"
    design = load_profile(path)
    # the optimiser's exact figure, which the file states to 12 digits only
    exact = dataclasses.replace(design, layout=dataclasses.replace(design.layout,
                                                                   cop_to_vertex=design.layout.cop_to_vertex + 4e-10))
    assert profile_digest(exact) != profile_digest(design)
    checked = Rig.from_profile(exact)
    seen_rigs = []

    def recheck(rig):
        seen_rigs.append(rig)
        return api.check(rig, **SMALL)

    publish_check(exports, path, checked, api.check(checked, **SMALL), recheck=recheck)
    assert len(seen_rigs) == 1 and profile_digest(seen_rigs[0].profile) == profile_digest(design)
    assert written_check(exports, design).state in ("passed", "failed")
