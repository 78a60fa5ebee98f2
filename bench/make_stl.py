"""The whole pipeline as a user runs it: `make stl` cold and with nothing changed, and the time and
peak memory of each stage (issue 7, table d).

Run from the repository root: ``.venv/bin/python bench/make_stl.py [--repeats 3]``. Writes
bench/results/make_stl.json and make_stl.png. Every command is the console script `make` runs
(``.venv/bin/rigcad ...``), started as a subprocess into a scratch exports folder, and reaped with
os.wait4, which gives that child's own resource usage: wall time, user + system CPU time and peak
resident memory (``ru_maxrss``, KiB on Linux; the largest of the process and the children it
waited for). Commands:

* ``stl_cold``: ``rigcad stl achutha2006 --exports EMPTY`` (what `make stl` runs on a fresh clone);
* ``stl_unchanged``: the same command again, nothing changed (the issue's target: under 1 s);
  decomposed by ``startup_*``: the interpreter alone, ``import rigcad.cli``, and building the
  argument parser (which imports every stage's CLI module);
* the stages apart: ``design`` and ``build`` (cold, each into an empty folder), ``check`` (100 000
  rays and the Monte Carlo, on the cold build's exports) and ``fab --printer vantage_i`` (no G-code).

Each is repeated ``--repeats`` times (``stl_unchanged`` and ``startup_*`` 5 times): min and median
wall time are reported. The issue's targets are reported against, never asserted.
"""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

from _common import ROOT, arguments, png, pyplot, reaped, run_info

from rigcad.export.atomic import write_bytes, write_json

RIGCAD = str(Path(sys.executable).parent / "rigcad")
PROFILE = "achutha2006"
TARGETS = {"stl_unchanged_wall_s": 1.0, "stl_cold_wall_s": 60.0}


def measured(cmd: list[str]) -> dict:
    """Run ``cmd`` from the repository root; its wall time (s), CPU time (s), peak RSS (MiB) and
    exit code. Output goes to a temporary file (kept in the result only on failure)."""
    res = reaped(cmd)
    out = {"wall_s": res["wall_s"], "cpu_s": res["user_s"] + res["system_s"],
           "max_rss_mib": round(res["peak_rss_kb"] / 1024, 1), "exit_code": res["exit_code"]}
    if res["exit_code"] != 0:
        out["output_tail"] = res["output"][-2000:]
    return out


def summary(runs: list[dict], cmd: list[str]) -> dict:
    """min/median wall and CPU time over the runs, the largest peak RSS, every run's figures."""
    walls = [r["wall_s"] for r in runs]
    return {"command": " ".join(Path(c).name if c == RIGCAD else c for c in cmd), "repeats": len(runs),
            "wall_min_s": min(walls), "wall_median_s": statistics.median(walls),
            "cpu_min_s": min(r["cpu_s"] for r in runs),
            "max_rss_mib": max(r["max_rss_mib"] for r in runs),
            "exit_codes": sorted({r["exit_code"] for r in runs}), "runs_s": runs}


def fresh(scratch: Path, name: str) -> Path:
    d = scratch / name
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    return d


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    repeats = 1 if args.quick else args.repeats
    run = run_info()
    result: dict = {"profile": PROFILE, "commands": {}, "run": run}
    cmds = result["commands"]

    def record(name: str, runs: list[dict], cmd: list[str]) -> None:
        cmds[name] = summary(runs, cmd)
        c = cmds[name]
        print(f"{name:<22} min {c['wall_min_s']:7.2f} s  median {c['wall_median_s']:7.2f} s  "
              f"peak RSS {c['max_rss_mib']:7.1f} MiB  exit {c['exit_codes']}", flush=True)

    py = sys.executable
    for name, code in (("startup_python", "pass"), ("startup_import_cli", "import rigcad.cli"),
                       ("startup_build_parser", "import rigcad.cli; rigcad.cli.build_parser()")):
        cmd = [py, "-c", code]
        record(name, [measured(cmd) for _ in range(1 if args.quick else 5)], cmd)

    with tempfile.TemporaryDirectory(prefix="rigcad-bench-") as tmp:
        scratch = Path(tmp)
        if args.quick:
            cmd = [RIGCAD, "design", PROFILE, "--exports", str(fresh(scratch, "design"))]
            record("design", [measured(cmd)], cmd)
        else:
            runs = []
            for _ in range(repeats):
                cmd = [RIGCAD, "stl", PROFILE, "--exports", str(fresh(scratch, "stl"))]
                runs.append(measured(cmd))
            record("stl_cold", runs, cmd)
            record("stl_unchanged", [measured(cmd) for _ in range(5)], cmd)
            exports = scratch / "stl"
            for stage in ("design", "build"):
                runs = []
                for _ in range(repeats):
                    cmd = [RIGCAD, stage, PROFILE, "--exports", str(fresh(scratch, stage))]
                    runs.append(measured(cmd))
                record(stage, runs, cmd)
            cmd = [RIGCAD, "check", PROFILE, "--exports", str(exports)]
            record("check", [measured(cmd) for _ in range(repeats)], cmd)
            runs = []
            for _ in range(repeats):
                shutil.rmtree(exports / PROFILE / "fab", ignore_errors=True)
                cmd = [RIGCAD, "fab", PROFILE, "--printer", "vantage_i", "--exports", str(exports)]
                runs.append(measured(cmd))
            record("fab", runs, cmd)
        for c in cmds.values():  # the scratch folder's random name would make the JSON differ run to run
            c["command"] = c["command"].replace(str(scratch), "SCRATCH")
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    result["all_children_max_rss_mib"] = round(children.ru_maxrss / 1024, 1)
    if "stl_cold" in cmds:
        result["targets"] = {
            "stl_unchanged_under_1_s": {"target_s": TARGETS["stl_unchanged_wall_s"],
                                        "measured_min_s": cmds["stl_unchanged"]["wall_min_s"],
                                        "measured_median_s": cmds["stl_unchanged"]["wall_median_s"]},
            "stl_cold_under_60_s_on_2_cores": {"target_s": TARGETS["stl_cold_wall_s"],
                                               "measured_min_s": cmds["stl_cold"]["wall_min_s"],
                                               "measured_median_s": cmds["stl_cold"]["wall_median_s"],
                                               "cpu_min_s": cmds["stl_cold"]["cpu_min_s"],
                                               "cpus": os.cpu_count()},
        }
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "make_stl.json", result))
    write_bytes(args.out / "make_stl.png", plot(result))


def plot(result: dict) -> bytes:
    plt = pyplot()
    cmds = result["commands"]
    names = list(cmds)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5))
    y = range(len(names))
    axes[0].barh(y, [cmds[n]["wall_median_s"] for n in names], color="tab:blue", label="median wall")
    axes[0].scatter([cmds[n]["wall_min_s"] for n in names], y, color="k", marker="|", s=200, label="min wall", zorder=3)
    for target, name in ((1.0, "stl_unchanged"), (60.0, "stl_cold")):
        if name in cmds:
            axes[0].axvline(target, color="tab:red", ls=":", lw=1)
            axes[0].annotate(f"target {name}", (target, len(names) - 0.5), color="tab:red", fontsize=7)
    axes[0].set_xscale("log")
    axes[0].set_xlabel("seconds (this machine)")
    axes[0].set_title(f"wall time ({os.cpu_count()} cores, load {result['run']['loadavg_1min']} at start)", fontsize=9)
    axes[1].barh(y, [cmds[n]["max_rss_mib"] for n in names], color="tab:green")
    axes[1].set_xlabel("peak resident memory (MiB)")
    axes[1].set_title("peak RSS (os.wait4 ru_maxrss)", fontsize=9)
    for ax in axes:
        ax.set_yticks(list(y), names, fontsize=8)
        ax.grid(True, axis="x", which="both", lw=0.3)
    axes[0].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    return png(fig)


if __name__ == "__main__":
    main()
