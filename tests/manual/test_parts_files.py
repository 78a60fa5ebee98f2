"""The manual refers to files it does not write (the parts' STEP and STL: ``rigcad stl``; the 3D view:
``rigcad view``): its text gives their paths from the manual's own folder and the command that writes
each, and ``rigcad manual`` says when the parts are missing or not made from the profile
(rigcad.manual.document.parts_text, parts_note)."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

from rigcad.manual import document as D


def test_the_paths_the_manual_gives_resolve_from_its_own_folder():
    text = D.parts_text("achutha2006", "prusa_mk3s")
    manual = Path("exports/achutha2006/manual/prusa_mk3s")
    paths = re.findall(r"`(\.\./\.\./[^`]+)`", text)
    assert paths, text
    where = {os.path.normpath(manual / p) for p in paths}
    for folder in (*D.PARTS_FOLDERS, "fab/prusa_mk3s", "view"):
        assert any(w == os.path.normpath(f"exports/achutha2006/{folder}") or
                   w.startswith(os.path.normpath(f"exports/achutha2006/{folder}") + os.sep) for w in where), (folder, where)
    # and the command that writes each
    for command in ("`rigcad stl achutha2006`", "`rigcad view achutha2006`", "`rigcad fab achutha2006 --printer prusa_mk3s`"):
        assert command in text, command


def _export(root: Path, profile) -> Path:
    """A one-file export of ``profile`` as ``rigcad stl`` records it: manifest.json with the inputs' key
    (the resolved profile and rigcad's code) and the file's SHA-256."""
    from rigcad.export.manifest import inputs_key, sha256_hex

    folder = root / profile.name
    (folder / "step").mkdir(parents=True)
    data = b"ISO-10303-21; a part\n"
    (folder / "step" / "dome.step").write_bytes(data)
    manifest = {"inputs_key": inputs_key(profile), "parts": {"dome": {"files": {"step/dome.step": sha256_hex(data)}}}}
    (folder / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    return folder


def test_the_note_says_when_the_parts_are_missing_and_not_when_they_are_current(table31, tmp_path):
    note = D.parts_note(table31, tmp_path)
    assert note is not None and "missing" in note and f"rigcad stl achutha2006 --exports {tmp_path}" in note
    for folder in D.PARTS_FOLDERS:
        assert f"{tmp_path / 'achutha2006' / folder}/" in note
    # written for this profile by this code, intact: no note
    folder = _export(tmp_path, table31)
    assert D.parts_note(table31, tmp_path) is None
    # a file changed since: named, not as missing
    (folder / "step" / "dome.step").write_bytes(b"edited")
    note = D.parts_note(table31, tmp_path)
    assert note is not None and "not made from this profile" in note, note


def test_another_profiles_parts_are_not_current(table31, tmp_path, write_profile, table31_text):
    from rigcad.profile import load_profile

    other = load_profile(write_profile(table31_text + "sample_holder:\n  sample_thickness: 2 mm\n", "achutha2006"))
    _export(tmp_path, other)
    assert D.parts_note(other, tmp_path) is None
    assert "not made from this profile" in D.parts_note(table31, tmp_path)
