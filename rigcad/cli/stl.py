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
    if api.export_up_to_date(profile, out):
        print(f"{profile.name}: up to date ({out}/manifest.json)")
        return 0
    from rigcad.parts import PARTS
    from rigcad.rig import Rig

    with stages(len(PARTS) + 6, f"stl {profile.name}") as step:
        rig = Rig.from_profile(profile)
        step("dome integrated")
        rig.design  # traced here, for the progress bar; the export reuses it
        step("design traced")
        result = api.export(rig, out, progress=step)
    env = rig.design.report["envelope"]
    print(f"{profile.name}: dome mirror {env['width_in']:.2f} x {env['height_in']:.2f} in; "
          f"{len(result.rebuilt)} part(s) built, {len(result.reused)} unchanged -> {out}/")
    print("\n".join(part_lines(result, list(PARTS))))
    return 0


def register(subparsers) -> None:
    """Add ``stl`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    p = profile_command(
        subparsers, "stl", cmd_stl,
        help="the main job (make stl): design + build, skipped when nothing changed",
        description="Run `design` then `build` for every part, recording the inputs' hash in manifest.json; "
                    "when the profile and rigcad's code are unchanged and every listed file is intact, "
                    "return at once.")
