"""The only YAML reader in rigcad: files -> nested dicts with a file:line mark per key.

Profiles are found by name on a search path (:func:`search_path`): the working directory's
``profiles/``, the folders in ``$RIGCAD_PROFILES`` (``os.pathsep``-separated) and the profiles
shipped inside the package (``rigcad/profiles/``), in that order; or given as a path. A profile may
say ``extends: other`` (a name looked up first beside it, then on the search path, or a file) and
override a few keys; mappings merge key by key, anything else is replaced. Each value keeps the mark of
the file and line that set it, so validation errors point at the line to edit.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from rigcad.errors import ProfileError

Key = tuple[str, ...]


@dataclass(frozen=True)
class RawProfile:
    """Merged profile data before validation.

    ``data`` is the nested mapping, ``marks`` maps a key path such as ``("layout", "cop_to_vertex")``
    to ``"profiles/x.yaml:12"``, ``sources`` lists the files read, child first.
    """

    name: str
    data: dict[str, Any]
    marks: dict[Key, str]
    sources: tuple[Path, ...]

    def where(self, key: Key) -> str | None:
        """The file:line that set ``key`` or, failing that, its nearest parent; None if unknown."""
        for cut in range(len(key), -1, -1):
            mark = self.marks.get(key[:cut])
            if mark:
                return mark
        return None


def _mark(path: Path, node: yaml.Node) -> str:
    return f"{_display(path)}:{node.start_mark.line + 1}"


def _display(path: Path) -> str:
    """How a file is named in messages and outputs: a shipped profile as ``rigcad/profiles/...``
    wherever rigcad is installed (outputs do not depend on the install folder), others relative to
    the working directory when under it."""
    resolved = path.resolve()
    try:
        return str(Path("rigcad") / "profiles" / resolved.relative_to(PACKAGE_PROFILES.resolve()))
    except ValueError:
        pass
    try:
        return str(resolved.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _build(loader: yaml.SafeLoader, node: yaml.Node, path: Path, key: Key, marks: dict[Key, str]) -> Any:
    marks.setdefault(key, _mark(path, node))
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            name = loader.construct_object(key_node)
            if not isinstance(name, str):
                raise ProfileError(f"keys must be names, got {name!r}", where=_mark(path, key_node))
            if name in out:
                raise ProfileError(f"key {'.'.join(key + (name,))!r} is given twice", where=_mark(path, key_node))
            marks[key + (name,)] = _mark(path, key_node)
            out[name] = _build(loader, value_node, path, key + (name,), marks)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_build(loader, item, path, key + (str(i),), marks) for i, item in enumerate(node.value)]
    return loader.construct_object(node, deep=True)


def _read_one(path: Path) -> tuple[dict[str, Any], dict[Key, str]]:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError as err:
        raise ProfileError(f"profile file not found: {_display(path)}") from err
    except OSError as err:
        raise ProfileError(f"cannot read profile {_display(path)}: {err.strerror}") from err
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        marks: dict[Key, str] = {}
        data = {} if node is None else _build(loader, node, path, (), marks)
    except yaml.MarkedYAMLError as err:
        line = err.problem_mark.line + 1 if err.problem_mark else 0
        raise ProfileError(f"YAML syntax: {err.problem}", where=f"{_display(path)}:{line}") from err
    finally:
        loader.dispose()
    if not isinstance(data, dict):
        raise ProfileError("a profile must be a mapping of keys to values", where=f"{_display(path)}:1")
    return data, marks


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


#: The profiles shipped with rigcad (rig profiles; printers under ``printers/``).
PACKAGE_PROFILES = Path(__file__).resolve().parents[1] / "profiles"
#: Environment variable naming extra profile folders, ``os.pathsep``-separated.
PROFILES_ENV = "RIGCAD_PROFILES"


def search_path(sub: str = "") -> list[Path]:
    """Folders searched for a profile given by name, first match wins: ``./profiles``, each folder
    of ``$RIGCAD_PROFILES``, the package's profiles; ``sub`` (e.g. ``printers``) is appended to each."""
    dirs = [Path("profiles")]
    dirs += [Path(p) for p in os.environ.get(PROFILES_ENV, "").split(os.pathsep) if p]
    dirs.append(PACKAGE_PROFILES)
    return [d / sub if sub else d for d in dirs]


def find_file(spec: str | Path, kind: str, sub: str = "", near: Path | None = None) -> Path:
    """A ``kind`` file ("profile", "printer") by path, or by name in ``near`` and then on
    :func:`search_path` (``sub`` below each folder); a missing name lists where it looked and the
    names found there. Raises ProfileError."""
    path = Path(spec)
    named = path.suffix == ""
    candidates = [path, path.with_suffix(".yaml")] if named else [path]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    folders = ([near] if near is not None else []) + search_path(sub)
    if not path.is_absolute() and len(path.parts) == 1:
        for folder in folders:
            candidate = folder / (path.name if not named else f"{path.name}.yaml")
            if candidate.is_file():
                return candidate
    looked = []
    for folder in dict.fromkeys(folders):
        names = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
        looked.append(f"{_display(folder)}/ ({', '.join(names) if names else 'none'})")
    raise ProfileError(f"no {kind} {str(spec)!r}: looked for {candidates[-1].name} in " + "; ".join(looked)
                       + f" (set ${PROFILES_ENV} to add folders)")


def resolve_profile_path(spec: str | Path, near: Path | None = None) -> Path:
    """Find a rig profile by path, or by name beside ``near`` and on the search path."""
    return find_file(spec, "profile", near=near)


def load_raw(spec: str | Path) -> RawProfile:
    """Read a profile and everything it extends, child keys overriding parent keys."""
    path = resolve_profile_path(spec)
    chain: list[Path] = []
    layers: list[tuple[dict[str, Any], dict[Key, str]]] = []
    current: Path | None = path
    while current is not None:
        resolved = current.resolve()
        if resolved in chain:
            cycle = " -> ".join(_display(p) for p in chain + [resolved])
            raise ProfileError(f"'extends' forms a cycle: {cycle}")
        chain.append(resolved)
        data, marks = _read_one(current)
        layers.append((data, marks))
        parent = data.pop("extends", None)
        if parent is None:
            current = None
        elif not isinstance(parent, str):
            raise ProfileError(f"'extends' takes a profile name or file, got {parent!r}", where=marks.get(("extends",)))
        else:
            current = resolve_profile_path(parent, near=current.parent)
    data: dict[str, Any] = {}
    marks: dict[Key, str] = {}
    for layer_data, layer_marks in reversed(layers):
        data = _merge(data, layer_data)
        marks.update({k: v for k, v in layer_marks.items() if k != ("extends",)})
    return RawProfile(name=path.stem, data=data, marks=marks, sources=tuple(Path(_display(p)) for p in chain))
