"""The assembly gate (rigcad.manual.gate): the default rig passes; a rig whose beam splitter cannot
slide into its holder (a projector whose axis sits 25 mm over its feet, so the shelf rises under
the splitter) is refused by name, with the keys the profile set; the verdict is kept beside the
export and read back only for the same profile and code; `rigcad stl`, `fab` and `manual` refuse it
in one line and exit 1, `stl` keeping its parts for inspection and the others writing nothing."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json

import pytest

from rigcad.cli import main
from pathlib import Path
from rigcad.errors import AssemblyError
from rigcad.manual import gate
from rigcad.profile import load_profile
from rigcad.rig import Rig

ROOT = Path(__file__).resolve().parents[2]
LOW = "projector:\n  pupil_height: 25 mm\n  lens_diameter: 25 mm\n"


@pytest.fixture(scope="module")
def low_rig(tmp_path_factory, table31_text):
    path = tmp_path_factory.mktemp("low") / "low.yaml"
    path.write_text(table31_text.lstrip("\n") + LOW)
    return Rig.from_profile(load_profile(path))


def test_the_default_rig_passes_the_gate(table31_rig):
    v = gate.verdict(table31_rig, search=False)
    assert v.ok, v.reason
    in_rig = {n for n, p in table31_rig.recipes.items() if p.in_rig}
    assert len(v.order) == len(set(v.order)) and in_rig <= set(v.order)  # every printed part placed once
    assert "finds an order" in v.line()


def test_a_splitter_that_cannot_go_in_is_refused_naming_the_parts_and_the_keys_set(low_rig):
    v = gate.verdict(low_rig, search=False)
    assert not v.ok
    assert v.step == "beam_splitter" and v.members == ("beam_splitter",)
    assert v.obstacles[0] == "splitter_holder"  # the way in that comes nearest runs into the holder's spring bolt
    # the keys the profile's own file set, first; then the splitter's and the holder's own
    assert set(v.keys[:2]) == {"projector.pupil_height", "projector.lens_diameter"}
    assert "beam_splitter.width" in v.keys and "tower.wall" in v.keys
    line = v.line()
    assert "\n" not in line and "beam_splitter cannot go in, it runs into splitter_holder" in line
    assert "cannot go in even with only what it needs in place" in v.reason  # the check's own words, kept


def test_the_verdict_is_read_back_only_for_the_same_profile_and_code(tmp_path, low_rig, table31_rig, monkeypatch):
    calls = []
    real = gate.verdict

    def counted(rig, meshes=None, search=True, progress=None):
        calls.append(rig.name)
        return real(rig, meshes, search=False)

    monkeypatch.setattr(gate, "verdict", counted)
    # a verdict not written anywhere points to no file; once checked() has written it, its line does
    assert "assembly.json" not in real(low_rig, search=False).line()
    calls.clear()
    first = gate.checked(low_rig, tmp_path)
    again = gate.checked(low_rig, tmp_path)
    assert calls == ["low"] and again == first  # read back: the same verdict, field for field
    assert gate.verdict_path(tmp_path, "low").is_file() and "(the check's whole reason: assembly.json" in first.line()
    path = gate.verdict_path(tmp_path, "low")
    doc = json.loads(path.read_text())
    doc["inputs_key"] = "0" * 64  # another profile or another rigcad made it
    path.write_text(json.dumps(doc))
    gate.checked(low_rig, tmp_path)
    assert calls == ["low", "low"]
    path.write_text("{not json")  # damaged: checked anew, not a traceback
    gate.checked(low_rig, tmp_path)
    assert calls == ["low", "low", "low"]
    path.write_text("[" * 100_000)  # a nesting bomb: checked anew, no RecursionError
    gate.checked(low_rig, tmp_path)
    assert calls == ["low", "low", "low", "low"]
    with pytest.raises(AssemblyError) as e:
        gate.gate(low_rig, tmp_path)
    assert e.value.exit_code == 1 and e.value.step == "beam_splitter"
    assert gate.gate(table31_rig, tmp_path / "other").ok


@pytest.mark.e2e  # a search of a few dozen rigs: ~40 s (4 min at load ~18)
def test_the_nearest_value_found_lets_the_whole_rig_go_together(low_rig):
    """The splitter's way in along -y runs into one of its seat's spring bolts, which
    projector.pupil_height does not move, while the key cuts its overlap along the other ways in: the
    keys are ranked per direction (gate.nearest_values), so the key is searched all the same."""
    v = gate.verdict(low_rig)
    fix = next(f for f in v.fixes if f.key == "projector.pupil_height")
    assert fix.now == 25.0 and fix.value is not None and fix.where.endswith("low.yaml:8")
    # the search tests the blocked step alone; the claim is the whole check's, at the value found ...
    ok = Rig.from_profile(gate._with(low_rig.profile, fix.key, fix.value), previous=low_rig)
    assert gate.verdict(ok, search=False).ok
    # ... and 0.2 mm back towards the profile's value (twice the search's resolution) it is refused
    short = Rig.from_profile(gate._with(low_rig.profile, fix.key, fix.value - 0.2), previous=low_rig)
    assert not gate.verdict(short, search=False).ok
    # docs/assembly.md quotes this line, with the profile's folder left out
    page = (ROOT / "docs" / "assembly.md").read_text(encoding="utf-8")
    shown = dataclasses.replace(v, kept=f"{gate.VERDICT_FILE} beside the export")  # as stl, fab and manual print it
    quoted = f"rigcad: error: {shown.line()}".replace(fix.where.rsplit("/", 1)[0] + "/", "")
    assert quoted in page, quoted


def _run(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


@pytest.mark.e2e  # stl builds every part of the refused rig: ~60 s
def test_stl_fab_and_manual_refuse_a_rig_that_cannot_be_assembled(tmp_path, table31_text):
    profile = tmp_path / "low.yaml"
    profile.write_text(table31_text.lstrip("\n") + LOW)
    exports = tmp_path / "exports"
    code, out, err = _run("stl", str(profile), "--exports", str(exports))
    assert code == 1
    lines = [ln for ln in err.splitlines() if ln.startswith("rigcad: error:")]
    assert len(lines) == 1 and "beam_splitter cannot go in" in lines[0] and "projector.pupil_height" in lines[0]
    assert "written for inspection only" in lines[0]
    assert (exports / "low" / "step" / "splitter_holder.step").is_file()  # kept, for inspection
    again = _run("stl", str(profile), "--exports", str(exports))
    # still refused, nothing rebuilt (the verdict read back; "0 part(s) built" when rigcad's code moved in between)
    assert again[0] == 1 and ("up to date" in again[1] or "0 part(s) built" in again[1]) and lines[0] in again[2]
    for command in (["fab", str(profile), "--printer", "prusa_mk3s"], ["manual", str(profile), "--printer", "prusa_mk3s"]):
        code, out, err = _run(*command, "--exports", str(exports))
        assert code == 1 and err.count("\n") == 1 and "beam_splitter cannot go in" in err, err
    assert not (exports / "low" / "fab").exists() and not (exports / "low" / "manual").exists()


# -- the checks `rigcad design` runs early: no solid needed -----------------------------------------
def _rig(tmp_path, text: str, name: str = "early"):
    path = tmp_path / f"{name}.yaml"
    path.write_text("extends: achutha2006\n" + text)
    return Rig.from_profile(load_profile(path))


def test_the_early_checks_pass_the_default_rig(table31_rig):
    assert gate.early_refusals(table31_rig) == ()


def test_the_early_checks_name_every_part_a_recipe_refuses_and_the_key(tmp_path):
    """A seat travel no M3 set screw covers refuses the three parts that carry such a screw, named
    together in one refusal with the key and the profile's line."""
    (r,) = gate.early_refusals(_rig(tmp_path, "adjusters:\n  seat_travel: 30 mm\n"))
    assert r.what == "projector_cross, projector_backplate, projector_mounting_plate"
    assert r.message.startswith(f"{tmp_path / 'early.yaml'}:3: ") and "lower adjusters.seat_travel" in r.message


def test_the_early_checks_report_the_layouts_refusal(tmp_path):
    (r,) = gate.early_refusals(_rig(tmp_path, "tower:\n  splitter_distance: 20 mm\n"))
    assert r.what == "the layout" and "raise tower.splitter_distance (now 20 mm)" in r.message


def test_design_prints_every_early_refusal_and_exits_1_with_its_files_written(tmp_path):
    profile = tmp_path / "early.yaml"
    profile.write_text("extends: achutha2006\nadjusters:\n  seat_travel: 30 mm\n")
    code, out, err = _run("design", str(profile), "--exports", str(tmp_path / "exports"))
    assert code == 1
    lines = err.splitlines()
    assert lines[-2:] == [  # one error line, then each refusal indented on its own line
        "rigcad: error: early: `rigcad stl` would refuse this rig: 1 refusal(s) found before any part is built, "
        "each below (the design's own files are written)",
        "  projector_cross, projector_backplate, projector_mounting_plate: "
        f"{profile}:3: no M3 set screw is 67.7 mm long: lower adjusters.seat_travel"]
    assert (tmp_path / "exports" / "early" / "design.json").is_file()
