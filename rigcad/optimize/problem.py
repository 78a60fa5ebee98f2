"""One design evaluation: free parameters -> a profile (``dataclasses.replace``, no YAML) -> derived
geometry -> the fast design (``optimize.fast``) and the printer fit (``optimize.printfit``) -> every
objective and every constraint. Constraint values g are <= 0 when met (units in ``CONSTRAINT_UNITS``).

A :class:`Problem` is what every evaluation needs, small and picklable (it is the engine's shared
object); :func:`evaluate_task` is the engine's job function.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from rigcad.check.tolerances import THETA_RANGE_SLACK
from rigcad.errors import RigcadError
from rigcad.optimize.fast import fast_design
from rigcad.optimize.printfit import dome_fit
from rigcad.optimize.spec import COATING_TOTAL, OBJECTIVES, OptimizeSpec
from rigcad.parts.tower import shelf_bottom_z
from rigcad.profile.derived import derive
from rigcad.profile.schema import Profile
from rigcad.units import DEG

#: Room (mm) the printer fit keeps in every direction beyond the printer's own bed margin: the
#: model's outline is sampled (its extents err by < 0.05 mm, measured) and the fabrication stage
#: cuts a meshed part; a design exactly at the edge of the bed is not one to print.
PRINT_RESERVE = 0.5
#: Room (mm) each geometric constraint (``design.*``) keeps beyond the refusal it mirrors in the
#: certified layout (parts.layout and parts.tower compare the same quantities, strictly). The search
#: drives an active constraint to g = 0, where the fast path's error (its dome top agrees with the
#: certified layout's to 4e-11 mm, measured on four designs; the certified dome's own tolerance is
#: <= 1e-7 mm) and the last bits of the sums (~1e-13 mm at 300 mm, which differ between CPUs) would
#: otherwise decide whether the written design builds. 1 um: 1e4 times those, nothing a print resolves.
GEOMETRY_RESERVE = 1e-3
#: Scale of one unit of violation, per unit, for the penalty merit (a constraint's g / scale).
UNIT_SCALE = {"mm": 1.0, "deg": 0.1, "px/deg": 0.01, "": 0.001, "count": 1.0}
#: Rows of the closed-form dome (optics.dome.build_equal_path) the later stages' layout is made on:
#: the layout reads the dome's meridian at a few heights (the flange, the seats, the top), which the
#: closed form gives to the DOP853 dome's 2e-9 mm; the stack's verdicts on the certified and the
#: closed-form rig agreed on all 8 preferred designs of achutha2006_optimize (measured).
LATER_DOME_ROWS = 201
#: The printer whose tolerance stack a design must hold when the optimize section names none.
DEFAULT_STACK_PRINTER = "prusa_mk3s"


@dataclass(frozen=True)
class PrinterFacts:
    """What the constraints read from a printer (mm; g/cm3)."""

    name: str
    usable: tuple[float, float, float]
    feature: float  #: nozzle (FDM) or pixel (SLA)
    density_g_cm3: float


@dataclass(frozen=True)
class Problem:
    base: Profile
    spec: OptimizeSpec
    printer: PrinterFacts | None
    #: The printer fab's tolerance stack is reckoned on (rigcad.fab.printers.Printer; None: no later stages).
    stack_printer: object = None

    @property
    def names(self) -> list[str]:
        return [p.key for p in self.spec.parameters]

    @property
    def lo(self) -> np.ndarray:
        return np.array([p.lo for p in self.spec.parameters])

    @property
    def hi(self) -> np.ndarray:
        return np.array([p.hi for p in self.spec.parameters])

    def to_x(self, unit: np.ndarray) -> np.ndarray:
        """Physical values (mm, rad, numbers) of a point of the unit cube."""
        return self.lo + np.clip(unit, 0.0, 1.0) * (self.hi - self.lo)

    def to_unit(self, x: np.ndarray) -> np.ndarray:
        return (np.asarray(x, float) - self.lo) / (self.hi - self.lo)

    @property
    def base_x(self) -> np.ndarray:
        return np.array([p.base for p in self.spec.parameters])


def make_problem(profile: Profile, spec: OptimizeSpec) -> Problem:
    from rigcad.fab.printers import load_printer

    facts = None
    if spec.constraints.printer is not None:
        p = load_printer(spec.constraints.printer)
        facts = PrinterFacts(p.name, p.usable, float(p.nozzle if p.nozzle is not None else p.pixel),
                             float(p.material_density_g_cm3))
    stack_printer = load_printer(spec.constraints.printer or DEFAULT_STACK_PRINTER) if spec.constraints.later_stages \
        else None
    return Problem(profile, spec, facts, stack_printer)


def custom_focal_length(profile: Profile, geometry: Derived) -> float | None:
    """None when a stock focusing lens brings the design's paraboloid into the projector's focus range;
    else the focal length (mm, to 0.1 mm) centred on it, checked to be reachable: the written design
    names it (a custom lens). Raises GeometryError when no focal length can."""
    from rigcad.errors import GeometryError
    from rigcad.optics.focus import focusing_lens, ideal_focal_length

    try:
        focusing_lens(profile, geometry)
        return None
    except GeometryError:
        f = round(ideal_focal_length(profile, geometry), 1)
        focusing_lens(dataclasses.replace(profile, lens=dataclasses.replace(profile.lens, focal_length=f)), geometry)
        return f


def later_stages(problem: Problem, profile: Profile, geometry: Derived) -> dict[str, float]:
    """The later stages' rules on one design, as constraint values (<= 0 when met): the rig's layout
    and every part's recipe (what `rigcad design` and `stl` refuse before any solid: the tower and its
    shelf, the splitter and its holder, the instruments against the dome, the seats, the flange; 1
    when one refuses, else 0), the calibration's screen inside the dome (its half diagonal against
    the dome's inside radius where the spacers put it, mm: rigcad.calibrate.kit.screen_room, which
    `rigcad manual` refuses) and `rigcad fab`'s tolerance stack on the run's printer (the placements
    it can neither hold nor adjust, counted), made on the closed-form dome (LATER_DOME_ROWS) with the
    design's focusing lens (a custom one when no stock lens focuses it, as the written design names).
    The same code those stages run; about 0.5 s a design (the layout's meridian searches)."""
    from types import SimpleNamespace

    from rigcad.calibrate.kit import screen_room
    from rigcad.errors import GeometryError
    from rigcad.fab import stack as ST
    from rigcad.optics.dome import build_equal_path
    from rigcad.parts import make_recipes

    dome = build_equal_path(geometry, LATER_DOME_ROWS)
    # the calibration's screen inside the dome (rigcad manual and calibrate --kit refuse a dome it does not fit)
    room = screen_room(SimpleNamespace(profile=profile, dome=dome))
    g = {"later.calibration_screen": room["half_diagonal_mm"] - room["tightest"]["dome_radius_mm"] + GEOMETRY_RESERVE}
    try:
        profile, layout = _later_layout(profile, geometry, dome)
        make_recipes(profile, layout)
    except GeometryError:
        return {**g, "later.layout_and_parts": 1.0}
    pr = problem.stack_printer
    refused = 0 if pr.process_errors is None else len(ST.stack(profile, layout, pr, cures=False).refused)
    return {**g, "later.layout_and_parts": 0.0, "later.tolerance_stack": float(refused)}


def _later_layout(profile: Profile, geometry: Derived, dome):
    """The profile with the design's focusing lens (a custom one when no stock lens focuses it) and the
    rig's layout on ``dome``, as :func:`later_stages` judges them (GeometryError when it refuses)."""
    from rigcad.parts import make_layout

    f = custom_focal_length(profile, geometry)
    if f is not None:
        profile = dataclasses.replace(profile, lens=dataclasses.replace(profile.lens, focal_length=f))
    return profile, make_layout(profile, geometry, dome)


def stack_refusals(problem: Problem, x) -> list[str]:
    """The placements `rigcad fab`'s tolerance stack refuses for the design at ``x`` (internal units) on the
    run's printer, as :func:`later_stages` counts them: each as 'element axis (tolerancing.key)', with the
    setting that would pass it where one does; empty when the layout itself refuses or nothing is refused."""
    from rigcad.errors import GeometryError
    from rigcad.fab import stack as ST
    from rigcad.optics.dome import build_equal_path

    pr = problem.stack_printer
    if pr is None or pr.process_errors is None:
        return []
    profile = apply(problem.base, problem.names, [float(v) for v in x])
    geometry = derive(profile)
    try:
        profile, layout = _later_layout(profile, geometry, build_equal_path(geometry, LATER_DOME_ROWS))
    except GeometryError:
        return []
    return [f"{ST.ELEMENT_NAMES[v.element]} {v.axis} (tolerancing.{v.tolerance_key}"
            + (f"; set {' or '.join(v.cure)})" if v.cure else ")") for v in ST.stack(profile, layout, pr).refused]


def apply(profile: Profile, keys: list[str], x) -> Profile:
    """``profile`` with the free parameters ``keys`` set to ``x`` (internal units)."""
    changes: dict[str, dict] = {}
    for key, value in zip(keys, x):
        value = float(value)
        if key == COATING_TOTAL:
            total = sum(t for _, t in profile.coating.layers)
            layers = tuple((n, t * value / total) for n, t in profile.coating.layers)
            changes.setdefault("coating", {})["layers"] = layers
            continue
        section, _, name = key.partition(".")
        changes.setdefault(section, {})[name] = value
    return dataclasses.replace(profile, **{s: dataclasses.replace(getattr(profile, s), **kw) for s, kw in changes.items()})


def evaluate(problem: Problem, x) -> dict:
    """Objectives, constraints and figures of the design at ``x`` (internal units). A design the
    geometry refuses (GeometryError...) comes back with ``error`` set and no figures."""
    t0, c0 = time.perf_counter(), time.process_time()
    spec = problem.spec
    x = [float(v) for v in x]
    row: dict = {"x": x, "error": None}
    try:
        profile = apply(problem.base, problem.names, x)
        geo = derive(profile)
        fd = fast_design(profile, geo, spec.nodes)
    except RigcadError as err:
        row.update(figures=None, objectives=None, constraints=None, feasible=False, error=err.message,
                   time_s=time.perf_counter() - t0, cpu_s=time.process_time() - c0)
        return row
    fig = dict(fd.figures)
    c = spec.constraints
    g: dict[str, float] = {
        "design.top_clearance": -fig["top_clearance_mm"],
        "design.cop_above_dome": -fig["cop_above_dome_mm"],
        "design.beam_above_flange": -fig["beam_above_flange_mm"],
        # parts.layout: the sample holder's stop lies inside the printed dome's base
        "design.holder_inside_base": profile.sample_holder.stop_radius - float(fd.outline.flange[3][0]),
    }
    if not geo.cop_at_infinity:
        # parts.tower: the projector's shelf must clear the dome's top (tower_layout refuses it otherwise)
        dome_top = float(max(fd.outline.outer[:, 1].max(), fd.outline.inner[:, 1].max()))
        g["design.tower_above_dome"] = dome_top + profile.tower.clearance - shelf_bottom_z(profile, geo.cop_z)
    for key in g:
        g[key] += GEOMETRY_RESERVE
    pr = problem.printer
    density = pr.density_g_cm3 if pr is not None else 1.24  # PLA when no printer is named
    fig["dome_mass_g"] = fig["dome_volume_mm3"] / 1000.0 * density
    if pr is not None:
        usable = tuple(u - PRINT_RESERVE for u in pr.usable)
        fit = dome_fit(fd.outline, usable, c.max_pieces)
        fig["dome_pieces"] = fit["pieces"]
        fig["dome_sectors"], fig["dome_bands"] = fit["sectors"], fit["bands"]
        fig["printer_margin_mm"] = fit["margin_mm"] + PRINT_RESERVE  # room left on the printer itself
        fig["printer_reserve_mm"] = PRINT_RESERVE
        g["printer.pieces"] = -fit["margin_mm"]
        if c.min_feature_nozzles is not None:
            need = c.min_feature_nozzles * pr.feature
            coating = float(sum(t for _, t in profile.coating.layers))
            g["min_feature.dome_wall"] = need - profile.dome_shell.wall
            g["min_feature.paraboloid_vertex"] = need - (geo.vertex_radius_of_curvature - coating)
    if c.max_cop_height is not None:
        g["max_cop_height"] = fig["cop_z_mm"] - c.max_cop_height
    if c.max_dome_width is not None:
        g["max_dome_width"] = fig["dome_outer_width_mm"] - c.max_dome_width
    if c.max_occluded_fraction is not None:
        g["max_occluded_fraction"] = fig["occluded_fraction"] - c.max_occluded_fraction
    if c.raycheck:
        rc, tg, k = profile.raycheck, profile.targets, 1.0 - c.raycheck_margin
        g["raycheck.theta_min_coverage"] = fig["theta_min_deg"] - (tg.theta_min + k * rc.theta_coverage_tolerance) / DEG
        g["raycheck.theta_max_coverage"] = (tg.theta_max - k * rc.theta_coverage_tolerance) / DEG - fig["theta_max_deg"]
        g["raycheck.min_px_per_deg"] = rc.min_px_per_deg / k - fig["px_per_deg_min"]
        # the design's own range against the targets themselves, as `rigcad check`, stl, fab and manual judge it
        g["targets.theta_min"] = fig["theta_min_deg"] - (tg.theta_min + THETA_RANGE_SLACK) / DEG
        g["targets.theta_max"] = (tg.theta_max - THETA_RANGE_SLACK) / DEG - fig["theta_max_deg"]
        g["raycheck.max_lost_fraction"] = fig["occluded_fraction"] - k * rc.max_lost_fraction
    if problem.stack_printer is not None and all(v <= 0 for v in g.values()):
        # the later stages' rules, on designs that meet every closed-form constraint (absent otherwise:
        # the design is refused already, and they cost about half a second)
        g.update(later_stages(problem, profile, geo))
    objectives = {name: float(fig[OBJECTIVES[name][0]]) for name, _ in spec.objectives}
    row.update(figures=fig, objectives=objectives, constraints=g, feasible=all(v <= 0 for v in g.values()),
               time_s=time.perf_counter() - t0, cpu_s=time.process_time() - c0)
    return row


#: Units of each constraint value (for the report and the penalty scale).
CONSTRAINT_UNITS = {
    "design.top_clearance": "mm", "design.cop_above_dome": "mm", "design.beam_above_flange": "mm",
    "design.holder_inside_base": "mm", "design.tower_above_dome": "mm",
    "printer.pieces": "mm", "min_feature.dome_wall": "mm", "min_feature.paraboloid_vertex": "mm",
    "max_cop_height": "mm", "max_dome_width": "mm", "max_occluded_fraction": "", "raycheck.theta_min_coverage": "deg",
    "raycheck.theta_max_coverage": "deg", "raycheck.min_px_per_deg": "px/deg", "raycheck.max_lost_fraction": "",
    "targets.theta_min": "deg", "targets.theta_max": "deg",
    "later.layout_and_parts": "count", "later.tolerance_stack": "count", "later.calibration_screen": "mm",
}
#: What each constraint means, for messages (the profile key that sets its limit).
CONSTRAINT_KEYS = {
    "design.top_clearance": "the dome's top opening must clear the projector's ray bundle",
    "design.cop_above_dome": "the COP must lie above the dome",
    "design.beam_above_flange": "the beam must sit above the dome's flange",
    "design.holder_inside_base": "sample_holder.stop_radius must lie inside the dome's base",
    "design.tower_above_dome": "the COP tower's projector shelf must clear the dome's top by tower.clearance "
                               "(raise the COP or lower tower.splitter_distance)",
    # every design.* value includes GEOMETRY_RESERVE mm
    "printer.pieces": "optimize.constraints.printer / max_pieces: the dome must print in at most max_pieces pieces "
                      "with PRINT_RESERVE mm to spare (value: how many mm too large the best split is)",
    "min_feature.dome_wall": "optimize.constraints.min_feature_nozzles: dome_shell.wall against the nozzle",
    "min_feature.paraboloid_vertex": "optimize.constraints.min_feature_nozzles: the paraboloid's vertex radius "
                                     "of curvature against the nozzle",
    "max_cop_height": "optimize.constraints.max_cop_height: the COP's height above the sample plane",
    "max_dome_width": "optimize.constraints.max_dome_width: the dome part's outer width, flange included",
    "max_occluded_fraction": "optimize.constraints.max_occluded_fraction: pixels the mount hides",
    "raycheck.theta_min_coverage": "raycheck.theta_coverage_tolerance: theta must reach targets.theta_min",
    "raycheck.theta_max_coverage": "raycheck.theta_coverage_tolerance: theta must reach targets.theta_max",
    "raycheck.min_px_per_deg": "raycheck.min_px_per_deg: fewest projector pixels per degree",
    "targets.theta_min": "targets.theta_min: the design's smallest theta must not lie above it (deg)",
    "targets.theta_max": "targets.theta_max: the design's largest theta must reach it (deg)",
    "raycheck.max_lost_fraction": "raycheck.max_lost_fraction: pixels the mount hides",
    "later.layout_and_parts": "optimize.constraints.later_stages: the rig's layout and part recipes build (the "
                              "tower, the splitter and the instruments against the dome; what rigcad design and stl "
                              "refuse before any solid)",
    "later.calibration_screen": "optimize.constraints.later_stages: the calibration's screen (calibration.screen_*) "
                                "lies inside the dome where its spacers put it (value: how far its corners reach in)",
    "later.tolerance_stack": "optimize.constraints.later_stages: rigcad fab's tolerance stack on the printer holds or "
                             "adjusts every placement (value: the placements refused)",
}


def violation(row: dict) -> float:
    """Sum of the scaled constraint violations (0 when feasible; inf for a refused design)."""
    if row["constraints"] is None:
        return math.inf
    return float(sum(max(v, 0.0) / UNIT_SCALE[CONSTRAINT_UNITS[k]] for k, v in row["constraints"].items()))


def evaluate_task(problem: Problem, batch: list) -> list[dict]:
    """The engine's job: evaluate a batch of points (internal units)."""
    return [evaluate(problem, x) for x in batch]
