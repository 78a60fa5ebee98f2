"""`rigcad manual`: the bill of materials is computed, not typed (the coating stack changes the paint,
the printer changes the pins), its figures agree with closed forms and direct geometry, and the
manual's files (Markdown, one self-contained HTML page, the calibration image) are written."""

from __future__ import annotations

import io
import math
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from rigcad.parts.joints import ScrewJoint

import rigcad
from rigcad.fab.printers import load_printer
from rigcad.manual import bom as B
from rigcad.manual import calibration as C
from rigcad.manual.document import build_manual, write_manual

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

MIL = 0.0254


def _profile(tmp_path, name: str, body: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent(body), encoding="utf-8")
    return rigcad.load(path)


@pytest.fixture(scope="module")
def fab_reports(table31_rig, tmp_path_factory):
    """The base plate through the fab stage on two printers: the MK3S's 250 x 210 mm bed splits the
    303 mm plate (pins), the Vantage's takes it whole (none). ~6 s."""
    out = {}
    for name in ("prusa_mk3s", "vantage_i"):
        out[name] = table31_rig.fab(name, tmp_path_factory.mktemp(name) / "fab", parts=["base_plate"]).report
    return out


def test_pin_count_follows_the_printer(fab_reports):
    prusa = B.dowel_pins(fab_reports["prusa_mk3s"], load_printer("prusa_mk3s"))
    vantage = B.dowel_pins(fab_reports["vantage_i"], load_printer("vantage_i"))
    split = fab_reports["prusa_mk3s"]["parts"]["base_plate"]
    assert prusa is not None and prusa["quantity"] == len(split["pins"]) > 0, prusa
    assert vantage is None, "the Vantage prints the plate whole: no pins"
    pin = load_printer("prusa_mk3s").alignment_pin
    assert prusa["diameter_mm"] == pin.diameter and prusa["length_mm"] == 2 * pin.depth - B.PIN_END_GAP_MM


def test_paint_volumes_follow_the_coating_stack(tmp_path, table31_rig):
    thick = _profile(tmp_path, "thick", """
        coating:
          layers:
            - {name: black base paint, thickness: 3 mil}
            - {name: polyurethane clearcoat, thickness: 2 mil}
            - {name: MirraChrome, thickness: 1 mil}
        templates:
          gauged_layer: polyurethane clearcoat
        """)
    base = {(c.layer, c.mirror): c for c in B.coating_rows(table31_rig)}
    new = {(c.layer, c.mirror): c for c in B.coating_rows(thick)}
    assert ("polyurethane primer", "dome") in base and ("polyurethane primer", "dome") not in new
    for mirror in ("dome", "paraboloid"):
        b, n = base[("black base paint", mirror)], new[("black base paint", mirror)]
        # twice the thickness, nearly the same area (the layer moves by under 0.1 mm on a 16-150 mm
        # surface): the film doubles to within 1e-3
        assert n.film_cm3 / b.film_cm3 == pytest.approx(2.0, rel=1e-3)
        assert n.to_buy_cm3 == pytest.approx(n.film_cm3 * thick.profile.coating.margin, rel=1e-12)


def test_paint_margin_is_the_profiles(tmp_path, table31_rig):
    more = _profile(tmp_path, "margin", "coating:\n  margin: 4\n")
    a = sum(c.to_buy_cm3 for c in B.coating_rows(table31_rig))
    b = sum(c.to_buy_cm3 for c in B.coating_rows(more))
    assert b / a == pytest.approx(4.0 / table31_rig.profile.coating.margin, rel=1e-12)


def test_revolved_area_matches_the_paraboloids_closed_form(table31_rig):
    """Area of z = z_v - r^2 / (4 f) for r <= R: (8 pi f^2 / 3) ((1 + R^2 / (4 f^2))^(3/2) - 1)."""
    g = table31_rig.geometry
    f, R = g.focal_length, g.rim_radius
    exact = 8 * math.pi * f * f / 3 * ((1 + R * R / (4 * f * f)) ** 1.5 - 1)
    area = B.revolved_area(table31_rig.layout.design_paraboloid)
    # midpoint rule on 20001 points: second order, ~1e-9 relative; 1e-7 leaves room
    assert abs(area - exact) / exact < 1e-7, (area, exact)


def _dome_joint(rig):
    # declared by the dome (rigcad.parts.dome.flange_joint)
    (joint,) = [j for j in rig.recipes["dome"].joints if isinstance(j, ScrewJoint)]
    assert not [j for j in B.bolt_joints(rig) if j["parts"] == ("base_plate", "dome")], \
        "a declared joint is not found again from the holes"
    return joint


def test_the_flange_joint_is_declared_and_sized_from_the_standards(tmp_path, table31_rig):
    p = table31_rig.profile
    j = _dome_joint(table31_rig)
    assert j.count == p.dome_shell.bolts == 8 and (j.thread, j.into) == ("M4", "insert")
    # M4: 1.0 large washer + 1.3 conical spring washer (free height) + 6 flange, into the 8.1 mm insert -> 16 mm
    assert j.length == 16 and j.item.startswith("M4 x 16 mm")
    other = _profile(tmp_path, "bolts", "base_plate:\n  thickness: 20 mm\ndome_shell:\n  bolt_diameter: 5.5 mm\n"
                                        "  bolts: 12\n  flange_width: 24 mm\n")
    j = _dome_joint(other)
    # M5 (5.5 mm medium clearance): 1.0 washer + 6 flange + 9.5 insert = 16.5 mm -> 16 mm
    assert j.thread == "M5" and j.count == 12 and j.length == 16 and j.item.startswith("M5 x 16 mm")
    # every through bolt the plan still finds from holes joins parts that exist, with some grip
    for b in B.bolt_joints(table31_rig):
        assert all(n in table31_rig.recipes for n in b["parts"]) and b["grip_mm"] > 0 and b["count"] > 0


def test_the_tower_hardware_is_the_towers_and_follows_the_mounting_threads(tmp_path, table31_rig):
    from rigcad.parts.tower import hardware

    rows = B.fasteners(table31_rig)
    tower = [r for r in rows if r.get("tower")]
    # every row of the tower's but its optics (those are the purchased table's)
    assert len(tower) == len([h for h in hardware(table31_rig.profile, table31_rig.layout) if "spec" not in h]) > 0
    assert not any(set(j["parts"]) & {"tower_column", "tower_shelf"} for j in B.bolt_joints(table31_rig)), \
        "the tower's joints have one home (parts.tower.hardware), not two"
    other = _profile(tmp_path, "thread", "projector:\n  mount_thread: M6\n")
    assert any(r["item"].startswith("M6 x ") and "projector" in r["use"] for r in B.fasteners(other))


def test_calibration_circle_is_the_rim_at_the_projectors_resolution(table31_rig):
    from PIL import Image

    png, info = C.circle_image(table31_rig)
    img = np.asarray(Image.open(io.BytesIO(png)))
    w, h = table31_rig.profile.projector.resolution
    assert img.shape == (h, w) and set(np.unique(img)) == {0, 255}
    # the derived figures' closed form (profile.derived, not the design map) gives the rim's pixel radius
    # without the focusing lens; the circle is set through it, x its pixel scale (the tower places the
    # projector so that, through the lens, the paraboloid sees its COP at the design COP)
    g = table31_rig.geometry
    assert info["radius_without_lens_px"] == pytest.approx(g.pixels_vertex_to_rim, rel=1e-9)
    assert info["radius_px"] == pytest.approx(g.pixels_vertex_to_rim * info["lens_pixel_scale"], rel=1e-9)
    assert info["radius_px"] / info["radius_without_lens_px"] == pytest.approx(1.076, abs=1e-3)
    lit = int((img == 255).sum())
    r = info["radius_px"]
    # pixel centres inside a circle: pi r^2 within the pixels its edge crosses (~ its perimeter)
    assert abs(lit - math.pi * r * r) < 2 * math.pi * r
    rows, cols = np.nonzero(img == 255)
    assert (rows.min() + rows.max() + 1) / 2 == pytest.approx(h / 2, abs=0.5)
    assert (cols.min() + cols.max() + 1) / 2 == pytest.approx(w / 2, abs=0.5)


def test_cross_shadow_separation_against_a_direct_construction(table31_rig):
    """The two cross centres' shadows cast from a COP off their line by 1 mm, by intersecting the rays
    with the backplate's plane directly."""
    table = C.projector_shadows(table31_rig)
    for row in table["rows"]:
        a = row["projector_to_near_cross_mm"]
        cop = np.array([-a, 1.0])  # (along the axis, across it), mm
        X = table["spacing_mm"] + table["backplate_distance_mm"]
        hits = []
        for x in (0.0, table["spacing_mm"]):
            d = np.array([x, 0.0]) - cop
            hits.append(cop[1] + d[1] * (X - cop[0]) / d[0])
        assert abs(hits[0] - hits[1]) == pytest.approx(row["separation_per_mm_offset"], rel=1e-12)


@pytest.fixture(scope="module")
def written(table31_rig, fab_reports, tmp_path_factory):
    out = tmp_path_factory.mktemp("manual") / "prusa_mk3s"
    paths = write_manual(table31_rig, load_printer("prusa_mk3s"), fab_reports["prusa_mk3s"], out)
    return out, paths


def test_the_manual_is_written_with_its_pictures_and_one_self_contained_page(written, fab_reports, table31_rig):
    out, paths = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    page = (out / "manual.html").read_text(encoding="utf-8")
    for ref in re.findall(r"\]\(([^)]+)\)", md):
        assert (out / ref).is_file(), f"manual.md shows {ref}, which was not written"
    assert not re.search(r"""(src|href)\s*=\s*["'](?!data:)""", page), "the page refers to a file or URL"
    assert page.count("data:image/png;base64,") == len(re.findall(r"!\[", md))
    for step in ("Bill of materials", "Sand the mirrors", "Coat, layer by layer", "Assemble", "Calibrate"):
        assert step in md
    pins = B.dowel_pins(fab_reports["prusa_mk3s"], load_printer("prusa_mk3s"))
    assert f"| {pins['item']} | {pins['quantity']} |" in md
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    # the hardware table is the plan's fasteners as the assembly check fits them (one source with the steps)
    for row in plan.hardware(plan.steps(table31_rig, picture_meshes(table31_rig))[0], table31_rig):
        assert f"| {row['item']} | {row['quantity']} |" in md, row
    assert (out / "calibration" / "circle.png").is_file()
    # the opening section shows one figure per size to measure, before section 1
    opening = md[:md.index("## 1.")]
    from rigcad.profile.instruments import measurements

    for m in measurements(table31_rig.profile):
        ref = f"images/measure/{m.key.replace('.', '_')}.png"
        assert f"]({ref})" in opening and (out / ref).is_file(), m.key
    import json

    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    shots = sorted(p.name for p in (out / "images").glob("step_*.png"))
    found = json.loads((out / "manual.json").read_text(encoding="utf-8"))["assembly_order"]
    # one step, one picture for every step the plan declares, in the order the assembly check found
    assert len(shots) == len(found) == len(plan.steps(table31_rig, picture_meshes(table31_rig))[0])
    assert [s["step"] for s in found][:3] == ["sample_holder", "base_plate", "dome"], found
    assert f"step_{[s['step'] for s in found].index('dome') + 1:02d}_dome.png" in shots
    assert md.count("### Step ") == len(shots)


def test_the_manual_is_deterministic(table31_rig, fab_reports, written):
    """A second build gives the same bytes as the files written by the first."""
    out, _ = written
    doc, files, _ = build_manual(table31_rig, load_printer("prusa_mk3s"), fab_reports["prusa_mk3s"])
    assert doc.markdown().encode("utf-8") == (out / "manual.md").read_bytes()
    for rel, data in files.items():
        assert (out / rel).read_bytes() == data, rel


def test_rigcad_manual_refuses_an_unknown_printer_in_one_line(tmp_path):
    run = subprocess.run([sys.executable, "-m", "rigcad", "manual", "achutha2006", "--printer", "nosuch",
                          "--exports", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode != 0 and run.stderr.startswith("rigcad: error:") and len(run.stderr.splitlines()) == 1
    assert "nosuch" in run.stderr and not any(tmp_path.iterdir())


def test_printed_times_are_the_slicers_when_it_sliced(fab_reports, table31_rig):
    """With G-code (fab --gcode) each piece carries PrusaSlicer's estimates: the bill takes those."""
    import copy

    report = copy.deepcopy(fab_reports["prusa_mk3s"])
    pieces = report["parts"]["base_plate"]["pieces"]
    for k, pc in enumerate(pieces):
        pc["gcode"] = {"estimates": {"print_time_s": 3600.0 * (k + 1), "filament_g": 10.0 * (k + 1)}}
    row = next(r for r in B.printed(table31_rig, report) if r["part"] == "base_plate")
    n = len(pieces)
    assert row["source"] == "slicer"
    assert row["time_s"] == 3600.0 * n * (n + 1) / 2 and row["material_g"] == 10.0 * n * (n + 1) / 2
    estimate = next(r for r in B.printed(table31_rig, fab_reports["prusa_mk3s"]) if r["part"] == "base_plate")
    assert estimate["source"] == "rigcad estimate"
    assert estimate["time_s"] == pytest.approx(sum(pc["estimate"]["print_time_s"] for pc in pieces), rel=1e-12)


def test_the_manual_opens_with_a_figure_of_each_size_to_measure(table31):
    """Section 0 lists the assumed sizes and shows one figure per size, each a PNG written with it."""
    import io
    from types import SimpleNamespace

    from PIL import Image

    from rigcad.manual.document import Doc, measure_first
    from rigcad.profile.instruments import measurements

    d, c = Doc(), SimpleNamespace(p=table31, files={})
    measure_first(d, c)
    images = [(b[1], b[2]) for b in d.blocks if b[0] == "img"]
    keys = [m.key for m in measurements(table31)]
    assert len(images) == len(keys) == len(c.files)
    for key, (path, caption) in zip(keys, images):
        assert f"`{key}`" in caption and key.replace(".", "_") in path
        assert Image.open(io.BytesIO(c.files[path])).size[0] > 200


def test_a_bought_part_is_billed_with_its_stock_not_as_a_cut_plate(table31_rig):
    """The fab stage reports a bought part as {"process": "bought", "stock": ...} (no pieces, no plate):
    the bill lists it with its stock (it used to read a cut plate's thickness and fail)."""
    stock = "aluminium extrusion 40 x 40 mm, slot 8, cut to 292.0 mm"
    rows = B.printed(table31_rig, {"parts": {"tower_column": {"process": "bought", "stock": stock, "quantity": 1}}})
    assert rows == [{"part": "tower_column", "use": "rig", "quantity": 1, "process": "bought", "pieces": 0,
                     "time_s": None, "material_g": None, "source": None, "note": stock}]


# -- manual.md states what manual.json holds -------------------------------------------------------
def _md_table(md: str, heading: str) -> list[list[str]]:
    """The rows (cells stripped, header and rule dropped) of the first table after ``### heading``."""
    section = md.split(f"### {heading}\n", 1)[1].split("\n### ", 1)[0].splitlines()
    start = next(k for k, ln in enumerate(section) if ln.startswith("|"))
    lines = []
    for ln in section[start:]:
        if not ln.startswith("|"):
            break
        lines.append(ln)
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines[2:]]


def disagreements(md: str, doc: dict) -> list[str]:
    """Where manual.md's bill (its hardware, printed parts, optics and coating tables and the total
    line) differs from manual.json's: each difference as a sentence; [] when they agree."""
    from rigcad.units import hours_minutes

    bill, out = doc["bill"], []
    pairs = [("Hardware", [[r[0], r[1]] for r in _md_table(md, "Hardware")],
              [[r["item"], str(r["quantity"])] for r in bill["hardware"]]),
             ("Printed and cut parts", [[r[0].strip("`"), r[2], r[3]] for r in _md_table(md, "Printed and cut parts")],
              [[r["part"], str(r["quantity"] or "-"), str(r["pieces"]) if r.get("time_s") is not None else
                ("bought" if r["process"] == "bought" else "cut" if r["quantity"] else "-")] for r in bill["printed"]]),
             ("Optics and instruments", [[r[0], r[1]] for r in _md_table(md, "Optics and instruments")],
              [[r["item"], str(r["quantity"])] for r in bill["purchased"]]),
             ("Paint and clearcoat", [[r[0], r[4].strip("*")] for r in _md_table(md, "Paint and clearcoat")],
              [[c["layer"], f"{c['to_buy_cm3']:.1f} ml"] for c in bill["coating"]])]
    for name, shown, held in pairs:
        if shown != held:
            out.append(f"{name}: manual.md {shown} against manual.json {held}")
    timed = [r for r in bill["printed"] if r.get("time_s") is not None]
    total = (f"In all: **{sum(r['pieces'] * r['quantity'] for r in timed)} printed pieces, "
             f"{hours_minutes(sum(r['time_s'] for r in timed))} of printing and "
             f"{sum(r['material_g'] for r in timed):.0f} g")
    if total not in md:
        out.append(f"the total line: manual.md does not say {total!r}")
    return out


def test_manual_md_states_the_figures_manual_json_holds(written):
    import json

    out, _ = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    doc = json.loads((out / "manual.json").read_text(encoding="utf-8"))
    assert disagreements(md, doc) == []
    assert doc["bill"]["hardware"] and "fasteners" not in doc["bill"]  # one hardware list, the steps'
    # planted contradictions, one at a time, each found
    row = doc["bill"]["hardware"][0]
    planted = md.replace(f"| {row['item']} | {row['quantity']} |", f"| {row['item']} | {row['quantity'] + 1} |", 1)
    assert planted != md and disagreements(planted, doc)
    other = json.loads(json.dumps(doc))
    other["bill"]["coating"][0]["to_buy_cm3"] += 0.5
    assert disagreements(md, other)
    other = json.loads(json.dumps(doc))
    other["bill"]["printed"][0]["quantity"] = (other["bill"]["printed"][0]["quantity"] or 0) + 1
    assert disagreements(md, other)


def test_every_hardware_line_has_its_step_and_every_bought_step_its_line(table31_rig):
    """The bill's hardware lines name the steps that fit them (as data: the plan's fasteners, the parts'
    declared registers, the tower's rows' ``steps``), and every bought part a step puts in is in the
    bill: the optics table or a hardware line of that step."""
    from rigcad.manual import bom as B
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    steps = plan.steps(table31_rig, picture_meshes(table31_rig))[0]
    names = {s.name for s in steps}
    rows = plan.bill_hardware(table31_rig, steps, {"fasteners": B.fasteners(table31_rig), "pins": None})
    for r in rows:
        if r["steps"] == ["with the bolts above"]:
            continue  # the nuts, washers and inserts counted from the bolts of the steps above
        assert r["steps"] and set(r["steps"]) <= names, r
    optics = {"projector_body", "camera_body", "beam_splitter", "focusing_lens"}
    for st in steps:
        if st.bought and st.name not in optics:
            assert any(st.name in r["steps"] for r in rows), st.name


def _h3_sections(md: str, start: str, stop: str | None = None) -> dict[str, str]:
    """The ``### `` subsections of manual.md from the heading ``start`` on (to ``stop``): heading -> text."""
    text = md[md.index(start):]
    if stop:
        text = text[:text.index(stop)]
    parts = re.split(r"^### (.*)$", text, flags=re.M)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts), 2)}


def test_every_item_a_calibration_step_names_has_its_bill_line(written, table31_rig):
    """Section 6's steps (and the finishing's optical acceptance test) name their items by the words of the
    calibration kit (calibration.kit_items); each named item has its bill line listing that step, with what
    to buy; nothing undefined ('plug') is used."""
    import json

    out, _ = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    doc = json.loads((out / "manual.json").read_text(encoding="utf-8"))
    sections = _h3_sections(md, "## 6. Calibrate")
    # the finishing's test, where the schedule does it: after the assembly, before section 6
    sections[C.STEP_ACCEPTANCE] = _h3_sections(md, "## 5. ", "## 6. ")[C.STEP_ACCEPTANCE]
    items = C.kit_items(table31_rig)
    assert C.kit_misses(sections, items) == []
    # the bill's lines: manual.md's table and manual.json hold every item, its quantity, spec and steps
    table = {r[0]: r for r in _md_table(md, "Calibration and test kit")}
    held = {r["item"]: r for r in doc["bill"]["calibration_kit"]}
    for it in items:
        assert it.spec and it.quantity, it
        assert table[it.item][1:] == [it.quantity, it.spec, "; ".join(it.steps)], it.item
        assert held[it.item]["steps"] == list(it.steps) and held[it.item]["spec"] == it.spec
    for want in ("tablet", "upright display", "gray card", "drafting film", "blocks", "spacer"):
        assert any(want in it.words for it in items), want
    assert not re.search(r"\bplug\b", md[md.index("## 6. Calibrate"):]), "section 6 uses an undefined 'plug'"
    # planted: an item dropped from the bill, and an item named in a step that does not list it
    assert C.kit_misses(sections, [it for it in items if "tape" not in it.words])
    film = C.STEP_FILM
    assert C.kit_misses({**sections, film: sections[film] + " Lay the tablet on it."}, items)


def test_inserts_nuts_and_pins_go_in_before_what_needs_them(written):
    """From manual.json's order: every insert or trap nut a step's screws thread into was set in an earlier
    step (or this step, before its part goes in), in the step that places the part holding it, as many as the
    screws; every pin or ball a step presses is pressed before its part (the text says so first); the seat's
    balls go in with the splitter holder, in the cups of its push screws."""
    import json

    out, _ = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    order = json.loads((out / "manual.json").read_text(encoding="utf-8"))["assembly_order"]
    at = {m: k for k, st in enumerate(order) for m in st["parts"]}
    threaded = 0
    for k, st in enumerate(order):
        for t in st["threads_into"]:
            threaded += 1
            assert t["part"] in at and at[t["part"]] <= k, (st["step"], t)
            kind = "insert" if t["kind"] == "insert" else "nut"
            prep = [r for r in order[at[t["part"]]]["prepare"] if r["kind"] == kind and r["into"] == t["part"]
                    and r["for"] == st["step"]]
            assert len(prep) == 1, (st["step"], t)
            assert prep[0]["quantity"] == sum(1 for u in st["threads_into"] if u["part"] == t["part"]
                                              and u["kind"] == t["kind"]), prep
    assert threaded >= 8 + 4 + 4 + 3  # the dome's 8, the column's 4 trap nuts, the shelf's 4, the seat's 3
    steps = _h3_sections(md, "## 5. Assemble", "### Torques")
    for k, st in enumerate(order):
        text = next(v for h, v in steps.items() if h.startswith(f"Step {k + 1}:"))
        for r in st["prepare"]:
            if r["kind"] in ("insert", "nut", "pressed"):
                assert text.index("Before it goes in") < text.index("Take "), st["step"]
            if r["kind"] == "register":
                assert text.index("register pins") < text.index("Take "), st["step"]
    # the column's dowels: half before the column (in the tongue), half before the shelf
    dowels = {st["step"]: r["quantity"] for st in order for r in st["prepare"]
              if r["kind"] == "pressed" and r["item"].startswith("dowel pin") and "4 x" in r["item"]}
    assert dowels == {"tower_column": 2, "tower_shelf": 2}, dowels
    holder = next(st for st in order if "splitter_holder" in st["parts"])
    assert sum(p.startswith("seat_ball_") for p in holder["parts"]) == 3, holder["parts"]


def test_section_6_undoes_the_spring_bolts_and_sets_them_back(written, table31_rig):
    """Lifting the splitter holder off its seat: its spring bolts' nuts come off first and go back to the
    spring's installed length (its preload), the figures of the tower's row."""
    from rigcad.manual.document import spring_bolts

    out, _ = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    text = _h3_sections(md, "## 6. Calibrate")[C.STEP_CROSSES]
    row = next(h for h in B.tower_hardware(table31_rig) if h.get("spring_mm"))
    words = spring_bolts(table31_rig)
    assert words["off"] and words["on"]
    assert text.index(words["off"]) < text.index("Lift the splitter holder") < text.index(words["on"])
    assert f"**{row['spring_mm']['installed_length']:g} mm**" in words["on"]
    assert f"{row['preload_N']:.1f} N" in words["on"] and f"{row['quantity']} spring bolts" in words["off"]


def test_the_bill_names_a_camera_lens_to_buy(written, table31_rig):
    """The thesis's profile knows its lens in pixels only: the optics table names one in mm (the line of
    rigcad.manual.camera_lens), after the camera's own line."""
    from rigcad.manual import camera_lens

    out, _ = written
    optics = _md_table((out / "manual.md").read_text(encoding="utf-8"), "Optics and instruments")
    row = camera_lens.bill_row(table31_rig)
    items = [r[0] for r in optics]
    assert row["item"] in items, items
    assert items[items.index(row["item"]) - 1].startswith("camera"), items


def test_the_holders_drawing_is_written_and_linked_where_it_is_turned(written):
    """drawings/sample_holder.svg and .png are in the manual's folder, the bill's row of the bar and the
    holder's assembly step link them (rigcad.manual.drawings)."""
    out, _ = written
    md = (out / "manual.md").read_text(encoding="utf-8")
    assert (out / "drawings" / "sample_holder.svg").is_file() and (out / "drawings" / "sample_holder.png").is_file()
    # the bill's row of the bar, where the fab report lists it (this module's fab run is the base plate's only)
    for row in (r for r in _md_table(md, "Printed and cut parts") if r[0] == "`sample_holder`"):
        assert "`drawings/sample_holder.svg`" in row[-1], row
    step = next(s for s in md.split("\n### Step ")[1:] if s.split("\n", 1)[0].split(": ", 1)[1].startswith("sample holder"))
    assert "`drawings/sample_holder.svg`" in step and "](drawings/sample_holder.png)" in step, step[:400]
