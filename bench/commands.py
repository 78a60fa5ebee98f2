"""Each command of the chain a user runs, on the default profile: into a fresh exports folder, then
run again with nothing changed; wall time, CPU and the stage that dominates each run.

The chain, in order, into one empty exports folder: ``stl``, ``check``, ``fab --printer
prusa_mk3s``, ``manual --printer prusa_mk3s``, ``calibrate --kit``, ``view``; then the same six
again, in the same order, into the same folder (``rerun``). Every command is the console script
(``.venv/bin/rigcad``) as a child process, reaped with os.wait4 (wall, user and system CPU, peak
RSS). Where it is: the child runs with ``RIGCAD_EVENTS`` set, so each progress step it reports
comes as a line ``rigcad-event: <label>`` on stderr; each line is stamped as it arrives, and a
step's time is the gap since the line before it (the first one: since the start, which includes
Python's start-up, the imports and loading the profile). The step with the largest gap is the
one that dominates. A command that reports no steps (``check``, run with ``-v``) is read by the
stage times it prints itself instead.

The code is hashed at the start and recorded (``rigcad``): a stage whose code changed redoes its
work, so in a working tree others edit, run it on a snapshot (``git archive HEAD rigcad | tar -x
-C SNAP`` and ``PYTHONPATH=SNAP``), whose path is recorded too.

Run from the repository root: ``.venv/bin/python bench/commands.py [--out DIR] [--quick]``
(``--quick``: ``stl`` and ``fab --parts beam`` only, for the smoke test). Writes commands.json.
Timings vary run to run (keys ending in ``_s``) and depend on the machine's other load, recorded
in ``run`` and ``run_end``; never asserted.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import ROOT, arguments, run_info

import rigcad
from rigcad.export import reuse
from rigcad.export.atomic import write_json
from rigcad.progress import EVENTS_ENV

RIGCAD = str(Path(sys.executable).parent / "rigcad")
PROFILE = "achutha2006"
PRINTER = "prusa_mk3s"
CHAIN = {
    "stl": ["stl", PROFILE],
    "check": ["check", PROFILE, "-v"],  # -v: its stages' times ("time <stage>: <s> s"); it reports no steps
    "fab": ["fab", PROFILE, "--printer", PRINTER],
    "manual": ["manual", PROFILE, "--printer", PRINTER],
    "calibrate_kit": ["calibrate", PROFILE, "--kit"],
    "view": ["view", PROFILE],
}
QUICK = {"stl": ["stl", PROFILE], "fab_beam": ["fab", PROFILE, "--printer", PRINTER, "--parts", "beam"]}
EVENT = "rigcad-event: "
#: A stage's time as a command prints it itself (check -v, fab --timings): "  time <stage>: <s> s".
TIME_LINE = re.compile(r"^\s*time (.+): ([0-9.]+) s$")


def timed_run(args: list[str], exports: Path) -> dict:
    """One command as a child: wall, user and system CPU (s), peak RSS (KiB), exit code, each
    progress step's time (s, in order) and the dominating step."""
    env = dict(os.environ, **{EVENTS_ENV: "1"})
    steps: list[tuple[str, float]] = []
    with tempfile.TemporaryFile() as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen([RIGCAD, *args, "--exports", str(exports)], cwd=ROOT, env=env, stdout=out,
                                stderr=subprocess.PIPE, text=True, errors="replace")
        last, other = t0, []
        for line in proc.stderr:  # stamped as each arrives
            now = time.perf_counter()
            if line.startswith(EVENT):
                steps.append((line[len(EVENT):].strip(), now - last))
                last = now
            else:
                other.append(line)
        _, status, ru = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        stdout = out.read().decode(errors="replace")
    if steps:
        steps.append(("(after the last step)", t0 + wall - last))
    else:  # no steps reported: the stages' times the command printed, if any
        steps = [(m.group(1), float(m.group(2))) for m in map(TIME_LINE.match, other) if m]
    top = max(steps, key=lambda s: s[1]) if steps else None
    return {"command": f"rigcad {' '.join(args)}", "wall_s": wall, "user_s": ru.ru_utime, "system_s": ru.ru_stime,
            "peak_rss_kb": ru.ru_maxrss, "exit_code": proc.returncode,
            "steps_s": [{"step": name, "s": dt} for name, dt in steps],
            "dominating_step": None if top is None else {"step": top[0], "s": top[1], "share": top[1] / wall},
            "output_tail": (stdout + "".join(other))[-600:]}


def main() -> None:
    ap = arguments(__doc__)
    args = ap.parse_args()
    chain = QUICK if args.quick else CHAIN
    result = {"profile": PROFILE, "printer": PRINTER, "run": run_info(), "commands": {},
              "rigcad": {"tree": str(Path(rigcad.__file__).parent), "code_sha256_16": reuse.running_code()}}
    with tempfile.TemporaryDirectory(prefix="rigcad-bench-commands-") as tmp:
        exports = Path(tmp) / "exports"
        for label in ("fresh", "rerun"):
            for name, cmd in chain.items():
                rec = timed_run(cmd, exports)
                result["commands"].setdefault(name, {})[label] = rec
                top = rec["dominating_step"]
                print(f"{label:6s} {name:14s} {rec['wall_s']:7.2f} s wall, {rec['user_s'] + rec['system_s']:7.2f} s CPU"
                      + (f"; most: {top['step']} {top['s']:.2f} s" if top else "")
                      + ("" if rec["exit_code"] == 0 else f"; EXIT {rec['exit_code']}: {rec['output_tail'][-200:]}"),
                      flush=True)
    result["run_end"] = run_info()
    for label in ("fresh", "rerun"):
        result[f"chain_{label}_wall_s"] = sum(c[label]["wall_s"] for c in result["commands"].values())
    print(write_json(args.out / "commands.json", result))


if __name__ == "__main__":
    main()
