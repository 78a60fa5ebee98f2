"""Tolerancing at scale (issue 12): the 10,000-sample Monte Carlo of the default profile on one
worker (this process), two loky workers, and a Dask LocalCluster of two workers; wall time of each,
samples/s, the speed-up over one worker, and whether the three summaries (and per-sample tables)
are the same bits.

Run from the repository root: ``.venv/bin/python bench/tolerance.py [--samples N] [--rays N]``.
Writes bench/results/tolerance.{json,png}. Timings vary run to run (keys ending in ``_s``, rates,
speed-ups; the ``run`` section records the load); they are never asserted.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import arguments, png, pyplot, run_info  # noqa: E402

from rigcad.engine import LOCAL_DASK, Engine  # noqa: E402
from rigcad.export.atomic import write_bytes, write_json  # noqa: E402
from rigcad.rig import load  # noqa: E402
from rigcad.check.montecarlo import run_monte_carlo  # noqa: E402


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--rays", type=int, default=1000, help="pinhole rays per light path and sample")
    ap.add_argument("--profile", default="achutha2006")
    args = ap.parse_args()
    if args.quick:
        args.samples, args.rays = 24, 200
    rig = load(args.profile)
    engines = {"1 worker (serial)": Engine(1), "2 loky workers": Engine(2)}
    try:
        import distributed  # noqa: F401

        engines["Dask LocalCluster, 2 workers"] = Engine(2, LOCAL_DASK)
    except ImportError:
        pass
    run_monte_carlo(rig, 2, 100, Engine(1))  # compile/load the kernels in this process first
    result = {"profile": rig.name, "samples": args.samples, "rays_per_path": args.rays, "run": run_info(),
              "engines": {}}
    first = None
    for name, engine in engines.items():
        t0 = time.perf_counter()
        mc = run_monte_carlo(rig, args.samples, args.rays, engine)
        wall = time.perf_counter() - t0
        same = None
        if first is None:
            first = mc
        else:
            same = mc.summary == first.summary and all(np.array_equal(mc.columns[k], first.columns[k])
                                                       for k in first.columns)
        result["engines"][name] = {"engine": engine.name, "workers": engine.n_workers, "wall_s": wall,
                                   "samples_per_s": args.samples / wall,
                                   "rays_per_s": 2 * args.rays * args.samples / wall,
                                   "same_bits_as_serial": same}
        print(name, result["engines"][name])
    base = result["engines"]["1 worker (serial)"]["wall_s"]
    for r in result["engines"].values():
        r["speed_up_over_one_worker"] = base / r["wall_s"]
    result["summary"] = first.summary
    args.out.mkdir(parents=True, exist_ok=True)
    write_json(args.out / "tolerance.json", result)

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.8))
    names = list(result["engines"])
    walls = [result["engines"][n]["wall_s"] for n in names]
    ax.barh(np.arange(len(names))[::-1], walls, color=["0.5", "tab:blue", "tab:green"][: len(names)])
    for i, n in enumerate(names):
        r = result["engines"][n]
        ax.text(walls[i], len(names) - 1 - i, f" {walls[i]:.1f} s, {r['speed_up_over_one_worker']:.2f}x"
                + ("" if r["same_bits_as_serial"] is None else (", same bits" if r["same_bits_as_serial"] else ", DIFFERENT")),
                va="center", fontsize=8)
    ax.set_yticks(np.arange(len(names))[::-1], names, fontsize=8)
    ax.set_xlabel("wall time (s)")
    ax.set_xlim(0, max(walls) * 1.6)
    ax.set_title(f"{args.samples} builds x {args.rays} rays per path (load {result['run']['loadavg_1min']})", fontsize=10)
    fig.tight_layout()
    write_bytes(args.out / "tolerance.png", png(fig))


if __name__ == "__main__":
    main()
