"""``rigcad sweep PROFILE --set SECTION.KEY=A..B:N``: one design per value of a key, on the same engine
as ``rigcad tolerance``; one row of design, check and printer-fit figures per design."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rigcad.cli.tolerance import checked_tolerance, engine_args, engine_from, engine_progress


def cmd_sweep(args: argparse.Namespace) -> int:
    from rigcad.profile.schema import check_override
    from rigcad.tolerance.sweep import finite_or_none, parse_set, run_sweep, sweep_csv

    spec = parse_set(args.set)
    engine = engine_from(args)
    checked_tolerance(len(spec.values), args.rays, engine, "--set (points)", "--rays", ("raycheck", "rays"))
    check_override("raycheck", "rays", args.rays, "--rays")
    from rigcad import plots
    from rigcad.progress import progress_bar
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.fab.printers import load_printer
    from rigcad.profile.loader import load_raw

    raw = load_raw(args.profile)
    from rigcad.export.atomic import check_exports

    check_exports(args.exports, raw.name, "sweep")  # a planted link or lock: one line now, not after the work
    printer = None if args.printer == "none" else load_printer(args.printer)
    t0 = time.perf_counter()
    with progress_bar(len(spec.values), f"sweep {spec.name} ({engine.name})", "design") as update:
        rows = run_sweep(raw, spec, args.rays, 2006, printer, engine, progress=engine_progress(update))
    wall = time.perf_counter() - t0
    out = Path(args.exports) / raw.name / "sweep" / spec.name
    scale = 1.0
    unit = spec.unit or "-"
    cols = [("dome_width_mm", "dome width (mm)"), ("check_max_spot_radius_mm", "max spot radius (mm)"),
            ("check_theta_min_deg", "traced theta min (deg)"), ("check_px_per_deg_min", "min px/deg")]
    if printer is not None:
        cols.append(("parts_to_split_count", f"parts to split ({printer.name})"))
    plot_rows = [dict(r, value=r["value"] * scale) for r in rows]
    files = {"sweep.csv": sweep_csv(spec, rows),
             "sweep.json": json_bytes({"key": spec.name, "unit": spec.unit, "values": list(spec.values),
                                       "rays": args.rays,
                                       "rows": [{k: finite_or_none(v) for k, v in r.items()} for r in rows]}),
             "sweep.png": plots.sweep_plot(spec.name, unit, plot_rows, cols)}
    with Staging(out, profile_lock(Path(args.exports), raw.name), carry=lambda rel: False) as stage:
        for name, data in files.items():
            stage.write_bytes(out / name, data)
        paths = stage.commit()
    good = [r for r in rows if r["ok"]]
    print(f"{raw.name}: {len(rows)} designs of {spec.name} on {engine.name} in {wall:.1f} s; "
          f"{len(good)} built, {len(rows) - len(good)} refused")
    for r in rows:
        if not r["ok"]:
            print(f"  {spec.name} = {r['value']:.6g} {spec.unit}: {r['error']}", file=sys.stderr)
    for p in paths:
        print(f"  wrote {p}")
    return 0


def register(subparsers) -> None:
    """Add ``sweep`` to rigcad's subcommands."""
    from rigcad.arguments import positive_int, profile_command

    s = profile_command(
        subparsers, "sweep", cmd_sweep,
        help="parameter sweep: one row per design (design, check and printer-fit figures)",
        description="Build one design per value of --set section.key=A..B:N (or v1,v2,...; units as in a "
                    "profile, e.g. layout.cop_to_vertex=25cm..35cm:21) on the same engine as tolerance; write "
                    "exports/<profile>/sweep/<key>/{sweep.csv, sweep.json, sweep.png}.")
    s.add_argument("--set", required=True, metavar="SECTION.KEY=A..B:N", help="the swept key and its values")
    s.add_argument("--rays", type=positive_int, default=20000, help="pinhole rays of each design's check (default 20000)")
    s.add_argument("--printer", default="prusa_mk3s", help="printer for the fit column, or 'none' (default prusa_mk3s)")
    engine_args(s)
