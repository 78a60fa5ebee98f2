"""Compression limiters in the bolted joints on a datum chain (rigcad.parts.joints.ScrewJoint.limiter,
rigcad.standards.COMPRESSION_LIMITERS): a datum joint without its limiter is refused; the grip, the
bolt's length and the hole run through the sleeve; the bill's sleeves are summed from the joints;
the squeeze the sleeve leaves on the plastic stays under PLA's creep limit."""

from __future__ import annotations

import types

import pytest

from rigcad.errors import GeometryError
from rigcad.fab import loads
from rigcad.manual import bom
from rigcad.parts.joints import LIMITER_SQUEEZE_MM, ScrewJoint
from rigcad.standards import COMPRESSION_LIMITERS, INSERTS, THREADS

#: A joint like the dome's flange: 6 mm of printed flange on a 10 mm plate, one M4 screw into an insert.
KW = dict(points=((0.0, 0.0),), upper_z=(0.0, 6.0), lower_z=(-10.0, 0.0))


def test_a_datum_joint_without_its_limiter_is_refused_naming_the_joint():
    with pytest.raises(GeometryError, match="joint flange: it locates a datum, so its bolts need compression limiters"):
        ScrewJoint("flange", "dome", "base_plate", "M4", **KW, datum=True)
    ok = ScrewJoint("flange", "dome", "base_plate", "M4", **KW, datum=True, limiter=True)
    assert ok.limiter_part is COMPRESSION_LIMITERS["M4"]


def test_every_limiter_passes_its_bolt_and_bears_on_its_insert_not_on_plastic():
    for thread, lim in COMPRESSION_LIMITERS.items():
        # the bolt passes at ISO 273's fine clearance at least
        assert lim.bore >= THREADS[thread].clearance_fine - 1e-9, thread
        # the sleeve's end overlaps the insert's top (bore under its knurl's outside): metal on metal
        assert lim.bore < INSERTS[thread].outer, thread
        # and it is a sleeve, not a rod: its wall stands between bore and outside
        assert 0 < lim.wall < lim.outer / 2, thread


def test_the_grip_the_length_and_the_hole_run_through_the_limiter():
    plain = ScrewJoint("j", "dome", "base_plate", "M4", **KW)
    sleeved = ScrewJoint("j", "dome", "base_plate", "M4", **KW, limiter=True)
    # the head bears on its washer on the sleeve, which is the flange's span less the squeeze
    assert sleeved.limiter_length == pytest.approx(6.0 - LIMITER_SQUEEZE_MM, abs=1e-12)
    assert sleeved.grip == pytest.approx(THREADS["M4"].washer_thickness + sleeved.limiter_length, abs=1e-12)
    # the screw is the longest that ends in the insert past that grip, by at least a diameter
    assert sleeved.length == 12 and sleeved.engagement == pytest.approx(12 - sleeved.grip, abs=1e-12)
    assert sleeved.engagement >= THREADS["M4"].major
    # the hole is wider by the sleeve's walls: the sleeve keeps the bolt's room around it
    (h0,), (h1,) = plain.clearance_holes(), sleeved.clearance_holes()
    lim = COMPRESSION_LIMITERS["M4"]
    assert 2 * h1.radius - 2 * h0.radius == pytest.approx(lim.outer - THREADS["M4"].major, abs=1e-12)
    assert 2 * h1.radius - lim.outer == pytest.approx(THREADS["M4"].clearance - THREADS["M4"].major, abs=1e-12)
    # an opened hole (7.97 mm, the dome's) keeps its opening around the sleeve too
    (h2,) = sleeved.clearance_holes(7.97)
    assert 2 * h2.radius == pytest.approx(7.97 + lim.outer - THREADS["M4"].major, abs=1e-12)
    # the bill's item and the shop step name the sleeve and its length
    assert "compression limiter (6 x 0.8 mm sleeve, 5.98 mm long)" in sleeved.item
    assert "5.98 mm as drawn" in sleeved.limiter_step() and plain.limiter_step() == ""
    # the length is chosen on the grip through the sleeve: on a 7.11 mm flange the plain joint reaches
    # 0.8 + 7.11 + 8.1 = 16.01 mm (M4 x 16), the sleeved one 15.99 mm, so M4 x 16 would bottom in the insert
    # and M4 x 12 is chosen, 4.11 mm in it
    kw = dict(points=((0.0, 0.0),), upper_z=(0.0, 7.11), lower_z=(-10.0, 0.0))
    assert ScrewJoint("j", "dome", "base_plate", "M4", **kw).length == 16
    thick = ScrewJoint("j", "dome", "base_plate", "M4", **kw, limiter=True)
    assert thick.length == 12 and thick.engagement == pytest.approx(12 - 0.8 - 7.09, abs=1e-9)

def test_a_too_thin_part_or_an_unknown_thread_is_refused():
    with pytest.raises(GeometryError, match="too thin for a compression limiter"):
        ScrewJoint("j", "dome", "base_plate", "M4", points=((0.0, 0.0),), upper_z=(0.0, 0.01),
                   lower_z=(-10.0, 0.0), limiter=True)
    with pytest.raises(GeometryError, match="no compression limiter for M2"):
        ScrewJoint("j", "dome", "base_plate", "M2", **KW, into="nut", limiter=True)


def test_the_bills_sleeves_are_summed_from_the_joints(monkeypatch):
    a = ScrewJoint("flange", "dome", "base_plate", "M4", points=tuple((float(k), 0.0) for k in range(8)),
                   upper_z=(0.0, 6.0), lower_z=(-10.0, 0.0), datum=True, limiter=True)
    b = ScrewJoint("foot", "tower_column", "base_plate", "M4", points=tuple((0.0, float(k)) for k in range(4)),
                   upper_z=(0.0, 6.0), lower_z=(-10.0, 0.0), datum=True, limiter=True)
    c = ScrewJoint("lens", "lens_mount", "tower_shelf", "M4", **KW)  # no limiter: not counted
    rig = types.SimpleNamespace(layout=types.SimpleNamespace(), recipes={"dome": types.SimpleNamespace(joints=(a, c)),
                                         "tower_column": types.SimpleNamespace(joints=(b,))})
    lines = bom.limiter_lines(rig)
    assert sum(lines.values()) == 12 and len(lines) == 2  # two lines: each names its part and faced length
    assert all(k.startswith("M4 compression limiter: steel sleeve 6 x 0.8 mm") for k in lines)
    # the bill's washer and nut lines carry them (plan.bill_hardware reads washer_nut_lines)
    monkeypatch.setattr(bom, "bolt_stacks", lambda rig: [])
    assert bom.washer_nut_lines(rig) == lines


def test_the_squeeze_stays_under_plas_creep_limit_on_a_five_mm_part():
    pla = loads.MATERIALS["pla"]
    allow = loads.BEARING_SHARE * pla.yield_strength  # the creep limit the torque table keeps to (13 MPa)
    # the thinnest part on a datum chain: the printed column's 5 mm flange (tower.wall); stiffest modulus
    stress = pla.modulus_high * LIMITER_SQUEEZE_MM / 5.0
    assert stress <= allow, f"{stress:.1f} MPa squeeze stress against {allow:.1f} MPa"


# -- the printed column's joints (rigcad.parts.tower): on the datum chain, so limited at both ends -----------

def _cuts(solid) -> list:
    """Every Cylinder the recipe cuts from its top-level Difference (holes: the joints', the dowels')."""
    from rigcad.parts.recipe import Cylinder, Difference

    return [c for c in solid.cuts if isinstance(c, Cylinder)] if isinstance(solid, Difference) else []


def _hole_at(solid, x: float, y: float) -> float:
    """The diameter (mm) of the cut cylinder whose axis stands at (x, y), read from the part's recipe."""
    hits = [2 * c.radius for c in _cuts(solid) if abs(c.base[0] - x) < 1e-9 and abs(c.base[1] - y) < 1e-9]
    assert len(hits) == 1, (x, y, hits)
    return hits[0]


def test_the_columns_datum_joints_have_limiters_through_holes_sized_for_them(table31_rig):
    from rigcad.parts import tower as T
    from rigcad.parts.locating import bolt_hole

    p, t = table31_rig.profile, table31_rig.layout.tower
    lim = T.COLUMN_LIMITER
    pts = T._column_flange_points(t, p)
    far = max(abs(complex(*T.column_dowel_points(t, p)[0]) - complex(*q)) for q in pts)
    opened = bolt_hole("M4", far, p.datum.print_position, p.datum.print_scale)
    for x, y in pts:
        # the column's flanges: the opened hole, wider by the sleeve's walls (the sleeve keeps the bolt's room)
        tongue = _hole_at(table31_rig.recipes["base_plate"].solid, x, y)
        # the tongue passes the foot's sleeve down to the nut: the bolt's hole plus the walls
        assert tongue == pytest.approx(p.tower.bolt_diameter + lim.outer - THREADS["M4"].major, abs=1e-12)
        assert tongue > lim.outer  # the sleeve passes it
    holes = [2 * c.radius for c in _cuts(table31_rig.recipes["tower_column"].solid)
             if any(abs(c.base[0] - x) < 1e-9 and abs(c.base[1] - y) < 1e-9 for x, y in pts)]
    assert len(holes) == 8  # four bolts at each flange
    for h in holes:
        assert h == pytest.approx(opened + lim.outer - THREADS["M4"].major, abs=1e-12) and h > lim.outer


def test_the_foots_sleeve_runs_from_the_head_to_the_nut_and_the_bolts_count_it(table31_rig):
    from rigcad.parts import tower as T
    from rigcad.parts.washers import washers_over

    p, t = table31_rig.profile, table31_rig.layout.tower
    foot = T.column_foot_bolt(p, t)
    # from the nut's top face (the trap's roof, trap_depth over the bench) to the foot's top face, less the squeeze
    assert foot["limiter_mm"] == pytest.approx(p.tower.wall - t.bench_z - foot["trap_depth_mm"] - LIMITER_SQUEEZE_MM,
                                               abs=1e-9)
    # the bolt's grip is its washers and the sleeve; it stands a thread out of its nut
    assert foot["grip_mm"] == pytest.approx(foot["washers_mm"] + foot["limiter_mm"], abs=1e-9)
    assert foot["proud_mm"] >= THREADS["M4"].pitch - 1e-9
    # the top: washers, the 5 mm flange squeezed to its sleeve, into the shelf's insert, short of its end
    stack = washers_over("M4", ("round", T.column_bolt_hole(t, p))).thickness + T.spring_washer("M4")[1]
    reach = stack + T.shelf_limiter_length(p) + INSERTS["M4"].length - 0.5
    assert T.shelf_limiter_length(p) == pytest.approx(p.tower.wall - LIMITER_SQUEEZE_MM, abs=1e-12)
    length = T.shelf_bolt_length(p)
    assert length <= reach and length - stack - T.shelf_limiter_length(p) >= THREADS["M4"].major


def test_every_datum_row_of_the_tower_has_its_limiters_and_the_bill_counts_them(table31_rig):
    from rigcad.parts import tower as T

    rows = [h for h in T.hardware(table31_rig.profile, table31_rig.layout) if h.get("spring_washer")]
    # the tower marks its datum joints by their spring washers (the loads table's rule): the column's two
    assert len(rows) == 2 and all(h.get("limiter") == T.COLUMN_LIMITER.name() for h in rows), rows
    assert all("compression limiter" in h["joins"] and "face each to" in h["joins"] for h in rows)
    lines = bom.limiter_lines(table31_rig)
    # the column's 8 and the dome flange's (its ScrewJoint, tests/parts/test_dome_limiters.py)
    flange = sum(j.count for part in table31_rig.recipes.values() for j in part.joints
                 if isinstance(j, ScrewJoint) and j.limiter)
    assert flange == 8 and sum(lines.values()) == sum(h["quantity"] for h in rows) + flange == 16
    for h in rows:  # each row's sleeves, at its faced length, in the bill
        assert any(f"faced to {h['limiter_mm']:.2f} mm" in k and v == h["quantity"] for k, v in lines.items())


def test_the_mechanics_page_states_the_limiters_as_the_code_has_them(table31_rig):
    from pathlib import Path

    from rigcad.parts import tower as T

    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md").read_text().split())
    p, t = table31_rig.profile, table31_rig.layout.tower
    lim = T.COLUMN_LIMITER
    pla = loads.MATERIALS["pla"]
    assert f"{lim.outer:g} x {lim.wall:g} mm for M4" in text
    assert f"creep allowance ({loads.BEARING_SHARE * pla.yield_strength:.0f} MPa)" in text
    assert f"a {LIMITER_SQUEEZE_MM:g} mm squeeze" in text
    assert f"{pla.modulus_high * LIMITER_SQUEEZE_MM / p.tower.wall:.0f} MPa at PLA's stiffest modulus on a {p.tower.wall:g} mm part" in text
    assert f"at its foot a {T.column_foot_bolt(p, t)['limiter_mm']:.2f} mm sleeve" in text
    assert f"at its top a {T.shelf_limiter_length(p):.2f} mm sleeve" in text
