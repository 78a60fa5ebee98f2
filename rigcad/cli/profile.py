"""``rigcad profile show PROFILE [--json]``: every resolved parameter with where it came from (the
profile's file:line, the instrument file's file:line, or "default"), where each instrument figure
was read (its datasheet), and the derived geometry and camera (closed forms: no dome is integrated
to show them)."""

from __future__ import annotations

import argparse
import math
import re
import sys
from dataclasses import fields

from rigcad.units import DEG


def _fmt(spec, value) -> str:
    if value is None:
        return "-"
    if spec.kind == "length":
        return "inf" if math.isinf(value) else f"{value:.6g} mm"
    if spec.kind == "angle":
        return f"{value / DEG:.6g} deg"
    if spec.kind == "mass":
        return f"{value:.6g} kg"
    if spec.kind == "layers":
        return "; ".join(f"{name} {t / 0.0254:.4g} mil" for name, t in value) + f" (total {sum(t for _, t in value) / 0.0254:.4g} mil)"
    return str(list(value) if isinstance(value, tuple) else value)


#: "(assumed)" or "(assumed: why)" in a key's doc: true of the default only.
_ASSUMED = re.compile(r"\s*\(assumed(?::[^)]*)?\)")


def _doc(profile, section: str, f) -> str:
    """The key's doc; a key the profile or an instrument file set is no longer "(assumed)"."""
    doc = f.metadata["spec"].doc
    return doc if profile.set_by(section, f.name) == "default" else _ASSUMED.sub("", doc)


def _columns(row, widths) -> str:
    """One line of a table: each cell padded to its column's width (the widest cell), the last free."""
    return " ".join(f"{cell:<{w}}" for cell, w in zip(row, widths)) + " " + " ".join(row[len(widths):])


def cmd_show(args: argparse.Namespace) -> int:
    from rigcad.export.atomic import json_bytes
    from rigcad.optics.camera import camera_model
    from rigcad.profile import derive, load_profile
    from rigcad.profile.schema import SECTIONS

    profile = load_profile(args.profile)
    geo = derive(profile)  # the profile's own figures; no dome is integrated to show them
    camera = None if geo.cop_at_infinity else camera_model(profile, geo)
    if args.json:
        origins = {section: {f.name: {"set_by": profile.set_by(section, f.name), "where": profile.origin(section, f.name),
                                      **({"source": profile.source(section, f.name)}
                                         if profile.source(section, f.name) else {})}
                             for f in fields(getattr(profile, section))} for section in SECTIONS}
        instruments = {key: {"kind": i.kind, "name": i.name, "title": i.title, "file": i.file}
                       for key, i in profile.instruments.items()}
        sys.stdout.write(json_bytes({"parameters": profile.as_dict(), "origins": origins, "instruments": instruments,
                                     "derived": geo.as_dict(),
                                     "camera": camera.as_dict() if camera else None}).decode())
        return 0
    print(f"profile {profile.name}  ({' <- '.join(profile.sources)})")
    if profile.description:
        print(f"  {profile.description}")
    for key, inst in profile.instruments.items():
        print(f"  {key}: {inst.name} = {inst.title} ({inst.file})")
    table = {section: [(f.name, _fmt(f.metadata["spec"], getattr(getattr(profile, section), f.name)),
                        profile.origin(section, f.name)
                        + (f" (that file's figure for its own {section}, not from {section}.model "
                           f"{getattr(getattr(profile, section), 'model', '')}: check it)"
                           if profile.apart_from_model(section, f.name) else ""),
                        _doc(profile, section, f))
                       for f in fields(getattr(profile, section))] for section in SECTIONS}
    if camera is not None and camera.focal_from == "derived":  # no lens stated: the one rigcad derives
        table["camera"] = [(n, f"({camera.focal_px:.5g} px)", "derived", d) if n == "focal_length" else (n, v, o, d)
                           for n, v, o, d in table["camera"]]
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
        _projector_axis_row(profile),
    ]
    width = max(len(name) for name, _ in rows)
    for name, value in rows:
        print(f"  {name:<{width}} {value}")
    if camera is not None:
        _print_camera(camera)
    sourced = [(f"{section}.{f.name}", profile.source(section, f.name)) for section in SECTIONS
               for f in fields(getattr(profile, section)) if profile.source(section, f.name)]
    if sourced:
        print("\n[sources] where each instrument figure was read")
        width = max(len(key) for key, _ in sourced)
        for key, source in sourced:
            print(f"  {key:<{width}} {source}")
    return 0


def _projector_axis_row(profile) -> tuple[str, str]:
    """Where the projector's lens axis meets its image (rigcad.profile.derived): the paraboloid's image
    is a disc about that pixel, and the image holds a disc this wide about it."""
    from rigcad.profile.derived import projector_disc_room, projector_principal_point

    (x, y), pj = projector_principal_point(profile.projector), profile.projector
    return ("projector_axis_pixel", f"[{x:g}, {y:g}] px of {pj.resolution[0]} x {pj.resolution[1]} (lens_offset "
                                    f"{pj.lens_offset:.0%}); room for a disc {projector_disc_room(pj):g} px in radius")


def _print_camera(camera) -> None:
    """The camera's derived figures (rigcad.optics.camera): its lens and the paraboloid's image."""
    from rigcad.optics.camera import DEFAULT_FILL

    f_fill, f_fill_mm = camera.focal_for_fill(DEFAULT_FILL)
    mm = (lambda v: "-" if v is None else f"{v:.4g} mm")
    rows = [
        ("focal_length", f"{mm(camera.focal_length)} = {camera.focal_px:.5g} px ({camera.focal_from})"),
        ("principal_point", f"[{camera.principal_point[0]:g}, {camera.principal_point[1]:g}] px"),
        ("paraboloid_image", f"{2 * camera.image_radius_px:.4g} px across, {camera.fill:.1%} of the "
                             f"{camera.short_side_px} px short side, "
                             + ("all on the sensor" if camera.on_sensor else "NOT all on the sensor")),
        (f"focal_length_for_{DEFAULT_FILL:.0%}".replace("%", "pc"), f"{mm(f_fill_mm)} = {f_fill:.5g} px"),
        ("working_distance", f"{camera.working_distance:.4g} mm (lens front to the paraboloid's vertex; closest "
                             f"focus {mm(camera.min_working_distance)})"),
    ]
    print("\n[derived camera]")
    width = max(len(name) for name, _ in rows)
    for name, value in rows:
        print(f"  {name:<{width}} {value}")


def register(subparsers) -> None:
    """Add ``profile show`` to rigcad's subcommands."""
    p_profile = subparsers.add_parser("profile", help="inspect profiles", description="Inspect profiles.")
    psub = p_profile.add_subparsers(dest="profile_command", metavar="ACTION", required=True)
    p_show = psub.add_parser("show", help="print resolved and derived parameters, with where each came from",
                             description="Print every resolved parameter (with the file:line that set it, "
                                         "or 'default') and the derived geometry.")
    p_show.add_argument("profile", help="profile name (under profiles/) or path")
    p_show.add_argument("--json", action="store_true", help="machine-readable output, units in the keys")
    p_show.set_defaults(func=cmd_show)
