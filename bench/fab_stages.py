"""Benchmark of the fabrication stage: time per stage and per slicer run, staircase figures per
printer and orientation, the dome's split; and the estimate model (rigcad.fab.estimate) against
PrusaSlicer on every piece of the MK3S. Writes bench/results/fab_stages.json (not a test: no timed
assertions).

    .venv/bin/python bench/fab_stages.py [--gcode] [--printers vantage_i prusa_mk3s form3]
    .venv/bin/python bench/fab_stages.py --estimates [--from-report exports/achutha2006/fab/prusa_mk3s/fab.json] [--fit]

``--estimates`` slices every piece on the MK3S (~5 min on 2 cores; or reads a fab.json written
with --gcode) and prints, per piece, rigcad's estimate against PrusaSlicer's time and filament;
``--fit`` refits the model's coefficients to those figures (NNLS) and prints them for
rigcad/fab/estimate.py, with each piece's error when its part (all its pieces) is left out of the fit.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from rigcad.export.atomic import write_json
from rigcad.fab import estimate as E
from rigcad.fab.printers import load_printer
from rigcad.fab.stage import run_fab
from rigcad.profile import load_profile
from rigcad.rig import Rig


def _stages(args, rig, profile) -> dict:
    out: dict = {"profile": profile.name, "printers": {}}
    for name in args.printers:
        printer = load_printer(name)
        with tempfile.TemporaryDirectory() as tmp:
            t = time.perf_counter()
            res = run_fab(rig, printer, Path(tmp), gcode=args.gcode)
            total = time.perf_counter() - t
        rows = {}
        for part, e in res.report["parts"].items():
            if "error" in e:
                rows[part] = {"error": e["error"]}
                continue
            if "pieces" not in e:
                continue
            rows[part] = {"split": e["split"], "sanding_stock": e.get("sanding_stock"), "pieces": [
                {"name": pc["name"], "orientation": pc["orientation"], "layers": pc["layers"],
                 "candidates": {c["orientation"]: {"fits": c["fits"],
                                                   **({"cusp_mean_mm": c["staircase_closed_form"]["cusp_mean_mm"],
                                                       "cusp_p95_mm": c["staircase_closed_form"]["cusp_p95_mm"],
                                                       "mirror_overhang_area_mm2": c["mirror_overhang_area_mm2"]}
                                                      if "staircase_closed_form" in c else {}),
                                                   **({"support_model": c["support_model"]} if "support_model" in c else {})}
                                for c in pc["candidates"]},
                 "staircase_from_slices": pc.get("staircase_from_slices"), "polishing": pc.get("polishing"),
                 "ray_angle_error_median_deg": pc.get("optical_effect_as_printed", {}).get("ray_angle_error_median_deg"),
                 "slicer_estimates": pc.get("gcode", {}).get("estimates"),
                 "support_contact_from_gcode": pc.get("gcode", {}).get("support_contact"),
                 "rigcad_estimate": pc["estimate"]}
                for pc in e["pieces"]]}
            if "reassembly" in e:
                rows[part]["reassembly"] = e["reassembly"]
        out["printers"][name] = {"total_s": total, "stages_s": res.timings_s, "slicer_s": res.slicer_s,
                                 "totals": res.report["totals"], "problems": res.problems, "parts": rows}
        print(f"{name}: {total:.1f} s; problems: {res.problems}")
    return out


def _pieces(report: dict) -> list[tuple[str, dict]]:
    return [(pc["name"], pc) for e in report["parts"].values() for pc in e.get("pieces", []) if "gcode" in pc]


def _part_of(report: dict) -> dict[str, str]:
    """piece name -> its part (the pieces of one part are left out of a fit together: the four
    dome quarters are one shape, so leaving out one of them would test nothing)."""
    return {pc["name"]: part for part, e in report["parts"].items() for pc in e.get("pieces", [])}


def _estimates(args, rig) -> dict:
    printer = load_printer("prusa_mk3s")
    if args.from_report:
        report = json.loads(Path(args.from_report).read_text(encoding="utf-8"))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            report = run_fab(rig, printer, Path(tmp), gcode=True).report
    pieces = _pieces(report)
    feats = {n: E.Features(**pc["estimate"]["features"]) for n, pc in pieces}
    truth = {n: (pc["gcode"]["estimates"]["print_time_s"], pc["gcode"]["estimates"]["filament_g"]) for n, pc in pieces}
    rho = printer.material_density_g_cm3
    fit = E.FIT
    part_of = _part_of(report)
    out: dict = {}
    if args.fit:
        fit = E.fit([(feats[n], *truth[n]) for n, _ in pieces], rho, report["gcode"].get("slicer_version") or "")
        print("fitted:", fit)
        loo = {}
        for part in dict.fromkeys(part_of[n] for n, _ in pieces):
            f1 = E.fit([(feats[m], *truth[m]) for m, _ in pieces if part_of[m] != part], rho, "leave-one-out")
            for n in (m for m, _ in pieces if part_of[m] == part):
                e = E.estimate(feats[n], printer, f1)
                loo[n] = {"time_rel_error": e["print_time_s"] / truth[n][0] - 1,
                          "filament_rel_error": e["material_g"] / truth[n][1] - 1}
        out["fit"] = fit.__dict__
        out["leave_one_out"] = loo
    table = []
    features_by_piece = {n: feats[n].__dict__ for n, _ in pieces}
    print(f"{'piece':34s} {'slicer h':>9s} {'rigcad h':>9s} {'err':>7s} {'slicer g':>9s} {'rigcad g':>9s} {'err':>7s}")
    for n, _ in pieces:
        e = E.estimate(feats[n], printer, fit)
        t, g = truth[n]
        row = {"piece": n, "part": part_of[n], "features": features_by_piece[n], "slicer_print_time_s": t, "rigcad_print_time_s": e["print_time_s"],
               "time_rel_error": e["print_time_s"] / t - 1, "slicer_filament_g": g, "rigcad_material_g": e["material_g"],
               "filament_rel_error": e["material_g"] / g - 1}
        if "leave_one_out" in out:
            row.update({f"leave_one_out_{k}": v for k, v in out["leave_one_out"][n].items()})
        table.append(row)
        print(f"{n:34s} {t / 3600:9.2f} {e['print_time_s'] / 3600:9.2f} {row['time_rel_error']:+7.1%} "
              f"{g:9.1f} {e['material_g']:9.1f} {row['filament_rel_error']:+7.1%}")
    worst = max(max(abs(r["time_rel_error"]), abs(r["filament_rel_error"])) for r in table)
    print(f"worst per-piece error: {worst:.1%} (target {E.MAX_REL_ERROR:.0%})")
    if "leave_one_out" in out:
        lw = max(max(abs(v) for v in r.values()) for r in out["leave_one_out"].values())
        print(f"worst leave-one-part-out error: {lw:.1%}")
        out["worst_leave_one_out_rel_error"] = lw
    out.update({"printer": "prusa_mk3s", "slicer_version": report["gcode"].get("slicer_version"), "pieces": table,
                "worst_rel_error": worst})
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--printers", nargs="+", default=["vantage_i", "prusa_mk3s", "form3"])
    ap.add_argument("--gcode", action="store_true")
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--estimates", action="store_true", help="rigcad's estimates against PrusaSlicer (MK3S)")
    ap.add_argument("--from-report", help="a fab.json written with --gcode (skips slicing)")
    ap.add_argument("--fit", action="store_true", help="refit the estimate model's coefficients")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results",
                    help="results folder (default: bench/results)")
    args = ap.parse_args()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
    results = args.out
    if args.estimates:
        path = write_json(results / "fab_estimates.json", _estimates(args, rig))
    else:
        path = write_json(results / "fab_stages.json", _stages(args, rig, profile))
    print(path)


if __name__ == "__main__":
    main()
