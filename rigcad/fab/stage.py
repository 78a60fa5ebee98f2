"""The fabrication stage: a Rig + printer -> exports/<profile>/fab/<printer>/.

For every part: fit it to the printer (or split it, rigcad.fab.split), choose each piece's
orientation (rigcad.fab.orientation: no support on a mirror, then the least staircase; thin
plates flat), print each mirror forward by its sanding stock (:func:`_with_stock`), slice it
in-process (rigcad.fab.staircase: layer count, the staircase map from the slices against the
closed form, the polishing allowance, the optical effect), write its STL in print position and,
with ``gcode``, its G-code through PrusaSlicer (rigcad.fab.slicer) with the support contact read
from it (rigcad.fab.support). Time and material: rigcad.fab.estimate (fitted to PrusaSlicer), and
the slicer's own figures where it ran. Flat templates become DXF and SVG cutting outlines
(rigcad.fab.outlines), one per finishing stage. fab.json (units in keys) and fab.md (with the
pictures) report it all. Outputs are staged and published together (rigcad.export.atomic).

Files: stl/<piece>.stl, gcode/<piece>.gcode, printer.ini, outlines/<part>[_printed|_sanded].{dxf,svg},
staircase/<part>.png, support/<piece>.png, fab.json, fab.md. Timings are returned, not written
(fab.json is deterministic). With G-code, also 3mf/<piece>.3mf: the PrusaSlicer project that made it.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rigcad._version import __version__
from rigcad.errors import FabricationError, RigcadError
from rigcad.export.atomic import Staging, json_bytes
from rigcad.export.manifest import profile_digest, sha256_hex
from rigcad import plots
from rigcad.fab import estimate
from rigcad.fab import outlines
from rigcad.fab import orientation
from rigcad.fab import slicer
from rigcad.fab import split
from rigcad.fab import staircase
from rigcad.fab.mirror import MirrorSurface, mirror_faces
from rigcad.fab.printers import Printer
from rigcad.parts.recipe import Prism
from rigcad.units import hours_minutes

#: Parts cut from plate rather than printed.
CUT_PARTS = ("dome_template", "paraboloid_template")
#: Two orientations whose mean cusp differs by less than this fraction tie (upright and upside
#: down give the same |n . D| everywhere); the tie goes to less support on the mirror.
CUSP_TIE_RTOL = 1e-3


@dataclass
class FabResult:
    report: dict
    written: list[Path]
    timings_s: dict[str, float] = field(default_factory=dict)
    slicer_s: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)


def _mirror(part, layout) -> MirrorSurface | None:
    """The part's printed mirror: the design surface behind by the coating, forward by the layout's
    sanding stock (the surface the printer makes)."""
    if not part.mirrors:
        return None
    name, design = part.mirrors[0]
    stock = {"dome": layout.dome_stock, "paraboloid": layout.paraboloid_stock}.get(name, 0.0)
    return MirrorSurface(name, design.behind(layout.coating - stock), design)


def sanding_stock(printer: Printer, needed: float) -> tuple[float, str]:
    """The stock (mm) printed in front of a mirror and where it comes from: the printer file's
    ``sanding_stock``, or (auto) ``needed``, the stock the part's staircase needs in its print
    orientation (:func:`stock_bound`: no valley behind the sanded surface)."""
    if printer.sanding_stock is not None:
        return printer.sanding_stock, "printer file (sanding_stock)"
    return needed, "auto: the staircase's bound in the chosen orientations (stock_bound)"


def evaluate(vertices, faces, orient: orientation.Orientation, printer: Printer, mirror_f) -> dict:
    """One candidate orientation of one piece: fit, staircase (closed form), supports."""
    spin, extents = orientation.fit_spin(vertices, orient.direction, printer.usable)
    row = {"orientation": orient.name, "build_direction": [round(float(v), 12) for v in orient.direction],
           "fits": spin is not None, "spin_deg": None if spin is None else math.degrees(spin),
           "extents_mm": extents, "overhang_area_mm2": orientation.overhang_area(vertices, faces, orient.direction)}
    mask = None
    if mirror_f is not None and len(mirror_f.index):
        mask = np.zeros(len(faces), bool)
        mask[mirror_f.index] = True
        row["mirror_overhang_area_mm2"] = orientation.overhang_area(vertices, faces, orient.direction, mask)
        row["staircase_closed_form"] = staircase.surface_staircase(mirror_f, orient.direction, printer.layer_height)
    if spin is not None:
        row["support_model"] = orientation.support_contact(vertices, faces, orient.direction, mask)
    return row


#: Support contact on a mirror (mm2, the model's estimate) below this counts as none: a few
#: facets at a sector's edge, far under one support line's footprint.
MIRROR_SUPPORT_TIE_MM2 = 1.0


def choose(rows: list[dict]) -> int:
    """Index of the best candidate: among those that fit, the least support contact on the mirror
    (the model's estimate; below MIRROR_SUPPORT_TIE_MM2 counts as none), then the least mean cusp
    on the mirror (ties within CUSP_TIE_RTOL), then the least overhang, then the lowest height;
    without a mirror, the least overhang, then the lowest height."""
    ok = [i for i, r in enumerate(rows) if r["fits"]]
    if not ok:
        return 0
    if all("staircase_closed_form" in rows[i] for i in ok):
        def on_mirror(i):
            a = rows[i]["support_model"]["mirror_mm2"]
            return 0.0 if a < MIRROR_SUPPORT_TIE_MM2 else round(a, 0)

        least = min(on_mirror(i) for i in ok)
        ok = [i for i in ok if on_mirror(i) == least]
        best = min(rows[i]["staircase_closed_form"]["cusp_mean_mm"] for i in ok)
        ok = [i for i in ok if rows[i]["staircase_closed_form"]["cusp_mean_mm"] <= best * (1 + CUSP_TIE_RTOL)]
        return min(ok, key=lambda i: (round(rows[i]["overhang_area_mm2"], 3), rows[i]["extents_mm"]["z_mm"], i))
    return min(ok, key=lambda i: (round(rows[i]["overhang_area_mm2"], 3), rows[i]["extents_mm"]["z_mm"], i))


def run_fab(rig, printer: Printer, out: Path, *, gcode: bool = False, parts: list[str] | None = None,
            progress=None, workers: int | None = None, lock: Path | None = None, slicing=None) -> FabResult:
    """Run the stage for ``rig`` (a :class:`rigcad.rig.Rig`: the same converged dome, layout and
    recipes as the exported parts) into ``out`` (exports/<profile>/fab/<printer>); see the module
    docstring. ``progress(label)`` is called as each part is done; ``slicing(total)``, when
    given, is a context manager yielding ``step(label)``, called as each piece is sliced."""
    from rigcad.export.build import select_parts

    say = progress or (lambda msg: None)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    profile, layout = rig.profile, rig.layout
    timings["design_and_layout"] = time.perf_counter() - t0
    chord = profile.tessellation.chord_error
    tol_mirror = chord + 2e-3  # mesh vertices lie on the surface; facets within the chord error
    names = select_parts(parts)
    bed_c = (printer.build_volume.x / 2, printer.build_volume.y / 2)
    report_parts: dict[str, dict] = {}
    problems: list[str] = []
    jobs: list[slicer.SliceJob] = []
    job_part: dict[str, str] = {}
    stocks: dict[str, float] = {}  # mirror name -> stock printed in front of it (mm)
    meshes: dict[str, tuple] = {}  # piece -> (vertices in print position, faces, mirror face indices)

    with Staging(out, lock, made_from=profile_digest(rig.profile)) as stage:
        old_path = out / "fab.json"
        try:
            old = json.loads(old_path.read_text(encoding="utf-8")) if old_path.is_file() else {}
        except (OSError, ValueError):
            old = {}  # unreadable: nothing is reused
        for name in names:
            part = rig.recipe(name)
            if name in CUT_PARTS and isinstance(part.solid, Prism):
                t = time.perf_counter()
                o = outlines.outline(part, chord)
                dxf, svg = outlines.dxf_bytes(o), outlines.svg_bytes(o)
                stage.write_bytes(out / "outlines" / f"{name}.dxf", dxf)
                stage.write_bytes(out / "outlines" / f"{name}.svg", svg)
                report_parts[name] = {"process": "cut from plate (laser / water-jet)", "quantity": part.quantity,
                                      "plate_thickness_mm": o.thickness, "outline_size_mm": list(o.size),
                                      "outline_points": len(o.polygon), "chord_error_mm": chord,
                                      "files": {f"outlines/{name}.dxf": sha256_hex(dxf), f"outlines/{name}.svg": sha256_hex(svg)}}
                report_parts[name]["stages"] = _stage_templates(rig, name, printer, stocks, chord, stage, out)
                timings[f"outline:{name}"] = time.perf_counter() - t
                say(name)
                continue
            try:
                if part.mirrors:
                    entry, part_jobs = _with_stock(rig, part, printer, chord, tol_mirror, bed_c, stage, out, timings,
                                                   stocks, meshes)
                else:
                    entry, part_jobs = _fab_part(part, layout, printer, chord, tol_mirror, bed_c, stage, out, timings,
                                                 meshes)
                entry.pop("_plan", None)
            except RigcadError as err:
                problems.append(f"{name}: {err}")
                report_parts[name] = {"error": str(err)}
                say(name)
                continue
            say(name)
            report_parts[name] = entry
            for job in part_jobs:
                jobs.append(job)
                job_part[job.name] = name

        slicer_s: dict[str, float] = {}
        report_gcode = {"requested": gcode, "slicer": printer.slicer}
        ini = None
        if gcode and printer.slicer == "prusa-slicer" and jobs:
            t = time.perf_counter()
            cached = {}
            for pname, entry in old.get("parts", {}).items():
                for pc in entry.get("pieces", []):
                    g = pc.get("gcode") or {}
                    path = out / "gcode" / f"{pc['name']}.gcode"
                    proj = out / "3mf" / f"{pc['name']}.3mf"
                    if (g.get("key") and path.is_file() and sha256_hex(path.read_bytes()) == g.get("sha256")
                            and proj.is_file() and sha256_hex(proj.read_bytes()) == g.get("project_sha256")):
                        cached[pc["name"]] = (g["key"], path.read_bytes(), proj.read_bytes())
            from contextlib import nullcontext

            try:
                with (slicing(len(jobs)) if slicing else nullcontext(None)) as step:
                    results, version = slicer.slice_all(jobs, cached, workers,
                                                   on_done=(lambda r: step(f"sliced {r.name}")) if step else None)
            except FabricationError as err:
                problems.append(str(err))
                report_gcode["error"] = str(err)
                results, version = [], None
            report_gcode["slicer_version"] = version
            for job, res in zip(jobs, results):
                stage.write_bytes(out / "gcode" / f"{job.name}.gcode", res.gcode)
                stage.write_bytes(out / "3mf" / f"{job.name}.3mf", res.project)
                slicer_s[job.name] = res.seconds
                pc = next(p for p in report_parts[job_part[job.name]]["pieces"] if p["name"] == job.name)
                pc["gcode"] = {"key": job.key(version), "sha256": sha256_hex(res.gcode), "estimates": res.estimates,
                               "slicer_warnings": list(res.warnings), "project": f"3mf/{job.name}.3mf",
                               "project_sha256": sha256_hex(res.project), "placement": res.placement}
                if res.warnings:
                    problems.append(f"{job.name}: slicer warnings: {'; '.join(res.warnings)}")
                if job.name in meshes:
                    pc["gcode"]["support_contact"] = _support_contact(job.name, res.gcode, meshes[job.name], printer,
                                                                      stage, out)
            timings["gcode"] = time.perf_counter() - t
            ini = slicer.printer_ini(printer, support=False)
        elif gcode and printer.slicer != "prusa-slicer":
            report_gcode["note"] = (f"printer '{printer.name}' has no slicer rigcad can run (slicer: {printer.slicer}); "
                                    "time and material are rigcad's estimates")
        if ini is not None:
            stage.write_bytes(out / "printer.ini", ini.encode())

        t = time.perf_counter()
        report = {
            "rigcad_version": __version__,
            "profile": profile.name,
            "printer": printer.describe(),
            "frame": "part frame: mm, sample point at the origin, optical axis +z, working position; print "
                     "frame: build direction +z, bed at z = 0",
            "tolerances": {"stl_chord_error_mm": chord, "mirror_face_tolerance_mm": tol_mirror,
                           "pin_min_wall_mm": split.MIN_WALL, "pin_mirror_clearance_mm": split.MIRROR_CLEARANCE,
                           "orientation_cusp_tie_rtol": CUSP_TIE_RTOL,
                           "overhang_angle_deg": math.degrees(orientation.OVERHANG_ANGLE)},
            "gcode": report_gcode,
            "totals": _totals(report_parts),
            "parts": report_parts,
            "problems": problems,
        }
        stage.write_bytes(out / "fab.json", json_bytes(report))
        stage.write_bytes(out / "fab.md", markdown(report).encode())
        timings["report"] = time.perf_counter() - t
        written = stage.commit()
    return FabResult(report, written, timings, slicer_s, problems)


def _support_contact(name: str, gcode: bytes, mesh: tuple, printer: Printer, stage: Staging, out: Path) -> dict:
    """Support contact of one piece from its G-code's support extrusions (rigcad.fab.support), mm2
    on its mirror and its other faces; a picture (support/<piece>.png) for pieces with a mirror."""
    from rigcad.fab import support

    vertices, faces, mirror_index = mesh
    settings = printer.slicer_config.effective() if printer.slicer_config else {}
    beads = support.support_beads(gcode)
    areas = support.contact_areas(vertices, faces, mirror_index, beads, support.contact_reach(settings, printer.layer_height))
    pts, touched, on_m = areas.pop("_points"), areas.pop("_touched"), areas.pop("_mirror")
    areas["method"] = ("surface samples within reach_mm of the G-code's ;TYPE:Support material / Support material "
                       "interface extrusions (rigcad.fab.support)")
    if len(mirror_index):
        png = plots.support_contact(pts, touched, on_m, beads.points,
                                    f"{name}: support contact from the G-code: mirror {areas['mirror_mm2']:.0f} mm2, "
                                    f"other faces {areas['other_mm2']:.0f} mm2")
        stage.write_bytes(out / "support" / f"{name}.png", png)
        areas["png"] = f"support/{name}.png"
        areas["png_sha256"] = sha256_hex(png)
    return areas


#: The mirror each template gauges.
TEMPLATE_MIRROR = {"dome_template": "dome", "paraboloid_template": "paraboloid"}


def _stage_templates(rig, name: str, printer: Printer, stocks: dict, chord: float, stage: Staging,
                     out: Path) -> dict:
    """Templates that gauge the mirror at each stage of its finishing (thesis 3.4, Figure 3.11):
    ``printed`` (the surface the printer makes: the stock in front of the sanded one), ``sanded``
    (the surface the coating goes on: the design surface behind by the whole coating) and
    ``coated`` (the profile's gauged layer: ``outlines/<template>.dxf``). Depths in mm behind the
    design surface; the printed stage needs the stock, known when the mirror's part is in the
    same run or the printer file states it."""
    from rigcad.parts import templates

    make = {"dome_template": templates.dome_template, "paraboloid_template": templates.paraboloid_template}[name]
    mirror = TEMPLATE_MIRROR[name]
    coating = rig.layout.coating
    stock = stocks.get(mirror, printer.sanding_stock)
    rows = {"coated": {"gauges": f"the {rig.profile.templates.gauged_layer} surface",
                       "depth_behind_design_mm": templates.gauged_depth(rig.profile),
                       "files": [f"outlines/{name}.dxf", f"outlines/{name}.svg"]}}
    depths = {"sanded": ("the sanded surface, under the whole coating", coating)}
    if stock is not None:
        depths["printed"] = (f"the printed surface, {stock:.3f} mm of sanding stock in front of the sanded one",
                             coating - stock)
    else:
        rows["printed"] = {"note": f"not written: the stock is 'auto' and the {mirror} is not in this run "
                                   "(fab it too, or set sanding_stock in the printer file)"}
    for label, (what, depth) in depths.items():
        o = outlines.outline(make(rig.profile, rig.layout, depth), chord)
        files = {}
        for ext, data in (("dxf", outlines.dxf_bytes(o)), ("svg", outlines.svg_bytes(o))):
            path = f"outlines/{name}_{label}.{ext}"
            stage.write_bytes(out / path, data)
            files[path] = sha256_hex(data)
        rows[label] = {"gauges": what, "depth_behind_design_mm": depth, "files": files}
    return rows


def _with_stock(rig, part, printer: Printer, chord: float, tol_mirror: float, bed_c, stage: Staging, out: Path,
                timings: dict, stocks: dict, meshes: dict) -> tuple[dict, list]:
    """A mirror part printed with its sanding stock: the split and the orientations are chosen on
    the part as designed (0.1 mm changes neither), the stock follows (:func:`sanding_stock`), then
    the part with its mirror moved forward by the stock is split the same way and fabricated.
    Records the stock in ``stocks`` and in the entry."""
    name = part.name
    mirror = part.mirrors[0][0]
    t = time.perf_counter()
    first, _ = _fab_part(part, rig.layout, printer, chord, tol_mirror, bed_c, stage, out, timings, orient_only=True)
    steep = [pc["mirror_max_abs_normal_along_build"] for pc in first["pieces"]
             if pc["mirror_max_abs_normal_along_build"] is not None]
    bound = stock_bound(printer.layer_height, max(steep, default=0.0), chord)
    stock, source = sanding_stock(printer, bound)
    stocks[mirror] = stock
    record = {"stock_mm": stock, "source": source, "needed_bound_mm": bound,
              "needed_bound_formula": "layer/2 x max |n . D| over the mirror + STL chord error",
              "part_volume_without_stock_mm3": first["volume_mm3"],
              "mirror_area_without_stock_mm2": sum(pc["mirror_area_mm2"] for pc in first["pieces"])}
    timings[f"{name}:orient_for_stock"] = time.perf_counter() - t
    layout = rig.layout.with_sanding_stock(**{mirror: stock, ("paraboloid" if mirror == "dome" else "dome"): 0.0})
    stocked = replace(part, solid=rig.recipe(name, layout).solid)  # the same part, its mirror moved
    new, new_jobs = _fab_part(stocked, layout, printer, chord, tol_mirror, bed_c, stage, out, timings, meshes,
                              plan=first["_plan"])
    record["volume_added_mm3"] = new["volume_mm3"] - first["volume_mm3"]
    record["mirror_area_times_stock_mm3"] = record["mirror_area_without_stock_mm2"] * stock
    record["volume_added_over_area_times_stock"] = (record["volume_added_mm3"] / record["mirror_area_times_stock_mm3"]
                                                    if record["mirror_area_times_stock_mm3"] > 0 else None)
    changed = [pc["name"] for pc, q in zip(first["pieces"], new["pieces"]) if pc["orientation"] != q["orientation"]]
    if changed:
        record["orientation_changed_by_stock"] = changed
    # the stepped surface measured on the slices of the stocked mesh: any valley behind the sanded
    # surface is what sanding to the template would leave unfilled (0 when the bound holds)
    if "polishing" in new:
        record["valley_behind_sanded_surface_mm"] = max(0.0, new["polishing"]["stock_to_add_mm"] - stock)
    new["sanding_stock"] = record
    return new, new_jobs


def stock_bound(layer: float, steepest: float, chord: float) -> float:
    """The stock (mm) that keeps every valley of the staircase in front of the sanded surface,
    whatever the layers' phase: a layer's wall stands at its mid-height contour, so its inner
    corner lies layer/2 x |n . D| behind the surface (D the build direction, n the mirror's
    normal), and the STL's facets depart from the surface by up to the chord error."""
    return 0.5 * layer * steepest + chord


def _fab_part(part, layout, printer: Printer, chord: float, tol_mirror: float, bed_c, stage: Staging, out: Path,
              timings: dict, meshes: dict | None = None, plan=None, orient_only: bool = False) -> tuple[dict, list]:
    """One printed part: mesh, fit or split (``plan``: a split decided before, or None to find the
    fewest pieces), orient every piece, slice it, its STL and slicing job; ``orient_only`` stops
    after choosing the orientations (what the sanding stock needs to know, :func:`_with_stock`)."""
    from rigcad.export import mesh

    name = part.name
    t = time.perf_counter()
    man = mesh.build(part.solid, chord)
    mirror = _mirror(part, layout)
    timings[f"{name}:mesh"] = time.perf_counter() - t

    t = time.perf_counter()
    v, f = mesh.mesh_arrays(man)
    plate = None if mirror else orientation.plate_axis(v)

    def candidates(sector=None, sectors: bool = False) -> list[orientation.Orientation]:
        if mirror:
            return orientation.mirror_candidates(sector if sectors else None)
        return orientation.flat_candidates(plate) if plate is not None else orientation.generic_candidates()

    whole_fits = plan is None and orientation.fits_whole(v, bool(mirror), printer.usable)
    if plan is not None:
        pass
    elif whole_fits:
        plan = split.SplitPlan(1, 1, 0.0, (float(v[:, 2].min()), float(v[:, 2].max())))
    else:
        def fits(cell, plan, i, j):
            if cell.is_empty():
                return True
            cv, _ = mesh.mesh_arrays(cell)
            rng = plan.sector_range(i) if plan.sectors > 1 else None
            cands = candidates(rng, isinstance(plan, split.SplitPlan))
            return any(orientation.fit_spin(cv, o.direction, printer.usable)[0] is not None for o in cands)

        if split.is_off_axis(man):  # flat / off-axis parts: a grid in their own bounding box
            plan = split.plan_grid(man, fits)
        else:
            try:
                plan = split.plan_split(man, fits)
            except FabricationError:
                plan = split.plan_grid(man, fits)
    tongues: list = []
    pieces, pins, drilled = split.split_part(man, name, plan, printer.alignment_pin, mirror, tongues)
    timings[f"{name}:fit_split"] = time.perf_counter() - t

    entry = {"process": printer.process, "quantity": part.quantity, "description": part.description,
             "volume_mm3": man.volume(), "split": plan.describe(),
             "mirror": mirror.name if mirror else None, "_plan": plan}
    if plan.count > 1 and not orient_only:
        entry["pins"] = [{"centre_mm": list(p.centre), "axis": list(p.axis), "face": p.face} for p in pins]
        if tongues:
            entry["tongues"] = [t.describe() for t in tongues]
        entry["reassembly"] = reassembly(man, drilled, pieces, mirror, tol_mirror, pins, printer)
    piece_rows = []
    jobs = []
    map_pts, map_cusp = [], []
    t = time.perf_counter()
    for pc in pieces:
        pv, pf = mesh.mesh_arrays(pc.manifold)
        mf = mirror_faces(pv, pf, mirror, tol_mirror) if mirror else None
        cands = candidates(pc.sector_range, isinstance(plan, split.SplitPlan))
        rows = [evaluate(pv, pf, o, printer, mf) for o in cands]
        k = choose(rows)
        if not rows[k]["fits"]:
            raise FabricationError(f"piece {pc.name} fits the printer in no orientation")
        best = orientation.Orientation(cands[k].name, cands[k].direction, math.radians(rows[k]["spin_deg"]))
        rot = best.rotation()
        steep = float(np.abs(mf.normals @ np.asarray(best.direction)).max()) if mf is not None and len(mf.index) else None
        if orient_only:
            piece_rows.append({"name": pc.name, "orientation": best.name, "mirror_area_mm2": mf.area if mf else 0.0,
                               "mirror_max_abs_normal_along_build": steep})
            continue
        layers, shift = staircase.slice_layers(pc.manifold, rot, printer.layer_height, printer.first_layer_height)
        placed = orientation.place(pv, best, bed_c)
        if meshes is not None:
            meshes[pc.name] = (placed, pf, mf.index if mf is not None else np.zeros(0, int))
        stl = mesh.stl_bytes(placed, pf, pc.name)
        stage.write_bytes(out / "stl" / f"{pc.name}.stl", stl)
        volume = pc.manifold.volume()
        # print position = rotation @ part frame + translation (what orientation.place did), for readers of the STL
        translation = (placed - pv @ rot.T).mean(axis=0)
        row = {"name": pc.name, "orientation": best.name, "build_direction": rows[k]["build_direction"],
               "spin_deg": rows[k]["spin_deg"], "extents_mm": rows[k]["extents_mm"], "layers": layers.count,
               "print_transform": {"rotation": rot.tolist(), "translation_mm": translation.tolist()},
               "volume_mm3": volume, "needs_support": rows[k]["overhang_area_mm2"] > 0,
               "candidates": rows, "stl_sha256": sha256_hex(stl),
               "support_model": rows[k]["support_model"],
               "estimate": estimate.estimate(estimate.Features(volume, pc.manifold.surface_area(), layers.count,
                                                 rows[k]["support_model"]["support_envelope_mm3"],
                                                 rows[k]["support_model"]["mirror_under_mm2"]
                                                 + rows[k]["support_model"]["other_under_mm2"],
                                                 estimate.shell_thickness(printer), estimate.island_layers(layers)), printer)}
        if mf is not None and len(mf.index):
            steps = staircase.step_map(layers, rot, shift, mirror, tol_mirror)
            row["mirror_area_mm2"] = mf.area
            row["mirror_max_abs_normal_along_build"] = steep
            row["staircase_from_slices"] = steps.summary()
            row["polishing"] = staircase.polishing_allowance(steps)
            row["optical_effect_as_printed"] = staircase.optical_effect(mf, best.direction, mirror.name)
            map_pts.append(steps.points)
            map_cusp.append(steps.cusp_slices)
        piece_rows.append(row)
        if printer.slicer == "prusa-slicer":
            jobs.append(slicer.slice_job(printer, pc.name, stl, row["needs_support"], bed_c))
    timings[f"{name}:orient_slice"] = time.perf_counter() - t
    entry["pieces"] = piece_rows
    if orient_only:
        return entry, []
    entry["layers_total"] = sum(r["layers"] for r in piece_rows)
    if map_pts:
        pts, cusp = np.concatenate(map_pts), np.concatenate(map_cusp)
        orients = sorted({r["orientation"] for r in piece_rows})
        png = plots.staircase_map(pts, cusp, printer.layer_height,
                                  f"{name} on {printer.name}: cusp from slices, {printer.layer_height:.4g} mm layers, "
                                  f"{', '.join(orients)}")
        stage.write_bytes(out / "staircase" / f"{name}.png", png)
        ok = np.isfinite(cusp)
        entry["staircase_map"] = {"png": f"staircase/{name}.png", "png_sha256": sha256_hex(png),
                                  "cusp_mean_mm": float(cusp[ok].mean()), "cusp_max_mm": float(cusp[ok].max()),
                                  "cusp_p95_mm": float(np.percentile(cusp[ok], 95))}
        entry["polishing"] = {"sanding_depth_mm": max(r["polishing"]["sanding_depth_mm"] for r in piece_rows if "polishing" in r),
                              "stock_to_add_mm": max(r["polishing"]["stock_to_add_mm"] for r in piece_rows if "polishing" in r)}
    return entry, jobs


def reassembly(man, drilled, pieces, mirror, tol, pins, printer) -> dict:
    """The pieces put back together against the part: volumes, the mirror's area and its distance
    from the exact surface, the pins' distance from the mirror."""
    import manifold3d as m3d

    from rigcad.export import mesh

    union = m3d.Manifold.batch_boolean([p.manifold for p in pieces], m3d.OpType.Add)
    out = {"part_volume_mm3": man.volume(), "drilled_volume_mm3": drilled.volume(),
           "pieces_volume_sum_mm3": sum(p.manifold.volume() for p in pieces),
           "union_volume_mm3": union.volume(), "pin_holes": len(pins),
           "symmetric_difference_mm3": (union - drilled).volume() + (drilled - union).volume()}
    if mirror is not None:
        v, f = mesh.mesh_arrays(man)
        whole = mirror_faces(v, f, mirror, tol)
        area, dmax = 0.0, 0.0
        for p in pieces:
            pv, pf = mesh.mesh_arrays(p.manifold)
            mf = mirror_faces(pv, pf, mirror, tol)
            area += mf.area
            if len(mf.index):
                used = np.unique(pf[mf.index])
                dmax = max(dmax, float(np.abs(mirror.signed_distance(pv[used])).max()))
        out["mirror_area_part_mm2"] = whole.area
        out["mirror_area_pieces_mm2"] = area
        out["mirror_max_distance_pieces_mm"] = dmax
        if pins:
            c = np.array([p.centre for p in pins])
            out["pin_centre_min_depth_behind_mirror_mm"] = float(-mirror.signed_distance(c).max())
            out["pin_hole_min_clearance_to_mirror_mm"] = float(-mirror.signed_distance(c).max()
                                                               - printer.alignment_pin.hole_radius)
    return out


def _totals(parts: dict) -> dict:
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
    pr = report["printer"]
    lines = [f"# Fabrication: {report['profile']} on {pr['name']}", "",
             f"{pr['description']} ({pr['process']}); build volume {' x '.join(f'{v:g}' for v in pr['build_volume_mm'])} mm; "
             f"layer {pr['layer_height_mm']:.4g} mm; material {pr['material']}. Source: `{pr['source']}`.", "",
             "| part | qty | pieces | orientation | layers | time | material | mirror cusp mean / max (mm) | sanding depth / stock printed (mm) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, e in report["parts"].items():
        if "error" in e:
            lines.append(f"| {name} | | | **not printable:** {e['error']} | | | | | |")
            continue
        if "pieces" not in e:
            lines.append(f"| {name} | {e['quantity']} | cut | {e['process']}: `outlines/{name}.dxf`, `.svg` "
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
    lines += ["", f"Totals (with quantities): {tot['pieces']} pieces, {hours_minutes(tot['estimate_print_time_s'])} and "
              f"{tot['estimate_material_g']:.0f} g by rigcad's estimate (rigcad.fab.estimate, fitted to PrusaSlicer)"
              + (f"; slicer: {hours_minutes(tot['slicer_print_time_s'])}, {tot['slicer_filament_g']:.0f} g" if "slicer_print_time_s" in tot else "")
              + ".", ""]
    stocked = [(n, e) for n, e in report["parts"].items() if e.get("sanding_stock")]
    if stocked:
        lines += ["## Sanding stock", "",
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
        lines.append("")
    contact = [(pc, e) for e in report["parts"].values() for pc in e.get("pieces", [])
               if pc.get("gcode", {}).get("support_contact")]
    if contact:
        lines += ["## Support contact (from the G-code's support extrusions)", "",
                  "| piece | orientation | on the mirror (mm2) | on other faces (mm2) | model: mirror / other (mm2) | picture |",
                  "|---|---|---|---|---|---|"]
        for pc, e in contact:
            sc, sm = pc["gcode"]["support_contact"], pc.get("support_model", {})
            pic = f"![{pc['name']}]({sc['png']})" if "png" in sc else ""
            lines.append(f"| {pc['name']} | {pc['orientation']} | {sc['mirror_mm2']:.0f} | {sc['other_mm2']:.0f} | "
                         f"{sm.get('mirror_mm2', 0):.0f} / {sm.get('other_mm2', 0):.0f} | {pic} |")
        lines.append("")
    for name, e in report["parts"].items():
        if not e.get("staircase_map"):
            continue
        lines += [f"## {name}: staircase on the mirror", ""]
        if e["split"]["pieces"] > 1:
            s = e["split"]
            r = e.get("reassembly", {})
            lines.append(f"Split into {s['pieces']} pieces ({s['sectors']} sectors at "
                         f"{', '.join(f'{a:.1f}' for a in s['sector_planes_deg'])} deg"
                         + (f", bands cut at z = {', '.join(f'{z:.1f}' for z in s['band_cuts_z_mm'])} mm" if s["band_cuts_z_mm"] else "")
                         + f"), {r.get('pin_holes', 0)} pin holes of {pr['alignment_pin']['diameter_mm']:g} mm "
                         f"(at least {r.get('pin_hole_min_clearance_to_mirror_mm', float('nan')):.2f} mm behind the mirror)"
                         + "".join(f"; band cut z = {t['z_mm']:.1f} mm joined by a tongue and groove {t['depth_mm']:g} mm deep "
                                   f"({t['min_clearance_to_mirror_mm']:.2f} mm behind the mirror)" for t in e.get("tongues", []))
                         + ".")
            lines.append("")
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
        lines += ["", f"![staircase map of {name}]({e['staircase_map']['png']})", "",
                  "As printed, the steps' treads and risers tilt the surface normal by tens of degrees (ideal steps), "
                  "so every reflected ray is lost: the steps must be sanded away (depth above) before the coating. "
                  "The mirror is printed forward by the sanding stock (above), so that every valley lies in front of the sanded surface.", ""]
    if report["problems"]:
        lines += ["## Problems", ""] + [f"- {p}" for p in report["problems"]] + [""]
    return "\n".join(lines)
