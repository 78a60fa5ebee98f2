"""A fab run reads back what an earlier run published from the same inputs (the profile, rigcad's
code, the printer's resolved settings, the options) instead of doing the work again, whichever
command published it; a changed printer file, profile key or published file makes it work again.
The fab work is counted at the stage's two doors: every printed part goes through _fab_part (a
mirror part twice, _with_stock) and every cut template through _cut_part."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rigcad.export import reuse
from rigcad.fab import stage as S
from rigcad.fab.printers import load_printer

ROOT = Path(__file__).resolve().parents[2]
#: Two quick parts: one printed (the beam), one cut from plate (a template)
PARTS = ["beam", "paraboloid_template"]


@pytest.fixture
def fab_calls(monkeypatch):
    """The number of times each door of the fab work was entered since the test began."""
    calls = {"_fab_part": 0, "_cut_part": 0}
    for name in calls:
        real = getattr(S, name)

        def counted(*args, _real=real, _name=name, **kwargs):
            calls[_name] += 1
            return _real(*args, **kwargs)

        monkeypatch.setattr(S, name, counted)
    return calls


def _files(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


def _run(rig, printer, out, **kw):
    return S.run_fab(rig, printer, out, parts=kw.pop("parts", PARTS), **kw)


def test_a_second_run_reads_the_first_back_and_does_no_fab_work(table31_rig, prusa, tmp_path, fab_calls):
    out = tmp_path / "fab" / "prusa_mk3s"
    first = _run(table31_rig, prusa, out)
    assert not first.reused and fab_calls == {"_fab_part": 1, "_cut_part": 1}, fab_calls
    record = json.loads((out / reuse.RECORD).read_text())
    assert "fab.json" in record["files"] and "stl/beam.stl" in record["files"]  # every file of the run vouched for
    published = _files(out)
    seen = []
    second = _run(table31_rig, prusa, out, progress=seen.append)
    assert second.reused and fab_calls == {"_fab_part": 1, "_cut_part": 1}, fab_calls  # zero calls the second time
    assert second.report == json.loads((out / "fab.json").read_text()) == first.report
    assert seen == PARTS  # a progress bar counting the parts still fills
    assert _files(out) == published  # nothing rewritten


def test_a_changed_printer_file_redoes_the_work(table31_rig, prusa, tmp_path, fab_calls):
    out = tmp_path / "fab" / "prusa_mk3s"
    _run(table31_rig, prusa, out)
    text = (ROOT / "profiles" / "printers" / "prusa_mk3s.yaml").read_text()
    assert "layer_time_s: 1.0\n" in text
    changed = tmp_path / "printers" / "prusa_mk3s.yaml"
    changed.parent.mkdir()
    changed.write_text(text.replace("layer_time_s: 1.0\n", "layer_time_s: 2.0\n"))  # only the estimate reads it
    again = _run(table31_rig, load_printer(changed), out)
    assert not again.reused and fab_calls == {"_fab_part": 2, "_cut_part": 2}, fab_calls
    assert again.report["printer"]["layer_time_s"] == 2.0
    # the same file once more: read back
    assert _run(table31_rig, load_printer(changed), out).reused and fab_calls["_fab_part"] == 2


def test_a_changed_profile_key_or_option_redoes_the_work(table31_rig, prusa, tmp_path, fab_calls):
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    out = tmp_path / "fab" / "prusa_mk3s"
    _run(table31_rig, prusa, out)
    text = (ROOT / "profiles" / "achutha2006.yaml").read_text()
    assert "\ntessellation:" not in text and table31_rig.profile.tessellation.chord_error != 0.02
    path = tmp_path / "achutha2006.yaml"
    path.write_text(text + "\ntessellation:\n  chord_error: 0.02 mm\n")  # the meshes the pieces are cut from
    rig = Rig.from_profile(load_profile(path))
    assert not _run(rig, prusa, out).reused and fab_calls["_fab_part"] == 2  # another profile: the work again
    assert not _run(rig, prusa, out, parts=["beam"]).reused and fab_calls["_fab_part"] == 3  # other parts
    assert not _run(rig.moved("dome", (0.1, 0.0, 0.0)), prusa, out, parts=["beam"]).reused  # a moved rig: never
    assert fab_calls["_fab_part"] == 4


def test_a_changed_or_missing_published_file_redoes_the_work(table31_rig, prusa, tmp_path, fab_calls):
    out = tmp_path / "fab" / "prusa_mk3s"
    _run(table31_rig, prusa, out)
    stl = out / "stl" / "beam.stl"
    good = stl.read_bytes()
    stl.write_bytes(good[:-1] + bytes([good[-1] ^ 1]))  # one bit
    assert not _run(table31_rig, prusa, out).reused and fab_calls["_fab_part"] == 2
    assert stl.read_bytes() == good  # written anew
    (out / "fab.md").unlink()
    assert not _run(table31_rig, prusa, out).reused and fab_calls["_fab_part"] == 3
    (out.parent / f"{out.name}.made_from.json").unlink()  # no record of the profile: not vouched for
    assert not _run(table31_rig, prusa, out).reused and fab_calls["_fab_part"] == 4
    assert _run(table31_rig, prusa, out).reused and fab_calls["_fab_part"] == 4


def test_a_run_with_problems_is_never_read_back(table31_rig, prusa, tmp_path, fab_calls, monkeypatch):
    out = tmp_path / "fab" / "prusa_mk3s"
    _run(table31_rig, prusa, out)
    assert (out / reuse.RECORD).is_file()
    real = S._fab_part

    def failing(part, *args, **kwargs):
        if part.name == "beam":
            raise S.FabricationError("the beam is refused on purpose")
        return real(part, *args, **kwargs)

    monkeypatch.setattr(S, "_fab_part", failing)
    (out / "fab.md").write_text("edited")  # so that the run does the work
    assert _run(table31_rig, prusa, out).problems
    assert not (out / reuse.RECORD).exists()  # the earlier record is not carried over either
    monkeypatch.setattr(S, "_fab_part", real)
    calls = fab_calls["_cut_part"]
    assert not _run(table31_rig, prusa, out).reused and fab_calls["_cut_part"] == calls + 1


@pytest.mark.e2e  # the whole rig's fab and manual through the command line (~40 s): make test-e2e
def test_manual_right_after_fab_does_no_fab_work(tmp_path, fab_calls):
    import contextlib
    import io

    from rigcad.cli import main

    def run(*args):
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main([*args, "achutha2006", "--printer", "prusa_mk3s", "--exports", str(tmp_path)])
        assert code == 0, err.getvalue()[-2000:]

    run("fab")
    done = dict(fab_calls)
    report = json.loads((tmp_path / "achutha2006" / "fab" / "prusa_mk3s" / "fab.json").read_text())
    printed = [e for e in report["parts"].values() if "pieces" in e]
    # every printed part once, a mirror part twice (the second time with its stock), both templates
    assert done == {"_fab_part": len(printed) + sum("sanding_stock" in e for e in printed), "_cut_part": 2}, done
    run("manual")
    assert fab_calls == done, fab_calls  # the manual read the fab run back: not one call more
    assert (tmp_path / "achutha2006" / "manual" / "prusa_mk3s" / "manual.md").is_file()


def test_the_api_reads_a_published_run_back_without_building_a_rig(table31_rig, prusa, tmp_path, fab_calls,
                                                                   monkeypatch):
    from rigcad import api
    from rigcad.rig import Rig

    out = tmp_path / "fab" / "prusa_mk3s"
    profile = table31_rig.profile
    assert api.fab_published(profile, prusa, out, parts=PARTS) is None  # nothing published yet
    first = _run(table31_rig, prusa, out)

    def no_rig(*args, **kwargs):
        raise AssertionError("a rig was built")

    monkeypatch.setattr(Rig, "from_profile", no_rig)
    back = api.fab_published(profile, prusa, out, parts=PARTS)
    assert back.reused and back.report == first.report and fab_calls["_fab_part"] == 1
    assert api.fab_published(profile, prusa, out, parts=["beam"]) is None  # other parts: another key
    assert api.fab_published(profile, prusa, out, parts=PARTS, gcode=True) is None  # G-code asked: another key


def test_a_nesting_bomb_in_a_published_record_or_report_reads_as_nothing_published(tmp_path):
    """rigcad reads its own records back as data (rigcad.export.readback): a record, or an earlier
    fab.json, of 10^5 nested brackets is no run to reuse, never a RecursionError."""
    from rigcad.export import reuse
    from rigcad.fab import stage

    folder = tmp_path / "fab"
    folder.mkdir()
    (folder / "fab.json").write_text("[" * 100_000)
    assert stage._previous_report(folder) == {}
    (folder / reuse.RECORD).write_text("[" * 100_000)
    from rigcad.export.atomic import made_from_path

    made_from_path(folder).write_text('{"profile_sha256": "' + "0" * 64 + '"}')  # the record is read, not skipped
    assert reuse.read_back(folder, "k" * 64, "0" * 64, tmp_path / ".fab.lock") is None
