"""``rigcad build PROFILE [--parts ...]``: the 3D parts (STEP, STL, the assembly, the manifest)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rigcad.export.atomic import check_exports, profile_lock
from rigcad.progress import stages


def part_lines(result, names) -> list[str]:
    """One line per part of a build: built or unchanged, volume, triangles, quantity; columns as wide
    as the longest part name."""
    m = result.manifest
    width = max((len(n) for n in names), default=0)
    lines = []
    for name in names:
        e = m["parts"][name]
        tag = "built" if name in result.rebuilt else "unchanged"
        lines.append(f"  {name:<{width}} {tag:<9} volume {e['volume_mm3'] / 1000:9.2f} cm^3  {e['triangles']:7d} triangles"
                     + (f"  x{e['quantity']}" if e["quantity"] > 1 else ""))
    return lines


def cmd_build(args: argparse.Namespace) -> int:
    from rigcad.export.build import build_rig, select_parts
    from rigcad.profile import load_profile
    from rigcad.rig import load

    names = select_parts(args.parts)
    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name)
    with stages(len(names) + 2, "build") as step:
        rig = load(profile)
        step("dome integrated")
        out = Path(args.exports) / rig.name
        result = build_rig(rig, out, names, progress=step, lock=profile_lock(args.exports, rig.name))
    print(f"{rig.name}: {len(result.rebuilt)} part(s) built, {len(result.reused)} unchanged -> {out}/")
    print("\n".join(part_lines(result, names)))
    print(f"  manifest: {out / 'manifest.json'}")
    return 0


def register(subparsers) -> None:
    """Add ``build`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    p = profile_command(
        subparsers, "build", cmd_build,
        help="3D parts: STEP and STL per part, rig assembly, manifest",
        description="Build the rig's parts into exports/<profile>/: step/<part>.step (exact B-rep, re-imported "
                    "and checked), stl/<part>.stl (at tessellation.chord_error), rig.step (the assembly, named "
                    "and coloured parts) and manifest.json. Unchanged parts are not rebuilt.",
        epilog="parts: dome, paraboloid, beam, base_plate, sample_holder, projector_cross, projector_backplate, "
               "projector_mounting_plate, camera_cross_hung, camera_cross_base, dome_template, paraboloid_template, "
               "tower_column, tower_shelf, splitter_holder, lens_mount, tower_shim")
    p.add_argument("--parts", nargs="+", metavar="PART", help="build only these parts (default: all)")
