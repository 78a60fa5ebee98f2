"""Whole-run publication: a killed or failing run never leaves half a run behind; the manifest
always describes exactly the files beside it; the next run cleans what a killed one left; two
runs on one folder do not interleave; a full disk is one line, exit 1, old exports untouched."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from rigcad.export.atomic import Staging, hold_lock
from rigcad.export.manifest import listed_files
from rigcad.check.criteria import KEPT_FILE as CRITERIA_FILE
from rigcad.manual.gate import VERDICT_FILE

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

#: Coarse tessellations keep each cold build to a few seconds; the publication logic does not
#: depend on them.
FAST = """extends: achutha2006
tessellation:
  chord_error: 0.03 mm
  mirror_chord_error: 0.02 mm
  mirror_normal_error: 0.05 rad
"""


def _profile(folder: Path, extra: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "rig.yaml"
    path.write_text(FAST + extra)
    return path


#: Records kept beside the export outside any run's manifest (the assembly check's verdict, the ray
#: check's cheap criteria), written whole (atomically) after the parts are published: each carries the
#: key of the profile and code that made it and is read back only under that key
#: (rigcad.manual.gate.read_verdict, rigcad.check.criteria.kept_rows), so none is read as another run's.
KEPT = {VERDICT_FILE: "inputs_key", CRITERIA_FILE: "key"}


def _consistent(out: Path) -> list[str]:
    """Files the manifest lists that do not match it, files it does not list (besides the kept
    records, :data:`KEPT`), and kept records that are not whole or carry no key. Empty: the folder
    is one run's output."""
    manifest = json.loads((out / "manifest.json").read_text())
    listed = listed_files(manifest)
    bad = [rel for rel, digest in listed.items()
           if not (out / rel).is_file() or hashlib.sha256((out / rel).read_bytes()).hexdigest() != digest]
    present = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    bad += sorted(present - set(listed) - {"manifest.json"} - set(KEPT))
    for name, key in KEPT.items():
        if (out / name).is_file():
            try:
                doc = json.loads((out / name).read_text())
            except ValueError:
                doc = None
            if not (isinstance(doc, dict) and isinstance(doc.get(key), str)):
                bad.append(name)
    return bad


def _leftovers(exports: Path) -> list[Path]:
    return [p for p in exports.rglob("*") if ".new-" in p.name or ".old-" in p.name or p.name.endswith(".tmp")]


def _stl(profile: Path, exports: Path, env=None, **kw):
    return subprocess.Popen([sys.executable, "-m", "rigcad", "stl", str(profile), "--exports", str(exports)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, **kw)


#: Where the runs of the changed profile are killed: its own progress events, from the design
#: stage to the moment it starts publishing (the mirror parts rebuild; the others are unchanged).
KILL_AT = ("dome integrated", "paraboloid", "tower_column", "publishing")


@pytest.mark.slow  # six `rigcad stl` processes (already at the coarsest tessellation): the default run's longest test
def test_a_killed_stl_never_publishes_half_a_run(tmp_path):
    """A good build of one profile, then builds of a changed one (every mirror part rebuilds)
    killed with SIGKILL at its progress events, the last one just as it starts publishing. After
    each kill every file matches the manifest beside it; the next run completes and leaves no
    temporary file."""
    exports = tmp_path / "exports"
    good = _profile(tmp_path / "a")
    assert _stl(good, exports).wait(timeout=600) == 0
    out = exports / "rig"
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    changed = _profile(tmp_path / "b", "coating:\n  layers:\n"
                       + "".join(f"    - {{name: {n}, thickness: 2 mil}}\n" for n in (
                           "black base paint", "polyurethane primer", "polyurethane clearcoat", "MirraChrome")))
    env = {**os.environ, "RIGCAD_EVENTS": "1"}
    for event in KILL_AT:
        run = _stl(changed, exports, env=env)
        seen = []
        for line in run.stderr:
            if line.startswith("rigcad-event: "):
                seen.append(line.split(": ", 1)[1].strip())
                if seen[-1] == event:
                    run.send_signal(signal.SIGKILL)
                    break
        run.wait(timeout=600)
        assert seen[-1] == event, f"the run ended before the event {event!r}: {seen}"
        # publishing takes milliseconds: the kill sent at its event may land during it or after it
        assert run.returncode == -signal.SIGKILL or (event == "publishing" and run.returncode == 0), event
        assert _consistent(out) == [], f"killed at {event!r}: {_consistent(out)}"
        now = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
        assert now == before or _consistent(out) == [], event  # the old run, or the whole new one
    done = _stl(changed, exports)
    assert done.wait(timeout=600) == 0, done.stderr.read()
    assert _consistent(out) == [] and _leftovers(exports) == []
    assert json.loads((out / "manifest.json").read_text())["layout"]["coating_total_mm"] == pytest.approx(8 * 0.0254)


def _write_counter(monkeypatch, fail_at: int, code=errno.ENOSPC):
    """Make the fail_at-th staged write raise OSError(code), as a full disk would."""
    count = {"n": 0}
    real = Staging.write_with

    def write_with(self, path, writer):
        count["n"] += 1
        if count["n"] == fail_at:
            def failing(tmp):
                Path(tmp).write_bytes(b"partial")  # a disk fills mid-file
                raise OSError(code, os.strerror(code), str(tmp))
            return real(self, path, failing)
        return real(self, path, writer)

    monkeypatch.setattr(Staging, "write_with", write_with)
    return count


def test_a_full_disk_at_any_write_is_one_line_and_the_old_exports_stay(tmp_path, monkeypatch, capsys):
    from rigcad.cli import main

    exports = tmp_path / "exports"
    profile = _profile(tmp_path / "a")
    assert main(["build", str(profile), "--parts", "beam", "paraboloid", "--exports", str(exports)]) == 0
    out = exports / "rig"
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    changed = _profile(tmp_path / "b", "beam:\n  width: 5 mm\n")  # rebuilds both parts
    counter = _write_counter(monkeypatch, fail_at=10**9)
    capsys.readouterr()
    shutil.copytree(exports, tmp_path / "count")  # the same starting state: the same writes
    assert main(["build", str(changed), "--parts", "beam", "paraboloid", "--exports", str(tmp_path / "count")]) == 0
    writes = counter["n"]
    assert writes >= 9  # STEP, STL, 3MF, PNG per part, PLY, rig.step, manifest: every writer is reached
    for k in range(1, writes + 1):
        _write_counter(monkeypatch, fail_at=k)
        capsys.readouterr()
        code = main(["build", str(changed), "--parts", "beam", "paraboloid", "--exports", str(exports)])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 1, (k, err)
        assert len(err) == 1 and "no space left on the device" in err[0] and "cannot write" in err[0], (k, err)
        assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before, k
        assert _leftovers(exports) == [], k


def test_read_only_folder_is_one_line(tmp_path, monkeypatch, capsys):
    from rigcad.cli import main

    _write_counter(monkeypatch, fail_at=1, code=errno.EROFS)
    code = main(["build", str(_profile(tmp_path / "a")), "--parts", "beam", "--exports", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1 and "read-only file system" in err[0], err


def test_stale_leftovers_of_a_killed_run_are_removed_by_the_next(tmp_path):
    out = tmp_path / "exports" / "rig"
    out.mkdir(parents=True)
    (out / "keep.txt").write_text("the last good run")
    stale = [tmp_path / "exports" / ".rig.new-abc123", tmp_path / "exports" / ".rig.old-999"]
    for d in stale:
        d.mkdir()
        (d / "half.step").write_text("half")
    (out / ".design.json.x1y2.tmp").write_text("half")
    with Staging(out) as stage:
        stage.write_bytes(out / "new.txt", b"new")
        stage.commit()
    assert not any(d.exists() for d in stale) and not (out / ".design.json.x1y2.tmp").exists()
    assert (out / "keep.txt").read_text() == "the last good run" and (out / "new.txt").read_bytes() == b"new"


def test_an_up_to_date_run_removes_what_a_run_killed_while_publishing_left(tmp_path):
    """Killed after its exchange, while deleting the old tree, a run leaves its new folder complete
    and an .old- sibling: the next `rigcad stl` finds the folder up to date and publishes nothing,
    so it removes the sibling itself (rigcad.export.atomic.tidy), under the profile's lock."""
    from rigcad.export.atomic import tidy

    exports = tmp_path / "exports"
    out = exports / "rig"
    out.mkdir(parents=True)
    lock = exports / ".rig.lock"
    assert tidy(out, lock) == [] and not lock.exists()  # nothing to remove: no lock taken
    old = exports / ".rig.old-85ub6_oa"
    old.mkdir()
    (old / "dome.step").write_text("the previous run, half deleted")
    assert tidy(out, lock) == [old] and not old.exists() and out.is_dir()


def test_a_second_run_waits_for_the_first_and_says_who_holds_the_lock(tmp_path):
    lock = tmp_path / ".rig.lock"
    held = hold_lock(lock)
    said, reported, done = [], threading.Event(), threading.Event()

    def say(msg):
        said.append(msg)
        reported.set()

    def second():
        h = hold_lock(lock, say=say)
        done.set()
        h.release()

    t = threading.Thread(target=second)
    t.start()
    # the second run says who holds the lock before it blocks; 60 s is a hang guard, not a timing
    assert reported.wait(timeout=60), "the second run never said it was waiting"
    # while the first holds the lock the second cannot go ahead, however long we look: a correct lock
    # never fails this; a lock that does not block fails it (0.5 s for the thread to get there)
    assert not done.wait(timeout=0.5), "the second run went ahead while the first held the lock"
    assert said and f"pid {os.getpid()}" in said[0] and str(lock) in said[0], said
    held.release()
    t.join(timeout=10)
    assert done.is_set()
