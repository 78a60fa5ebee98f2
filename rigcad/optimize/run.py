"""``rigcad optimize PROFILE``: read the ``optimize:`` section, search, check the chosen design on
the certified path (``Rig.from_profile`` + the 2D design), and publish, all together, into
``exports/<profile>/optimize/``:

* ``<profile>_design.yaml``: the chosen design as a profile that ``extends:`` PROFILE and sets only
  the parameters that changed (``rigcad stl exports/<profile>/optimize/<profile>_design.yaml``); when
  PROFILE is not shipped with rigcad, it is written beside PROFILE's file instead, where its
  ``extends:`` resolves from any folder, and goes with it when the folder moves;
* ``optimize.json``: the settings, every evaluation (parameters, objectives, constraint values,
  time), the Pareto set, the base and chosen designs, the certified check of the chosen one;
* ``history.png`` (merit per evaluation) and ``pareto.png`` (objectives, front, base, chosen).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rigcad.engine import Engine
from rigcad.optimize.problem import (CONSTRAINT_UNITS, DEFAULT_STACK_PRINTER, Problem, apply, custom_focal_length,
                                     make_problem)
from rigcad.errors import RigcadError
from rigcad.optimize.search import OptimizeError, Result, infeasible_message, optimize, preference
from rigcad.optimize.spec import COATING_TOTAL, OBJECTIVES, read_optimize
from rigcad.units import DEG

#: Designs the assembly gate (the costly check, seconds to a minute each) judges, best first, before
#: the run gives up.
MAX_CERTIFY = 8
#: Designs tried on the certified path at most (the layout, the recipes and fab's tolerance stack
#: cost about a second each): designs these refuse give way to the next without counting in MAX_CERTIFY.
MAX_TRIED = 40
#: Relative change below which a free parameter counts as unchanged (not written to the profile).
UNCHANGED_RTOL = 1e-9


@dataclass
class OptimizeRun:
    report: dict
    written: list[Path]
    profile_path: Path | None
    result: Result


def load_problem(profile_spec, overrides: dict | None = None) -> Problem:
    """The profile (by name or path) and its validated optimize section; ``overrides`` replaces
    search settings (seed, evaluations, workers) from the command line."""
    import dataclasses

    from rigcad.profile.loader import load_raw
    from rigcad.profile.schema import validate

    raw = load_raw(profile_spec)
    profile = validate(raw)
    spec = read_optimize(raw, profile)
    if overrides:
        from rigcad.errors import ProfileError
        from rigcad.optimize.spec import MAX_EVALUATIONS

        limits = {"seed": (0, 2**63 - 1), "evaluations": (10, MAX_EVALUATIONS), "workers": (0, 256)}
        for key, value in overrides.items():
            lo, hi = limits[key]
            if value is not None and not lo <= value <= hi:
                raise ProfileError(f"--{key} {value}: expected a whole number {lo}..{hi}", param=f"--{key}")
        spec = dataclasses.replace(spec, **{k: v for k, v in overrides.items() if v is not None})
    return make_problem(profile, spec)


def _values(problem: Problem, x) -> dict:
    out = {}
    for p, v in zip(problem.spec.parameters, x):
        unit = {"length": "_mm", "angle": "_deg"}.get(p.kind, "")
        out[p.key + unit] = v / DEG if p.kind == "angle" else v
    return out


def _row_json(problem: Problem, r: dict) -> dict:
    return {"index": r["index"], "phase": r["phase"], "parameters": _values(problem, r["x"]),
            "objectives": r["objectives"], "constraints": r["constraints"], "feasible": r["feasible"],
            "merit": r["merit"], "error": r["error"], "time_s": r["time_s"], "cpu_s": r["cpu_s"],
            "figures": r["figures"]}


def design_yaml(problem: Problem, row: dict, base_name: str, note: str) -> str:
    """The chosen design as a profile extending ``base_name``, setting only what changed."""
    profile = apply(problem.base, problem.names, row["x"])
    sections: dict[str, list[str]] = {}
    for p, v in zip(problem.spec.parameters, row["x"]):
        if abs(v - p.base) <= UNCHANGED_RTOL * max(abs(p.base), 1e-12):
            continue
        if p.key == COATING_TOTAL:
            lines = [f"    - {{name: {n!r}, thickness: {t:.12g} mm}}" for n, t in profile.coating.layers]
            sections.setdefault("coating", []).append("  layers:\n" + "\n".join(lines))
            continue
        section, _, name = p.key.partition(".")
        sections.setdefault(section, []).append(f"  {name}: {p.shown(v)}")
    if row.get("dome_tolerance_mm") is not None:
        sections.setdefault("dome", []).append(
            f"  tolerance: {row['dome_tolerance_mm']:g} mm   # the base's {problem.base.dome.tolerance:g} mm cannot be "
            "certified in float64 on this geometry")
    if row.get("mirror_normal_error_rad") is not None:
        sections.setdefault("tessellation", []).append(
            f"  mirror_normal_error: {row['mirror_normal_error_rad']:g} rad   # finer mirror meshes: the base's "
            f"{problem.base.tessellation.mirror_normal_error:g} rad fail rigcad check's mesh-read rows on this design")
    if row.get("focal_length_mm") is not None:
        sections.setdefault("lens", []).append(
            f"  focal_length: {row['focal_length_mm']:g} mm   # no stock 2 in singlet focuses this design: a custom lens")
    f = row["figures"]
    head = [f"# Chosen by `rigcad optimize {base_name}` ({note}).",
            f"# theta {f['theta_min_deg']:.3f}..{f['theta_max_deg']:.1f} deg, {f['px_per_deg_mean']:.4f} px/deg mean "
            f"(CV {f['px_per_deg_cv']:.4f}, min {f['px_per_deg_min']:.4f}), dome {f['dome_outer_width_mm']:.1f} x "
            f"{f['dome_outer_height_mm']:.1f} mm"
            + (f", {f['dome_pieces']} piece(s) on {problem.printer.name}" if f.get("dome_pieces") else "") + ".",
            f"extends: {base_name}",
            f"description: {base_name} as chosen by rigcad optimize"]
    body = [f"{s}:\n" + "\n".join(lines) for s, lines in sections.items()]
    return "\n".join(head) + "\n\n" + "\n\n".join(body) + "\n"


#: Looser dome tolerances (mm) tried, in order, when float64 cannot certify the base profile's
#: explicit ``dome.tolerance`` on a chosen geometry; each stays far below what the dome's curve
#: needs (CURVE_MISS_RTOL of the optical path, ~6e-7 mm) and the meshes' micrometres.
LOOSER_TOLERANCES = (3e-9, 1e-8, 3e-8, 1e-7)


def certified_rig(problem: Problem, row: dict):
    """The Rig of ``row``'s design (``Rig.from_profile``), and the dome tolerance it needed (mm) when
    the base profile's explicit one cannot be certified there (None: the base's own)."""
    import dataclasses

    from rigcad.errors import IntegrationError
    from rigcad.rig import Rig

    profile = apply(problem.base, problem.names, row["x"])
    base_tol = profile.dome.tolerance
    tries = [None] + [t for t in LOOSER_TOLERANCES if base_tol is not None and t > base_tol]
    for tol in tries:
        p = profile if tol is None else dataclasses.replace(profile, dome=dataclasses.replace(profile.dome, tolerance=tol))
        try:
            return Rig.from_profile(p), tol
        except IntegrationError as err:
            if err.param != "dome.tolerance" or tol == tries[-1]:
                raise
    raise AssertionError("unreachable")


#: The design's focusing lens (rigcad.optimize.problem.custom_focal_length), under its old name.
_custom_focal_length = custom_focal_length


#: Finer mirror meshes tried when the 3D check refuses a design on the profile's own: the profile's
#: tessellation.mirror_normal_error times each factor in turn (the rows that read the meshes, such as
#: the camera through the splitter, shrink with the facets; measured on a design of achutha2006_optimize:
#: 0.0101 deg against the 0.01 deg limit at 0.01 rad, 0.0084 deg at 0.005 rad).
FINER_MESHES = (0.5, 0.25)


def ray_check(rig):
    """`rigcad check` on ``rig`` in memory (rigcad.api.check: the profile's rays, reading and seeded
    Monte Carlo yield, the mirrors meshed from the profile), and, when it fails, again with finer
    mirror meshes (FINER_MESHES). Returns the rig that passed, the mirror_normal_error (rad) it needed
    when finer than the profile's (else None), what optimize.json records and the check's result
    (a RayCheck, for :func:`publish_check`); CheckError (the
    check's own message, naming each failed row) when none passes."""
    import dataclasses

    from rigcad import api
    from rigcad.check.tolerances import raise_if_failed
    from rigcad.rig import Rig

    p, first = rig.profile, None
    for factor in (1.0, *FINER_MESHES):
        normal = p.tessellation.mirror_normal_error * factor
        r = rig if factor == 1.0 else Rig.from_profile(
            dataclasses.replace(p, tessellation=dataclasses.replace(p.tessellation, mirror_normal_error=normal)),
            previous=rig)  # the same dome: only the meshes change
        result = api.check(r)
        first = first or result
        if result.passed:
            mc = result.report.get("monte_carlo") or {}
            return r, (None if factor == 1.0 else normal), {
                "passed": True, "mirror_normal_error_rad": normal, "monte_carlo_yield": mc.get("yield"),
                "min_yield": mc.get("min_yield"), "builds": mc.get("builds"), "rays": result.report.get("rays")}, result
    raise_if_failed(first.rows, rig.name)  # the profile's own meshes' failures
    raise AssertionError("unreachable: a failed check raises")


def certify(problem: Problem, row: dict, also=None, check: bool = True) -> dict:
    """The chosen design on the certified path (converged DOP853 dome, the 2D design's report) beside
    the fast path's figures: the differences say how far the optimiser's evaluation can be trusted.
    ``also(rig)``: a further check of the design's rig that raises a RigcadError to refuse it (the
    command passes the assembly gate, rigcad.manual.gate, which lives on a floor this one cannot import)."""
    from rigcad.parts.tower import shelf_bottom_z

    import dataclasses

    from rigcad.rig import Rig

    rig, tol = certified_rig(problem, row)
    # the focusing lens first (the optics alone): the tower is laid out about it, so a design that
    # names its custom lens is laid out and checked with that lens on the same dome
    row["focal_length_mm"] = _custom_focal_length(rig.profile, rig.geometry)
    if row["focal_length_mm"] is not None:
        p = rig.profile
        rig = Rig.from_profile(dataclasses.replace(p, lens=dataclasses.replace(p.lens, focal_length=row["focal_length_mm"])),
                               previous=rig)  # the same dome: only the lens changes
    # the refusals `rigcad design` and `stl` make before any solid, on the certified dome (GeometryError:
    # the next design is tried): the layout (beam over the flange, holder inside the base, the tower:
    # its shelf over the dome's top, the splitter, the instruments), every part's recipe; the search's
    # constraints hold GEOMETRY_RESERVE mm short of the ones it models
    layout = rig.layout
    rig.recipes
    # the calibration's screen in the dome (ProfileError, as `rigcad manual` refuses it: the next design is tried)
    from rigcad.calibrate.kit import check_screen_fits

    check_screen_fits(rig)
    # `rigcad fab`'s tolerance stack on the run's printer (FabricationError: the next design is tried)
    row["tolerance_stack"] = tolerance_stack(problem, rig)
    if also is not None:
        also(rig)
    # `rigcad check` with its yield (CheckError: the next design is tried), finer mirror meshes if they pass it
    row["ray_check"] = None
    row["mirror_normal_error_rad"] = None
    if check:
        checked, row["mirror_normal_error_rad"], row["ray_check"], result = ray_check(rig)
        row["checked"] = (checked, result)  # published for the written design (publish_check)
    row["dome_tolerance_mm"] = tol
    r = rig.design.report
    f = row["figures"]
    pairs = {"theta_min_deg": r["measurable_range"]["theta_min_deg"],
             "px_per_deg_mean": r["pixels"]["px_per_deg_mean"],
             "px_per_deg_min": r["pixels"]["px_per_deg_min"],
             "dome_width_mm": r["envelope"]["width_mm"], "dome_height_mm": r["envelope"]["height_mm"],
             "top_clearance_mm": r["top_aperture"]["clearance_mm"]}
    return {"certified": pairs, "fast_minus_certified": {k: f[k] - v for k, v in pairs.items()},
            "note": "px_per_deg_min of the certified design: np.gradient over its 2001+ rows (second order); the fast "
                    "path's is exact at its nodes", "dome_rows": int(len(rig.dome.s)),
            "dome_error_estimate_mm": rig.dome.error_estimate, "dome_tolerance_mm": rig.dome.tolerance,
            "dome_tolerance_loosened": tol is not None,
            "tolerance_stack": row["tolerance_stack"],  # fab's stack on the run's printer: held or adjusted
            "ray_check": row["ray_check"],  # rigcad check's verdict with its Monte Carlo yield (None: not run)
            # a focal length no stock lens has, written into the design (None: a stock lens focuses it)
            "custom_focal_length_mm": row["focal_length_mm"],
            # room left between the projector's shelf and the dome's top beyond tower.clearance (mm)
            "tower_room_mm": None if rig.geometry.cop_at_infinity else
            shelf_bottom_z(rig.profile, rig.geometry.cop_z) - layout.dome_top_z - rig.profile.tower.clearance}


def tolerance_stack(problem: Problem, rig) -> dict:
    """`rigcad fab`'s tolerance stack (rigcad.fab.stack.stack, closed forms: seams estimated from
    the parts' extents against the bed, as fab estimates a part it did not split) of ``rig`` on the
    optimize section's printer, else DEFAULT_STACK_PRINTER; FabricationError (the stack's own
    refusal, naming the element, axis and dominating links) when the printed rig can neither hold
    nor adjust a placement. Returns what optimize.json records: the printer and each refused or
    adjusted axis (none refused)."""
    from rigcad.fab import stack as ST
    from rigcad.fab.printers import load_printer

    printer = load_printer(problem.spec.constraints.printer or DEFAULT_STACK_PRINTER)
    if printer.process_errors is None:
        return {"printer": printer.name, "note": "no process_errors in the printer file: no stack to reckon"}
    report = ST.stack(rig.profile, rig.layout, printer)
    ST.refuse(report)
    return {"printer": printer.name, "adjusted": [f"{v.element} {v.axis}" for e in report.elements for v in e.axes
                                                  if v.status == "adjusted"]}


def run_optimize(profile_spec, exports: Path = Path("exports"), engine: Engine | None = None, overrides=None,
                 progress=None, certify_also=None, check: bool = True) -> OptimizeRun:
    """Search and publish (module docstring). Raises OptimizeError (after publishing the record of
    every evaluation) when no design meets the constraints. ``certify_also``: :func:`certify`'s
    ``also``, a check every certified design must pass (a design it refuses gives way to the next);
    ``check``: the certified design must pass `rigcad check` with its Monte Carlo yield (:func:`ray_check`)."""
    from rigcad import plots
    from rigcad.export.atomic import Staging, json_bytes, profile_lock

    problem = load_problem(profile_spec, overrides)
    spec = problem.spec
    engine = engine or Engine(workers=spec.workers)
    result = optimize(problem, engine, progress)
    name = problem.base.name
    out = Path(exports) / name / "optimize"
    report = _report(problem, result, engine)
    files: dict[str, bytes] = {}
    profile_path = None
    rejected = _certify_choice(problem, result, report, certify_also, check) if result.chosen is not None else []
    if result.chosen is not None:
        note = f"seed {spec.seed}, {len(result.history)} evaluations, {result.method}; {result.reason}"
        stem = f"{name}_design"
        text = design_yaml(problem, result.chosen, name, note).encode()
        home = _design_home(profile_spec, name, out)
        profile_path = home / f"{stem}.yaml"
        if home == out:
            files[f"{stem}.yaml"] = text
        report["design_profile"] = str(profile_path)
    elif rejected:
        stages: dict[str, int] = {}
        for r in rejected:
            stages[r["stage"]] = stages.get(r["stage"], 0) + 1
        report["infeasible"] = (f"the {len(rejected)} best designs were refused by the later stages ("
                                + ", ".join(f"{n} by the {s}" for s, n in stages.items())
                                + f"); the first: {rejected[0]['error']}")
    else:
        report["infeasible"] = infeasible_message(problem, result.history)
    files["optimize.json"] = json_bytes(report)
    files["history.png"] = plots.optimize_history(report)
    files["pareto.png"] = plots.optimize_pareto(report)
    with Staging(out, profile_lock(exports, name), carry=lambda rel: False) as stage:
        for fname, data in files.items():
            stage.write_bytes(out / fname, data)
        written = stage.commit()
    if profile_path is not None and profile_path.parent != out:
        from rigcad.export.atomic import write_bytes

        written.append(write_bytes(profile_path, text))
    if result.chosen is None:
        raise OptimizeError(f"{name}: {report['infeasible']} (every evaluation in {out / 'optimize.json'})")
    if result.chosen.get("checked") is not None:
        written += publish_check(exports, profile_path, *result.chosen["checked"])
    return OptimizeRun(report, written, profile_path, result)


def publish_check(exports, design_path: Path, checked_rig, result, recheck=None) -> list[Path]:
    """Publish the check of the written design where `rigcad fab`, `stl` and `manual` read the last
    `rigcad check` of a profile (``exports/<design>/check/``, rigcad.check.criteria.written_check),
    recorded as made from the design as its file reads back (export.manifest.profile_digest). The
    certified check (``result`` on ``checked_rig``) is published as it is when the file reads back to
    the same resolved parameters; else (the file's rounded figures) the design as written is checked
    again (``recheck``, default rigcad.api.check) and that result is published, passed or not."""
    from rigcad import api
    from rigcad.export.manifest import profile_digest
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    design = load_profile(design_path)
    rig = Rig.from_profile(design, previous=checked_rig)  # the same dome when the figures agree
    if profile_digest(design) != profile_digest(checked_rig.profile):
        result = (recheck or api.check)(rig)
    return api.write_check(rig, result, Path(exports) / design.name / "check")


def _report(problem, result, engine: Engine) -> dict:
    """optimize.json before the certified path has spoken: the search, its spec and units, the base,
    chosen and Pareto designs and every evaluation."""
    from rigcad._version import __version__

    spec = problem.spec
    name = problem.base.name
    return {
        "rigcad_version": __version__,
        "profile": name, "sources": list(problem.base.sources),
        "method": result.method, "engine": engine.name, "workers": engine.n_workers,
        "spec": spec.describe(),
        "units": {"parameters": "keys end in _mm, _deg or nothing (a number)", "constraints": {
            k: v or "fraction" for k, v in CONSTRAINT_UNITS.items()},
            "constraint_sign": "value <= 0 when met", "merit": "first objective / its scale (minimised); infeasible "
            f"designs {1e6:g} x (1 + scaled violation) above; refused designs 1e12"},
        "objective_scales": {n: OBJECTIVES[n][2] for n, _ in spec.objectives},
        "status": "ok" if result.chosen is not None else "infeasible",
        "reason": result.reason if result.chosen is not None else (result.reason or "no design met the constraints"),
        "base": _row_json(problem, result.base),
        "chosen": _row_json(problem, result.chosen) if result.chosen else None,
        "pareto": [_row_json(problem, r) for r in result.front],
        "timings_s": result.timings,
        "evaluation_time_s": _time_stats(result.history),
        "evaluations": [_row_json(problem, r) for r in result.history],
    }


def _certify_choice(problem, result, report: dict, also=None, check: bool = True) -> list[dict]:
    """Certify the search's choice: the certified path (converged DOP853 dome at the profile's
    dome.tolerance) has the last word, and a design it refuses (e.g. a tolerance float64 cannot
    certify there, a tolerance stack fab refuses, a rig the further check refuses) gives way to the next
    in preference, up to MAX_TRIED designs of which MAX_CERTIFY reach the further check. Sets ``result.chosen``
    and ``.reason`` (None: every one refused) and the report's verdict; returns the refused designs."""
    rejected, certified = [], None
    for row, why in preference(problem, result)[:MAX_TRIED]:
        if sum(1 for r in rejected if r["stage"].startswith("assembly")) >= MAX_CERTIFY:
            break
        try:
            report["certified_check"] = certify(problem, row, also, check)
        except RigcadError as err:
            # the stage that refused it (the constraint that bound) and, for a one-line digest, the whole reason
            rejected.append({"index": row["index"], "error": str(err), "stage": _stage_of(err),
                             **({"detail": err.detail} if getattr(err, "detail", "") else {})})
            continue
        certified = (row, why)
        break
    if certified is not None:
        result.chosen, result.reason = certified
    else:  # every design tried was refused (or none was tried): the search's reason no longer holds
        result.chosen = None
        result.reason = (f"none of the {len(rejected)} designs tried passed the later stages"
                         if rejected else "no design to certify")
    report["rejected_by_certified_path"] = rejected
    report["chosen"] = _row_json(problem, result.chosen) if result.chosen else None
    report["reason"] = result.reason
    report["status"] = "ok" if result.chosen is not None else "infeasible"
    return rejected


def _stage_of(err: RigcadError) -> str:
    """Which later stage refused a certified design: the assembly gate, fab's tolerance stack, or the
    rig's layout and part recipes (what `rigcad design` and `stl` refuse before any solid)."""
    from rigcad.errors import AssemblyError, CheckError, FabricationError, ProfileError

    if isinstance(err, ProfileError):
        return "calibration screen in the dome (rigcad manual)"
    if isinstance(err, AssemblyError):
        return "assembly gate (rigcad stl, fab, manual)"
    if isinstance(err, CheckError):
        return "ray check with its yield (rigcad check)"
    if isinstance(err, FabricationError):
        return "tolerance stack (rigcad fab)"
    return "layout and part recipes (rigcad design, stl)"


def _design_home(profile_spec, name: str, out: Path) -> Path:
    """Where the design profile goes: ``out`` when its ``extends: name`` names a profile shipped with
    rigcad (found by name from any folder), else beside the searched profile's own file, where the
    name resolves wherever the folder is moved or the command is run from (a name found through
    ./profiles or $RIGCAD_PROFILES resolves only from that folder or with that variable set)."""
    from rigcad.errors import ProfileError
    from rigcad.profile.loader import find_file, resolve_profile_path
    from rigcad.profile.paths import SHIPPED_PROFILES

    base = resolve_profile_path(profile_spec).resolve()
    try:
        found = find_file(name, "profile", near=out, as_path=False).resolve()
    except ProfileError:
        found = None
    return out if found == base and base.parent == SHIPPED_PROFILES.resolve() else base.parent


def _time_stats(rows: list[dict]) -> dict:
    import numpy as np

    t = np.array([r["time_s"] for r in rows])
    c = np.array([r["cpu_s"] for r in rows])
    return {"evaluations": int(len(t)), "median_s": float(np.median(t)), "max_s": float(t.max()),
            "cpu_median_s": float(np.median(c)), "cpu_max_s": float(c.max()),
            "note": "per evaluation in its worker (one core): wall time (time_s) and the process's CPU time (cpu_s, "
                    "what the evaluation cost whatever else the machine runs)"}
