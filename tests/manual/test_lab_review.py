"""The lab technician's read-through, point by point, as checks on the manual's own data: no step says a
sentence twice, a figure a base profile set for its own instrument is flagged when inherited with
another model, the tools a step uses are in the bill, the gray card's height and the lab's temperature
are stated from the data that sets them."""

from __future__ import annotations

import re
import textwrap

import pytest

import rigcad
from rigcad.manual import bom as B
from rigcad.manual import document as D


def _profile(tmp_path, name: str, body: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent(body), encoding="utf-8")
    return rigcad.load(path)


def repeated_sentences(text: str) -> list[str]:
    """The sentences (split at '. ' and at the end) that occur more than once in ``text``, normalised for
    spaces; sentences under 40 characters ('Tighten them.') may repeat."""
    seen, out = set(), []
    for s in re.split(r"(?<=[.!?])\s+", " ".join(text.split())):
        if len(s) >= 40 and s in seen and s not in out:
            out.append(s)
        seen.add(s)
    return out


def test_repeated_sentences_are_found():
    once = "Fit the shim between the printed shims of each stack. Tighten the screw."
    assert repeated_sentences(once) == []
    assert repeated_sentences(once + " " + once) == ["Fit the shim between the printed shims of each stack."]


def test_the_bought_items_a_step_fits_are_one_sentence_per_use(table31_rig):
    """The precision shims (one row per thickness, the same use) are named in one sentence: step 14 said
    the same sentence four times."""
    rows = [{"kind": "placed", "item": B.tower_item(h), "quantity": h["quantity"], "into": None, "for": "projector_body",
             "joins": h["joins"]} for h in B.tower_hardware(table31_rig) if "precision shim" in h["item"]]
    assert len(rows) >= 2, "the tower buys more than one thickness of shim"
    text = D.placed_text(rows)
    assert repeated_sentences(text) == [], text
    for r in rows:  # every thickness is still named, with its count per stack
        assert r["item"] in text
    # the use is said once: planted back as one sentence per row, it repeats
    planted = "".join(f" Press them in: {r['joins'].split(' ', 1)[1]}." for r in rows)
    assert repeated_sentences(planted)


def test_an_inherited_instrument_figure_is_flagged_with_its_file(tmp_path):
    """A profile that extends the thesis's and restates its projector inherits the BenQ's throw ratio: the
    bill says which file set it (the base profile's line), not the file that named the projector. (Named
    with another projector, the inherited figure is refused: tests/profile/test_precedence.py.)"""
    restated = _profile(tmp_path, "restated", """
        projector:
          model: benq_pb6210
        """)
    spec = B._describe(restated.profile.projector, restated.profile, "projector")
    assert re.search(r"throw ratio 1\.75 \(set in `profiles/achutha2006\.yaml:\d+`, not with the model", spec), spec
    own = rigcad.load("achutha2006")
    assert "not with the model" not in B._describe(own.profile.projector, own.profile, "projector")


def _table_after(md: str, heading: str) -> list[str]:
    """The rows (lower case) of the first table after ``heading`` in a manual.md."""
    if heading not in md:
        return []
    rest = md.split(heading, 1)[1]
    rows, started = [], False
    for line in rest.splitlines():
        if line.startswith("|"):
            started = True
            rows.append(line.lower())
        elif started:
            break
    return rows


def tool_misses(md: str) -> list[str]:
    """The tools (B.TOOL_WORDS) sections 2-6 of a manual.md name that no line of its tools or calibration
    kit tables holds."""
    body = md.split("## 2. Print", 1)[1]
    lines = _table_after(md, "### Tools") + _table_after(md, "### Calibration and test kit")
    return [w for w in B.TOOL_WORDS if re.search(rf"\b{re.escape(w)}", body, re.I) and not any(w in r for r in lines)]


def test_a_tool_missing_from_the_bill_is_found():
    md = ("### Tools\n\n| item | qty |\n|---|---|\n| Digital caliper | 1 |\n\n## 2. Print\n\n"
          "Measure it with the caliper.\n")
    assert tool_misses(md) == []
    assert tool_misses(md + "Ream the hole with the reamer.\n") == ["reamer"]


@pytest.mark.e2e
def test_every_tool_a_step_names_is_in_the_bill(written):
    md = (written / "manual.md").read_text(encoding="utf-8")
    assert tool_misses(md) == []
    # the dome's register: its drill and reamers, and the indicator that centres it, are tools lines
    tools = " ".join(_table_after(md, "### Tools"))
    assert "dial test indicator" in tools and "twist drill" in tools and "reamer" in tools
    # planted: the tools table without its tin snips line misses the snips the shims' step names
    planted = "\n".join(line for line in md.splitlines() if not (line.startswith("|") and "tin snips" in line.lower()))
    assert "tin snips" in tool_misses(planted)


@pytest.mark.e2e
def test_no_step_of_the_manual_says_a_sentence_twice(written):
    md = (written / "manual.md").read_text(encoding="utf-8")
    steps = re.split(r"\n### ", md.split("## 5. Assemble", 1)[1].split("\n## ", 1)[0])
    assert len(steps) > 10
    for step in steps:
        text = " ".join(line for line in step.splitlines()[1:] if line and not line.startswith(("!", "*")))
        assert repeated_sentences(text) == [], step.splitlines()[0]


def test_the_gray_card_sits_at_o_on_the_holder(tmp_path, table31_rig):
    """The card's seat: the holder's top (read from its mesh) is the sample's thickness under O, in every
    profile (a 2 mm sample puts it 2 mm under)."""
    card = D.gray_card_seat(table31_rig)
    p = table31_rig.profile
    assert abs(card["holder_top_z_mm"] + p.sample_holder.sample_thickness) < 1e-6, card  # the mesh's top, to 1e-6 mm
    assert card["face_z_mm"] == 0.0 and card["card_diameter_mm"] == 2 * p.sample_holder.radius
    thick = _profile(tmp_path, "thick_sample", """
        sample_holder:
          sample_thickness: 2 mm
        """)
    assert abs(D.gray_card_seat(thick)["holder_top_z_mm"] + 2.0) < 1e-6


def test_the_lab_temperature_is_the_expansion_over_the_cop_height(table31_rig):
    """alpha x dT x (COP to vertex): the closed form of a uniform swing (both stand on the base plate); the
    limit is the swing at which it takes the whole tolerance."""
    from types import SimpleNamespace

    from rigcad.fab import loads as L
    from rigcad.fab.printers import load_printer

    printer = load_printer("prusa_mk3s")
    p = table31_rig.profile
    t = D.lab_temperature(SimpleNamespace(rig=table31_rig, p=p, printer=printer))
    along = L.material(printer).expansion * L.LAB_SWING_K * p.layout.cop_to_vertex
    assert abs(t["along_mm"] - along) < 1e-12 and t["swing_K"] == 3.0  # the machinist's +-3 C
    assert t["share"] >= along / p.tolerancing.projector_height - 1e-12
    assert abs(t["limit_K"] * t["share"] - L.LAB_SWING_K) < 1e-9


@pytest.mark.e2e
def test_section_6_states_the_lab_temperature_and_the_gray_cards_height(written):
    import json

    md = (written / "manual.md").read_text(encoding="utf-8")
    doc = json.loads((written / "manual.json").read_text(encoding="utf-8"))
    cal = doc["calibration"]
    assert f"within **±{cal['lab_temperature']['swing_K']:g} C**" in md
    assert f"{cal['lab_temperature']['along_mm']:.3f} mm along" in md
    assert f"top stands **{-cal['gray_card']['holder_top_z_mm']:g} mm under it**" in md
    seat = cal["splitter_seat"]["screws"]
    assert f"**{seat['flat']['rows_px_per_step']:.1f} px along the rows**" in md


def test_profile_show_marks_an_inherited_figure_not_with_the_model(tmp_path):
    """`rigcad profile show` credits the throw ratio to the base profile's line, and says it did not come with
    the file that names the projector; on the thesis's own profile no line says so. Named with another
    projector, the inherited throw ratio stops the command in one line, no traceback."""
    import subprocess
    import sys

    path = tmp_path / "restated.yaml"
    path.write_text("extends: achutha2006\nprojector:\n  model: benq_pb6210\n", encoding="utf-8")
    restated = rigcad.load(path).profile
    assert re.fullmatch(r"profiles/achutha2006\.yaml:\d+", restated.apart_from_model("projector", "throw_ratio") or "")
    assert restated.apart_from_model("projector", "resolution") is None  # the BenQ's file set it
    out = subprocess.run([sys.executable, "-m", "rigcad", "profile", "show", str(path)], capture_output=True,
                         text=True, check=True).stdout
    line = next(x for x in out.splitlines() if x.strip().startswith("throw_ratio"))
    assert "achutha2006.yaml" in line and "(that file's figure for its own projector, not from projector.model " \
        "benq_pb6210: check it)" in line, line
    own = subprocess.run([sys.executable, "-m", "rigcad", "profile", "show", "achutha2006"], capture_output=True,
                         text=True, check=True).stdout
    assert "not from projector.model" not in own
    epson = tmp_path / "epson.yaml"
    epson.write_text("extends: achutha2006\nprojector:\n  model: epson_eb_w52\n", encoding="utf-8")
    run = subprocess.run([sys.executable, "-m", "rigcad", "profile", "show", str(epson)], capture_output=True, text=True)
    assert run.returncode != 0 and "Traceback" not in run.stderr, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "projector.throw_ratio" in run.stderr, run.stderr
