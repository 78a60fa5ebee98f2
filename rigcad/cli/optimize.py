"""``rigcad optimize PROFILE``: inverse design from the command line."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path


#: First line of a design profile rigcad optimize writes (rigcad.optimize.run.design_yaml): a file
#: that starts otherwise was not written by rigcad and is never replaced.
DESIGN_MARK = b"# Chosen by `rigcad optimize "


def refuse_foreign_design(profile_spec, name: str, out: Path) -> None:
    """The chosen design is written beside the profile's file when the profile is given by a path off
    the search path (there its ``extends: name`` resolves; under the exports it would not, and an
    absolute ``extends`` would tie the file to this machine). Such a file is replaced only when an
    earlier run of rigcad optimize wrote it: a file of the user's of that name is refused before the
    search, naming it."""
    from rigcad.errors import ProfileError
    from rigcad.optimize.run import _design_home

    home = _design_home(profile_spec, name, out)
    if home == out:
        return
    path = home / f"{name}_design.yaml"
    try:
        with open(path, "rb") as fh:
            head = fh.read(len(DESIGN_MARK))
    except FileNotFoundError:
        return
    except OSError as err:
        raise ProfileError(f"{path}: cannot read it to check who wrote it ({err.strerror}); rigcad optimize writes "
                           "its chosen design there", param="--exports") from err
    if os.path.islink(path) or head != DESIGN_MARK:
        raise ProfileError(f"{path} exists and was not written by rigcad optimize: it would be replaced by the chosen "
                           f"design (written beside {name}'s file, where its extends: {name} resolves); rename or "
                           "move that file, or put the profile on the search path (./profiles or $RIGCAD_PROFILES) "
                           "so the design goes under the exports")


def assembly_gate(rig) -> None:
    """The assembly gate on a certified design (rigcad.manual.gate.verdict, no search for fixes): a rig
    that cannot be put together raises AssemblyError, and the optimiser tries its next design."""
    from rigcad.errors import AssemblyError
    from rigcad.manual import gate

    v = gate.verdict(rig, search=False)
    if not v.ok:  # its line points to no file (none is written here): the whole reason goes into optimize.json
        raise AssemblyError(v.line(), step=v.step, members=v.members, obstacles=v.obstacles, summary=v.summary,
                            detail=v.reason)


def cmd_optimize(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from rigcad.engine import Engine
    from rigcad.optimize.run import load_problem, run_optimize

    overrides = {"seed": args.seed, "evaluations": args.evaluations, "workers": args.workers}
    problem = load_problem(args.profile, overrides)  # refuses a bad optimize section before any work
    refuse_foreign_design(args.profile, problem.base.name, Path(args.exports) / problem.base.name / "optimize")
    spec = problem.spec
    engine = Engine(workers=spec.workers, scheduler=args.scheduler)
    bar = tqdm(total=spec.evaluations, desc=f"optimize {problem.base.name}", unit="design", disable=None,
               leave=False, file=sys.stderr)

    def progress(done: int, best: float) -> None:
        bar.update(done - bar.n)
        bar.set_postfix_str(f"best merit {best:.6g}")

    try:
        # every design the certified path checks must pass the assembly gate: a refused one gives way to the next
        run = run_optimize(args.profile, Path(args.exports), engine, overrides, progress, certify_also=assembly_gate)
    finally:
        bar.close()
    rep = run.report
    base, chosen = rep["base"], rep["chosen"]
    print(f"{rep['profile']}: {rep['method']}, {len(rep['evaluations'])} evaluations on {rep['engine']} "
          f"({rep['workers']} worker(s)) in {rep['timings_s']['total_s']:.1f} s; median evaluation "
          f"{1e3 * rep['evaluation_time_s']['cpu_median_s']:.2f} ms CPU; {len(rep['pareto'])} design(s) on the Pareto front")
    print(f"  chosen: {rep['reason']}")
    print(f"  {'':<24} {'base':>12} {'chosen':>12}")
    keys = [(k, k) for k in ("theta_min_deg", "px_per_deg_cv", "px_per_deg_mean", "px_per_deg_min",
                             "occluded_fraction", "dome_outer_width_mm", "dome_outer_height_mm", "dome_mass_g",
                             "cop_z_mm", "dome_pieces")]
    for label, k in keys:
        b = base["figures"].get(k) if base["figures"] else None
        c = chosen["figures"].get(k)
        fmt = (lambda v: "-" if v is None else (f"{v:.5g}" if isinstance(v, float) else str(v)))
        print(f"  {label:<24} {fmt(b):>12} {fmt(c):>12}")
    for key, value in chosen["parameters"].items():
        print(f"  {key:<32} {value:.6g}  (base {base['parameters'][key]:.6g})")
    for refused in rep["rejected_by_certified_path"]:
        print(f"  refused on the certified path: evaluation {refused['index']}: {refused['error']}")
    rc = rep["certified_check"].get("ray_check")
    if rc:
        print(f"  rigcad check passes: Monte Carlo yield {rc['monte_carlo_yield']:.3g} (tolerancing.min_yield "
              f"{rc['min_yield']:g}, {rc['builds']} builds), mirror meshes {rc['mirror_normal_error_rad']:g} rad; "
              f"fab's tolerance stack holds on {rep['certified_check']['tolerance_stack']['printer']}; the assembly "
              "gate finds an order")
    cert = rep["certified_check"]["fast_minus_certified"]
    print("  certified path (converged DOP853 dome) minus fast path: "
          + ", ".join(f"{k} {-v:+.2g}" for k, v in cert.items()))
    for p in run.written:
        print(f"  wrote {p}")
    print(f"  build it: rigcad stl {run.profile_path}")
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``optimize`` to rigcad's subcommands."""
    from rigcad.arguments import positive_int, profile_command, worker_count

    p = profile_command(
        subparsers, "optimize", cmd_optimize,
        profile_help="profile name (under profiles/) or path, with an optimize: section",
        help="inverse design: search the profile's optimize: section for the rig that meets its targets",
        description="Seeded global search (differential evolution for one objective, NSGA-II for two or more) "
                    "and a local polish over the free parameters of the profile's optimize: section, under its "
                    "constraints; writes exports/<profile>/optimize/{<profile>_design.yaml, optimize.json, "
                    "history.png, pareto.png}. Exit 1 naming the constraint that could not be met.",
        epilog="Example: rigcad optimize achutha2006_optimize (profiles/achutha2006_optimize.yaml)")
    p.add_argument("--seed", type=int, help="seed (default: optimize.seed)")
    p.add_argument("--evaluations", type=positive_int, help="evaluation budget (default: optimize.evaluations)")
    p.add_argument("--workers", type=worker_count, help="worker processes, 0 = every core (default: optimize.workers)")
    p.add_argument("--scheduler", help="a Dask scheduler address, or local-dask (default: loky / serial)")
    return p
