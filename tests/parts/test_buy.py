"""Buy or print: a bought column and shelf are standard stock, drawn in the rig, listed with their
stock, valid solids that do not cut into their neighbours, and never printed."""

import pytest

from rigcad.parts import _kernel as K
from rigcad.profile import load_profile
from rigcad.rig import Rig

#: Contacts share faces only (see test_tower.CONTACT_MM3).
CONTACT_MM3 = 1e-6


@pytest.fixture(scope="module")
def bought(tmp_path_factory, table31_text):
    path = tmp_path_factory.mktemp("buy") / "b.yaml"
    path.write_text(table31_text + "buy:\n  column: extrusion_40x40\n  shelf: aluminium_plate\n")
    return Rig.from_profile(load_profile(path))


def _solid(part):
    return K.part_solid(part, 1e-4, K.FitReport())


def test_bought_parts_carry_their_stock_and_printed_ones_none(bought, table31_rig):
    assert "extrusion 40 x 40 mm" in bought.recipe("tower_column").bought
    assert "EN AW-5083" in bought.recipe("tower_shelf").bought
    assert not bought.recipe("base_plate").bought and not table31_rig.recipe("tower_column").bought
    # the extrusion spans from the tongue's pocket to the shelf's: 1.5 mm into each
    t = bought.layout.tower
    lo, hi = bought.recipe("tower_column").solid.lo, bought.recipe("tower_column").solid.hi
    assert hi[0] - lo[0] == 40.0 and lo[2] == t.column_base_z - 1.5
    assert hi[2] == pytest.approx(t.shelf_top_z - t.shelf_thickness + 1.5)


def test_the_extrusion_sits_in_its_pockets_without_overlap(bought):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    shapes = {n: _solid(bought.recipe(n)) for n in ("tower_column", "tower_shelf", "base_plate")}
    for other in ("tower_shelf", "base_plate"):
        assert K.volume(BRepAlgoAPI_Common(shapes["tower_column"], shapes[other]).Shape()) < CONTACT_MM3


def test_the_hardware_follows_the_choice(bought, table31_rig):
    from rigcad.parts.tower import hardware

    b = hardware(bought.profile, bought.layout)
    p = hardware(table31_rig.profile, table31_rig.layout)
    def column_dowels(rows):  # the splitter seat's vee is two dowel pins too: only the column's count here
        return any("dowel" in i["item"] and "column" in i["joins"] for i in rows)

    assert any(i["thread"] == "M8" for i in b) and not column_dowels(b)
    assert not any(i["thread"] == "M8" for i in p) and column_dowels(p)


def test_fab_prints_nothing_of_a_bought_part(bought, tmp_path):
    from rigcad.fab.printers import load_printer
    from rigcad.fab.stage import run_fab

    report = run_fab(bought, load_printer("prusa_mk3s"), tmp_path / "fab", parts=["tower_column"]).report
    entry = report["parts"]["tower_column"]
    assert entry["process"] == "bought" and "extrusion" in entry["stock"]
    assert report["totals"]["pieces"] == 0
    assert not list((tmp_path / "fab").glob("stl/*.stl"))
