"""rigcad's command line: thin. Parses arguments, calls the stages, prints. A RigcadError becomes
one readable line on stderr and a non-zero exit code; a traceback is a bug."""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import fields
from pathlib import Path

from rigcad._version import __version__
from rigcad.arguments import exports_root
from rigcad.errors import RigcadError
from rigcad.export.atomic import check_exports, profile_lock, tidy
from rigcad.progress import stages
from rigcad.units import DEG


def _fmt(spec, value) -> str:
    if value is None:
        return "-"
    if spec.kind == "length":
        return "inf" if math.isinf(value) else f"{value:.6g} mm"
    if spec.kind == "angle":
        return f"{value / DEG:.6g} deg"
    if spec.kind == "layers":
        return "; ".join(f"{name} {t / 0.0254:.4g} mil" for name, t in value) + f" (total {sum(t for _, t in value) / 0.0254:.4g} mil)"
    return str(list(value) if isinstance(value, tuple) else value)


def cmd_profile_show(args: argparse.Namespace) -> int:
    from rigcad.export.atomic import json_bytes
    from rigcad.profile import derive, load_profile
    from rigcad.profile.schema import SECTIONS

    profile = load_profile(args.profile)
    geo = derive(profile)  # the profile's own figures; no dome is integrated to show them
    if args.json:
        sys.stdout.write(json_bytes({"parameters": profile.as_dict(), "derived": geo.as_dict()}).decode())
        return 0
    print(f"profile {profile.name}  ({' <- '.join(profile.sources)})")
    if profile.description:
        print(f"  {profile.description}")
    table = {section: [(f.name, _fmt(f.metadata["spec"], getattr(getattr(profile, section), f.name)),
                        profile.marks.get((section, f.name)) or "default", f.metadata["spec"].doc)
                       for f in fields(getattr(profile, section))] for section in SECTIONS}
    # a value wider than this (the coating's layer list) goes on its own line under its row, so that
    # one long cell does not push every other row's columns to the right
    cap = 32
    widths = [max(len(row[i]) for rows in table.values() for row in rows if i != 1 or len(row[1]) <= cap)
              for i in range(3)]
    for section, rows in table.items():
        print(f"\n[{section}]")
        for name, value, origin, doc in rows:
            long = len(value) > cap
            print("  " + _columns((name, "(below)" if long else value, origin, doc), widths))
            if long:
                print("  " + " " * (widths[0] + 1) + value)
    print("\n[derived]")
    rows = [
        ("focal_length", f"{geo.focal_length:.6g} mm"),
        ("rim_radius", f"{geo.rim_radius:.6g} mm"),
        ("vertical_extent", f"{geo.vertical_extent:.6g} mm"),
        ("tangent_angle", f"{geo.tangent_angle / DEG:.6g} deg"),
        ("vertex_radius_of_curvature", f"{geo.vertex_radius_of_curvature:.6g} mm"),
        ("vertex_z", f"{geo.vertex_z:.6g} mm"),
        ("rim_z", f"{geo.rim_z:.6g} mm"),
        ("focus_z", f"{geo.focus_z:.6g} mm"),
        ("cop_z", "inf" if geo.cop_at_infinity else f"{geo.cop_z:.6g} mm"),
        ("occlusion_theta", f"{geo.occlusion_theta / DEG:.6g} deg"),
        ("rim_angle_at_cop", f"{geo.rim_angle_at_cop / DEG:.6g} deg"),
        ("pixels_vertex_to_rim", "-" if geo.cop_at_infinity else f"{geo.pixels_vertex_to_rim:.4g} px"),
    ]
    width = max(len(name) for name, _ in rows)
    for name, value in rows:
        print(f"  {name:<{width}} {value}")
    return 0


def _columns(row, widths) -> str:
    """One line of a table: each cell padded to its column's width (the widest cell), the last free."""
    return " ".join(f"{cell:<{w}}" for cell, w in zip(row, widths)) + " " + " ".join(row[len(widths):])


def _part_lines(result, names) -> list[str]:
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


def cmd_design(args: argparse.Namespace) -> int:
    from rigcad.export.design import write_design
    from rigcad.profile import load_profile
    from rigcad.rig import load

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name)  # a planted link or lock: one line now, not after the work
    with stages(3, "design") as step:
        rig = load(profile)
        step("dome integrated")
        design = rig.design
        step("traced")
        out_dir = Path(args.exports) / rig.name
        paths = write_design(design, out_dir, profile_lock(args.exports, rig.name))
        step("written")
    r = design.report
    env, rng, px = r["envelope"], r["measurable_range"], r["pixels"]
    print(f"{rig.name}: dome {env['width_mm']:.1f} x {env['height_mm']:.1f} mm "
          f"({env['width_in']:.2f} x {env['height_in']:.2f} in), theta {rng['theta_min_deg']:.2f}..{rng['theta_max_deg']:.1f} deg, "
          f"dome by {r['dome']['method']} (error vs closed form {r['dome']['error_vs_equal_path_mm']:.2g} mm), "
          f"max miss at O {r['convergence']['max_miss_mm']:.2g} mm"
          + (f", {px['vertex_to_rim_px']:.0f} px vertex to rim" if px["vertex_to_rim_px"] else ""))
    if not rng["targets_met"]:
        print(f"warning: the design covers theta {rng['theta_min_deg']:.2f}..{rng['theta_max_deg']:.2f} deg, "
              f"not the target {rng['target_theta_min_deg']:g}..{rng['target_theta_max_deg']:g} deg", file=sys.stderr)
    for p in paths:
        print(f"  wrote {p}")
    return 0


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
    print("\n".join(_part_lines(result, names)))
    print(f"  manifest: {out / 'manifest.json'}")
    return 0


def cmd_stl(args: argparse.Namespace) -> int:
    """The main job: design + build, returning at once when nothing changed since the last run."""
    from rigcad.export.atomic import stale_results
    from rigcad.export.manifest import inputs_key, profile_digest, up_to_date
    from rigcad.profile import load_profile

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name)
    out = Path(args.exports) / profile.name
    key = inputs_key(profile)
    if up_to_date(out, key) and not stale_results(out, profile_digest(profile)):  # else a build removes them
        tidy(out, profile_lock(args.exports, profile.name))
        print(f"{profile.name}: up to date ({out}/manifest.json)")
        return 0
    from rigcad.parts import PARTS
    from rigcad.rig import Rig

    with stages(len(PARTS) + 6, f"stl {profile.name}") as step:
        rig = Rig.from_profile(profile)
        step("dome integrated")
        rig.design  # traced here, for the progress bar; the export reuses it
        step("design traced")
        result = rig.export(out, progress=step)  # the Python API's path: the same lock and cache key
    env = rig.design.report["envelope"]
    print(f"{profile.name}: dome mirror {env['width_in']:.2f} x {env['height_in']:.2f} in; "
          f"{len(result.rebuilt)} part(s) built, {len(result.reused)} unchanged -> {out}/")
    print("\n".join(_part_lines(result, list(PARTS))))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rigcad",
        description="CAD and fabrication toolchain for the image-based BRDF acquisition rig "
                    "(Achutha 2006): YAML profile -> optical design -> parts -> exports.",
        epilog="Profiles are looked up by name under profiles/ or given as a path. Lengths and angles "
               "in profiles carry units: '13.5 cm', '11 in', '5.5 mil', '20 deg'.")
    parser.add_argument("--version", action="version", version=f"rigcad {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p_profile = sub.add_parser("profile", help="inspect profiles", description="Inspect profiles.")
    psub = p_profile.add_subparsers(dest="profile_command", metavar="ACTION", required=True)
    p_show = psub.add_parser("show", help="print resolved and derived parameters, with where each came from",
                             description="Print every resolved parameter (with the file:line that set it, "
                                         "or 'default') and the derived geometry.")
    p_show.add_argument("profile", help="profile name (under profiles/) or path")
    p_show.add_argument("--json", action="store_true", help="machine-readable output, units in the keys")
    p_show.set_defaults(func=cmd_profile_show)

    p_design = sub.add_parser(
        "design", help="2D optical design: dome profile, ray diagram, derived figures",
        description="Integrate the dome profile, trace the design in 2D (pinhole, thin lens, misalignment) "
                    "and write exports/<profile>/design.json, dome_profile.csv, rays.png and incidence.png.")
    p_design.add_argument("profile", help="profile name (under profiles/) or path")
    p_design.add_argument("--exports", default="exports", help="output root (default: exports)")
    p_design.set_defaults(func=cmd_design)

    p_build = sub.add_parser(
        "build", help="3D parts: STEP and STL per part, rig assembly, manifest",
        description="Build the rig's parts into exports/<profile>/: step/<part>.step (exact B-rep, re-imported "
                    "and checked), stl/<part>.stl (at tessellation.chord_error), rig.step (the assembly, named "
                    "and coloured parts) and manifest.json. Unchanged parts are not rebuilt.",
        epilog="parts: dome, paraboloid, beam, base_plate, sample_holder, projector_cross, projector_backplate, "
               "projector_mounting_plate, camera_cross_hung, camera_cross_base, dome_template, paraboloid_template, "
               "tower_column, tower_shelf, splitter_holder, lens_mount, tower_shim")
    p_build.add_argument("profile", help="profile name (under profiles/) or path")
    p_build.add_argument("--parts", nargs="+", metavar="PART", help="build only these parts (default: all)")
    p_build.add_argument("--exports", default="exports", help="output root (default: exports)")
    p_build.set_defaults(func=cmd_build)

    p_stl = sub.add_parser(
        "stl", help="the main job (make stl): design + build, skipped when nothing changed",
        description="Run `design` then `build` for every part, recording the inputs' hash in manifest.json; "
                    "when the profile and rigcad's code are unchanged and every listed file is intact, "
                    "return at once.")
    p_stl.add_argument("profile", help="profile name (under profiles/) or path")
    p_stl.add_argument("--exports", default="exports", help="output root (default: exports)")
    p_stl.set_defaults(func=cmd_stl)

    from rigcad.check.cli import register as register_check

    register_check(sub)

    from rigcad.fab.cli import register as register_fab

    register_fab(sub)

    from rigcad.basis.cli import register as register_basis

    register_basis(sub)

    from rigcad.optimize.cli import register as register_optimize

    register_optimize(sub)
    from rigcad.manual.cli import register as register_manual

    register_manual(sub)
    from rigcad.tolerance.cli import register as register_tolerance

    register_tolerance(sub)
    from rigcad.live.cli import register as register_watch

    register_watch(sub)
    _require_exports_root(parser)
    return parser


def _require_exports_root(parser: argparse.ArgumentParser) -> None:
    """Every command's ``--exports`` takes :func:`exports_root` (one rule, whichever module added it)."""
    for action in parser._actions:
        if action.dest == "exports":
            action.type = exports_root
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                _require_exports_root(child)


def _error_line(message: object) -> str:
    """``rigcad: error: <message>`` on one line: a newline or other control character that a name,
    a path or a value brought into the message is shown escaped (``\\n``), never printed."""
    text = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in str(message))
    return f"rigcad: error: {text}"


def main(argv: list[str] | None = None) -> int:
    from rigcad.engine import run_temp_dir

    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with run_temp_dir():
            return args.func(args)
    except RigcadError as err:
        print(_error_line(err), file=sys.stderr)
        return err.exit_code
    except BrokenPipeError:  # output piped into head & co.
        return 0
    except OSError as err:  # an I/O failure outside the writers' own guards: still one line
        from rigcad.export.atomic import write_error

        failure = write_error(Path(err.filename or "."), err)
        print(_error_line(failure), file=sys.stderr)
        return failure.exit_code
    except KeyboardInterrupt:
        print("rigcad: interrupted", file=sys.stderr)
        return 130
    except MemoryError as err:  # an allocation the estimates before it did not foresee
        print(_error_line(f"out of memory{': ' + str(err) if str(err) else ''}; ask for fewer rays, builds or "
                          "samples, or run on a machine with more memory"), file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
