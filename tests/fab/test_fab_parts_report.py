"""`rigcad fab --parts` writes one report for the whole folder: the parts of an earlier run from the
same profile, whose files stay beside this run's, keep their entries (marked); from another profile
neither their files nor their entries stay."""

from __future__ import annotations

import json

from rigcad.fab import stage as S


def _stls(out):
    return sorted(p.name for p in (out / "stl").glob("*.stl"))


def test_a_run_of_some_parts_keeps_the_earlier_parts_of_the_same_profile(table31_rig, prusa, tmp_path):
    out = tmp_path / "fab" / "prusa_mk3s"
    S.run_fab(table31_rig, prusa, out, parts=["beam"])
    res = S.run_fab(table31_rig, prusa, out, parts=["paraboloid_template"])
    report = json.loads((out / "fab.json").read_text())
    assert report == res.report
    assert list(report["parts"]) == ["beam", "paraboloid_template"]
    assert report["parts"]["beam"]["from_earlier_run"] is True
    assert "from_earlier_run" not in report["parts"]["paraboloid_template"]
    assert _stls(out) == ["beam.stl"]  # the file its entry describes is there
    assert report["totals"]["pieces"] == 1  # the beam's piece counts in the folder's totals
    assert "beam (earlier run)" in (out / "fab.md").read_text()


def test_an_earlier_run_from_another_profile_leaves_neither_files_nor_entries(table31_rig, prusa, tmp_path):
    out = tmp_path / "fab" / "prusa_mk3s"
    S.run_fab(table31_rig, prusa, out, parts=["beam"])
    from dataclasses import replace

    from rigcad.rig import Rig

    p = table31_rig.profile
    other = Rig.from_profile(replace(p, beam=replace(p.beam, height=p.beam.height + 1)), previous=table31_rig)
    S.run_fab(other, prusa, out, parts=["paraboloid_template"])
    report = json.loads((out / "fab.json").read_text())
    assert list(report["parts"]) == ["paraboloid_template"]
    assert _stls(out) == []
