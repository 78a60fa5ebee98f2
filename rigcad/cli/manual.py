"""``rigcad manual PROFILE --printer NAME``: the assembly and calibration manual, after ``rigcad fab``
for that printer (run again when its report is missing or stale)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def cmd_manual(args: argparse.Namespace) -> int:
    from rigcad import api
    from rigcad.export.atomic import check_exports, profile_lock
    from rigcad.fab.printers import load_printer
    from rigcad.manual.document import write_manual
    from rigcad.profile import load_profile
    from rigcad.progress import stages
    from rigcad.rig import load

    printer = load_printer(args.printer)  # a refused printer file costs no rig
    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "manual")  # a planted link or lock: one line now, not after the work
    back = api.manual_published(profile, printer, args.exports, args.gcode)
    if back is not None:  # the same inputs, fab run and check as the published manual: nothing redone, nothing written
        print(f"{profile.name}: manual for {printer.name} up to date in {Path(args.exports) / profile.name / 'manual'}"
              f"/{printer.name}/ ({len(back['files'])} files; nothing written)")
        for note in back.get("notes", []):
            print(f"note: {note}", file=sys.stderr)
        _parts_note(profile, args.exports)
        return 0
    rig = load(profile)
    from rigcad.cli.check import criteria_notes, criteria_refusal
    from rigcad.manual.gate import gate

    criteria = criteria_refusal(rig, args.exports, "manual")
    if not criteria.ok:  # a rig that fails its own check gets no manual
        return 1
    gate(rig, args.exports)  # a rig that cannot be put together gets no manual
    root = Path(args.exports) / rig.name
    total = len(rig.recipes) + 3 + sum(1 for p in [*rig.recipes.values(), *rig.instruments] if p.in_rig)
    with stages(total, f"manual {rig.name} ({printer.name})") as step:
        fab = _fab_report(api, rig, profile, printer, root / "fab" / printer.name, args.gcode, step)
        for problem in fab.problems:
            print(f"rigcad: fab: {problem}", file=sys.stderr)
        out = root / "manual" / printer.name
        from rigcad.errors import one_line
        from rigcad.export import reuse

        key = None if fab.problems else api.manual_key(profile, printer, args.exports, args.gcode)  # problems: never kept
        with reuse.recording(out, key, {"notes": [one_line(n) for n in criteria.notes]}):
            written = write_manual(rig, printer, fab.report, out, profile_lock(args.exports, rig.name), progress=step)
    html_path = out / "manual.html"
    print(f"{rig.name}: manual for {printer.name} -> {out}/ (manual.md, manual.html "
          f"{html_path.stat().st_size / 1e6:.1f} MB, {len(written)} files)")
    criteria_notes(criteria)
    _parts_note(profile, args.exports)
    if fab.problems:  # a manual whose bill glues what cannot be glued, or prints what fab refused, is no pass
        print(f"rigcad: error: fab found {len(fab.problems)} problem(s), listed above; the manual is written, "
              f"and follows {root / 'fab' / printer.name}/fab.json, which lists them", file=sys.stderr)
        return 1
    return 0


def _parts_note(profile, exports) -> None:
    """The note when the parts the manual refers to (STEP, STL: ``rigcad stl``) are missing or stale."""
    from rigcad.manual.document import parts_note

    note = parts_note(profile, exports)
    if note:
        print(f"note: {note}", file=sys.stderr)


def _fab_report(api, rig, profile, printer, folder: Path, gcode: bool, step):
    """The fab run the manual follows. Without ``gcode``, a sliced report is never replaced by an
    unsliced one: a run with the slicer's G-code published in ``folder`` from the same profile,
    printer and code (rigcad.api.fab_published: fresh and intact) is kept as it is, with its slicer
    figures and support table; a report there that was sliced but cannot be kept so (a run with
    problems is never read back, or its inputs changed) is made again with the slicer, whose G-code
    is cached per piece (only changed pieces are sliced). Otherwise the fab stage for ``gcode``
    (which reads back its own published run)."""
    from rigcad.export.readback import own_json
    from rigcad.optics.frames import Misalignment

    if not gcode and rig.misalignment == Misalignment.none():
        sliced = api.fab_published(profile, printer, folder, gcode=True, progress=step)
        if sliced is not None:
            return sliced
        old = own_json(folder / "fab.json")  # read as data: anything unreadable is no sliced report
        was = old.get("gcode") if isinstance(old, dict) else None
        if isinstance(was, dict) and was.get("requested") is True and was.get("slicer") == "prusa-slicer" \
                and printer.slicer == "prusa-slicer":
            print(f"rigcad: manual: {folder}/fab.json was made with the slicer's G-code (--gcode): made again "
                  "with it (cached per piece), not replaced by rigcad's estimate", file=sys.stderr)
            gcode = True
    return api.fab(rig, printer, folder, gcode=gcode, progress=step)


def register(subparsers) -> None:
    """Add ``manual`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    m = profile_command(
        subparsers, "manual", cmd_manual,
        help="assembly and calibration manual with the bill of materials, for a profile and a printer",
        description="Write exports/<profile>/manual/<printer>/: manual.md and manual.html (printable, self-contained) "
                    "with the bill of materials (printed pieces with time and filament from `rigcad fab`, bolts, "
                    "nuts, dowel pins, optics, paint and clearcoat volumes), the steps (print, sand, coat, "
                    "assemble with exploded views, calibrate as thesis 4.1.1) and the calibration image at the "
                    "projector's resolution. Runs `rigcad fab` for the printer when its report is missing or stale.")
    m.add_argument("--printer", required=True, help="printer name (under printers/ on the profile search path) or path")
    m.add_argument("--gcode", action="store_true",
                   help="slice the pieces with PrusaSlicer so that times and filament are the slicer's (cached "
                        "per piece); default: rigcad's estimate")
