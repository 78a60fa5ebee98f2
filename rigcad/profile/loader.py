"""The only YAML reader in rigcad: files -> nested dicts with a file:line mark per key.

A profile may say ``extends: other`` (a file beside it, with or without ``.yaml``) and override
a few keys; mappings merge key by key, anything else is replaced. Each value keeps the mark of
the file and line that set it, so validation errors point at the line to edit.
"""

from __future__ import annotations

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
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
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


def resolve_profile_path(spec: str | Path, search: Path | None = None) -> Path:
    """Find a profile by path, or by name under ``search`` (default ``profiles/``)."""
    path = Path(spec)
    candidates = [path, path.with_suffix(".yaml")] if path.suffix == "" else [path]
    base = search if search is not None else Path("profiles")
    if not path.is_absolute():
        candidates += [base / c.name for c in list(candidates)]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    known = sorted(p.stem for p in base.glob("*.yaml")) if base.is_dir() else []
    hint = f"; profiles in {base}/: {', '.join(known)}" if known else ""
    raise ProfileError(f"no profile {str(spec)!r}{hint}")


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
            current = resolve_profile_path(parent, search=current.parent)
    data: dict[str, Any] = {}
    marks: dict[Key, str] = {}
    for layer_data, layer_marks in reversed(layers):
        data = _merge(data, layer_data)
        marks.update({k: v for k, v in layer_marks.items() if k != ("extends",)})
    return RawProfile(name=path.stem, data=data, marks=marks, sources=tuple(Path(_display(p)) for p in chain))
