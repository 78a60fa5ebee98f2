"""The ``optimize:`` section of a profile: free parameters with bounds and units, objectives, hard
constraints and the search settings, validated with the profile's own rules (units, file:line).

    optimize:
      parameters:                      # profile keys (section.key) with [low, high] bounds, in units
        layout.cop_to_vertex: [20 cm, 45 cm]
        paraboloid.tangent_angle: [12 deg, 28 deg]
        coating.total: [4 mil, 7 mil]  # the paint stack scaled to this total thickness
      objectives:                      # name: minimize | maximize | {target: value} (OBJECTIVES)
        theta_min: minimize
        px_per_deg_cv: minimize
      constraints:
        printer: prusa_mk3s            # the dome prints on it ...
        max_pieces: 4                  # ... in at most this many pieces
        max_cop_height: 60 cm          # the COP (projector lens) under a ceiling, above the sample plane
        max_dome_width: 30 cm          # the dome's outer width (flange included), a hard limit
        min_feature_nozzles: 2         # dome wall and the paraboloid's vertex radius >= 2 nozzles
        max_occluded_fraction: 0.06    # pixels the mount hides
        raycheck: true                 # the design-level checks of the raycheck section pass
        raycheck_margin: 0.03          # ... with 3 % of each limit to spare
        later_stages: true             # the layout, part recipes and fab's tolerance stack hold (default)
      seed: 2006
      evaluations: 300                 # budget: global search + local polish
      workers: 1                       # processes (rigcad.engine); 0 = every core

Every value is checked when ``rigcad optimize`` reads the profile; other commands ignore the section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from rigcad.errors import ProfileError
from rigcad.profile.loader import RawProfile
from rigcad.profile.schema import SECTIONS, Profile, Spec, convert_value, suggest
from rigcad.units import DEG

#: Objectives: name -> (figure key of the evaluation, unit, scale for the merit: one unit of merit).
OBJECTIVES: dict[str, tuple[str, str, float]] = {
    "theta_min": ("theta_min_deg", "deg", 1.0),
    "px_per_deg_cv": ("px_per_deg_cv", "", 0.01),
    "px_per_deg_mean": ("px_per_deg_mean", "px/deg", 0.01),
    "px_per_deg_min": ("px_per_deg_min", "px/deg", 0.01),
    "occluded_fraction": ("occluded_fraction", "", 0.001),
    "dome_width": ("dome_outer_width_mm", "mm", 1.0),
    "dome_height": ("dome_outer_height_mm", "mm", 1.0),
    "dome_mass": ("dome_mass_g", "g", 10.0),
    "cop_height": ("cop_z_mm", "mm", 1.0),
}
#: Free parameters besides the profile's scalar keys.
COATING_TOTAL = "coating.total"
_SEARCH = {"parameters", "objectives", "constraints", "seed", "evaluations", "workers", "nodes"}
_CONSTRAINTS = {"printer", "max_pieces", "max_cop_height", "min_feature_nozzles", "max_occluded_fraction",
                "raycheck", "raycheck_margin", "later_stages", "max_dome_width"}
#: Default share of each raycheck limit kept in reserve (the 3D check measures on a finite fan of
#: pixels and 1e5 seeded rays: its px/deg minimum and lost fraction differ from the exact ones by
#: ~1e-3; see docs/optimize.md).
RAYCHECK_MARGIN = 0.03
#: Most free parameters and evaluations a run may ask for (a bench-top design space).
MAX_PARAMETERS = 12
MAX_EVALUATIONS = 100_000


@dataclass(frozen=True)
class FreeParameter:
    """A profile key the search moves, between ``lo`` and ``hi`` (mm or rad, or a plain number)."""

    key: str  #: "section.name", or coating.total
    kind: str  #: length, angle or float
    lo: float
    hi: float
    base: float  #: the value in the profile

    def describe(self) -> dict:
        unit, scale = {"length": ("mm", 1.0), "angle": ("deg", DEG)}.get(self.kind, ("", 1.0))
        return {"key": self.key, "unit": unit, "low": self.lo / scale, "high": self.hi / scale,
                "base": self.base / scale}

    def shown(self, value: float) -> str:
        """The value as a profile writes it (units), to the precision the YAML round trip keeps."""
        if self.kind == "length":
            return f"{value:.12g} mm"
        if self.kind == "angle":
            return f"{value / DEG:.12g} deg"
        return f"{value:.12g}"


@dataclass(frozen=True)
class Constraints:
    printer: str | None = None
    max_pieces: int = 1
    max_cop_height: float | None = None  #: mm above the sample plane
    min_feature_nozzles: float | None = None
    max_occluded_fraction: float | None = None
    raycheck: bool = True
    raycheck_margin: float = RAYCHECK_MARGIN
    #: The later stages' rules as constraints of the search (rigcad.optimize.problem.later_stages):
    #: the rig's layout and part recipes and fab's tolerance stack, on the closed-form dome.
    later_stages: bool = True
    max_dome_width: float | None = None  #: mm: the dome part's outer width, flange included


@dataclass(frozen=True)
class OptimizeSpec:
    parameters: tuple[FreeParameter, ...]
    objectives: tuple[tuple[str, str], ...]  #: (name, "minimize" | "maximize")
    constraints: Constraints
    seed: int = 2006
    evaluations: int = 300
    workers: int = 1
    nodes: int = 48

    def describe(self) -> dict:
        c = self.constraints
        return {"parameters": [p.describe() for p in self.parameters],
                "objectives": [{"name": n, "sense": s, "figure": OBJECTIVES[n][0], "unit": OBJECTIVES[n][1]}
                               for n, s in self.objectives],
                "constraints": {"printer": c.printer, "max_pieces": c.max_pieces,
                                "max_cop_height_mm": c.max_cop_height, "min_feature_nozzles": c.min_feature_nozzles,
                                "max_occluded_fraction": c.max_occluded_fraction, "raycheck": c.raycheck,
                                "raycheck_margin": c.raycheck_margin, "later_stages": c.later_stages,
                                "max_dome_width_mm": c.max_dome_width},
                "seed": self.seed, "evaluations": self.evaluations, "workers": self.workers,
                "quadrature_nodes": self.nodes}


def _spec_of(key: str) -> Spec | None:
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    if cls is None:
        return None
    for f in fields(cls):
        if f.name == name:
            return f.metadata["spec"]
    return None


def _free_keys() -> list[str]:
    keys = [COATING_TOTAL]
    for section, cls in SECTIONS.items():
        for f in fields(cls):
            if f.metadata["spec"].kind in ("length", "angle", "float"):
                keys.append(f"{section}.{f.name}")
    return keys


def base_value(profile: Profile, key: str) -> float | None:
    if key == COATING_TOTAL:
        return float(sum(t for _, t in profile.coating.layers))
    section, _, name = key.partition(".")
    return getattr(getattr(profile, section), name)


def read_optimize(raw: RawProfile, profile: Profile) -> OptimizeSpec:
    """The validated ``optimize:`` section of ``raw`` (the profile ``profile`` was validated from);
    ProfileError with file:line for anything wrong, naming what would be valid."""
    where = raw.where
    data = raw.data.get("optimize")
    if not isinstance(data, dict):
        raise ProfileError(f"profile {profile.name} has no 'optimize:' section (free parameters, objectives, "
                           "constraints); see profiles/achutha2006_optimize.yaml",
                           where=where(("optimize",)) or (str(raw.sources[0]) if raw.sources else None))
    for key in data:
        if key not in _SEARCH:
            raise ProfileError(f"unknown key optimize.{key}{suggest(str(key), sorted(_SEARCH))}; valid: "
                               + ", ".join(sorted(_SEARCH)), where=where(("optimize", key)))
    params = _parameters(data.get("parameters"), raw, profile)
    objectives = _objectives(data.get("objectives"), raw)
    constraints = _constraints(data.get("constraints") or {}, raw)

    def integer(name: str, default: int, lo: int, hi: int) -> int:
        value = data.get(name, default)
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ProfileError(f"optimize.{name}: expected a whole number {lo}..{hi}, got {value!r}"[:200],
                               where=where(("optimize", name)))
        return value

    return OptimizeSpec(params, objectives, constraints, seed=integer("seed", 2006, 0, 2**63 - 1),
                        evaluations=integer("evaluations", 300, 10, MAX_EVALUATIONS),
                        workers=integer("workers", 1, 0, 256), nodes=integer("nodes", 48, 8, 512))


def _parameters(data, raw: RawProfile, profile: Profile) -> tuple[FreeParameter, ...]:
    where = raw.where
    if not isinstance(data, dict) or not data:
        raise ProfileError("optimize.parameters: give the free parameters as 'section.key: [low, high]' with units, "
                           "e.g. 'layout.cop_to_vertex: [20 cm, 45 cm]'", where=where(("optimize", "parameters")))
    if len(data) > MAX_PARAMETERS:
        raise ProfileError(f"optimize.parameters: {len(data)} free parameters; at most {MAX_PARAMETERS}",
                           where=where(("optimize", "parameters")))
    valid = _free_keys()
    out = []
    for key, bounds in data.items():
        at = where(("optimize", "parameters", key))
        if key not in valid:
            raise ProfileError(f"optimize.parameters.{key}: not a free parameter{suggest(str(key), valid)}; valid: any "
                               "length, angle or number of the profile (section.key) or coating.total", where=at)
        base = base_value(profile, key)
        if base is None:
            raise ProfileError(f"optimize.parameters.{key}: the profile does not set {key} (the paraboloid is given by "
                               "the other pair: vertical_extent and tangent_angle, or focal_length and rim_radius)",
                               where=at)
        spec = Spec("length", "coating total", lo=0) if key == COATING_TOTAL else _spec_of(key)
        if not isinstance(bounds, list) or len(bounds) != 2:
            raise ProfileError(f"optimize.parameters.{key}: expected [low, high] with units, got {bounds!r}"[:200],
                               where=at)
        lo, hi = (convert_value(spec, b, f"optimize.parameters.{key}", at) for b in bounds)
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ProfileError(f"optimize.parameters.{key}: need finite bounds with low < high, got {bounds!r}", where=at)
        if key == COATING_TOTAL and base <= 0:
            raise ProfileError("optimize.parameters.coating.total: the profile's coating has zero thickness; "
                               "nothing to scale", where=at)
        out.append(FreeParameter(key, spec.kind, float(lo), float(hi), float(base)))
    return tuple(out)


def _objectives(data, raw: RawProfile) -> tuple[tuple[str, str], ...]:
    where = raw.where
    if not isinstance(data, dict) or not data:
        raise ProfileError("optimize.objectives: give one or more of " + ", ".join(OBJECTIVES)
                           + " with minimize or maximize", where=where(("optimize", "objectives")))
    out = []
    for name, sense in data.items():
        at = where(("optimize", "objectives", name))
        if name not in OBJECTIVES:
            raise ProfileError(f"optimize.objectives.{name}: unknown objective{suggest(str(name), list(OBJECTIVES))}; "
                               "valid: " + ", ".join(OBJECTIVES), where=at)
        if isinstance(sense, dict) and set(sense) == {"target"}:
            unit = OBJECTIVES[name][1]
            kind = {"deg": "angle", "mm": "length"}.get(unit, "float")
            value = convert_value(Spec(kind, name), sense["target"], f"optimize.objectives.{name}.target",
                                  where(("optimize", "objectives", name, "target")))
            out.append((name, f"target {value / DEG if kind == 'angle' else value!r}"))
            continue
        if sense not in ("minimize", "maximize"):
            raise ProfileError(f"optimize.objectives.{name}: {sense!r} is not valid; one of minimize, maximize, or "
                               "{target: value} (with its unit)", where=at)
        out.append((name, sense))
    return tuple(out)


def target_of(sense: str) -> float | None:
    """The target value (the objective's unit) of a ``target ...`` sense, else None."""
    return float(sense.split(" ", 1)[1]) if sense.startswith("target ") else None


def _constraints(data, raw: RawProfile) -> Constraints:
    where = raw.where
    if not isinstance(data, dict):
        raise ProfileError("optimize.constraints must be a mapping", where=where(("optimize", "constraints")))
    for key in data:
        if key not in _CONSTRAINTS:
            raise ProfileError(f"unknown constraint optimize.constraints.{key}{suggest(str(key), sorted(_CONSTRAINTS))}; "
                               "valid: " + ", ".join(sorted(_CONSTRAINTS)), where=where(("optimize", "constraints", key)))

    def at(k):
        return where(("optimize", "constraints", k))

    printer = data.get("printer")
    if printer is not None:
        from rigcad.fab.printers import load_printer

        if not isinstance(printer, str):
            raise ProfileError(f"optimize.constraints.printer: expected a printer name, got {printer!r}"[:200],
                               where=at("printer"))
        load_printer(printer)  # refused here, naming the printers, when it does not exist
    pieces = data.get("max_pieces", 1)
    if isinstance(pieces, bool) or not isinstance(pieces, int) or not 1 <= pieces <= 64:
        raise ProfileError(f"optimize.constraints.max_pieces: expected a whole number 1..64, got {pieces!r}"[:200],
                           where=at("max_pieces"))
    if "max_pieces" in data and printer is None:
        raise ProfileError("optimize.constraints.max_pieces needs optimize.constraints.printer", where=at("max_pieces"))
    ceiling = None
    if data.get("max_cop_height") is not None:
        ceiling = convert_value(Spec("length", "COP height", lo=0, lo_open=True), data["max_cop_height"],
                                "optimize.constraints.max_cop_height", at("max_cop_height"))
    width = None
    if data.get("max_dome_width") is not None:
        width = convert_value(Spec("length", "dome width", lo=0, lo_open=True), data["max_dome_width"],
                              "optimize.constraints.max_dome_width", at("max_dome_width"))
    nozzles = None
    if data.get("min_feature_nozzles") is not None:
        nozzles = convert_value(Spec("float", "nozzles", lo=0, hi=100), data["min_feature_nozzles"],
                                "optimize.constraints.min_feature_nozzles", at("min_feature_nozzles"))
        if printer is None:
            raise ProfileError("optimize.constraints.min_feature_nozzles needs optimize.constraints.printer",
                               where=at("min_feature_nozzles"))
    occluded = None
    if data.get("max_occluded_fraction") is not None:
        occluded = convert_value(Spec("float", "fraction", lo=0, hi=1), data["max_occluded_fraction"],
                                 "optimize.constraints.max_occluded_fraction", at("max_occluded_fraction"))
    rc = data.get("raycheck", True)
    if not isinstance(rc, bool):
        raise ProfileError(f"optimize.constraints.raycheck: expected true or false, got {rc!r}"[:200], where=at("raycheck"))
    margin = RAYCHECK_MARGIN
    if data.get("raycheck_margin") is not None:
        margin = convert_value(Spec("float", "share", lo=0, hi=0.5), data["raycheck_margin"],
                               "optimize.constraints.raycheck_margin", at("raycheck_margin"))
    later = data.get("later_stages", True)
    if not isinstance(later, bool):
        raise ProfileError(f"optimize.constraints.later_stages: expected true or false, got {later!r}"[:200],
                           where=at("later_stages"))
    return Constraints(printer, pieces, ceiling, nozzles, occluded, rc, margin, later, width)
