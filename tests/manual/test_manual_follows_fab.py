"""The manual states fab's tolerance stack, not one of its own: its table is the one fab reckoned with
the seams of its own split plans (rigcad.fab.stage.tolerance_stack), fab's problems open the manual in
a box, and a dome fab could not print is never taken 'as printed (one piece)'."""

from types import SimpleNamespace

import pytest

from rigcad.fab import stack as ST
from rigcad.fab.stage import tolerance_stack
from rigcad.manual import document as D
from rigcad.manual import schedule as S
from rigcad.fab.printers import load_printer
from tests.conftest import ROOT

#: A run whose split plans leave more seams on the base plate's chains than the estimate: four base
#: plate seams (the newcomer's Prusa MINI+ split the plate into many pieces) and a dome fab refused.
SPLIT_RUN = {"base_plate": {"split": {"pieces": 9}, "datum_seams": [{"count": 4}, {"count": 4}]},
             "dome": {"error": "sector plane 45.0 deg, band 2: no room for two 1.75 mm pins; use thinner pins "
                               "(alignment_pin.diameter)"}}


@pytest.fixture(scope="module")
def worse_prusa():
    """The MK3S at three times its position error: the stack is refused on it (tests/fab/test_fab_stack.py)."""
    return ST.with_process(load_printer(ROOT / "profiles" / "printers" / "prusa_mk3s.yaml"), position=0.3)


@pytest.fixture(scope="module")
def fab_report(table31_rig, worse_prusa):
    """fab.json as rigcad fab writes it for SPLIT_RUN: the parts, its stack and its problems."""
    rec, problems = tolerance_stack(table31_rig, worse_prusa, SPLIT_RUN)
    return {"parts": SPLIT_RUN, "stack": rec, "problems": [f"dome: {SPLIT_RUN['dome']['error']}", *problems]}


def _mechanics(rig, printer, report) -> tuple[list[list[str]], dict]:
    """The stack table's rows (as fab.json's Markdown cells) and the record section 5 writes."""
    d = D.Doc()
    c = SimpleNamespace(rig=rig, printer=printer, fab_report=report, p=rig.profile)
    D._section_mechanics(d, c)
    tables = [b for b in d.blocks if b[0] == "table" and b[1][:2] == ["element", "axis"]]
    (table,) = tables
    return table[2], c.mechanics


def test_the_manuals_stack_is_fabs_on_a_printer_where_fab_splits_and_refuses(table31_rig, worse_prusa, fab_report):
    assert not fab_report["stack"]["ok"] and fab_report["stack"]["seams"]["base_plate"] == 4
    rows, mechanics = _mechanics(table31_rig, worse_prusa, fab_report)
    fab_rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in fab_report["stack"]["table_md"][2:]]
    assert rows == fab_rows
    assert mechanics["stack"]["elements"] == fab_report["stack"]["elements"]
    # the stack the manual reckoned on its own (estimated seams) differs here: the test can tell them apart
    own = ST.table_lines(ST.stack(table31_rig.profile, table31_rig.layout, worse_prusa))
    assert own != fab_report["stack"]["table_md"]
    # a report fab wrote without its stack: the manual makes fab's own call on the report's parts
    rows_again, _ = _mechanics(table31_rig, worse_prusa, {k: v for k, v in fab_report.items() if k != "stack"})
    assert rows_again == fab_rows


def test_fabs_problems_open_the_manual_in_a_box_one_item_per_refused_placement(fab_report):
    items = D.fab_problems(fab_report)
    refused = sum(a["status"] == "refused" for e in fab_report["stack"]["elements"] for a in e["axes"])
    assert refused >= 1
    assert len(items) == 1 + refused  # the dome's, then one per refused placement
    assert items[0].startswith("dome: ")
    assert all("tolerancing." in x and "dominated by" in x for x in items[1:])
    d = D.Doc()
    d.box("rigcad fab found problems", items)
    md = d.markdown()
    assert md.startswith("> **rigcad fab found problems**") and md.count("\n> - ") == len(items)
    assert '<div class="box">' in d.html("t", {})


def test_a_dome_fab_refused_is_never_taken_as_printed(table31_rig, fab_report):
    stages = S.schedule(table31_rig, fab_report)
    texts = [s.what for s in stages]
    assert not any("as printed (one piece)" in t for t in texts)
    assert any("not printable on this printer" in t and "alignment_pin.diameter" in t for t in texts)
    S.check(stages)  # the step still makes the dome whole for the stages after it
    whole = S.schedule(table31_rig, {"parts": {}})
    assert any("as printed (one piece)" in s.what for s in whole)  # a printable one-piece dome still is
