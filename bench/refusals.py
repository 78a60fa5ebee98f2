"""How long rigcad takes to refuse a count or argument no machine could serve, and how much memory
the refusal costs.

Run from the repository root: ``.venv/bin/python bench/refusals.py``. Writes
bench/results/refusals.json and refusals.png. Each command runs in its own process, started by a
small launcher (Linux keeps a forked child's peak RSS over exec, so a large parent would inflate
it), in three timed parts: importing rigcad's command-line modules (``import_s``), then ``main``
up to the refusal (``refusal_s``: what the requirement "within 1 s of the command's start, apart
from the import time" bounds); the peak RSS of the whole process (``peak_rss_kb``, wait4) is what
"far under 2 GB" bounds. Timings are not asserted (tests/test_cli_limits.py checks the refusals
themselves, before the rig is built, and their memory).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import ROOT, arguments, png, pyplot, run_info

from rigcad.export.atomic import write_bytes, write_json

COMMANDS = [
    ["check", "achutha2006", "--rays", "300000000"],
    ["check", "achutha2006", "--builds", "1000000000"],
    ["check", "achutha2006", "--rays", "-1"],
    ["view", "achutha2006", "--rays", "100000000"],
    ["tolerance", "achutha2006", "--samples", "1000000000000"],
    ["tolerance", "achutha2006", "--rays", "1000000000000"],
    ["sweep", "achutha2006", "--set", "layout.cop_to_vertex=25cm..35cm:100000000"],
    ["design", "achutha2006", "--exports", ""],
]
#: The child: times its imports and main() apart, prints them as JSON on stderr's last line.
CHILD = """
import json, sys, time
t0 = time.perf_counter()
import rigcad.cli, rigcad.engine, rigcad.profile, rigcad.cli.check, rigcad.cli.tolerance, rigcad.cli.manual
t1 = time.perf_counter()
try:
    code = rigcad.cli.main(sys.argv[1:])
except SystemExit as stop:
    code = stop.code
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "refusal_s": t2 - t1, "exit": code}), file=sys.stderr)
"""
LAUNCHER = ("import os, subprocess, sys; p = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL); "
            "_, status, usage = os.wait4(p.pid, 0); print(usage.ru_maxrss)")


def measure(argv: list[str], home: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(home))
    proc = subprocess.run([sys.executable, "-c", LAUNCHER, sys.executable, "-c", CHILD, *argv],
                          capture_output=True, text=True, env=env, cwd=home, timeout=600)
    lines = proc.stderr.strip().splitlines()
    figures = json.loads(lines[-1])
    return {"command": "rigcad " + " ".join(repr(a) if not a else a for a in argv), "message": lines[-2] if len(lines) > 1 else "",
            "exit_code": figures["exit"], "import_s": figures["import_s"], "refusal_s": figures["refusal_s"],
            "peak_rss_kb": int(proc.stdout.split()[-1])}


def main() -> None:
    args = arguments(__doc__).parse_args()
    commands = COMMANDS[:2] if args.quick else COMMANDS
    with tempfile.TemporaryDirectory() as tmp:
        rows = [measure(c, Path(tmp)) for c in commands]
    out = args.out
    data = {"run": run_info(), "rows": rows,
            "max_refusal_s": max(r["refusal_s"] for r in rows),
            "max_peak_rss_kb": max(r["peak_rss_kb"] for r in rows)}
    write_json(out / "refusals.json", data)
    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 0.5 * len(rows) + 1.8), sharey=True)
    names = [r["command"].replace("rigcad ", "").replace("achutha2006 ", "") for r in rows]
    y = list(range(len(rows)))
    a.barh(y, [r["import_s"] for r in rows], color="0.7", label="import")
    a.barh(y, [r["refusal_s"] for r in rows], left=[r["import_s"] for r in rows], color="C3", label="to the refusal")
    a.axvline(0, color="k", lw=0.5)
    a.set_yticks(y, names, fontsize=7)
    a.set_xlabel("time (s)")
    a.legend(fontsize=7)
    b.barh(y, [r["peak_rss_kb"] / 1024 for r in rows], color="C0")
    b.axvline(2048, color="k", ls="--", lw=0.8)
    b.set_xlabel("peak RSS (MB); dashed: 2 GB")
    fig.suptitle(f"refusals (load average {data['run']['loadavg_1min']})", fontsize=9)
    fig.tight_layout()
    write_bytes(out / "refusals.png", png(fig))
    for r in rows:
        print(f"{r['command']:<80} import {r['import_s']:.2f} s, refusal {r['refusal_s']:.3f} s, "
              f"peak {r['peak_rss_kb'] / 1024:.0f} MB, exit {r['exit_code']}")


if __name__ == "__main__":
    main()
