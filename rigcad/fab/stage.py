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
A run without problems also records its inputs' key and every file's SHA-256 (published.json,
rigcad.export.reuse): a later run with the same key (:func:`inputs_key`), whichever command makes
it, reads the folder back instead of doing the work again, while every file is intact.
"""

from __future__ import annotations

import math
import time
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rigcad import plots
from rigcad.errors import FabricationError, RigcadError
from rigcad.export import reuse
from rigcad.export.atomic import Staging, json_bytes
from rigcad.export.manifest import profile_digest, sha256_hex
from rigcad.fab import choice, estimate, orientation, outlines, seams, slicer, split, staircase, support
from rigcad.fab.mirror import MirrorSurface, mirror_faces
from rigcad.fab.printers import Printer
from rigcad.fab.published import FabResult, inputs_key, read_back  # noqa: F401 (FabResult: this module's result)
from rigcad.fab.report import fab_report, markdown
from rigcad.optics.frames import Misalignment
from rigcad.parts.recipe import Prism

#: Parts cut from plate rather than printed.
CUT_PARTS = ("dome_template", "paraboloid_template")


@dataclass(frozen=True)
class _Run:
    """What every part of one run shares: the printer, the STL's chord error (mm), how far from the
    exact mirror a facet still counts as mirror (mm), the bed's centre (mm), and where files go."""
    printer: Printer
    chord: float
    tol_mirror: float
    bed_centre: tuple[float, float]
    stage: Staging
    out: Path


@dataclass
class PartFab:
    """One part through the stage: its fab.json entry, its slicing jobs, the split plan it was cut by
    (a mirror part is cut again by the same plan once its sanding stock is known), its pieces'
    meshes in print position (vertices, faces, mirror face indices: for the support contact read
    from the G-code) and the time of each step (s)."""
    entry: dict
    jobs: list = field(default_factory=list)
    plan: object = None
    meshes: dict[str, tuple] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)


@dataclass
class _Sliced:
    """The run's pieces through the slicer: fab.json's ``gcode`` figures of the run, each piece's
    G-code record, each piece's slicing time (s) and the problems met."""
    report: dict
    records: dict[str, dict]
    seconds: dict[str, float]
    problems: list[str]


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
    return needed, ("auto: the staircase's bound in the chosen orientations (stock_bound), the seams' step on the "
                    "gluing gauge and the sanding margin (seams.stock_needed)")


def run_fab(rig, printer: Printer, out: Path, *, gcode: bool = False, parts: list[str] | None = None,
            progress=None, workers: int | None = None, lock: Path | None = None, slicing=None) -> FabResult:
    """Run the stage for ``rig`` (a :class:`rigcad.rig.Rig`: the same converged dome, layout and
    recipes as the exported parts) into ``out`` (exports/<profile>/fab/<printer>); see the module
    docstring. ``progress(label)`` is called as each part is done; ``slicing(total)``, when
    given, is a context manager yielding ``step(label)``, called as each piece is sliced."""
    from rigcad.export.build import select_parts

    say = progress or (lambda msg: None)
    t0 = time.perf_counter()
    profile = rig.profile
    names = select_parts(parts)
    as_designed = rig.misalignment == Misalignment.none()  # a moved rig's result is never read back
    if as_designed:
        back = read_back(profile, printer, out, gcode=gcode, parts=parts, progress=progress, lock=lock)
        if back is not None:  # published from the same inputs and intact: nothing redone
            return back
    key = inputs_key(profile, printer, gcode, parts) if as_designed else None
    timings: dict[str, float] = {"design_and_layout": time.perf_counter() - t0}
    chord = profile.tessellation.chord_error
    report_parts: dict[str, dict] = {}
    problems: list[str] = []
    done: dict[str, PartFab] = {}
    stocks: dict[str, float] = {}  # mirror name -> stock printed in front of it (mm)
    with Staging(out, lock, made_from=profile_digest(rig.profile), carry=reuse.carried) as stage:
        # mesh vertices lie on the surface; facets within the chord error
        run = _Run(printer, chord, chord + 2e-3, (printer.build_volume.x / 2, printer.build_volume.y / 2), stage, out)
        old = _previous_report(out)  # read before anything is published over it
        for name in names:
            part = rig.recipe(name)
            if part.bought:  # the profile's buy: standard stock, never printed
                report_parts[name] = {"process": "bought", "stock": part.bought, "quantity": part.quantity}
                say(name)
                continue
            if name in CUT_PARTS and isinstance(part.solid, Prism):
                done[name] = _cut_part(rig, part, run, stocks)
            else:
                try:
                    if part.mirrors:
                        done[name], stocks[part.mirrors[0][0]] = _with_stock(rig, part, run)
                    else:
                        done[name] = _fab_part(part, rig.layout, run)
                except RigcadError as err:
                    problems.append(f"{name}: {err}")
                    done[name] = PartFab({"error": str(err)})
            report_parts[name] = done[name].entry
            rec = done[name].entry.get("seams")
            whole = whole_fit_hint(rig, name, printer, chord) if rec and not rec.get("glue_fills", True) else ""
            problems += seams.problems(name, rec, whole)
            timings.update(done[name].timings)
            say(name)
        if parts:
            report_parts = _with_earlier_parts(report_parts, old, out, rig.profile)
        jobs = [job for d in done.values() for job in d.jobs]
        report_gcode = {"requested": gcode, "slicer": printer.slicer}
        slicer_s: dict[str, float] = {}
        if gcode and printer.slicer == "prusa-slicer" and jobs:
            t = time.perf_counter()
            meshes = {piece: m for d in done.values() for piece, m in d.meshes.items()}
            sliced = _slice(jobs, meshes, _cached_gcode(old, out), run, workers, slicing)
            report_gcode.update(sliced.report)
            problems += sliced.problems
            slicer_s = sliced.seconds
            problems += _with_gcode(done, sliced.records, printer)
            timings["gcode"] = time.perf_counter() - t
            stage.write_bytes(out / "printer.ini", slicer.printer_ini(printer, support=False).encode())
        elif gcode and printer.slicer != "prusa-slicer":
            report_gcode["note"] = (f"printer '{printer.name}' has no slicer rigcad can run (slicer: {printer.slicer}); "
                                    "time and material are rigcad's estimates")
        t = time.perf_counter()
        report = _report(rig, printer, run, report_gcode, report_parts, problems)
        stage.write_bytes(out / "fab.json", json_bytes(report))
        stage.write_bytes(out / "fab.md", markdown(report).encode())
        if key is not None and not problems:  # a run with problems is never read back: the next one retries
            reuse.record(stage, out, key)
        timings["report"] = time.perf_counter() - t
        written = stage.commit()
    return FabResult(report, written, timings, slicer_s, problems)


#: A split part's profile key that sets its length, whose value lets it print whole (the beam's
#: overhang beyond the dome's wall at each end; rigcad.parts.beam).
LENGTH_KEYS = {"beam": "beam.overhang"}
#: The step (mm) a suggested value is rounded down to: a figure one types into a profile.
SUGGEST_STEP = 0.5


def _with_gcode(done: dict, records: dict, printer: Printer) -> list[str]:
    """Each sliced piece's G-code record put in its fab.json row; the problems: support the G-code
    puts on a mirror outside its seams' faired band (rigcad.fab.support.mirror_problems)."""
    problems = []
    for d in done.values():
        for pc in d.entry.get("pieces", []):
            if pc["name"] in records:
                pc["gcode"] = records[pc["name"]]
                if d.entry.get("mirror") and "support_contact" in pc["gcode"]:
                    problems += support.mirror_problems(pc["name"], pc["gcode"]["support_contact"],
                                                        pc["support_model"]["mirror_mm2"], printer.source)
    return problems


def whole_fit_hint(rig, name: str, printer: Printer, chord: float) -> str:
    """What lets part ``name`` print whole on ``printer`` (no seams to glue), for a problem line:
    the printer's usable volume to beat with another printer, and for a part whose length a profile
    key sets (LENGTH_KEYS) the largest value, rounded down to SUGGEST_STEP, with which the part fits
    (judged by the same fit test as the split, rigcad.fab.choice.fits); none when even 0 does not fit."""
    from dataclasses import replace as dc_replace

    from rigcad.export import mesh
    from rigcad.parts.beam import beam as beam_recipe

    u = printer.usable
    other = f"a printer whose usable volume ({u[0]:g} x {u[1]:g} x {u[2]:g} mm on the {printer.name}) takes it whole (--printer)"
    key = LENGTH_KEYS.get(name)
    if key != "beam.overhang":
        return other
    layout, profile = rig.layout, rig.profile

    def fits_with(overhang: float) -> bool:
        part = beam_recipe(profile, dc_replace(layout, beam_half_length=layout.slot_r + overhang))
        v, _ = mesh.mesh_arrays(mesh.build(part.solid, chord))
        return choice.fits(v, choice.candidates(False, orientation.plate_axis(v)), printer)

    now = profile.beam.overhang
    if not fits_with(0.0):
        return f"{key} cannot (the beam does not fit whole even at 0 mm: its seats set its length); {other}"
    lo, hi = 0.0, now  # fits at lo, not at hi (the run split it): bisect to a hundredth of the step
    while hi - lo > 0.01 * SUGGEST_STEP:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits_with(mid) else (lo, mid)
    best = SUGGEST_STEP * math.floor(lo / SUGGEST_STEP)
    while best > 0.0 and not fits_with(best):  # the fit is monotonic in the length; kept honest anyway
        best -= SUGGEST_STEP
    return f"{key} at most {best:g} mm (now {now:g} mm; the beam then fits the bed whole), or {other}"


def _with_earlier_parts(report_parts: dict, old: dict, out: Path, profile) -> dict:
    """A run of some parts (``--parts``) into a folder where an earlier run made others from the same
    profile keeps their files (Staging carries them over), so the report keeps their entries too,
    marked ``from_earlier_run``: one report for the whole folder, never one that disagrees with the
    files beside it. An earlier run from another profile has its files dropped, and its entries."""
    from rigcad.export.atomic import read_made_from
    from rigcad.export.build import PARTS

    earlier = old.get("parts") if isinstance(old.get("parts"), dict) else {}
    if not earlier or read_made_from(out) != profile_digest(profile):
        return report_parts
    out_parts = {}
    for name in PARTS:
        if name in report_parts:
            out_parts[name] = report_parts[name]
        elif isinstance(earlier.get(name), dict):
            out_parts[name] = {**earlier[name], "from_earlier_run": True}
    return out_parts


def _previous_report(out: Path) -> dict:
    """The fab.json of an earlier run in ``out`` ({} when there is none or it cannot be read)."""
    from rigcad.export.readback import own_json

    old = own_json(out / "fab.json")  # read as data: a bomb, a FIFO or a giant is None, never a traceback
    return old if isinstance(old, dict) else {}  # unreadable: nothing is reused


def _cached_gcode(old: dict, out: Path) -> dict[str, tuple]:
    """The G-code and PrusaSlicer projects of the earlier run whose report is ``old``, still in
    ``out`` as it recorded them: piece -> (slicing key, G-code, project)."""
    cached = {}
    for entry in old.get("parts", {}).values():
        for pc in entry.get("pieces", []):
            g = pc.get("gcode") or {}
            gcode, project = out / "gcode" / f"{pc['name']}.gcode", out / "3mf" / f"{pc['name']}.3mf"
            if (g.get("key") and gcode.is_file() and sha256_hex(gcode.read_bytes()) == g.get("sha256")
                    and project.is_file() and sha256_hex(project.read_bytes()) == g.get("project_sha256")):
                cached[pc["name"]] = (g["key"], gcode.read_bytes(), project.read_bytes())
    return cached


def _slice(jobs: list, meshes: dict, cached: dict, run: _Run, workers: int | None, slicing) -> _Sliced:
    """Slice every piece with PrusaSlicer (``cached``: an earlier run's results by key), write each
    G-code and project, and read each piece's support contact from its G-code."""
    problems: list[str] = []
    report: dict = {}
    try:
        with (slicing(len(jobs)) if slicing else nullcontext(None)) as step:
            results, version = slicer.slice_all(jobs, cached, workers,
                                                on_done=(lambda r: step(f"sliced {r.name}")) if step else None)
    except FabricationError as err:
        problems.append(str(err))
        report["error"] = str(err)
        results, version = [], None
    report["slicer_version"] = version
    records, seconds = {}, {}
    for job, res in zip(jobs, results):
        run.stage.write_bytes(run.out / "gcode" / f"{job.name}.gcode", res.gcode)
        run.stage.write_bytes(run.out / "3mf" / f"{job.name}.3mf", res.project)
        seconds[job.name] = res.seconds
        records[job.name] = {"key": job.key(version), "sha256": sha256_hex(res.gcode), "estimates": res.estimates,
                             "slicer_warnings": list(res.warnings), "project": f"3mf/{job.name}.3mf",
                             "project_sha256": sha256_hex(res.project), "placement": res.placement}
        if res.warnings:
            problems.append(f"{job.name}: slicer warnings: {'; '.join(res.warnings)}")
        if job.name in meshes:
            records[job.name]["support_contact"] = _support_contact(job.name, res.gcode, meshes[job.name], run)
    return _Sliced(report, records, seconds, problems)


def _cut_part(rig, part, run: _Run, stocks: dict) -> PartFab:
    """A template cut from plate: its DXF and SVG outlines, and one per finishing stage of the
    mirror it gauges (``stocks``: the sanding stock of the mirrors fabricated so far in this run)."""
    name, chord = part.name, run.chord
    t = time.perf_counter()
    o = outlines.outline(part, chord)
    dxf, svg = outlines.dxf_bytes(o), outlines.svg_bytes(o)
    run.stage.write_bytes(run.out / "outlines" / f"{name}.dxf", dxf)
    run.stage.write_bytes(run.out / "outlines" / f"{name}.svg", svg)
    entry = {"process": "cut from plate (laser / water-jet)", "quantity": part.quantity,
             "plate_thickness_mm": o.thickness, "outline_size_mm": list(o.size),
             "outline_points": len(o.polygon), "chord_error_mm": chord,
             "files": {f"outlines/{name}.dxf": sha256_hex(dxf), f"outlines/{name}.svg": sha256_hex(svg)}}
    entry["stages"] = _stage_templates(rig, name, run, stocks)
    return PartFab(entry, timings={f"outline:{name}": time.perf_counter() - t})


def _support_contact(name: str, gcode: bytes, mesh: tuple, run: "_Run") -> dict:
    """Support contact of one piece from its G-code's support extrusions (rigcad.fab.support), mm2
    on its mirror (within and outside its meridional seams' faired band, rigcad.fab.seams) and its
    other faces; a picture (support/<piece>.png) for pieces with a mirror."""
    printer, stage, out = run.printer, run.stage, run.out
    vertices, faces, mirror_index, frame_vertices, seam_normals = mesh
    settings = printer.slicer_config.effective() if printer.slicer_config else {}
    beads = support.support_beads(gcode)
    band = (frame_vertices, lambda p: seams.seam_distance(p, seam_normals), seams.SEAM_BAND_MM) if seam_normals else None
    areas = support.contact_areas(vertices, faces, mirror_index, beads, support.contact_reach(settings, printer.layer_height),
                                  band)
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


def _stage_templates(rig, name: str, run: "_Run", stocks: dict) -> dict:
    """Templates that gauge the mirror at each stage of its finishing (thesis 3.4, Figure 3.11):
    ``printed`` (the surface the printer makes: the stock in front of the sanded one), ``sanded``
    (the surface the coating goes on: the design surface behind by the whole coating) and
    ``coated`` (the profile's gauged layer: ``outlines/<template>.dxf``). Depths in mm behind the
    design surface; the printed stage needs the stock, known when the mirror's part is in the
    same run or the printer file states it."""
    from rigcad.parts import templates

    printer, chord, stage, out = run.printer, run.chord, run.stage, run.out
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


def _with_stock(rig, part, run: _Run) -> tuple[PartFab, float]:
    """A mirror part printed with its sanding stock: the split and the orientations are chosen on
    the part as designed (0.1 mm changes neither), the stock follows (:func:`sanding_stock`), then
    the part with its mirror moved forward by the stock is split the same way and fabricated.
    Returns it with the stock (mm), which its entry records too."""
    name = part.name
    mirror = part.mirrors[0][0]
    t = time.perf_counter()
    first = _fab_part(part, rig.layout, run, orient_only=True)
    pieces = first.entry["pieces"]
    steep = [pc["mirror_max_abs_normal_along_build"] for pc in pieces if pc["mirror_max_abs_normal_along_build"] is not None]
    bound = stock_bound(run.printer.layer_height, max(steep, default=0.0), run.chord)
    step = seams.step_on_gauge(rig.profile.templates.thickness) if first.plan.count > 1 else 0.0  # a split mirror's seams
    stock, source = sanding_stock(run.printer, seams.stock_needed(bound, step))
    record = {"stock_mm": stock, "source": source, "needed_bound_mm": bound, "seam_step_mm": step,
              "sanding_margin_mm": seams.SANDING_MARGIN_MM, "needed_mm": seams.stock_needed(bound, step),
              "needed_bound_formula": "layer/2 x max |n . D| over the mirror + STL chord error",
              "part_volume_without_stock_mm3": first.entry["volume_mm3"],
              "mirror_area_without_stock_mm2": sum(pc["mirror_area_mm2"] for pc in pieces)}
    stock_s = time.perf_counter() - t
    layout = rig.layout.with_sanding_stock(**{mirror: stock, ("paraboloid" if mirror == "dome" else "dome"): 0.0})
    stocked = replace(part, solid=rig.recipe(name, layout).solid)  # the same part, its mirror moved
    done = _fab_part(stocked, layout, run, plan=first.plan)
    new = done.entry
    record["volume_added_mm3"] = new["volume_mm3"] - first.entry["volume_mm3"]
    record["mirror_area_times_stock_mm3"] = record["mirror_area_without_stock_mm2"] * stock
    record["volume_added_over_area_times_stock"] = (record["volume_added_mm3"] / record["mirror_area_times_stock_mm3"]
                                                    if record["mirror_area_times_stock_mm3"] > 0 else None)
    changed = [pc["name"] for pc, q in zip(pieces, new["pieces"]) if pc["orientation"] != q["orientation"]]
    if changed:
        record["orientation_changed_by_stock"] = changed
    # the stepped surface measured on the slices of the stocked mesh: any valley behind the sanded
    # surface is what sanding to the template would leave unfilled (0 when the bound holds)
    if "polishing" in new:
        record["valley_behind_sanded_surface_mm"] = max(0.0, new["polishing"]["stock_to_add_mm"] - stock)
    new["sanding_stock"] = record
    if "seams" in new:
        new["seams"].update(seams.mirror_record(run.printer, stock, rig.profile.templates.thickness,
                                                (new.get("pin_fit") or {}).get("pin_diameter_mm"), bound,
                                                (new.get("reassembly") or {}).get("pin_hole_wall_min_depth_behind_mirror_mm")))
    done.timings = {**first.timings, f"{name}:orient_for_stock": stock_s, **done.timings}
    return done, stock


def _report(rig, printer: Printer, run: _Run, report_gcode: dict, report_parts: dict, problems: list[str]) -> dict:
    """fab.json's content: the parts, the G-code and the tolerance stack with this run's seams (its
    refusals are added to ``problems``)."""
    stack_record, stack_problems = tolerance_stack(rig, printer, report_parts)
    problems += stack_problems
    report = fab_report(rig.profile.name, printer, run.chord, run.tol_mirror, report_gcode, report_parts, problems)
    if stack_record is not None:
        report["stack"] = stack_record
    return report


def tolerance_stack(rig, printer: Printer, report_parts: dict) -> tuple[dict | None, list[str]]:
    """The rig's tolerance stack on this printer (rigcad.fab.stack): the seams a chain crosses in each
    chain part from this run's split plans (``seams_from_fab``; estimated for a chain part the run did
    not make), with the adjusters and locating features the parts declare. Returns fab.json's record
    (with the table as Markdown lines) and the problems: one line naming each placement the printed
    rig can neither hold nor adjust, its dominating links and the ``buy:`` option. A printer file
    without ``process_errors`` has no stack (None, no problem: nothing to reckon with)."""
    from rigcad.fab import stack as ST

    if printer.process_errors is None:
        return None, []
    seams = ST.estimate_seams(rig.profile, rig.layout, printer)
    made = {k: e for k, e in report_parts.items()
            if k in ST.CHAIN_PARTS and "error" not in e and e.get("process") != "bought" and "split" in e}
    seams.update(ST.seams_from_fab(made))
    report = ST.stack(rig.profile, rig.layout, printer, seams=seams)
    rec = ST.record(report)
    rec["seams_from"] = {k: ("this run's split plans" if k in made else "estimated") for k in sorted(seams)}
    rec["table_md"] = ST.table_lines(report)
    try:
        ST.refuse(report)
    except FabricationError as err:
        return rec, [f"tolerance stack: {err}"]
    return rec, []


def stock_bound(layer: float, steepest: float, chord: float) -> float:
    """The stock (mm) that keeps every valley of the staircase in front of the sanded surface,
    whatever the layers' phase: a layer's wall stands at its mid-height contour, so its inner
    corner lies layer/2 x |n . D| behind the surface (D the build direction, n the mirror's
    normal), and the STL's facets depart from the surface by up to the chord error."""
    return 0.5 * layer * steepest + chord


@dataclass
class _Oriented:
    """A piece in its chosen print orientation: its mesh in the part frame, its mirror's faces
    (None without a mirror), the orientation with its spin, every candidate's row and the chosen
    one, and the steepest |n . D| over its mirror (None without one)."""
    vertices: np.ndarray
    faces: np.ndarray
    mirror_f: object
    best: orientation.Orientation
    rows: list[dict]
    chosen: dict
    steepest: float | None


def _fab_part(part, layout, run: _Run, plan=None, orient_only: bool = False) -> PartFab:
    """One printed part: mesh, fit or split (``plan``: a split decided before, or None to find the
    fewest pieces), orient every piece, slice it, its STL and slicing job; ``orient_only`` stops
    after choosing the orientations (what the sanding stock needs to know, :func:`_with_stock`)."""
    from rigcad.export import mesh

    name = part.name
    timings = {}
    t = time.perf_counter()
    man = mesh.build(part.solid, run.chord)
    mirror = _mirror(part, layout)
    timings[f"{name}:mesh"] = time.perf_counter() - t
    t = time.perf_counter()
    v, _ = mesh.mesh_arrays(man)
    plate = None if mirror else orientation.plate_axis(v)
    datums = getattr(part, "datums", ())
    if plan is None:
        plan = choice.split_plan(man, v, mirror is not None, plate, run.printer, split.keepouts(datums))
    tongues: list = []
    pin = run.printer.alignment_pin
    if mirror is not None and run.printer.process_errors is not None:
        pin = seams.float_pin(pin, run.printer.process_errors.position)  # glued on a gauge, not on the pins
    pinless: list = []  # a split mirror's seams that take no pins (split.PINLESS_WHY)
    pieces, pins, drilled = split.split_part(man, name, plan, pin, mirror, tongues, wall=split.pin_wall(run.printer),
                                             pinless=pinless)
    timings[f"{name}:fit_split"] = time.perf_counter() - t
    entry = {"process": run.printer.process, "quantity": part.quantity, "description": part.description,
             "volume_mm3": man.volume(), "split": plan.describe(), "mirror": mirror.name if mirror else None}
    if plan.count > 1 and not orient_only:
        entry["pins"] = [{"centre_mm": list(p.centre), "axis": list(p.axis), "face": p.face, "diameter_mm": p.diameter}
                         for p in pins]
        entry["pin_fit"] = split.pin_fit(run.printer, pins, pin)
        if datums:
            entry["datum_seams"] = split.datum_seams(datums, plan)
        if tongues:
            entry["tongues"] = [t.describe() for t in tongues]
        if pinless:
            entry["pinless_seams"] = pinless
        entry["reassembly"] = reassembly(man, drilled, pieces, mirror, run.tol_mirror, pins, run.printer)
    t = time.perf_counter()
    sectors = isinstance(plan, split.SplitPlan)
    oriented = [_orient(pc, mirror, plate, sectors, run) for pc in pieces]
    if orient_only:
        entry["pieces"] = [{"name": pc.name, "orientation": o.best.name,
                            "mirror_area_mm2": o.mirror_f.area if o.mirror_f else 0.0,
                            "mirror_max_abs_normal_along_build": o.steepest} for pc, o in zip(pieces, oriented)]
        timings[f"{name}:orient_slice"] = time.perf_counter() - t
        return PartFab(entry, plan=plan, timings=timings)
    if plan.count > 1:
        entry["seams"] = seams.glue_record(run.printer, plan, pieces, oriented)
    done = PartFab(entry, plan=plan, timings=timings)
    entry["pieces"], maps = [], []
    for pc, o in zip(pieces, oriented):
        seam_normals = seams.cut_normals(plan, pc) if mirror is not None and sectors else []
        row, done.meshes[pc.name], job, staircase_map = _print_piece(pc, o, mirror, run, seam_normals)
        entry["pieces"].append(row)
        done.jobs += [job] if job is not None else []
        maps += [staircase_map] if staircase_map is not None else []
    timings[f"{name}:orient_slice"] = time.perf_counter() - t
    entry["layers_total"] = sum(r["layers"] for r in entry["pieces"])
    if maps:
        entry.update(_staircase_map(name, entry["pieces"], maps, run))
    return done


def _orient(pc, mirror, plate, sectors: bool, run: _Run) -> _Oriented:
    """Piece ``pc`` in its best print orientation (rigcad.fab.choice) among its part's candidates
    (``sectors``: the part is split in sectors about its axis, each with its own candidates)."""
    from rigcad.export import mesh

    pv, pf = mesh.mesh_arrays(pc.manifold)
    mf = mirror_faces(pv, pf, mirror, run.tol_mirror) if mirror else None
    cands = choice.candidates(mirror is not None, plate, pc.sector_range if sectors else None)
    best, rows, chosen = choice.best_orientation(pv, pf, mf, cands, run.printer, pc.name)
    steep = float(np.abs(mf.normals @ np.asarray(best.direction)).max()) if mf is not None and len(mf.index) else None
    return _Oriented(pv, pf, mf, best, rows, chosen, steep)


def _print_piece(pc, o: _Oriented, mirror, run: _Run, seam_normals=()) -> tuple[dict, tuple, object, tuple | None]:
    """Slice piece ``pc`` in its orientation and write its STL in print position. Returns its
    fab.json row, its mesh in print position (vertices, faces, mirror face indices, and the same
    vertices in the part frame with ``seam_normals``, its meridional cut planes' normals), its slicing
    job (None for a printer rigcad cannot slice for) and its mirror's staircase map (points, cusp
    from the slices; None without a mirror)."""
    from rigcad.export import mesh

    printer = run.printer
    rot = o.best.rotation()
    layers, shift = staircase.slice_layers(pc.manifold, rot, printer.layer_height, printer.first_layer_height)
    placed = orientation.place(o.vertices, o.best, run.bed_centre)
    stl = mesh.stl_bytes(placed, o.faces, pc.name)
    run.stage.write_bytes(run.out / "stl" / f"{pc.name}.stl", stl)
    volume = pc.manifold.volume()
    # print position = rotation @ part frame + translation (what orientation.place did), for readers of the STL
    translation = (placed - o.vertices @ rot.T).mean(axis=0)
    support_model = o.chosen["support_model"]
    row = {"name": pc.name, "orientation": o.best.name, "build_direction": o.chosen["build_direction"],
           "spin_deg": o.chosen["spin_deg"], "extents_mm": o.chosen["extents_mm"], "layers": layers.count,
           "print_transform": {"rotation": rot.tolist(), "translation_mm": translation.tolist()},
           "volume_mm3": volume, "needs_support": o.chosen["overhang_area_mm2"] > 0,
           "candidates": o.rows, "stl_sha256": sha256_hex(stl), "support_model": support_model,
           "estimate": estimate.estimate(estimate.Features(
               volume, pc.manifold.surface_area(), layers.count, support_model["support_envelope_mm3"],
               support_model["mirror_under_mm2"] + support_model["other_under_mm2"],
               estimate.shell_thickness(printer), estimate.island_layers(layers)), printer)}
    staircase_map = None
    if o.mirror_f is not None and len(o.mirror_f.index):
        steps = staircase.step_map(layers, rot, shift, mirror, run.tol_mirror)
        row["mirror_area_mm2"] = o.mirror_f.area
        row["mirror_max_abs_normal_along_build"] = o.steepest
        row["staircase_from_slices"] = steps.summary()
        row["polishing"] = staircase.polishing_allowance(steps)
        row["optical_effect_as_printed"] = staircase.optical_effect(o.mirror_f, o.best.direction, mirror.name)
        staircase_map = (steps.points, steps.cusp_slices)
    job = slicer.slice_job(printer, pc.name, stl, row["needs_support"], run.bed_centre) \
        if printer.slicer == "prusa-slicer" else None
    piece_mesh = (placed, o.faces, o.mirror_f.index if o.mirror_f is not None else np.zeros(0, int),
                  o.vertices, list(seam_normals))
    return row, piece_mesh, job, staircase_map


def _staircase_map(name: str, rows: list[dict], maps: list[tuple], run: _Run) -> dict:
    """A mirror part's staircase over all its pieces: the map's picture (staircase/<part>.png), its
    cusp statistics, and the deepest sanding and stock any piece needs."""
    pts, cusp = np.concatenate([m[0] for m in maps]), np.concatenate([m[1] for m in maps])
    orients = sorted({r["orientation"] for r in rows})
    printer = run.printer
    png = plots.staircase_map(pts, cusp, printer.layer_height,
                              f"{name} on {printer.name}: cusp from slices, {printer.layer_height:.4g} mm layers, "
                              f"{', '.join(orients)}")
    run.stage.write_bytes(run.out / "staircase" / f"{name}.png", png)
    ok = np.isfinite(cusp)
    polished = [r["polishing"] for r in rows if "polishing" in r]
    return {"staircase_map": {"png": f"staircase/{name}.png", "png_sha256": sha256_hex(png),
                              "cusp_mean_mm": float(cusp[ok].mean()), "cusp_max_mm": float(cusp[ok].max()),
                              "cusp_p95_mm": float(np.percentile(cusp[ok], 95))},
            "polishing": {"sanding_depth_mm": max(p["sanding_depth_mm"] for p in polished),
                          "stock_to_add_mm": max(p["stock_to_add_mm"] for p in polished)}}


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
            r = np.array([p.hole_diameter / 2 or printer.alignment_pin.hole_radius for p in pins])
            out["pin_hole_min_clearance_to_mirror_mm"] = float((-mirror.signed_distance(c) - r).min())
            # the holes' walls along their whole depth (the ends of a hole in a curved shell come nearest)
            out["pin_hole_wall_min_depth_behind_mirror_mm"] = split.hole_clearance(
                pins, printer.alignment_pin.depth, mirror)
    return out
