"""``check``, ``view``, ``calibrate --kit`` and ``manual`` run again with nothing changed read back what
they published (rigcad.export.reuse.recording: the record published with the folder) and write
nothing, byte for byte and file for file; a changed profile key, option, code, input file, or a
missing or edited output makes them work again. Each command's work is counted at its one door
(the stage or writer it calls), as tests/fab/test_stage_reuse.py counts fab's. Whole commands on the
default rig: marked e2e (make test-e2e)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from rigcad.export import reuse

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.e2e


def _counted(monkeypatch, module, name: str) -> dict:
    """Count the calls of ``module.name`` (the command's door to its work) from now on."""
    calls = {"n": 0}
    real = getattr(module, name)

    def counted(*args, **kwargs):
        calls["n"] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)
    return calls


def run_cli(*args) -> tuple[int, str, str]:
    """Run the command line in this process: (exit status, stdout, stderr)."""
    from rigcad.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


def _state(folder: Path) -> dict[str, tuple]:
    """Each file's bytes, inode and mtime: a publication makes new files (Staging exchanges the tree)."""
    return {p.relative_to(folder).as_posix(): (p.read_bytes(), p.stat().st_ino, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _changed_profile(tmp_path: Path) -> Path:
    """The default profile with one key changed (the meshes' chord error), under its own name."""
    text = (ROOT / "profiles" / "achutha2006.yaml").read_text()
    assert "\ntessellation:" not in text
    path = tmp_path / "profiles" / "achutha2006.yaml"
    path.parent.mkdir()
    path.write_text(text + "\ntessellation:\n  chord_error: 0.02 mm\n")
    return path


def _flip(path: Path) -> bytes:
    good = path.read_bytes()
    path.write_bytes(good[:-1] + bytes([good[-1] ^ 1]))
    return good


def test_check_reads_back_and_a_change_redoes_it(tmp_path, monkeypatch):
    from rigcad import api

    calls = _counted(monkeypatch, api, "check")
    ex = tmp_path / "exports"
    opts = ["--exports", str(ex), "--rays", "2000", "--mode", "analytic", "--no-monte-carlo"]
    code, out, _ = run_cli("check", "achutha2006", *opts)
    assert code == 0 and calls["n"] == 1, out
    folder = ex / "achutha2006" / "check"
    before = _state(folder)
    code, again, _ = run_cli("check", "achutha2006", *opts)
    assert code == 0 and calls["n"] == 1  # read back: not traced
    assert _state(folder) == before  # nothing written
    assert again.splitlines()[:-3] == out.splitlines()[:-4]  # the same figures and table (less 'wrote' lines)
    assert run_cli("check", "achutha2006", *opts[:3], "2500", *opts[4:])[0] == 0 and calls["n"] == 2  # an option
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 3
    (ex / "achutha2006" / "stl").mkdir(parents=True)
    (ex / "achutha2006" / "stl" / "beam.stl").write_bytes(b"solid beam\nendsolid beam\n")  # an input file
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 4
    good = _flip(folder / "spot.png")  # an edited output
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 5
    assert (folder / "spot.png").read_bytes() == good  # written anew, the same bytes
    (folder / "theta_map.png").unlink()  # a missing output
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 6
    monkeypatch.setattr(reuse, "running_code", lambda: "another version of rigcad")  # the code
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 7
    assert run_cli("check", "achutha2006", *opts)[0] == 0 and calls["n"] == 7
    monkeypatch.undo()
    calls = _counted(monkeypatch, api, "check")
    assert run_cli("check", str(_changed_profile(tmp_path)), *opts)[0] == 0 and calls["n"] == 1  # a profile key


def test_view_reads_back_and_a_change_redoes_it(tmp_path, monkeypatch):
    from rigcad.manual import view

    calls = _counted(monkeypatch, view, "write_view")
    ex = tmp_path / "exports"
    opts = ["--exports", str(ex), "--rays", "20"]
    assert run_cli("view", "achutha2006", *opts)[0] == 0 and calls["n"] == 1
    folder = ex / "achutha2006" / "view"
    before = _state(folder)
    code, out, _ = run_cli("view", "achutha2006", *opts)
    assert code == 0 and calls["n"] == 1 and "up to date" in out
    assert _state(folder) == before
    assert run_cli("view", "achutha2006", *opts[:2], "--rays", "21")[0] == 0 and calls["n"] == 2  # an option
    assert run_cli("view", "achutha2006", *opts)[0] == 0 and calls["n"] == 3
    (folder / "rig.png").unlink()
    assert run_cli("view", "achutha2006", *opts)[0] == 0 and calls["n"] == 4
    assert run_cli("view", str(_changed_profile(tmp_path)), *opts)[0] == 0 and calls["n"] == 5  # a profile key


def test_calibrate_kit_reads_back_and_a_change_redoes_it(tmp_path, monkeypatch):
    from rigcad.calibrate import kit

    calls = _counted(monkeypatch, kit, "write_kit")
    ex = tmp_path / "exports"
    assert run_cli("calibrate", "achutha2006", "--kit", "--exports", str(ex))[0] == 0 and calls["n"] == 1
    folder = ex / "achutha2006" / "calibrate_kit"
    before = _state(folder)
    code, out, _ = run_cli("calibrate", "achutha2006", "--kit", "--exports", str(ex))
    assert code == 0 and calls["n"] == 1 and "up to date" in out
    assert _state(folder) == before
    _flip(folder / "calibration.md")
    assert run_cli("calibrate", "achutha2006", "--kit", "--exports", str(ex))[0] == 0 and calls["n"] == 2
    assert _state(folder).keys() == before.keys()
    monkeypatch.setattr(reuse, "running_code", lambda: "another version of rigcad")
    assert run_cli("calibrate", "achutha2006", "--kit", "--exports", str(ex))[0] == 0 and calls["n"] == 3
    changed = _changed_profile(tmp_path)
    assert run_cli("calibrate", str(changed), "--kit", "--exports", str(ex))[0] == 0 and calls["n"] == 4


def test_manual_reads_back_and_follows_fab_and_check(tmp_path, monkeypatch):
    """The manual's key holds fab's record and the check it is judged by: a new check or a changed
    printer file makes the manual again (and only the changed stage's work is done)."""
    from rigcad.fab import stage
    from rigcad.manual import document

    manuals = _counted(monkeypatch, document, "write_manual")
    fabs = _counted(monkeypatch, stage, "_fab_part")
    ex = tmp_path / "exports"
    man = ["--printer", "prusa_mk3s", "--exports", str(ex)]
    code, _, err = run_cli("manual", "achutha2006", *man)
    assert code == 0 and manuals["n"] == 1 and fabs["n"] > 0, err[-2000:]
    assert "no `rigcad check` result" in err  # the criteria not judged without a check
    done = fabs["n"]
    folder = ex / "achutha2006" / "manual" / "prusa_mk3s"
    before = _state(folder)
    code, out, err = run_cli("manual", "achutha2006", *man)
    assert code == 0 and manuals["n"] == 1 and fabs["n"] == done and "up to date" in out
    assert "no `rigcad check` result" in err  # the note said again
    assert _state(folder) == before
    assert run_cli("check", "achutha2006", "--exports", str(ex), "--rays", "2000", "--mode", "analytic",
                "--no-monte-carlo")[0] == 0
    code, _, err = run_cli("manual", "achutha2006", *man)  # a check now judges it: the manual again, fab read back
    assert code == 0 and manuals["n"] == 2 and fabs["n"] == done and "no `rigcad check`" not in err
    assert run_cli("manual", "achutha2006", *man)[0] == 0 and manuals["n"] == 2
    text = (ROOT / "profiles" / "printers" / "prusa_mk3s.yaml").read_text()
    assert "layer_time_s: 1.0\n" in text
    printer = tmp_path / "printers" / "prusa_mk3s.yaml"
    printer.parent.mkdir()
    printer.write_text(text.replace("layer_time_s: 1.0\n", "layer_time_s: 2.0\n"))
    man[1] = str(printer)
    assert run_cli("manual", "achutha2006", *man)[0] == 0 and manuals["n"] == 3 and fabs["n"] > done  # fab again
    done = fabs["n"]
    assert run_cli("manual", "achutha2006", *man)[0] == 0 and manuals["n"] == 3 and fabs["n"] == done
