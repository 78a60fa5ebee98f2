"""Where profiles are found, and how their files are named in messages and outputs.

A profile given by name is looked up, first match wins, in the working directory's ``profiles/``,
in each folder of ``$RIGCAD_PROFILES`` (``os.pathsep``-separated) and in the profiles shipped with
rigcad (:data:`SHIPPED_PROFILES`). Printers are the same with ``printers/`` below each folder, and
instruments (projectors, cameras, lenses, splitters) with ``instruments/``.

The shipped profiles live at the top of the repository, ``profiles/``, where people edit them; a
wheel carries the same files inside the package as ``rigcad/profiles/`` (pyproject.toml maps the
one folder onto the other). Either way a shipped file is named ``profiles/<name>.yaml``, so
messages point at the file to edit and outputs do not depend on where rigcad is installed.

Standard library only: ``rigcad fab --help`` lists the printers without importing YAML or numpy.
"""

from __future__ import annotations

import os
from pathlib import Path

#: Environment variable naming extra profile folders, ``os.pathsep``-separated.
PROFILES_ENV = "RIGCAD_PROFILES"
#: How a shipped profile's folder is named in messages and outputs.
SHIPPED_NAME = "profiles"
#: Printer files live in this folder under each folder of the profile search path.
PRINTERS_SUBDIR = "printers"
#: Instrument files (one YAML per projector, camera, lens, splitter) live in this folder under each
#: folder of the profile search path.
INSTRUMENTS_SUBDIR = "instruments"


def _shipped_folder() -> Path:
    """The shipped profiles: inside the package in an installed wheel (``rigcad/profiles``), else the
    repository's top-level ``profiles/`` beside the package (a checkout: editable install, PYTHONPATH)."""
    package = Path(__file__).resolve().parents[1]
    inside = package / SHIPPED_NAME
    return inside if inside.is_dir() else package.parent / SHIPPED_NAME


#: The profiles shipped with rigcad (rig profiles; printers under ``printers/``).
SHIPPED_PROFILES = _shipped_folder()


def search_path(sub: str = "") -> list[Path]:
    """Folders searched for a profile given by name, first match wins: ``./profiles``, each folder
    of ``$RIGCAD_PROFILES``, the shipped profiles; ``sub`` (e.g. ``printers``) is appended to each."""
    dirs = [Path("profiles")]
    dirs += [Path(p) for p in os.environ.get(PROFILES_ENV, "").split(os.pathsep) if p]
    dirs.append(SHIPPED_PROFILES)
    return [d / sub if sub else d for d in dirs]


def names_on_search_path(sub: str = "") -> list[str]:
    """The names (file stems) of the YAML files on :func:`search_path` (``sub`` below each folder)."""
    return sorted({p.stem for d in search_path(sub) if d.is_dir() for p in d.glob("*.yaml")})


def is_shipped(path: Path) -> bool:
    """True when ``path`` is a file or folder of the shipped profiles."""
    try:
        path.resolve().relative_to(SHIPPED_PROFILES.resolve())
    except ValueError:
        return False
    return True


def display(path: Path) -> str:
    """How a file is named in messages and outputs: a shipped profile as ``profiles/...`` wherever
    rigcad is installed, others relative to the working directory when under it, else as given."""
    resolved = path.resolve()
    try:
        return str(Path(SHIPPED_NAME) / resolved.relative_to(SHIPPED_PROFILES.resolve()))
    except ValueError:
        pass
    try:
        return str(resolved.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)
