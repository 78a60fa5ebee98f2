"""The gray card's recovery (rigcad.calibrate.graycard) over seeds: simulated captures on the
default rig's own pixels with a planted gamma-2.2 or S-shaped camera, untilted or tilted, each
analysed as ``rigcad calibrate --gray-card`` does; per run the curve's, the camera side's and the
light side's error against the planted, the criterion's figures, and a 50 % card's albedo through
the calibration. Writes bench/results/graycard.json (deterministic but for the ``run`` section);
docs/calibrate-notes.md ("The gray card") quotes it.

    .venv/bin/python bench/graycard.py [--seeds 10] [--profile achutha2006] [--out DIR] [--quick]
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import arguments, run_info  # noqa: E402

from rigcad.basis.card_light import card_light  # noqa: E402
from rigcad.calibrate import graycard as G  # noqa: E402
from rigcad.export.atomic import write_json  # noqa: E402
from rigcad.rig import load  # noqa: E402

CURVES = {"gamma_2.2": G.gamma_curve(2.2), "s_curve": G.s_curve()}
TILTS_DEG = (0.0, 1.0, 2.0)


def one(plan, view, light, curve, tilt_deg: float, seed: int) -> dict:
    truth = G.planted(view, light, curve, tilt_rad=math.radians(tilt_deg))
    result = G.analyse(plan, G.as_read(plan, G.render(plan, view, light, truth, np.random.default_rng(seed))),
                       view, light)
    flat = G.planted(view, light, curve)  # the light side a flat card would give: what a tilt spoils
    lit = flat.g > 0.2 * np.median(flat.g)
    ratio = result.fit.light_g[lit] / flat.g[lit]
    plan2 = G.Plan(exposures_ms=(20.0, 40.0, 80.0))
    cap2 = G.as_read(plan2, G.render(plan2, view, light, dataclasses.replace(truth, albedo=0.5),
                                     np.random.default_rng(seed + 1000)))
    c2 = G.coefficients(plan2, G.radiance(result.response, cap2.frames, plan2.exposures_s))[:, view.used].T
    albedo = G.lambert_albedo(G.calibrated(result.fit, light.levels, light.zonal, light.weight_sr, c2), light)
    r = result.report
    return {"seed": seed, "tilt_deg": tilt_deg, "verdict": r["verdict"], **G.compare(result, truth, view, light),
            "light_side_vs_flat_card_max_relative_error": float(np.max(np.abs(ratio / np.median(ratio) - 1))),
            "exposure_spread_rms": max(d["rms"] for d in r["response_curve"]["exposure_spread"].values()
                                       if isinstance(d, dict)),
            "separable_residual_block_p95": r["card"]["separable_residual"]["blocks"]["p95"],
            "light_max_over_min": r["card"]["illumination_side"]["max_over_min"],
            "albedo_50_card_median": float(np.median(albedo)),
            "albedo_50_card_p5_p95": [float(np.percentile(albedo, 5)), float(np.percentile(albedo, 95))]}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--profile", default="achutha2006")
    args = ap.parse_args()
    seeds = 1 if args.quick else args.seeds
    rig = load(args.profile)
    light, view, plan = card_light(rig), G.view_of(rig), G.Plan()
    rows = [{"curve": name, **one(plan, view, light, curve, tilt, seed)}
            for name, curve in CURVES.items() for tilt in TILTS_DEG for seed in range(seeds)]
    summary = {}
    for name in CURVES:
        for tilt in TILTS_DEG:
            sel = [r for r in rows if r["curve"] == name and r["tilt_deg"] == tilt]
            summary[f"{name}_tilt_{tilt:g}deg"] = {
                k: [min(r[k] for r in sel), max(r[k] for r in sel)]
                for k in ("curve_max_relative_error", "camera_side_block_max_relative_error",
                          "light_side_max_relative_error", "light_side_vs_flat_card_max_relative_error",
                          "exposure_spread_rms", "separable_residual_block_p95", "light_max_over_min",
                          "albedo_50_card_median")} | {"verdicts": sorted({r["verdict"] for r in sel})}
    write_json(Path(args.out) / "graycard.json", {"profile": args.profile, "seeds": seeds,
                                "about": "ranges [min, max] over the seeds; rows: each run",
                                "summary": summary, "rows": rows, "run": run_info()})
    for key, s in summary.items():
        print(key, {k: [round(v, 4) for v in x] if isinstance(x[0], float) else x for k, x in s.items()})


if __name__ == "__main__":
    main()
