"""Benchmark of the fabrication stage: time per stage and per slicer run, staircase figures per
printer and orientation, the dome's split. Writes bench/results/fab_stages.json (not a test: no
timed assertions).

    .venv/bin/python bench/fab_stages.py [--gcode] [--printers vantage_i prusa_mk3s form3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from rigcad.export.atomic import write_json
from rigcad.fab.printers import load_printer
from rigcad.fab.stage import run_fab
from rigcad.profile import load_profile
from rigcad.rig import Rig


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--printers", nargs="+", default=["vantage_i", "prusa_mk3s", "form3"])
    ap.add_argument("--gcode", action="store_true")
    ap.add_argument("--profile", default="achutha2006")
    args = ap.parse_args()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
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
            rows[part] = {"split": e["split"], "pieces": [
                {"name": pc["name"], "orientation": pc["orientation"], "layers": pc["layers"],
                 "candidates": {c["orientation"]: {"fits": c["fits"],
                                                   **({"cusp_mean_mm": c["staircase_closed_form"]["cusp_mean_mm"],
                                                       "cusp_p95_mm": c["staircase_closed_form"]["cusp_p95_mm"],
                                                       "mirror_overhang_area_mm2": c["mirror_overhang_area_mm2"]}
                                                      if "staircase_closed_form" in c else {})}
                                for c in pc["candidates"]},
                 "staircase_from_slices": pc.get("staircase_from_slices"), "polishing": pc.get("polishing"),
                 "ray_angle_error_median_deg": pc.get("optical_effect_as_printed", {}).get("ray_angle_error_median_deg"),
                 "slicer_estimates": pc.get("gcode", {}).get("estimates"), "rigcad_estimate": pc["estimate"]}
                for pc in e["pieces"]]}
            if "reassembly" in e:
                rows[part]["reassembly"] = e["reassembly"]
        out["printers"][name] = {"total_s": total, "stages_s": res.timings_s, "slicer_s": res.slicer_s,
                                 "totals": res.report["totals"], "problems": res.problems, "parts": rows}
        print(f"{name}: {total:.1f} s; problems: {res.problems}")
    path = write_json(Path(__file__).parent / "results" / "fab_stages.json", out)
    print(path)


if __name__ == "__main__":
    main()
