"""The docs tell the truth: every marked number in README.md and docs/*.md is its figure in
docs/figures.json (within the figure's stated tolerance), the figures are the current code's (the
ones the session's own `rigcad stl` and MK3S fab runs give), the pictures are the ones `make docs`
copied from the current outputs, every page is linked from the README, and the pages' examples run.
docs/figures.md says what `make docs` writes; docs/figures.py and docs/figure_spec.py do it."""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"


@pytest.fixture(scope="module")
def tools():
    """docs/figures.py and docs/figure_spec.py (repository tooling beside the pages, not rigcad)."""
    sys.path.insert(0, str(DOCS))
    try:
        figures = importlib.import_module("figures")
        spec = importlib.import_module("figure_spec")
    finally:
        sys.path.remove(str(DOCS))
    return figures, spec


@pytest.fixture(scope="module")
def data() -> dict:
    return json.loads((DOCS / "figures.json").read_text(encoding="utf-8"))


def _pages() -> list[Path]:
    return [README, *sorted(DOCS.glob("*.md"))]


def _number(text: str) -> list[float]:
    return [float(t.replace(",", "")) for t in text.split(" x ")]


def _printed_tolerance(text: str) -> float:
    """Half a unit of the last digit printed: '1.12' -> 0.005, '1,096' -> 0.5, '1.5e-08' -> 0.05e-08."""
    mant, _, exp = text.replace(",", "").partition("e")
    decimals = len(mant.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals) * (10.0 ** int(exp) if exp else 1.0)


def _agrees(text: str, entry: dict) -> bool:
    value = entry["value"]
    values = value if isinstance(value, list) else [value]
    shown = _number(text)
    if len(shown) != len(values):
        return False
    tol = entry["tolerance"]
    for s, v, t in zip(shown, values, text.split(" x ")):
        if tol == "exact":
            ok = s == v
        elif tol.endswith("%"):  # a measured time: within the stated share, or as printed
            ok = abs(s - v) <= max(float(tol[:-1]) / 100 * abs(v), _printed_tolerance(t))
        else:  # as printed; 1e-9 relative for the decimal rendering of a binary float
            ok = abs(s - v) <= _printed_tolerance(t) * (1 + 1e-9) + 1e-12 * abs(v)
        if not ok:
            return False
    return True


def test_every_marked_number_is_its_figure(tools, data):
    figures, _ = tools
    marks, wrong = 0, []
    for page in _pages():
        for m in figures.MARKED.finditer(page.read_text(encoding="utf-8")):
            marks += 1
            entry = data["figures"].get(m["name"])
            if entry is None:
                wrong.append(f"{page.name}: {m['name']} is not in docs/figures.json")
            elif not _agrees(figures.shown_numbers(m["num"], entry), entry):
                wrong.append(f"{page.name}: {m['num']} for {m['name']}, the file says {entry['value']} "
                             f"{entry['unit']} ({entry['tolerance']})")
    assert marks >= 100, marks  # the pages quote well over a hundred figures; none marked = a vacuous pass
    assert not wrong, "run `make docs`:\n" + "\n".join(wrong)


def test_a_stale_number_is_caught():
    """The comparison itself: a number one printed digit off, or a count one off, disagrees."""
    entry = {"value": 1.1234, "tolerance": "as printed"}
    assert _agrees("1.12", entry) and not _agrees("1.13", entry) and not _agrees("1.1", {**entry, "value": 1.16})
    assert _agrees("48", {"value": 48, "tolerance": "exact"}) and not _agrees("49", {"value": 48, "tolerance": "exact"})
    assert _agrees("293.5 x 293.5 x 233.9", {"value": [293.47, 293.47, 233.88], "tolerance": "as printed"})
    assert not _agrees("293.5 x 293.5 x 233.9", {"value": [293.47, 293.47, 234.0], "tolerance": "as printed"})
    assert _agrees("31", {"value": 32.2, "tolerance": "5 %"}) and not _agrees("31", {"value": 34.0, "tolerance": "5 %"})


#: Units of what the stages measure or produce (times, masses, sizes of files, counts of pieces, pins,
#: triangles, steps): a number before one of them is a figure, never an input of the profile.
OUTPUT_UNITS = r"(?:h|min|g|kg|MB|MiB|KB|s|ms|pieces|pins|triangles|steps)\b"
#: Words that make a number a bound or a target rather than a measured figure.
BOUND = re.compile(r"(<|<=|>=|>|under|within|targets?|limit|at most|up to|timeout)\W*[\d.,x ]*$", re.I)
#: A sentence that names its numbers as targets ("Targets: 1.5 s for an edit, 10 s for ...").
TARGETS = re.compile(r"\btargets?\b(?:(?!\.\s).)*$", re.I | re.S)
#: Words after a number that make it a bound ("400 ms at most").
BOUND_AFTER = re.compile(r"^\s*(at most|or less|or more|at least)", re.I)


def unmarked_figures(text: str) -> list[str]:
    """Numbers before an output unit that carry no figure marker, outside code, in a paragraph or
    table row that does not call itself a one-off measurement and not written as a bound."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`]*`", "``", text)
    found = []
    for block in re.split(r"\n\s*\n|\n(?=\|)", text):
        if "one-off" in block:
            continue
        # <!--given--> after a number: a setting or a constant the page states, not a measurement
        for m in re.finditer(rf"(?<![\w.\-/])(\d[\d,]*(?:\.\d+)?)(?!<!--fig|<!--given-->)\s?{OUTPUT_UNITS}", block):
            before, after = block[:m.start()], block[m.end():]
            if not (BOUND.search(before[-30:]) or TARGETS.search(before) or BOUND_AFTER.search(after)):
                found.append(" ".join(block[max(0, m.start() - 40):m.end()].split()))
    return found


def test_no_unmarked_figure(tools):
    """Every time, mass, file size and count the pages state is marked (and so checked), or is said to
    be a one-off measurement, or is a bound or a target, or is marked <!--given--> (a setting)."""
    wrong = [f"{page.name}: ...{hit}" for page in _pages() for hit in unmarked_figures(page.read_text(encoding="utf-8"))]
    assert not wrong, "mark these figures (docs/figures.md) or say they are one-off:\n" + "\n".join(wrong)


def test_an_unmarked_figure_is_caught():
    assert unmarked_figures("The dome prints in 53.1 h.") == ["The dome prints in 53.1 h"]
    assert unmarked_figures("The dome prints in 53.1<!--fig:x--> h.") == []
    assert unmarked_figures("The dome prints in 53.1 h (one-off, `rigcad fab --gcode`).") == []
    assert unmarked_figures("A run takes under 2 s.") == []
    assert unmarked_figures("Targets: 1.5 s for one edit, 10 s for another.") == []
    assert unmarked_figures("Edits are grouped (400 ms at most).") == []
    assert unmarked_figures("ended by 30<!--given--> ms of quiet") == []
    assert unmarked_figures("Targets: 1.5 s. It took 3.2 s.") == ["Targets: 1.5 s. It took 3.2 s"]


def test_the_seat_that_is_enough_is_the_benchs():
    """docs/calibrate-notes.md's "What seat is enough" states bench/results/calibrate_seating_0.01deg.json's
    count of trials with every parameter within target and its frame's tilts (calibrate.md shows the
    seating sweep on the current code: tests/calibrate/test_calibrate_page.py)."""
    run = json.loads((ROOT / "bench" / "results" / "calibrate_seating_0.01deg.json").read_text(encoding="utf-8"))
    every = sum(t["parameters_met"] == t["parameters_total"] for t in run["per_trial"])
    lo, mid, hi = run["frame_tilt_deg_range"]
    page = " ".join((DOCS / "calibrate-notes.md").read_text(encoding="utf-8").split())
    assert run["profile"] == "achutha2006 + screen_seating_0.01deg"
    assert f"within target in {every} of {run['trials']} trials" in page
    assert f"the frame's tilt against the truth {lo:.4f}-{hi:.4f} (median {mid:.4f}) deg" in page


def _bench_tables(page: str, marker: str) -> str:
    """The block of ``page`` between ``<!-- {marker} -->`` and ``<!-- end of {marker} -->``."""
    text = (DOCS / page).read_text(encoding="utf-8")
    found = re.search(rf"<!-- {re.escape(marker)} -->\n(.*?)<!-- end of {re.escape(marker)} -->", text, re.S)
    assert found, f"docs/{page} has no block marked <!-- {marker} -->"
    return found.group(1)


def test_calibration_tables_are_the_bench_results():
    """docs/calibrate.md's tables are bench/calibrate.py's rendering of the committed
    bench/results/calibrate.json: a rerun of the bench that is not copied into the page fails here."""
    spec = importlib.util.spec_from_file_location("bench_calibrate", ROOT / "bench" / "calibrate.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    result = json.loads((ROOT / "bench" / "results" / "calibrate.json").read_text(encoding="utf-8"))
    assert _bench_tables("calibrate.md", "bench/calibrate.py tables") == bench.tables(result)


def test_every_figure_states_unit_source_and_tolerance(data):
    for name, e in data["figures"].items():
        assert {"value", "unit", "tolerance", "source"} <= set(e), name
        if e.get("kind") in ("measured", "one-off"):  # a time or a bench figure: where and when
            assert e.get("machine") and e.get("date"), name


def _changed(spec_figs, fresh: dict, data: dict) -> list[str]:
    """The figures of ``spec_figs`` whose current value (``fresh``) no longer holds the file's
    (figures.Figure.holds)."""
    return [f"{fig.name}: the current code gives {fresh[fig.name]}, docs/figures.json says "
            f"{data['figures'][fig.name]['value']}" for fig in spec_figs
            if fig.name in fresh and not fig.holds(fresh[fig.name], data["figures"][fig.name]["value"])]


def test_a_figure_at_the_floor_may_move_by_a_cpu_not_by_a_change(tools):
    """Another CPU's last bits: a residual at the arithmetic's floor moves by percents and passes; a
    changed design moves it by orders and fails; an ordinary figure moved by 1e-4 fails."""
    figures, _ = tools
    floor = figures.Figure("design.max_miss_mm", "stl", "design.json", "x", "mm", ".1e", roundoff=True)
    plain = figures.Figure("design.focal_length_mm", "stl", "design.json", "x", "mm", ".2f")
    data = {"figures": {floor.name: {"value": 1.48e-8}, plain.name: {"value": 12.5}}}
    assert not _changed([floor, plain], {floor.name: 1.466e-8, plain.name: 12.5}, data)
    assert _changed([floor], {floor.name: 2.0e-6}, data)
    assert _changed([floor], {floor.name: 5.0e-9}, data)
    assert _changed([plain], {plain.name: 12.5 * (1 + 1e-4)}, data)


def test_stl_figures_are_the_current_codes(tools, data, default_exports):
    """The design's and the parts' figures from this session's `rigcad stl` equal the file's."""
    figures, spec = tools
    figs = [f for f in spec.FIGURES if f.run == "stl"]
    assert len(figs) > 50, len(figs)
    fresh = figures.extract(figs, spec.RUNS, default_exports.root)
    assert not _changed(figs, fresh, data), "run `make docs`:\n" + "\n".join(_changed(figs, fresh, data))


@pytest.mark.e2e  # the whole rig through fab on the MK3S: make test-e2e
def test_fab_figures_are_the_current_codes(tools, data, shared_build, table31_rig):
    """Pieces and dowel pins per part on the MK3S, from this session's fab run of the dome and a few
    parts that print whole, equal the file's: one more pin in the split rule fails here until
    `make docs` runs."""
    figures, spec = tools
    from rigcad.fab.printers import load_printer
    from rigcad.fab.stage import run_fab

    parts = ["dome", "paraboloid", "beam", "camera_cross_base", "camera_cross_hung", "dome_template",
             "paraboloid_template"]

    def build(folder):  # the same run as tests/fab/conftest.py's prusa_run: one run serves both
        prusa = load_printer(ROOT / "profiles" / "printers" / "prusa_mk3s.yaml")
        out = folder / "prusa_mk3s"
        return out, run_fab(table31_rig, prusa, out, parts=parts)

    out, _ = shared_build("prusa_run", build)
    report = json.loads((out / "fab.json").read_text())
    figs = [f for f in spec.FIGURES if f.run == "fab_mk3s" and f.name.split(".")[2] in parts
            and f.name.split(".")[-1] in ("pieces", "pins")]
    assert len(figs) == 2 * len(parts)
    fresh = {f.name: f.get(report) if callable(f.get) else figures.dig(report, f.get) for f in figs}
    assert fresh["fab.prusa_mk3s.dome.pins"] > 0  # the dome splits on the MK3S: its pins are the test
    assert not _changed(figs, fresh, data), "run `make docs`:\n" + "\n".join(_changed(figs, fresh, data))


def _shown_pictures() -> set[str]:
    """Every picture a page shows, as a path under docs/."""
    out = set()
    for page in _pages():
        for target in re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", page.read_text(encoding="utf-8")):
            path = (page.parent / target).resolve()
            out.add(path.relative_to(DOCS).as_posix())
    return out


def test_every_picture_shown_is_made_by_make_docs(data):
    pictures = data["pictures"]
    missing = _shown_pictures() - set(pictures)
    assert not missing, f"pictures shown but not refreshed by `make docs`: {sorted(missing)}"
    for doc, entry in pictures.items():
        digest = hashlib.sha256((DOCS / doc).read_bytes()).hexdigest()
        assert digest == entry["sha256"], f"docs/{doc} is not the picture `make docs` copied: run `make docs`"


def test_pictures_are_drawn_from_the_current_outputs(tools, data, default_exports, table31_rig):
    """The part pictures' sources (each part's shape in the manifest) and the ray diagram's
    (design.json's sections) are what the current code gives."""
    figures, spec = tools
    checked = 0
    for pic in spec.PICTURES:
        if pic.run != "stl":
            continue
        now = figures.picture_source(default_exports.root, pic.source)
        assert figures.same_source(data["pictures"][pic.doc], now), f"docs/{pic.doc}: drawn from older outputs; run `make docs`"
        checked += 1
    assert checked > 10, checked


def test_a_part_picture_is_stale_when_its_shape_moves_not_its_last_bits(tools):
    """Another CPU's last bits (a volume by 4e-14, a box by 5e-13 mm) keep a part's picture current;
    a part 1 um larger, a hole more, or a picture recorded by digest against one by numbers, do not."""
    figures, _ = tools
    shape = {"volume_mm3": 895152.0745144694, "bbox_min_mm": [-146.7, -146.7, 0.0], "bbox_max_mm": [146.7, 146.7, 233.9],
             "genus": 11, "quantity": 1}
    moved = lambda **kw: {"source_values": {**shape, **kw}}  # noqa: E731
    recorded = {"source_values": shape}
    assert figures.same_source(recorded, moved(volume_mm3=shape["volume_mm3"] * (1 + 4e-14),
                                                bbox_min_mm=[-146.7, -146.7, 5e-13]))
    assert not figures.same_source(recorded, moved(bbox_max_mm=[146.7, 146.7, 233.901]))
    assert not figures.same_source(recorded, moved(genus=12))
    assert not figures.same_source(recorded, {"source_sha256": "0" * 64})


def test_every_page_is_linked_from_the_readme():
    readme = README.read_text(encoding="utf-8")
    links = set(re.findall(r"\]\((docs/[^)#]+\.md)", readme))
    pages = {f"docs/{p.name}" for p in DOCS.glob("*.md")}
    assert not pages - links, f"pages the README does not link: {sorted(pages - links)}"
    assert not links - pages, f"README links to missing pages: {sorted(links - pages)}"


def test_readme_is_a_front_door():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, len(lines)  # two screens
    text = "\n".join(lines)
    two = re.search(r"## Two commands\n+```sh\n(.*?)```", text, flags=re.S)
    assert two, "the README's two commands"
    commands = [line.split("#")[0].strip() for line in two[1].splitlines() if line.strip()]
    assert commands == ["make stl", "make test"], commands
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.search(r"^make test$", ci, flags=re.M), "CI runs the README's test command"


def test_readme_floors_are_the_import_contract():
    """The README's list of floors is the layers contract of pyproject.toml, in order."""
    import tomllib

    layers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]["layers"]
    text = README.read_text(encoding="utf-8").split("## The floors", 1)[1].split("\n## ", 1)[0]
    listed = [re.findall(r"`([\w.]+)`", line.split(":")[0]) for line in text.splitlines() if line.startswith("- ")]
    assert listed == [[m.strip() for m in layer.split("|")] for layer in layers]


def _examples() -> list[tuple[str, str]]:
    out = []
    for page in sorted(DOCS.glob("*.md")):
        if page.name == "api.md":  # tests/test_api_docs.py runs it, with its own checks
            continue
        for i, code in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)):
            out.append((f"{page.name}[{i}]", code))
    return out


@pytest.mark.parametrize("where,code", _examples(), ids=[w for w, _ in _examples()])
def test_page_examples_run(where, code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("RIGCAD_PROFILES", raising=False)
    exec(compile(code, where, "exec"), {})


def test_pages_have_examples():
    pages = {w.split("[")[0] for w, _ in _examples()}
    stages = {"design.md", "parts.md", "check.md", "manual.md", "fab.md", "tolerance.md", "optimize.md"}
    assert stages <= pages, sorted(stages - pages)


def test_every_part_has_its_row_and_picture(tools):
    """A part added to the code appears in docs/parts.md's table and pictures (after `make docs`)."""
    _, spec = tools
    text = (DOCS / "parts.md").read_text(encoding="utf-8")
    for name in spec._parts():
        assert f"<!--fig:parts.{name}.size_mm-->" in text, f"docs/parts.md has no row for the part {name}"
        assert f"(parts/{name}.png)" in text, f"docs/parts.md does not show parts/{name}.png"
