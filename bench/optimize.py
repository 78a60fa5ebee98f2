"""Inverse design (issue 13): the cost of one design evaluation against the certified path, the fast
path's accuracy against its one knob (quadrature nodes), and a whole `rigcad optimize` run.

(a) One evaluation (derived geometry, the closed-form dome at the optimiser's nodes, every objective
    and constraint, the printer fit) on one core, CPU time (``time.process_time``: what this
    process used, whatever else the machine runs) and wall time, over Table 3.1 and random designs
    of the example's bounds; side by side, ``derive`` + ``converged_dome`` (the certified path) and
    the raw DOP853 solve at 1e-6 mm on the same designs.
(b) Accuracy against nodes: px/deg CV, mean and min, occluded fraction, each against the certified
    design (converged DOP853 dome, its 2D report) or, where that reads coarser, 512 nodes.
(c) `rigcad optimize achutha2006_optimize` with 1 and 2 workers: time, evaluations, the result
    beside Table 3.1, and that the two runs agree bit for bit.

    .venv/bin/python bench/optimize.py [--quick] [--out bench/results]
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._common import arguments, png, pyplot, run_info  # noqa: E402


def main() -> int:
    args = arguments(__doc__).parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    from rigcad.engine import Engine
    from rigcad.optics.design import converged_dome
    from rigcad.optics.dome import _solve, occlusion_s, start
    from rigcad.optimize.fast import fast_design
    from rigcad.optimize.problem import apply, evaluate
    from rigcad.optimize.run import load_problem
    from rigcad.optimize.search import optimize
    from rigcad.profile import derive
    from rigcad.rig import Rig

    out: dict = {"run": run_info()}
    pb = load_problem("achutha2006_optimize")
    rng = np.random.default_rng(13)
    n = 10 if args.quick else 200
    X = [pb.base_x] + [pb.to_x(rng.uniform(size=len(pb.names))) for _ in range(n)]
    for x in X[:3]:
        evaluate(pb, x)  # warm caches (Gauss nodes, sweep tables)

    # (a) one evaluation
    cpu, wall, feasible, refused = [], [], [], 0
    for x in X:
        c0, w0 = time.process_time(), time.perf_counter()
        r = evaluate(pb, x)
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
        feasible.append(bool(r["feasible"]))
        refused += r["error"] is not None
    cpu, wall = np.array(cpu), np.array(wall)
    m = 5 if args.quick else 30
    cert_cpu, raw_cpu, fast_same = [], [], []
    for i, x in enumerate(X[:m]):
        p = apply(pb.base, pb.names, x)
        c0 = time.process_time()
        try:
            converged_dome(p, derive(p))
        except Exception:  # noqa: BLE001 - only designs the certified path builds are compared
            continue
        cert_cpu.append(time.process_time() - c0)
        fast_same.append(cpu[i])
        try:
            g = derive(p)
            st = start(g)
            c0 = time.process_time()
            _solve(g, "dop853", 1e-6, st, occlusion_s(g, st.path_length))
            raw_cpu.append(time.process_time() - c0)
        except Exception:  # noqa: BLE001
            pass
    out["evaluation"] = {
        "designs": len(X), "feasible": int(sum(feasible)), "refused_by_geometry": refused,
        "table31_cpu_s": float(cpu[0]),
        "cpu_median_s": float(np.median(cpu)), "cpu_p90_s": float(np.percentile(cpu, 90)),
        "cpu_max_s": float(cpu.max()), "wall_median_s": float(np.median(wall)),
        "certified_derive_plus_converged_dome_cpu_median_s": float(np.median(cert_cpu)),
        "raw_dop853_1e-6_mm_cpu_median_s": float(np.median(raw_cpu)) if raw_cpu else None,
        "table31_certified_cpu_s": float(cert_cpu[0]),
        "certified_designs_compared": len(cert_cpu),
        "speedup_vs_certified": float(np.median(cert_cpu) / np.median(fast_same)),
        "target_s": 0.010,
    }

    # (b) accuracy against the nodes
    designs = [pb.base_x, np.array([200.0, 200.0, 25.0, np.radians(13.0)])]
    acc = []
    for x in designs[: 1 if args.quick else 2]:
        p = apply(pb.base, pb.names, x)
        g = derive(p)
        rig = Rig.from_profile(p)
        rep = rig.design.report["pixels"]
        ref = fast_design(p, g, 512).figures
        for nodes in (8, 12, 16, 24, 32, 48, 96):
            c0 = time.process_time()
            for _ in range(20):
                f = fast_design(p, g, nodes).figures
            t = (time.process_time() - c0) / 20
            acc.append({"design_mm_rad": [float(v) for v in x], "nodes": nodes, "fast_design_cpu_s": t,
                        "px_per_deg_mean_rel_error_vs_certified": abs(f["px_per_deg_mean"] / rep["px_per_deg_mean"] - 1),
                        "px_per_deg_min_rel_error_vs_certified": abs(f["px_per_deg_min"] / rep["px_per_deg_min"] - 1),
                        "px_per_deg_cv_rel_error_vs_512_nodes": abs(f["px_per_deg_cv"] / ref["px_per_deg_cv"] - 1),
                        "occluded_fraction_abs_error_vs_512_nodes": abs(f["occluded_fraction"] - ref["occluded_fraction"])})
    out["nodes"] = acc

    # (c) the whole run, 1 and 2 workers
    runs = {}
    budget = 40 if args.quick else None
    overrides = {"evaluations": budget} if budget else None
    pbr = load_problem("achutha2006_optimize", overrides)
    for w in (1, 2):
        t0 = time.perf_counter()
        res = optimize(pbr, Engine(workers=w))
        runs[w] = (time.perf_counter() - t0, res)
    (t1, r1), (t2, r2) = runs[1], runs[2]
    same = [(a["x"], a["objectives"]) for a in r1.history] == [(b["x"], b["objectives"]) for b in r2.history]
    base, chosen = r1.base, r1.chosen
    out["run"]["note_runs"] = "search only (no certified check, no files): rigcad optimize adds ~2-4 s"
    out["optimize"] = {
        "evaluations": len(r1.history), "method": r1.method,
        "workers_1_s": t1, "workers_2_s": t2, "speedup_2_workers": t1 / t2,
        "bit_identical_1_vs_2_workers": bool(same),
        "base_table31": {k: base["figures"][k] for k in ("theta_min_deg", "px_per_deg_cv", "px_per_deg_mean",
                                                          "px_per_deg_min", "dome_outer_width_mm",
                                                          "dome_outer_height_mm", "dome_pieces", "occluded_fraction")},
        "chosen": None if chosen is None else {
            "parameters_mm_rad": dict(zip(pbr.names, chosen["x"])), "reason": r1.reason,
            **{k: chosen["figures"][k] for k in ("theta_min_deg", "px_per_deg_cv", "px_per_deg_mean", "px_per_deg_min",
                                                  "dome_outer_width_mm", "dome_outer_height_mm", "dome_pieces",
                                                  "occluded_fraction")}},
        "pareto_size": len(r1.front), "targets": {"evaluations": 300, "time_s": 120.0},
    }
    (args.out / "optimize.json").write_text(json.dumps(out, indent=1, default=float) + "\n")

    plt = pyplot()
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(15, 4.2))
    a1.hist(cpu * 1e3, bins=30, color="tab:blue", alpha=0.8, label="fast evaluation (every objective, constraint)")
    a1.axvline(np.median(cert_cpu) * 1e3, color="tab:red", label="derive + converged_dome (certified), median")
    a1.axvline(10.0, color="k", ls="--", label="target 10 ms")
    a1.set_xscale("log")
    a1.set_xlabel("CPU time per design (ms, one core)")
    a1.set_ylabel("designs")
    a1.legend(fontsize=7)
    for x in sorted({tuple(r["design_mm_rad"]) for r in acc}):
        rows = [r for r in acc if tuple(r["design_mm_rad"]) == x]
        nn = [r["nodes"] for r in rows]
        a2.semilogy(nn, [max(r["px_per_deg_cv_rel_error_vs_512_nodes"], 1e-17) for r in rows], "o-",
                    label=f"CV, d_cp {x[0]:.0f} mm")
        a2.semilogy(nn, [max(r["occluded_fraction_abs_error_vs_512_nodes"], 1e-17) for r in rows], "s--",
                    label=f"occluded fraction, d_cp {x[0]:.0f} mm")
    a2.set_xlabel("Gauss-Legendre nodes")
    a2.set_ylabel("error against 512 nodes")
    a2.legend(fontsize=7)
    a2.grid(alpha=0.3)
    rows = [r for r in r1.history if r["objectives"] is not None]
    a3.scatter([r["figures"]["theta_min_deg"] for r in rows if not r["feasible"]],
               [r["figures"]["px_per_deg_cv"] for r in rows if not r["feasible"]], s=6, color="0.8", label="infeasible")
    a3.scatter([r["figures"]["theta_min_deg"] for r in rows if r["feasible"]],
               [r["figures"]["px_per_deg_cv"] for r in rows if r["feasible"]], s=8, color="tab:blue", label="feasible")
    a3.plot([base["figures"]["theta_min_deg"]], [base["figures"]["px_per_deg_cv"]], "r*", ms=14, label="Table 3.1")
    if chosen is not None:
        a3.plot([chosen["figures"]["theta_min_deg"]], [chosen["figures"]["px_per_deg_cv"]], "D", color="tab:orange",
                mec="k", ms=9, label="chosen")
    a3.set_xlabel("lowest measurable theta (deg)")
    a3.set_ylabel("px/deg coefficient of variation")
    a3.legend(fontsize=7)
    a3.grid(alpha=0.3)
    fig.suptitle(f"rigcad optimize: {len(r1.history)} evaluations, {t1:.1f} s (1 worker) / {t2:.1f} s (2 workers)",
                 fontsize=10)
    fig.tight_layout()
    (args.out / "optimize.png").write_bytes(png(fig))
    e = out["evaluation"]
    print(f"evaluation: CPU median {1e3 * e['cpu_median_s']:.2f} ms (p90 {1e3 * e['cpu_p90_s']:.2f}, Table 3.1 "
          f"{1e3 * e['table31_cpu_s']:.2f}); certified derive+converged_dome {1e3 * e['certified_derive_plus_converged_dome_cpu_median_s']:.0f} ms "
          f"({e['speedup_vs_certified']:.0f}x)")
    o = out["optimize"]
    print(f"optimize: {o['evaluations']} evaluations, {o['workers_1_s']:.1f} s / {o['workers_2_s']:.1f} s (1/2 workers), "
          f"identical {o['bit_identical_1_vs_2_workers']}; chosen {o['chosen']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
