"""``rigcad stl PROFILE`` (``make stl``): design + build, returning at once when nothing changed."""

from __future__ import annotations

import argparse
from rigcad import api
from rigcad.cli.build import part_lines
from rigcad.export.atomic import check_exports
from rigcad.progress import stages


def cmd_stl(args: argparse.Namespace) -> int:
    """The main job: design + build, returning at once when nothing changed since the last run."""
    from rigcad.profile import load_profile

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name)
    out = api.default_folder(profile.name, root=args.exports)
    from rigcad.manual import gate

    if api.export_up_to_date(profile, out):
        kept = gate.read_verdict(args.exports, profile)
        if kept is not None:
            print(f"{profile.name}: up to date ({out}/manifest.json)")
            return max(_verdict_exit(kept), _criteria_exit(profile, args.exports))  # no rig while the criteria are kept
    from rigcad.parts import PARTS
    from rigcad.rig import Rig

    with stages(len(PARTS) + 7, f"stl {profile.name}") as step:
        rig = Rig.from_profile(profile)
        step("dome integrated")
        rig.design  # traced here, for the progress bar; the export reuses it
        step("design traced")
        result = api.export(rig, out, progress=step)
        verdict = gate.checked(rig, args.exports, progress=step)
        step("assembly checked")
    env = rig.design.report["envelope"]
    print(f"{profile.name}: dome mirror {env['width_in']:.2f} x {env['height_in']:.2f} in; "
          f"{len(result.rebuilt)} part(s) built, {len(result.reused)} unchanged -> {out}/")
    print("\n".join(part_lines(result, list(PARTS))))
    return max(_verdict_exit(verdict), _criteria_exit(rig, args.exports))


def _criteria_exit(rig, exports) -> int:
    """1 when the rig (a Rig, or a loaded Profile: rigcad.cli.check.criteria_refusal) fails the ray
    check's criteria (its lines, the parts written for inspection only), else 0 with a note of what
    was not judged."""
    from rigcad.cli.check import criteria_notes, criteria_refusal

    verdict = criteria_refusal(rig, exports, "stl", written=True)
    criteria_notes(verdict)
    return 0 if verdict.ok else 1


def _verdict_exit(verdict) -> int:
    """0 when the assembly check finds an order; else its one line (the parts stay written, for
    inspection) and exit code 1."""
    import sys

    from rigcad.errors import one_line

    if verdict.ok:
        return 0
    print(f"rigcad: error: {one_line(verdict.line())}; the parts are written for inspection only: do not print "
          "them", file=sys.stderr)
    return 1


def register(subparsers) -> None:
    """Add ``stl`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    p = profile_command(
        subparsers, "stl", cmd_stl,
        help="the main job (make stl): design + build, skipped when nothing changed",
        description="Run `design` then `build` for every part, recording the inputs' hash in manifest.json; "
                    "when the profile and rigcad's code are unchanged and every listed file is intact, "
                    "return at once.")
