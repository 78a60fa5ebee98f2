"""PrusaSlicer's own presets: the vendor bundles it ships (PrusaResearch.ini and others) and a
user's exported configuration, read into plain ``key -> text`` settings rigcad hands back to
PrusaSlicer.

A vendor bundle is an INI file with sections ``[vendor]``, ``[printer_model:ID]`` and presets
``[printer:NAME]``, ``[print:NAME]``, ``[filament:NAME]`` (and SLA ones rigcad does not use).
A preset may say ``inherits = a; b``: the parents are flattened first and applied left to right,
later parents overriding earlier ones, the preset's own keys overriding them all. That is
PrusaSlicer's rule (``flatten_configbundle_hierarchy`` in PresetBundle.cpp: own keys win, then
the parents from the last to the first fill in what is still missing). Names starting with
``*`` are abstract building blocks, never selected. Values stay in PrusaSlicer's own text form
(``\\n`` escapes in G-code, ``20%``, comma-separated vectors): rigcad writes them back verbatim.

The INI reader is written by hand: configparser lowercases keys and gives ``%`` and inline ``;``
meanings PrusaSlicer's files do not have. It follows boost's ``read_ini``, which PrusaSlicer uses:
whole-line comments start with ``;`` or ``#``, ``key = value`` with both sides trimmed, no key or
section twice. Files are parsed once per process (keyed by path, size and modification time).
"""

from __future__ import annotations

import difflib
import functools
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab import allowlist as A

#: Text mode for PrusaSlicer's output: UTF-8 whatever the locale (a "C" locale, as set by some
#: libraries on import or found on CI, would make Python decode it as ASCII and fail on a degree sign).
TEXT = {"text": True, "encoding": "utf-8", "errors": "replace"}

SLICER = "prusa-slicer"
INSTALL_HINT = ("install PrusaSlicer, which ships the vendor bundles: `apt-get update && apt-get install "
                "prusa-slicer` (Debian/Ubuntu) or from https://www.prusa3d.com/")
#: Preset groups rigcad reads, in the order PrusaSlicer composes a full FFF configuration
#: (PresetBundle::full_fff_config: print, then printer, then filament).
GROUPS = ("print", "printer", "filament")
#: Keys that only mean something inside a bundle (inheritance, renames, the GUI's compatibility
#: filters, which PrusaSlicer also drops from a full configuration); never handed to the slicer.
BUNDLE_ONLY = frozenset({"inherits", "renamed_from", "alias", "compatible_printers", "compatible_printers_condition",
                         "compatible_prints", "compatible_prints_condition"})


class Problems(ProfileError):
    """Every problem found in one file (a printer file and the presets it names), reported at once:
    ``problems`` the errors, each with its own file:line; the message lists them all on one line."""

    def __init__(self, problems: list, what: str) -> None:
        self.problems = list(problems)
        super().__init__(f"{what}: {len(self.problems)} problems, each with its file:line: "
                         + " | ".join(f"({i}) {p}" for i, p in enumerate(self.problems, 1)))


def gather(problems: list, err: Exception) -> None:
    """Add ``err`` (or each problem of a :class:`Problems`) to ``problems``."""
    problems.extend(err.problems if isinstance(err, Problems) else [err])


def raise_problems(problems: list, what: str) -> None:
    """Raise the one problem as it is, several as one :class:`Problems`; nothing when there is none."""
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise Problems(sorted(problems, key=_place), what)


def _place(err: Exception) -> tuple:
    """Where an error points, as (file, line) for sorting: in the file's order, those without a place last."""
    file, _, line = (getattr(err, "where", None) or "\uffff").rpartition(":")
    return (file, int(line)) if line.isdigit() else ("\uffff", 0)


# -- the INI reader ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class IniFile:
    """An INI file as PrusaSlicer reads it: ``top`` holds keys before any section (a flat config
    file), ``sections`` the rest; ``lines`` maps (section or "", key) to its 1-based line."""

    path: Path
    top: dict[str, str]
    sections: dict[str, dict[str, str]]
    section_lines: dict[str, int]
    lines: dict[tuple[str, str], int]

    def where(self, section: str, key: str | None = None) -> str:
        line = self.lines.get((section, key)) if key is not None else None
        return f"{self.path}:{line or self.section_lines.get(section, 1)}"


#: Largest PrusaSlicer configuration read (bytes): the biggest bundle PrusaSlicer 2.5 ships,
#: PrusaResearch.ini, is 0.4 MB; a user's exported .ini is ~20 kB.
MAX_INI_BYTES = 16 * 1024 * 1024
#: Control characters no PrusaSlicer configuration holds (tab allowed; line ends split lines).
_INI_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


def read_ini(path: str | Path) -> IniFile:
    """Parse an INI file (cached per process while the file is unchanged). Errors name the file
    and line, never the file's content: a file that is not a PrusaSlicer configuration is not
    quoted back."""
    path = Path(path)
    try:
        st = path.stat()
    except OSError as err:
        raise FabricationError(f"cannot read PrusaSlicer configuration {path}: {err.strerror}") from err
    return _read_ini(path.resolve(), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _read_ini(path: Path, size: int, mtime_ns: int) -> IniFile:  # size, mtime: part of the cache key
    not_ini = f"{path} is not a PrusaSlicer configuration"
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_INI_BYTES + 1)
    except OSError as err:
        raise FabricationError(f"cannot read PrusaSlicer configuration {path}: {err.strerror}") from err
    if len(data) > MAX_INI_BYTES:
        raise FabricationError(f"{not_ini}: larger than {MAX_INI_BYTES >> 20} MiB (PrusaSlicer's bundles are < 1 MB)")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise FabricationError(f"{not_ini}: not UTF-8 (byte offset {err.start})", where=f"{path}:{line}") from None
    bad = _INI_CONTROL.search(text)
    if bad:
        line = text.count("\n", 0, bad.start()) + 1
        raise FabricationError(f"{not_ini}: control character U+{ord(bad.group()):04X}", where=f"{path}:{line}")
    top: dict[str, str] = {}
    sections: dict[str, dict[str, str]] = {}
    section_lines: dict[str, int] = {}
    lines: dict[tuple[str, str], int] = {}
    current, name = top, ""
    for n, raw in enumerate(text.splitlines(), 1):
        s = raw.strip()
        if not s or s[0] in ";#":
            continue
        if s[0] == "[":
            if not s.endswith("]"):
                raise FabricationError(f"{not_ini}: an unclosed section header", where=f"{path}:{n}")
            name = s[1:-1].strip()
            if name in sections:
                raise FabricationError(f"section [{name[:60]}] is given twice (first at line {section_lines[name]})",
                                       where=f"{path}:{n}")
            current = sections[name] = {}
            section_lines[name] = n
            continue
        key, eq, value = s.partition("=")
        key = key.strip()
        if not eq or not key:
            raise FabricationError(f"{not_ini}: expected 'key = value' or '[section]'", where=f"{path}:{n}")
        if key in current:
            raise FabricationError(f"key {key[:60]!r} is given twice in [{name[:60]}] (first at line "
                                   f"{lines[(name, key)]})", where=f"{path}:{n}")
        current[key] = value.strip()
        lines[(name, key)] = n
    return IniFile(path, top, sections, section_lines, lines)


def split_inherits(value: str) -> list[str]:
    """``a; "b; c"`` -> ["a", "b; c"]: PrusaSlicer's ``unescape_strings_cstyle`` on an inherits
    list (``;``-separated, a name may be double-quoted with ``\\"`` and ``\\\\`` escapes)."""
    out: list[str] = []
    i, n = 0, len(value)
    while i < n:
        while i < n and value[i] in " \t":
            i += 1
        if i < n and value[i] == '"':
            i += 1
            buf = []
            while i < n and value[i] != '"':
                if value[i] == "\\" and i + 1 < n:
                    i += 1
                buf.append(value[i])
                i += 1
            i += 1
            item = "".join(buf)
            while i < n and value[i] != ";":
                i += 1
        else:
            j = value.find(";", i)
            j = n if j < 0 else j
            item, i = value[i:j].strip(), j
        if item:
            out.append(item)
        i += 1  # past the ';'
    return out


# -- finding the bundles ----------------------------------------------------------------------------

def bundle_dirs() -> list[Path]:
    """Where PrusaSlicer keeps its vendor bundles, in the order rigcad searches: beside the
    installed executable (Debian: /usr/bin -> /usr/share/PrusaSlicer/profiles; an unpacked
    release: resources/profiles), the usual system folders, then the user's updated copies
    (~/.config/PrusaSlicer/vendor, written by PrusaSlicer's configuration updater)."""
    dirs: list[Path] = []
    exe = shutil.which(SLICER)
    if exe:
        real = Path(os.path.realpath(exe)).parent
        dirs += [real.parent / "share" / "PrusaSlicer" / "profiles", real / "resources" / "profiles"]
    dirs += [Path("/usr/share/PrusaSlicer/profiles"), Path("/usr/local/share/PrusaSlicer/profiles"),
             Path.home() / ".config" / "PrusaSlicer" / "vendor"]
    seen: list[Path] = []
    for d in dirs:
        if d not in seen:
            seen.append(d)
    return seen


def available_bundles(dirs: list[Path] | None = None) -> dict[str, Path]:
    """Vendor bundle name -> file (the first folder holding a name wins)."""
    out: dict[str, Path] = {}
    for d in dirs if dirs is not None else bundle_dirs():
        if d.is_dir():
            for p in sorted(d.glob("*.ini")):
                out.setdefault(p.stem, p)
    return out


#: Folders whose files are never a slicer configuration or a printer file (kernel, devices, system
#: settings and secrets): refused before they are opened, wherever a search path points.
SYSTEM_DIRS = tuple(Path(p) for p in ("/proc", "/sys", "/dev", "/etc", "/run", "/boot"))
#: A bundle named rather than given by path: a file name without folder or suffix.
_BUNDLE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9 _+.-]{0,127}")


def in_system_dir(path: Path) -> bool:
    """Whether ``path`` (resolved) lies under one of :data:`SYSTEM_DIRS`."""
    return any(path == d or d in path.parents for d in SYSTEM_DIRS)


def _inside(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def find_bundle(spec: str, base: Path | None = None, where: str | None = None,
                dirs: list[Path] | None = None) -> Path:
    """A bundle by name (``PrusaResearch``) among the installed ones, or a PrusaSlicer ``.ini`` by
    path, relative to ``base`` (the printer file's folder). A path is read only when it stays,
    links resolved, inside ``base``, a folder of the profile search path or an installed bundle
    folder, and outside :data:`SYSTEM_DIRS`, as ``extends:`` is resolved; anything else is refused
    before it is opened, so its content is never shown. Errors say where rigcad looked."""
    from rigcad.profile.loader import search_path

    search = dirs if dirs is not None else bundle_dirs()
    named = not spec.endswith(".ini") and "/" not in spec and "\\" not in spec and os.sep not in spec
    if named and not _BUNDLE_NAME.fullmatch(spec):
        raise ProfileError(f"slicer.vendor_bundle: {spec[:60]!r} is neither an installed bundle's name (letters, "
                           "digits, '_', '-', e.g. PrusaResearch) nor the path of a PrusaSlicer .ini", where=where)
    if not named:
        given = Path(spec)
        path = given if given.is_absolute() or base is None else base / given
        real = path.resolve()
        roots = list(dict.fromkeys(r.resolve() for r in ([base] if base is not None else []) + search_path()
                                   + list(search)))
        if given.suffix != ".ini" or real.suffix != ".ini":
            problem = "is not a PrusaSlicer .ini file"
        elif in_system_dir(real) or not any(_inside(real, r) for r in roots):
            problem = "leads outside the printer file's folder and the profile search path"
        elif not real.is_file():
            raise ProfileError(f"slicer.vendor_bundle: no file {spec!r} (a bundle name such as 'PrusaResearch', "
                               "or the path of a PrusaSlicer .ini, relative to the printer file)", where=where)
        else:
            return real
        raise ProfileError(f"slicer.vendor_bundle: {spec[:200]!r} {problem}, so it is not read; name an installed "
                           "bundle (e.g. PrusaResearch) or a .ini beside the printer file or in "
                           + ", ".join(str(r) + "/" for r in roots[:4]), where=where)
    found = available_bundles(search)
    if spec in found:
        return found[spec]
    looked = ", ".join(str(d) for d in search)
    if not found:
        raise FabricationError(f"slicer.vendor_bundle {spec!r}: no PrusaSlicer vendor bundles found (looked in "
                               f"{looked}); {INSTALL_HINT}", where=where)
    close = difflib.get_close_matches(spec, list(found), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ProfileError(f"slicer.vendor_bundle: no bundle {spec!r}{hint}; installed: {', '.join(sorted(found))} "
                       f"(looked in {looked})", where=where)


# -- bundles and their presets -----------------------------------------------------------------------

#: A printer preset name this close to one the bundle has (difflib's ratio) is a slip of the pen
#: ("MK3S & MK3S" for "MK3S & MK3S+": 0.98); below, another printer ("Original Prusa MK4" against
#: "Original Prusa i3 MK3": 0.87), which the bundle lacks.
MISSPELT = 0.9


@dataclass(frozen=True)
class Bundle:
    """A parsed vendor bundle; :meth:`flatten` gives a preset with its inherits chain applied."""

    ini: IniFile
    _flat: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def path(self) -> Path:
        return self.ini.path

    @property
    def vendor(self) -> dict[str, str]:
        return self.ini.sections.get("vendor", {})

    def label(self) -> str:
        v = self.vendor
        return f"{v.get('name', self.path.stem)} {v.get('config_version', '')}".strip()

    def printer_models(self) -> dict[str, dict[str, str]]:
        return {k.split(":", 1)[1]: v for k, v in self.ini.sections.items() if k.startswith("printer_model:")}

    def model_name(self, model_id: str) -> str:
        """The printer model's name as PrusaSlicer shows it (``&&`` is its escaped ``&``), or the ID."""
        return self.printer_models().get(model_id, {}).get("name", model_id).replace("&&", "&")

    def presets(self, group: str, abstract: bool = False) -> list[str]:
        """Preset names of ``group`` in file order; ``abstract`` also lists the ``*name*`` ones."""
        head = group + ":"
        names = [k[len(head):] for k in self.ini.sections if k.startswith(head)]
        return [n for n in names if abstract or not n.startswith("*")]

    def _section(self, group: str, name: str) -> dict[str, str] | None:
        return self.ini.sections.get(f"{group}:{name}")

    def flatten(self, group: str, name: str, where: str | None = None) -> dict[str, str]:
        """The preset's settings with its inherits chain applied (a fresh dict, bundle-only keys
        kept so a caller can see them; :data:`BUNDLE_ONLY` says which they are)."""
        if self._section(group, name) is None or name.startswith("*"):
            raise ProfileError(self._unknown(group, name), where=where)
        return dict(self._flatten(group, name, ()))

    def _flatten(self, group: str, name: str, chain: tuple[str, ...]) -> dict[str, str]:
        key = (group, name)
        if key in self._flat:
            return self._flat[key]
        if name in chain:
            raise FabricationError(f"[{group}:{name}] inherits itself: {' -> '.join(chain + (name,))}",
                                   where=self.ini.where(f"{group}:{chain[-1]}", "inherits"))
        own = self._section(group, name)
        if own is None:
            raise FabricationError(f"[{group}:{chain[-1]}] inherits an unknown preset {name!r}",
                                   where=self.ini.where(f"{group}:{chain[-1]}", "inherits"))
        out: dict[str, str] = {}
        for parent in split_inherits(own.get("inherits", "")):
            out.update(self._flatten(group, parent, chain + (name,)))
        out.update(own)
        out.pop("inherits", None)
        self._flat[key] = out
        return out

    def where_set(self, group: str, name: str, key: str) -> str:
        """file:line of the section that gives ``key`` its value in preset ``name`` (its own
        keys first, then its parents from the last to the first, as :meth:`_flatten` applies them)."""
        def find(n: str, seen: tuple[str, ...]) -> str | None:
            own = self._section(group, n)
            if own is None or n in seen:
                return None
            if key in own:
                return self.ini.where(f"{group}:{n}", key)
            for parent in reversed(split_inherits(own.get("inherits", ""))):
                hit = find(parent, seen + (n,))
                if hit:
                    return hit
            return None
        return find(name, ()) or self.ini.where(f"{group}:{name}")

    def _unknown(self, group: str, name: str) -> str:
        names = self.presets(group)
        if name.startswith("*") and self._section(group, name) is not None:
            return (f"{group}_preset {name!r} is an abstract building block of {self.path.name} (names in '*' are "
                    f"never selected); choose a preset that inherits it")
        for other in names:
            if self._section(group, other).get("renamed_from", "").strip('"') == name:
                return f"{group}_preset {name!r} was renamed to {other!r} in {self.path.name} ({self.label()})"
        variants = [n for n in names if n.lower().startswith(name.lower().strip())]
        misspelt = difflib.get_close_matches(name, names, n=1, cutoff=MISSPELT)
        if variants and not misspelt:  # a printer whose presets are per nozzle (or MMU): "Creality Ender-3 V2 (0.4 mm nozzle)"
            return (f"{group}_preset {name!r} names no preset of {self.path} ({self.label()}), but {len(variants)} "
                    f"start with it: {', '.join(repr(v) for v in variants[:6])}; name the one for your nozzle")
        if group == "printer" and not misspelt:
            return self._unknown_printer(name, names)
        close = difflib.get_close_matches(name, names, n=3, cutoff=0.6)
        hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        return (f"{group}_preset {name!r} is not in {self.path} ({self.label()}, {len(names)} {group} presets){hint}"
                f" (list them with `python -m rigcad.fab.vendor {self.path.stem} {group}`)")

    def _unknown_printer(self, name: str, names: list[str]) -> str:
        """A printer the installed bundle has no preset for: the nearest it has, and what to do."""
        fff = [n for n in names if self.flatten("printer", n).get("printer_technology", "FFF") == "FFF"]
        close = difflib.get_close_matches(name, fff, n=3, cutoff=0.4)
        near = f"; the nearest it has: {', '.join(repr(c) for c in close)}" if close else ""
        return (f"printer_preset {name!r} is not in the installed PrusaSlicer's bundle {self.path} ({self.label()}, "
                f"{len(names)} printer presets): this PrusaSlicer has no presets for that printer{near} (all: "
                f"`python -m rigcad.fab.vendor {self.path.stem} printer`). Either give the machine's own settings: "
                "export them from a PrusaSlicer that knows it (File > Export > Export Config) and name that .ini as "
                "slicer.vendor_bundle, without the *_preset keys; or name the nearest printer's presets with "
                "`model:` your printer and `stand_in:` why its G-code suits it (docs/instruments.md, 'Your printer')")


def load_bundle(path: str | Path) -> Bundle:
    """The bundle at ``path``, parsed once per process (while the file is unchanged); each
    preset is flattened once, on first use."""
    path = Path(path)
    try:
        st = path.stat()
    except OSError as err:
        raise FabricationError(f"cannot read PrusaSlicer configuration {path}: {err.strerror}") from err
    return _load_bundle(path.resolve(), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=16)
def _load_bundle(path: Path, size: int, mtime_ns: int) -> Bundle:
    return Bundle(_read_ini(path, size, mtime_ns))


# -- PrusaSlicer's own key list ----------------------------------------------------------------------

def slicer_keys(exe: str | None = None) -> frozenset[str]:
    """Every configuration key the installed PrusaSlicer knows: its full default configuration
    (``--save``) and the options of ``--help-fff``. Empty when PrusaSlicer is not installed."""
    exe = exe or shutil.which(SLICER)
    return _slicer_options(exe)[0] if exe else frozenset()


def slicer_help(key: str, exe: str | None = None) -> str:
    """The tail of ``--help-fff``'s text on ``key``: its unit, choices and default, e.g.
    "(reprap, ..., marlin2, ...; default: reprap)"; "" when unknown."""
    exe = exe or shutil.which(SLICER)
    return _slicer_options(exe)[1].get(key, "") if exe else ""


@functools.lru_cache(maxsize=4)
def _slicer_options(exe: str) -> tuple[frozenset[str], dict[str, str]]:
    keys: set[str] = set()
    with tempfile.TemporaryDirectory(prefix="rigcad-keys-") as tmp:
        out = Path(tmp) / "defaults.ini"
        try:
            subprocess.run([exe, "--save", str(out)], capture_output=True, timeout=120)
            help_fff = subprocess.run([exe, "--help-fff"], capture_output=True, timeout=120, **TEXT).stdout
        except (OSError, subprocess.TimeoutExpired) as err:
            raise FabricationError(f"{exe} does not run: {err}; {INSTALL_HINT}") from err
        if out.is_file():
            keys |= set(read_ini(out).top)
    # after the actions and transforms, one option per " --bed-temperature N  text" line, its
    # text continued on indented lines and ending in "(unit, choices; default: x)"
    helps: dict[str, str] = {}
    key = None
    for line in help_fff.split("Print options are processed", 1)[-1].splitlines():
        if line.startswith(" --"):
            key = line[3:].split()[0].split(",")[0].replace("-", "_")
            keys.add(key)
            helps[key] = line[3:].split(None, 1)[1] if len(line[3:].split(None, 1)) > 1 else ""
        elif key and line.startswith("  "):
            helps[key] += " " + line.strip()
        else:
            key = None
    tails = {k: m.group(0) for k, v in helps.items() if (m := re.search(r"\([^()]*\)\s*$", v.strip()))}
    return frozenset(keys), tails


def check_values(settings: dict[str, str], where: dict[str, str | None], exe: str | None = None) -> None:
    """Let PrusaSlicer itself parse ``settings`` (``--load`` then ``--save``, ~0.1 s) and turn a
    value it refuses into a ProfileError at the key's file:line. Skipped without PrusaSlicer."""
    exe = exe or shutil.which(SLICER)
    if exe is None or not settings:
        return
    text = "".join(f"{k} = {v}\n" for k, v in sorted(settings.items()))
    _check_values(exe, text, tuple(sorted(where.items(), key=lambda kv: kv[0])))


@functools.lru_cache(maxsize=64)
def _check_values(exe: str, text: str, where: tuple[tuple[str, str | None], ...]) -> None:
    with tempfile.TemporaryDirectory(prefix="rigcad-check-") as tmp:
        d = Path(tmp)
        (d / "in.ini").write_text(text, encoding="utf-8")
        try:
            proc = subprocess.run([exe, "--config-compatibility", "disable", "--loglevel", "1", "--load", "in.ini",
                                   "--save", "out.ini"], cwd=d, capture_output=True, timeout=120, **TEXT)
        except (OSError, subprocess.TimeoutExpired) as err:
            raise FabricationError(f"{exe} does not run: {err}; {INSTALL_HINT}") from err
    if proc.returncode == 0:
        return
    log = (proc.stdout + proc.stderr).strip().splitlines()
    msg = next((ln for ln in log if "Invalid value" in ln or "rror" in ln), log[-1] if log else "")
    marks = dict(where)
    key = next((k for k in marks if f"parameter {k}:" in msg), None)
    detail = msg.split("Invalid value provided for ", 1)[-1]
    valid = f"; valid: {slicer_help(key, exe)}" if key and slicer_help(key, exe) else ""
    raise ProfileError(f"slicer.overrides{'.' + key if key else ''}: PrusaSlicer refuses it: {detail}{valid}",
                       where=marks.get(key) if key else None)


# -- the configuration rigcad hands to PrusaSlicer -------------------------------------------------

@dataclass(frozen=True)
class VendorConfig:
    """PrusaSlicer settings resolved from a bundle's presets (or a user's flat .ini) and the
    printer file's overrides. ``settings``: the flattened presets, bundle-only keys dropped and
    ``*_settings_id`` set as the GUI sets them (the vendor G-code tests them); ``overrides``: the
    printer file's, already in PrusaSlicer's text form. Both sorted by key (deterministic)."""

    source: Path
    kind: str  # "bundle" or "config"
    vendor: str
    printer_preset: str | None
    print_preset: str | None
    filament_preset: str | None
    settings: tuple[tuple[str, str], ...]
    overrides: tuple[tuple[str, str], ...]

    def effective(self) -> dict[str, str]:
        """What PrusaSlicer prints with before rigcad's per-piece settings: presets, then overrides."""
        out = dict(self.settings)
        out.update(self.overrides)
        return out

    def describe(self) -> dict:
        return {"source": str(self.source), "kind": self.kind, "vendor": self.vendor,
                "printer_preset": self.printer_preset, "print_preset": self.print_preset,
                "filament_preset": self.filament_preset, "overrides": dict(self.overrides)}


def ini_value(value, key: str = "value", where: str | None = None) -> str:
    """A YAML value in PrusaSlicer's text form: booleans 1/0, numbers as written, text with
    newlines and backslashes escaped (PrusaSlicer's ``escape_string_cstyle``), lists of numbers
    comma-separated (per-extruder vectors), lists of text ``;``-separated and quoted."""
    def esc(s: str) -> str:
        return s.replace("\\", "\\\\").replace("\n", "\\n").replace("\r", "\\r")

    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return esc(value)
    if isinstance(value, list) and value:
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            return ",".join(ini_value(v) for v in value)
        if all(isinstance(v, str) for v in value):
            return ";".join('"' + esc(v).replace('"', '\\"') + '"' for v in value)
    raise ProfileError(f"slicer.overrides.{key}: {value!r} is not a PrusaSlicer value (a number, true/false, text, "
                       "or a list of numbers or of texts)", where=where)


def resolve(source: Path, printer: str | None, print_: str | None, filament: str | None,
            overrides: dict[str, object], where: dict[str, str | None] | None = None) -> VendorConfig:
    """Resolve the printer file's ``slicer`` section against ``source`` (a bundle or a flat
    configuration, see :func:`find_bundle`). ``where`` maps "vendor_bundle", "printer_preset", ...,
    and "overrides.KEY" to their file:line. Unknown preset names and override keys are refused
    with a "did you mean"; override values are checked by PrusaSlicer itself when installed."""
    where = where or {}
    path = Path(source)
    ini = read_ini(path)
    names = {"printer": printer, "print": print_, "filament": filament}
    if ini.sections and not ini.top:
        b = load_bundle(path)
        missing = [g for g in ("printer", "print", "filament") if not names[g]]
        if missing:
            raise ProfileError(f"slicer: a vendor bundle needs {', '.join(g + '_preset' for g in missing)} "
                               f"(e.g. {missing[0]}_preset: {b.presets(missing[0])[0]!r})",
                               where=where.get("vendor_bundle"))
        merged: dict[str, str] = {}
        group_of: dict[str, str] = {}
        problems: list = []
        for g in GROUPS:
            try:
                flat = b.flatten(g, names[g], where.get(f"{g}_preset"))
            except ProfileError as err:  # every unknown preset at once
                problems.append(err)
                continue
            merged.update(flat)
            group_of.update(dict.fromkeys(flat, g))
        raise_problems(problems, f"slicer presets in {path}")
        kind, vendor = "bundle", b.label()

        def line_of(key: str) -> str:
            return b.where_set(group_of[key], names[group_of[key]], key)
    else:
        given = [g + "_preset" for g, n in names.items() if n]
        if given:
            raise ProfileError(f"slicer: {path} is a flat PrusaSlicer configuration (no [print:...] sections), so "
                               f"{', '.join(given)} mean nothing; drop them or name a vendor bundle",
                               where=where.get(given[0]))
        merged = dict(ini.top)
        kind, vendor = "config", "user configuration"

        def line_of(key: str) -> str:
            return ini.where("", key)
    settings = A.filter_preset({k: v for k, v in merged.items() if k not in BUNDLE_ONLY}, line_of)
    if kind == "bundle":
        settings.update({"print_settings_id": print_, "printer_settings_id": printer,
                         "filament_settings_id": '"' + filament.replace('"', '\\"') + '"'})
    over: dict[str, str] = {}
    problems = []
    for key, value in overrides.items():
        try:
            over[key] = _override(key, value, where.get(f"overrides.{key}"), merged)
        except ProfileError as err:  # every refused override at once
            problems.append(err)
    raise_problems(problems, "slicer.overrides")
    check_values(over, {k: where.get(f"overrides.{k}") for k in over})
    return VendorConfig(source=path, kind=kind, vendor=vendor, printer_preset=printer, print_preset=print_,
                        filament_preset=filament, settings=tuple(sorted(settings.items())),
                        overrides=tuple(sorted(over.items())))


def _override(key: str, value, at: str | None, merged: dict[str, str]) -> str:
    """One of the printer file's ``slicer.overrides``, checked, in PrusaSlicer's text form."""
    if key in BUNDLE_ONLY:
        raise ProfileError(f"slicer.overrides.{key}: a bundle's bookkeeping key, not a PrusaSlicer setting",
                           where=at)
    if key not in A.ALLOWED_KEYS and key not in A.REFUSED:
        if key in (set(merged) | slicer_keys()) - BUNDLE_ONLY:  # PrusaSlicer knows it: not a print setting
            raise ProfileError(f"slicer.overrides.{key}: refused: {A.why_refused(key)}", where=at)
        close = difflib.get_close_matches(key, sorted(A.ALLOWED_KEYS), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ProfileError(f"slicer.overrides: unknown PrusaSlicer setting {key!r}{hint}; valid keys are the "
                           f"{len(A.ALLOWED_KEYS)} settings that shape a print (rigcad.fab.allowlist.ALLOWED, "
                           "PrusaSlicer's names as in `prusa-slicer --help-fff` with '_' for '-')", where=at)
    text = ini_value(value, key, at)
    A.check_override(key, text, at)
    return text


def main(argv: list[str] | None = None) -> int:
    """``python -m rigcad.fab.vendor [BUNDLE [GROUP [PRESET]]]``: list bundles, presets, or one
    flattened preset."""
    import sys

    args = sys.argv[1:] if argv is None else argv
    try:
        if not args:
            found = available_bundles()
            print("\n".join(f"{k}\t{v}" for k, v in found.items()) or f"none in {bundle_dirs()}; {INSTALL_HINT}")
            return 0
        b = load_bundle(find_bundle(args[0], Path.cwd()))
        if len(args) == 1:
            for g in ("printer", "print", "filament"):
                print(f"{g}: {len(b.presets(g))} presets")
        elif len(args) == 2:
            print("\n".join(b.presets(args[1])))
        else:
            for k, v in sorted(b.flatten(args[1], args[2]).items()):
                print(f"{k} = {v}")
    except (ProfileError, FabricationError) as err:
        print(f"rigcad: {err}", file=sys.stderr)
        return err.exit_code
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
