"""The only YAML reader in rigcad: files -> nested dicts with a file:line mark per key.

Profiles are found by name on a search path (:func:`rigcad.profile.paths.search_path`): the working
directory's ``profiles/``, the folders in ``$RIGCAD_PROFILES`` (``os.pathsep``-separated) and the
profiles shipped with rigcad (the repository's ``profiles/``), in that order; or given as a path. A profile may
say ``extends: other`` (a name looked up first beside it, then on the search path, or a file) and
override a few keys; mappings merge key by key, anything else is replaced. Each value keeps the mark of
the file and line that set it, so validation errors point at the line to edit, and its depth in the
chain (RawProfile.depth), so that an instrument file a profile names wins over what it inherits.

Every file rigcad reads this way (profiles, printers, what they extend) crosses one hostile-input
boundary, :func:`read_text` and :func:`parse`: at most :data:`MAX_BYTES`, strict UTF-8 (the first
bad byte named by offset and line), no control characters, at most :data:`MAX_DEPTH` levels of
nesting and :data:`MAX_NODES` values once aliases are expanded (counted on the event stream while
parsing, before anything is built), scalars of at most :data:`MAX_SCALAR` characters. ``extends:``
is resolved only inside the profile search path (the profile's own folder included) and a refused
file is never opened, so its content is never echoed.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rigcad.errors import ProfileError
from rigcad.profile.paths import PROFILES_ENV, display as _display, is_shipped, search_path

Key = tuple[str, ...]

#: Largest profile or printer file read (bytes). rigcad's own profiles are ~4 kB.
MAX_BYTES = 256 * 1024
#: Deepest nesting of mappings and lists (a profile uses 3).
MAX_DEPTH = 32
#: Most values (scalars, mappings, lists) once every alias is expanded: bounds alias bombs.
MAX_NODES = 50_000
#: Longest scalar (characters): a number or a name, not a document.
MAX_SCALAR = 10_000
#: The YAML loader: libyaml's when PyYAML has it (fast enough to pre-scan under the limits), else PyYAML's.
_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
#: Characters YAML 1.1 forbids in a stream (C0 controls but tab, line feed, carriage return; DEL; C1
#: but NEL; surrogates; U+FFFE, U+FFFF).
_FORBIDDEN = re.compile("[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


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
    #: The same files, resolved (child first): what a watcher of the profile watches.
    files: tuple[Path, ...] = ()
    #: For each key of ``marks``, the index in ``sources`` of the file that set it (0: the profile itself).
    depths: dict[Key, int] = field(default_factory=dict)
    #: What each file of the chain itself says (child first, ``extends`` removed): the value a
    #: key had in the file that set it, beside the values that file set with it (its own model).
    layers: tuple[dict[str, Any], ...] = ()

    def where(self, key: Key) -> str | None:
        """The file:line that set ``key`` or, failing that, its nearest parent; None if unknown."""
        for cut in range(len(key), -1, -1):
            mark = self.marks.get(key[:cut])
            if mark:
                return mark
        return None

    def depth(self, key: Key) -> int | None:
        """How far up the ``extends:`` chain the file that set ``key`` is: 0 for the profile itself (or
        a value a caller set on top of it, such as a sweep's ``--set``), 1 for the profile it extends,
        and so on; None when no file set ``key``. The nearer file is the more specific:
        rigcad.profile.schema puts an instrument file between the file that names it and the files
        that file extends."""
        if key not in self.marks:
            return None
        return self.depths.get(key, 0)


def _mark(shown: str, node: yaml.Node) -> str:
    """``file:line`` of a node; ``shown`` is the file as :func:`_display` names it."""
    return f"{shown}:{node.start_mark.line + 1}"


def _build(loader: yaml.SafeLoader, node: yaml.Node, shown: str, key: Key, marks: dict[Key, str]) -> Any:
    marks.setdefault(key, _mark(shown, node))
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            name = _construct(loader, key_node, shown, key)
            if not isinstance(name, str):
                raise ProfileError(f"keys must be names, got {repr(name)[:60]}", where=_mark(shown, key_node))
            if name in out:
                raise ProfileError(f"key {'.'.join(key + (name,))!r} is given twice", where=_mark(shown, key_node))
            marks[key + (name,)] = _mark(shown, key_node)
            out[name] = _build(loader, value_node, shown, key + (name,), marks)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_build(loader, item, shown, key + (str(i),), marks) for i, item in enumerate(node.value)]
    return _construct(loader, node, shown, key)


def _construct(loader: yaml.SafeLoader, node: yaml.Node, shown: str, key: Key) -> Any:
    try:
        return loader.construct_object(node, deep=True)
    except (ValueError, OverflowError) as err:  # e.g. an integer past Python's 4300-digit limit
        name = ".".join(key) or "the document"
        raise ProfileError(f"{name}: a value of {len(str(node.value))} characters that rigcad cannot read as a "
                           "number", where=_mark(shown, node)) from None


def _a(kind: str) -> str:
    """``kind`` with its article: "a profile", "an instrument"."""
    return f"{'an' if kind[:1] in 'aeiou' else 'a'} {kind}"


def read_text(path: Path, kind: str = "profile") -> str:
    """The text of a profile or printer file, refused (ProfileError naming the file, the line and
    the byte offset, never the content) unless it is at most MAX_BYTES of UTF-8 without control
    characters."""
    shown = _display(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except FileNotFoundError as err:
        raise ProfileError(f"{kind} file not found: {shown}") from err
    except IsADirectoryError as err:
        raise ProfileError(f"{kind} {shown} is a folder, not a file") from err
    except OSError as err:
        raise ProfileError(f"cannot read {kind} {shown}: {err.strerror}") from err
    if len(data) > MAX_BYTES:
        raise ProfileError(f"{kind} {shown} is larger than {MAX_BYTES // 1024} KiB, the limit for {_a(kind)} file "
                           "(rigcad's own are ~4 KiB): is it the right file?")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ProfileError(f"{kind} {shown} is UTF-16 (byte-order mark at offset 0): save it as UTF-8")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise ProfileError(f"not UTF-8: byte 0x{data[err.start]:02x} at offset {err.start} cannot be decoded "
                           f"({err.reason}); save the {kind} as UTF-8", where=f"{shown}:{line}") from None
    text = text.removeprefix("\ufeff")
    bad = _FORBIDDEN.search(text)
    if bad:
        line = text.count("\n", 0, bad.start()) + 1
        column = bad.start() - (text.rfind("\n", 0, bad.start()) + 1) + 1
        raise ProfileError(f"control character U+{ord(bad.group()):04X} at column {column}: {_a(kind)} is plain "
                           "text (is this a binary file?)", where=f"{shown}:{line}")
    return text


def _prescan(text: str, shown: str) -> None:
    """Walk the YAML event stream once, before any node is built: refuse nesting deeper than
    MAX_DEPTH, scalars longer than MAX_SCALAR and documents that expand (aliases counted at the size
    of what they name) to more than MAX_NODES values. Time and memory stay linear in the file."""
    sizes: dict[str, int] = {}  # anchor -> expanded size of its node
    stack: list[list] = [[None, 0]]  # open collections: [anchor, expanded size so far]
    total = 0

    def where(event) -> str:
        return f"{shown}:{event.start_mark.line + 1}" if event.start_mark else shown

    for event in yaml.parse(text, Loader=_Loader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            if len(stack) > MAX_DEPTH:
                raise ProfileError(f"nested more than {MAX_DEPTH} levels deep (a profile needs 3)", where=where(event))
            stack.append([event.anchor, 1])
            continue
        if isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            anchor, size = stack.pop()
        elif isinstance(event, yaml.ScalarEvent):
            if len(event.value) > MAX_SCALAR:
                raise ProfileError(f"a value of {len(event.value)} characters (the limit is {MAX_SCALAR})",
                                   where=where(event))
            anchor, size = event.anchor, 1
        elif isinstance(event, yaml.AliasEvent):
            if any(frame[0] == event.anchor for frame in stack):
                raise ProfileError(f"alias *{event.anchor[:40]} inside the value it names (a cycle)", where=where(event))
            anchor, size = None, sizes.get(event.anchor, 1)
        else:
            continue
        if anchor is not None:
            sizes[anchor] = size
        stack[-1][1] += size
        total = stack[0][1]
        if total + sum(frame[1] for frame in stack[1:]) > MAX_NODES:
            raise ProfileError(f"expands to more than {MAX_NODES} values (aliases counted at the size of what "
                               "they name): an alias bomb, or not a profile", where=where(event))


def parse(path: Path, kind: str = "profile") -> tuple[Any, dict[Key, str]]:
    """Read ``path`` through the hostile-input boundary: its data and the file:line of every key."""
    shown = _display(path)
    text = read_text(path, kind)
    loader = _Loader(text)
    try:
        _prescan(text, shown)
        node = loader.get_single_node()
        marks: dict[Key, str] = {}
        data = {} if node is None else _build(loader, node, shown, (), marks)
    except yaml.MarkedYAMLError as err:
        line = err.problem_mark.line + 1 if err.problem_mark else 0
        raise ProfileError(f"YAML syntax: {err.problem}", where=f"{shown}:{line}") from None
    except yaml.YAMLError as err:  # a ReaderError or an emitter-side error: no content echoed
        raise ProfileError(f"not a YAML {kind}: {type(err).__name__}", where=shown) from None
    finally:
        loader.dispose()
    return data, marks


def _read_one(path: Path) -> tuple[dict[str, Any], dict[Key, str]]:
    data, marks = parse(path)
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


def find_file(spec: str | Path, kind: str, sub: str = "", near: Path | None = None,
              as_path: bool = True) -> Path:
    """A ``kind`` file ("profile", "printer") by path (unless ``as_path`` is False), or by name in
    ``near`` and then on :func:`search_path` (``sub`` below each folder); a missing name lists where
    it looked and the names found there. Raises ProfileError."""
    if not str(spec).strip() or "\x00" in str(spec):
        raise ProfileError(f"{_a(kind)} is named by its name or the path of its .yaml file; got {str(spec)!r}")
    path = Path(spec)
    named = path.suffix == ""
    candidates = [path, path.with_suffix(".yaml")] if named else [path]
    for candidate in candidates if as_path else ():
        if candidate.is_file():
            return candidate
    folders = ([near] if near is not None else []) + search_path(sub)
    if not path.is_absolute() and len(path.parts) == 1:
        for folder in folders:
            candidate = folder / (path.name if not named else f"{path.name}.yaml")
            if candidate.is_file():
                return candidate
    looked, known = [], []
    unique: dict[Path, Path] = {}
    for folder in folders:
        unique.setdefault(folder.resolve(), folder)  # each folder once (./profiles may be the shipped one)
    for folder in unique.values():
        if not folder.is_dir() and not is_shipped(folder):
            continue  # a folder that is not there (./profiles elsewhere) would read as the shipped one's name
        names = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
        known += names
        shipped = "shipped with rigcad: " if is_shipped(folder) else ""
        looked.append(f"{_display(folder)}/ ({shipped}{', '.join(names) if names else 'none'})")
    close = difflib.get_close_matches(path.stem if named else path.name, known, n=1)
    raise ProfileError(f"no {kind} {str(spec)!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
                       + f": looked for {candidates[-1].name} in " + "; ".join(looked)
                       + f" (set ${PROFILES_ENV} to add folders)")


def resolve_profile_path(spec: str | Path, near: Path | None = None) -> Path:
    """Find a rig profile by path, or by name beside ``near`` and on the search path."""
    return find_file(spec, "profile", near=near)


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.relative_to(folder)
    except ValueError:
        return False
    return True


def _resolve_extends(parent: Any, child: Path, where: str | None) -> Path:
    """The file ``extends: parent`` names in ``child``: a profile name looked up beside ``child`` and
    then on the search path, or a relative path that stays inside one of those folders. Anything
    else (an absolute path elsewhere, ``../..`` out of them, a symlink leading out) is refused
    before it is opened."""
    if not isinstance(parent, str) or not parent.strip():
        raise ProfileError(f"'extends' takes the name of a profile (e.g. achutha2006), got {repr(parent)[:60]}", where=where)
    spec = Path(parent)
    roots = list(dict.fromkeys(f.resolve() for f in [child.parent] + search_path()))
    if len(spec.parts) == 1 and not spec.is_absolute() and spec.suffix in ("", ".yaml", ".yml"):
        try:
            found = find_file(spec.name, "profile", near=child.parent, as_path=False)
        except ProfileError as err:
            raise ProfileError(str(err), where=where) from None
        candidate = found.resolve()
    else:
        candidate = (spec if spec.is_absolute() else child.parent / spec).resolve()
    if not any(_inside(candidate, root) for root in roots):  # ../.., an absolute path, a symlink out
        raise ProfileError(
            f"'extends: {parent}' leads outside the profile search path, so it is not read; extend a profile "
            "by name, or by a path inside " + ", ".join(_display(r) + "/" for r in roots), where=where)
    if not candidate.is_file():
        raise ProfileError(f"'extends: {parent}': no such profile file ({_display(candidate)})", where=where)
    return candidate


#: A profile's name is its file's name without ``.yaml``, and names its folder under the exports
#: (``exports/<name>/``, staged beside it as ``.<name>.new-*``): letters, digits, ``_ + - .`` and
#: spaces, not starting with a dot or a space, at most 100 characters. A name such as ``.`` (from
#: ``..yaml``), one with a newline or one with glob characters would name another folder.
PROFILE_NAME = re.compile(r"[^\W][\w .+-]{0,99}")


def check_profile_name(name: str, path: Path) -> str:
    """``name`` when it is a valid profile name (:data:`PROFILE_NAME`), else a ProfileError."""
    if not PROFILE_NAME.fullmatch(name) or name.rstrip(" .") != name:
        raise ProfileError(f"profile file {_display(path)!r}: its name {name!r} cannot name a folder under the exports; "
                           "rename the file to letters, digits, '_', '+', '-', '.' and spaces (not first or last), "
                           "at most 100 characters, e.g. my_rig.yaml")
    return name


def load_raw(spec: str | Path) -> RawProfile:
    """Read a profile and everything it extends, child keys overriding parent keys."""
    path = resolve_profile_path(spec)
    check_profile_name(path.stem, path)
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
        else:
            current = _resolve_extends(parent, current, marks.get(("extends",)))
    data: dict[str, Any] = {}
    marks: dict[Key, str] = {}
    depths: dict[Key, int] = {}
    for depth in range(len(layers) - 1, -1, -1):  # the farthest base first, the profile itself last
        layer_data, layer_marks = layers[depth]
        data = _merge(data, layer_data)
        marks.update({k: v for k, v in layer_marks.items() if k != ("extends",)})
        depths.update({k: depth for k in layer_marks if k != ("extends",)})
    return RawProfile(name=path.stem, data=data, marks=marks, sources=tuple(Path(_display(p)) for p in chain),
                      files=tuple(chain), depths=depths, layers=tuple(layer for layer, _ in layers))
