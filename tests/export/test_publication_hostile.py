"""Publication against a hostile exports folder: planted links and files where rigcad keeps its locks
and folders, a command publishing the whole folder while another is half-way through its own, and
results of an older profile left beside a new build. Nothing outside the exports is touched, nothing
is lost, and nothing stale is carried into a new build."""

from __future__ import annotations

import json
import os
import shutil
import threading
from contextlib import contextmanager
from pathlib import Path

import pytest

from rigcad.errors import ExportError, WriteError
from rigcad.export.atomic import Staging, hold_lock, profile_lock

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

#: Coarse tessellations keep each build to seconds; publication does not depend on them.
FAST = """extends: achutha2006
tessellation:
  chord_error: 0.03 mm
  mirror_chord_error: 0.02 mm
  mirror_normal_error: 0.05 rad
"""

#: A generous bound for a thread doing a few seconds of work on a loaded two-core machine: reaching
#: it means the thread hangs (a deadlock), not that it is slow.
HANG_S = 600


def _profile(folder: Path, extra: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "rig.yaml"
    path.write_text(FAST + extra)
    return path


def _tree(folder: Path) -> dict[str, bytes | str]:
    """Every entry under ``folder`` without following links: files by bytes, links by target."""
    out: dict[str, bytes | str] = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            rel = p.relative_to(folder).as_posix()
            if p.is_symlink():
                out[rel] = f"-> {os.readlink(p)}"
            elif p.is_file():
                out[rel] = p.read_bytes()
    return out


def _outside(tmp_path: Path) -> tuple[Path, dict]:
    """A folder outside the exports, with a file and a subfolder, and its exact contents."""
    home = tmp_path / "home"
    (home / "notes").mkdir(parents=True)
    (home / "precious.txt").write_text("three years of measurements\n")
    (home / "notes" / "a.txt").write_text("a\n")
    (home / "empty-flag").write_bytes(b"")  # empty: nothing in its text tells it from a fresh lock
    return home, _tree(home)


def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# -- lock files: never opened through a link, refused when rigcad did not make them -------------------
def _plant_symlink(lock: Path, home: Path) -> None:
    lock.symlink_to(home / "precious.txt")


def _plant_dangling(lock: Path, home: Path) -> None:
    lock.symlink_to(home / "created-through-the-link.txt")


def _plant_hardlink(lock: Path, home: Path) -> None:
    os.link(home / "empty-flag", lock)


def _plant_foreign(lock: Path, home: Path) -> None:
    lock.write_text("someone's notes, not a lock\n")


def _plant_fifo(lock: Path, home: Path) -> None:
    os.mkfifo(lock)


def _plant_folder(lock: Path, home: Path) -> None:
    lock.mkdir()
    (lock / "kept.txt").write_text("kept")


PLANTED = {"a symbolic link": _plant_symlink,
           "a dangling symbolic link": _plant_dangling, "2 names": _plant_hardlink,
           "text rigcad did not write": _plant_foreign, "not a plain file": _plant_fifo,
           "a folder": _plant_folder}


@pytest.mark.parametrize("kind", sorted(PLANTED))
@pytest.mark.parametrize("lock_name", [".rig.lock", "rig/.basis.lock"])
def test_a_planted_lock_is_refused_and_what_it_names_is_untouched(tmp_path, kind, lock_name):
    home, before = _outside(tmp_path)
    exports = tmp_path / "exports"
    lock = exports / lock_name
    lock.parent.mkdir(parents=True)
    PLANTED[kind](lock, home)
    planted = _tree(exports)
    folder = exports / "rig" / ("basis" if "basis" in lock_name else "")
    with pytest.raises(ExportError) as err:
        with Staging(folder, lock) as stage:  # the default lock of a folder is .<name>.lock beside it
            stage.write_bytes(folder / "x.txt", b"x")
            stage.commit()
    message = str(err.value)
    assert "\n" not in message and str(lock) in message and "not a lock file rigcad made" in message, message
    assert "someone's notes" not in message and "measurements" not in message  # a refused file is never quoted
    assert _tree(home) == before, "a file outside the exports changed"
    assert _tree(exports) == planted, "the refused run wrote into the exports"


def test_a_lock_rigcad_made_is_taken_again(tmp_path):
    """The checks let rigcad's own lock through: empty (released, or a run killed at once) or holding
    a holder line (a run killed while it held the lock). Held, it names its holder for a run that
    waits; released, it names no one, so the exports are the same bytes after every run."""
    lock = tmp_path / ".rig.lock"
    held = hold_lock(lock)
    assert lock.read_text().startswith(f"pid {os.getpid()}: ")
    held.release()
    assert lock.read_bytes() == b""
    lock.write_text("pid 1: rigcad stl achutha2006, since 12:00:00")  # killed while holding it
    hold_lock(lock).release()
    hold_lock(lock).release()
    assert lock.read_bytes() == b""


def test_the_cli_refuses_a_linked_lock_in_one_line(tmp_path, capsys):
    """`ln -s ~/precious.txt exports/.achutha2006.lock; rigcad design achutha2006`."""
    from rigcad.cli import main

    home, before = _outside(tmp_path)
    exports = tmp_path / "exports"
    exports.mkdir()
    (exports / ".achutha2006.lock").symlink_to(home / "precious.txt")
    code = main(["design", "achutha2006", "--exports", str(exports)])
    line = _one_line(capsys.readouterr().err)
    assert code != 0 and ".achutha2006.lock" in line and "symbolic link" in line, line
    assert _tree(home) == before
    assert sorted(p.name for p in exports.iterdir()) == [".achutha2006.lock"]  # nothing published


@pytest.mark.parametrize("planted", ["lock", "folder"])
@pytest.mark.parametrize("command", ["design", "build", "stl", "basis", "check", "view", "tolerance",
                                     "fab --printer prusa_mk3s", "manual --printer prusa_mk3s",
                                     "sweep --set paraboloid.tangent_angle=19deg..21deg:2 --printer none"])
def test_a_planted_link_is_refused_before_any_work(tmp_path, capsys, monkeypatch, command, planted):
    """The refusal comes before the rig is built (the dome integrated, the basis computed): a command
    that would only find the link when it publishes has done all its work for nothing."""
    from rigcad.cli import main
    from rigcad.rig import Rig

    def no_work(*args, **kwargs):
        raise AssertionError("the command started its work before refusing the planted link")

    monkeypatch.setattr(Rig, "from_profile", no_work)
    home, before = _outside(tmp_path)
    exports = tmp_path / "exports"
    exports.mkdir()
    if planted == "lock":
        (exports / ".achutha2006.lock").symlink_to(home / "precious.txt")
    else:
        (exports / "achutha2006").symlink_to(home, target_is_directory=True)
    name, *options = command.split()
    code = main([name, "achutha2006", *options, "--exports", str(exports)])
    line = _one_line(capsys.readouterr().err)
    assert code != 0 and "symbolic link" in line, line
    assert _tree(home) == before


# -- a staging folder that vanishes is an error, never re-made ------------------------------------------
@pytest.mark.parametrize("then", ["write", "commit"])
@pytest.mark.parametrize("replaced_by", ["nothing", "a link"])
def test_a_staging_folder_that_vanishes_is_an_error(tmp_path, then, replaced_by):
    home, before = _outside(tmp_path)
    out = tmp_path / "exports" / "rig" / "basis"
    out.mkdir(parents=True)
    (out / "basis.json").write_text("the last good run")
    with pytest.raises(WriteError, match="vanished or was replaced"):
        with Staging(out) as stage:
            stage.write_bytes(out / "projector" / "a.png", b"a")
            staged = stage.temp_path(out)
            shutil.rmtree(staged)  # another program deletes it (what a whole-folder swap used to do)
            if replaced_by == "a link":
                staged.symlink_to(home, target_is_directory=True)
            if then == "write":
                stage.write_bytes(out / "projector" / "b.png", b"b")
            stage.commit()
    assert _tree(out) == {"basis.json": b"the last good run"}
    assert _tree(home) == before
    assert not staged.exists() or staged.is_symlink()  # never re-made


# -- commands writing under exports/<profile> share one lock ---------------------------------------
def test_basis_paused_while_design_publishes_loses_nothing(tmp_path, monkeypatch):
    """The reproduction: `basis` paused inside its publication (its images staged, basis.json not
    yet), `design` run meanwhile, then `basis` resumed. Both publish everything they report: design
    waits for basis's lock instead of swapping the folder under it."""
    from rigcad import cli, progress
    from rigcad.export import atomic

    exports = tmp_path / "exports"
    paused, resume, design_moved = threading.Event(), threading.Event(), threading.Event()
    waits: list[str] = []
    real_progress = progress.stages

    @contextmanager
    def pausing_progress(total, desc):
        with real_progress(total, desc) as step:
            def pausing(label: str) -> None:
                step(label)
                if label == "Z_0^0 written":  # basis: inside its staging, the images written
                    paused.set()
                    assert resume.wait(timeout=HANG_S), "never resumed"
            yield pausing

    def waiting(message: str) -> None:
        waits.append(message)
        design_moved.set()

    monkeypatch.setattr(progress, "stages", pausing_progress)
    monkeypatch.setattr(atomic, "_say_waiting", waiting, raising=False)
    codes: dict[str, int] = {}

    def run(name: str, argv: list[str]) -> None:
        try:
            codes[name] = cli.main(argv)
        finally:
            if name == "design":
                design_moved.set()  # finished (or failed) without waiting
            paused.set()  # a basis that ends before its pause must not leave the test waiting

    basis = threading.Thread(target=run, args=("basis", ["basis", "achutha2006", "--order", "0",
                                                         "--exports", str(exports)]))
    basis.start()
    assert paused.wait(timeout=HANG_S)
    assert "basis" not in codes, "basis ended before its pause"
    design = threading.Thread(target=run, args=("design", ["design", "achutha2006", "--exports", str(exports)]))
    design.start()
    assert design_moved.wait(timeout=HANG_S)
    resume.set()
    basis.join(timeout=HANG_S)
    design.join(timeout=HANG_S)
    assert codes == {"basis": 0, "design": 0}, codes
    out = exports / "achutha2006"
    report = json.loads((out / "basis" / "basis.json").read_text())
    missing = [f for f in report["files"] if not (out / "basis" / f).is_file()]
    assert report["files"] and not missing, f"{len(missing)} of {len(report['files'])} listed files missing: {missing}"
    assert all((out / f).is_file() for f in ("design.json", "dome_profile.csv", "rays.png", "incidence.png"))
    assert waits and "achutha2006.lock" in waits[0], waits  # design waited for basis, under one lock
    assert not (out / ".basis.lock").exists()
    assert [p.name for p in exports.rglob("*") if ".new-" in p.name or ".old-" in p.name] == []


# -- links in the exports: publication never reaches through one ------------------------------------
def test_a_linked_profile_folder_is_refused_and_its_target_untouched(tmp_path, capsys):
    from rigcad.cli import main

    home, before = _outside(tmp_path)
    exports = tmp_path / "exports"
    exports.mkdir()
    (exports / "achutha2006").symlink_to(home, target_is_directory=True)
    code = main(["design", "achutha2006", "--exports", str(exports)])
    line = _one_line(capsys.readouterr().err)
    assert code != 0 and "achutha2006 is a symbolic link" in line, line
    assert _tree(home) == before, "the folder the link names changed"
    assert {p.name for p in exports.iterdir()} <= {".achutha2006.lock", "achutha2006"}  # no .old-* left
    assert (exports / "achutha2006").is_symlink()


@pytest.mark.parametrize("linked", ["rig", "rig/fab", "rig/fab/mk4"])
def test_a_link_between_the_exports_root_and_a_result_folder_is_refused(tmp_path, linked):
    """A result folder (exports/rig/fab/mk4) is published under the profile's lock: a link anywhere
    from exports/ down to it is refused; what the link names stays as it was."""
    home, before = _outside(tmp_path)
    exports = tmp_path / "exports"
    link = exports / linked
    link.parent.mkdir(parents=True)
    link.symlink_to(home, target_is_directory=True)
    out = exports / "rig" / "fab" / "mk4"
    with pytest.raises(ExportError, match="is a symbolic link"):
        with Staging(out, profile_lock(exports, "rig")) as stage:
            stage.write_bytes(out / "fab.json", b"{}")
            stage.commit()
    assert _tree(home) == before
    assert link.is_symlink() and not list(exports.rglob(".*.new-*")) and not list(exports.rglob(".*.old-*"))


def test_links_inside_the_exports_are_not_carried_through(tmp_path):
    """A link inside exports/<profile> (to a file or a folder outside) is not followed when the
    folder's other files are carried into the new one: nothing outside gets a name in the exports."""
    home, before = _outside(tmp_path)
    out = tmp_path / "exports" / "rig"
    out.mkdir(parents=True)
    (out / "kept.txt").write_text("kept")
    (out / "secret.txt").symlink_to(home / "precious.txt")
    (out / "notes").symlink_to(home / "notes", target_is_directory=True)
    (out / ".x.tmp").symlink_to(home / "precious.txt")  # a leftover name: the link goes, not its target
    old_tree = out.parent / ".rig.old-1234"  # what an old run left when it swapped a linked folder away
    old_tree.symlink_to(home, target_is_directory=True)
    with Staging(out) as stage:
        stage.write_bytes(out / "new.txt", b"new")
        stage.commit()
    assert _tree(out) == {"kept.txt": b"kept", "new.txt": b"new"}
    assert not os.path.lexists(old_tree)
    inodes = {os.stat(p).st_ino for p in home.rglob("*")}
    assert not any(os.lstat(p).st_ino in inodes for p in out.rglob("*")), "an outside file was linked in"
    assert _tree(home) == before


# -- results of another profile are not carried into a new build -----------------------------------
def _result(exports: Path, rel: str, digest: str | None, files=("r.json",)) -> None:
    """Publish a result folder as the commands do (made_from: the profile it was made from)."""
    out = exports / "rig" / rel
    with Staging(out, profile_lock(exports, "rig"), made_from=digest) as stage:
        for name in files:
            stage.write_bytes(out / name, f"{rel} made from {digest}".encode())
        stage.commit()


def test_a_build_of_a_changed_profile_removes_the_older_results(tmp_path, capsys):
    """Results record the profile they were made from; a build of another profile removes those of
    an older one (and those with no record), says so on stderr, lists them in manifest.json, and
    keeps those made from the profile it builds."""
    from rigcad.cli import main
    from rigcad.export.manifest import profile_digest
    from rigcad.profile import load_profile

    exports = tmp_path / "exports"
    a = _profile(tmp_path / "a")
    b = _profile(tmp_path / "b", "beam:\n  width: 5 mm\n")
    da, db = profile_digest(load_profile(a)), profile_digest(load_profile(b))
    assert main(["build", str(a), "--parts", "beam", "--exports", str(exports)]) == 0
    for rel in ("check", "basis", "tolerance", "fab/mk4", "manual/mk4"):
        _result(exports, rel, da)
    _result(exports, "fab/mini", db)  # made from the new profile already
    _result(exports, "view", db)
    legacy = exports / "rig" / "fab" / "old"  # a result without a record (an older rigcad's)
    legacy.mkdir()
    (legacy / "fab.json").write_text("{}")
    (exports / "rig" / "sweep" / "beam.width").mkdir(parents=True)  # not a result folder rigcad vouches for
    (exports / "rig" / "sweep" / "beam.width" / "sweep.json").write_text("{}")
    capsys.readouterr()
    assert main(["build", str(b), "--parts", "beam", "--exports", str(exports)]) == 0
    err = capsys.readouterr().err
    out = exports / "rig"
    removed = ["basis", "check", "fab/mk4", "fab/old", "manual/mk4", "tolerance"]
    for rel in removed:
        assert not (out / rel).exists(), rel
        assert f"rigcad: removed {rel}/" in err, err
    assert f"made from profile sha256 {da[:12]}" in err and "no record of the profile" in err, err
    assert (out / "fab" / "mini" / "r.json").read_bytes() == f"fab/mini made from {db}".encode()
    assert (out / "view" / "r.json").is_file() and (out / "sweep" / "beam.width" / "sweep.json").is_file()
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["profile"]["sha256"] == db
    assert manifest["stale_results_removed"] == [
        {"folder": rel, "made_from_profile_sha256": None if rel == "fab/old" else da} for rel in removed]
    assert not (out / "check.made_from.json").exists() and (out / "view.made_from.json").is_file()


def test_a_result_command_records_its_profile_and_a_new_design_removes_it(tmp_path, capsys):
    """`rigcad check` (a real run) records the profile it was made from; after the profile changes,
    `rigcad design` publishes the folder without it."""
    from rigcad.cli import main
    from rigcad.export.atomic import read_made_from
    from rigcad.export.manifest import profile_digest
    from rigcad.profile import load_profile

    exports = tmp_path / "exports"
    a = _profile(tmp_path / "a")
    b = _profile(tmp_path / "b", "beam:\n  width: 5 mm\n")
    main(["check", str(a), "--mode", "analytic", "--rays", "400", "--no-monte-carlo", "--exports", str(exports)])
    out = exports / "rig"
    assert (out / "check" / "raycheck.json").is_file()
    assert read_made_from(out / "check") == profile_digest(load_profile(a))
    assert main(["design", str(a), "--exports", str(exports)]) == 0  # the same profile: kept
    assert (out / "check" / "raycheck.json").is_file()
    capsys.readouterr()
    assert main(["design", str(b), "--exports", str(exports)]) == 0
    assert "rigcad: removed check/" in capsys.readouterr().err
    assert not (out / "check").exists() and (out / "design.json").is_file()


def test_a_result_folder_does_not_carry_files_of_another_profile(tmp_path):
    """A result run carries its folder's untouched files only when they were made from the same
    profile: a file an older run wrote (say theta_map.png, not written this time) does not survive
    into results stamped with a new profile."""
    exports = tmp_path / "exports"
    _result(exports, "check", "a" * 64, files=("raycheck.json", "theta_map.png"))
    _result(exports, "check", "a" * 64, files=("raycheck.json",))
    assert (exports / "rig" / "check" / "theta_map.png").is_file()  # same profile: carried
    _result(exports, "check", "b" * 64, files=("raycheck.json",))
    assert sorted(p.name for p in (exports / "rig" / "check").iterdir()) == ["raycheck.json"]


def test_stl_removes_results_of_an_older_profile_even_when_up_to_date(tmp_path, capsys):
    """The reported case: after the profile changed, `rigcad stl` rebuilt, and the old check/ and
    fab/ results moved into the new folder unmarked. Now they are removed; and a result of another
    profile published after an up-to-date build makes the next `stl` publish again, without it."""
    from rigcad.cli import main
    from rigcad.export.manifest import profile_digest
    from rigcad.profile import load_profile

    exports = tmp_path / "exports"
    out = exports / "rig"
    a = _profile(tmp_path / "a")
    b = _profile(tmp_path / "b", "beam:\n  width: 5 mm\n")  # rebuilds the beam only
    da = profile_digest(load_profile(a))
    assert main(["stl", str(a), "--exports", str(exports)]) == 0
    _result(exports, "check", da)
    _result(exports, "fab/mk4", da)
    capsys.readouterr()
    assert main(["stl", str(b), "--exports", str(exports)]) == 0
    err = capsys.readouterr().err
    assert "rigcad: removed check/" in err and "rigcad: removed fab/mk4/" in err, err
    assert not (out / "check").exists() and not (out / "fab" / "mk4").exists()
    assert [r["folder"] for r in json.loads((out / "manifest.json").read_text())["stale_results_removed"]] == [
        "check", "fab/mk4"]
    _result(exports, "tolerance", da)  # a run of the older profile, published after the build
    assert main(["stl", str(b), "--exports", str(exports)]) == 0
    text = capsys.readouterr()
    assert "up to date" not in text.out and "rigcad: removed tolerance/" in text.err, text
    assert not (out / "tolerance").exists()
    assert main(["stl", str(b), "--exports", str(exports)]) == 0
    assert "up to date" in capsys.readouterr().out
