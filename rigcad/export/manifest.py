"""manifest.json: what a build wrote, from which inputs, with each file's SHA-256; and the quick
check that lets `make stl` return at once when nothing changed. Deliberately light: it imports
nothing numerical, so the no-change path costs a YAML read and a few file hashes."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from rigcad._version import __version__

PACKAGE = Path(__file__).resolve().parents[1]


def code_version(*globs: str) -> str:
    """Hash of rigcad's source files matching ``globs`` (relative to the package), so that a changed
    writer invalidates what it wrote without anyone remembering to bump a number."""
    h = hashlib.sha256(__version__.encode())
    paths = sorted({p for g in globs for p in PACKAGE.glob(g)})
    for path in paths:
        h.update(str(path.relative_to(PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def profile_digest(profile) -> str:
    """SHA-256 of the resolved parameters (units inside, so '27 cm' and '270 mm' agree)."""
    return hashlib.sha256(json.dumps(profile.as_dict(), sort_keys=True, default=repr).encode()).hexdigest()


def inputs_key(profile) -> str:
    """Everything `make stl` depends on: the resolved profile and all of rigcad's code."""
    return hashlib.sha256(f"{profile_digest(profile)}|{code_version('**/*.py')}".encode()).hexdigest()


def sha256_hex(data: bytes) -> str:
    """SHA-256 of ``data``, hexadecimal: how every written file is recorded in a report."""
    return hashlib.sha256(data).hexdigest()


def file_sha(path: Path) -> str | None:
    """:func:`sha256_hex` of the file at ``path``; None if there is none. Read in blocks
    (hashlib.file_digest), not whole: an up-to-date `make stl` hashes every file it vouches for
    (42 MB for the thesis's rig), and reading each into one bytes object took twice as long."""
    if not path.is_file():
        return None
    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def listed_files(manifest: dict) -> dict[str, str]:
    """Every file a manifest vouches for, relative path -> SHA-256."""
    files: dict[str, str] = dict(manifest.get("design_files") or {})
    for group in ("parts", "mirrors"):
        for entry in (manifest.get(group) or {}).values():
            files.update(entry.get("files", {}))
    if manifest.get("assembly"):
        files.update(manifest["assembly"].get("files", {}))
    return files


def up_to_date(out: Path, key: str) -> bool:
    """True when ``out/manifest.json`` was written from inputs ``key`` and every file it lists is
    still there, unchanged."""
    from rigcad.export.readback import own_json

    manifest = own_json(out / "manifest.json")  # read as data: an unreadable one means "rebuild"
    if not isinstance(manifest, dict) or manifest.get("inputs_key") != key:
        return False
    files = listed_files(manifest)
    return bool(files) and all(file_sha(out / rel) == digest for rel, digest in files.items())
