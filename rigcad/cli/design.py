"""``rigcad design PROFILE``: the 2D optical design (dome profile, ray diagram, derived figures), and
every refusal of the rig's placements and part recipes that `rigcad stl` would make later."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rigcad.export.atomic import check_exports, profile_lock
from rigcad.progress import stages


def cmd_design(args: argparse.Namespace) -> int:
    from rigcad.profile import load_profile

    profile = load_profile(args.profile)  # first: a refused profile is one line, before numpy is imported
    check_exports(args.exports, profile.name)  # a planted link or lock: one line now, not after the work
    from rigcad.export.design import write_design
    from rigcad.rig import load

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
    _suggest_lens(rig, args.fill)
    for p in paths:
        print(f"  wrote {p}")
    return _early_refusals(rig)


def _early_refusals(rig) -> int:
    """The refusals `rigcad stl` would make later that need no part's solid (the ray check's criteria
    decided without its trace, rigcad.check.criteria.cheap_rows: the design's theta range against the
    targets, the projector's pixels per degree, the camera; rigcad.manual.gate.early_refusals: the
    layout, every part's recipe), all of them, each on its own line naming the
    key to change: exit 1 when there is one (the design's files stay written: its optics stand)."""
    from rigcad.check.criteria import cheap_rows, row_line
    from rigcad.check.tolerances import theta_range_rows
    from rigcad.errors import RigcadError, one_line
    from rigcad.manual.gate import early_refusals

    found = [r.line() for r in early_refusals(rig)]
    try:
        rows = cheap_rows(rig)
    except RigcadError:  # the rig's layout is refused (among ``found``): the optics' own rows still stand
        rows = theta_range_rows(rig.profile, rig.design.report["measurable_range"])
    lines = [row_line(r) for r in rows if not r.ok] + found
    if not lines:
        return 0
    print(f"rigcad: error: {rig.name}: `rigcad stl` would refuse this rig: {len(lines)} refusal(s) found before any "
          "part is built, each below (the design's own files are written)", file=sys.stderr)
    for line in lines:
        print(f"  {one_line(line)}", file=sys.stderr)
    return 1


def _suggest_lens(rig, fill: float) -> None:
    """The camera's lens against the paraboloid's image (rigcad.optics.camera): how much of the
    sensor's short side the image fills, and the focal length that fills ``fill`` of it."""
    from rigcad.optics.camera import camera_model

    if rig.geometry.cop_at_infinity:
        return
    cam = camera_model(rig.profile, rig.geometry)
    f_px, f_mm = cam.focal_for_fill(fill)
    lens = f"{cam.focal_length:.4g} mm" if cam.focal_length is not None else f"{cam.focal_px:.0f} px"
    print(f"camera: the {lens} lens ({cam.focal_from}) images the paraboloid {2 * cam.image_radius_px:.0f} px across, "
          f"{cam.fill:.0%} of the {cam.short_side_px} px short side"
          + ("" if cam.on_sensor else " (NOT all on the sensor)") + f"; {fill:.0%} needs "
          + (f"a {f_mm:.3g} mm lens ({f_px:.0f} px)" if f_mm is not None
             else f"{f_px:.0f} px (set camera.pixel_pitch for millimetres)"))


def fill_fraction(text: str) -> float:
    """An argparse type: a fraction 0 < f <= 1 of the sensor's short side, written 0.9 or 90%."""
    try:
        value = float(text[:-1]) / 100 if text.endswith("%") else float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a fraction such as 0.9 or 90%, got {text[:40]!r}") from None
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"expected a fraction 0 < f <= 1 (or 1%..100%), got {text[:40]!r}")
    return value


def register(subparsers) -> None:
    """Add ``design`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    p = profile_command(
        subparsers, "design", cmd_design,
        help="2D optical design: dome profile, ray diagram, derived figures",
        description="Integrate the dome profile, trace the design in 2D (pinhole, thin lens, misalignment) "
                    "and write exports/<profile>/design.json, dome_profile.csv, rays.png and incidence.png; "
                    "say how much of the camera's sensor the paraboloid's image fills, and the focal length "
                    "that fills --fill of it. Then run the checks `rigcad stl` makes before any solid is built (the "
                    "layout of the tower and the instruments against the dome, every part's recipe) and report "
                    "every refusal at once, each naming the key to change; exit 1 when there is one.")
    p.add_argument("--fill", type=fill_fraction, default=0.9, metavar="FRACTION",
                   help="the fraction of the camera sensor's short side the suggested lens fills with the "
                        "paraboloid's image (default: 0.9)")
