"""Printer profiles (``printers/<name>.yaml`` on the profile search path): build volume, layer height, nozzle or laser
spot, material, and what rigcad needs to estimate a print. Read through the one YAML reader
(rigcad.profile.loader, with its file:line marks and ``extends``) and validated with the same
:class:`rigcad.profile.schema.Spec` rules as rig profiles: every length carries its unit.
Inside: mm, float64.

``slicer`` is ``none``, ``prusa-slicer`` (a generic configuration rigcad writes itself) or a
mapping naming PrusaSlicer's own presets (rigcad.fab.vendor)::

    slicer:
      vendor_bundle: PrusaResearch        # an installed bundle, or a .ini beside this file or on the search path
      printer_preset: Original Prusa i3 MK3S & MK3S+
      print_preset: 0.15mm QUALITY @MK3
      filament_preset: Prusament PLA
      overrides: {brim_width: 5}          # settings that shape a print (rigcad.fab.allowlist), values checked

The resolved preset (with the overrides) is what PrusaSlicer prints with, so it is the truth
for the figures both state: layer_height, first_layer_height, nozzle, filament_diameter,
material and material_density_g_cm3 may be left out of the printer file and are then read from
the preset; stated, they must agree with it (as must build_volume with the preset's bed_shape and
max_print_height), otherwise loading fails naming both values. When no PrusaSlicer is installed
(so no bundle), the printer file's own figures stand and G-code reports why it cannot be made.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab import vendor as V
from rigcad.parts.process import ProcessErrors, from_measurements
from rigcad.profile.loader import RawProfile, find_file, load_raw
from rigcad.profile.paths import PRINTERS_SUBDIR, display, names_on_search_path, search_path
# The schema's own readers, so printer files follow the same unit, range and error rules.
from rigcad.profile.schema import REQUIRED, Spec, convert_value, read_section, spec, suggest, unknown_key

#: Thinnest layer a printer file may give (mm): a printer's resolution. The finest commercial
#: layers (SLA, material jetting) are 0.014..0.025 mm; thinner is a unit slip, and every layer of
#: every piece is sliced in memory (1e-9 mm reached 21 GB in two minutes).
MIN_LAYER_MM = 0.01


@dataclass(frozen=True)
class BuildVolume:
    """The printable box (mm): x, y the bed, z the height."""

    # 10 mm to 2 m: below, no part of a rig fits; above, larger than any gantry printer made
    x: float = spec("length", "bed width", lo=10, hi=2000)
    y: float = spec("length", "bed depth", lo=10, hi=2000)
    z: float = spec("length", "largest print height", lo=10, hi=2000)


@dataclass(frozen=True)
class AlignmentPin:
    """Dowel pins that align split pieces: a hole of diameter + clearance, depth into each piece."""

    # a pin is a stock dowel or filament: 0.5..20 mm; a clearance past 1 mm no longer aligns; a hole
    # deeper than 100 mm is deeper than the pieces are thick
    diameter: float = spec("length", "pin diameter", "1.75 mm", lo=0.5, hi=20)
    clearance: float = spec("length", "added to the hole diameter", "0.15 mm", lo=0, hi=1)
    depth: float = spec("length", "hole depth into each piece", "6 mm", lo=0.5, hi=100)

    @property
    def hole_radius(self) -> float:
        return (self.diameter + self.clearance) / 2


@dataclass(frozen=True)
class Printer:
    """A validated printer profile (mm). ``nozzle`` (FDM) or ``pixel`` (SLA laser spot / pixel)
    is the in-layer resolution; ``layer_height`` the step between layers."""

    name: str
    description: str
    process: str
    build_volume: BuildVolume
    bed_margin: float
    layer_height: float
    first_layer_height: float
    nozzle: float | None
    pixel: float | None
    filament_diameter: float | None
    material: str
    material_density_g_cm3: float
    deposition_rate_mm3_s: float
    layer_time_s: float
    slicer: str
    alignment_pin: AlignmentPin
    source: str
    #: Stock printed in front of every mirror (mm), or None for 'auto' (what the staircase needs).
    sanding_stock: float | None = None
    marks: dict = field(compare=False, repr=False, default_factory=dict)
    #: PrusaSlicer's presets and overrides, resolved (None for slicer none / generic prusa-slicer).
    slicer_config: V.VendorConfig | None = None
    #: Why presets named in the printer file could not be read (no PrusaSlicer installed), or None.
    slicer_unavailable: str | None = None
    #: Figures read from the preset because the printer file left them out.
    from_preset: tuple[str, ...] = ()
    #: The process's dimensional errors (``process_errors:``; rigcad.parts.process), or the
    #: process's published defaults (DEFAULT_PROCESS) when the file states none.
    process_errors: ProcessErrors | None = None
    #: The machine the file is for ('' when it does not say), and why another printer's presets
    #: stand in for it ('' when they do not).
    model: str = ""
    stand_in: str = ""

    @property
    def usable(self) -> tuple[float, float, float]:
        """The box a part must fit (mm): the bed less its margin on each side, the full height."""
        v = self.build_volume
        return (v.x - 2 * self.bed_margin, v.y - 2 * self.bed_margin, v.z)

    def describe(self) -> dict[str, Any]:
        """Resolved values for fab.json, units in the keys."""
        v = self.build_volume
        out = {"name": self.name, "description": self.description, "process": self.process,
               "model": self.model or None, "stand_in": self.stand_in or None,
               "source": self.source, "build_volume_mm": [v.x, v.y, v.z], "bed_margin_mm": self.bed_margin,
               "layer_height_mm": self.layer_height, "first_layer_height_mm": self.first_layer_height,
               "nozzle_mm": self.nozzle, "pixel_mm": self.pixel, "filament_diameter_mm": self.filament_diameter,
               "material": self.material, "material_density_g_cm3": self.material_density_g_cm3,
               "deposition_rate_mm3_s": self.deposition_rate_mm3_s, "layer_time_s": self.layer_time_s,
               "slicer": self.slicer,
               "sanding_stock_mm": "auto" if self.sanding_stock is None else self.sanding_stock,
               "slicer_presets": self.slicer_config.describe() if self.slicer_config else None,
               "figures_from_preset": list(self.from_preset),
               "process_errors": self.process_errors.describe() if self.process_errors else None,
               "alignment_pin": {"diameter_mm": self.alignment_pin.diameter,
                                 "clearance_mm": self.alignment_pin.clearance,
                                 "depth_mm": self.alignment_pin.depth}}
        return out


#: Top-level keys of a printer file and how each is read (sections are handled below).
_TOP: dict[str, Spec] = {
    "description": Spec("str", "one line saying what machine this is", ""),
    "process": Spec("choice", "printing process", choices=("fdm", "sla")),
    "bed_margin": Spec("length", "kept free on each side of the bed", "0 mm", lo=0, hi=500),
    # layers: at least MIN_LAYER_MM (a printer's resolution), at most 1 mm (the coarsest FDM layers)
    "layer_height": Spec("length", "layer height", lo=MIN_LAYER_MM, hi=1.0),
    "first_layer_height": Spec("length", "first layer height (default: the layer height)", None, lo=MIN_LAYER_MM,
                               hi=1.0),
    # FDM nozzles are made 0.1..1.2 mm, large-format ones up to ~3 mm
    "nozzle": Spec("length", "FDM nozzle (or tip) diameter", None, lo=0.05, hi=3.0),
    # SLA/DLP/LCD pixels and laser spots are ~0.02..0.15 mm
    "pixel": Spec("length", "SLA pixel or laser spot size", None, lo=0.005, hi=1.0),
    # filament is sold at 1.75, 2.85 and 3 mm
    "filament_diameter": Spec("length", "FDM filament diameter", None, lo=1.0, hi=3.5),
    "material": Spec("str", "material name", "unspecified"),
    # from foams (~0.1) to the densest printable metals (tungsten, 19.3)
    "material_density_g_cm3": Spec("float", "material density in g/cm3", lo=0.1, hi=25),
    # the fastest pellet extruders deposit a few hundred mm3/s; a layer never waits an hour
    "deposition_rate_mm3_s": Spec("float", "volume deposited per second, for estimates without a slicer "
                                  "(mm3/s; 0 for SLA)", 0.0, lo=0, hi=2000),
    "layer_time_s": Spec("float", "time per layer beyond the deposition, for estimates (s)", 0.0, lo=0, hi=3600),
    "slicer": Spec("choice", "slicer rigcad runs for G-code (or a mapping of PrusaSlicer presets)", "none",
                   choices=("none", "prusa-slicer")),
    "model": Spec("str", "the machine this file is for, as its maker names it (e.g. 'Original Prusa MK4'); with "
                  "slicer presets, refused when they are another printer's unless stand_in says why", ""),
    "stand_in": Spec("str", "why the slicer presets of another printer are used for this one (one line); left out, "
                     "presets for another model than 'model' are refused", ""),
    "sanding_stock": Spec("str", "material printed in front of every mirror surface, sanded off down to the "
                          "templates before the coating: 'auto' (the stock the staircase of each part needs in its "
                          "print orientation) or a length such as '0.1 mm' ('0 mm': none)", "auto"),
}
#: Largest sanding stock a printer file may ask for (mm): several layers of any printer; more is a unit slip.
MAX_SANDING_STOCK = 2.0
#: Control characters, never in a printer file's text (a line break would start a new slicer setting).
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f]")
#: Keys of the ``slicer`` mapping.
_SLICER_KEYS = ("vendor_bundle", "printer_preset", "print_preset", "filament_preset", "overrides")
#: Printer keys a PrusaSlicer preset also states -> (preset key, unit of the preset's number).
_PRESET_FIGURES = {"layer_height": "layer_height", "first_layer_height": "first_layer_height",
                   "nozzle": "nozzle_diameter", "filament_diameter": "filament_diameter",
                   "material_density_g_cm3": "filament_density", "material": "filament_type"}
#: Two figures agree when they differ by less than this (mm, or g/cm3 for the density): far
#: below any printer's resolution, above the rounding of decimal text such as "0.15".
AGREE_TOL = 1e-6
_SECTIONS = {"build_volume": BuildVolume, "alignment_pin": AlignmentPin}
#: Keys of ``process_errors`` (rigcad.parts.process), of its ``hole_shrink`` and of its ``measured``.
_PROCESS_KEYS = ("scale", "position", "hole_shrink", "layer_step", "source", "measured")
_SHRINK_KEYS = ("vertical", "horizontal", "per_mm")
_MEASURED_KEYS = ("lengths", "holes_vertical", "holes_horizontal")
#: Largest relative error a printer file may state (a fraction): 5 % is a printer out of calibration
#: by far; more is a slip (0.2 for 0.2 %).
MAX_SCALE = 0.05
#: Largest hole shrink or position error a printer file may state (mm): several nozzle widths.
MAX_PROCESS_MM = 2.0
#: The process errors of a printer file that states none, by process, from published figures:
#: FDM: Xometry's guideline for FDM parts, "+/- 0.004 in or +/- 0.002 in per inch, whichever is
#: greater" (https://xometry.zendesk.com/hc/en-us/articles/217170527-Accuracy-for-3D-Printed-Plastics),
#: holes "0.1-0.3 mm undersize" (Layer X, https://layerx3d.in/blog/3d-printing-tolerances-dimensional-accuracy-guide:
#: the middle for vertical axes, the top of the range for horizontal ones, whose top droops);
#: SLA: Layer X's "+/- 0.1 mm standard" and "a further 0.1-0.2 % over 48 hours" (the top), holes as the
#: position. layer_step: the file's layer height.
DEFAULT_PROCESS = {
    "fdm": {"scale": 0.002, "position": 0.1016, "vertical": 0.2, "horizontal": 0.3,
            "source": "default for fdm printers: Xometry's FDM guideline (0.004 in + 0.002 in/in), holes 0.1-0.3 mm "
                      "undersize (Layer X)"},
    "sla": {"scale": 0.002, "position": 0.1, "vertical": 0.1, "horizontal": 0.1,
            "source": "default for sla printers: Layer X's +-0.1 mm and 0.1-0.2 % post-cure shrinkage"},
}


#: PrusaSlicer's automatic extrusion width: 1.125 x the nozzle (its rule for a width set to 0).
AUTO_WIDTH_OVER_NOZZLE = 1.125


def extrusion_width(value, nozzle: float, fallback=None) -> float:
    """A PrusaSlicer extrusion width (mm) as the slicer reads it: a length, a percentage of the nozzle, or 0
    (or empty) for the ``fallback`` key's value or, failing it, the automatic width (AUTO_WIDTH_OVER_NOZZLE x
    the nozzle). Raises ValueError on text that is none of these."""
    v = str(value).strip() or "0"
    w = nozzle * float(v[:-1]) / 100.0 if v.endswith("%") else float(v)
    if w > 0:
        return w
    return extrusion_width(fallback, nozzle) if fallback not in (None, "") else AUTO_WIDTH_OVER_NOZZLE * nozzle


def perimeter_width(printer) -> float:
    """The width (mm) of an FDM printer's perimeter lines: its resolved slicer settings'
    ``perimeter_extrusion_width``, else ``extrusion_width``, else the automatic width (:func:`extrusion_width`);
    without slicer settings, or with unreadable ones, the automatic width of its nozzle (0.4 mm when it
    states none). The one home of this figure: the pin walls (rigcad.fab.split.pin_wall), the printed skin
    (rigcad.fab.loads.skin) and the print-time model's shell (rigcad.fab.estimate.shell_thickness)."""
    nozzle = getattr(printer, "nozzle", None) or 0.4
    cfg = getattr(printer, "slicer_config", None)
    eff = cfg.effective() if cfg is not None else {}
    try:
        return extrusion_width(eff.get("perimeter_extrusion_width", "0"), nozzle, eff.get("extrusion_width"))
    except ValueError:
        return AUTO_WIDTH_OVER_NOZZLE * nozzle


def printer_path(name: str | Path) -> Path:
    """A printer file by path, or by name under ``printers/`` on the profile search path. Only a
    YAML file (``.yaml``/``.yml``, its link target too) outside the system folders
    (rigcad.fab.vendor.SYSTEM_DIRS) is read: ``--printer /etc/shadow`` is refused before the file
    is opened, so its content is never shown."""
    if not str(name).strip() or "\x00" in str(name):
        raise ProfileError(f"printer {str(name)!r}: name a printer (e.g. prusa_mk3s) or give the path of its .yaml file")
    spec = Path(name)
    if spec.suffix not in ("", ".yaml", ".yml"):
        raise ProfileError(f"printer {str(name)[:200]!r} is not a printer file: printer files are YAML (.yaml), "
                           f"found by name in {', '.join(display(d) + '/' for d in search_path(PRINTERS_SUBDIR))}")
    if not spec.suffix:
        spec = spec.with_suffix(".yaml")
    refused = ProfileError(f"printer {str(name)[:200]!r} leads to a system folder or to a file that is not YAML, "
                           "so it is not read; name a printer or give the path of its .yaml file")
    if (spec.is_absolute() or len(spec.parts) > 1) and V.in_system_dir(spec.resolve()):
        raise refused
    path = find_file(spec if len(spec.parts) > 1 or spec.is_absolute() else spec.stem, "printer", sub=PRINTERS_SUBDIR)
    real = path.resolve()
    if V.in_system_dir(real) or real.suffix not in (".yaml", ".yml"):
        raise refused
    return path


def available_printers() -> list[str]:
    """Printer names on the search path (first folder wins for a name)."""
    return names_on_search_path(PRINTERS_SUBDIR)


def load_printer(name: str | Path) -> Printer:
    """Read and validate a printer profile; errors name the file:line, key, value and what is valid.
    Every problem of the file is reported at once (rigcad.fab.vendor.Problems): its unknown keys,
    bad values, presets the installed slicer lacks, figures that disagree with them, a model the
    presets are not for. A name that is no printer file but a printer preset of an installed
    PrusaSlicer bundle (``"Creality Ender-3 V2 (0.4 mm nozzle)"``) is that printer
    (:func:`preset_printer`)."""
    by_preset = preset_printer(name)
    if by_preset is not None:
        return _from_raw(*by_preset)
    try:
        path = printer_path(name)
    except ProfileError as err:
        if " " not in str(name).strip():
            raise
        raise ProfileError(f"{err}; nor is it a printer preset of an installed PrusaSlicer bundle (exactly as "
                           "`python -m rigcad.fab.vendor BUNDLE printer` lists them, e.g. 'Creality Ender-3 V2 "
                           "(0.4 mm nozzle)')", where=err.where) from None
    return _from_raw(load_raw(path), path)


def _slug(text: str) -> str:
    """A printer preset's name as a file name (the fab folder's): lower case, letters, digits and '_'."""
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:80] or "printer"


def preset_printer(name: str | Path) -> tuple[RawProfile, Path] | None:
    """The printer file a PrusaSlicer printer preset stands for, when ``name`` is no printer file on
    the search path but exactly the name of an FFF printer preset of an installed vendor bundle:
    its bundle's default print and filament presets (the preset's default_print_profile and
    default_filament_profile), the bed and height from its bed_shape and max_print_height, its
    printer model's name as ``model``; everything else as a printer file that leaves it out (the
    figures from the presets, the process errors the published defaults). None otherwise; a name
    without a space (every printer file's) or a path reads no bundle."""
    text = str(name)
    if " " not in text.strip() or "/" in text or "\\" in text or text.endswith((".yaml", ".yml")) or "\x00" in text:
        return None
    if any((d / f"{text}.yaml").is_file() for d in search_path(PRINTERS_SUBDIR)):
        return None
    for stem, bundle_path in V.available_bundles().items():
        try:
            bundle = V.load_bundle(bundle_path)
            if text not in bundle.presets("printer"):
                continue
            flat = bundle.flatten("printer", text)
        except (ProfileError, FabricationError):
            continue  # a bundle rigcad cannot read names no printer here
        if flat.get("printer_technology", "FFF") != "FFF":
            continue
        size = _bed_size(flat.get("bed_shape", ""))
        defaults = {k: flat.get(f"default_{k}_profile", "").strip().strip('"') for k in ("print", "filament")}
        if size is None or not all(defaults.values()):
            continue
        data = {"description": f"{text} (PrusaSlicer's preset, {bundle.label()})",
                "model": bundle.model_name(flat.get("printer_model", "")) or text, "process": "fdm",
                "build_volume": {"x": f"{size[0]!r} mm", "y": f"{size[1]!r} mm",
                                 "z": f"{float(flat.get('max_print_height', '0') or 0)!r} mm"},
                "slicer": {"vendor_bundle": stem, "printer_preset": text, "print_preset": defaults["print"],
                           "filament_preset": defaults["filament"]}}
        return RawProfile(name=_slug(text), data=data, marks={}, sources=(bundle_path,)), bundle_path
    return None


def _bed_size(bed_shape: str) -> tuple[float, float] | None:
    """The bed's x and y extent (mm) from PrusaSlicer's ``bed_shape`` ("0x0,250x0,250x210,0x210")."""
    try:
        pts = [tuple(float(c) for c in p.split("x")) for p in bed_shape.split(",")]
    except ValueError:
        return None
    if not pts or any(len(p) != 2 for p in pts):
        return None
    return (max(p[0] for p in pts) - min(p[0] for p in pts), max(p[1] for p in pts) - min(p[1] for p in pts))


def _from_raw(raw: RawProfile, path: Path) -> Printer:
    """A printer from its raw file (or a preset's stand-in for one, :func:`preset_printer`)."""
    problems: list = []
    valid = sorted([*_TOP, *_SECTIONS, "process_errors"])
    for key in raw.data:
        if key not in valid:
            problems.append(ProfileError(f"unknown printer key {unknown_key(key)}{suggest(str(key), valid)}; valid: "
                                         f"{', '.join(valid)}", where=raw.where((key,))))
    slicer_cfg, unavailable = None, None
    if isinstance(raw.data.get("slicer"), dict):
        try:
            slicer_cfg, unavailable = _read_slicer(raw, path)
        except (ProfileError, FabricationError) as err:
            V.gather(problems, err)
    preset: dict[str, Any] = {}
    if slicer_cfg:
        try:
            preset = _preset_figures(slicer_cfg, raw)
        except ProfileError as err:
            problems.append(err)
    top: dict[str, Any] = {}
    from_preset = []
    for key, s in _TOP.items():
        try:
            _top_value(key, s, raw, path, top, preset, from_preset, slicer_cfg, unavailable)
        except ProfileError as err:
            problems.append(err)
            top[key] = None
    try:
        top["sanding_stock"] = _sanding_stock(raw)
    except ProfileError as err:
        problems.append(err)
    sections = {}
    for k, cls in _SECTIONS.items():
        try:
            sections[k] = read_section(raw, k, cls)
        except ProfileError as err:
            problems.append(err)
    if top.get("first_layer_height") is None:
        top["first_layer_height"] = top.get("layer_height")
    if slicer_cfg and "build_volume" in sections:
        problems += _check_agreement(top, sections["build_volume"], preset, slicer_cfg, raw)
    problems += _check_process(top, sections, raw, path)
    if slicer_cfg:
        problems += _check_model(top, slicer_cfg, raw)
    process = None
    if top.get("process") in DEFAULT_PROCESS and top.get("layer_height") is not None:
        try:
            process = read_process_errors(raw, top["process"], top["layer_height"], path)
        except ProfileError as err:
            problems.append(err)
    V.raise_problems(problems, f"printer file {display(path)}")
    return Printer(name=raw.name, description=top["description"], process=top["process"],
                   build_volume=sections["build_volume"], bed_margin=top["bed_margin"],
                   layer_height=top["layer_height"],
                   first_layer_height=top["first_layer_height"], nozzle=top["nozzle"], pixel=top["pixel"],
                   filament_diameter=top["filament_diameter"], material=top["material"],
                   material_density_g_cm3=top["material_density_g_cm3"],
                   deposition_rate_mm3_s=top["deposition_rate_mm3_s"], layer_time_s=top["layer_time_s"],
                   slicer=top["slicer"], alignment_pin=sections["alignment_pin"], sanding_stock=top["sanding_stock"],
                   source=" <- ".join(str(s) for s in raw.sources), marks=dict(raw.marks),
                   slicer_config=slicer_cfg, slicer_unavailable=unavailable, from_preset=tuple(from_preset),
                   process_errors=process, model=top["model"], stand_in=top["stand_in"])


def _top_value(key: str, s: Spec, raw: RawProfile, path: Path, top: dict, preset: dict, from_preset: list,
               slicer_cfg, unavailable: str | None) -> None:
    """``top[key]``: the printer file's value, else the preset's, else the default (ProfileError
    when required and given nowhere)."""
    if key == "sanding_stock":
        return  # 'auto' or a length: _sanding_stock
    if key == "slicer" and (slicer_cfg or unavailable or isinstance(raw.data.get("slicer"), dict)):
        top[key] = "prusa-slicer"
        return
    if key not in raw.data:
        if key in preset:
            top[key] = preset[key]
            from_preset.append(key)
            return
        if s.default is REQUIRED:
            top[key] = None
            if key in _PRESET_FIGURES and isinstance(raw.data.get("slicer"), dict) and not (slicer_cfg or unavailable):
                return  # the presets that would state it are refused: that problem is reported
            need = " (or name a PrusaSlicer print preset, which states it)" if key in _PRESET_FIGURES else ""
            if unavailable:
                need = f" (the slicer presets would state it, but {unavailable})"
            raise ProfileError(f"printer key {key!r} is missing: {s.doc} ({s.describe_range()}){need}",
                               where=f"{path}:1")
        top[key] = s.default if s.default is None or s.kind == "str" else convert_value(s, s.default, key, None)
        return
    top[key] = convert_value(s, raw.data[key], key, raw.where((key,)))
    if s.kind == "str" and isinstance(top[key], str) and _CONTROL.search(top[key]):
        raise ProfileError(f"{key}: one line of text, without line breaks or control characters (it is written "
                           "into the slicer's configuration)", where=raw.where((key,)))


def _sanding_stock(raw: RawProfile) -> float | None:
    """``sanding_stock``: None for 'auto', else a length (a bare number or other text gets the
    length rules' message)."""
    stock = raw.data.get("sanding_stock", "auto")
    if stock == "auto":
        return None
    return convert_value(Spec("length", "'auto' or " + _TOP["sanding_stock"].doc, lo=0, hi=MAX_SANDING_STOCK),
                         stock, "sanding_stock", raw.where(("sanding_stock",)))


def _check_process(top: dict, sections: dict, raw: RawProfile, path: Path) -> list:
    """The figures a process needs (FDM: nozzle, and a slicer's filament or a deposition rate; SLA:
    pixel) and a bed left by the margin: every problem, as a list."""
    out = []
    process = top.get("process")
    if process == "fdm" and top.get("nozzle") is None and "nozzle" not in raw.data:
        out.append(ProfileError("an fdm printer needs 'nozzle' (e.g. '0.4 mm')", where=f"{path}:1"))
    if process == "sla" and top.get("pixel") is None and "pixel" not in raw.data:
        out.append(ProfileError("an sla printer needs 'pixel' (pixel or laser spot, e.g. '85 um')", where=f"{path}:1"))
    if top.get("slicer") == "prusa-slicer" and process is not None and (
            process != "fdm" or (top.get("filament_diameter") is None and "filament_diameter" not in raw.data)):
        out.append(ProfileError("slicer 'prusa-slicer' needs process 'fdm' and 'filament_diameter' (e.g. '1.75 mm')",
                                where=raw.where(("slicer",))))
    rate = top.get("deposition_rate_mm3_s")
    if process == "fdm" and top.get("slicer") == "none" and rate is not None and rate <= 0:
        out.append(ProfileError("deposition_rate_mm3_s: an fdm printer without a slicer needs a deposition rate > 0 "
                                "(mm3/s) for its time estimate",
                                where=raw.where(("deposition_rate_mm3_s",)) or f"{path}:1"))
    vol, margin = sections.get("build_volume"), top.get("bed_margin")
    if vol is not None and margin is not None and 2 * margin >= min(vol.x, vol.y):
        out.append(ProfileError(f"bed_margin: {margin:g} mm leaves no bed ({vol.x:g} x {vol.y:g} mm)",
                                where=raw.where(("bed_margin",))))
    return out


def _tokens(text: str) -> set[str]:
    return set(re.findall(r"[a-z0-9]+", text.lower().replace("&&", "&")))


def model_matches(model: str, model_id: str, model_name: str) -> bool:
    """Whether a printer file's ``model`` is the printer a preset is for (its bundle's printer_model
    ``model_id`` and that model's name): the ID, letters and digits only, within the model's
    ("Original Prusa i3 MK3S+" holds MK3S), or every word of the model in the name ("Creality
    Ender-3 V2" in "Creality Ender-3 V2")."""
    compact = "".join(sorted(_tokens(model), key=lambda t: model.lower().find(t)))
    mid = "".join(re.findall(r"[a-z0-9]+", model_id.lower()))
    return bool(mid) and mid in compact or bool(_tokens(model)) and _tokens(model) <= _tokens(model_name)


def _check_model(top: dict, cfg: V.VendorConfig, raw: RawProfile) -> list:
    """A printer file's ``model`` against the printer model its presets are for (the preset's
    printer_model, which its G-code names): refused when they differ, unless ``stand_in`` says why."""
    model, eff = top.get("model") or "", cfg.effective()
    model_id = eff.get("printer_model", "").strip()
    if not model or not model_id or cfg.kind != "bundle":
        return []
    name = V.load_bundle(cfg.source).model_name(model_id)
    if model_matches(model, model_id, name) or top.get("stand_in"):
        return []
    return [ProfileError(
        f"model: {model!r}, but slicer.printer_preset {cfg.printer_preset!r} is PrusaSlicer's preset for the "
        f"{name} (printer_model {model_id}): its G-code says printer_model = {model_id} and carries that printer's "
        f"start G-code, bed and limits. Name your printer's preset, give the machine's own settings (a .ini exported "
        f"from PrusaSlicer as slicer.vendor_bundle), or, when the stand-in is deliberate, say why in stand_in: "
        f"(docs/instruments.md, 'Your printer')", where=raw.where(("model",)))]


def _percent(raw: RawProfile, key: tuple[str, ...], lo: float = 0.0) -> float:
    """A relative error written as a percentage ("0.2 %"), as a fraction."""
    value, name, where = raw.data, ".".join(key), raw.where(key)
    for k in key:
        value = value[k]
    text = str(value).strip() if isinstance(value, (str, int, float)) and not isinstance(value, bool) else None
    m = re.fullmatch(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*%", text or "", re.ASCII)
    if not m:
        raise ProfileError(f"{name}: expected a percentage such as '0.2 %', got {value!r} (a bare number is refused: "
                           "0.2 could be 0.2 % or 20 %)", where=where)
    out = float(m.group(1)) / 100
    if not lo <= out <= MAX_SCALE:
        raise ProfileError(f"{name}: {m.group(1)} % is outside {100 * lo:g}..{100 * MAX_SCALE:g} %", where=where)
    return out


def _process_length(raw: RawProfile, key: tuple[str, ...], doc: str) -> float:
    value = raw.data
    for k in key:
        value = value[k]
    return convert_value(Spec("length", doc, lo=0, hi=MAX_PROCESS_MM), value, ".".join(key), raw.where(key))


def _mapping(raw: RawProfile, key: tuple[str, ...], valid: tuple[str, ...], example: str) -> dict:
    value = raw.data
    for k in key:
        value = value[k]
    name = ".".join(key)
    if not isinstance(value, dict):
        raise ProfileError(f"{name}: expected a mapping, e.g. {example}, got {value!r}", where=raw.where(key))
    for k in value:
        if k not in valid:
            raise ProfileError(f"unknown key {name}.{unknown_key(k)}{suggest(str(k), list(valid))}; valid keys in "
                               f"{name}: {', '.join(valid)}", where=raw.where((*key, k)))
    return value


def _measured_rows(raw: RawProfile, key: tuple[str, ...]) -> list[tuple[float, float]]:
    """A list of [nominal, measured] pairs of lengths (mm)."""
    value = raw.data
    for k in key:
        value = value[k]
    name, where = ".".join(key), raw.where(key)
    if not isinstance(value, list) or not all(isinstance(r, list) and len(r) == 2 for r in value):
        raise ProfileError(f"{name}: expected a list of [nominal, measured] pairs, e.g. [[20 mm, 19.96 mm], "
                           f"[100 mm, 99.81 mm]], got {value!r}", where=where)
    s = Spec("length", "a nominal or measured size", lo=0, hi=1000, lo_open=True)
    return [(convert_value(s, a, name, where), convert_value(s, b, name, where)) for a, b in value]


def read_process_errors(raw: RawProfile, process: str, layer_height: float, path: Path) -> ProcessErrors:
    """The printer file's ``process_errors`` (rigcad.parts.process): the stated figures, or the
    process's published defaults (DEFAULT_PROCESS) for those left out; ``measured`` (the calibration
    print's [nominal, measured] lengths and hole diameters) replaces them all. Every length carries
    its unit, the relative errors their '%'; errors name the file:line."""
    base = DEFAULT_PROCESS[process]
    if "process_errors" not in raw.data:
        return ProcessErrors(base["scale"], base["position"], base["vertical"], base["horizontal"], 0.0,
                             layer_height, base["source"])
    sec = _mapping(raw, ("process_errors",), _PROCESS_KEYS, "{scale: 0.2 %, position: 0.1 mm}")
    layer = (_process_length(raw, ("process_errors", "layer_step"), "the step printed heights come in")
             if "layer_step" in sec else layer_height)
    if "measured" in sec:
        m = _mapping(raw, ("process_errors", "measured"), _MEASURED_KEYS, "{lengths: [[20 mm, 19.96 mm], ...]}")
        rows = {k: _measured_rows(raw, ("process_errors", "measured", k)) for k in _MEASURED_KEYS if k in m}
        return from_measurements(rows.get("lengths", []), rows.get("holes_vertical", []),
                                 rows.get("holes_horizontal", []), layer_step=layer,
                                 source=f"the calibration print, measured ({display(path)})",
                                 where=raw.where(("process_errors", "measured")))
    shrink = (_mapping(raw, ("process_errors", "hole_shrink"), _SHRINK_KEYS, "{vertical: 0.2 mm, horizontal: 0.3 mm}")
              if "hole_shrink" in sec else {})
    source = sec.get("source", base["source"] if not sec.keys() - {"source"} else "stated in the printer file")
    if not isinstance(source, str) or not source.strip() or _CONTROL.search(source):
        raise ProfileError("process_errors.source: one line of text saying where the figures come from",
                           where=raw.where(("process_errors", "source")))
    return ProcessErrors(
        scale=_percent(raw, ("process_errors", "scale")) if "scale" in sec else base["scale"],
        position=(_process_length(raw, ("process_errors", "position"), "a printed feature's position error")
                  if "position" in sec else base["position"]),
        hole_shrink_vertical=(_process_length(raw, ("process_errors", "hole_shrink", "vertical"), "diametral "
                              "undersize of a hole with a vertical axis") if "vertical" in shrink else base["vertical"]),
        hole_shrink_horizontal=(_process_length(raw, ("process_errors", "hole_shrink", "horizontal"), "diametral "
                                "undersize of a hole with a horizontal axis") if "horizontal" in shrink
                                else base["horizontal"]),
        hole_shrink_per_mm=(_percent(raw, ("process_errors", "hole_shrink", "per_mm"))
                            if "per_mm" in shrink else 0.0),
        layer_step=layer, source=source.strip())


def _read_slicer(raw: RawProfile, path: Path) -> tuple[V.VendorConfig | None, str | None]:
    """The ``slicer`` mapping -> resolved PrusaSlicer presets; (None, reason) when no bundle is
    installed at all (PrusaSlicer missing), so the rest of rigcad still runs."""
    sec = raw.data["slicer"]
    for key in sec:
        if key not in _SLICER_KEYS:
            raise ProfileError(f"unknown key slicer.{key}{suggest(key, list(_SLICER_KEYS))}; valid keys in slicer: "
                               f"{', '.join(_SLICER_KEYS)}", where=raw.where(("slicer", key)))
    for key in _SLICER_KEYS[:4]:
        if key in sec and (not isinstance(sec[key], str) or not sec[key].strip()):
            raise ProfileError(f"slicer.{key}: expected a name (text), got {sec[key]!r}",
                               where=raw.where(("slicer", key)))
    if "vendor_bundle" not in sec:
        raise ProfileError("slicer.vendor_bundle is missing: an installed PrusaSlicer bundle (e.g. PrusaResearch) or "
                           "the path of a PrusaSlicer .ini", where=raw.where(("slicer",)))
    overrides = sec.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise ProfileError(f"slicer.overrides: expected a mapping of PrusaSlicer settings, e.g. {{brim_width: 5}}, "
                           f"got {overrides!r}", where=raw.where(("slicer", "overrides")))
    where = {k: raw.where(("slicer", k)) for k in _SLICER_KEYS}
    where.update({f"overrides.{k}": raw.where(("slicer", "overrides", k)) for k in overrides})
    try:
        source = V.find_bundle(sec["vendor_bundle"], path.parent, where["vendor_bundle"])
    except FabricationError as err:  # nothing installed: only G-code needs the presets
        return None, str(err)
    cfg = V.resolve(source, sec.get("printer_preset"), sec.get("print_preset"), sec.get("filament_preset"),
                    overrides, where=where)
    return cfg, None


def _number(cfg: V.VendorConfig, key: str, text: str, where: str | None, base: float | None = None) -> float:
    """A preset's number (the first of a per-extruder vector; ``75%`` of ``base``)."""
    first = text.split(",")[0].strip()
    try:
        if first.endswith("%") and base is not None:
            return base * float(first[:-1]) / 100.0
        return float(first)
    except ValueError as err:
        raise ProfileError(f"slicer: the preset's {key} = {text!r} is not a number ({cfg.vendor}, {cfg.source})",
                           where=where) from err


def _preset_figures(cfg: V.VendorConfig, raw: RawProfile) -> dict[str, Any]:
    """rigcad's figures as the resolved preset states them (mm, g/cm3, text)."""
    eff = cfg.effective()
    at = raw.where(("slicer",))
    out: dict[str, Any] = {}
    for key, pkey in _PRESET_FIGURES.items():
        if pkey not in eff or not eff[pkey].strip():
            continue
        if key == "material":
            out[key] = eff[pkey].split(";")[0].strip().strip('"')
        elif key == "first_layer_height":
            base = out.get("layer_height")
            out[key] = _number(cfg, pkey, eff[pkey], at, base)
        else:
            out[key] = _number(cfg, pkey, eff[pkey], at)
    return out


def _check_agreement(top: dict, vol: BuildVolume, preset: dict, cfg: V.VendorConfig, raw: RawProfile) -> list:
    """Figures the printer file states must agree with the resolved preset (see the module doc): every
    disagreement, as a list of errors."""
    out: list = []
    eff = cfg.effective()
    names = (f"{cfg.printer_preset} / {cfg.print_preset} / {cfg.filament_preset}" if cfg.kind == "bundle"
             else str(cfg.source))
    for key, pkey in _PRESET_FIGURES.items():
        if key not in preset or key not in raw.data or top.get(key) is None:
            continue
        mine, theirs = top[key], preset[key]
        same = (mine.lower() == theirs.lower()) if key == "material" else abs(mine - theirs) < AGREE_TOL
        if not same:
            out.append(ProfileError(
                f"{key}: {mine!r} disagrees with the slicer preset's {pkey} = {eff[pkey]!r} ({names}); PrusaSlicer "
                f"prints with the preset, so state the same value, leave {key} out, choose a matching preset or set "
                f"slicer.overrides.{pkey}", where=raw.where((key,)) or raw.where(("slicer",))))
    if "bed_shape" in eff:
        try:
            pts = [tuple(float(c) for c in p.split("x")) for p in eff["bed_shape"].split(",")]
        except ValueError:
            pts = []
        if pts:
            size = (max(p[0] for p in pts) - min(p[0] for p in pts), max(p[1] for p in pts) - min(p[1] for p in pts))
            for axis, mine, theirs in (("x", vol.x, size[0]), ("y", vol.y, size[1])):
                if abs(mine - theirs) >= AGREE_TOL:
                    out.append(ProfileError(f"build_volume.{axis}: {mine:g} mm disagrees with the preset's "
                                            f"bed_shape = {eff['bed_shape']} ({theirs:g} mm; {names})",
                                            where=raw.where(("build_volume", axis))))
    if "max_print_height" in eff:
        h = _number(cfg, "max_print_height", eff["max_print_height"], raw.where(("slicer",)))
        if abs(vol.z - h) >= AGREE_TOL:
            out.append(ProfileError(f"build_volume.z: {vol.z:g} mm disagrees with the preset's max_print_height = "
                                    f"{h:g} mm ({names})", where=raw.where(("build_volume", "z"))))
    return out
