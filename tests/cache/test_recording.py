"""The published record every stage shares (rigcad.export.reuse.recording and read_back), on a toy
writer: whichever writer publishes a folder inside ``recording`` publishes the record with its files;
a later read back with the same key returns them with nothing written, and a changed key, a missing
or edited file, or another profile's folder is no record at all."""

from __future__ import annotations

import json
import os
from pathlib import Path

from rigcad.export import reuse
from rigcad.export.atomic import Staging

MADE_FROM = "a" * 64


def _write(folder: Path, files: dict[str, bytes], made_from: str = MADE_FROM) -> list[Path]:
    """A writer that knows nothing of records, as a stage's writer is (rigcad.manual.view, ...)."""
    with Staging(folder, made_from=made_from) as stage:
        for name, data in files.items():
            stage.write_bytes(folder / name, data)
        return stage.commit()


def _back(folder: Path, key: str, read=()):
    return reuse.read_back(folder, key, MADE_FROM, folder.parent / f".{folder.name}.lock", read=read)


def _state(folder: Path) -> dict[str, tuple]:
    """Each file's bytes, inode and mtime: a rewrite changes the inode (Staging publishes a new tree)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            st = p.stat()
            out[p.relative_to(folder).as_posix()] = (p.read_bytes(), st.st_ino, st.st_mtime_ns)
    return out


def test_a_recorded_run_reads_back_with_its_summary_and_writes_nothing(tmp_path):
    out = tmp_path / "check"
    with reuse.recording(out, "key-1", {"notes": ["one"]}):
        _write(out, {"a.json": b"{}", "sub/b.png": b"png"})
    rec = json.loads((out / reuse.RECORD).read_text())
    assert rec["inputs_key"] == "key-1" and sorted(rec["files"]) == ["a.json", "sub/b.png"]  # not itself
    assert rec["summary"] == {"notes": ["one"]}
    before = _state(out)
    back = _back(out, "key-1", read=("a.json", reuse.RECORD))
    assert back["a.json"] == b"{}" and json.loads(back[reuse.RECORD])["summary"] == {"notes": ["one"]}
    assert _state(out) == before  # read back: not one file rewritten


def test_another_key_or_another_profile_is_no_record(tmp_path):
    out = tmp_path / "view"
    with reuse.recording(out, "key-1"):
        _write(out, {"rig.html": b"<html>"})
    assert _back(out, "key-2") is None  # a changed input (profile key, option, code, input file)
    assert reuse.read_back(out, "key-1", "b" * 64, tmp_path / ".view.lock") is None  # made from another profile
    assert _back(out, "key-1") is not None


def test_a_missing_or_edited_file_is_no_record(tmp_path):
    out = tmp_path / "kit"
    with reuse.recording(out, "k"):
        _write(out, {"a.png": b"\x00\x01", "b.stl": b"solid"})
    (out / "a.png").write_bytes(b"\x00\x00")  # one bit
    assert _back(out, "k") is None
    with reuse.recording(out, "k"):
        _write(out, {"a.png": b"\x00\x01", "b.stl": b"solid"})
    assert _back(out, "k") is not None
    (out / "b.stl").unlink()
    assert _back(out, "k") is None
    os.symlink(tmp_path / "elsewhere", out / "b.stl")  # a link in a file's place is not the file
    assert _back(out, "k") is None


def test_a_run_without_a_key_records_nothing_and_other_folders_are_not_recorded(tmp_path):
    out, other = tmp_path / "manual", tmp_path / "other"
    with reuse.recording(out, None):  # a run that must never be read back (problems, a moved rig)
        _write(out, {"manual.md": b"# m"})
    assert not (out / reuse.RECORD).exists()
    with reuse.recording(out, "k"):
        _write(other, {"x": b"1"})  # only the folder named is recorded
    assert not (other / reuse.RECORD).exists()
    _write(out, {"manual.md": b"# m"})  # outside the block: as before
    assert not (out / reuse.RECORD).exists()


def test_a_carried_record_never_vouches_for_files_another_run_replaced(tmp_path):
    out = tmp_path / "check"
    with reuse.recording(out, "k"):
        _write(out, {"raycheck.json": b"1", "spot.png": b"p"})
    _write(out, {"raycheck.json": b"2"})  # a run with other options, unrecorded: the old record is carried
    assert _back(out, "k") is None  # the old key's record does not hold for the new file
