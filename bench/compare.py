"""make bench's verdict: every speed ratio the benchmarks measure within one run, compared with the
committed figure.

A ratio taken inside one run (a reading against raw Embree on the same rays, round by round; the
adaptive integrator against Euler; two workers against one) compares two timings taken under the
same load, so the machine's noise mostly cancels in it, unlike a time alone. Each one listed in
:data:`RATIOS` (higher is better for all of them) is read from the run's results folder and from
bench/results (the committed figures); a measured ratio more than :data:`DROP` below the committed
one is a regression. A ratio the run did not measure (its script not run, or no such entry) is
said so, never counted as passing.

The committed figures change only when a run says so: ``--refresh`` copies the run's JSON and PNG
files over bench/results after the comparison (``make bench REFRESH=1``); without it nothing
under bench/results is written.

Usage, from the repository root: ``.venv/bin/python bench/compare.py MEASURED_DIR [--results DIR]
[--refresh] [--json PATH]``. Exit status 1 when a ratio regressed and the run did not refresh.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import RESULTS  # noqa: E402

#: A measured ratio below (1 - DROP) x the committed one is a regression (the issue's 10 %).
DROP = 0.10

#: (name, results file, path to the ratio inside it, what it compares). A path element (key, value)
#: picks the list item whose ``key`` is ``value``.
RATIOS = [
    ("raycheck.smooth", "raycheck.json", ("readings", "smooth", "raw_over_reading"),
     "raw Embree / smooth mesh reading, same rays, median of paired rounds"),
    ("raycheck.mesh", "raycheck.json", ("readings", "mesh", "raw_over_reading"),
     "raw Embree / flat-facet mesh reading, same rays, median of paired rounds"),
    ("raycheck.analytic_aligned", "raycheck.json", ("readings", "analytic_aligned", "raw_over_reading"),
     "raw Embree / analytic tracer, aligned rig"),
    ("raycheck.analytic_misaligned", "raycheck.json", ("readings", "analytic_misaligned", "raw_over_reading"),
     "raw Embree / analytic tracer, misaligned rig"),
    ("raycheck.smooth_cpu", "raycheck.json", ("readings", "smooth", "raw_over_reading_cpu"),
     "the same in CPU time (time.process_time), which leaves out waiting for a core"),
    ("raycheck.mesh_cpu", "raycheck.json", ("readings", "mesh", "raw_over_reading_cpu"),
     "the same in CPU time"),
    ("raycheck.analytic_aligned_cpu", "raycheck.json", ("readings", "analytic_aligned", "raw_over_reading_cpu"),
     "the same in CPU time"),
    ("raycheck.analytic_misaligned_cpu", "raycheck.json", ("readings", "analytic_misaligned", "raw_over_reading_cpu"),
     "the same in CPU time"),
    ("dome.table31", "dome.json", ("cases", ("case", "table31"), "speedup_at_1e-6_relative", "speedup"),
     "Euler time / adaptive integrator time at 1e-6 relative, Table 3.1"),
    ("dome.far_cop_ellipse", "dome.json", ("cases", ("case", "far_cop_ellipse"), "speedup_at_1e-6_relative", "speedup"),
     "Euler time / adaptive integrator time at 1e-6 relative, far-COP ellipse"),
    ("tolerance.loky", "tolerance.json", ("engines", "2 loky workers", "speed_up_over_one_worker"),
     "Monte Carlo: one worker's time / two loky workers'"),
    ("tolerance.dask", "tolerance.json", ("engines", "Dask LocalCluster, 2 workers", "speed_up_over_one_worker"),
     "Monte Carlo: one worker's time / two Dask workers'"),
    ("optimize.evaluation", "optimize.json", ("evaluation", "speedup_vs_certified"),
     "certified design evaluation time / the optimiser's evaluation"),
    ("optimize.two_workers", "optimize.json", ("optimize", "speedup_2_workers"),
     "rigcad optimize: serial time / two workers'"),
]


def lookup(doc, path):
    """The value at ``path`` in the JSON ``doc`` (see :data:`RATIOS`), or None when it is not there
    or not a positive number."""
    node = doc
    for step in path:
        if isinstance(step, tuple):
            key, value = step
            node = next((item for item in node if isinstance(item, dict) and item.get(key) == value), None) \
                if isinstance(node, list) else None
        else:
            node = node.get(step) if isinstance(node, dict) else None
        if node is None:
            return None
    if isinstance(node, bool) or not isinstance(node, (int, float)) or not node > 0:
        return None
    return float(node)


def _read(path: Path):
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def compare(measured: Path, committed: Path) -> list[dict]:
    """One row per ratio of :data:`RATIOS`: name, what it compares, the committed and measured
    values (None when absent), measured / committed, and the verdict (``ok``, ``regression``,
    ``not measured``, ``new``: no committed figure)."""
    rows = []
    for name, file, path, what in RATIOS:
        new_doc, old_doc = _read(measured / file), _read(committed / file)
        new = lookup(new_doc, path) if new_doc is not None else None
        old = lookup(old_doc, path) if old_doc is not None else None
        if new is None:
            verdict = "not measured"
        elif old is None:
            verdict = "new"
        else:
            verdict = "regression" if new < (1 - DROP) * old else "ok"
        rows.append({"name": name, "file": file, "compares": what, "committed": old, "measured": new,
                     "measured_over_committed": new / old if new is not None and old is not None else None,
                     "verdict": verdict, "cpu_committed": _cpu(old_doc), "cpu_measured": _cpu(new_doc)})
    return rows


def _cpu(doc) -> str | None:
    """The CPU model a results file was measured on (bench/_common.run_info), None when unrecorded."""
    run = doc.get("run") if isinstance(doc, dict) else None
    return run.get("cpu_model") if isinstance(run, dict) else None


def cpu_notes(rows: list[dict]) -> list[str]:
    """One line per results file whose committed figures were measured on another CPU, or on one
    not recorded: a ratio of two codes' times moves with the CPU, so such a drop may be the CPU's."""
    notes = {}
    for r in rows:
        if r["verdict"] in ("ok", "regression") and r["cpu_committed"] != r["cpu_measured"]:
            notes[r["file"]] = (f"note: {r['file']}: committed on {r['cpu_committed'] or 'a CPU not recorded'}, "
                                f"measured on {r['cpu_measured'] or 'a CPU not recorded'}; a ratio moves with the "
                                "CPU: compare on the CPU the figures were committed on, or refresh them there")
    return list(notes.values())


def refresh(measured: Path, committed: Path) -> list[Path]:
    """Copy every JSON and PNG of the run over the committed results; the paths written."""
    written = []
    committed.mkdir(parents=True, exist_ok=True)
    for src in sorted([*measured.glob("*.json"), *measured.glob("*.png")]):
        if src.name == "compare.json":
            continue  # this script's own record of the run, not a benchmark's result
        shutil.copyfile(src, committed / src.name)
        written.append(committed / src.name)
    return written


def table(rows: list[dict]) -> str:
    def fmt(v):
        return "-" if v is None else f"{v:.3g}"

    lines = [f"{'ratio':30s} {'committed':>10s} {'measured':>10s} {'change':>8s}  verdict"]
    for r in rows:
        change = "-" if r["measured_over_committed"] is None else f"{r['measured_over_committed'] - 1:+.0%}"
        verdict = r["verdict"].upper() if r["verdict"] == "regression" else r["verdict"]
        lines.append(f"{r['name']:30s} {fmt(r['committed']):>10s} {fmt(r['measured']):>10s} {change:>8s}  {verdict}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("measured", type=Path, help="the run's results folder (make bench: build/bench)")
    ap.add_argument("--results", type=Path, default=RESULTS, help="the committed results (default: bench/results)")
    ap.add_argument("--refresh", action="store_true",
                    help="after comparing, copy the run's JSON and PNG files over the committed results")
    ap.add_argument("--json", type=Path, help="also write the comparison here (default: MEASURED/compare.json)")
    args = ap.parse_args(argv)
    if args.measured.resolve() == args.results.resolve():
        print(f"bench/compare.py: the run's folder is the committed results ({args.results}); "
              "run the benchmarks with --out elsewhere (make bench: build/bench)", file=sys.stderr)
        return 2
    rows = compare(args.measured, args.results)
    print("\n".join([table(rows), *cpu_notes(rows)]))
    out = args.json or args.measured / "compare.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"drop_limit": DROP, "ratios": rows}, indent=2, sort_keys=True) + "\n")
    bad = [r["name"] for r in rows if r["verdict"] == "regression"]
    if args.refresh:
        written = refresh(args.measured, args.results)
        print(f"refreshed {len(written)} committed result files in {args.results}/ from {args.measured}/"
              + (f" (accepting the drop of {', '.join(bad)})" if bad else ""))
        return 0
    if bad:
        print(f"REGRESSION: {', '.join(bad)} dropped more than {DROP:.0%} below the committed figure "
              f"({args.results}/); if the drop is understood, `make bench REFRESH=1` records the new figures",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
