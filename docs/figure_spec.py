"""What `make docs` runs and which figure of which output each name in the docs means (read by
docs/figures.py and tests/test_docs.py). A name here is a figure the Markdown may quote as
``<number><!--fig:name-->``; every value is read from an output, never typed in."""

from __future__ import annotations

import json
import math
import re
import subprocess
from pathlib import Path

from figures import PROFILE, Figure, Picture, Run

P = PROFILE
MK3S = "prusa_mk3s"

#: The documented commands, in order (each reads what the ones before it wrote). Form 3 is not run:
#: today it refuses the tower column (no grid of up to 6 x 6 pieces fits), so `rigcad fab --printer
#: form3` exits 1 on the default profile.
RUNS = (
    Run("stl", ("stl", P)),
    Run("check", ("check", P)),
    Run("view", ("view", P)),
    Run("fab_mk3s", ("fab", P, "--printer", MK3S)),
    Run("fab_vantage", ("fab", P, "--printer", "vantage_i")),
    Run("manual", ("manual", P, "--printer", MK3S)),
    Run("tolerance", ("tolerance", P, "--samples", "10000")),
    Run("optimize", ("optimize", "achutha2006_optimize")),
    Run("basis", ("basis", P, "--order", "6", "--simulate")),
    # The calibration picture, in a root of its own: `rigcad basis --simulate` reads a corrected map
    # when one lies beside it, and the basis figures must not depend on an earlier `make docs`.
    Run("calibrate", ("calibrate", P, "--simulate", "--seed", "7"), folder="calibrate"),
    # The capture conventions' picture, drawn by the kit from the code's conventions
    Run("calibrate_kit", ("calibrate", P, "--kit"), folder="calibrate"),
    # The support picture: the dome and the paraboloid sliced by PrusaSlicer (the whole rig through
    # the slicer is a one-off: see bench_figures). A root of its own: a partial fab run would replace
    # the full run's fab.json.
    Run("support", ("fab", P, "--printer", MK3S, "--gcode", "--parts", "dome", "paraboloid"), folder="gcode"),
)

DESIGN = f"{P}/design.json"
MANIFEST = f"{P}/manifest.json"
RAYCHECK = f"{P}/check/raycheck.json"
MANUAL = f"{P}/manual/{MK3S}/manual.json"
TOLERANCE = f"{P}/tolerance/summary.json"
OPTIMIZE = "achutha2006_optimize/optimize/optimize.json"


def fab_json(printer: str) -> str:
    return f"{P}/fab/{printer}/fab.json"


def _size(part: str):
    def get(m):
        e = m["parts"][part]
        return [hi - lo for lo, hi in zip(e["bbox_min_mm"], e["bbox_max_mm"])]
    return get


def _parts() -> list[str]:
    """The parts the shipped code builds (the docs' parts table has a row for each)."""
    from rigcad.parts import PARTS  # noqa: PLC0415 - the spec is read with rigcad importable

    return list(PARTS)


def _design() -> list[Figure]:
    d = lambda name, path, unit, fmt: Figure(f"design.{name}", "stl", DESIGN, path, unit, fmt)  # noqa: E731
    return [
        d("dome.width_in", "envelope.width_in", "in", ".2f"),
        d("dome.height_in", "envelope.height_in", "in", ".2f"),
        d("dome.width_mm", "envelope.width_mm", "mm", ".1f"),
        d("dome.height_mm", "envelope.height_mm", "mm", ".1f"),
        d("pixels_vertex_to_rim", "pixels.vertex_to_rim_px", "px", ".1f"),
        d("theta_min_deg", "measurable_range.theta_min_deg", "deg", ".2f"),
        d("px_per_deg_mean", "pixels.px_per_deg_mean", "px/deg", ".2f"),
        d("px_per_deg_min", "pixels.px_per_deg_min", "px/deg", ".2f"),
        d("px_per_deg_max", "pixels.px_per_deg_max", "px/deg", ".2f"),
        d("focal_length_mm", "paraboloid.focal_length_mm", "mm", ".2f"),
        d("rim_radius_mm", "paraboloid.rim_radius_mm", "mm", ".2f"),
        d("vertex_roc_mm", "paraboloid.vertex_radius_of_curvature_mm", "mm", ".2f"),
        d("cop_z_mm", "paraboloid.cop_z_mm", "mm", ".1f"),
        Figure("design.max_miss_mm", "stl", DESIGN, "convergence.max_miss_mm", "mm", ".1e", roundoff=True),
        Figure("design.dome_vs_equal_path_mm", "stl", DESIGN, "dome.error_vs_equal_path_mm", "mm", ".1e",
               roundoff=True),
        d("splitter_thickness_mm", "profile.parameters.beam_splitter.thickness_mm", "mm", ".1f"),
        d("splitter_index", "profile.parameters.beam_splitter.index", "", ".4f"),
    ]


def _parts_figures() -> list[Figure]:
    out = []
    for name in _parts():
        out += [Figure(f"parts.{name}.quantity", "stl", MANIFEST, f"parts.{name}.quantity", "", count=True),
                Figure(f"parts.{name}.size_mm", "stl", MANIFEST, _size(name), "mm", ".1f"),
                Figure(f"parts.{name}.volume_cm3", "stl", MANIFEST,
                       lambda m, n=name: m["parts"][n]["volume_mm3"] / 1000, "cm^3", ".2f")]
    tower = "layout.tower"
    return out + [
        Figure("parts.dome.width_mm", "stl", MANIFEST, lambda m: _size("dome")(m)[0], "mm", ".1f"),
        Figure("parts.beam.hidden_sr", "stl", MANIFEST, "occlusion.beam_solid_angle_sr", "sr", ".3f"),
        Figure("parts.beam.hidden_percent", "stl", MANIFEST, lambda m: 100 * m["occlusion"]["blocked_fraction"], "%", ".2f"),
        Figure("parts.tower.plate_shift_mm", "stl", MANIFEST, f"{tower}.chief_ray_shift_closed_form_mm", "mm", ".4f"),
        Figure("parts.tower.camera_across_mm", "stl", MANIFEST,
               lambda m: abs(m["layout"]["tower"]["compensation_offset_mm"][0]), "mm", ".3f"),
        Figure("parts.tower.camera_up_mm", "stl", MANIFEST, f"{tower}.compensation_offset_mm.2", "mm", ".3f"),
        Figure("parts.tower.bundle_rms_um", "stl", MANIFEST,
               lambda m: 1000 * m["layout"]["tower"]["bundle_rms_distance_from_cop_mm"], "um", ".1f"),
    ]


def _check() -> list[Figure]:
    c = lambda name, get, unit, fmt, count=False: Figure(f"check.{name}", "check", RAYCHECK, get, unit, fmt, count)  # noqa: E731
    r, t = "readings", "tower"
    return [
        Figure("check.analytic.spot_mm", "check", RAYCHECK, f"{r}.analytic.max_spot_radius_mm", "mm", ".1e",
               roundoff=True),
        Figure("check.analytic.angle_rad", "check", RAYCHECK, f"{r}.analytic.max_angle_error_rad", "rad", ".1e",
               roundoff=True),
        c("smooth.spot_um", lambda j: 1000 * j[r]["smooth"]["max_spot_radius_mm"], "um", ".1f"),
        c("smooth.angle_rad", f"{r}.smooth.max_angle_error_rad", "rad", ".1e"),
        c("smooth.angle_deg", lambda j: math.degrees(j[r]["smooth"]["max_angle_error_rad"]), "deg", ".4f"),
        c("mesh.spot_mm", f"{r}.mesh.max_spot_radius_mm", "mm", ".2f"),
        c("mesh.angle_rad", f"{r}.mesh.max_angle_error_rad", "rad", ".3f"),
        c("analytic.beam_percent", lambda j: 100 * j[r]["analytic"]["losses"]["occluded_by_beam"]["fraction"], "%", ".2f"),
        c("analytic.theta_min_deg", f"{r}.analytic.theta_min_deg", "deg", ".2f"),
        c("analytic.theta_max_deg", f"{r}.analytic.theta_max_deg", "deg", ".1f"),
        c("px_per_deg_min", "pixels_per_degree.px_per_deg_min", "px/deg", ".2f"),
        c("px_per_deg_max", "pixels_per_degree.px_per_deg_max", "px/deg", ".2f"),
        c("splitter.spot_um", lambda j: 1000 * j[t]["camera_through_splitter"]["max_spot_radius_mm"], "um", ".1f"),
        c("splitter.angle_deg", lambda j: math.degrees(j[t]["camera_through_splitter"]["max_mirror_angle_error_rad"]),
          "deg", ".4f"),
        c("splitter_uncompensated.spot_um",
          lambda j: 1000 * j[t]["camera_through_splitter_uncompensated"]["max_spot_radius_mm"], "um", ".1f"),
        c("splitter_uncompensated.angle_rad", f"{t}.camera_through_splitter_uncompensated.max_angle_error_rad",
          "rad", ".3f"),
        c("splitter_uncompensated.offset_um",
          lambda j: 1000 * j[t]["camera_through_splitter_uncompensated"]["convergence_offset_mm"], "um", ".1f"),
        c("tower.projector_blocked", f"{t}.bundle_clearance.projector.blocked", "rays", "d", True),
        c("tower.projector_rays", f"{t}.bundle_clearance.projector.segments", "rays", ",d", True),
        c("tower.camera_blocked", f"{t}.bundle_clearance.camera.blocked", "rays", "d", True),
        c("tower.camera_rays", f"{t}.bundle_clearance.camera.segments", "rays", ",d", True),
        c("monte_carlo.yield_percent", lambda j: 100 * j["monte_carlo"]["yield"], "%", ".0f"),
    ]


def _fab(printer: str, run: str) -> list[Figure]:
    f = lambda name, get, unit, fmt, count=False: Figure(f"fab.{printer}.{name}", run, fab_json(printer), get, unit, fmt, count)  # noqa: E731
    out = [f("pieces", "totals.pieces", "pieces", "d", True),
           f("print_hours", lambda j: j["totals"]["estimate_print_time_s"] / 3600, "h", ".0f"),
           f("material_g", "totals.estimate_material_g", "g", ",.0f"),
           f("dome.cusp_max_mm", "parts.dome.staircase_map.cusp_max_mm", "mm", ".3f"),
           f("dome.cusp_mean_mm", "parts.dome.staircase_map.cusp_mean_mm", "mm", ".3f"),
           f("dome.sanding_depth_mm", "parts.dome.polishing.sanding_depth_mm", "mm", ".3f"),
           f("dome.stock_mm", "parts.dome.sanding_stock.stock_mm", "mm", ".3f")]
    if printer == MK3S:  # the dome is split on the desktop printer only
        out += [f("dome.seam_step_on_pins_mm", "parts.dome.seams.step_on_pins_mm", "mm", ".2f"),
                f("dome.seam_step_on_gauge_mm", "parts.dome.seams.step_on_gauge_mm", "mm", ".3f"),
                f("dome.staircase_bound_mm", "parts.dome.sanding_stock.needed_bound_mm", "mm", ".3f"),
                f("dome.pin_hole_behind_printed_mm", "parts.dome.seams.pin_hole_behind_printed_mm", "mm", ".2f"),
                f("dome.pin_hole_cover_mm", "parts.dome.seams.pin_hole_cover_after_sanding_mm", "mm", ".2f"),
                f("dome.glue_face_step_mm", "parts.dome.seams.glue_face_step_mm", "mm", ".3f"),
                f("dome.glue_gap_mm", "parts.dome.seams.glue_gap_mm", "mm", ".2f"),
                f("dome.pin_hole_mm", "parts.dome.pin_fit.hole_drawn_mm", "mm", ".2f")]
    for name in _parts():
        out += [f(f"{name}.pieces", lambda j, n=name: len(j["parts"][n].get("pieces") or []), "pieces", "d", True),
                f(f"{name}.pins", lambda j, n=name: len(j["parts"][n].get("pins", [])), "pins", "d", True)]
    return out


def _manual() -> list[Figure]:
    m = lambda name, get, unit, fmt, count=False: Figure(f"manual.{MK3S}.{name}", "manual", MANUAL, get, unit, fmt, count)  # noqa: E731
    cal = "calibration"
    return [
        m("dowel_pins", "bill.pins.quantity", "pins", "d", True),
        m("pin_length_mm", "bill.pins.length_mm", "mm", "g"),
        m("pieces", "bill.totals.pieces", "pieces", "d", True),
        m("print_hours", lambda j: j["bill"]["totals"]["estimate_print_time_s"] / 3600, "h", ".0f"),
        m("material_g", "bill.totals.estimate_material_g", "g", ",.0f"),
        m("flange_bolts", lambda j: next(r["quantity"] for r in j["bill"]["hardware"]
                                         if r["steps"] == ["dome"] and "bolt" in r["item"]), "bolts", "d", True),
        m("dome_area_cm2", lambda j: j["bill"]["mirrors"][0]["design_area_mm2"] / 100, "cm^2", ".1f"),
        m("paraboloid_area_cm2", lambda j: j["bill"]["mirrors"][1]["design_area_mm2"] / 100, "cm^2", ".1f"),
        m("base_paint_ml", "bill.coating.0.to_buy_cm3", "ml", ".0f"),
        m("circle_radius_px", f"{cal}.circle.radius_px", "px", ".1f"),
        m("paraboloid_shadow_mm", f"{cal}.film.paraboloid_shadow_radius_mm", "mm", ".1f"),
        m("beam_shadow_mm", lambda j: 2 * j[cal]["film"]["beam_shadow_half_width_mm"], "mm", ".1f"),
        m("camera_cross_mrad_per_mm", f"{cal}.camera_crosses.separation_mrad_per_mm_offset", "mrad/mm", ".2f"),
        m("projector_cross_mm_per_mm", f"{cal}.projector_crosses.rows.0.separation_per_mm_offset", "mm/mm", ".2f"),
        m("projector_cross_distance_mm", f"{cal}.projector_crosses.rows.0.projector_to_near_cross_mm", "mm", ".1f"),
        m("projector_cross_plate_mm", f"{cal}.projector_crosses.plate_length_mm", "mm", ".0f"),
        Figure(f"manual.{MK3S}.assembly_steps", "manual", f"{P}/manual/{MK3S}/manual.md",
               lambda text: len(re.findall(r"^### Step \d+:", text, flags=re.M)), "steps", "d", True),
        Figure(f"manual.{MK3S}.html_mb", "manual", f"{P}/manual/{MK3S}/manual.html", "@bytes", "MB", ".1f"),
        Figure("view.html_mb", "view", f"{P}/view/rig.html", "@bytes", "MB", ".2f"),
    ]


def _build() -> tuple[Figure, ...]:
    figs = (_design() + _parts_figures() + _check() + _fab(MK3S, "fab_mk3s") + _fab("vantage_i", "fab_vantage")
            + _manual())
    return tuple(figs)


def bench_figures(root: Path) -> dict[str, dict]:
    """Figures of the committed bench results (bench/results/*.json, `make bench`): one-off
    measurements, each with its command, the machine it ran on and the date it was committed."""
    spec = [
        ("bench.dome.speedup_table31", "dome", "cases.0.speedup_at_1e-6_relative.speedup", "x", ",.0f"),
        ("bench.dome.speedup_ellipse", "dome", "cases.1.speedup_at_1e-6_relative.speedup", "x", ",.0f"),
        ("bench.make_stl.design_s", "make_stl", "commands.design.wall_median_s", "s", ".1f"),
        ("bench.make_stl.design_rss_mib", "make_stl", "commands.design.max_rss_mib", "MiB", ".0f"),
        ("bench.make_stl.cold_s", "make_stl", "commands.stl_cold.wall_median_s", "s", ".1f"),
        ("bench.make_stl.unchanged_s", "make_stl", "commands.stl_unchanged.wall_median_s", "s", ".2f"),
        ("bench.make_stl.build_rss_mib", "make_stl", "commands.build.max_rss_mib", "MiB", ".0f"),
        ("bench.make_stl.check_s", "make_stl", "commands.check.wall_median_s", "s", ".1f"),
        ("bench.make_stl.check_rss_mib", "make_stl", "commands.check.max_rss_mib", "MiB", ".0f"),
        ("bench.fab.estimate_worst_percent", "fab_estimates", "worst_rel_error", "%", ".1f", 100),
        ("bench.fab.estimate_loo_percent", "fab_estimates", "worst_leave_one_out_rel_error", "%", ".1f", 100),
        ("bench.tolerance.serial_s", "tolerance", "engines.1 worker (serial).wall_s", "s", ".1f"),
        ("bench.tolerance.loky_s", "tolerance", "engines.2 loky workers.wall_s", "s", ".1f"),
        ("bench.tolerance.loky_speedup", "tolerance", "engines.2 loky workers.speed_up_over_one_worker", "x", ".2f"),
        ("bench.tolerance.dask_s", "tolerance", "engines.Dask LocalCluster, 2 workers.wall_s", "s", ".1f"),
        ("bench.tolerance.dask_speedup", "tolerance", "engines.Dask LocalCluster, 2 workers.speed_up_over_one_worker",
         "x", ".2f"),
        ("bench.optimize.eval_ms", "optimize", "evaluation.cpu_median_s", "ms", ".1f", 1000),
        ("bench.optimize.eval_p90_ms", "optimize", "evaluation.cpu_p90_s", "ms", ".1f", 1000),
        ("bench.optimize.table31_ms", "optimize", "evaluation.table31_cpu_s", "ms", ".1f", 1000),
        ("bench.optimize.certified_ms", "optimize", "evaluation.certified_derive_plus_converged_dome_cpu_median_s",
         "ms", ".0f", 1000),
        ("bench.optimize.speedup", "optimize", "evaluation.speedup_vs_certified", "x", ".0f"),
        ("bench.optimize.designs", "optimize", "evaluation.designs", "designs", "d", None),
        ("bench.optimize.evaluations", "optimize", "optimize.evaluations", "evaluations", "d", None),
        ("bench.optimize.serial_s", "optimize", "optimize.workers_1_s", "s", ".0f"),
        ("bench.optimize.two_workers_s", "optimize", "optimize.workers_2_s", "s", ".0f"),
    ]
    out = {}
    from figures import dig  # noqa: PLC0415

    for name, bench, path, unit, fmt, *scale in spec:
        file = root / "bench" / "results" / f"{bench}.json"
        data = json.loads(file.read_text())
        value = dig(data, path)
        count = scale == [None]
        if not count:
            value = float(value) * (scale[0] if scale else 1)
        run = data.get("run") or data.get("machine") or {}
        if isinstance(run, dict) and run.get("cpus"):
            machine = f"{run.get('machine', 'x86_64')}, {run['cpus']} cores, load average {run.get('loadavg_1min', '?')}"
        else:  # the older bench files do not record it
            machine = str(run) if run and not isinstance(run, dict) else "the project's shared 2-core machine (not recorded in the result)"
        date = subprocess.run(["git", "log", "-1", "--format=%cs", "--", str(file)], cwd=root, capture_output=True,
                              text=True).stdout.strip() or "uncommitted"
        out[name] = {"value": int(value) if count else value, "unit": unit, "format": fmt,
                     "tolerance": "exact" if count else "as printed", "kind": "one-off",
                     "source": f"`python bench/{bench}.py` (`make bench`) -> bench/results/{bench}.json {path}",
                     "machine": machine, "date": date}
    return out


PICTURES = (
    Picture("rig.png", "view", "view/rig.png", "view/rig.html"),
    # the diagram is drawn from the design of this profile: not from design.json's residuals at the
    # arithmetic's floor and finite-difference sensitivities, whose 9th digits move with the CPU
    # (OPENBLAS_CORETYPE=Prescott with numpy's SIMD off moves 14 of them)
    Picture("rays.png", "stl", "rays.png", "design.json#profile,envelope,measurable_range,paraboloid"),
    Picture("spot.png", "check", "check/spot.png", "check/raycheck.json#readings"),
    Picture("theta_map.png", "check", "check/theta_map.png", "check/raycheck.json#pixel_grid"),
    Picture("fab_support_dome.png", "support", f"fab/{MK3S}/support/dome_s1of4.png",
            f"fab/{MK3S}/fab.json#parts.dome.pieces.0.gcode.sha256"),  # the G-code it is drawn from
    Picture("tolerance_histograms.png", "tolerance", "tolerance/histograms.png", "tolerance/summary.json"),
    Picture("tolerance_sensitivity.png", "tolerance", "tolerance/sensitivity.png", "tolerance/summary.json"),
    Picture("calibrate_maps.png", "calibrate", "calibrate/maps.png", "calibrate/calibration.json#residual_slopes"),
    Picture("calibrate_conventions.png", "calibrate_kit", "calibrate_kit/conventions.png", "calibrate_kit/conventions.png"),
    Picture("optimize_history.png", "optimize", "../achutha2006_optimize/optimize/history.png",
            "../achutha2006_optimize/optimize/optimize.json#evaluations"),
    Picture("optimize_pareto.png", "optimize", "../achutha2006_optimize/optimize/pareto.png",
            "../achutha2006_optimize/optimize/optimize.json#evaluations"),
)


def _part_pictures() -> tuple[Picture, ...]:
    return tuple(Picture(f"parts/{n}.png", "stl", f"renders/{n}.png", f"part:{n}") for n in _parts())


def _basis() -> list[Figure]:
    j = f"{P}/basis/basis.json"
    s = f"{P}/basis/simulation.json"
    b = lambda name, file, get, unit, fmt: Figure(f"basis.{name}", "basis", file, get, unit, fmt)  # noqa: E731
    return [
        b("solid_angle_rel_error", j, lambda d: abs(d["solid_angle"]["relative_error"]), "", ".1e"),
        b("zone_alpha_deg", j, "zone.alpha_deg", "deg", ".2f"),
        b("gram_off_min", j, "gram.order_2.analytic.max_abs", "", ".2f"),
        b("gram_off_max", j, "gram.order_6.analytic.max_abs", "", ".2f"),
        b("dark_percent", j, lambda d: 100 * (1 - d["projector"]["lit_fraction_of_zone"]), "%", ".1f"),
        b("lowdin_8bit", j, "gram.order_6.lowdin_8bit.max_abs", "", ".0e"),
        b("gray_card", s, "rigs.as_designed.gray_card_order_1.gram.albedo_max_rel_error", "", ".1e"),
    ]


def _limit_row(summary: dict, parameter: str) -> dict:
    return next(r for r in summary["sensitivity_and_limits"] if r["parameter"] == parameter)


def _tolerance() -> list[Figure]:
    t = lambda name, get, unit, fmt, count=False: Figure(f"tolerance.{name}", "tolerance", TOLERANCE, get, unit, fmt, count)  # noqa: E731
    return [
        t("samples", "samples", "samples", ",d", True),
        t("yield_percent", lambda s: 100 * s["yield"], "%", ".0f"),
        t("spot_max_mm", "figures.max_spot_radius_mm.max", "mm", ".2f"),
        t("spot_p90_mm", "figures.max_spot_radius_mm.p90", "mm", ".2f"),
        t("dome_offset.spot_budget_percent", lambda s: 100 * _limit_row(s, "dome_offset")["spot_budget_used"], "%", ".0f"),
        t("dome_offset.angle_limit_mm", lambda s: _limit_row(s, "dome_offset")["limit_mm"], "mm", ".1f"),
        t("paraboloid_tilt.angle_budget_percent",
          lambda s: 100 * _limit_row(s, "paraboloid_tilt")["angle_budget_used"], "%", ".0f"),
        t("paraboloid_tilt.angle_limit_deg", lambda s: math.degrees(_limit_row(s, "paraboloid_tilt")["limit_rad"]),
          "deg", ".2f"),
    ]


def _optimize() -> list[Figure]:
    o = lambda name, get, unit, fmt, count=False: Figure(f"optimize.{name}", "optimize", OPTIMIZE, get, unit, fmt, count)  # noqa: E731
    out = [o("evaluations", "evaluation_time_s.evaluations", "evaluations", "d", True),
           o("search_s", "timings_s.total_s", "s", ".1f"),
           o("improvement_percent", lambda j: float(re.search(r"([\d.]+) %", j["reason"])[1]), "%", ".0f")]
    for which in ("base", "chosen"):
        f = f"{which}.figures"
        out += [
            o(f"{which}.theta_min_deg", f"{f}.theta_min_deg", "deg", ".2f"),
            o(f"{which}.px_per_deg_cv", f"{f}.px_per_deg_cv", "", ".4f"),
            o(f"{which}.px_per_deg_mean", f"{f}.px_per_deg_mean", "px/deg", ".3f"),
            o(f"{which}.px_per_deg_min", f"{f}.px_per_deg_min", "px/deg", ".3f"),
            o(f"{which}.px_per_deg_max", f"{f}.px_per_deg_max", "px/deg", ".3f"),
            o(f"{which}.vertex_to_rim_px", f"{f}.vertex_to_rim_px", "px", ".1f"),
            o(f"{which}.occluded_percent", lambda j, w=which: 100 * j[w]["figures"]["occluded_fraction"], "%", ".2f"),
            o(f"{which}.dome_outer_width_mm", f"{f}.dome_outer_width_mm", "mm", ".1f"),
            o(f"{which}.dome_outer_height_mm", f"{f}.dome_outer_height_mm", "mm", ".1f"),
            o(f"{which}.dome_mass_g", f"{f}.dome_mass_g", "g", ",.0f"),
            o(f"{which}.cop_z_mm", f"{f}.cop_z_mm", "mm", ".1f"),
            o(f"{which}.dome_pieces", f"{f}.dome_pieces", "pieces", "d", True),
            o(f"{which}.dome_sectors", f"{f}.dome_sectors", "sectors", "d", True),
            o(f"{which}.dome_bands", f"{f}.dome_bands", "bands", "d", True),
        ]
    return out + [
        o("chosen.cop_to_vertex_cm", lambda j: j["chosen"]["parameters"]["layout.cop_to_vertex_mm"] / 10, "cm", ".2f"),
        o("chosen.sample_to_rim_cm", lambda j: j["chosen"]["parameters"]["layout.sample_to_rim_mm"] / 10, "cm", ".2f"),
        o("chosen.vertical_extent_cm", lambda j: j["chosen"]["parameters"]["paraboloid.vertical_extent_mm"] / 10,
          "cm", ".3f"),
        o("chosen.tangent_angle_deg", lambda j: j["chosen"]["parameters"]["paraboloid.tangent_angle_deg"], "deg", ".0f"),
        o("fast_minus_certified.theta_min_deg", lambda j: abs(j["certified_check"]["fast_minus_certified"]["theta_min_deg"]),
          "deg", ".0e"),
        o("fast_minus_certified.dome_width_mm", lambda j: abs(j["certified_check"]["fast_minus_certified"]["dome_width_mm"]),
          "mm", ".0e"),
    ]


def _pieces(j: dict, part: str) -> list[dict]:
    return [pc["gcode"] for pc in j["parts"][part]["pieces"] if "gcode" in pc]


def _support() -> list[Figure]:
    """The slicer's own figures for the dome's quarters and the paraboloid (`rigcad fab --gcode`)."""
    s = lambda name, get, unit, fmt: Figure(f"gcode.{name}", "support", fab_json(MK3S), get, unit, fmt)  # noqa: E731
    contact = lambda part, key, pick: lambda j: pick(g["support_contact"][key] for g in _pieces(j, part))  # noqa: E731
    estimate = lambda part, key, pick, scale=1: lambda j: pick(g["estimates"][key] for g in _pieces(j, part)) * scale  # noqa: E731
    return [
        s("dome.mirror_mm2", contact("dome", "mirror_mm2", max), "mm^2", ",.0f"),
        s("dome.other_min_mm2", contact("dome", "other_mm2", min), "mm^2", ",.0f"),
        s("dome.other_max_mm2", contact("dome", "other_mm2", max), "mm^2", ",.0f"),
        s("dome.piece_hours", estimate("dome", "print_time_s", max, 1 / 3600), "h", ".1f"),
        s("dome.piece_g", estimate("dome", "filament_g", max), "g", ".0f"),
        s("dome.hours", estimate("dome", "print_time_s", sum, 1 / 3600), "h", ".0f"),
        s("dome.kg", estimate("dome", "filament_g", sum, 1e-3), "kg", ".2f"),
        s("paraboloid.mirror_mm2", contact("paraboloid", "mirror_mm2", max), "mm^2", ",.0f"),
        s("paraboloid.other_mm2", contact("paraboloid", "other_mm2", max), "mm^2", ",.0f"),
    ]


FIGURES = _build() + tuple(_basis()) + tuple(_tolerance()) + tuple(_optimize()) + tuple(_support())
PICTURES = PICTURES + _part_pictures()
