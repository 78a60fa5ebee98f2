"""Reading back what a stage published instead of computing it again.

A result folder (``fab/<printer>/``, ...) records, inside it, the key of the inputs it was made
from and the SHA-256 of every file its run wrote (:data:`RECORD`). A later run of the stage whose
key is the same reads the folder back, under the folder's lock, when every recorded file is still
there, a plain file, unchanged, and the folder still records the profile it was made from
(export.atomic.read_made_from); otherwise it computes and publishes as before. The key follows
``rigcad stl``'s manifest (export.manifest.inputs_key: the resolved profile and all of rigcad's
code), with whatever else the stage reads folded in by the stage (:func:`stage_key`).

Whichever command published a result (``rigcad fab``, ``rigcad manual``, the API), every other
reads it back alike: the record lives with the result, not with the command. A stage whose writer
is not its own (``check``, ``view``, ``manual``, ``calibrate --kit``) records through
:func:`recording`, around whichever writer publishes its folder, and asks :func:`read_back` first.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import stat
from pathlib import Path

from rigcad.export.atomic import Staging, before_commit, hold_lock, json_bytes, read_made_from
from rigcad.errors import ExportError
from rigcad.export.manifest import code_version, profile_digest, sha256_hex
from rigcad.export.readback import parse_json

#: The record inside a result folder: ``{"inputs_key": ..., "files": {relative path: sha256}}``.
RECORD = "published.json"


def stage_key(profile, stage: str, inputs: dict) -> str:
    """The key of a stage's result: what the manifest's inputs key holds (the resolved profile and
    rigcad's code), the stage's name and ``inputs`` (JSON-able: whatever else it reads)."""
    text = json.dumps({"stage": stage, "inputs": inputs}, sort_keys=True, default=repr)
    return sha256_hex(f"{profile_digest(profile)}|{running_code()}|{text}".encode())


@functools.lru_cache(maxsize=1)
def running_code() -> str:
    """export.manifest.code_version of all of rigcad's code, hashed once per process: the code a
    process runs is the code it started with, so a source file saved while it runs (an editor, a
    checkout) changes the key of the next process, not of this one's second stage."""
    return code_version("**/*.py")


def input_files(paths: dict[str, Path]) -> dict[str, str | None]:
    """For a stage's key: the SHA-256 of each file a stage reads besides the profile (by name;
    None for a file that is not there, or not a plain file)."""
    digests = {}
    for name, path in sorted(paths.items()):
        try:
            digests[name] = sha256_hex(_read_plain(Path(path)))
        except OSError:
            digests[name] = None
    return digests


@contextlib.contextmanager
def recording(folder: Path, key: str | None, summary: dict | None = None):
    """Within the block, the run publishing ``folder`` (an export.atomic.Staging, whichever writer
    makes it) publishes :data:`RECORD` with it: ``key``, the SHA-256 of every file the run staged,
    and ``summary`` (JSON: what the command says of a result read back). ``key`` None: nothing
    recorded (a result that must never be read back: a moved rig, a run with problems)."""
    if key is None:
        yield
        return
    with before_commit(Path(folder), lambda stage: record(stage, Path(folder), key, summary)):
        yield


def record(stage: Staging, folder: Path, key: str, summary: dict | None = None) -> None:
    """Stage :data:`RECORD` into ``folder``: ``key`` and the SHA-256 of every file this run has
    staged so far (the files of an earlier run carried over at commit are not vouched for), and
    ``summary`` when given."""
    staged = stage.temp_path(Path(folder))
    files = {}
    for dirpath, _, filenames in os.walk(staged):
        for name in filenames:
            path = Path(dirpath) / name
            files[path.relative_to(staged).as_posix()] = sha256_hex(path.read_bytes())
    files.pop(RECORD, None)  # a record never vouches for itself
    rec = {"inputs_key": key, "files": dict(sorted(files.items()))}
    if summary is not None:
        rec["summary"] = summary
    stage.write_bytes(Path(folder) / RECORD, json_bytes(rec))


def carried(rel: Path) -> bool:
    """For Staging's ``carry``: an earlier run's record is never carried into a run that does not
    write its own (it would vouch for files this run replaced)."""
    return Path(rel) != Path(RECORD)


def read_back(folder: Path, key: str, made_from: str, lock: Path, read: tuple[str, ...] = ()) -> dict[str, bytes] | None:
    """The published result in ``folder`` when its record's key is ``key``, it records the profile
    ``made_from`` and every file it lists is intact: the bytes of the files named in ``read``
    (each among the listed ones; :data:`RECORD` itself for the record, with its ``summary``), all
    read under ``lock``, so that no writer replaces the folder meanwhile. None when anything
    differs or is missing: the stage then runs."""
    folder = Path(folder)
    if folder.is_symlink() or not _plain(folder / RECORD):
        return None  # nothing published with a record: no lock taken, nothing created
    held = hold_lock(lock)
    try:
        if read_made_from(folder) != made_from:
            return None
        try:
            raw = _read_plain(folder / RECORD)
            rec = parse_json(raw, str(folder / RECORD))
        except (OSError, ExportError):  # unreadable, or not JSON rigcad could have written (a nesting bomb)
            return None
        if not isinstance(rec, dict):
            return None
        files = rec.get("files")
        if rec.get("inputs_key") != key or not isinstance(files, dict) or not files \
                or any(name not in files and name != RECORD for name in read):
            return None
        out = {RECORD: raw} if RECORD in read else {}
        for rel, digest in files.items():
            try:
                data = _read_plain(folder / rel)
            except OSError:
                return None
            if sha256_hex(data) != digest:
                return None
            if rel in read:
                out[rel] = data
        return out
    finally:
        held.release()


def _plain(path: Path) -> bool:
    """True when ``path`` is a plain file (not a link, not missing)."""
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def _read_plain(path: Path) -> bytes:
    """The bytes of the plain file ``path``; a link or anything else raises OSError (never followed)."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(f"{path} is not a plain file")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            return fh.read()
    finally:
        os.close(fd)
