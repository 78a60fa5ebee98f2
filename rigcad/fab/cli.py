"""`rigcad fab PROFILE --printer NAME [--exports DIR] [--gcode] [--parts ...] [--jobs N]`:
the fabrication stage from the command line. Wired into rigcad.cli by :func:`register`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def cmd_fab(args: argparse.Namespace) -> int:
    from rigcad.fab.printers import load_printer
    from rigcad.fab.stage import run_fab
    from rigcad.export.atomic import profile_lock
    from rigcad.rig import load

    rig = load(args.profile)
    profile = rig.profile
    printer = load_printer(args.printer)
    out = Path(args.exports) / profile.name / "fab" / printer.name
    res = run_fab(rig, printer, out, gcode=args.gcode, parts=args.parts, workers=args.jobs,
                  lock=profile_lock(args.exports, profile.name),
                  progress=lambda msg: print(f"  {msg}", file=sys.stderr) if args.verbose else None)
    tot = res.report["totals"]
    print(f"fab {profile.name} on {printer.name}: {tot['pieces']} pieces -> {out}/ (fab.json, fab.md)")
    for name, e in res.report["parts"].items():
        if "pieces" in e:
            orient = ", ".join(sorted({pc["orientation"] for pc in e["pieces"]}))
            sm = e.get("staircase_map")
            extra = f"; mirror cusp mean {sm['cusp_mean_mm']:.3f} mm, max {sm['cusp_max_mm']:.3f} mm" if sm else ""
            print(f"  {name}: {len(e['pieces'])} piece(s), {orient}, {e['layers_total']} layers{extra}")
        elif "error" not in e:
            print(f"  {name}: outlines/{name}.dxf, .svg")
    if args.timings:
        for k, v in sorted(res.timings_s.items()):
            print(f"  time {k}: {v:.2f} s")
        for k, v in sorted(res.slicer_s.items()):
            print(f"  slicer {k}: {v:.2f} s")
    for p in res.problems:
        print(f"rigcad: fab: {p}", file=sys.stderr)
    return 1 if res.problems else 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add the `fab` command to rigcad's subparsers (rigcad.cli.build_parser)."""
    from rigcad.fab.printers import available_printers

    p = subparsers.add_parser(
        "fab", help="fabrication: fit/split, print orientation, staircase, G-code, cutting outlines, report",
        description="Fit every part to a printer (splitting it into pinned pieces when it does not fit), orient "
                    "each piece for the least staircase on its mirror, slice it in-process (layers, staircase map, "
                    "polishing allowance, optical effect), write STL in print position, G-code through PrusaSlicer "
                    "(--gcode), DXF/SVG outlines of the templates, fab.json and fab.md into "
                    "exports/<profile>/fab/<printer>/.",
        epilog="printers: " + ", ".join(available_printers()) + "; parts: as for `rigcad build --help`")
    p.add_argument("profile", help="profile name (under profiles/) or path")
    p.add_argument("--printer", required=True, help="printer name (under profiles/printers/) or path")
    p.add_argument("--exports", default="exports", help="output root (default: exports)")
    p.add_argument("--gcode", action="store_true", help="also slice with PrusaSlicer (printers with slicer: prusa-slicer)")
    p.add_argument("--parts", nargs="+", metavar="PART", help="only these parts (default: all)")
    p.add_argument("--jobs", type=int, default=None, help="slicer processes at once (default: cores, at most 4)")
    p.add_argument("--timings", action="store_true", help="print the time of each stage and slicer run")
    p.add_argument("-v", "--verbose", action="store_true", help="name each part as it is processed")
    p.set_defaults(func=cmd_fab)
    return p
