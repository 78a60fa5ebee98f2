"""``rigcad manual PROFILE --printer NAME``: the assembly and calibration manual of one rig for one
printer, written to ``exports/<profile>/manual/<printer>/``:

- ``manual.md`` with its pictures in ``images/`` (assembled rig, one exploded view per assembly
  step, the calibration tools) and ``calibration/circle.png`` (the projector's calibration image at
  its resolution);
- ``manual.html``: the same document as one printable, self-contained page (pictures inline);
- ``manual.json``: every computed figure of the bill and the calibration, units in the keys.

The document is built once as a list of blocks and written twice (Markdown, HTML), so the two never
differ. Its figures come from the Rig (recipes, layout, design map), the printer and the fab stage's
report (run here for that printer: ``rigcad.fab``), never typed in.
"""

from __future__ import annotations

import base64
import html
import math
import re
from pathlib import Path

from rigcad._version import __version__
from rigcad.manual import bom as B
from rigcad.manual import calibration as C
from rigcad.manual import camera_lens
from rigcad.manual import drawings
from rigcad.manual import tower_joints
from rigcad.parts.locating import DowelRegister
from rigcad.units import hours_minutes

MIL = 0.0254  # mm

# -- a small document model ---------------------------------------------------------------------


class Doc:
    """Blocks: ("h", level, text), ("p", text), ("ul", [text]), ("ol", [text]), ("table", header,
    rows), ("img", relative path, caption), ("box", title, [text]): a framed warning. Inline: `code` and
    **bold**."""

    def __init__(self) -> None:
        self.blocks: list[tuple] = []

    def h(self, level: int, text: str) -> None:
        self.blocks.append(("h", level, text))

    def p(self, text: str) -> None:
        self.blocks.append(("p", text))

    def ul(self, items) -> None:
        self.blocks.append(("ul", list(items)))

    def ol(self, items) -> None:
        self.blocks.append(("ol", list(items)))

    def table(self, header, rows) -> None:
        self.blocks.append(("table", list(header), [list(r) for r in rows]))

    def img(self, path: str, caption: str) -> None:
        self.blocks.append(("img", path, caption))

    def box(self, title: str, items) -> None:
        """A framed warning: its title in bold and its items (a blockquote in Markdown)."""
        self.blocks.append(("box", title, list(items)))

    def page(self, text: str, shift: int = 1) -> None:
        """Blocks from a Markdown page of headings (their level moved down by ``shift``), lists (``-`` or
        ``1.``; an indented line continues the item) and paragraphs, as another module writes one."""
        kind, items, para = None, [], []

        def flush() -> None:
            nonlocal kind, items, para
            if para:
                self.p(" ".join(para))
            if items:
                (self.ol if kind == "ol" else self.ul)(items)
            kind, items, para = None, [], []

        for line in text.splitlines():
            head = re.match(r"(#+) (.*)", line)
            item = re.match(r"(?:- |\d+\. )(.*)", line)
            if head:
                flush()
                self.h(min(len(head.group(1)) + shift, 6), head.group(2))
            elif item:
                if para:
                    flush()
                new = "ol" if line[0].isdigit() else "ul"
                if kind not in (None, new):
                    flush()
                kind = new
                items.append(item.group(1))
            elif line.startswith("  ") and items:
                items[-1] += " " + line.strip()
            elif line.strip():
                if items:
                    flush()
                para.append(line.strip())
            else:
                flush()
        flush()

    def markdown(self) -> str:
        out = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                out.append("#" * b[1] + " " + b[2])
            elif kind == "p":
                out.append(b[1])
            elif kind in ("ul", "ol"):
                out.append("\n".join((f"{i + 1}. " if kind == "ol" else "- ") + t for i, t in enumerate(b[1])))
            elif kind == "table":
                out.append("\n".join(["| " + " | ".join(b[1]) + " |", "|" + "---|" * len(b[1])]
                                     + ["| " + " | ".join(str(c) for c in r) + " |" for r in b[2]]))
            elif kind == "img":
                out.append(f"![{b[2]}]({b[1]})\n\n*{b[2]}*")
            elif kind == "box":
                out.append("\n".join([f"> **{b[1]}**", ">", *(f"> - {t}" for t in b[2])]))
            out.append("")
        return "\n".join(out)

    def html(self, title: str, images: dict[str, bytes]) -> str:
        """One page: the pictures inline as data: URIs (``images``: relative path -> PNG bytes)."""
        body = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                body.append(f"<h{b[1]}>{_inline(b[2])}</h{b[1]}>")
            elif kind == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif kind in ("ul", "ol"):
                tag = "ol" if kind == "ol" else "ul"
                body.append(f"<{tag}>" + "".join(f"<li>{_inline(t)}</li>" for t in b[1]) + f"</{tag}>")
            elif kind == "table":
                head = "".join(f"<th>{_inline(c)}</th>" for c in b[1])
                rows = "".join("<tr>" + "".join(f"<td>{_inline(str(c))}</td>" for c in r) + "</tr>" for r in b[2])
                body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>")
            elif kind == "img":
                data = base64.b64encode(images[b[1]]).decode("ascii")
                body.append(f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{_inline(b[2])}</figcaption></figure>")
            elif kind == "box":
                body.append(f'<div class="box"><p><b>{_inline(b[1])}</b></p><ul>'
                            + "".join(f"<li>{_inline(t)}</li>" for t in b[2]) + "</ul></div>")
        return _HTML.replace("@@TITLE@@", html.escape(title)).replace("@@BODY@@", "\n".join(body))


def _inline(text: str) -> str:
    t = html.escape(text, quote=False)
    t = re.sub(r"`([^`]+)`", r"<code>\1</code>", t)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", t)


_HTML = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>@@TITLE@@</title>
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; img-src data:">
<style>
  body { font: 11pt/1.45 sans-serif; max-width: 190mm; margin: 12mm auto; color: #111; }
  h1 { font-size: 18pt; } h2 { font-size: 14pt; border-bottom: 1px solid #999; margin-top: 1.6em; }
  h3 { font-size: 12pt; }
  table { border-collapse: collapse; margin: 0.6em 0; font-size: 9.5pt; }
  th, td { border: 1px solid #bbb; padding: 2px 6px; vertical-align: top; text-align: left; }
  th { background: #eee; }
  code { font-size: 9.5pt; background: #f3f3f3; padding: 0 2px; }
  figure { margin: 0.8em 0; text-align: center; page-break-inside: avoid; }
  figure img { max-width: 100%; max-height: 150mm; }
  figcaption { font-size: 9pt; color: #444; }
  .box { border: 2px solid #b00; background: #fff4f4; padding: 0 8px; margin: 0.8em 0; }
  @media print { body { margin: 0; max-width: none; } h2 { page-break-before: always; }
                 h2:first-of-type { page-break-before: avoid; } tr { page-break-inside: avoid; } }
</style>
</head>
<body>
@@BODY@@
</body>
</html>
"""

# -- the manual -------------------------------------------------------------------------------------

#: What to do at each assembly step, for the parts the thesis's rig has; a part without an entry is
#: placed as its recipe's description says.
STEP_TEXT = {
    "base_plate": "Lay the base plate on the bench, its top face up: that face is the sample plane z = 0.",
    "sample_holder": "Slide the sample holder into the plate's bore from below until its collar stops against "
                     "the plate; with a sample of `sample_holder.sample_thickness` its top is on z = 0.",
    "beam": "With the dome off the plate, pass the beam through the dome's two wall slots so that it rests on "
            "the slots' floors and overhangs the wall equally at both ends (drawn here in place, without the "
            "dome).",
    "paraboloid": "Reach in through the dome's open base and push the paraboloid's U clamp onto the middle of "
                  "the beam, mirror up; the stem centres it over the sample point.",
    "dome": "Lower the dome, with the beam and the paraboloid in it, onto the base plate: flange holes over the "
            "plate's holes.",
    "tower_column": "Stand the tower's column on the bench beside the base plate (the bench is level with the "
                    "sample holder's stop collar).",
    "tower_shelf": "Lay the shelf on the column's top flange, its end with the bundle hole over the optical axis.",
    "projector_shims_1": "Put a stack of the printed `tower_shim`s on each of the projector's four slots in the "
                         "shelf (the nominal stack; add or remove shims to set the projector's height).",
    "projector_body": "Stand the projector on its shim stacks, its lens towards the beam splitter (looking -x), and "
                      "screw it down through the shelf's slots, finger tight until the calibration. A projector that "
                      "throws its image off its lens axis (`projector.lens_offset`) stands level all the same, never "
                      "tilted to centre its image: the rig's axis is its lens axis, and rigcad draws its images about "
                      "that axis's pixel (set a lens shift, if it has one, to the offset the profile states).",
    "camera_shims": "Put the camera's shim stack against the bracket (more or fewer shims move the camera across "
                    "the axis in y).",
    "camera_body": "Screw the camera to the bracket above the beam splitter through its slot, looking down the "
                   "optical axis. Tie its cable to the column with the cable ties its bill row states, a slack loop "
                   "left between the camera and the upper tie.",
    "beam_splitter": "Slide the plate beam splitter into the holder's 45 deg grooves through the +y wall, coated "
                     "face towards the projector (+x) and down. Handle it by its edges. Then fix it on its datum flank (the grooves' "
                     "lower flanks, under its coated face) with the dots of silicone RTV its bill row states, the holder "
                     "upright while they cure.",
    "focusing_lens": "Drop the focusing lens into the lens mount's square pocket.",
}


def _mil(mm: float) -> str:
    return f"{mm / MIL:.3g} mil"


def build_manual(rig, printer, fab_report: dict, progress=None) -> tuple[Doc, dict[str, bytes], dict]:
    """The document, its files (relative path -> bytes: pictures and the calibration image) and the
    figures (for manual.json)."""
    from types import SimpleNamespace

    from rigcad import plots
    from rigcad.manual import assembly as A
    from rigcad.manual.view import traced_rays

    step = progress or (lambda label: None)
    meshes = A.picture_meshes(rig)
    from rigcad.manual import plan

    bill = B.bill(rig, fab_report, printer)
    bill["purchased"] = camera_lens.with_camera_lens(rig, bill["purchased"])  # the lens to buy when none is named
    steps, solids = plan.steps(rig, meshes)  # once: the bill's hardware and section 5's order both read them
    bill["hardware"] = plan.bill_hardware(rig, steps, bill) + _spring_washers(rig, printer)  # one list
    bill["calibration_kit"] = [{"item": k.item, "quantity": k.quantity, "spec": k.spec, "steps": list(k.steps)}
                               for k in C.kit_items(rig)]  # what section 6 uses: one list
    c = SimpleNamespace(rig=rig, printer=printer, fab_report=fab_report, p=rig.profile, files={}, meshes=meshes,
                        bill=bill, cut_away=A.encloses(meshes), step=step, steps=steps, solids=solids)
    c.files.update(drawings.drawings(rig))  # the machined parts' shop drawings (drawings/<part>.svg, .png)
    c.files["images/rig.png"] = plots.rig_picture(meshes, traced_rays(rig), f"{rig.name}: the assembled rig",
                                                  cut_away=c.cut_away)
    step("rig picture")
    d = Doc()
    _introduction(d, c)
    for section in (_section_bill, _bill_consumables, _section_schedule, _section_print, _section_sand, _section_finish, _section_coat,
                    _section_assemble, _section_mechanics, _section_acceptance, _section_calibrate):
        section(d, c)
    figures = {"rigcad_version": __version__, "profile": rig.name, "printer": printer.name,
               # the hardware as the steps fit it; bom.fasteners' candidate joints stay internal
               "bill": {k: v for k, v in c.bill.items() if k != "fasteners"}, "calibration": c.calibration, "finishing": c.finishing,
               "coating_gauged_layer": c.gauged, "coating_total_mm": c.total, "mechanics": c.mechanics,
               "assembly_order": getattr(c, "assembly_order", None), "schedule": c.schedule}
    return d, c.files, figures


def assumed_sizes(profile) -> list[dict]:
    """What must be measured before printing: the instrument sizes that neither the chosen library
    entry sources nor the profile gives (rigcad.profile.instruments.measurements, the one home of
    that list), each with how to measure it (the view and the two features it runs between)."""
    from rigcad.profile.instruments import measurements

    out = []
    for m in measurements(profile):
        section, key = m.key.split(".", 1) if "." in m.key else ("", m.key)
        value = f"{m.assumed:g} {m.unit}" if isinstance(m.assumed, (int, float)) else f"{m.assumed} {m.unit}".strip()
        out.append({"key": m.key, "value": value,
                    "doc": f"{m.what} ({m.view} view: from the {m.between[0]} to the {m.between[1]})",
                    "set_in": _write_in(profile, section, key)})
    return out


def _write_in(profile, section: str, key: str) -> str:
    """Where an assumed size is written once measured: the file:line that sets it, else the instrument file
    the profile chose for its section (a projector's or camera's own file, not the profile's section line),
    else "default"."""
    if not section:
        return "default"
    origin = profile.origin(section, key)
    if origin != "default":
        return origin
    files = sorted(i.file for i in profile.instruments.values() if i.section == section and i.kind == section)
    return files[0] if files else "default"


def measure_first(d: Doc, c) -> None:
    """What must be measured or chosen before anything is printed: the assumed sizes."""
    rows = assumed_sizes(c.p)
    d.h(2, "0. Before printing: measure or choose")
    _optics_figures(d, c.p)
    _weigh_first(d, c.p)
    if not rows:
        d.p("Every instrument size in this profile is given, none assumed: nothing to measure first.")
        return
    d.p(f"The parts are shaped around these **{len(rows)} sizes, which the profile only assumes**. Measure each on "
        "your own instrument (a caliper; a lens's pupil from the maker's data sheet), write it into the profile "
        "under its key and build again before you print: a wrong size puts the centre of projection in the wrong "
        "place.")
    d.table(["key", "assumed", "what it is", "set in (or write it in)"],
            [[f"`{r['key']}`", r["value"], r["doc"], f"`{r['set_in']}`"] for r in rows])
    d.p("Each size drawn on the instrument's outline (at the assumed sizes), between the two features to measure "
        "from and to:")
    for path, caption in measurement_figures(c.p, c.files):
        d.img(path, caption)


def _weigh_first(d: Doc, profile) -> None:
    """The instruments' masses the profile only assumes (``projector.mass``, ``camera.mass``: their schema
    defaults): the shelf's and the column's bending, the seat's hold and the rig's stance are judged with them."""
    rows = [(f"{section}.mass", getattr(profile, section).mass) for section in ("projector", "camera")
            if profile.set_by(section, "mass") == "default"]
    if rows:
        d.p("Weigh " + " and ".join(f"the {k.split('.')[0]} with its lens (`{k}`, assumed {m:g} kg)" for k, m in rows)
            + " on a kitchen scale and write the figure into the profile with its unit: the shelf's and the "
            "column's bending, the splitter seat's hold and the rig's stance are judged with it (section 5's "
            "'Torques, and what bends'; a heavier projector may need `buy.shelf: aluminium_plate`).")


def _optics_figures(d: Doc, profile) -> None:
    """The figures that decide the optics (rigcad.profile.instruments.optics_figures), each with where it came
    from: a figure the profile assumes or does not know is one to read off a datasheet or measure first."""
    from rigcad.profile.instruments import optics_figures

    said = {"datasheet": "from the instrument file's datasheet", "instrument file": "from the instrument file (no "
            "source given: check it)", "profile": "set in the profile", "assumed": "**assumed**: read or measure it",
            "unknown": "**not known**: read or measure it"}
    figures = optics_figures(profile)
    open_ = sum(f.state in ("assumed", "unknown") for f in figures)
    d.p(f"The figures that decide the optics: the field of view, where the paraboloid's disc sits in the image, "
        f"the camera's lens in millimetres and how near it focuses. **{open_} of {len(figures)} are assumed or not "
        "known**; write each one you read or measure into the profile under its key and build again.")
    d.table(["key", "value", "what it is", "where it came from", "how to read or check it"],
            [[f"`{f.key}`", f.value, f.what, f"{said[f.state]} (`{f.origin}`)", f.how] for f in figures])


def measurement_figures(profile, files: dict) -> list[tuple[str, str]]:
    """One figure per size to measure (rigcad.profile.instruments.sketch, drawn by
    rigcad.plots.measurement_figure) into ``files`` (path -> PNG bytes): the (path, caption) of each."""
    from rigcad import plots
    from rigcad.profile.instruments import measurements, sketch

    out = []
    for m in measurements(profile):
        path = f"images/measure/{m.key.replace('.', '_')}.png"
        what = f"from: {m.between[0]}; to: {m.between[1]}"
        s = sketch(profile, m)
        extra, dims, note = hole_pattern_marks(profile, s)
        files[path] = plots.measurement_figure(s, what, extra, dims)
        out.append((path, f"`{m.key}` ({m.view} view): {m.what}, {what}{note}"))
    return out


def hole_pattern_marks(profile, s) -> tuple[tuple, tuple, str]:
    """For the projector's mounting-hole figure (``projector.mount_holes``): the shelf's slot around each hole
    (rigcad.parts.tower's: the thread's clearance hole plus ``tower.travel_along`` / ``travel_across`` each
    way), the holes' spacings along and across as dimensions ((x0, y0), (x1, y1), label), and the caption's
    words for them; nothing for another figure."""
    if s.key != "projector.mount_holes" or not s.circles or getattr(profile, "tower", None) is None:
        return (), (), ""
    from rigcad.parts.tower import clearance_hole

    d, tw = clearance_hole(profile.projector.mount_thread), profile.tower
    hx, hy = d / 2 + tw.travel_along, d / 2 + tw.travel_across
    centres = [c for _, c, _ in s.circles]
    extra = tuple((f"shelf slot {k + 1}", ((x - hx, y - hy), (x + hx, y - hy), (x + hx, y + hy), (x - hx, y + hy),
                                           (x - hx, y - hy))) for k, (x, y) in enumerate(centres))
    xs, ys = sorted({round(x, 6) for x, _ in centres}), sorted({round(y, 6) for _, y in centres})
    dims = []
    if len(xs) > 1:
        y = ys[0] + hy + 10.0  # inside the body, just off the first row's slots
        dims.append(((xs[0], y), (xs[-1], y), f"{xs[-1] - xs[0]:g} mm"))
    if len(ys) > 1:
        x = xs[0] + hx + 10.0
        dims.append(((x, ys[0]), (x, ys[-1]), f"{ys[-1] - ys[0]:g} mm"))
    return extra, tuple(dims), (f"; the holes' spacings dimensioned (black), the shelf's slots dashed blue around them "
                                f"({2 * hx:g} x {2 * hy:g} mm: the {profile.projector.mount_thread} clearance hole "
                                f"{d:g} mm plus `tower.travel_along` ±{tw.travel_along:g} mm and `tower.travel_across` "
                                f"±{tw.travel_across:g} mm), and a scale bar")


def _introduction(d: Doc, c) -> None:
    """The title, what the manual is made from, and the assembled rig."""
    rig, printer, p = c.rig, c.printer, c.p
    d.h(1, f"{rig.name}: assembly and calibration manual ({printer.name})")
    d.p(f"The rig of profile `{rig.name}` ({' <- '.join(p.sources)}), printed on **{printer.description}** "
        f"(`{printer.source}`). Every figure below is computed by rigcad {__version__} from the profile, the "
        f"part recipes and the printer. " + parts_text(rig.name, printer.name))
    problems = fab_problems(c.fab_report)
    if problems:
        d.box(f"rigcad fab found {len(problems)} problem(s) on the {printer.name}: this rig cannot be built as "
              f"printed until each is solved (fab/{printer.name}/fab.json lists them; the sections below follow it)",
              problems)
    d.img("images/rig.png", "The assembled rig (front of the dome cut away) with rays traced from the centre of "
                            "projection, coloured by their incidence angle at the sample")
    measure_first(d, c)


def fab_problems(fab_report: dict) -> list[str]:
    """fab's problems (fab.json's ``problems``) as the manual's top box lists them: one item per problem,
    the tolerance stack's refusal one item per placement it refuses."""
    out = []
    for problem in fab_report.get("problems") or ():
        head, sep, rest = problem.partition(" placement(s) the printed rig cannot hold or adjust: ")
        if problem.startswith("tolerance stack: ") and sep:
            out += [f"{head.removeprefix('tolerance stack: ')} the printed rig can neither hold nor adjust the {x}"
                    for x in rest.split(" | ")]
        else:
            out.append(problem)
    return out


#: The folders of ``exports/<profile>/`` that ``rigcad stl`` writes and the manual refers to, not writes.
PARTS_FOLDERS = ("step", "stl")


def parts_text(profile: str, printer: str) -> str:
    """Where the files the manual refers to are, from its own folder (``exports/<profile>/manual/<printer>/``)
    and which command writes each: the print files (``rigcad fab``, run by ``rigcad manual``), the parts
    (``rigcad stl``: :data:`PARTS_FOLDERS`), the 3D view (``rigcad view``)."""
    return (f"The other files are in `exports/{profile}/`, two folders up from this one (`../../`): the print files "
            f"in `../../fab/{printer}/` (written with this manual: `rigcad manual` runs `rigcad fab {profile} --printer "
            f"{printer}`); the parts as `../../step/<part>.step` and `../../stl/<part>.stl`, written by `rigcad stl "
            f"{profile}`, not by `rigcad manual`, which says when they are missing or not made from this profile; the "
            f"3D view in `../../view/rig.html`, written by `rigcad view {profile}`.")


def parts_note(profile, exports) -> str | None:
    """None when ``<exports>/<profile>/`` holds the parts of ``profile`` (a loaded Profile) as this code makes
    them, intact (rigcad.api.export_up_to_date: the manifest's inputs key and every file it lists); else
    the note ``rigcad manual`` prints: which folders, and the command that writes them."""
    from rigcad import api

    folder = Path(exports) / profile.name
    if api.export_up_to_date(profile, folder):
        return None
    state = ("missing" if not any((folder / f).is_dir() for f in PARTS_FOLDERS) else
             "not made from this profile by this rigcad, or incomplete")
    return (f"{profile.name}: the parts the manual refers to ({', '.join(f'{folder / f}/' for f in PARTS_FOLDERS)}) "
            f"are {state}: run `rigcad stl {profile.name} --exports {exports}` before printing")


def _section_bill(d: Doc, c) -> None:
    """The manual's section: 1 bill of materials."""
    rig, printer, p, bill = c.rig, c.printer, c.p, c.bill
    d.h(2, "1. Bill of materials")
    d.h(3, "Printed and cut parts")
    rows = []
    for r in bill["printed"]:
        if r.get("time_s") is None:
            kind = "bought" if r["process"] == "bought" else "cut" if r["quantity"] else "-"
            note = r["note"] + (f" (`drawings/{r['part']}.svg`)" if f"drawings/{r['part']}.svg" in c.files else "")
            rows.append([f"`{r['part']}`", r["use"], r["quantity"] or "-", kind, r["process"], "-", "-", note])
        else:
            rows.append([f"`{r['part']}`", r["use"], r["quantity"], r["pieces"], r["process"], hours_minutes(r["time_s"]),
                         f"{r['material_g']:.0f} g", f"{r['note']} ({r['source']})"])
    d.table(["part", "use", "qty", "pieces", "process", "print time (with qty)", "material", "orientation"], rows)
    timed = [r for r in bill["printed"] if r.get("time_s") is not None]
    total_t = sum(r["time_s"] for r in timed)
    total_g = sum(r["material_g"] for r in timed)
    pieces = sum(r["pieces"] * r["quantity"] for r in timed)
    d.p(f"In all: **{pieces} printed pieces, {hours_minutes(total_t)} of printing and {total_g:.0f} g of "
        f"{printer.material}**" + ("" if all(r["source"] == "slicer" for r in timed) else
                                   " (rigcad's estimate where no G-code was sliced"
                                   + (": `rigcad manual ... --gcode` uses PrusaSlicer's own figures)"
                                      if printer.slicer == "prusa-slicer" else ")")) + ".")
    d.h(3, "Hardware")
    d.table(["item", "qty", "where", "note"], [[r["item"], r["quantity"], r["where"], r["note"]] for r in bill["hardware"]])
    if not bill["pins"]:
        d.p(f"No part is split on {printer.name}: no dowel pins.")
    d.h(3, "Optics and instruments")
    if bill["purchased"]:
        d.table(["item", "qty", "as the profile gives it", "set in"],
                [[r["item"], r["quantity"], r["spec"], f"`{r['source']}`"] for r in bill["purchased"]])
    kit = bill.get("calibration_kit") or []
    if kit:
        d.h(3, "Calibration and test kit")
        d.p("What section 6 (calibration) and the optical acceptance test use besides the printed parts above and "
            "the tools below: what to buy or make, and the steps that use it.")
        d.table(["item", "qty", "what to buy", "used in"],
                [[r["item"], r["quantity"], r["spec"], "; ".join(r["steps"])] for r in kit])
    d.h(3, "Paint and clearcoat")
    d.p(f"Volumes of each layer of `coating.layers` over the mirrors ({', '.join(m['mirror'] for m in bill['mirrors'])}: "
        + ", ".join(f"{m['design_area_mm2'] / 100:.1f} cm²" for m in bill["mirrors"])
        + f" of design surface), as dry film; 'to have at hand' is `coating.margin` = {bill['coating_margin']:g} "
          "times that.")
    d.table(["layer (bottom to top)", "thickness", "area covered", "film", "to have at hand"],
            [[c["layer"], f"{_mil(c['thickness_mm'])} ({c['thickness_mm']:.4f} mm)", f"{c['area_mm2'] / 100:.1f} cm²",
              f"{c['film_cm3']:.2f} ml", f"**{c['to_buy_cm3']:.1f} ml**"] for c in bill["coating"]])


def _bill_consumables(d: Doc, c) -> None:
    """The consumables and tools lists, the feeler leaves from the template gaps (finishing.template_gaps)."""
    from rigcad.manual import finishing as F

    d.h(3, "Consumables")
    d.table(["item", "qty"], [list(_abrasive() if r[0].startswith("Wet-or-dry") else r)
                              for r in (*B.CONSUMABLES, *F.paint_companions(c.bill["coating"]),
                                        *B.glue_rows(c.fab_report))])
    d.h(3, "Tools")
    keys, rule = B.set_screw_keys(c.bill["hardware"]), B.template_straightedge(c.rig)
    d.table(["item", "qty"], [list(_blocks(c.rig) if r[0].startswith("Sanding blocks") else r)
                              for r in (*B.TOOLS, B.feeler_gauge(F.template_gaps(c.p)),
                                        B.dowel_drills(c.fab_report, c.rig), *B.register_tools(c.rig),
                                        *([keys] if keys else []), *([rule] if rule else []))])


def _section_schedule(d: Doc, c) -> None:
    """The one schedule from print to calibrated rig (rigcad.manual.schedule): each stage with the rig
    state it needs and leaves, checked in order before it is written."""
    from rigcad.manual import schedule as S

    stages = S.schedule(c.rig, c.fab_report, c.steps)
    S.check(stages)
    d.h(2, "The schedule: from print to calibrated rig")
    d.p("Do the work in this order, one stage after the other; the sections after it say how (named at the end "
        "of each stage). Each stage needs the rig as the stages before it leave it: which parts are whole, in or "
        "off, what is cured or coated. rigcad checks that every stage finds the state it needs before it writes "
        "this list.")
    d.ol([f"{st.what} ({st.where}; needs: {', '.join(sorted(st.needs)) or 'nothing'}; leaves: "
          f"{', '.join(sorted(st.makes))}" + (f"; undoes: {', '.join(sorted(st.ends))}" if st.ends else "") + ")"
          for st in stages])
    c.schedule = [st.record() for st in stages]


def _abrasive() -> tuple[str, str]:
    """The consumables' abrasive line: the film the printed sanding blocks carry (rigcad.manual.finishing)."""
    from rigcad.manual import finishing as F

    return (f"Abrasive for the sanding blocks: {F.ABRASIVE_SPEC}, grades " + ", ".join(g for g, _ in F.ABRASIVE)
            + f" (FEPA P, ISO 6344), {F.ABRASIVE_MM:g} mm thick with its grit", "2 sheets of each grade")


def _blocks(rig) -> tuple[str, str]:
    """The tools' sanding blocks line: the printed blocks (rigcad.manual.finishing.sanding_block_set)."""
    from rigcad.manual import finishing as F

    return ("Sanding blocks: printed from `blocks/*.stl`, faced with the abrasive film (section 3)",
            str(len(F.sanding_block_set(rig))))


def _section_print(d: Doc, c) -> None:
    """The manual's section: 2 print."""
    printer, fab_report, p, bill, files = c.printer, c.fab_report, c.p, c.bill, c.files
    d.h(2, "2. Print")
    items = []
    for name, e in fab_report["parts"].items():
        if "pieces" in e:
            names = ", ".join(f"`{pc['name']}`" for pc in e["pieces"])
            support = any(pc["needs_support"] for pc in e["pieces"])
            items.append(f"`{name}` x{e['quantity']}: {len(e['pieces'])} piece(s) {names}, printed "
                         f"{', '.join(sorted({pc['orientation'] for pc in e['pieces']}))}"
                         + ("; needs support" if support else "")
                         + (f"; {len(e['pins'])} pin holes" if e.get("pins") else ""))
        elif e.get("process") == "bought":
            items.append(f"`{name}`: bought, not printed: {e['stock']}")
        elif "error" not in e:
            items.append(_cut_line(name, e))
        else:
            items.append(f"`{name}`: **not printable on {printer.name}**: {e['error']}")
    d.p(f"Print files: `fab/{printer.name}/stl/` (each piece in its print orientation)"
        + (f", G-code in `fab/{printer.name}/gcode/`" if fab_report["gcode"].get("requested") else "")
        + f"; `fab/{printer.name}/fab.md` has the staircase maps.")
    d.ul(items)
    if bill["pins"]:
        sizes = bill["pins"].get("by_diameter_mm") or {f"{bill['pins']['diameter_mm']:g}": bill["pins"]["quantity"]}
        rods = " and ".join(f"{k} x {dia} mm" for dia, k in sizes.items())
        d.p(f"Split pieces: cut {bill['pins']['quantity']} pins of {bill['pins']['length_mm']:g} mm from "
            f"{rods} rod (or filament), drill each part's pin holes to the size "
            "the tools list gives, push the pins into one piece's holes, join the next piece on them and glue "
            "the cut faces with the glue the consumables list names for that part."
            + (" Lap the tower column's glue faces flat before you glue them: wet P240 paper on the float glass, "
               "figure-of-eight strokes, until the steel straightedge laid across each face in four directions admits "
               f"no {_lapped():g} mm feeler leaf." if "tower_column" in (bill["pins"].get("use") or "") else ""))
        _glue_mirror_seams(d, c)


def _lapped() -> float:
    """How flat a lapped glue face is (mm, rigcad.parts.tower.LAPPED_FLATNESS): the feeler leaf that checks it."""
    from rigcad.parts.tower import LAPPED_FLATNESS

    return LAPPED_FLATNESS


def _cut_line(name: str, e: dict) -> str:
    """The print section's line for a template cut from plate, with its printed-stage outline when the
    fab run wrote one (the gauge a split mirror's seams are glued on: rigcad.fab.seams)."""
    printed, sanded = ([f for f in ((e.get("stages") or {}).get(k) or {}).get("files") or () if f.endswith(".dxf")]
                       for k in ("printed", "sanded"))
    return (f"`{name}`: cut from a {e['plate_thickness_mm']:g} mm plate (`outlines/{name}.dxf`, `.svg`)"
            + (f"; cut its printed stage too (`{printed[0]}`: the surface as printed, the gauge a split mirror's "
               "seams are glued on)" if printed else "")
            + (f"; cut its sanded stage too (`{sanded[0]}`: the surface the coats go on, the gauge section 3 sands "
               "to)" if sanded else ""))


def _spring_washers(rig, printer) -> list[dict]:
    """The conical spring washers (DIN 6796) the torque table puts under the joints that locate a
    datum (rigcad.fab.loads: creep would relax them), one per screw: bill rows like the hardware's."""
    from rigcad.fab import loads as L

    if printer.process_errors is None or getattr(rig.layout, "tower", None) is None:
        return []
    by: dict[str, list] = {}
    for b in L.loads(rig.profile, rig.layout, printer).bolts:
        if b.spring_washer:
            by.setdefault(b.thread, []).append(b)
    return [{"item": f"{thread} conical spring washer (DIN 6796)", "quantity": sum(b.count for b in bolts),
             "where": "under the heads of " + ", ".join(b.joint for b in bolts),
             "note": "section 5's torque table: the joints that locate a datum", "steps": []}
            for thread, bolts in by.items()]


def _glue_mirror_seams(d: Doc, c) -> None:
    """How a split mirror's seams are glued: on the printed-stage template, not on the pins
    (rigcad.fab.seams: the pins alone would step the mirror by more than its sanding stock)."""
    from rigcad.fab.seams import FEELER_LEAF

    for name, e in c.fab_report["parts"].items():
        s = e.get("seams") or {}
        if "step_on_gauge_mm" not in s:
            continue
        template = f"{name}_template_printed"
        d.p(f"**The {name}'s seams are glued on a gauge, not on their pins.** Its pins alone would let a seam step "
            f"{s['step_on_pins_mm']:.2f} mm ({s['step_on_pins_how']}) against {s['stock_mm']:.3f} mm of sanding "
            f"stock: sanding to the template would leave the lower side as a groove. So its pin holes are drawn "
            f"wide and the glue fills them. Cut `outlines/{template}.dxf` from the same plate as the templates (its "
            f"edge is the surface as printed). First melt the base plate's heat-set inserts (as its step in section 5 "
            f"says, before it goes on the bench): the dome's flange screws go into them. Then glue one seam at a time, "
            f"before the dome's own inserts, the pieces standing on the base plate "
            f"(packing tape over the plate under the seam, so no glue reaches it) with their flange screws in, "
            f"finger-tight: mix the {s['glue']} ({s['glue_open_min']:g} min to set the seam), butter both cut faces "
            f"and the pins, push the pieces together, stand the template in the seam's plane with its datum edge on "
            f"the plate and its axis line on the centre mark, and push both pieces against its edge until a "
            f"{FEELER_LEAF:g} mm feeler leaf passes under it on neither "
            f"side, along the whole seam. Tape the seam on the outside and leave it to cure before the next. That "
            f"holds the step to {s['step_on_gauge_mm']:.3f} mm ({s['step_on_gauge_how']}), within the stock."
            + "".join(f" The seam at {q['face']} has no pins ({q['why']}): glue it the same way, without pins; "
                      f"what holds it is {q['held_by']}." for q in e.get("pinless_seams", [])))


def _section_sand(d: Doc, c) -> None:
    """The manual's section: 3 sand."""
    from rigcad import plots
    from rigcad.parts.templates import gauged_depth

    rig, fab_report, p, files = c.rig, c.fab_report, c.p, c.files
    gd = gauged_depth(p)
    total = float(sum(t for _, t in p.coating.layers))
    gauged = p.templates.gauged_layer
    d.h(2, "3. Sand the mirrors to the template")
    from rigcad.manual import finishing as F

    sand = []
    for name, e in fab_report["parts"].items():
        if "polishing" in e:
            stock = printed_stock(e)
            need = e["polishing"]["stock_to_add_mm"]
            sand.append(f"`{name}`: sand the print's staircase flat. Its steps stand up to "
                        f"{e['polishing']['sanding_depth_mm']:.3f} mm from crest to valley; the whole mirror was "
                        f"printed {stock:.3f} mm forward of the surface the coats go on (its sanding stock), which "
                        f"keeps even the deepest valley {max(0.0, stock - need):.3f} mm in front of it. So the "
                        "sanding takes the crests down, more at a crest than the stock; "
                        + F.sanding_stop(total - gd, (name,)))
    d.ul(sand)
    d.p(f"The templates (`dome_template`, `paraboloid_template`, cut from plate) carry the surface of the "
        f"**{gauged}** layer. Sanded to size, the bare print lies {total - gd:.3f} mm ({_mil(total - gd)}: the layers "
        f"up to and including the {gauged}) behind the template's edge all along it: check with a feeler gauge "
        "or against the light, in several meridional planes.")
    c.templates = F.template_datums(rig)
    for row in c.templates:  # drawn flat with its datum: the picture and the text read the same row
        name = row["template"]
        files[f"images/{name}.png"] = plots.template_drawing(row)
        d.img(f"images/{name}.png", f"`{name}`: {rig.recipes[name].description}; its datum in red")

    c.gauged, c.total, c.gd = gauged, total, gd


def _section_coat(d: Doc, c) -> None:
    """The manual's section: 4 coat."""
    rig, p, bill, step = c.rig, c.p, c.bill, c.step
    gauged, total, gd = c.gauged, c.total, c.gd
    d.h(2, "4. Coat, layer by layer, checking with the template")
    layers = p.coating.layers
    rows, cum = [], 0.0
    by_layer = {c["layer"]: c for c in bill["coating"]}
    for k, (name, t) in enumerate(layers):
        cum += t
        gap = (total - gd) - cum  # template edge to the coat's top (mm): positive = a gap under the template
        if abs(gap) < 1e-9:
            check = "**flush**: polish until the template fits along its whole edge"
        elif gap > 0:
            check = f"a gap of {gap:.3f} mm ({_mil(gap)}) under the template"
        else:
            check = f"past the gauged layer: the template stands {-gap:.3f} mm ({_mil(-gap)}) proud; do not force it"
        rows.append([k + 1, name, f"{_mil(t)}", f"{_mil(cum)}", check, f"{by_layer[name]['to_buy_cm3']:.1f} ml"])
    d.table(["#", "layer", "thickness", "total so far", "template check after this layer", "paint at hand"], rows)
    d.p(f"The finished surface is the design surface: the prints sit {total:.4f} mm ({_mil(total)}) behind it "
        "(`coating.layers`), the dome outwards, the paraboloid inwards.")
    step("bill and steps")


#: How a step's direction reads (rig frame: +z up, the projector on the +x side).
MOVES = {"-z (down)": "lower it from above", "+z (up)": "push it up from below",
         "-x": "slide it in level along -x, from the +x side", "+x": "slide it in level along +x, from the -x side",
         "-y": "slide it in level along -y, from the +y side", "+y": "slide it in level along +y, from the -y side"}
#: Fastenings by what takes the thread: what the step says after the bolt.
TORQUE = "tighten crosswise with a torque screwdriver to the joint's torque (section 5's 'Torques, and what bends')"
THREAD_IN = {"nut": f"a washer under the head and under the nut; hold the nut with the spanner, {TORQUE}",
             "insert": f"screwed into the heat-set insert set in step {{k}}; {TORQUE}",
             "instrument": "into the instrument's own threaded holes, finger tight until the calibration",
             "bench": "into the bench (on a breadboard: into its tapped holes, on the grid)",
             "tapped": "into the thread tapped in the part",
             "trap": f"a washer under the head; its nut waits in the hexagonal trap (put in at step {{k}}), {TORQUE}"}


def assembly_order(rig, steps, solids):
    """The order rigcad's assembly check finds (rigcad.manual.assembly_check.find_order over
    rigcad.manual.plan's steps). A rig with no order gets no manual: the gate's refusal
    (rigcad.manual.gate: AssemblyError, its one line naming the parts and the profile keys)."""
    from rigcad.errors import AssemblyError
    from rigcad.manual import assembly_check, gate

    try:
        return gate.order(rig, assembly_check.Assembly(solids, steps))  # the gate's order handed on when it judged the rig
    except AssemblyError as err:
        v = gate.refused(rig, err, search=False)
        raise AssemblyError(v.line(), step=v.step, members=v.members, obstacles=v.obstacles) from err


def register_text(reg) -> str:
    """What a step says of the register a part sits on (rigcad.parts.locating.DowelRegister)."""
    lateral, turn = reg.repeatability
    upper = reg.upper.replace("_", " ")
    if getattr(reg, "drilled", False) and getattr(reg, "procedure", ""):
        return reg.procedure + " "  # drilled in place once the part is indicated in: the part's own shop step
    return (f"Before the {upper}: {reg.shop_text()} The {upper} drops onto the pins: lifted off and set back "
            f"(section 6 does, for "
            f"the calibration screens and the checkerboard) it returns to within {1e3 * lateral:.0f} µm and "
            f"{1e3 * math.degrees(turn):.1f} mdeg, whatever its screws do; tighten its screws only once it sits on the "
            "pins. ")


def preparations(rig, order, meshes_by_name: dict) -> dict[str, list[dict]]:
    """What each step does before its parts go in (step name -> rows, in order): the heat-set inserts
    melted and the nuts pushed into their traps in the part that takes a later (or this) step's screws
    (:func:`rigcad.manual.plan.thread_host`), set in the step that places that part; the locating pins
    and balls the tower's rows fit (``rigcad.parts.tower.hardware``'s unthreaded rows: a row naming
    several steps is fitted in equal shares, one in each), pressed in before the part they locate; a
    part's register pins (DowelRegister) before that part; a step that places the bought item itself has it
    as "placed" (its own text). Each row: kind ("insert", "nut", "pressed", "placed", "register"), item,
    quantity, the part it goes into (``into``, None when the row does not say) and
    the step whose part or screws it serves (``for``)."""
    from rigcad.manual import plan

    step_of = {m: p.step.name for p in order for m in p.step.members}
    out: dict[str, list[dict]] = {p.step.name: [] for p in order}
    for p in order:
        st = p.step
        for m in st.members:
            if m in rig.recipes:
                for j in rig.recipes[m].joints:
                    if isinstance(j, DowelRegister):
                        out[st.name].append({"kind": "register", "item": j.item, "quantity": len(j.points),
                                             "into": j.lower, "for": st.name})
        for f in st.fasteners:
            kind = "insert" if f.thread_in == "insert" else "nut" if f.thread_in == "nut" and f.nut_tool is None else None
            if kind is None:
                continue
            host = plan.thread_host(f, meshes_by_name)
            if host is None or host not in step_of:
                continue
            thread = plan.thread_of(f)
            item = plan.insert_item(thread) if kind == "insert" else f"{thread} hex nut (ISO 4032)"
            rows = out[step_of[host]]
            row = next((r for r in rows if (r["kind"], r["item"], r["into"], r["for"]) == (kind, item, host, st.name)),
                       None)
            if row is None:
                rows.append({"kind": kind, "item": item, "quantity": 1, "into": host, "for": st.name})
            else:
                row["quantity"] += 1
    for h in B.tower_hardware(rig):
        if h.get("thread") or "heat-set insert" in h["item"] or "mounting holes" in h["joins"] or tower_joints.placed(h):
            continue
        named = plan.step_names([p.step for p in order], h.get("steps", ()))  # a unit's parts: its step
        bought = {p.step.name for p in order if p.step.bought}
        for n in named:  # a bought step places the item itself ("placed"); else it is pressed in before the part
            out[n].append({"kind": "placed" if n in bought else "pressed", "item": B.tower_item(h),
                           "quantity": h["quantity"] // len(named), "into": None, "for": n, "joins": h["joins"]})
    from rigcad.parts.paraboloid import hardware as stop_hardware

    # the paraboloid's stops' and the beam seats' bought items (set screws, roll bars, the stop pin, the foil), in
    # the first step the bill assigns each to (the inserts: that step melts them); a later step says where it was listed
    for h in stop_hardware(rig.profile, rig.layout) if "paraboloid" in rig.recipes else ():
        named = plan.step_names([p.step for p in order], h.get("steps", ()))
        named = sorted(named, key=list(out).index)
        if named and "heat-set insert" not in h["item"]:
            out[named[0]].append({"kind": "pressed", "item": B.tower_item(h), "quantity": h["quantity"], "into": None,
                                  "for": named[0], "joins": h["joins"]})
        for n in named[1:]:  # a later step that uses it says where it was listed
            out[n].append({"kind": "listed", "item": B.tower_item(h), "quantity": h["quantity"], "into": None,
                           "for": n, "at": named[0]})
    return out


def preparation_text(rows: list[dict], number: dict[str, int], here: str) -> str:
    """What a step says before its parts go in (:func:`preparations`' rows for it)."""
    text = ""
    for r in rows:
        into = (r["into"] or "").replace("_", " ")
        serves = ("for its own screws below" if r["for"] == here else
                  f"for the {r['for'].replace('_', ' ')}'s screws in step {number[r['for']]}")
        if r["kind"] == "insert":
            text += (f"Before it goes in, melt {r['quantity']} x {r['item']} into the {into}'s pockets ({serves}): "
                     "the soldering iron's insert tip at the insert maker's temperature, each pressed in square until "
                     "flush with the face; a pocket that printed small is drilled to the insert's hole size, never "
                     "to its outside. ")
        elif r["kind"] == "nut":
            text += (f"Before it goes in, push {r['quantity']} x {r['item']} into the hexagonal traps of the {into} "
                     f"({serves}), a drop of cyanoacrylate in each: once the {into} stands on the bench they cannot "
                     "be reached. ")
        elif r["kind"] == "pressed":
            text += f"Before it goes in, fit {r['quantity']} x {r['item']}: {r['joins']}. "
        elif r["kind"] == "listed":
            text += f"It takes its share of the {r['item']} listed at step {number[r['at']]}. "
    return text


#: What a bonded seat part's row asks of the part that stands on the seat while the bond cures.
CURE_ON_SEAT = "standing on its seat"


def cure_on_seat(order, prep: dict[str, list[dict]]) -> tuple[list[str], str | None]:
    """The steps that bond seat parts which cure with the part they carry standing on them (their
    "placed" rows say CURE_ON_SEAT), and the later step that places that part (the first whose parts
    rest on them), or ([], None)."""
    bonded = [p.step.name for p in order
              if any(r["kind"] == "placed" and CURE_ON_SEAT in r.get("joins", "") for r in prep[p.step.name])]
    members = {m for p in order if p.step.name in bonded for m in p.step.members}
    holder = next((p.step.name for p in order if members & set(p.step.needs)), None)
    return (bonded, holder) if bonded and holder else ([], None)


def cure_text(cure: tuple[list[str], str | None], here: str, number: dict[str, int]) -> str:
    """What a step says when the bonds of :func:`cure_on_seat` cure under the part of a later step: the
    first bonding step has that part prepared before it; the part's own step says it was."""
    bonded, holder = cure
    if not bonded:
        return ""
    name, first, last = holder.replace("_", " "), number[bonded[0]], number[bonded[-1]]
    span = f"steps {first}-{last}" if last > first else f"step {first}"
    if here == bonded[0]:
        return (f"The {name} stands on its seat while the seat's bonds cure ({span}), so prepare it first, before "
                f"any bonding: do now what step {number[holder]} says before it goes in (its heat-set inserts and its "
                "ball-ended push screws, their balls in their cups). Then bond the seat's parts of "
                f"{span} in one session, stand the prepared {name} on them while the bond is wet and let it cure; "
                f"lift it off again until step {number[holder]}. ")
    if here in bonded:
        return f"(This bond cures with the others of {span}, the prepared {name} standing on the seat.) "
    if here == holder:
        return f"Prepared before step {first} (its inserts and push screws, as below): now it goes in for good. "
    return ""


def placed_text(rows: list[dict]) -> str:
    """What a step says of the bought items it fits itself (:func:`preparations`' "placed" rows): rows whose
    use reads the same but for its leading count (the precision shims, one row per thickness) are one
    sentence naming each item with its count, so no sentence of the step repeats."""
    groups: dict[str, list[tuple[str, str]]] = {}
    for r in rows:
        m = re.match(r"(\d+) (.*)", r["joins"], re.S)
        count, use = (m.group(1), m.group(2)) if m else ("", r["joins"])
        groups.setdefault(use, []).append((count, r["item"]))
    text = ""
    for use, items in groups.items():
        if len(items) == 1 and not items[0][0]:
            text += f" Press them in: {use}."
            continue
        named = "; ".join(f"{n} x {item}" if n else item for n, item in items)
        text += f" Fit {named}, {use}."
    return text


#: Steps that put shim stacks in: the stacks are drawn as boxes; each holds ``tower.shims_nominal`` shims.
SHIM_STACKS = ("projector_shims", "camera_shims")


def shim_stacks(step, meshes_by_name: dict, shim_mm: float | None) -> tuple[int, int] | None:
    """(stacks, shims in each) of a step that puts shim stacks in (SHIM_STACKS), else None: the
    nominal stacks as the tower draws them (boxes), each holding its thickness over one shim's
    (``shim_mm``, ``tower.shim_thickness``): the picture and the text share that count."""
    if not shim_mm:
        return None
    names = [n for n in step.members if re.sub(r"_\d+$", "", n) in SHIM_STACKS]
    if not names or len(names) != len(step.members):
        return None
    shims = {stack_count(meshes_by_name[n], shim_mm) for n in names}
    return (len(names), shims.pop()) if len(shims) == 1 else None


def stack_count(mesh, shim_mm: float) -> int:
    """Shims in a stack's box (a PartMesh): its thinnest extent over one shim's thickness (mm)."""
    return int(round(float(min(mesh.hi - mesh.lo)) / shim_mm))


def lifted_encloser(step, placed_names, meshes_by_name: dict, rig) -> str | None:
    """The part already in place that holds the whole step (its bounding box holds every member's: the
    dome round the paraboloid) and sits on a repeatable register, so that the step is done with it lifted
    off (section 6 handles the paraboloid with the dome off the same way); None when there is none."""
    import numpy as np

    for name in placed_names:
        a = meshes_by_name.get(name)
        reg = any(isinstance(j, DowelRegister) for j in getattr(rig.recipes.get(name), "joints", ()))
        if a is None or not reg:
            continue
        if all(np.all(a.lo <= meshes_by_name[m].lo) and np.all(meshes_by_name[m].hi <= a.hi) for m in step.members):
            return name
    return None


def step_text(placed, meshes_by_name: dict, prepared: dict | None = None, shim_mm: float | None = None,
              spring: str = "", lifted: str | None = None, off_since: int | None = None, fix_later: str = "") -> str:
    """What a found step says: what goes in, how (its direction), on what, and each group of like
    fasteners with its tool and what takes its thread (``prepared``: (kind, thread host) -> the step
    number where its inserts or trap nuts were set, :func:`preparations`). ``lifted``: the part in place
    round the whole step (:func:`lifted_encloser`): the step is done with it lifted off its register;
    ``off_since``: that part is off already, upside down on the bench since that step (the schedule's state:
    :func:`dome_steps`). ``fix_later``: the words that put the step's fastening off (its part goes back later)."""
    from collections import Counter

    from rigcad.manual import plan
    from rigcad.manual.assembly_check import _dir_name

    st = placed.step
    by_stem: dict[str, list[str]] = {}
    for n in sorted(st.members, key=lambda n: n != st.name):
        by_stem.setdefault(re.sub(r"_\d+$", "", n), []).append(n)
    stacks = shim_stacks(st, meshes_by_name, shim_mm)
    if stacks:
        k, each = stacks
        parts = f"{k} stack{'s' * (k > 1)} of {each} printed `tower_shim`s ({k * each} shims)"
    else:
        parts = " with ".join((f"the {len(ns)} {stem.replace('_', ' ')}s" if len(ns) > 1 else
                               f"the {ns[0].replace('_', ' ')}") for stem, ns in by_stem.items())
    bought = " (bought)" if st.bought else ""
    lead = st.name if st.name in st.members else st.members[0]
    from rigcad.manual.assembly import group_description

    text = f"Take {parts}{bought}: {group_description(st.members, lead, meshes_by_name)}. "
    # screws that carry a bought part of the step (a ball in a push screw's cup) go in before the step's part
    carried = {n for n in st.members if meshes_by_name[n].bought}
    first = [f for f in st.fasteners if carried & set(f.passes)]
    for (item,), n in Counter((f.item,) for f in first).items():
        balls = sorted(carried & {p for f in first for p in f.passes})
        what = re.sub(r"_\d+$", "", balls[0]).replace("_", " ")
        text += (f"Before it goes in, thread its {n} x {item} down into its inserts from above until each one's end "
                 f"stands out under its boss, and seat a {what} in each one's cup with a drop of retaining "
                 "compound; turn them from above once it stands (they set its height and tilt). ")
    on = ", ".join(n.replace("_", " ") for n in st.needs)
    if lifted and off_since is not None:
        outer, way = lifted.replace("_", " "), _dir_name(placed.direction)
        text += (f"The {outer} is off its register pins, upside down on the bench with its open base up, as step "
                 f"{off_since} left it: ")
        text += (into_upturned(outer, on, placed.direction) if way in ("-z (down)", "+z (up)")
                 else f"{MOVES.get(way, f'move it in along {way}')}, into the upturned {outer}, until it lies "
                 + (f"in the {outer}'s seats." if on == outer else f"on the {on}."))
    elif lifted:
        outer = lifted.replace("_", " ")
        text += (f"The {outer} is on its register pins now and closes round this part (its top opening leaves no "
                 f"room to work through): take out the {outer}'s screws, lift it straight off its pins (what it carries "
                 f"rides with it) and stand it upside down on the bench. "
                 + into_upturned(outer, on, placed.direction) + f" Then set the {outer} back on its pins and screw it "
                 f"down to its torque (section 6 does the same whenever this part is handled).")
    else:
        text += MOVES.get(_dir_name(placed.direction), f"move it in along {_dir_name(placed.direction)}").capitalize()
        text += f" until it rests on the {on}." if st.needs else " onto the bench."
    groups = Counter((f.item, f.tools[0].name, "trap" if f.thread_in == "nut" and f.nut_tool is None else f.thread_in,
                      plan.thread_host(f, meshes_by_name) if f.thread_in in ("insert", "nut") else None)
                     for f in st.fasteners if f not in first)
    for (item, tool, thread_in, host), n in groups.items():
        kind = {"insert": "insert", "trap": "nut"}.get(thread_in)
        k = (prepared or {}).get((kind, host), "?")
        how = THREAD_IN[thread_in].format(k=k)
        if spring and "compression spring" in item:  # the seat's spring bolts: set by the spring's length
            how = ("a washer under the head, the spring, a washer and the nut on top; hold the nut with the spanner "
                   f"and {spring}")
        text += f" {fix_later + ', fix' if fix_later else 'Fix'} it with {n} x {item}, {how} (tool: {tool} or an L key)."
    lift = max((f.lift_mm for f in st.fasteners), default=0.0)
    if lift:
        text += (f" Its screw goes in from below: lift the rig onto blocks {lift:g} mm high under the tongue (the "
                 "film test's), turn it with the L key's short arm in the socket, then set the rig down.")
    return text


#: The part the schedule lifts off its register for the steps done inside it (rigcad.manual.schedule.DOME_OFF).
DOME = "dome"


def dome_steps(schedule, names: list[str]) -> dict:
    """Where the dome is at each of section 5's steps (``names``, in its order), read from the schedule
    (``schedule``: its stages or manual.json's records; rigcad.manual.schedule.placing_states): ``off``, the
    steps after the dome's own whose stage begins with the dome off (done with it upside down on the bench);
    ``leaves_off``, whether the dome's own stage leaves it off; ``back``, the stage that sets it back (ends
    DOME_OFF), and ``between``, the stages from the one after the last step off to that one (their words)."""
    from rigcad.manual import schedule as S

    states = S.placing_states(schedule)
    if DOME not in names or DOME not in states:
        return {"off": [], "leaves_off": False, "back": None, "between": []}
    off = [n for n in names[names.index(DOME) + 1:] if n in states and S.DOME_OFF in states[n][1]]
    back = S.stage_ending(schedule, S.DOME_OFF)
    records = [st.record() if isinstance(st, S.Stage) else st for st in schedule]
    last = max((states[n][0] for n in off), default=None)
    between = [r["what"] for r in records[last:back]] if off and back and last < back else []
    return {"off": off, "leaves_off": S.DOME_OFF in states[DOME][2], "back": back, "between": between}


def _numbers(ks: list[int]) -> str:
    return f"step {ks[0]}" if len(ks) == 1 else f"steps {', '.join(map(str, ks[:-1]))} and {ks[-1]}"


def dome_words(name: str, dome: dict, number: dict[str, int]) -> tuple[str, str]:
    """What step ``name`` says about the dome (:func:`dome_steps`): (the words that put the dome's own
    fastening off until it goes back, the sentences that close the step)."""
    off = [number[n] for n in dome["off"]]
    if name == DOME and dome["leaves_off"] and off:
        return (f"When it goes back on its pins after step {off[-1]}",
                f" Then lift the dome off its pins again and stand it upside down on the bench, its open base up: the "
                f"film goes on the plate now (section 6, \"{C.STEP_FILM}\"), and {_numbers(off)} are done with the "
                f"dome off; it goes back on its pins after step {off[-1]} (the schedule's stage {dome['back']}).")
    if off and name == dome["off"][-1] and dome["between"]:
        return "", (" Then, before the next step: " + "; ".join(w[:1].lower() + w[1:].rstrip(".") for w in dome["between"])
                    + f" (the schedule's stage{'s' * (len(dome['between']) > 1)} up to {dome['back']}; the dome's "
                    f"bolts are step {number[DOME]}'s).")
    return "", ""


def lifted_way(direction):
    """The way a part goes onto what carries it in the upturned dome, in its step's picture (assembly.lifted_view's
    frame): its working ``direction`` turned with the dome (UPSIDE_DOWN). A part lowered onto the beam in the
    working position (the paraboloid's U clamp, open at the bottom) is pushed up onto it from below in the upturned
    dome, its opening towards the open base; one slid in level keeps its way, turned."""
    import numpy as np

    from rigcad.manual.assembly import UPSIDE_DOWN

    return UPSIDE_DOWN @ np.asarray(direction, float)


def into_upturned(outer: str, on: str, direction) -> str:
    """How a part that goes onto ``on`` along the vertical ``direction`` (its working position's) gets there with
    ``outer`` (the dome) upside down, its open base up, and what holds it then (:func:`lifted_way`). Lowered onto
    ``on`` in the working position, it sits under ``on`` in the upturned dome, its opening towards the open base:
    it goes in beside ``on`` and up onto it from below, and hangs there on its clamping screw alone."""
    if lifted_way(direction)[2] < 0:  # pushed up in the working position: lowered onto it from above now
        return f"Put the part in through the {outer}'s open base and lower it onto the {on}."
    return (f"Upside down, the part belongs under the {on}, its clamp's open side up, towards the {outer}'s open "
            f"base: lower it through the open base beside the {on}, past the {on}'s side, then push it up onto the "
            f"{on} from below, its open side first, and hold it there while you tighten its set screw. While the "
            f"{outer} is upside down nothing else holds it (its clamp hangs under the {on}): lay a folded lint-free "
            f"cloth in the {outer} under it, tighten the set screw before you let go, and keep a hand under the part "
            "whenever the set screw is loosened (to set its foil packs, or to take it off).")


#: In a step's picture the shims of a stack are drawn apart by this fraction of the picture's size, so
#: that each one shows (a 1 mm shim is under a pixel at page width).
SHIM_SPREAD = 0.025


def step_picture(meshes, done: list[int], members: list[int], offsets: dict, direction, shim_mm):
    """What a step's picture draws: (meshes, the indices that go in, their offsets). A shim stack that
    goes in (SHIM_STACKS) is drawn as its shims, one box each, ``shim_mm`` thick, fanned out along the
    stack's own axis (its thinnest extent) by SHIM_SPREAD of the picture's size: the count the text states."""
    import dataclasses

    import numpy as np

    stems = {re.sub(r"_\d+$", "", meshes[i].name) for i in members}
    if not shim_mm or not stems <= set(SHIM_STACKS):
        return meshes, members, offsets
    shown = list(meshes)
    lo = np.min([m.lo for m in meshes], axis=0)
    hi = np.max([m.hi for m in meshes], axis=0)
    gap = SHIM_SPREAD * float(np.max(hi - lo))
    new, moved = [], {}
    for i in members:
        m = meshes[i]
        axis = int(np.argmin(m.hi - m.lo))
        n = stack_count(m, shim_mm)
        for j in range(n):
            a, b = m.lo.copy(), m.hi.copy()
            a[axis], b[axis] = m.lo[axis] + j * shim_mm, m.lo[axis] + (j + 1) * shim_mm
            corners = np.array([[x, y, z] for x in (a[0], b[0]) for y in (a[1], b[1]) for z in (a[2], b[2])])
            faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                              [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
            shown.append(dataclasses.replace(m, name=f"{m.name}_shim_{j + 1}", vertices=corners, faces=faces))
            new.append(len(shown) - 1)
            moved[len(shown) - 1] = offsets[i] + np.eye(3)[axis] * gap * j  # fanned out along the stack's own axis
    return shown, new, moved


def _shim_mm(rig) -> float | None:
    """One printed shim's thickness (mm, ``tower.shim_thickness``); None without the tower."""
    tower = getattr(rig.profile, "tower", None)
    return getattr(tower, "shim_thickness", None) if getattr(rig.layout, "tower", None) is not None else None


def _section_assemble(d: Doc, c) -> None:
    """The manual's section 5: the assembly steps in the order the assembly check finds."""
    import numpy as np

    from rigcad import plots
    from rigcad.manual import assembly as A

    d.h(2, "5. Assemble")
    order = assembly_order(c.rig, c.steps, c.solids)
    d.p("The order below is the one rigcad's assembly check found: each part, swept along the direction the "
        "step names, clears everything already in place; each bolt's head, nut and tool have a straight way "
        "in. Each picture shows what is in place (grey) and what goes in (orange), drawn before its place "
        "along the direction it moves in, with a dashed line to where it goes.")
    index = {m.name: i for i, m in enumerate(c.meshes)}
    by_name = {m.name: m for m in c.meshes}
    tower_at = _tower_rows_by_step(c.rig, [p.step for p in order])
    prep = preparations(c.rig, order, by_name)
    number = {p.step.name: k + 1 for k, p in enumerate(order)}
    prepared = {(r["kind"], r["into"]): number[name] for name, rows in prep.items() for r in rows
                if r["kind"] in ("insert", "nut")}
    cure = cure_on_seat(order, prep)
    dome = dome_steps(c.schedule, [p.step.name for p in order])
    done: list[int] = []
    for k, placed in enumerate(order):
        st = placed.step
        members = [index[n] for n in st.members]
        stacks = shim_stacks(st, by_name, _shim_mm(c.rig))
        label = st.name.replace("_", " ") + (f" ({stacks[0]} stacks of {stacks[1]})" if stacks else f" (x{len(members)})"
                                             if len(members) > 1 and st.name not in st.members else "")
        text = "".join(register_text(j) for m in st.members if m in c.rig.recipes
                       for j in c.rig.recipes[m].joints if isinstance(j, DowelRegister))
        text += cure_text(cure, st.name, number)
        text += preparation_text(prep[st.name], number, st.name)
        off = st.name in dome["off"]
        lifted = DOME if off else lifted_encloser(st, [p.step.name for p in order[:k]], by_name, c.rig)
        later, closing = dome_words(st.name, dome, number)
        text += step_text(placed, by_name, prepared, _shim_mm(c.rig), spring_bolts(c.rig).get("set", ""), lifted,
                          number[DOME] if off else None, later)
        text += placed_text([r for r in prep[st.name] if r["kind"] == "placed"]) + closing
        text += _step_extras(c, st.name, tower_at)
        d.h(3, f"Step {k + 1}: {label}")
        d.p(text)
        path = f"images/step_{k + 1:02d}_{st.name}.png"
        # a step done with its encloser lifted off is drawn as done: the encloser upside down, the part going in
        pic, pic_done, way, turn = c.meshes, done, placed.direction, np.eye(3)
        if lifted:
            pic, pic_done, _ = A.lifted_view(c.meshes, done, lifted)
            way, turn = lifted_way(placed.direction), A.UPSIDE_DOWN
        offsets = _approach(pic, pic_done, members, way)
        shift = offsets[members[0]] if members else 0.0
        bolts = [(turn @ np.asarray(f.head) + shift - turn @ np.asarray(f.axis) * f.head_height_mm,
                  turn @ np.asarray(f.head) + shift + turn @ np.asarray(f.axis) * f.length_mm) for f in st.fasteners]
        shown, new, moved = step_picture(pic, pic_done, members, offsets, way, _shim_mm(c.rig))
        c.files[path] = plots.assembly_step(shown, pic_done, new, moved, f"step {k + 1}: {label}",
                                            cut_away=c.cut_away, fasteners=bolts)
        d.img(path, f"Step {k + 1}: the {label} (orange) moves along the dashed line to its place"
              + (f", the {lifted.replace('_', ' ')} lifted off and upside down" if lifted else ""))
        _drawing(d, c, st.name)
        done += members
        c.step(f"step {k + 1}")
    from rigcad.manual import plan as P

    c.assembly_order = [{"step": p.step.name, "parts": list(p.step.members), "direction": list(p.direction),
                         "prepare": prep[p.step.name],
                         "fasteners": [f.item for f in p.step.fasteners],
                         "threads_into": [{"item": f.item, "kind": f.thread_in, "part": P.thread_host(f, by_name)}
                                          for f in p.step.fasteners if f.thread_in in ("insert", "nut")
                                          and (f.thread_in == "insert" or f.nut_tool is None)]} for p in order]


def _step_extras(c, name: str, tower_at: dict) -> str:
    """What a step says about its own part beyond the plan: the projector's screws, the splitter's coated
    face, the focusing lens, the film at the base plate, and the tower's threaded rows fixed at it."""
    from rigcad.manual import plan as P

    text = ""
    if name == "projector_body":
        text += P.projector_screw_text(c.rig)
    if name == "beam_splitter":
        text += (" Its coated face (the reflecting one: the maker marks its edge, or a pen tip touching it shows "
                 "one reflection, where the uncoated face shows two) goes towards the projector (+x) and down, "
                 "towards the paraboloid.")
    if name == "focusing_lens":
        from rigcad.optics.focus import focusing_lens

        text += (f" It is the f = {focusing_lens(c.p, c.rig.geometry).focal_length:g} mm plano-convex lens of "
                 "the bill, its curved face towards the projector.")
    if name == "base_plate" and "camera_cross_base" in c.rig.recipes:
        text += (" To calibrate (section 6), the film goes on the plate once the dome's register is drilled "
                 "and the dome lifted off its pins again, before it is bolted down: see \"The film at the "
                 "sample plane\".")
    for h in tower_at.get(name, []):  # the threaded rows; the pressed ones came before the part
        if h.get("thread") and "heat-set insert" not in h["item"]:
            text += f" Fix it with {h['quantity']} x {B.tower_item(h)}: {h['joins']}."
    for h in B.tower_hardware(c.rig):  # the tower joints' bolts the plan places: their sleeves, faced first
        if tower_joints.placed(h) and h.get("shop_steps") and _last_step(h, tower_at["_order"]) == name:
            text += " Before its bolts: " + "; ".join(h["shop_steps"]) + "."
    return text


def _last_step(h: dict, order: list[str]) -> str | None:
    """The last of a tower hardware row's declared steps (``steps``: data) that this assembly has (``order``)."""
    named = [s for s in h.get("steps", ()) if s in order]
    return max(named, key=order.index) if named else None


def _drawing(d: Doc, c, part: str) -> None:
    """The shop drawing of a machined part (rigcad.manual.drawings), at the step that places it."""
    if f"drawings/{part}.png" not in c.files:
        return
    d.p(f"It is turned to its drawing, `drawings/{part}.svg` (or `.png`, shown here): take it to the lathe or "
        "to the machine shop with the bar the bill names.")
    d.img(f"drawings/{part}.png", f"`{part}`: its shop drawing (mm; the fit and the tolerances its recipe states)")


def _md_tables(d: Doc, lines: list[str]) -> None:
    """Tables another module wrote as Markdown lines (a header, its rule, rows; blank lines between
    tables), as the document's own tables."""
    blocks, block = [], []
    for line in [*lines, ""]:
        if line.startswith("|"):
            block.append([cell.strip() for cell in line.strip().strip("|").split("|")])
        elif block:
            blocks.append(block)
            block = []
    for b in blocks:
        d.table(b[0], b[2:])


def _section_mechanics(d: Doc, c) -> None:
    """Torques for the bolts into printed plastic and what bends (rigcad.fab.loads), and the tolerance
    stack of every optical element on this printer (rigcad.fab.stack), as findings the lab reads
    before it aligns."""
    from rigcad.fab import loads as L
    from rigcad.fab.stage import tolerance_stack

    c.mechanics = None
    if c.printer.process_errors is None or getattr(c.rig.layout, "tower", None) is None:
        return
    loads = L.loads(c.p, c.rig.layout, c.printer)
    stack = c.fab_report.get("stack")
    if stack is None:  # a report fab wrote without a stack: the call fab makes, on the report's parts
        stack = tolerance_stack(c.rig, c.printer, c.fab_report.get("parts", {}))[0]
    d.h(3, "Torques, and what bends")
    d.p("Tighten every bolt into printed plastic with a torque screwdriver to the torque below, never hand-tight: "
        "a hand-tight M4 presses the plastic past half its yield, and it creeps. Put a conical spring washer (DIN 6796, "
        "in the bill) under the heads of the joints marked yes: they locate a datum, and creep would relax them.")
    _md_tables(d, loads.table_lines())
    d.h(3, "The tolerance stack on this printer")
    d.p(f"Each optical element's position and tilt error from the datum (the base plate's bore) through every printed "
        f"link, seam, pin and clearance, on the {c.printer.name}'s process errors (`process_errors` in its printer file; "
        "measure yours with the calibration print, docs/rig-mechanics.md), against `tolerancing:`. 'adjusted': an "
        "adjuster's range covers it at a quarter of the tolerance or finer; 'refused': neither a locating feature "
        "nor an adjuster holds it yet, and the last column names the links that dominate.")
    _md_tables(d, stack["table_md"])  # fab's own table, with the seams of its split plans: one stack
    c.mechanics = {"loads": loads.record(), "stack": {k: v for k, v in stack.items() if k != "table_md"}}


def _approach(meshes, done: list[int], new: list[int], direction) -> dict:
    """Where a step's parts are drawn before they go in: moved back against their direction until
    their bounding box clears the parts in place (and by a gap)."""
    import numpy as np

    from rigcad.manual.assembly import EXPLODE_GAP

    d = np.asarray(direction, float)
    lo = np.min([meshes[i].lo for i in new], axis=0)
    hi = np.max([meshes[i].hi for i in new], axis=0)
    size = float(np.max(hi - lo))
    back = size + EXPLODE_GAP * size if done else 0.0
    return {i: -d * back for i in new}


def _tower_rows_by_step(rig, steps) -> dict:
    """The tower's hardware rows (rigcad.parts.tower.hardware) that the plan does not place itself
    (the tower's own joints), each in the last of the steps it declares (``steps``: data) that this
    assembly has."""
    order = [s.name for s in steps]
    out: dict = {"_order": order}  # the steps in order, for _last_step
    for h in B.tower_hardware(rig):
        if "mounting holes" in h["joins"] or tower_joints.placed(h):
            continue  # the instruments' screws and the tower joints' bolts: the plan's
        last = _last_step(h, order)
        if last:
            out.setdefault(last, []).append(h)
    return out


def printed_stock(entry: dict) -> float:
    """The sanding stock a mirror part was printed forward by (mm): the fab report's record of it
    (rigcad.fab.stage), the one figure the manual and docs/fab.md state."""
    if entry.get("sanding_stock"):
        return entry["sanding_stock"]["stock_mm"]
    return entry["polishing"]["stock_to_add_mm"]  # a report written without a stocked print: what it needs


def _section_finish(d: Doc, c) -> None:
    """The finishing recipe, the blocks from the mirrors' curvature, the templates' cutting, and the
    optical acceptance test (rigcad.manual.finishing)."""
    from rigcad.manual import finishing as F

    d.h(3, "Finishing recipe, stage by stage")
    stock = {n: printed_stock(e) for n, e in c.fab_report["parts"].items() if "polishing" in e}
    d.p("One recipe from the print to the mirror: the coats are the profile's `coating.layers`, in their order, and "
        "nothing else is sprayed (a coat not in them would move the surface off the design by its thickness). The "
        "slope test comes before the mirror coat, while a bad area can still be sanded.")
    d.table(["stage", "what", "how", "cure / wait", "check"], [list(r) for r in F.recipe(c.p, stock)])
    blocks = F.sanding_blocks(c.rig)
    block_set = F.sanding_block_set(c.rig)
    sanding_blocks(d, c, block_set)
    making = F.template_making(c.p, c.templates)
    d.p(F.template_making_text(making))
    d.p(" ".join(F.template_text(r) for r in c.templates) + " Check in at least four meridional planes, a quarter "
        "turn apart.")
    c.finishing = {"blocks": blocks, "acceptance": F.slope_acceptance(c.rig), "templates": c.templates,
                   "template_making": [{k: v for k, v in r.items()} for r in making],
                   "block_set": [{k: v for k, v in r.items() if k != "part"} for r in block_set]}


def _section_acceptance(d: Doc, c) -> None:
    """The optical acceptance test (rigcad.manual.finishing.slope_acceptance), where the schedule does it:
    on the assembled rig with its camera, on the polished clear coat, before the mirror coat."""
    acc = c.finishing["acceptance"]
    d.h(3, C.STEP_ACCEPTANCE)
    d.p("Here, with the rig assembled and the mirrors' clear coat polished, before their mirror coat (the schedule's "
        "order): if it fails, lift the dome off its register, take the paraboloid off the beam, block and polish the "
        "area again and repeat; once it passes, lift them off again for the mirror coat (section 4's last layer), "
        "set them back and repeat the test on the finished mirrors.")
    d.p(f"**Place the paraboloid first** (to `tolerancing.paraboloid_offset`, {acc['placement_offset_mm']:g} mm): "
        "unplaced, its lateral stack alone throws rays past the disc and the test could not tell a slope error from "
        "a misplaced paraboloid. With the dome off its pins, the beam and the paraboloid in it, stand the dome upside "
        "down on the turntable and centre it: the dial test indicator on the inside of the dome's base (the circle "
        "it was indicated in by on the plate, so its axis is O's), turn and tap the dome until the reading stays "
        "within one graduation. Then bring the indicator's tip onto the paraboloid's rim edge and read it at the "
        "four turns 45 deg off the beam (the beam stops the arm at the others): half the difference of two opposite "
        "readings is the paraboloid's offset along that diagonal. Move the clamp by its foil packs (the stop pin's "
        "along the beam, the set screw's across) until both are under the tolerance, and set the dome back on its "
        f"pins. Placed so, its placement alone lands the rays within **{acc['placement_spot_mm']:.2f} mm** of O "
        f"(the design's chief rays, traced with the paraboloid {acc['placement_offset_mm']:g} mm off), which leaves "
        f"**{acc['slope_room_mm']:.2f} mm** of the disc to the slopes. After the mirror coat the deflectometry "
        "(section 6) reads the placement again and re-seats it.")
    d.p("The mirrors' slope must be right, not only their form: in a right rig every ray the camera sees lands on "
        f"the sample point O within `tolerancing.max_spot_radius` ({acc['disc_radius_mm']:g} mm). The test lights a "
        "disc of that radius at O and looks at it through the mirrors with the rig's own camera:")
    d.ol([
        "The rig assembled, the camera aligned on its two crosses (section 6, \"Camera: the two crosses\": the first "
        "time, just before this test; this test's budget counts the paraboloid's placement only, so an unaligned "
        "camera's own offset would read as a slope error) looking down the axis through the splitter, the "
        "projector off, the room dark. The film of the circle test lies on the base plate's top over the bore, O "
        "traced on it (section 6, \"The film at the sample plane\": it goes on once the dome's register is drilled, "
        "before the dome is bolted down).",
        f"Lift the rig onto the film test's blocks (**{acc['block_under_tongue_mm']:g} mm** under the tongue, "
        f"**{acc['block_under_disc_mm']:g} mm** under the disc) and take what stands in the bore out from below "
        "(the `camera_cross_base` the film was traced on): "
        f"the film is now the only thing over the bore ({2 * acc['bore_radius_mm']:.1f} mm across), "
        f"{acc['film_above_bench_mm']:g} mm above the bench.",
        f"The light: a white LED torch (or a phone's torch) on the bench under the bore, pointing straight up, no "
        f"taller than {acc['lamp_room_mm']:g} mm (the blocks' height). The film scatters its light up into every "
        "direction the dome's rays arrive from: the lit film is the sample.",
        f"The reference picture: with the whole bore lit (radius {acc['bore_radius_mm']:.2f} mm), take the camera's "
        "picture, its exposure set so the brightest part of the paraboloid's image sits at 80-90 % of full scale.",
        f"The test picture: tape a black paper mask with a **{2 * acc['disc_radius_mm']:g} mm** hole (a leather "
        "punch) on the film, the hole centred on O's mark, and take the picture again at the same exposure "
        "(the film in the hole is as bright as before; only the lit area shrinks).",
    ])
    d.p(f"**Pass:** over at least {100 * acc['pass_fraction']:g} % of the paraboloid's image (outside the occlusion "
        "disc of the calibration circle), a pixel lit in the reference is lit in the test picture too (at least half "
        "its reference brightness). That is the pass the calibration holds the finished mirrors to, with the same "
        f"camera: the dome's slope error's 99th percentile within {acc['dome_slope_tolerance_mrad']:.2f} mrad "
        "(`rigcad calibrate`'s `residual_slope_p99_mrad`), so a dome that passes here is not sent back under its "
        "coat by the calibration for its slopes. A pixel lit in the "
        f"reference but dark in the test sees a point of the film between {acc['disc_radius_mm']:g} and "
        f"{acc['bore_radius_mm']:.1f} mm from O: the mirror area it looks at is off in slope by "
        f"{acc['dome_slope_tolerance_mrad']:.1f} to {acc['bore_slope_mrad']:.1f} mrad at the dome's farthest point "
        f"from O ({acc['dome_farthest_from_o_mm']:.0f} mm; a slope error e turns a ray by 2 e); block and polish it "
        "again. A pixel dark in both looks past the bore: farther off still. Run it first on the polished coat, "
        "before the mirror coat (the recipe's slope test: a bad area can still be sanded), then again on the "
        "finished mirrors.")


CHECKER_SQUARE_MM = C.CHECKER_SQUARE_MM


def spring_bolts(rig) -> dict:
    """What section 6 says to take the splitter holder off its seat and to put it back: its spring bolts
    (rigcad.parts.tower.hardware's row with the springs: thread, count, the spring's installed length and
    preload) undone, and set again by their springs' length. ``off``/``on``: the two sentences."""
    from rigcad.standards import THREADS

    row = next((h for h in B.tower_hardware(rig) if h.get("spring_mm")), None)
    if row is None:
        return {"off": "", "on": ""}
    th = THREADS[row["thread"]]
    sp = row["spring_mm"]
    off = (f"Undo the holder's {row['quantity']} spring bolts first: hold each bolt's head under the shelf with the "
           f"{th.hex_key:g} mm hex key, run its nut off the top with the {th.nut_af:g} mm spanner, and lift off the "
           "washer and the spring (keep each bolt's set together); the bolts drop out from under the shelf with the "
           "washers under their heads. ")
    on = (f"Put the {row['quantity']} spring bolts back up through the shelf and the holder's flange, a washer under "
          f"each head, then on top the spring ({sp['wire']:g} mm wire, {sp['outer_diameter']:g} mm outside, "
          f"{sp['free_length']:g} mm free), a washer and the nut, and " + spring_setting(row))
    return {"off": off, "on": on, "set": spring_setting(row)}


def spring_setting(row: dict) -> str:
    """How a spring bolt's nut is set (the tower's row with ``spring_mm``): to the spring's installed length."""
    return (f"run each nut down until its spring is **{row['spring_mm']['installed_length']:g} mm** long, measured "
            f"with the caliper: {row['preload_N']:.1f} N each, the preload the seat is designed for (these bolts are "
            "set by their springs' length, not by a torque).")


def sanding_blocks(d: Doc, c, block_set: list[dict]) -> None:
    """The printed sanding blocks (rigcad.manual.finishing.sanding_block_set): their STL files into
    ``blocks/``, how they are printed, faced with the abrasive and used, and their table."""
    import numpy as np

    from rigcad.export import mesh as EM
    from rigcad.manual import finishing as F

    for r in block_set:
        mesh = c.rig.mesh(r["part"])
        c.files[f"blocks/{r['part'].name}.stl"] = EM.stl_bytes(np.asarray(mesh.vertices), np.asarray(mesh.faces),
                                                               r["part"].name)
    mirrors = sorted({r["mirror"] for r in block_set})
    count = {m: sum(r["mirror"] == m for r in block_set) for m in mirrors}
    d.p(f"Sanding blocks: print the {len(block_set)} blocks of `blocks/` ("
        + ", ".join(f"{count[m]} for the {m}" for m in mirrors)
        + f"; {F.BLOCK_LENGTH_MM:g} mm along the meridian, or the whole meridian where it is shorter, "
          f"{F.BLOCK_WIDTH_MM:g} mm across, {F.BLOCK_THICKNESS_MM:g} mm thick; neighbours overlap by "
          f"{F.BLOCK_OVERLAP_MM:g} mm). A block's face is the mirror's own surface over its band of the meridian, "
          "revolved: it matches both curvatures, along the meridian and across it, by construction, and stands "
          f"{F.ABRASIVE_MM:g} mm proud of the surface, the abrasive film's thickness. The abrasive: "
          f"{F.ABRASIVE_SPEC}; " + "; ".join(f"{g} for {what}" for g, what in F.ABRASIVE) + ". Print the blocks "
          "face up, 0.1 mm layers, 100 % infill. Before first use, true each face on its own band of the "
          "knocked-down print: P240 film on the block, a pencil scribble over the face, strokes around the axis "
          "until the scribble is gone everywhere; then the grade of the stage. Sand with strokes around the axis "
          "(the surface is the same at every azimuth, so the face fits wherever it turns), moving the block along "
          f"the meridian no further than its slide below, where its face would stand off by {F.BLOCK_SAG_MM:g} mm "
          "(1 mil, the thinnest coat). The first band starts at the dome's base and at the paraboloid's rim.")
    d.table(["mirror", "block (blocks/)", "band along the meridian", "least radius along / across",
             "slide along the meridian"],
            [[r["mirror"], f"`{r['part'].name}.stl`", f"{r['from_mm']:.0f}-{r['to_mm']:.0f} mm",
              f"{r['meridional_radius_mm']:.1f} / {r['sagittal_radius_mm']:.1f} mm",
              f"±{r['slide_mm']:.1f} mm" if r["slide_mm"] > 0 else "none: turn it about the axis only"]
             for r in block_set])


def _film_step(d: Doc, c) -> None:
    """The film test as a lab does it: what holds the dome over the film at the sample plane, how the
    film is registered at O and where it is seen from (rigcad.manual.calibration.film_setup)."""
    f = C.film_setup(c.rig)
    d.h(3, C.STEP_FILM)
    d.p("The dome stands bolted on the base plate over the film: the plate's top "
        "is the dome's base plane and the sample plane (z = 0) by design, and the plate's bore, which centres the "
        "sample holder, centres the film's mark. The film goes on during the assembly, once the dome has been "
        "indicated in from the bore and its register drilled (the indicator's arm stands on the sample holder "
        "turning in the bore, so nothing else may be in it then), and is seen from below, through the bore:")
    seen = ("light past the rim falls inside the bore too" if f["direct_light_seen"] else
            f"light past the rim (outside the paraboloid's shadow, {f['paraboloid_shadow_radius_mm']:.1f} mm from O) "
            f"falls on the plate outside the bore ({f['bore_radius_mm']:.2f} mm) and is not seen from below: judge the "
            "circle by the spot, symmetric about the mark and smallest")
    d.ol([
        "In the assembly, once the dome's register is drilled and its pins pressed and the dome lifted off them "
        "again (the beam and the paraboloid go into it while it is off), before it is set back and bolted down: "
        "lift the plate off the sample holder, stand the `camera_cross_base` in its place (the same body and "
        "collar: the bore centres it the same way) and set the plate back over it. The cross's top is z = 0, level "
        "with the plate's top.",
        f"Lay a disc of matte drafting film ({1e3 * f['film_thickness_mm']:g} µm polyester, "
        f"**{f['film_diameter_mm']:.0f} mm** across, cut from the sheet with the scalpel) on the plate's top, "
        "centred on the bore, and tape its edge to "
        "the plate. Trace the cross under it with a fine pen: its centre is O. Then go on with the assembly: the beam "
        "and the paraboloid go into the dome while it is still off, and it goes back on its pins over the film after "
        f"them (section 5; the dome's flange and its {f['dome_bolts']} bolts are far outside the film).",
        f"For the test, lift the rig as one piece (plate, dome and tower are one rigid assembly; two people) onto "
        f"three blocks: one **{f['block_under_tongue_mm']:g} mm** tall under the tongue below the column, two "
        f"**{f['block_under_disc_mm']:g} mm** tall under the disc's rim either side of the dome (the tongue reaches "
        f"{f['tongue_below_disc_mm']:g} mm lower than the disc). Take the `camera_cross_base` out of the bore from "
        "below (the film stays taped over the bore, its mark traced).",
        f"Look up through the bore: a 45 deg mirror or a phone's camera on the bench under it (the "
        f"{f['block_under_disc_mm']:g} mm blocks leave room for it). Project the circle and set it as described "
        f"above; {seen}.",
        "Afterwards push the `camera_cross_base` back in for the camera's crosses (next) and set the rig down. "
        f"Then take out the dome's {f['dome_bolts']} flange screws, lift it off its register pins, peel the whole film "
        "and its tape off the plate's top and set the dome back on its pins: the film "
        f"({1e3 * f['film_thickness_mm']:g} µm) and the tape at its edge would otherwise stand on z = 0 under "
        "everything section 6 lays on the plate or checks against its top.",
    ])


def _calibration_more(d: Doc, c, cam: dict) -> None:
    """The steps after the crosses: the turned camera crosses, the checkerboard and the gray card
    (thesis 4.1.1, 4.1.2)."""
    rig = c.rig
    hidden = cam["base_cross_arm_mrad"] < cam["hung_cross_arm_mrad"]
    d.p("Turn the base cross 45 degrees to the hung one (it turns freely in the holder's bore)"
        + (f": seen from the COP its arms span {cam['base_cross_arm_mrad']:.1f} mrad, less than the hung cross's "
           f"{cam['hung_cross_arm_mrad']:.1f} mrad, so aligned it would hide behind it; turned, its arms show in the "
           "gaps between the hung cross's arms." if hidden else ": its arms then show between the hung cross's."))
    cb = C.checkerboard(rig)
    n = cb["squares"]
    d.h(3, C.STEP_CHECKER)
    d.p(f"Print a checkerboard of {cb['square_mm']:g} mm black and white squares ({n} x {n} squares on {cb['sheet']} "
        "matte paper, laser-printed at 600 dpi, checked with the caliper over ten squares) and cut it with the circle "
        f"cutter to a **{cb['disc_diameter_mm']:.0f} mm** disc, a square's corner at its centre, with a "
        f"{cb['hole_diameter_mm']:.0f} mm hole there for the bore (the scalpel finishes the cut): it lies on the base "
        f"plate inside the dome ({cb['dome_inside_diameter_mm']:.1f} mm across at the plate). Take out the dome's "
        f"{len(rig.layout.bolt_angles)} flange screws and lift the dome off its register pins (as for the calibration "
        "screens), lay the disc on the plate centred on the bore, set the dome back and screw it down to its torque "
        "(section 5). Then lift the dome again to take the disc out.")
    corr = C.camera_correspondence(rig)
    c.correspondence = corr
    d.p(C.checker_text(corr))
    d.h(3, C.STEP_GRAY)
    from rigcad.calibrate.graycard import manual_text

    card = gray_card_seat(rig)
    c.gray_card = card
    d.p(C.gray_card_placement(rig, card))
    d.p(manual_text(rig))  # the gray card command's own procedure (one home)


def _as_built(d: Doc, c) -> None:
    """The deflectometric calibration of the rig as built (rigcad.calibrate.kit's page), when the
    profile has a calibration section."""
    if getattr(c.p, "calibration", None) is None:
        return
    from rigcad.calibrate.kit import manual_page

    from rigcad.manual.finishing import recipe

    d.page(manual_page(c.rig, [row[0] for row in recipe(c.p)]), shift=2)


def _section_calibrate(d: Doc, c) -> None:
    """The manual's section: 6 calibrate."""
    import numpy as np

    from rigcad import plots
    from rigcad.export import mesh as M
    from rigcad.manual import assembly as A

    rig, p, files, step = c.rig, c.p, c.files, c.step
    circle, info = C.circle_image(rig)
    files["calibration/circle.png"] = circle
    files["calibration/circle.html"] = C.circle_page(rig, info)
    film = C.film_shadows(rig)
    pshadow = C.projector_shadows(rig)
    cam = C.camera_crosses(rig)
    d.h(2, "6. Calibrate (thesis 4.1.1)")
    thermal = lab_temperature(c)
    if thermal:
        d.p(f"**The lab's temperature.** Align, calibrate and measure within **±{thermal['swing_K']:g} C** of one "
            f"temperature (a lab's swing over a day, at its working 20-25 C, where the coats were cured): every printed length grows by "
            f"{thermal['expansion_per_K'] * 1e6:.0f}e-6 per degree ({thermal['material']}), and a uniform "
            f"±{thermal['swing_K']:g} C moves the projector's centre of projection {thermal['along_mm']:.3f} mm along "
            f"the axis against the paraboloid (both stand on the base plate): {100 * thermal['share']:.0f} % of its "
            f"tolerance (`tolerancing.projector_height`, `projector_offset`; "
            f"rigcad.fab.loads.thermal). A uniform change takes the whole tolerance only at ±{thermal['limit_K']:.0f} C "
            "(align and calibrate again past that), so what sets the range is what a uniform swing does not do: a "
            "gradient across the rig tilts it. Keep it out of sunlight, off a radiator's draught and out of the "
            "projector's exhaust, and let it settle an hour after the projector is switched on.")
    d.p("How each calibration item gets to its place, and what rigcad checked (a rig where one cannot is refused "
        "before this manual is written):")
    d.table(["item", "goes in", "what comes out of its way", "which goes back", "checked"],
            [[r["item"], r["way"], r["out_of_the_way"], r["back"], r["checked"]] for r in C.access(rig)])
    springs = spring_bolts(rig)
    _crosses(d, pshadow, springs, p, rig, c.printer)
    seat = C.splitter_seat(rig)
    if seat:
        _seat_section(d, c, seat, springs)
    d.h(3, C.STEP_CIRCLE)
    d.p("Leave the focusing lens in its mount: the circle is set through it, as the basis images are shown. Open "
        "`calibration/circle.html` in a browser on the projector's screen and press f (full screen): arrow keys "
        "move the circle (Shift: 10 px), + and - change its radius, 0 restores the design's circle, and its centre "
        "and radius in pixels are shown at the top left (h hides them). The same circle as a fixed image:")
    d.p(f"`calibration/circle.png` ({info['resolution_px'][0]} x {info['resolution_px'][1]} px, the "
        f"projector's resolution): a bright disc of radius **{info['radius_px']:.1f} px** centred on pixel "
        f"({info['centre_px_from_top_left'][0]:g}, {info['centre_px_from_top_left'][1]:g}) from the top left, the "
        f"paraboloid's rim through the lens ({info['radius_without_lens_px']:.1f} px without it: the lens scales the "
        f"pixels' angles x {info['lens_pixel_scale']:.3f}). Lay a film over the dome's base, marked at the sample point O (as below). "
        "With the projector placed as designed the reflected light converges to the mark; move the circle in the "
        "image until the spot is symmetric about the mark, then adjust its radius until the light converges to a "
        f"point. A circle larger than the rim throws direct light onto the film around the paraboloid's shadow, "
        f"a disc of **{film['paraboloid_shadow_radius_mm']:.1f} mm** radius about O, crossed by the beam's shadow, "
        f"a strip **{2 * film['beam_shadow_half_width_mm']:.1f} mm** wide. The directions below "
        f"{info['occlusion_radius_px']:.1f} px from the centre are hidden by the paraboloid itself (occlusion limit).")
    d.img("calibration/circle.png", f"calibration/circle.png: the calibration image, {info['resolution_px'][0]} x "
                                    f"{info['resolution_px'][1]} px, shown at page width")
    d.p(C.record_circle(rig, info))
    _film_step(d, c)
    _camera_crosses_step(d, c, cam)
    for name in ("projector_cross", "projector_backplate", "projector_mounting_plate", "camera_cross_hung",
                 "camera_cross_base"):
        if name in rig.recipes:
            part = rig.recipes[name]
            mesh = rig.mesh(part, M.PICTURE_CHORD_ERROR)
            files[f"images/{name}.png"] = plots.render_mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), name,
                                                            part.color)
            d.img(f"images/{name}.png", f"`{name}`: {part.description}")
    _calibration_more(d, c, cam)
    _as_built(d, c)
    step("calibration")
    c.calibration = {"circle": info, "film": film, "projector_crosses": pshadow, "camera_crosses": cam,
                     "splitter_seat": seat, "gray_card": c.gray_card, "lab_temperature": thermal,
                     "camera_correspondence": c.correspondence}


def _camera_crosses_step(d: Doc, c, cam: dict) -> None:
    """Section 6's camera crosses (rigcad.manual.calibration.camera_crosses): the camera set on the dome's
    axis, focused once and locked, then the projector referenced to the same axis through its COP."""
    rig, p = c.rig, c.p
    d.h(3, C.STEP_CAMERA)
    bolts = C.film_setup(rig)["dome_bolts"]
    d.p("**Twice.** First before the slope test (the optical acceptance test, on the polished clear coat, the "
        "schedule's order): that test's budget counts the paraboloid's placement only, so the camera must be on its "
        "place for it. The film is on the plate then, taped over the bore with the `camera_cross_base` under it: the "
        "camera looks at O's mark traced over the base cross, which is the base cross; focus and lock the camera as "
        "below, and leave the projector's check on one COP for the second time. Then again after the splitter "
        "seat's push screws are set (they tilt the holder the camera rides on), the film off, as follows in full.")
    d.p(f"The beam is inside the dome: take out the dome's {bolts} flange screws, lift the dome off its register pins "
        "(the beam and the paraboloid come with it) and stand it upside down on the bench, its open base up. The "
        "paraboloid's clamp hangs under the beam now, its open side up, on its set screw alone: a hand under the "
        "paraboloid, loosen the set screw, draw the clamp down off the beam and take the paraboloid out past the "
        "beam's side through the open base, its foil packs kept with it (in their places: they hold its setting). "
        f"Hang the `camera_cross_hung` on the beam in place of the paraboloid (its centre at the paraboloid's "
        f"vertex, z = {cam['hung_cross_z_mm']:.1f} mm), the `camera_cross_base` in the sample holder's place in the bore "
        "(its top on z = 0; it stays there from the earlier steps). Set the dome back on its pins and screw it down to its torque before you look: the cross "
        "hangs where the paraboloid's vertex is only with the dome on its register. "
        f"From the COP (z = {cam['cop_z_mm']:.1f} mm) the hung cross's arms span "
        f"{cam['hung_cross_arm_mrad']:.1f} mrad and the base cross's {cam['base_cross_arm_mrad']:.1f} mrad. Move the "
        "camera until the two overlap symmetrically in its image. A camera off the "
        f"axis by 1 mm shows them {cam['separation_mrad_per_mm_offset']:.2f} mrad apart "
        f"(`tolerancing.camera_offset` = {p.tolerancing.camera_offset:g} mm).")
    d.p(C.camera_focus_and_lock(rig, c.printer))
    d.p(C.shared_cop_text(rig, c.printer))
    d.p(f"**Then put the paraboloid back:** the {bolts} flange screws out, the dome lifted off and upside down again, "
        "the hung cross off the beam; clamp the paraboloid on the beam as before (in through the open base beside the "
        "beam, then up onto it from below, a hand under it until the set screw holds; its end on the stop pin, its foil "
        "packs in their places, the set screw tightened), set the dome back on its pins and screw it down to its "
        "torque. Take the `camera_cross_base` out of the bore and put the sample holder back in its place.")


def _crosses(d: Doc, pshadow: dict, springs: dict, p, rig, printer) -> None:
    """Section 6's projector crosses: the holder off its seat, the plate, crosses and backplate on it, the
    shadows' separation per mm of projector offset (rigcad.manual.calibration.projector_shadows)."""
    d.h(3, C.STEP_CROSSES)
    row = pshadow["rows"][0]
    d.p(springs["off"] + "Lift the splitter holder, with the camera on it, off its seat (its kinematic seat puts it back "
        "in the same place; the balls in its push screws' cups go with it, the cone's balls, the vee's pins and the "
        "flat's gauge block stay on the shelf) and take the focusing lens out of its mount; leave the mount "
        f"where it is. Set the `projector_mounting_plate` ({pshadow['plate_length_mm']:.0f} mm long) on the splitter seat "
        "in the holder's place: the three steel balls pressed into its underside (retaining compound) sit on the seat's "
        "cone, vee and flat where the holder's sat; it stops short of the lens mount's foot and never touches it. Stand "
        "the `projector_backplate` in the fence at the shelf's end, its cut cross towards the projector, and the "
        "two `projector_cross`es in the other two fences: their centres are then on the projector's axis, "
        f"{pshadow['axis_height_mm']:.1f} mm above the plate, {pshadow['spacing_mm']:.1f} mm apart, the far one "
        f"{pshadow['backplate_distance_mm']:.1f} mm in front of the backplate.")
    d.p(f"Project a white image. The near cross stands {row['projector_to_near_cross_mm']:.1f} mm from the projector's "
        f"COP: its shadow's arms reach {row['near_shadow_arm_mm']:.1f} mm on the backplate, the far cross's "
        f"{row['far_shadow_arm_mm']:.1f} mm. Aligned, the two shadows' centres coincide on the backplate's cut cross. "
        f"A projector off the crosses' line by 1 mm across the axis separates them by "
        f"**{row['separation_per_mm_offset']:.2f} mm**: move the projector on its slots (across) and its shims "
        f"(height) until they coincide. The profile allows `tolerancing.projector_offset` = "
        f"{p.tolerancing.projector_offset:g} mm. " + C.projector_lock(rig, printer) + " Then take the plate, crosses "
        "and backplate off. " + C.projector_focus_text(rig) + " Put the lens back and set the holder back on its "
        "seat. " + springs["on"])


def gray_card_seat(rig) -> dict:
    """Where the gray card sits (mm): the sample holder's top (its recipe's top face, under O by the sample's
    thickness), the bore's pocket it lies in, the card's disc (the holder's diameter), the shim foil that
    packs it up to O (rigcad.standards.SHIM_FOIL) and the feeler leaf that checks it flush."""
    from rigcad.fab.seams import FEELER_LEAF
    from rigcad.standards import SHIM_FOIL

    import numpy as np

    mesh = rig.mesh(rig.recipes["sample_holder"])
    h = rig.profile.sample_holder
    return {"holder_top_z_mm": float(np.asarray(mesh.vertices)[:, 2].max()), "face_z_mm": 0.0,
            "bore_diameter_mm": 2 * (h.radius + h.clearance), "card_diameter_mm": 2 * h.radius,
            "foil_mm": list(SHIM_FOIL), "feeler_mm": FEELER_LEAF}


def lab_temperature(c) -> dict | None:
    """The lab's temperature range: a uniform swing of rigcad.fab.loads.LAB_SWING_K each way, what it moves the
    projector's COP by (loads.thermal) and its share of the tolerance, and the swing that would take the whole
    tolerance (the share grows with the swing). None without the COP tower or the printer's process errors."""
    from rigcad.fab import loads as L

    if c.printer.process_errors is None or getattr(c.rig.layout, "tower", None) is None:
        return None
    t = L.thermal(c.p, c.rig.layout, c.printer)
    mat = L.material(c.printer)
    return {"swing_K": L.LAB_SWING_K, "material": mat.name.split(",")[0], "expansion_per_K": mat.expansion,
            "along_mm": t.sag_mm, "share": t.share, "limit_K": L.LAB_SWING_K / t.share, "model": t.model}


def _seat_section(d: Doc, c, seat: dict, springs: dict) -> None:
    """Section 6's adjustment of the splitter seat (rigcad.manual.calibration.splitter_seat): when, what to
    watch, which screw moves what and by how much per step, when to stop, how to lock."""
    from rigcad.manual import schedule as S
    from rigcad.manual.calibration import circle_image
    from rigcad.standards import SET_SCREW_KEY

    _, info = circle_image(c.rig)
    cx, cy = info["centre_px_from_top_left"]
    flat, vee = seat["screws"]["flat"], seat["screws"]["vee"]
    step = f"1/{round(1 / seat['turn_fraction']):d}" if seat["turn_fraction"] < 1 else f"{seat['turn_fraction']:g}"
    key = SET_SCREW_KEY.get(seat["thread"])
    row = next((h for h in B.tower_hardware(c.rig) if h.get("spring_mm")), None)
    spring = f"{row['spring_mm']['installed_length']:g} mm" if row else "its installed length"
    d.h(3, C.STEP_SEAT)
    d.p(f"**When:** after the crosses, the holder back on its seat with its spring bolts set, the focusing lens in, "
        "the mirrors coated and the film under the dome, O traced on it (the circle's set-up, next). The two spring "
        f"bolts only hold the holder down on its three balls: never turn them to adjust; each spring stays {spring} "
        f"long (the caliper), before and after. The three push screws ({seat['thread']}, {seat['pitch_mm']:g} mm "
        f"pitch, turned from above with the {key:g} mm hex key) carry it: screwed in (clockwise seen from above) a "
        f"screw lifts the holder at its ball by **{seat['lift_per_step_mm']:.4f} mm per {step} turn**. They start "
        f"where the splitter holder's step left them: the holder's underside {seat['gap_mm']:.2f} mm above the shelf beside each "
        "screw (the caliper's depth rod).")
    d.p("**What to watch:** `calibration/circle.html` on the projector (next section) and the film from below. "
        f"Press 0 (the design's circle, centred on pixel ({cx:g}, {cy:g})) and move the circle with the arrow keys "
        "until the spot on the film is symmetric about O's mark: the read-out's centre less the design's is how far "
        f"the projector's axis leans, **{seat['px_per_mrad']:.2f} px per mrad**.")
    d.ol([
        f"The vee's screw (its ball at +y): {step} turn in leans the axis towards {vee['leans']} by "
        f"{vee['axis_turn_per_step_mrad']:.2f} mrad: the circle that centres the spot moves "
        f"**{vee['columns_px_per_step']:.1f} px along the image's columns and {vee['rows_px_per_step']:.1f} px along "
        f"its rows**. Turn it first, by the columns' offset over {vee['columns_px_per_step']:.1f} px per {step} turn.",
        f"The flat's screw (its ball behind the holder, -x): {step} turn in leans the axis towards {flat['leans']} by "
        f"{flat['axis_turn_per_step_mrad']:.2f} mrad: **{flat['rows_px_per_step']:.1f} px along the rows**, "
        f"{flat['columns_px_per_step']:.1f} px along the columns. Turn it second, by what the rows' offset is then.",
        f"Which way: the projector's menu may mirror its image (ceiling or rear projection). Turn {step} in, "
        "re-centre the circle, and see the offset fall by about that many pixels; if it grows, turn the other way.",
        f"The cone's screw: leave it. Turned with the other two by the same amount it lifts the whole holder "
        f"{seat['lift_per_step_mm']:.4f} mm per {step} turn; use it so only to bring a screw back into its range "
        f"(each has {seat['travel_each_way_mm']:g} mm each way: {flat['range_each_way_steps']:.0f} steps of {step} turn, "
        f"{flat['range_each_way_mrad']:.0f} mrad on the flat, {vee['range_each_way_mrad']:.0f} mrad on the vee).",
        f"**Stop** when the centre is within one step of the design's both ways (re-centre after each turn): "
        f"{flat['rows_px_per_step']:.1f} px along the rows, {vee['columns_px_per_step']:.1f} px along the columns, "
        f"a quarter or less of `tolerancing.projector_tilt` ({seat['tolerance_mrad']:.1f} mrad, "
        f"{seat['tolerance_px']:.0f} px).",
        f"**Lock:** check both springs at {spring} again; put a drop of wicking threadlocker (the consumables) where "
        "each push screw enters its insert, leave it 10 min, then re-centre the circle once more: the centre must "
        "not have moved by a step. Then go on with the circle.",
    ])


def write_manual(rig, printer, fab_report: dict, out: Path, lock: Path | None = None, progress=None) -> list[Path]:
    """Write the manual's folder ``out`` (all files published together; see the module docstring)."""
    from rigcad.export.atomic import Staging, json_bytes

    doc, files, figures = build_manual(rig, printer, fab_report, progress)
    title = f"{rig.name}: assembly and calibration manual ({printer.name})"
    page = doc.html(title, files).encode("utf-8")
    from rigcad.export.manifest import profile_digest

    with Staging(out, lock, carry=lambda rel: False, made_from=profile_digest(rig.profile)) as stage:
        for rel, data in sorted(files.items()):
            stage.write_bytes(out / rel, data)
        stage.write_bytes(out / "manual.md", doc.markdown().encode("utf-8"))
        stage.write_bytes(out / "manual.html", page)
        stage.write_bytes(out / "manual.json", json_bytes(figures))
        return stage.commit()


__all__ = ["PARTS_FOLDERS", "Doc", "build_manual", "parts_note", "parts_text", "write_manual"]
