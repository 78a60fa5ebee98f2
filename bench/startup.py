"""Start-up time of the commands a user waits on before any work: `rigcad --help`, an up-to-date
`rigcad stl`, a refused profile's one-line error; with the interpreter alone and `import rigcad`
to read them against.

Run from the repository root: ``.venv/bin/python bench/startup.py [--runs 5] [--before TREE]``.
Writes bench/results/startup.json. Every command is the console script's body (``from rigcad.cli
import main``; see RIGCAD) started as a subprocess with ``PYTHONPATH`` set to the source tree measured, and
reaped with os.wait4: wall time and the child's user + system CPU time. "Warm": each command runs
once unmeasured first (files in the page cache, bytecode compiled), then ``--runs`` times.

``--before TREE`` measures a second source tree the same way, each run interleaved with this
tree's so both see the same load: e.g. the commit before a change, exported with
``git archive <commit> | tar -x -C /tmp/before``. Commands:

* ``python``: ``python -c pass``, the interpreter's own start-up (the floor under every figure);
* ``import_rigcad``: ``python -c "import rigcad"``;
* ``help``: ``rigcad --help`` (imports rigcad.cli and builds every sub-command's parser);
* ``stl_unchanged``: ``rigcad stl achutha2006`` on exports it built just before, unmeasured: what
  `make stl` does when nothing changed (reads the profile, hashes it and the files, returns);
* ``refused``: ``rigcad design`` on a profile with a length without its unit: one line, exit 2.

Targets (reported, never asserted): help and stl_unchanged at most 0.3 s, refused at most 0.5 s.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _common import ROOT, arguments, reaped, run_info

from rigcad.export.atomic import write_json

#: The console script's own body, run by the interpreter: ``from rigcad.cli import main`` is the same
#: call in a tree from before the command line became a package (script ``rigcad.cli:main``) and
#: after (``rigcad.cli.main:main``, which rigcad.cli re-exports), so one launcher measures both.
RIGCAD = [sys.executable, "-c", "import sys; from rigcad.cli import main; sys.exit(main())"]
PROFILE = "achutha2006"
TARGETS_S = {"help": 0.3, "stl_unchanged": 0.3, "refused": 0.5}
#: A profile rigcad refuses at validation: a length without its unit.
REFUSED = "extends: achutha2006\nlayout:\n  cop_to_vertex: 27\n"


def measured(cmd: list[str], tree: Path) -> dict:
    """Run ``cmd`` with ``tree`` first on the import path, from ``tree``: wall time (s), the child's
    CPU time (s) and exit code; its output is kept only when it is not the expected one."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    env.pop("RIGCAD_PROFILES", None)
    # warm means compiled: a shell that sets PYTHONDONTWRITEBYTECODE would have every run compile
    # rigcad's modules again (~0.1 s), which no user's installed rigcad does
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    res = reaped(cmd, cwd=tree, env=env)
    return {"wall_s": res["wall_s"], "cpu_s": res["user_s"] + res["system_s"], "exit_code": res["exit_code"],
            "output": res["output"]}


def commands(scratch: Path, label: str, quick: bool) -> dict[str, tuple[list[str], int]]:
    """name -> (command, expected exit code) for one tree; ``label`` keeps the trees' exports apart."""
    py = sys.executable
    refused = scratch / "refused.yaml"
    refused.write_text(REFUSED)
    out = {"python": ([py, "-c", "pass"], 0),
           "import_rigcad": ([py, "-c", "import rigcad"], 0),
           "help": ([*RIGCAD, "--help"], 0),
           "refused": ([*RIGCAD, "design", str(refused), "--exports", str(scratch / f"refused_{label}")], 2)}
    if not quick:
        out["stl_unchanged"] = ([*RIGCAD, "stl", PROFILE, "--exports", str(scratch / f"stl_{label}")], 0)
    return out


def summary(runs: list[dict]) -> dict:
    walls = sorted(r["wall_s"] for r in runs)
    return {"runs": len(runs), "wall_median_s": statistics.median(walls), "wall_min_s": walls[0],
            "wall_max_s": walls[-1], "cpu_median_s": statistics.median(r["cpu_s"] for r in runs),
            "exit_codes": sorted({r["exit_code"] for r in runs}), "wall_runs_s": [r["wall_s"] for r in runs]}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--runs", type=int, default=5, help="measured runs per command (default 5)")
    ap.add_argument("--before", type=Path, help="a second source tree to measure the same way (e.g. the base commit)")
    args = ap.parse_args()
    runs = 1 if args.quick else args.runs
    trees = {"after": ROOT} | ({"before": args.before.resolve()} if args.before else {})
    result: dict = {"profile": PROFILE, "runs_per_command": runs, "warmup_runs_per_command": 1,
                    "trees": {k: str(v) for k, v in trees.items()}, "commands": {}, "run": run_info()}
    with tempfile.TemporaryDirectory(prefix="rigcad-startup-") as tmp:
        scratch = Path(tmp)
        plans = {label: commands(scratch, label, args.quick) for label in trees}
        for name in plans["after"]:
            samples: dict[str, list[dict]] = {label: [] for label in trees}
            for i in range(runs + 1):  # the first round warms up (and builds the exports stl_unchanged reads)
                for label, tree in trees.items():
                    cmd, expected = plans[label][name]
                    res = measured(cmd, tree)
                    if res["exit_code"] != expected:
                        raise SystemExit(f"{label} {name}: exit {res['exit_code']}, expected {expected}:\n"
                                         + res["output"][-2000:])
                    if i:
                        samples[label].append(res)
            cmd = plans["after"][name][0]
            shown = ["rigcad", *cmd[len(RIGCAD):]] if cmd[:len(RIGCAD)] == RIGCAD else \
                [Path(c).name if c == sys.executable else c for c in cmd]
            entry = {"command": " ".join(shown).replace(str(scratch), "SCRATCH")}
            entry |= {label: summary(s) for label, s in samples.items()}
            if name in TARGETS_S:
                entry["target_wall_s"] = TARGETS_S[name]
            if name == "refused":
                entry["message"] = samples["after"][0]["output"].strip().replace(str(scratch), "SCRATCH")
            result["commands"][name] = entry
            print(f"{name:<15}" + "".join(f"  {label}: median {entry[label]['wall_median_s']:.3f} s wall, "
                                           f"{entry[label]['cpu_median_s']:.3f} s CPU" for label in trees), flush=True)
    result["run_end"] = run_info()
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "startup.json", result))


if __name__ == "__main__":
    main()
