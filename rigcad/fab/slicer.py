"""G-code and project files through a real slicer: PrusaSlicer's command line, headless (Debian
package prusa-slicer).

For each piece rigcad writes one configuration (.ini) into a private temporary folder and runs
``prusa-slicer --export-gcode --load piece.ini --center X,Y --output DIR/piece.gcode piece.stl``,
then ``--export-3mf`` the same way to ``DIR/piece.3mf`` (pieces in parallel, up to the cores);
the folder must then hold exactly those files. The configuration holds only settings that shape a
print (rigcad.fab.allowlist: no program, path or host ever reaches PrusaSlicer) and is, in this
order, later keys winning:

1. the printer's PrusaSlicer presets, flattened (rigcad.fab.vendor: the vendor's start G-code with
   its printer-model check and mesh bed levelling, the filament's temperatures, ...);
2. rigcad's own settings: the layer heights its staircase maths used, support when the piece has
   overhangs, and the brim and skirt rule below;
3. the printer file's ``slicer.overrides``.

A printer without presets (``slicer: prusa-slicer``) gets rigcad's generic configuration instead
(no start G-code, no temperatures: only for trying a mesh by hand, ``printer.ini``); no G-code is
made with it (:func:`generic_refusal`).

Brim rule (presets only): a piece gets a BRIM_WIDTH brim when its contact with the bed is small
(area below BRIM_MIN_CONTACT) or it is slender (height above BRIM_MAX_SLENDERNESS times the
smaller side of its contact patch's bounding box): both peel or tip off a PEI sheet. The brim,
and the preset's skirt around it, must leave the printer's bed margin free; what does not fit is
narrowed or dropped, and the piece's report says so. An override of brim_width or skirts wins.

The G-code's first line loses its date; the 3MF project (PrusaSlicer's CLI stores no settings in
it) gets the G-code's own configuration block as Metadata/Slic3r_PE.config, the file PrusaSlicer
reads settings from, and is rewritten with fixed zip dates and without creation dates, so the
same input gives the same bytes. PrusaSlicer's estimates are read from the G-code's comments. A
piece whose STL and configuration did not change (content hash, with the slicer's version) is
not sliced again. A missing slicer raises a FabricationError saying how to install it; the
caller decides whether the rest goes on.

Each slice runs on one CPU. PrusaSlicer slices a mesh in TBB tasks, and the lines each task cuts
from a layer are appended in the order the threads arrive (TriangleMeshSlicer's
slice_facet_at_zs), so a closed loop's first point, and with it where a perimeter starts when
several corners tie, can change from one run to the next: a 20 mm cube's first perimeter started
at another corner in 2 of some 8 full test runs, and a finely meshed cube sliced 198 times gave a
second G-code twice (on one CPU: 190 runs, one G-code). TBB sizes its thread pool from the CPU
affinity mask, so a slicer started on one CPU runs its tasks on one thread, in a fixed order. The
pieces are sliced side by side, each on its own CPU, so the cores stay busy. (Linux; elsewhere
the slicer picks its threads.) This does not make every piece's G-code the same bytes: larger
pieces (the paraboloid, the dome's quarters) still differ between one-thread runs (progress lines
and some moves), so only the cache above makes a re-run byte-identical.
"""

from __future__ import annotations

import hashlib
import io
import itertools
import os
import re
import shutil
import stat
import subprocess
import tempfile
import zipfile
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigcad.errors import FabricationError
from rigcad.fab import allowlist as A
from rigcad.fab.printers import Printer
from rigcad.fab.vendor import TEXT

SLICER = "prusa-slicer"
INSTALL_HINT = "install it with `apt-get install prusa-slicer` (Debian/Ubuntu) or from https://www.prusa3d.com/"
#: Seconds one slice may take before it is abandoned (a dome quarter takes ~45 s on one CPU).
TIMEOUT_S = 900
#: Part of every cache key: bump when the post-processing of G-code or 3MF, or the way the
#: slicer is run, changes (4: one CPU per slice, whose G-code differs from a many-thread run's;
#: 5: the 3MF project repaired and titled, repair_package).
OUTPUT_FORMAT = "rigcad-slice-5"

#: Brim width (mm) when the rule asks for one: PrusaSlicer's usual 5 mm, several loops of a 0.4 mm nozzle.
BRIM_WIDTH = 5.0
#: Contact area (mm2) below which a piece gets a brim: a 20 x 20 mm patch, about the smallest a
#: PLA part on a PEI sheet holds reliably through a long print.
BRIM_MIN_CONTACT = 400.0
#: Height / smaller side of the contact patch above which a piece gets a brim (lever against the bed).
BRIM_MAX_SLENDERNESS = 2.0
#: A brim narrower than this (mm) is not worth printing; the rule drops it and says so.
BRIM_MIN_USEFUL = 2.0
#: A facet touches the bed when its vertices are within this (mm) of the lowest point and it
#: faces down; the STL is float32 (about 1e-5 mm at 200 mm), so 1e-3 mm is well clear of rounding.
CONTACT_TOL = 1e-3


def find_slicer() -> str | None:
    return shutil.which(SLICER)


def slicer_version(exe: str) -> str:
    """The slicer's version line (part of every cache key)."""
    try:
        out = subprocess.run([exe, "--help"], capture_output=True, timeout=60, **TEXT)
    except (OSError, subprocess.TimeoutExpired) as err:
        raise FabricationError(f"{exe} does not run: {err}; {INSTALL_HINT}") from err
    for line in out.stdout.splitlines():
        if line.startswith("PrusaSlicer"):
            return line.strip()
    raise FabricationError(f"{exe} --help did not name its version; is it PrusaSlicer? {INSTALL_HINT}")


def _generic(printer: Printer, support: bool) -> dict[str, str]:
    """rigcad's generic configuration for a printer without presets (mm). Skirt and brim are off
    so a part may use the bed up to the profile's margin; support is on for pieces with overhangs."""
    v = printer.build_volume
    return {
        "printer_technology": "FFF",
        "bed_shape": f"0x0,{v.x:g}x0,{v.x:g}x{v.y:g},0x{v.y:g}",
        "max_print_height": f"{v.z:g}",
        "nozzle_diameter": f"{printer.nozzle:g}",
        "layer_height": f"{printer.layer_height:g}",
        "first_layer_height": f"{printer.first_layer_height:g}",
        "filament_diameter": f"{printer.filament_diameter:g}",
        "filament_density": f"{printer.material_density_g_cm3:g}",
        "filament_type": printer.material,
        "skirts": "0",
        "brim_width": "0",
        "gcode_flavor": "marlin2",
        "support_material": "1" if support else "0",
        "support_material_auto": "1",
        "fill_density": "20%",
        "perimeters": "3",
    }


def generic_refusal(printer: Printer) -> str:
    """Why rigcad's generic configuration (``slicer: prusa-slicer``, no presets) makes no G-code to
    print: it states no start G-code (no homing, no bed levelling) and no temperatures, so PrusaSlicer
    writes a cold bed (bed_temperature = 0) and its default nozzle temperature for whatever the
    filament is."""
    return (f"printer '{printer.name}' has no PrusaSlicer presets (slicer: prusa-slicer is rigcad's generic "
            "configuration: no start G-code, no temperatures, the bed at 0 C), so no G-code is made for it; name "
            "the machine's presets (slicer: vendor_bundle, printer_preset, ...), a PrusaSlicer printer preset as "
            "--printer, or its own settings exported from PrusaSlicer as a .ini (docs/instruments.md, 'Your printer')")


def printer_ini(printer: Printer, support: bool, piece: dict[str, str] | None = None) -> str:
    """The PrusaSlicer configuration for one piece (see the module docstring for its layers):
    ``piece`` holds rigcad's per-piece settings (brim, skirt) from :func:`placement`. Every
    setting is checked against rigcad.fab.allowlist before it is written; text rigcad adds in
    comments (the printer's name and description, the bundle's path) is escaped to one line."""
    cfg = printer.slicer_config
    if cfg is None:
        note = f"; presets not used: {printer.slicer_unavailable}" if printer.slicer_unavailable else ""
        return _render([f"rigcad: printer '{printer.name}' ({printer.description}): generic settings{note}"],
                       _generic(printer, support))
    lines = dict(cfg.settings)
    lines.update({"layer_height": f"{printer.layer_height:g}", "first_layer_height": f"{printer.first_layer_height:g}",
                  "support_material": "1" if support else "0"})
    lines.update(piece or {})
    lines.update(cfg.overrides)
    names = (f"{cfg.printer_preset} + {cfg.print_preset} + {cfg.filament_preset}" if cfg.kind == "bundle"
             else "a user configuration")
    head = [f"rigcad: printer '{printer.name}' ({printer.description})",
            f"{names} from {cfg.source} ({cfg.vendor}), then rigcad's layer heights, support, brim and skirt, "
            f"then the printer file's overrides ({', '.join(k for k, _ in cfg.overrides) or 'none'})"]
    return _render(head, lines)


def _one_line(text: str) -> str:
    """``text`` with every control character escaped, so a comment stays one comment line."""
    return re.sub(r"[\x00-\x1f\x7f]", lambda m: {"\n": "\\n", "\r": "\\r", "\t": "\\t"}.get(
        m.group(), f"\\x{ord(m.group()):02x}"), text)


def check_ini(text: str, what: str) -> None:
    """A PrusaSlicer .ini as rigcad hands it over: comments and ``key = value`` lines only, every
    setting allowed (rigcad.fab.allowlist.check_config); FabricationError otherwise."""
    settings: dict[str, str] = {}
    for n, line in enumerate(text.split("\n"), 1):
        if not line.strip() or line.startswith("#"):
            continue
        key, eq, value = line.partition(" = ")
        if not eq or not re.fullmatch(r"\w+", key) or "\r" in line:
            raise FabricationError(f"{what}, line {n}: not a 'key = value' line")
        settings[key] = value
    A.check_config(settings, what)


def _render(comments: list[str], settings: dict[str, str]) -> str:
    """A PrusaSlicer .ini: ``# comment`` lines, then ``key = value`` sorted by key, after
    rigcad.fab.allowlist.check_config (only settings that shape a print, each value one line)."""
    A.check_config(settings, "the configuration rigcad writes for PrusaSlicer")
    return ("".join(f"# {_one_line(c)}\n" for c in comments)
            + "".join(f"{k} = {settings[k]}\n" for k in sorted(settings)))


@dataclass(frozen=True)
class Footprint:
    """What the bed sees of a piece in print position (mm, mm2)."""

    extents: tuple[float, float, float]
    contact_area: float
    contact_size: tuple[float, float]  # bounding box of the contact patch in x, y

    @property
    def slenderness(self) -> float:
        """Height over the contact patch's smaller side (inf without contact)."""
        side = min(self.contact_size)
        return self.extents[2] / side if side > 0 else float("inf")


def footprint(stl: bytes) -> Footprint:
    """Extents and bed contact of a binary STL (as rigcad.export.mesh.stl_bytes writes it)."""
    if len(stl) < 84:
        raise FabricationError("not a binary STL (shorter than its 84-byte header)")
    n = int(np.frombuffer(stl, "<u4", 1, 80)[0])
    rec = np.frombuffer(stl, [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")], n, 84)
    tri = rec["v"].astype(np.float64)  # (n, 3, 3)
    pts = tri.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # (n, 3), length = 2 area
    down = (tri[:, :, 2].max(axis=1) <= lo[2] + CONTACT_TOL) & (normal[:, 2] < 0)
    area = float(np.abs(normal[down, 2]).sum() / 2)
    if down.any():
        cp = tri[down].reshape(-1, 3)
        size = (float(np.ptp(cp[:, 0])), float(np.ptp(cp[:, 1])))
    else:
        size = (0.0, 0.0)
    return Footprint(tuple(float(v) for v in hi - lo), area, size)


def placement(printer: Printer, fp: Footprint) -> tuple[dict[str, str], dict]:
    """rigcad's brim and skirt for a piece centred on the bed (the module docstring's rule):
    the settings for the .ini and a record of why, for the report."""
    cfg = printer.slicer_config
    over = dict(cfg.overrides) if cfg else {}
    eff = cfg.effective() if cfg else {}
    v = printer.build_volume
    room = min(v.x - fp.extents[0], v.y - fp.extents[1]) / 2 - printer.bed_margin  # free bed each side (mm)
    why = []
    if fp.contact_area < BRIM_MIN_CONTACT:
        why.append(f"contact area {fp.contact_area:.0f} mm2 < {BRIM_MIN_CONTACT:g} mm2")
    if fp.slenderness > BRIM_MAX_SLENDERNESS:
        why.append(f"height / contact side {fp.slenderness:.2f} > {BRIM_MAX_SLENDERNESS:g}")
    rec: dict = {"contact_area_mm2": fp.contact_area, "slenderness": fp.slenderness,
                 "free_bed_each_side_mm": room, "brim_wanted": bool(why), "brim_reason": "; ".join(why) or None}
    settings: dict[str, str] = {}
    if "brim_width" in over:
        brim = float(over["brim_width"])
        rec["brim_note"] = "brim_width from the printer file's overrides"
    else:
        brim = min(BRIM_WIDTH, np.floor(max(room, 0.0) * 10) / 10) if why else 0.0
        if why and brim < BRIM_MIN_USEFUL:
            rec["brim_note"] = f"brim wanted but only {max(room, 0.0):.1f} mm of bed around the piece: none printed"
            brim = 0.0
        settings["brim_width"] = f"{brim:g}"
    rec["brim_width_mm"] = brim
    skirts = int(float(eff.get("skirts", "0") or 0))
    if skirts and "skirts" not in over:
        nozzle = printer.nozzle or 0.4
        ring = brim + float(eff.get("skirt_distance", "0") or 0) + skirts * 1.25 * nozzle  # a loop ~1.25 nozzle wide
        if ring > room:
            settings["skirts"] = "0"
            rec["skirt_note"] = (f"the preset's skirt needs {ring:.1f} mm around the piece, "
                                 f"{max(room, 0.0):.1f} mm free: off")
            skirts = 0
    rec["skirts"] = skirts
    return settings, rec


def slice_job(printer: Printer, name: str, stl: bytes, support: bool, center: tuple[float, float]) -> "SliceJob":
    """The slicing job for one piece in print position: its configuration with rigcad's
    per-piece settings (printers with presets) and the reason it cannot run, if any."""
    if printer.slicer_config is None:
        return SliceJob(name, stl, printer_ini(printer, support), center,
                        problem=printer.slicer_unavailable or generic_refusal(printer))
    settings, rec = placement(printer, footprint(stl))
    rec["support_material"] = support
    return SliceJob(name, stl, printer_ini(printer, support, settings), center, tuple(sorted(rec.items())))


@dataclass(frozen=True)
class SliceJob:
    """One piece to slice: its STL in print position, its configuration, the bed point to centre
    it on; ``placement`` records rigcad's per-piece settings (brim, skirt, support) and why;
    ``problem`` says why it cannot be sliced (presets named but not installed)."""

    name: str
    stl: bytes
    ini: str
    center: tuple[float, float]
    placement: tuple[tuple[str, object], ...] = ()
    problem: str | None = None

    def key(self, version: str) -> str:
        h = hashlib.sha256(version.encode())
        h.update(OUTPUT_FORMAT.encode())
        h.update(self.ini.encode())
        h.update(repr(self.center).encode())
        h.update(self.stl)
        return h.hexdigest()


@dataclass(frozen=True)
class SliceResult:
    name: str
    gcode: bytes
    seconds: float  # wall time of the slicer run (0 when reused)
    estimates: dict
    warnings: tuple[str, ...]
    project: bytes = b""  # the PrusaSlicer 3MF project, settings inside
    placement: dict = field(default_factory=dict)


_GENERATED = re.compile(rb"^(; generated by PrusaSlicer[^\n]*?) on \d{4}-\d\d-\d\d at \d\d:\d\d:\d\d UTC", re.M)
_CONFIG_BLOCK = re.compile(rb"^; prusaslicer_config = begin\n(.*?)^; prusaslicer_config = end", re.M | re.S)
_MODEL_DATES = re.compile(rb'(<metadata name="(?:CreationDate|ModificationDate)">)[^<]*(</metadata>)')
_CONFIG_LINE = re.compile(rb"^; (\w+) = (.*)$")
#: The 3MF member PrusaSlicer reads a project's settings from ("; key = value" lines).
PROJECT_CONFIG = "Metadata/Slic3r_PE.config"
#: Zip entry date of every 3MF member: the earliest a zip can hold, so no clock leaks in.
ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)


def normalise(gcode: bytes) -> bytes:
    """Drop the date from the 'generated by' line: same input, same bytes."""
    return _GENERATED.sub(rb"\1", gcode, count=1)


def project_3mf(exported: bytes, gcode: bytes, name: str | None = None) -> bytes:
    """PrusaSlicer's CLI 3MF (model and placement, no settings) made into a project: the G-code's
    configuration block, the allow-listed settings that sliced it (rigcad.fab.allowlist; PrusaSlicer
    reads the others, never given, as its defaults), stored as Metadata/Slic3r_PE.config in the
    format PrusaSlicer writes ("; generated by ..." then "; key = value" lines); creation dates
    emptied and zip dates fixed so the bytes are deterministic. The result is read back and
    checked (:func:`check_project`): a project never carries a program or a path to PrusaSlicer.

    Repaired on the way (:func:`repair_package`), so that strict 3MF readers (lib3mf) open it:
    PrusaSlicer 2.5's CLI lists a thumbnail (/Metadata/thumbnail.png) in _rels/.rels that it never
    writes, marks build items with an attribute outside the 3MF core, and titles the model after its
    output file ("piece") with unnamed objects. The project and its object are titled ``name`` (the piece; default: the object's name in PrusaSlicer's
    model configuration, its STL's name)."""
    block = _CONFIG_BLOCK.search(gcode)
    if block is None:
        raise FabricationError("the G-code has no '; prusaslicer_config = begin ... end' block to put into the 3MF")
    kept = []
    for line in block.group(1).splitlines(keepends=True):
        m = _CONFIG_LINE.match(line)
        if m is None:
            continue
        key, value = m.group(1).decode(), m.group(2).decode("utf-8", "replace")
        if key in A.ALLOWED_KEYS:
            kept.append(line)
        elif key in A.REFUSED and not A.harmless(key, value):
            raise FabricationError(f"{SLICER} sliced with {key} set ({A.REFUSED[key][0]}), which rigcad never "
                                   "hands it; the G-code is not kept")
    first = gcode.split(b"\n", 1)[0]
    config = first + b"\n\n" + b"".join(kept)
    out = io.BytesIO()
    try:
        with zipfile.ZipFile(io.BytesIO(exported)) as src, zipfile.ZipFile(out, "w") as dst:
            members = {info.filename: src.read(info.filename) for info in src.infolist()
                       if info.filename != PROJECT_CONFIG}
            members[PROJECT_CONFIG] = config
            for member, data in repair_package(members, name).items():
                _add(dst, member, data)
    except zipfile.BadZipFile as err:
        raise FabricationError(f"{SLICER} wrote a 3MF that is not a zip: {err}") from err
    project = out.getvalue()
    check_project(project)
    return project


_RELATIONSHIP = re.compile(rb'\s*<Relationship\b[^>]*?\bTarget="([^"]*)"[^>]*/>')
_MODEL_TEXT = re.compile(rb'(<metadata name="(?:Title|Description)">)[^<]*(</metadata>)')
_UNNAMED_OBJECT = re.compile(rb'<object (?![^>]*\bname=)')
_CONFIG_OBJECT_NAME = re.compile(rb'<metadata type="object" key="name" value="([^"]*)"/>')
_PRINTABLE_ITEM = re.compile(rb'(<item\b[^>]*?) printable="1"')


def repair_package(members: dict[str, bytes], name: str | None = None) -> dict[str, bytes]:
    """A PrusaSlicer 3MF's members (name -> bytes, in archive order) as rigcad passes them on:
    _rels/.rels without relationships to parts the archive lacks (PrusaSlicer 2.5's CLI names a
    thumbnail it does not write, and lib3mf refuses the package: "Could not create OPC Part"); the
    model's creation dates emptied (no clock in the bytes); its Title and Description, and every
    unnamed object, set to ``name`` (default: the object's name in Metadata/Slic3r_PE_model.config
    without its .stl); build items without PrusaSlicer's ``printable="1"``, an attribute the 3MF
    core specification does not have (lib3mf's strict mode refuses it: "Invalid Attribute in
    namespace"), whose absence PrusaSlicer reads as the same default, printable. Raises
    FabricationError when no name is given or found."""
    from xml.sax.saxutils import escape, quoteattr

    if name is None:
        found = _CONFIG_OBJECT_NAME.search(members.get(_MODEL_CONFIG, b""))
        if found is None:
            raise FabricationError(f"the 3MF project names no object in {_MODEL_CONFIG}, and no name was given")
        name = found.group(1).decode("utf-8", "replace").removesuffix(".stl")
    out = {}
    for member, data in members.items():
        if member == "_rels/.rels":
            data = _RELATIONSHIP.sub(lambda m: m.group(0) if m.group(1).decode().lstrip("/") in members else b"", data)
        elif member.endswith(".model"):
            data = _MODEL_DATES.sub(rb"\1\2", data)
            data = _MODEL_TEXT.sub(lambda m: m.group(1) + escape(name).encode() + m.group(2), data)
            data = _UNNAMED_OBJECT.sub(b"<object name=" + quoteattr(name).encode() + b" ", data)
            data = _PRINTABLE_ITEM.sub(rb"\1", data)
        out[member] = data
    return out


#: Per-object and per-volume keys PrusaSlicer 2.5's CLI writes into Metadata/Slic3r_PE_model.config.
MODEL_KEYS = frozenset({"name", "volume_type", "matrix", "source_file", "source_object_id", "source_volume_id",
                        "source_offset_x", "source_offset_y", "source_offset_z", "source_in_inches",
                        "source_in_meters"})
_MODEL_CONFIG = "Metadata/Slic3r_PE_model.config"


def check_project(project: bytes) -> None:
    """Read a 3MF project as PrusaSlicer would and refuse (FabricationError) any setting in it
    that is not on rigcad.fab.allowlist's list, so opening the project runs nothing: the
    project's configuration, and the per-object settings of its model configuration."""
    try:
        with zipfile.ZipFile(io.BytesIO(project)) as z:
            names = set(z.namelist())
            config = z.read(PROJECT_CONFIG).decode("utf-8", "replace") if PROJECT_CONFIG in names else ""
            model = z.read(_MODEL_CONFIG).decode("utf-8", "replace") if _MODEL_CONFIG in names else ""
    except zipfile.BadZipFile as err:
        raise FabricationError(f"the 3MF project is not a zip: {err}") from err
    settings = dict(re.findall(r"^; (\S+) = (.*)$", config, re.M))
    A.check_config(settings, f"the 3MF project's {PROJECT_CONFIG}")
    for key in re.findall(r'<metadata type="(?:object|volume)" key="([^"]*)"', model):
        if key not in MODEL_KEYS and key not in A.ALLOWED_KEYS:
            raise FabricationError(f"the 3MF project's {_MODEL_CONFIG}: setting {key} is not kept: "
                                   f"{A.why_refused(key)}")


def _add(z: zipfile.ZipFile, name: str, data: bytes) -> None:
    info = zipfile.ZipInfo(name, ZIP_EPOCH)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    z.writestr(info, data)


def parse_estimates(gcode: bytes) -> dict:
    """The slicer's estimates: printing time (s, normal mode), filament (mm, cm3, g)."""
    tail = gcode[-200_000:].decode("utf-8", "replace")
    out: dict = {}
    m = re.search(r"^; estimated printing time \(normal mode\) = (.+)$", tail, re.M)
    if m:
        secs = 0
        for num, unit in re.findall(r"(\d+)([dhms])", m.group(1)):
            secs += int(num) * {"d": 86400, "h": 3600, "m": 60, "s": 1}[unit]
        out["print_time_s"] = secs
        out["print_time_text"] = m.group(1).strip()
    for key, pat in (("filament_mm", r"filament used \[mm\]"), ("filament_cm3", r"filament used \[cm3\]"),
                     ("filament_g", r"filament used \[g\]")):
        m = re.search(rf"^; {pat} = ([\d.]+)", tail, re.M)
        if m:
            out[key] = float(m.group(1))
    m = re.search(r"^; layer_height = ([\d.]+)", tail, re.M)
    if m:
        out["layer_height_mm"] = float(m.group(1))
    return out


def _warnings(text: str) -> tuple[str, ...]:
    """Warning and error lines of the slicer's log (its trace/debug/info chatter left out)."""
    bad = []
    for line in text.splitlines():
        low = line.lower()
        if "[trace]" in low or "[debug]" in low or "[info]" in low:
            continue
        if "warning" in low or "error" in low or "repaired" in low or "open edges" in low:
            bad.append(line.strip())
    return tuple(bad)


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "piece"


#: The names of the files in a slicing folder besides the piece's STL: what rigcad writes and
#: the two outputs it asks PrusaSlicer for by explicit path.
RUN_INI, RUN_GCODE, RUN_3MF = "piece.ini", "piece.gcode", "piece.3mf"


def _slicer(exe: str, args: list[str], d: Path, job: SliceJob) -> tuple[subprocess.CompletedProcess, float]:
    import time

    t0 = time.perf_counter()
    try:
        proc = subprocess.run([exe, *args], cwd=d, capture_output=True, timeout=TIMEOUT_S, **TEXT)
    except subprocess.TimeoutExpired as err:
        raise FabricationError(f"{job.name}: {SLICER} took over {TIMEOUT_S} s") from err
    log = proc.stdout + "\n" + proc.stderr
    if proc.returncode != 0:
        lines = [ln for ln in log.splitlines() if ln.strip() and "[trace]" not in ln][-3:]
        hint = " (the piece does not fit the bed: split or orient it first)" if "could not fit" in log else ""
        raise FabricationError(f"{job.name}: {SLICER} failed with exit code {proc.returncode}{hint}: "
                               + " | ".join(lines))
    return proc, time.perf_counter() - t0


_next_cpu = itertools.count()


def _on_one_cpu() -> None:
    """Thread-pool initializer: the calling thread, and so every slicer it starts (a child keeps
    its parent thread's affinity), runs on one CPU of those this process may use; successive
    threads, and processes by their id, take different ones."""
    if not hasattr(os, "sched_setaffinity"):
        return
    cpus = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpus[(os.getpid() + next(_next_cpu)) % len(cpus)]})


def slicing_pool(workers: int) -> ThreadPoolExecutor:
    """The threads that run the slicers: ``workers`` of them, each on one CPU (see the module's
    note on determinism)."""
    return ThreadPoolExecutor(max_workers=max(1, workers), initializer=_on_one_cpu)


def _output(d: Path, name: str, job: SliceJob) -> bytes:
    """The output rigcad asked for at ``d/name``: a regular file (not a link), read without
    following links."""
    path = d / name
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError as err:
        raise FabricationError(f"{job.name}: {SLICER} did not write {name} where rigcad asked "
                               f"({err.strerror})") from err
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
            raise FabricationError(f"{job.name}: {SLICER}'s {name} is not a regular file")
        return fh.read()


def _run(exe: str, job: SliceJob) -> SliceResult:
    """Slice one piece in a private temporary folder: PrusaSlicer writes the G-code, then the 3MF,
    each to the explicit path rigcad gives with --output (no name template, no other folder).
    Afterwards the folder must hold exactly rigcad's inputs and those two files."""
    with tempfile.TemporaryDirectory(prefix="rigcad-slice-") as tmp:
        d = Path(tmp)
        stl = f"{_safe(job.name)}.stl"  # PrusaSlicer names the object (and its G-code label) after the file
        (d / stl).write_bytes(job.stl)
        (d / RUN_INI).write_text(job.ini, encoding="utf-8")
        center = f"{job.center[0]:g},{job.center[1]:g}"
        proc, seconds = _slicer(exe, ["--export-gcode", "--load", RUN_INI, "--center", center,
                                      "--output", str(d / RUN_GCODE), stl], d, job)
        _slicer(exe, ["--export-3mf", "--center", center, "--output", str(d / RUN_3MF), stl], d, job)
        extra = sorted(set(os.listdir(d)) - {stl, RUN_INI, RUN_GCODE, RUN_3MF})
        if extra:
            raise FabricationError(f"{job.name}: {SLICER} wrote {', '.join(extra)[:200]}, which rigcad did not ask "
                                   "for; the outputs are not kept")
        gcode = normalise(_output(d, RUN_GCODE, job))
        project = project_3mf(_output(d, RUN_3MF, job), gcode, job.name)
    log = proc.stdout + "\n" + proc.stderr
    return SliceResult(job.name, gcode, seconds, parse_estimates(gcode), _warnings(log), project, dict(job.placement))


def slice_all(jobs: list[SliceJob], cached: dict[str, tuple] | None = None,
              workers: int | None = None, on_done=None) -> tuple[list[SliceResult], str]:
    """Slice every job, ``workers`` at a time (default: the cores, at most 4). ``cached`` maps a
    job name to (key, gcode bytes, 3MF bytes) of an earlier run; a job with the same key is
    reused. ``on_done(result)`` is called as each piece is done (reused ones first). Returns the
    results in job order and the slicer's version."""
    exe = find_slicer()
    if exe is None:
        raise FabricationError(f"{SLICER} is not installed, so no G-code was written; {INSTALL_HINT}")
    blocked = [j for j in jobs if j.problem]
    if blocked:
        raise FabricationError(f"no G-code was written: {blocked[0].problem}")
    for job in jobs:  # every job's configuration, before any slicing starts
        check_ini(job.ini, f"{job.name}'s configuration")
    version = slicer_version(exe)
    cached = cached or {}
    results: dict[str, SliceResult] = {}
    todo = []
    for job in jobs:
        old = cached.get(job.name)
        if old and len(old) == 3 and old[0] == job.key(version) and old[2]:
            results[job.name] = SliceResult(job.name, old[1], 0.0, parse_estimates(old[1]), (), old[2],
                                            dict(job.placement))
            if on_done:
                on_done(results[job.name])
        else:
            todo.append(job)
    n = workers or min(4, os.cpu_count() or 1)
    with slicing_pool(n) as pool:
        futures = [pool.submit(_run, exe, j) for j in todo]
        for fut in as_completed(futures):
            res = fut.result()
            results[res.name] = res
            if on_done:
                on_done(res)
    return [results[j.name] for j in jobs], version
