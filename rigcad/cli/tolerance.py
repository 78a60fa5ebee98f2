"""``rigcad tolerance PROFILE``: the Monte Carlo tolerancing at scale (per-sample table, sensitivity,
inverse limits), and the engine arguments and memory guard ``rigcad sweep`` shares."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rigcad.units import DEG


#: Peak memory per Monte Carlo sample kept (bytes): 4 kB measured (peak RSS 343 MB at 200 samples,
#: 358 MB at 4,000: /usr/bin/time -f %M rigcad tolerance achutha2006 --no-limits --workers 1
#: --rays 100 --samples N), doubled for the table writers (parquet, CSV) holding a copy.
TOLERANCE_BYTES_PER_SAMPLE = 8000
#: Peak memory per pinhole ray of a light path traced at once, in each worker (bytes): 460 measured
#: (805 MB at 1,000,000 rays against 343 MB at 100, one worker), doubled.
TOLERANCE_BYTES_PER_RAY = 1000
#: Memory of the parent and of each worker before any sample (bytes): interpreter, rig, tracer.
TOLERANCE_FIXED_BYTES = 400e6


def engine_from(args):
    """The engine ``--workers`` and ``--scheduler`` ask for; a note on stderr when it has fewer workers."""
    from rigcad.engine import LOCAL_DASK, Engine, cores

    engine = Engine(workers=args.workers, scheduler=args.scheduler)
    if args.workers and args.workers > engine.n_workers:
        where = "this machine's cores" if args.scheduler in (None, LOCAL_DASK) else "rigcad's Dask bound"
        print(f"note: --workers {args.workers} is more than {where}: {engine.n_workers} worker(s) "
              f"({cores()} core(s) here)", file=sys.stderr)
    return engine


def _local_workers(engine) -> int:
    """Workers on this machine (a remote Dask scheduler's are elsewhere: only the parent here)."""
    from rigcad.engine import LOCAL_DASK

    return engine.n_workers if engine.scheduler in (None, LOCAL_DASK) else 1


def checked_tolerance(samples: int, rays: int, engine, samples_flag: str, rays_flag: str,
                      rays_key: tuple[str, str] = ("tolerancing", "rays")) -> None:
    """Refuse, before any work, a sample count whose table or a ray count whose traces (one light
    path per local worker at once) would not fit in this machine's memory."""
    from rigcad.engine import require_memory
    from rigcad.profile.schema import bound

    workers = _local_workers(engine)
    require_memory(rays_flag, rays, TOLERANCE_BYTES_PER_RAY * workers, TOLERANCE_FIXED_BYTES * (workers + 1),
                   f"tracing one light path in each of {workers} worker(s)", most=bound(*rays_key))
    require_memory(samples_flag, samples, TOLERANCE_BYTES_PER_SAMPLE,
                   TOLERANCE_FIXED_BYTES * (workers + 1) + rays * TOLERANCE_BYTES_PER_RAY * workers,
                   "keeping every sample's row")


def engine_progress(update):
    """The engine's progress callback, feeding a progress bar's ``update(done)``."""
    return lambda tasks_done, tasks, done, total: update(done)


def cmd_tolerance(args: argparse.Namespace) -> int:
    from rigcad.profile import load_profile
    from rigcad.profile.schema import check_override

    from rigcad.export.atomic import check_exports

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "tolerance")  # a planted link or lock: one line now, not after the work
    tol = profile.tolerancing
    engine = engine_from(args)
    samples = tol.builds if args.samples is None else args.samples
    rays = tol.rays if args.rays is None else args.rays
    # --samples may pass tolerancing.builds' bound (at scale, on Dask): memory is its limit
    checked_tolerance(samples, rays, engine, "--samples" if args.samples else "tolerancing.builds",
                      "--rays" if args.rays else "tolerancing.rays")
    if args.rays is not None:
        check_override("tolerancing", "rays", args.rays, "--rays")
    # the stages' modules (and their libraries) only once the counts are known to be sane
    from rigcad.progress import progress_bar
    from rigcad.errors import CheckError
    from rigcad.export.atomic import profile_lock
    from rigcad.rig import load
    from rigcad.tolerance.limits import run_limits
    from rigcad.check.montecarlo import Job, run_monte_carlo
    from rigcad.tolerance.montecarlo import rank_correlations
    from rigcad.tolerance.report import write_tolerance

    rig = load(profile)
    t0 = time.perf_counter()
    with progress_bar(samples, f"tolerance {profile.name} ({engine.name})", "sample") as update:
        mc = run_monte_carlo(rig, samples, rays, engine, progress=engine_progress(update))
    mc_s = time.perf_counter() - t0
    limits = None
    limits_s = 0.0
    if not args.no_limits:
        from rigcad.tolerance.params import PARAMETERS

        t1 = time.perf_counter()
        with progress_bar(len(PARAMETERS), "inverse limits", "parameter") as update:
            limits = run_limits(rig, Job(rig, rays, 0, 0).key, rays, int(tol.seed) + 1, engine,
                                progress=engine_progress(update))
        limits_s = time.perf_counter() - t1
    corr = rank_correlations(mc.columns) if samples > 2 else None
    run_info = {"engine": engine.name, "workers": engine.n_workers, "scheduler": args.scheduler,
                "monte_carlo_s": mc_s, "samples_per_s": samples / mc_s, "limits_s": limits_s,
                "note": "the one file that differs run to run; every other file is the same bytes for any engine"}
    out = Path(args.exports) / profile.name / "tolerance"
    paths = write_tolerance(out, profile, mc, limits, corr, run_info, profile_lock(Path(args.exports), profile.name))
    s = mc.summary
    fs, fa = s["figures"]["max_spot_radius_mm"], s["figures"]["max_mirror_angle_error_rad"]
    print(f"{profile.name}: {samples} builds x {rays} rays per path on {engine.name} ({engine.n_workers} worker(s)) "
          f"in {mc_s:.1f} s ({samples / mc_s:.0f} samples/s)")
    print(f"  yield {s['yield']:.2%} (required {tol.min_yield:.0%}); spot p90 {fs['p90']:.3g} mm, max {fs['max']:.3g} mm; "
          f"angle p90 {fa['p90'] / DEG:.3g} deg, max {fa['max'] / DEG:.3g} deg")
    if limits:
        print("  most sensitive: " + ", ".join(f"{r['parameter']} ({max(r['spot_budget_used'], r['angle_budget_used']):.0%})"
                                               for r in limits[:3]))
    for p in paths:
        print(f"  wrote {p}")
    if s["yield"] < tol.min_yield:
        where = profile.where("tolerancing", "min_yield") or "default"
        raise CheckError(f"{profile.name}: tolerance yield {s['yield']:.2%} is below tolerancing.min_yield "
                         f"{tol.min_yield:.0%} ({where}); see {out / 'tolerance.md'} for the parameters to tighten")
    return 0


def engine_args(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--scheduler``, shared by ``tolerance`` and ``sweep``."""
    from rigcad.arguments import worker_count

    p.add_argument("--workers", type=worker_count, default=0,
                   help="worker processes (default 0: every core; 1: in this process)")
    p.add_argument("--scheduler", metavar="ADDR",
                   help="run the tasks on Dask: a dask.distributed scheduler address (tcp://host:8786) or "
                        "'local-dask' (a LocalCluster of --workers processes); needs pip install 'rigcad[dask]'")


def register(subparsers) -> None:
    """Add ``tolerance`` to rigcad's subcommands."""
    from rigcad.arguments import positive_int, profile_command

    p = profile_command(
        subparsers, "tolerance", cmd_tolerance,
        help="Monte Carlo tolerancing at scale: per-sample table, sensitivity, inverse limits",
        description="Trace --samples random builds (tolerancing.*) through the analytic tracer on this machine's "
                    "cores (joblib) or Dask; write exports/<profile>/tolerance/{samples.parquet, samples.csv, "
                    "summary.json, tolerance.md, histograms.png, sensitivity.png, run.json}. Exit 1 when the "
                    "yield is below tolerancing.min_yield.")
    p.add_argument("--samples", type=positive_int, help="random builds (default: tolerancing.builds)")
    p.add_argument("--rays", type=positive_int, help="pinhole rays per light path (default: tolerancing.rays)")
    p.add_argument("--no-limits", action="store_true", help="skip the sensitivity ranking and inverse limits")
    engine_args(p)
