"""Printer profiles (``printers/<name>.yaml`` on the profile search path): build volume, layer height, nozzle or laser
spot, material, and what rigcad needs to estimate a print. Read through the one YAML reader
(rigcad.profile.loader, with its file:line marks and ``extends``) and validated with the same
:class:`rigcad.profile.schema.Spec` rules as rig profiles: every length carries its unit.
Inside: mm, float64.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rigcad.errors import ProfileError
from rigcad.profile.loader import find_file, load_raw, search_path
# The schema's own readers, so printer files follow the same unit, range and error rules.
from rigcad.profile.schema import REQUIRED, Spec, convert_value, read_section, spec, suggest

#: Printer files live in this folder under each folder of the profile search path.
PRINTERS_SUBDIR = "printers"

_POS = dict(lo=0, lo_open=True)


@dataclass(frozen=True)
class BuildVolume:
    """The printable box (mm): x, y the bed, z the height."""

    x: float = spec("length", "bed width", **_POS)
    y: float = spec("length", "bed depth", **_POS)
    z: float = spec("length", "largest print height", **_POS)


@dataclass(frozen=True)
class AlignmentPin:
    """Dowel pins that align split pieces: a hole of diameter + clearance, depth into each piece."""

    diameter: float = spec("length", "pin diameter", "1.75 mm", **_POS)
    clearance: float = spec("length", "added to the hole diameter", "0.15 mm", lo=0)
    depth: float = spec("length", "hole depth into each piece", "6 mm", **_POS)

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
    marks: dict = field(compare=False, repr=False, default_factory=dict)

    @property
    def usable(self) -> tuple[float, float, float]:
        """The box a part must fit (mm): the bed less its margin on each side, the full height."""
        v = self.build_volume
        return (v.x - 2 * self.bed_margin, v.y - 2 * self.bed_margin, v.z)

    def describe(self) -> dict[str, Any]:
        """Resolved values for fab.json, units in the keys."""
        v = self.build_volume
        out = {"name": self.name, "description": self.description, "process": self.process,
               "source": self.source, "build_volume_mm": [v.x, v.y, v.z], "bed_margin_mm": self.bed_margin,
               "layer_height_mm": self.layer_height, "first_layer_height_mm": self.first_layer_height,
               "nozzle_mm": self.nozzle, "pixel_mm": self.pixel, "filament_diameter_mm": self.filament_diameter,
               "material": self.material, "material_density_g_cm3": self.material_density_g_cm3,
               "deposition_rate_mm3_s": self.deposition_rate_mm3_s, "layer_time_s": self.layer_time_s,
               "slicer": self.slicer,
               "alignment_pin": {"diameter_mm": self.alignment_pin.diameter,
                                 "clearance_mm": self.alignment_pin.clearance,
                                 "depth_mm": self.alignment_pin.depth}}
        return out


#: Top-level keys of a printer file and how each is read (sections are handled below).
_TOP: dict[str, Spec] = {
    "description": Spec("str", "one line saying what machine this is", ""),
    "process": Spec("choice", "printing process", choices=("fdm", "sla")),
    "bed_margin": Spec("length", "kept free on each side of the bed", "0 mm", lo=0),
    "layer_height": Spec("length", "layer height", lo=0, lo_open=True, hi=1.0),
    "first_layer_height": Spec("length", "first layer height (default: the layer height)", None, lo=0, lo_open=True,
                               hi=1.0),
    "nozzle": Spec("length", "FDM nozzle (or tip) diameter", None, lo=0, lo_open=True),
    "pixel": Spec("length", "SLA pixel or laser spot size", None, lo=0, lo_open=True),
    "filament_diameter": Spec("length", "FDM filament diameter", None, lo=0, lo_open=True),
    "material": Spec("str", "material name", "unspecified"),
    "material_density_g_cm3": Spec("float", "material density in g/cm3", lo=0, lo_open=True, hi=25),
    "deposition_rate_mm3_s": Spec("float", "volume deposited per second, for estimates without a slicer "
                                  "(mm3/s; 0 for SLA)", 0.0, lo=0),
    "layer_time_s": Spec("float", "time per layer beyond the deposition, for estimates (s)", 0.0, lo=0),
    "slicer": Spec("choice", "slicer rigcad runs for G-code", "none", choices=("none", "prusa-slicer")),
}
_SECTIONS = {"build_volume": BuildVolume, "alignment_pin": AlignmentPin}


def printer_path(name: str | Path) -> Path:
    """A printer file by path, or by name under ``printers/`` on the profile search path."""
    return find_file(name, "printer", sub=PRINTERS_SUBDIR)


def available_printers() -> list[str]:
    """Printer names on the search path (first folder wins for a name)."""
    return sorted({p.stem for d in search_path(PRINTERS_SUBDIR) if d.is_dir() for p in d.glob("*.yaml")})


def load_printer(name: str | Path) -> Printer:
    """Read and validate a printer profile; errors name the file:line, key, value and what is valid."""
    path = printer_path(name)
    raw = load_raw(path)
    valid = sorted([*_TOP, *_SECTIONS])
    for key in raw.data:
        if key not in valid:
            raise ProfileError(f"unknown printer key {key!r}{suggest(key, valid)}; valid: {', '.join(valid)}",
                               where=raw.where((key,)))
    top: dict[str, Any] = {}
    for key, s in _TOP.items():
        if key not in raw.data:
            if s.default is REQUIRED:
                raise ProfileError(f"printer key {key!r} is missing: {s.doc} ({s.describe_range()})",
                                   where=f"{path}:1")
            top[key] = s.default if s.default is None or s.kind == "str" else convert_value(s, s.default, key, None)
            continue
        top[key] = convert_value(s, raw.data[key], key, raw.where((key,)))
    sections = {k: read_section(raw, k, cls) for k, cls in _SECTIONS.items()}
    if top["process"] == "fdm" and top["nozzle"] is None:
        raise ProfileError("an fdm printer needs 'nozzle' (e.g. '0.4 mm')", where=f"{path}:1")
    if top["process"] == "sla" and top["pixel"] is None:
        raise ProfileError("an sla printer needs 'pixel' (pixel or laser spot, e.g. '85 um')", where=f"{path}:1")
    if top["slicer"] == "prusa-slicer" and (top["process"] != "fdm" or top["filament_diameter"] is None):
        raise ProfileError("slicer 'prusa-slicer' needs process 'fdm' and 'filament_diameter' (e.g. '1.75 mm')",
                           where=raw.where(("slicer",)))
    if top["process"] == "fdm" and top["slicer"] == "none" and top["deposition_rate_mm3_s"] <= 0:
        raise ProfileError("deposition_rate_mm3_s: an fdm printer without a slicer needs a deposition rate > 0 "
                           "(mm3/s) for its time estimate", where=raw.where(("deposition_rate_mm3_s",)) or f"{path}:1")
    vol = sections["build_volume"]
    margin = top["bed_margin"]
    if 2 * margin >= min(vol.x, vol.y):
        raise ProfileError(f"bed_margin: {margin:g} mm leaves no bed ({vol.x:g} x {vol.y:g} mm)",
                           where=raw.where(("bed_margin",)))
    if top["first_layer_height"] is None:
        top["first_layer_height"] = top["layer_height"]
    return Printer(name=raw.name, description=top["description"], process=top["process"], build_volume=vol,
                   bed_margin=margin, layer_height=top["layer_height"],
                   first_layer_height=top["first_layer_height"], nozzle=top["nozzle"], pixel=top["pixel"],
                   filament_diameter=top["filament_diameter"], material=top["material"],
                   material_density_g_cm3=top["material_density_g_cm3"],
                   deposition_rate_mm3_s=top["deposition_rate_mm3_s"], layer_time_s=top["layer_time_s"],
                   slicer=top["slicer"], alignment_pin=sections["alignment_pin"],
                   source=" <- ".join(str(s) for s in raw.sources), marks=dict(raw.marks))

