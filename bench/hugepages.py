"""numpy's huge-page advice on and off, side by side: the same rigcad command in fresh processes,
``NUMPY_MADVISE_HUGEPAGE=1`` (numpy's default) and ``0`` (rigcad's: rigcad.cli.main.process_defaults),
runs interleaved so both see the same load. Each run is reaped with os.wait4: wall time, the
child's user and system CPU time, its peak memory. The outputs of the two settings are compared
byte for byte (the files that carry no timing).

Run from the repository root: ``.venv/bin/python bench/hugepages.py [--runs 2]``. Writes
bench/results/hugepages.json, with the kernel's transparent huge page settings (what decides the
result: with ``defrag`` at ``madvise`` a fault in advised memory may stall on compaction).

The command: ``rigcad calibrate achutha2006 --simulate --seed 5`` (render a capture and calibrate
it: many large temporaries); ``--quick``: ``rigcad design achutha2006``.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
from pathlib import Path

from _common import ROOT, arguments, reaped, run_info

from rigcad.export.atomic import write_json

RIGCAD = [sys.executable, "-c", "import sys; from rigcad.cli.main import main; sys.exit(main())"]
SETTINGS = {"numpy_default_advised": "1", "rigcad_default_not_advised": "0"}
#: Files each command writes that carry no timing: compared byte for byte between the settings.
COMPARED = {"calibrate": ("calibrate/corrected_map.npz",), "design": ("dome_profile.csv",)}
THP = Path("/sys/kernel/mm/transparent_hugepage")


def thp_settings() -> dict:
    """The kernel's transparent huge page settings (the bracketed choice of each), where it has them."""
    out = {}
    for name in ("enabled", "defrag"):
        try:
            text = (THP / name).read_text()
        except OSError:
            continue
        out[name] = text[text.index("[") + 1:text.index("]")] if "[" in text else text.strip()
    return out


def measured(cmd: list[str], value: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMPY_MADVISE_HUGEPAGE": value}
    res = reaped(cmd, env=env)
    if res["exit_code"]:
        raise SystemExit(f"NUMPY_MADVISE_HUGEPAGE={value}: exit {res['exit_code']}:\n{res['output'][-2000:]}")
    return {k: res[k] for k in ("wall_s", "user_s", "system_s", "peak_rss_kb")}


def summary(runs: list[dict]) -> dict:
    return {"wall_median_s": statistics.median(r["wall_s"] for r in runs),
            "user_median_s": statistics.median(r["user_s"] for r in runs),
            "system_median_s": statistics.median(r["system_s"] for r in runs),
            "peak_rss_max_kb": max(r["peak_rss_kb"] for r in runs), "wall_runs_s": [r["wall_s"] for r in runs]}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--runs", type=int, default=2, help="measured runs per setting (default 2)")
    args = ap.parse_args()
    command = "design" if args.quick else "calibrate"
    extra = [] if args.quick else ["--simulate", "--seed", "5"]
    result: dict = {"command": f"rigcad {command} achutha2006 {' '.join(extra)}".strip(),
                    "transparent_hugepage": thp_settings(), "runs_per_setting": args.runs, "run": run_info()}
    samples: dict[str, list[dict]] = {name: [] for name in SETTINGS}
    with tempfile.TemporaryDirectory(prefix="rigcad-hugepages-") as tmp:
        for i in range(args.runs):
            for name, value in SETTINGS.items():
                out = Path(tmp) / f"{name}_{i}"
                samples[name].append(measured([*RIGCAD, command, "achutha2006", *extra, "--exports", str(out)], value))
                print(f"run {i} {name}: {samples[name][-1]['wall_s']:.1f} s wall, "
                      f"{samples[name][-1]['system_s']:.1f} s system", flush=True)
        first = {name: Path(tmp) / f"{name}_0" / "achutha2006" for name in SETTINGS}
        result["same_outputs"] = {f: len({(d / f).read_bytes() for d in first.values()}) == 1 for f in COMPARED[command]}
    result["settings"] = {name: {"NUMPY_MADVISE_HUGEPAGE": SETTINGS[name]} | summary(s) for name, s in samples.items()}
    on, off = (result["settings"][n] for n in SETTINGS)
    result["advised_over_not"] = {k: on[k] / off[k] for k in ("wall_median_s", "user_median_s", "system_median_s")
                                  if off[k] > 0}
    result["run_end"] = run_info()
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "hugepages.json", result))


if __name__ == "__main__":
    main()
