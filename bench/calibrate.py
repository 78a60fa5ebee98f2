"""Deflectometric calibration over seeded simulated captures (rigcad.calibrate): recovered
misalignments against their tolerances, the corrected map's incidence error (p99 over the lit camera
pixels) next to the design map's on the same rig, the dome's slope recovery, and one calibration's
run time at the profile's camera resolution. Writes bench/results/calibrate.json.

    python bench/calibrate.py [--trials N] [--profile achutha2006] [--sweep-trials M] [--keep-sweep]

The sweep (``--sweep-trials``, per variant): run time against error as the phase steps (3, 4, 8) and
the spacer heights (two, three) vary, each a profile extending ``--profile``.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

# The BLAS on one thread, set before numpy loads it: the bench runs several processes on the
# machine's cores, where a BLAS's own threads spin waiting for a core and a process's CPU time counts
# that (one-off, seed 41 beside three other processes on 2 cores: 62.8 s with the BLAS's two threads,
# 41.8 s with one, the same fit). One thread's CPU time is the calibration's work, and bounds its
# wall time on the 2 free cores the target names.
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")
# and numpy's huge-page advice as `rigcad` sets it (bench/hugepages.py), run directly or by make
from rigcad.cli.main import process_defaults  # noqa: E402

process_defaults()

import numpy as np  # noqa: E402


def near_null(fit, count: int = 3) -> list:
    """The fit's least-determined parameter combinations: the correlation matrix's smallest
    eigenvalues, each with its eigenvector's largest components (parameter: weight)."""
    names = list(fit.names)
    free = [i for i in range(len(names)) if fit.standard_error[i] > 0]
    vals, vecs = np.linalg.eigh(fit.correlation[np.ix_(free, free)])
    out = []
    for j in range(count):
        order = np.argsort(-np.abs(vecs[:, j]))[:5]
        out.append({"eigenvalue": float(vals[j]),
                    "combination": {names[free[i]]: round(float(vecs[i, j]), 3) for i in order}})
    return out


def trial(optics, rig, seed: int, without_bias: bool = False, aligned: bool = False) -> dict:
    """One seeded trial (``aligned``: the rig as designed, no surface error on the dome; the screens
    still laid by hand as the seed draws them)."""
    from rigcad.calibrate import model as M, simulate as S
    from rigcad.calibrate.patterns import Sequence
    from rigcad.calibrate.run import calibrate, compare
    from rigcad.calibrate.upright import random_placement

    seq = Sequence.from_profile(rig.profile.calibration)
    plan = M.Plan.of(rig.profile)
    rng = np.random.default_rng(seed)
    theta = S.random_misalignment(rig, plan, rng)
    placement = random_placement(rig.profile, rng)
    surface = S.planted_surface(rig, rng)
    if aligned:
        theta[:len(M.RIG_NAMES)] = 0.0
        surface = None
    t0 = time.perf_counter()
    cam = M.Camera.of(rig)
    images = S.render(optics, rig, theta, surface, cam, seq, plan, rng, placement)
    t1 = time.perf_counter()
    c1 = time.process_time()
    frames = S.as_read(cam, images)
    result = calibrate(optics, rig, frames)
    t2 = time.perf_counter()
    cpu = time.process_time() - c1
    out = compare(optics, rig, result, theta, surface, placement)
    if without_bias:  # the same capture without removing the decoding's own bias (rigcad.calibrate.bias)
        plain = compare(optics, rig, calibrate(optics, rig, frames, bias=None), theta, surface, placement)
        out["without_bias_correction"] = {k: plain[k] for k in (
            "corrected_incidence_error_deg", "corrected_incidence_error_deg_by_source", "parameters_met",
            "fitted_model_incidence_error_deg", "recovered_slope_rms_mrad", "slope_difference_rms_mrad")}
    out["strong_correlations"] = result.fit.as_dict()["strong_correlations"]["pairs"]
    out["near_null_combinations"] = near_null(result.fit)
    out["outliers_dropped"] = {"fit": result.fit.outliers, "map_fit": result.map_fit.outliers}
    out["residual_slopes"] = result.slope_figures()
    out.update(seed=seed, render_s=t1 - t0, calibration_s=t2 - t1, calibration_cpu_s=cpu, stages_s=result.timings_s,
               fit_rms_residual_mm=result.fit.rms_residual_mm,
               fit_direct_view={"residuals": result.fit.direct_residuals, "weight": result.fit.direct_weight,
                                "rms_residual_mm": result.fit.direct_rms_residual_mm})
    return out


#: The sweep's variants: name -> the profile keys they change (YAML under ``extends``).
VARIANTS = {"steps3": "calibration:\n  phase_steps: 3\n", "steps4": "calibration:\n  phase_steps: 4\n",
            "steps8": "calibration:\n  phase_steps: 8\n",
            "heights_2_10mm": "calibration:\n  spacer_heights: [2 mm, 10 mm]\n",
            "heights_1_20mm": "calibration:\n  spacer_heights: [1 mm, 20 mm]\n",
            "heights_1_30mm": "calibration:\n  spacer_heights: [1 mm, 30 mm]\n",
            "heights_1_10_20mm": "calibration:\n  spacer_heights: [1 mm, 10 mm, 20 mm]\n",
            # the grazing rays (docs/calibrate-notes.md, "Why the all-lit p99 stayed above"): a coarse period
            # whose phase needs only 3 Gray bits survives long footprints; a thin panel's emitting
            # surface 1 mm up (not the tablet's 6 mm) reaches the rays that pass under the tablet
            "periods_1024_128_16": "calibration:\n  periods: [1024, 128, 16]\n  gray_bits: 3\n",
            "thin_1mm": "calibration:\n  screen_thickness: 1 mm\n",
            "thin_1mm_periods_1024_128_16": "calibration:\n  screen_thickness: 1 mm\n  periods: [1024, 128, 16]\n  gray_bits: 3\n",
            # the frame (docs/calibrate-notes.md, "What fixes the frame"): without the half turn, the
            # screen's wedge sets it; a screen that settles less repeatably, or more (on three pads);
            # one flatter on its spacer (planted and assumed alike)
            "half_turn_none": "calibration:\n  half_turn: none\n",
            "half_turn_highest": "calibration:\n  half_turn: highest\n",
            "screen_seating_0.05deg": "calibration:\n  screen_seating: 0.05 deg\n",
            "screen_seating_0.02deg": "calibration:\n  screen_seating: 0.02 deg\n",
            "screen_seating_0.01deg": "calibration:\n  screen_seating: 0.01 deg\n",
            "screen_seating_0.005deg": "calibration:\n  screen_seating: 0.005 deg\n",
            "screen_tilt_0.02deg": "calibration:\n  screen_tilt: 0.02 deg\n",
            # what the mirrors' loss costs: the capture as the simulation rendered it before
            # coating.reflectance (both views at the screen's full light)
            "mirrors_lossless": "coating:\n  reflectance: 1\n",
            # the upright display (rigcad.calibrate.upright): without it (the earlier capture); three
            # turns rather than four; its active area starting at the sample plane, not 1 mm under it
            "upright_none": "calibration:\n  upright_turns: 0\n",
            "upright_turns_3": "calibration:\n  upright_turns: 3\n",
            "upright_depth_0": "calibration:\n  upright_depth: 0 mm\n"}


def sweep(base: str, trials: int, names: list[str] | None = None) -> dict:
    """One row per variant (``names``, all by default): median corrected p99, CPU seconds of the
    calibration."""
    from rigcad.check.scene import analytic_optics

    out = {}
    for name in VARIANTS:
        if names and name not in names:
            continue
        rig = variant_rig(base, name)
        optics = analytic_optics(rig)
        rows = [trial(optics, rig, 1000 + seed) for seed in range(trials)]
        out[name] = {"trials": trials,
                     "corrected_p99_deg": float(np.median([r["corrected_incidence_error_deg"]["p99"] for r in rows])),
                     "corrected_p50_deg": float(np.median([r["corrected_incidence_error_deg"]["p50"] for r in rows])),
                     "measured_pixels_p99_deg": float(np.median(
                         [r["corrected_incidence_error_deg_by_source"]["measured"]["p99"] for r in rows])),
                     "parameters_met": float(np.median([r["parameters_met"] for r in rows])),
                     "parameters_total": rows[0]["parameters_total"],
                     "unmeasured_causes_fraction_of_lit": cause_medians(rows),
                     "calibration_cpu_s": float(np.median([r["calibration_cpu_s"] for r in rows])),
                     "render_s": float(np.median([r["render_s"] for r in rows])),
                     **seat_figures(rows)}
        print(name, out[name], flush=True)
    return out


def seat_figures(rows: list) -> dict:
    """What the screen's seat moves, as medians over a variant's trials: the frame's tilt against the
    truth (deg), the paraboloid's and the camera's placements against the dome within target (of
    10), and the measured pixels' error within one and two stated uncertainties (shares)."""
    cover = [r["uncertainty_coverage"]["measured"] for r in rows]
    return {"frame_tilt_deg": float(np.median([r["frame"]["tilt_deg"] for r in rows])),
            "dome_frame_parameters_met": float(np.median([r["dome_frame"]["parameters_met"] for r in rows])),
            "dome_frame_parameters_total": rows[0]["dome_frame"]["parameters_total"],
            "measured_within_1": float(np.median([c["within_1"] for c in cover])),
            "measured_within_2": float(np.median([c["within_2"] for c in cover]))}


def variant_rig(base: str, name: str):
    """The rig of profile ``base`` with the variant ``name``'s keys (:data:`VARIANTS`) over it."""
    import tempfile

    from rigcad.profile.schema import load_profile
    from rigcad.rig import Rig

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{name}.yaml"
        path.write_text(f"extends: {base}\n{VARIANTS[name]}")
        return Rig.from_profile(load_profile(path))


def cause_medians(trials: list) -> dict:
    """Per cause (rigcad.calibrate.maps.CAUSES), the median over ``trials`` of its share of the lit pixels."""
    names = trials[0]["unmeasured_causes"]
    return {n: float(np.median([t["unmeasured_causes"][n]["fraction_of_lit"] for t in trials])) for n in names}


def coverage_medians(trials: list) -> dict:
    """Per map source, the median over ``trials`` of how the stated uncertainty covers the error
    (rigcad.calibrate.run.compare's ``uncertainty_coverage``; trials without such pixels left out)."""
    if "uncertainty_coverage" not in trials[0]:
        return {}
    out = {}
    for source in trials[0]["uncertainty_coverage"]:
        rows = [t["uncertainty_coverage"][source] for t in trials if "within_1" in t["uncertainty_coverage"][source]]
        if rows:
            out[source] = {k: float(np.median([r[k] for r in rows])) for k in rows[0] if k != "pixels"}
            out[source]["trials"] = len(rows)
    return out


def coverage_pooled(trials: list) -> dict:
    """Per map source, the share of every trial's pixels (pooled) within one and two stated
    uncertainties of the truth, and the range over the trials of the share within one."""
    out = {}
    for source in trials[0].get("uncertainty_coverage", {}):
        rows = [t["uncertainty_coverage"][source] for t in trials if "within_1" in t["uncertainty_coverage"][source]]
        if rows:
            n = sum(r["pixels"] for r in rows)
            out[source] = {"pixels": n, "trials": len(rows),
                           "within_1": sum(r["within_1"] * r["pixels"] for r in rows) / n,
                           "within_2": sum(r["within_2"] * r["pixels"] for r in rows) / n,
                           "within_1_range_over_trials": [min(r["within_1"] for r in rows),
                                                          max(r["within_1"] for r in rows)]}
    return out


def aligned_summary(rows: list) -> dict:
    """The trials on an aligned rig (:func:`trial` with ``aligned``): per trial, the corrected map's
    and the design map's p99 (deg) over the lit pixels, and what the report shows on a rig with
    nothing to find: residuals dropped as outliers, strong correlations listed, residual slopes."""
    keep = ("seed", "corrected_incidence_error_deg", "design_incidence_error_deg", "fitted_model_incidence_error_deg",
            "corrected_incidence_error_deg_by_source", "uncertainty_coverage", "frame", "outliers_dropped",
            "residual_slopes", "strong_correlations", "parameters_met", "parameters_total", "dome_frame")
    trials = [{k: t[k] for k in keep if k in t} for t in rows]
    return {"about": "the rig as designed, no surface error on the dome, the screens laid by hand as each seed draws",
            "trials": len(trials),
            "corrected_not_worse_than_design": int(sum(t["corrected_incidence_error_deg"]["p99"]
                                                       <= t["design_incidence_error_deg"]["p99"] for t in trials)),
            "uncertainty_coverage_pooled": coverage_pooled(trials), "per_trial": trials}


def merged(profile: str, runs: list[dict], sweep_rows: dict | None) -> dict:
    """One summary from runs over disjoint seeds (``--first-seed``), their trials in seed order, with
    ``sweep_rows`` (the sweep kept from the file merged into)."""
    trials = sorted((t for run in runs for t in run["per_trial"]), key=lambda t: t["seed"])
    seeds = [t["seed"] for t in trials]
    if len(set(seeds)) != len(seeds):
        raise SystemExit(f"--merge: seeds run twice: {sorted({s for s in seeds if seeds.count(s) > 1})}")
    if {run["profile"] for run in runs} != {profile}:
        raise SystemExit(f"--merge: runs of profiles {sorted({run['profile'] for run in runs})}, not {profile}")
    summary = summarize(profile, runs[0]["camera_resolution_px"], trials)
    aligned = [t for run in runs for t in run.get("aligned_rig", {}).get("per_trial", [])]
    if aligned:
        summary["aligned_rig"] = aligned_summary(sorted(aligned, key=lambda t: t["seed"]))
    if sweep_rows:
        summary["sweep_phase_steps_and_heights"] = sweep_rows
    return summary


def summarize(profile: str, resolution, trials: list) -> dict:
    """The trials' figures against the targets, and the trials themselves."""
    p99c = [t["corrected_incidence_error_deg"]["p99"] for t in trials]
    measured = [t["corrected_incidence_error_deg_by_source"]["measured"]["p99"] for t in trials]
    met = [t["parameters_met"] for t in trials]
    ratio = [t["recovered_slope_rms_mrad"] / t["planted_slope_rms_mrad"] for t in trials]
    summary = {
        "profile": profile, "trials": len(trials), "camera_resolution_px": list(resolution),
        "targets": {"parameter_error": "<= max(10 % of tolerance, 0.02 mm / 0.01 deg)",
                    "corrected_incidence_error_p99_deg": 0.05, "slope_rms_recovery": "within 20 % or 0.1 mrad",
                    "calibration_time_s": 60},
        "parameters_within_target_fraction": float(np.mean([t["parameters_met"] / t["parameters_total"]
                                                            for t in trials])),
        "corrected_incidence_error_p99_deg_worst": float(max(p99c)),
        "corrected_incidence_error_p99_deg_median": float(np.median(p99c)),
        "corrected_incidence_error_p99_deg_median_measured_pixels": float(np.median(
            [t["corrected_incidence_error_deg_by_source"]["measured"]["p99"] for t in trials])),
        "corrected_incidence_error_p99_deg_range_measured_pixels": [float(f(measured)) for f in (np.min, np.max)],
        "trials_with_measured_pixels_p99_within_target": int(np.sum(np.array(measured) <= 0.05)),
        "measured_fraction_of_lit_median": float(np.median(
            [t["corrected_incidence_error_deg_by_source"]["measured"]["pixels"] / t["lit_pixels"] for t in trials])),
        "parameters_met_range": [int(min(met)), int(max(met))],
        "unmeasured_causes_fraction_of_lit_median": cause_medians(trials),
        "uncertainty_coverage_median": coverage_medians(trials),
        "uncertainty_coverage_pooled": coverage_pooled(trials),
        "frame_tilt_deg_range": [float(f([t["frame"]["tilt_deg"] for t in trials])) for f in (np.min, np.median, np.max)],
        "measured_pixels_p99_deg_without_the_frame_tilt_range": [
            float(f([t["frame"]["measured_error_without_it_deg"]["p99"] for t in trials])) for f in (np.min, np.median, np.max)],
        "parameter_met_fraction": {n: float(np.mean([t["parameters"][n]["met"] for t in trials]))
                                   for n in trials[0]["parameters"]},
        **dome_frame_summary(trials),
        "slope_rms_ratio_range": [float(f(ratio)) for f in (np.min, np.max)],
        "design_incidence_error_p99_deg_median": float(np.median([t["design_incidence_error_deg"]["p99"]
                                                                  for t in trials])),
        "calibration_s_median": float(np.median([t["calibration_s"] for t in trials])),
        "calibration_cpu_s_median": float(np.median([t["calibration_cpu_s"] for t in trials])),
        "machine_note": "shared 2-core machine under load from other jobs: wall times are upper bounds; the "
                        "CPU time of this process, its BLAS on one thread, is the comparable figure",
        "per_trial": trials,
    }
    return summary


def dome_frame_summary(trials: list) -> dict:
    """The paraboloid's and the camera's placement against the dome (rigcad.calibrate.run.compare's
    ``dome_frame``): per parameter, the share of the trials within target, and how many trials had
    them all within target."""
    rows = [t["dome_frame"] for t in trials]
    return {"dome_frame_parameter_met_fraction": {n: float(np.mean([r["parameters"][n]["met"] for r in rows]))
                                                  for n in rows[0]["parameters"]},
            "dome_frame_trials_with_every_parameter_met": int(sum(r["parameters_met"] == r["parameters_total"]
                                                                   for r in rows))}


#: The sweep's rows as docs/calibrate-notes.md names them, in its order.
VARIANT_LABELS = {"steps3": "3 phase steps", "steps4": "4 phase steps (the default)", "steps8": "8 phase steps",
                  "heights_2_10mm": "spacers 2, 10 mm (the earlier default)",
                  "heights_1_20mm": "spacers 1, 20 mm (the default)", "heights_1_30mm": "spacers 1, 30 mm",
                  "heights_1_10_20mm": "spacers 1, 10, 20 mm",
                  "periods_1024_128_16": "periods 1024, 128, 16 px (3 Gray bits)",
                  "thin_1mm": "a 1 mm thin panel (surface 1 mm up, not 6)",
                  "thin_1mm_periods_1024_128_16": "the 1 mm panel, periods 1024, 128, 16 px",
                  "half_turn_none": "no half turn (the earlier capture)",
                  "half_turn_highest": "a half turn at the highest spacer only (3 captures)",
                  "screen_seating_0.05deg": "the screen settling to 0.05 deg, not 0.02",
                  "screen_seating_0.02deg": "the screen settling to 0.02 deg (the default)",
                  "screen_seating_0.01deg": "the screen settling to 0.01 deg",
                  "screen_seating_0.005deg": "the screen settling to 0.005 deg (a three-point seat)",
                  "screen_tilt_0.02deg": "the screen flat on its spacers to 0.02 deg, not 0.2",
                  "mirrors_lossless": "mirrors that lose no light (reflectance 1, not 0.6)",
                  "upright_none": "no upright display (the earlier capture)",
                  "upright_turns_3": "the upright display at 3 turns, not 4",
                  "upright_depth_0": "its active area from the sample plane, not 1 mm under it"}


def _spread(values, digits: int) -> str:
    """'min-max; median' of ``values``, to ``digits`` decimals."""
    lo, hi, mid = (f"{float(f(values)):.{digits}f}" for f in (np.min, np.max, np.median))
    return f"{lo}-{hi}; {mid}"


def tables(summary: dict) -> str:
    """The bench's tables in Markdown, as docs/calibrate.md shows them (tests/test_docs.py holds the
    page to this rendering of bench/results/calibrate.json)."""
    trials = summary["per_trial"]
    source = [t["corrected_incidence_error_deg_by_source"]["measured"] for t in trials]
    measured = [s["p99"] for s in source]
    lit = [t["corrected_incidence_error_deg"]["p99"] for t in trials]
    met = [t["parameters_met"] for t in trials]
    total = trials[0]["parameters_total"]
    ratio = [t["recovered_slope_rms_mrad"] / t["planted_slope_rms_mrad"] for t in trials]
    n, target = len(trials), summary["targets"]["corrected_incidence_error_p99_deg"]
    def verdict(values):
        k = int(np.sum(np.array(values) <= target))
        return f"{target} deg: **{'met' if k == n else 'not met'}** ({k} of {n})"
    cpu = [t["calibration_cpu_s"] for t in trials]
    rows = [
        "| figure (range over the trials; median) | value | target |", "|---|---|---|",
        f"| corrected map p99, measured pixels ({100 * summary['measured_fraction_of_lit_median']:.0f} % of lit) "
        f"| {_spread(measured, 3)} deg | {verdict(measured)} |",
        f"| corrected map p99, all lit pixels | {_spread(lit, 3)} deg | {verdict(lit)} |",
        f"| corrected map p50, measured pixels | {_spread([s['p50'] for s in source], 3)} deg | |",
        f"| the frame's tilt (the fit's against the truth's; only the priors fix it) | "
        f"{_spread([t['frame']['tilt_deg'] for t in trials], 3)} deg | |",
        f"| corrected map p99, measured pixels, that tilt removed | "
        f"{_spread([t['frame']['measured_error_without_it_deg']['p99'] for t in trials], 3)} deg | |",
        f"| design (uncorrected) map p99, same rigs | {_spread([t['design_incidence_error_deg']['p99'] for t in trials], 1)}"
        " deg | |",
        *aligned_rows(summary),
        f"| parameters within max(10 % tol, 0.02 mm / 0.01 deg) | {min(met)}-{max(met)} of {total}; "
        f"{np.median(met):.0f} ({100 * summary['parameters_within_target_fraction']:.0f} %) | all: **"
        f"{'met' if min(met) == total else 'not met'}** ({sum(m == total for m in met)} of {n}) |",
        *dome_frame_rows(trials),
        *upright_rows(trials),
        f"| slope RMS recovered / planted ({np.median([t['planted_slope_rms_mrad'] for t in trials]):.2f} mrad) "
        f"| {min(ratio):.3f}-{max(ratio):.3f} | within 20 %: **{'met' if max(abs(r - 1) for r in ratio) <= 0.2 else 'not met'}** |",
        f"| slope difference RMS, pointwise | {_spread([t['slope_difference_rms_mrad'] for t in trials], 2)} mrad | |",
        f"| calibration CPU, one-off bench figure | {_spread(cpu, 1)} s | {summary['targets']['calibration_time_s']} s: "
        f"**{'met' if max(cpu) <= summary['targets']['calibration_time_s'] else 'not met'}** (CPU) |",
    ]
    rows += causes_table(summary) + coverage_table(summary) + standard_error_table(summary)
    return "\n".join(rows) + "\n"


def sweep_table(summary: dict) -> str:
    """The sweep's rows in Markdown (``sweep_phase_steps_and_heights``), as docs/calibrate-notes.md
    records them; empty without a sweep."""
    sweep_rows = summary.get("sweep_phase_steps_and_heights", {})
    if not sweep_rows:
        return ""
    k = next(iter(sweep_rows.values()))["trials"]
    rows = [f"Sweep, {k} trial{'s' if k > 1 else ''} a variant (seed{'s' if k > 1 else ''} 1000"
            f"{f'-{999 + k}' if k > 1 else ''}; p99 and p50 in deg; CPU one-off):", "",
            "| variant | p99 all lit | p99 measured | measured % of lit | p50 all lit | parameters within target "
            "| CPU s |", "|---|---|---|---|---|---|---|"]
    for name, label in VARIANT_LABELS.items():
        if name in sweep_rows:
            r = sweep_rows[name]
            measured = r["unmeasured_causes_fraction_of_lit"]["measured"]
            rows.append(f"| {label} | {r['corrected_p99_deg']:.3f} | {r['measured_pixels_p99_deg']:.3f} | "
                        f"{100 * measured:.0f} | {r['corrected_p50_deg']:.3f} | {r['parameters_met']:.0f} of "
                        f"{r['parameters_total']} | {r['calibration_cpu_s']:.1f} |")
    return "\n".join(rows) + "\n"


#: The seating sweep's variants (``--sweep-only --variants ...`` into
#: bench/results/calibrate_seating_sweep.json), in the order :func:`seating_table` shows them.
SEATING_VARIANTS = ("screen_seating_0.05deg", "screen_seating_0.02deg", "screen_seating_0.01deg",
                    "screen_seating_0.005deg")


def seating_table(summary: dict) -> str:
    """The seating sweep's rows in Markdown (:data:`SEATING_VARIANTS` that ran), as
    docs/calibrate.md shows them (tests/calibrate/test_seating_sweep.py holds the page to it)."""
    rows_in = summary.get("sweep_phase_steps_and_heights", {})
    ran = [n for n in SEATING_VARIANTS if n in rows_in and "frame_tilt_deg" in rows_in[n]]
    if not ran:
        return ""
    k = {rows_in[n]["trials"] for n in ran}
    seeds = "1000" if k == {1} else f"1000-{999 + max(k)}"
    rows = [f"| seating ({'/'.join(str(n) for n in sorted(k))} trials, seeds {seeds}; medians) | the frame's tilt against the truth | parameters within target | against the dome "
            "within target | measured pixels within 1; 2 uncertainties | p99 measured |", "|---|---|---|---|---|---|"]
    for name in ran:
        r = rows_in[name]
        rows.append(f"| {VARIANT_LABELS[name].removeprefix('the screen settling to ')} | {r['frame_tilt_deg']:.4f} deg | "
                    f"{r['parameters_met']:.0f} of {r['parameters_total']} | {r['dome_frame_parameters_met']:.0f} of "
                    f"{r['dome_frame_parameters_total']} | {100 * r['measured_within_1']:.0f} %; "
                    f"{100 * r['measured_within_2']:.0f} % | {r['measured_pixels_p99_deg']:.3f} deg |")
    return "\n".join(rows) + "\n"


def aligned_rows(summary: dict) -> list[str]:
    """The summary table's rows on the aligned rig (:func:`aligned_summary`; none without it)."""
    a = summary.get("aligned_rig")
    if not a:
        return []
    rows, n = a["per_trial"], a["trials"]
    c = [t["corrected_incidence_error_deg"]["p99"] for t in rows]
    d = [t["design_incidence_error_deg"]["p99"] for t in rows]
    out = [t["outliers_dropped"]["fit"] + t["outliers_dropped"]["map_fit"] for t in rows]
    worst = [t["residual_slopes"]["residual_slope_worst_mrad"] for t in rows]
    return [f"| an aligned rig, no surface error ({n} trials): corrected map p99, all lit pixels; the design map's | "
            f"{_spread(c, 4)}; {_spread(d, 4)} deg | not worse than the design: **"
            f"{'met' if a['corrected_not_worse_than_design'] == n else 'not met'}** ({a['corrected_not_worse_than_design']} of {n}) |",
            f"| the same: residuals dropped as outliers (both fits); correlations listed; worst residual slope | "
            f"{min(out)}-{max(out)}; {min(len(t['strong_correlations']) for t in rows)}-"
            f"{max(len(t['strong_correlations']) for t in rows)}; {_spread(worst, 2)} mrad | |"]


def upright_rows(trials: list) -> list[str]:
    """The summary table's row on the upright display's placements (none without it)."""
    placed = [t["upright_placement"] for t in trials if "upright_placement" in t]
    if not placed:
        return []
    mm = [1e3 * max(p[k] for k in ("dz_mm", "du_mm", "dv_mm")) for p in placed]
    rad = [1e3 * max(p[k] for k in ("tilt_x_rad", "tilt_y_rad", "turn_rad")) for p in placed]
    every = sum(p["captures_placed"] == p["captures"] for p in placed)
    return [f"| the upright display's placements, the largest error over a trial's captures: offsets; tilts and "
            f"turn | {_spread(mm, 1)} um; {_spread(rad, 3)} mrad | (every capture placed in {every} of "
            f"{len(placed)}) |"]


def dome_frame_rows(trials: list) -> list[str]:
    """The summary table's rows on the paraboloid and the camera against the dome, and on the dome's
    tilts (the frame's share)."""
    met = [t["dome_frame"]["parameters_met"] for t in trials]
    total, n = trials[0]["dome_frame"]["parameters_total"], len(trials)
    tilts = [all(t["parameters"][f"dome_tilt_{a}_rad"]["met"] for a in "xy") for t in trials]
    return [f"| the same, the paraboloid and the camera against the dome (what the images fix) | {min(met)}-{max(met)} "
            f"of {total}; {np.median(met):.0f} | all: **{'met' if min(met) == total else 'not met'}** "
            f"({sum(m == total for m in met)} of {n}) |",
            f"| the same, the dome's tilts (the rig's tilt over the sample plane: the frame, the priors' part) | "
            f"both within target in {sum(tilts)} of {n} | |"]


#: The parameters' groups as the standard-error table names them: label -> (the name's start, its
#: end); the gauge (rigcad.calibrate.model.GAUGE), which is not fitted, is left out.
PARAMETER_GROUPS = {"the rig's tilts": ("", "_tilt_"), "the rig's lateral offsets": ("", ("_dx_mm", "_dy_mm")),
                    "the rig's heights": ("", "_dz_mm"), "the screens' heights": ("screen", "_dz_mm"),
                    "the screens' tilts": ("screen", "_tilt_"), "the screens' centres": ("screen", ("_du_mm", "_dv_mm")),
                    "the screens' turns": ("screen", "_turn_rad")}


def _in_group(name: str, group: tuple) -> bool:
    start, part = group
    parts = (part,) if isinstance(part, str) else part
    return name.startswith(start) and (start or not name.startswith("screen")) and any(q in name for q in parts)


def standard_error_table(summary: dict) -> list[str]:
    """How the fit's standard errors hold its errors against the truth, per group of parameters:
    the median over the trials and the group's parameters of |error| / standard error, and the share
    within two (a Gaussian: 0.67 and 95 %). From the run of the code that states them now
    (``standard_errors``, :func:`standard_errors_run`) when the summary carries one, else from its
    own trials."""
    from rigcad.calibrate.model import GAUGE

    run = summary.get("standard_errors")
    trials = run["per_trial"] if run else summary["per_trial"]
    where = (f"{len(trials)} trials, seeds {', '.join(str(t['seed']) for t in trials)}, on the code that states "
             f"them now: {run['source']}" if run else "over the trials")
    rows = ["", f"How the fit's standard errors hold its errors against the truth ({where}; each group's "
                "parameters pooled; the first screen's height and centre are the gauge, not fitted):", "",
            "| parameters | error / standard error, p50 | within 1 standard error | within 2 |", "|---|---|---|---|"]
    for label, group in PARAMETER_GROUPS.items():
        z = np.array([p["error_over_standard_error"] for t in trials for n, p in t["parameters"].items()
                      if _in_group(n, group) and n not in GAUGE])
        rows.append(f"| {label} | {np.median(z):.2f} | {100 * np.mean(z <= 1):.0f} % | {100 * np.mean(z <= 2):.0f} % |")
    z = np.array([p["error_over_standard_error"] for t in trials for p in t["dome_frame"]["parameters"].values()])
    rows.append(f"| the paraboloid and the camera against the dome | {np.median(z):.2f} | {100 * np.mean(z <= 1):.0f} % | "
                f"{100 * np.mean(z <= 2):.0f} % |")
    rows.append("| calibrated (a Gaussian error) | 0.67 | 68 % | 95 % |")
    return rows


def standard_errors_run(path: Path) -> dict:
    """What :func:`standard_error_table` reads of a bench run (``--standard-errors``): per trial,
    its seed and each parameter's error over its standard error, in the sample frame and against
    the dome."""
    run = json.loads(path.read_text(encoding="utf-8"))
    keep = lambda params: {n: {"error_over_standard_error": p["error_over_standard_error"]}  # noqa: E731
                           for n, p in params.items()}
    return {"source": f"bench/results/{path.name}",
            "per_trial": [{"seed": t["seed"], "parameters": keep(t["parameters"]),
                           "dome_frame": {"parameters": keep(t["dome_frame"]["parameters"])}}
                          for t in run["per_trial"]]}


#: The map's sources as the coverage table names them.
SOURCE_LABELS = {"measured": "measured", "filled": "filled from neighbours", "model_only": "the fitted model alone"}


def coverage_table(summary: dict) -> list[str]:
    """How the corrected map's stated uncertainty covers its error against the truth, per source:
    pooled over every trial's pixels, with the range over the trials of the share within one, next
    to the target and to what a calibrated round Gaussian error gives."""
    cov = summary.get("uncertainty_coverage_pooled", {})
    if not cov:
        return []
    rows = ["", "How the stated uncertainty (`uncertainty_rad`, an RMS angle) covers the error against the truth "
                "(every trial's pixels pooled; the frame's tilt is one draw a trial, so one trial's share moves "
                "with it):", "",
            "| map source | pixels (trials) | error within 1 uncertainty | its range over the trials | within 2 |",
            "|---|---|---|---|---|"]
    for source, label in SOURCE_LABELS.items():
        if source in cov:
            c = cov[source]
            lo, hi = c["within_1_range_over_trials"]
            rows.append(f"| {label} | {c['pixels']:,} ({c['trials']}) | {100 * c['within_1']:.0f} % | "
                        f"{100 * lo:.0f}-{100 * hi:.0f} % | {100 * c['within_2']:.0f} % |")
    a = summary.get("aligned_rig", {}).get("uncertainty_coverage_pooled", {}).get("measured")
    if a:
        lo, hi = a["within_1_range_over_trials"]
        rows.append(f"| measured, on the aligned rig | {a['pixels']:,} ({a['trials']}) | {100 * a['within_1']:.0f} % | "
                    f"{100 * lo:.0f}-{100 * hi:.0f} % | {100 * a['within_2']:.0f} % |")
    rows.append("| target (measured pixels) | | 60-76 % | | at least 93 % |")
    rows.append("| calibrated (a round Gaussian error) | | 63 % | | 98 % |")
    return rows


#: The causes' column heads (rigcad.calibrate.maps.CAUSES but "measured").
CAUSE_HEADS = {"under_the_screens": "under the screens", "dark_in_every_capture": "dark in every capture",
               "lit_not_decoded": "lit, not decoded", "within_the_edge_rule": "within the edge rule",
               "next_to_unmeasured": "next to unmeasured"}


def causes_table(summary: dict) -> list[str]:
    """Why lit pixels are not measured: each cause's median share of the lit pixels (%), for the
    trials and each sweep variant, and the trials' incidence error p99 per cause."""
    trials = summary["per_trial"]
    if "unmeasured_causes" not in trials[0]:
        return []
    heads = list(CAUSE_HEADS)
    pct = lambda shares: " | ".join(f"{100 * shares[c]:.1f}" for c in heads)  # noqa: E731
    p99 = [np.median([t["unmeasured_causes"][c]["p99"] for t in trials if "p99" in t["unmeasured_causes"][c]])
           if any("p99" in t["unmeasured_causes"][c] for t in trials) else np.nan for c in heads]
    rows = ["", "Why lit pixels are not measured (rigcad.calibrate.maps.CAUSES; each pixel under the first cause "
                "that applies; median % of the lit pixels):", "",
            "| capture | measured | " + " | ".join(CAUSE_HEADS[c] for c in heads) + " |",
            "|---" * (len(heads) + 2) + "|",
            f"| the default, {len(trials)} trial{'s' if len(trials) > 1 else ''} | {100 * summary['unmeasured_causes_fraction_of_lit_median']['measured']:.1f}"
            f" | {pct(summary['unmeasured_causes_fraction_of_lit_median'])} |",
            "| its incidence error p99 (deg, median) | | "
            + " | ".join("" if np.isnan(v) else f"{v:.3f}" for v in p99) + " |"]
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--trials", type=int, default=50, help="seeded trials (50 for the targets; fewer on a shared CPU)")
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--sweep-trials", type=int, default=1, help="trials per sweep variant (0: no sweep)")
    ap.add_argument("--without-bias", action="store_true",
                    help="also calibrate each capture without the decoding's bias correction (twice the time)")
    ap.add_argument("--sweep-only", action="store_true",
                    help="re-run only the sweep into the existing --out file (its trials kept)")
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS),
                    help="with --sweep-only: re-run only these variants, keeping the file's other rows")
    ap.add_argument("--keep-sweep", action="store_true",
                    help="re-run only the trials, keeping the existing --out file's sweep")
    ap.add_argument("--first-seed", type=int, default=0,
                    help="the trials' seeds start here (to split a run over processes; merge with --merge)")
    ap.add_argument("--merge", nargs="+", metavar="JSON",
                    help="write --out from these runs' trials (in seed order) and --out's sweep if it has one, "
                         "then stop")
    ap.add_argument("--variant", choices=list(VARIANTS),
                    help="run the trials on this sweep variant of --profile (e.g. a seat that settles better), "
                         "into --out, without a sweep")
    ap.add_argument("--aligned", type=int, default=0, metavar="K",
                    help="also K trials (seeds --first-seed on) on the rig as designed, with no surface error")
    ap.add_argument("--standard-errors", metavar="JSON", type=Path,
                    help="take the standard errors' table from this run (of the code that states them now: "
                         "bench/results/calibrate_standard_errors.json) into --out, then stop")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "calibrate.json"))
    args = ap.parse_args()
    from rigcad.check.scene import analytic_optics
    from rigcad.export.atomic import write_json
    from rigcad.rig import load

    name = f"{args.profile} + {args.variant}" if args.variant else args.profile
    if args.standard_errors:
        summary = json.loads(Path(args.out).read_text(encoding="utf-8"))
        summary["standard_errors"] = standard_errors_run(args.standard_errors)
        write_json(Path(args.out), summary)
        print(tables(summary))
        return 0
    if args.merge:
        out = Path(args.out)
        kept = json.loads(out.read_text(encoding="utf-8")).get("sweep_phase_steps_and_heights") \
            if out.is_file() else None  # a new --out: no sweep to keep
        summary = merged(name, [json.loads(Path(f).read_text(encoding="utf-8")) for f in args.merge], kept)
        write_json(Path(args.out), summary)
        print(tables(summary))
        return 0
    if args.sweep_only:
        out = Path(args.out)  # a new --out: a sweep of its own (the seating's: bench/results/calibrate_seating_sweep.json)
        summary = json.loads(out.read_text(encoding="utf-8")) if out.is_file() else {"profile": args.profile}
        rows = summary.get("sweep_phase_steps_and_heights", {}) if args.variants else {}
        rows.update(sweep(args.profile, args.sweep_trials, args.variants))
        summary["sweep_phase_steps_and_heights"] = {n: rows[n] for n in VARIANTS if n in rows}
        write_json(Path(args.out), summary)
        print(tables(summary) if "per_trial" in summary else seating_table(summary))
        return 0
    rig = variant_rig(args.profile, args.variant) if args.variant else load(args.profile)
    optics = analytic_optics(rig)
    kept = json.loads(Path(args.out).read_text(encoding="utf-8")).get("sweep_phase_steps_and_heights") \
        if args.keep_sweep else None
    trials = []
    for seed in range(args.first_seed, args.first_seed + args.trials):
        trials.append(trial(optics, rig, seed, args.without_bias))
        t = trials[-1]
        print(f"trial {seed}: {t['parameters_met']}/{t['parameters_total']} parameters within target; "
              f"corrected p99 {t['corrected_incidence_error_deg']['p99']:.3f} deg (measured pixels "
              f"{t['corrected_incidence_error_deg_by_source']['measured']['p99']:.3f}) vs design "
              f"{t['design_incidence_error_deg']['p99']:.3f} deg; slopes {t['recovered_slope_rms_mrad']:.3f} vs "
              f"planted {t['planted_slope_rms_mrad']:.3f} mrad; {t['calibration_s']:.1f} s", flush=True)
        # written after every trial: a run stopped early keeps what it measured
        summary = summarize(name, rig.profile.camera.resolution, trials)
        if kept:
            summary["sweep_phase_steps_and_heights"] = kept
        write_json(Path(args.out), summary)
    if args.aligned:
        if not trials:
            summary = {"profile": name, "per_trial": []}
        rows = []
        for seed in range(args.first_seed, args.first_seed + args.aligned):
            rows.append(trial(optics, rig, seed, aligned=True))
            t = rows[-1]
            print(f"aligned {seed}: corrected p99 {t['corrected_incidence_error_deg']['p99']:.4f} deg vs design "
                  f"{t['design_incidence_error_deg']['p99']:.4f}; outliers {t['outliers_dropped']}; "
                  f"{len(t['strong_correlations'])} correlations listed", flush=True)
            summary["aligned_rig"] = aligned_summary(rows)
            write_json(Path(args.out), summary)
    if args.sweep_trials and not args.keep_sweep and not args.variant:
        summary["sweep_phase_steps_and_heights"] = sweep(args.profile, args.sweep_trials)
    write_json(Path(args.out), summary)
    print(json.dumps({k: v for k, v in summary.items() if k != "per_trial"}, indent=1))
    print(tables(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
