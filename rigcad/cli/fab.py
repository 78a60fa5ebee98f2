"""`rigcad fab PROFILE --printer NAME [--exports DIR] [--gcode] [--parts ...] [--jobs N]`:
the fabrication stage from the command line."""

from __future__ import annotations

import argparse
import sys

from rigcad.units import hours_minutes


def cmd_fab(args: argparse.Namespace) -> int:
    from rigcad.fab.printers import load_printer

    printer = load_printer(args.printer)  # first: a refused printer file costs no rig and no CAD kernel import
    _refuse_generic_gcode(printer, args.gcode)
    from rigcad import api
    from rigcad.export.build import select_parts
    from rigcad.progress import stages
    from rigcad.export.atomic import check_exports
    from rigcad.profile import load_profile
    from rigcad.rig import load

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "fab")  # a planted link or lock: one line now, not after the work
    names = select_parts(args.parts)  # a bad part name costs no rig
    from rigcad.cli.check import criteria_notes, criteria_refusal
    from rigcad.manual.gate import gate, kept_gate

    out = api.default_folder(profile.name, "fab", printer.name, root=args.exports)
    criteria = criteria_refusal(profile, args.exports, "fab")  # the rig built only when its criteria are not kept
    if not criteria.ok:  # a rig that fails its own check gets no print files
        return 1
    # a verdict and a fab run both kept from these inputs: read back, no rig built
    res = (api.fab_published(profile, printer, out, gcode=args.gcode, parts=args.parts)
           if kept_gate(args.exports, profile) else None)
    if res is None:
        rig = load(profile)
        gate(rig, args.exports)  # a rig that cannot be put together is refused before a piece is sliced
        with stages(len(names), f"fab {profile.name}") as step:
            def progress(msg: str) -> None:
                step(msg)
                if args.verbose:
                    print(f"  {msg}", file=sys.stderr)

            res = api.fab(rig, printer, out, gcode=args.gcode, parts=args.parts, workers=args.jobs,
                          progress=progress, slicing=lambda total: stages(total, f"slicing ({printer.slicer})"))
    tot = res.report["totals"]
    print(f"fab {profile.name} on {printer.name}: {tot['pieces']} pieces -> {out}/ (fab.json, fab.md)")
    if args.gcode and printer.slicer_config is not None:  # which machine the G-code is for, never silently another's
        print(_gcode_line(printer))
    for name, e in res.report["parts"].items():
        if "pieces" in e:
            orient = ", ".join(sorted({pc["orientation"] for pc in e["pieces"]}))
            sm = e.get("staircase_map")
            extra = f"; mirror cusp mean {sm['cusp_mean_mm']:.3f} mm, max {sm['cusp_max_mm']:.3f} mm" if sm else ""
            st = e.get("sanding_stock")
            extra += f"; printed {st['stock_mm']:.3f} mm forward (sanding stock)" if st else ""
            sliced = [pc["gcode"] for pc in e["pieces"] if "gcode" in pc]
            if sliced and len(sliced) == len(e["pieces"]):
                t = sum(g["estimates"].get("print_time_s", 0) for g in sliced)
                g_ = sum(g["estimates"].get("filament_g", 0) for g in sliced)
                extra += f"; slicer {hours_minutes(t)}, {g_:.0f} g"
                sc = [g["support_contact"] for g in sliced if "support_contact" in g]
                if sc and (e.get("mirror") or any(c["other_mm2"] for c in sc)):
                    extra += (f"; support contact mirror {sum(c['mirror_mm2'] for c in sc):.0f} mm2, "
                              f"other {sum(c['other_mm2'] for c in sc):.0f} mm2")
            else:
                est = sum(pc["estimate"]["print_time_s"] for pc in e["pieces"])
                extra += f"; est. {hours_minutes(est)}, {sum(pc['estimate']['material_g'] for pc in e['pieces']):.0f} g"
            print(f"  {name}: {len(e['pieces'])} piece(s), {orient}, {e['layers_total']} layers{extra}")
        elif e.get("process") == "bought":
            print(f"  {name}: bought, not printed ({e['stock']})")
        elif "error" not in e:
            print(f"  {name}: outlines/{name}.dxf, .svg" + (" (+ _printed, _sanded stages)" if "stages" in e else ""))
    print(total_line(res.report, printer))
    if args.timings:
        for k, v in sorted(res.timings_s.items()):
            print(f"  time {k}: {v:.2f} s")
        for k, v in sorted(res.slicer_s.items()):
            print(f"  slicer {k}: {v:.2f} s")
    criteria_notes(criteria)
    for p in res.problems:
        print(f"rigcad: fab: {p}", file=sys.stderr)
    if res.problems:  # the verdict, on one line of its own: the problems above are its details
        print(f"rigcad: error: fab found {len(res.problems)} problem(s), listed above; the outputs are written, "
              f"with the problems in {out}/fab.json", file=sys.stderr)
    return 1 if res.problems else 0


def _gcode_line(printer) -> str:
    """Whose PrusaSlicer presets the G-code is made with: the preset, its printer_model, a stand-in's why."""
    cfg = printer.slicer_config
    model = cfg.effective().get("printer_model")
    return (f"  G-code with PrusaSlicer's presets {cfg.printer_preset or cfg.source}"
            + (f" (printer_model {model})" if model else "")
            + (f", standing in for the {printer.model}: {printer.stand_in}" if printer.stand_in else ""))


def _refuse_generic_gcode(printer, gcode: bool) -> None:
    """G-code asked of a printer with no presets (no start G-code, no temperatures): refused before
    the work (rigcad.fab.slicer.generic_refusal)."""
    if gcode and printer.slicer == "prusa-slicer" and printer.slicer_config is None \
            and printer.slicer_unavailable is None:
        from rigcad.errors import FabricationError
        from rigcad.fab.slicer import generic_refusal

        raise FabricationError(generic_refusal(printer))


def total_line(report: dict, printer) -> str:
    """The run's print time and material, with quantities: the slicer's wherever it ran, rigcad's
    estimate (rigcad.fab.estimate, its volume terms scaled by the printer's deposition_rate_mm3_s)
    only for the pieces no slicer ran on, and labelled so, with why."""
    pieces = [(pc, e.get("quantity", 1)) for e in report["parts"].values() for pc in e.get("pieces", [])]
    sliced = [(pc, q) for pc, q in pieces if pc.get("gcode", {}).get("estimates", {}).get("print_time_s")]
    rest = [(pc, q) for pc, q in pieces if not pc.get("gcode", {}).get("estimates", {}).get("print_time_s")]
    slicer_t = sum(pc["gcode"]["estimates"]["print_time_s"] * q for pc, q in sliced)
    slicer_g = sum(pc["gcode"]["estimates"].get("filament_g", 0) * q for pc, q in sliced)
    est_t = sum(pc["estimate"]["print_time_s"] * q for pc, q in rest)
    est_g = sum(pc["estimate"]["material_g"] * q for pc, q in rest)
    if printer.slicer != "prusa-slicer":
        why = f"{printer.name} has no slicer rigcad runs"
    elif not report.get("gcode", {}).get("requested"):
        why = "no slicer ran: --gcode for PrusaSlicer's own time"
    else:
        why = "not sliced: see the problems"
    from rigcad.fab.estimate import CALIBRATION

    rate = ""
    if printer.process == "fdm":  # the estimate's volume terms scale by the printer's rate (rigcad.fab.estimate)
        rate = (f", its volume terms at deposition_rate_mm3_s {printer.deposition_rate_mm3_s:g}"
                if printer.deposition_rate_mm3_s else
                f", at the {CALIBRATION['printer']} fit's {CALIBRATION['deposition_rate_mm3_s']:g} mm3/s: the printer "
                "states no deposition_rate_mm3_s")
    estimate = f"rigcad's estimate ({why}{rate})"
    if not sliced:
        return f"  total ({estimate}; with quantities): {hours_minutes(est_t)}, {est_g:.0f} g"
    line = (f"  total ({printer.slicer}, with quantities): {hours_minutes(slicer_t)}, {slicer_g:.0f} g filament"
            + (f" for {sum(q for _, q in sliced)} of {sum(q for _, q in pieces)} pieces" if rest else ""))
    if rest:
        line += f"; the other {sum(q for _, q in rest)} by {estimate}: {hours_minutes(est_t)}, {est_g:.0f} g"
    return line


def register(subparsers) -> argparse.ArgumentParser:
    """Add the `fab` command to rigcad's subparsers (rigcad.cli.main.build_parser)."""
    from rigcad.arguments import positive_int, profile_command
    from rigcad.profile.paths import PRINTERS_SUBDIR, names_on_search_path  # not fab.printers: no numpy for --help

    p = profile_command(
        subparsers, "fab", cmd_fab,
        help="fabrication: fit/split, print orientation, staircase, G-code, cutting outlines, report",
        description="Fit every part to a printer (splitting it into pinned pieces when it does not fit), orient "
                    "each piece for the least staircase on its mirror, slice it in-process (layers, staircase map, "
                    "polishing allowance, optical effect), write STL in print position, G-code through PrusaSlicer "
                    "(--gcode), DXF/SVG outlines of the templates, fab.json and fab.md into "
                    "exports/<profile>/fab/<printer>/.",
        epilog="printers: " + ", ".join(names_on_search_path(PRINTERS_SUBDIR)) + "; parts: as for `rigcad build --help`")
    p.add_argument("--printer", required=True, help="printer name (under profiles/printers/) or path")
    p.add_argument("--gcode", action="store_true", help="also slice with PrusaSlicer (printers with slicer: prusa-slicer)")
    p.add_argument("--parts", nargs="+", metavar="PART", help="only these parts (default: all)")
    p.add_argument("--jobs", type=positive_int, default=None, help="slicer processes at once (default: cores, at most 4)")
    p.add_argument("--timings", action="store_true", help="print the time of each stage and slicer run")
    p.add_argument("-v", "--verbose", action="store_true", help="name each part as it is processed")
    return p
