"""The fabrication stage's report: fab.json's figures (units in the keys) and fab.md, the page a
fabricator reads (parts, pieces, orientations, time and material, sanding stock, support contact,
the staircase maps). Both are made from the report dict alone, so they never disagree.
"""

from __future__ import annotations

import math

from rigcad._version import __version__
from rigcad.fab import orientation, split
from rigcad.fab.choice import CUSP_TIE_RTOL
from rigcad.units import hours_minutes


def fab_report(profile: str, printer, chord: float, tol_mirror: float, gcode: dict, parts: dict,
               problems: list[str]) -> dict:
    """fab.json: the run's settings and tolerances, the slicing (``gcode``), the totals and every
    part's entry (``parts``), and the problems met."""
    return {
        "rigcad_version": __version__,
        "profile": profile,
        "printer": printer.describe(),
        "frame": "part frame: mm, sample point at the origin, optical axis +z, working position; print "
                 "frame: build direction +z, bed at z = 0",
        "tolerances": {"stl_chord_error_mm": chord, "mirror_face_tolerance_mm": tol_mirror,
                       "pin_min_wall_mm": split.pin_wall(printer), "pin_mirror_clearance_mm": split.MIRROR_CLEARANCE,
                       "orientation_cusp_tie_rtol": CUSP_TIE_RTOL,
                       "overhang_angle_deg": math.degrees(orientation.OVERHANG_ANGLE)},
        "gcode": gcode,
        "totals": totals(parts),
        "parts": parts,
        "problems": problems,
    }


def totals(parts: dict) -> dict:
    """Pieces, print time and material of the whole run, with each part's quantity: rigcad's
    estimate, and the slicer's when every piece was sliced."""
    pieces = [pc for e in parts.values() for pc in e.get("pieces", [])]
    qty = {pc["name"]: e.get("quantity", 1) for e in parts.values() for pc in e.get("pieces", [])}
    est_t = sum(pc["estimate"]["print_time_s"] * qty[pc["name"]] for pc in pieces)
    est_g = sum(pc["estimate"]["material_g"] * qty[pc["name"]] for pc in pieces)
    out = {"pieces": sum(qty.values()), "estimate_print_time_s": est_t, "estimate_material_g": est_g}
    sl = [pc for pc in pieces if "gcode" in pc]
    if sl and len(sl) == len(pieces):
        out["slicer_print_time_s"] = sum(pc["gcode"]["estimates"].get("print_time_s", 0) * qty[pc["name"]] for pc in sl)
        out["slicer_filament_g"] = sum(pc["gcode"]["estimates"].get("filament_g", 0) * qty[pc["name"]] for pc in sl)
    return out


def markdown(report: dict) -> str:
    """fab.md: one page a fabricator reads, with the staircase maps."""
    lines = _parts_table(report) + _stock_section(report) + _contact_section(report)
    for name, e in report["parts"].items():
        if e.get("staircase_map"):
            lines += _staircase_section(name, e, report["printer"])
    if report.get("stack"):
        st = report["stack"]
        lines += ["## Tolerance stack", "",
                  "Each optical element's placement error from the base plate's bore through every printed link, "
                  "seam, pin, clearance and joint, on this printer's process errors, against the profile's "
                  "`tolerancing:` (rigcad.fab.stack; docs/rig-mechanics.md). Seams: "
                  + ", ".join(f"{k} {v} ({st['seams_from'][k]})" for k, v in st["seams"].items()) + ".", "",
                  *st["table_md"], ""]
    if report["problems"]:
        lines += ["## Problems", ""] + [f"- {p}" for p in report["problems"]] + [""]
    return "\n".join(lines)


def _parts_table(report: dict) -> list[str]:
    """The page's title, the printer, one row per part and the totals."""
    pr = report["printer"]
    lines = [f"# Fabrication: {report['profile']} on {pr['name']}", "",
             f"{pr['description']} ({pr['process']}); build volume {' x '.join(f'{v:g}' for v in pr['build_volume_mm'])} mm; "
             f"layer {pr['layer_height_mm']:.4g} mm; material {pr['material']}. Source: `{pr['source']}`.", "",
             "| part | qty | pieces | orientation | layers | time | material | mirror cusp mean / max (mm) | sanding depth / stock printed (mm) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for label, e in report["parts"].items():
        name = label + (" (earlier run)" if e.get("from_earlier_run") else "")
        if "error" in e:
            lines.append(f"| {name} | | | **not printable:** {e['error']} | | | | | |")
            continue
        if e.get("process") == "bought":
            lines.append(f"| {name} | {e['quantity']} | bought | {e['stock']} | | | | | |")
            continue
        if "pieces" not in e:
            lines.append(f"| {name} | {e['quantity']} | cut | {e['process']}: `outlines/{label}.dxf`, `.svg` "
                         f"({e['outline_size_mm'][0]:.1f} x {e['outline_size_mm'][1]:.1f} mm, plate {e['plate_thickness_mm']:g} mm) | | | | | |")
            continue
        pcs = e["pieces"]
        t = sum((pc.get("gcode", {}).get("estimates", {}).get("print_time_s") or pc["estimate"]["print_time_s"]) for pc in pcs)
        g = sum((pc.get("gcode", {}).get("estimates", {}).get("filament_g") or pc["estimate"]["material_g"]) for pc in pcs)
        src = "slicer" if all("gcode" in pc for pc in pcs) else "est."
        orient = ", ".join(sorted({pc["orientation"] for pc in pcs}))
        sm = e.get("staircase_map")
        cusp = f"{sm['cusp_mean_mm']:.3f} / {sm['cusp_max_mm']:.3f}" if sm else "-"
        stock = e["sanding_stock"]["stock_mm"] if e.get("sanding_stock") else e.get("polishing", {}).get("stock_to_add_mm")
        pol = f"{e['polishing']['sanding_depth_mm']:.3f} / {stock:.3f}" if "polishing" in e else "-"
        lines.append(f"| {name} | {e['quantity']} | {len(pcs)} | {orient} | {e['layers_total']} | {hours_minutes(t)} ({src}) | "
                     f"{g:.0f} g | {cusp} | {pol} |")
    tot = report["totals"]
    # the slicer's figures when every piece was sliced; rigcad's estimate only when none was
    lines += ["", f"Totals (with quantities): {tot['pieces']} pieces, "
              + (f"{hours_minutes(tot['slicer_print_time_s'])} and {tot['slicer_filament_g']:.0f} g by the slicer"
                 if "slicer_print_time_s" in tot else
                 f"{hours_minutes(tot['estimate_print_time_s'])} and {tot['estimate_material_g']:.0f} g by rigcad's "
                 "estimate (rigcad.fab.estimate, fitted to PrusaSlicer; not every piece was sliced)")
              + ".", ""]
    return lines


def _stock_section(report: dict) -> list[str]:
    """The sanding stock printed in front of each mirror, and what it added (none: no lines)."""
    stocked = [(n, e) for n, e in report["parts"].items() if e.get("sanding_stock")]
    if not stocked:
        return []
    lines = ["## Sanding stock", "",
             "Every mirror is printed forward, into the light, by the stock: sand down to the `_sanded` template "
             "(the steps' valleys then lie in front of it), coat, and the coating brings the surface to the design "
             "surface. Templates: `outlines/<mirror>_template_printed` gauges the print, `_sanded` the sanded "
             "surface, `<mirror>_template` the coating layer the profile names.", "",
             "| part | stock (mm) | from | volume added (cm3) | / (mirror area x stock) | valley left behind the sanded surface (mm) |",
             "|---|---|---|---|---|---|"]
    for n, e in stocked:
        st = e["sanding_stock"]
        ratio = st.get("volume_added_over_area_times_stock")
        lines.append(f"| {n} | {st['stock_mm']:.3f} | {st['source']} | {st.get('volume_added_mm3', 0) / 1000:.2f} | "
                     f"{'-' if ratio is None else f'{ratio:.4f}'} | {st.get('valley_behind_sanded_surface_mm', 0):.4f} |")
    return lines + [""]


def _contact_section(report: dict) -> list[str]:
    """The support contact read from the G-code, per sliced piece (none sliced: no lines)."""
    contact = [(pc, e) for e in report["parts"].values() for pc in e.get("pieces", [])
               if pc.get("gcode", {}).get("support_contact")]
    if not contact:
        return []
    lines = ["## Support contact (from the G-code's support extrusions)", "",
             "| piece | orientation | on the mirror (mm2) | of it within the seams' faired band (mm2) | "
             "on other faces (mm2) | model: mirror / other (mm2) | picture |",
             "|---|---|---|---|---|---|---|"]
    for pc, e in contact:
        sc, sm = pc["gcode"]["support_contact"], pc.get("support_model", {})
        pic = f"![{pc['name']}]({sc['png']})" if "png" in sc else ""
        band = f"{sc['mirror_in_band_mm2']:.1f} (band {sc['band_mm']:g} mm)" if "band_mm" in sc else "-"
        lines.append(f"| {pc['name']} | {pc['orientation']} | {sc['mirror_mm2']:.1f} | {band} | {sc['other_mm2']:.0f} | "
                     f"{sm.get('mirror_mm2', 0):.0f} / {sm.get('other_mm2', 0):.0f} | {pic} |")
    return lines + [""]


def _split_line(e: dict, pr: dict) -> str:
    """How a split part was cut: sectors, bands, pins and tongues, and their depth behind the mirror."""
    s = e["split"]
    r = e.get("reassembly", {})
    return (f"Split into {s['pieces']} pieces ({s['sectors']} sectors at "
            f"{', '.join(f'{a:.1f}' for a in s['sector_planes_deg'])} deg"
            + (f", bands cut at z = {', '.join(f'{z:.1f}' for z in s['band_cuts_z_mm'])} mm" if s["band_cuts_z_mm"] else "")
            + f"), {r.get('pin_holes', 0)} pin holes of {pr['alignment_pin']['diameter_mm']:g} mm "
            f"(at least {r.get('pin_hole_min_clearance_to_mirror_mm', float('nan')):.2f} mm behind the mirror)"
            + "".join(f"; band cut z = {t['z_mm']:.1f} mm joined by a tongue and groove {t['depth_mm']:g} mm deep "
                      f"({t['min_clearance_to_mirror_mm']:.2f} mm behind the mirror)" for t in e.get("tongues", []))
            + "".join(f"; {s['face']} takes no pins ({s['why']}): {s['held_by']}" for s in e.get("pinless_seams", []))
            + ".")


def _staircase_section(name: str, e: dict, pr: dict) -> list[str]:
    """A mirror part's staircase: its split, each piece's cusp (closed form per candidate, from the
    slices) and ray error, and the map."""
    lines = [f"## {name}: staircase on the mirror", ""]
    if e["split"]["pieces"] > 1:
        lines += [_split_line(e, pr), ""]
    lines += ["| piece | orientation | closed-form cusp mean (mm) | from slices mean / max (mm) | ray error median (deg, as printed) |",
              "|---|---|---|---|---|"]
    for pc in e["pieces"]:
        if "staircase_from_slices" not in pc:
            continue
        cand = {c["orientation"]: c for c in pc["candidates"]}
        cf = ", ".join(f"{o}: {c['staircase_closed_form']['cusp_mean_mm']:.4f}" + ("" if c["fits"] else " (no fit)")
                       for o, c in cand.items())
        s = pc["staircase_from_slices"]
        lines.append(f"| {pc['name']} | **{pc['orientation']}** | {cf} | {s['cusp_from_slices_mean_mm']:.4f} / "
                     f"{s['cusp_from_slices_max_mm']:.4f} | {pc['optical_effect_as_printed']['ray_angle_error_median_deg']:.1f} |")
    return lines + ["", f"![staircase map of {name}]({e['staircase_map']['png']})", "",
                    "As printed, the steps' treads and risers tilt the surface normal by tens of degrees (ideal steps), "
                    "so every reflected ray is lost: the steps must be sanded away (depth above) before the coating. "
                    "The mirror is printed forward by the sanding stock (above), so that every valley lies in front of the sanded surface.", ""]
