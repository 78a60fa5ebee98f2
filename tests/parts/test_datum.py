"""The datum chain from the base plate to the splitter: its sum against a hand computation, and its
checks against the tolerances and the adjusters' travel."""

import math

import pytest

from rigcad.parts.datum import DOWEL_FIT, check_datum_chain, datum_chain
from rigcad.parts.tower import column_dowel_points
from rigcad.profile import load_profile
from rigcad.rig import Rig


def test_the_chain_adds_its_links_as_stated(table31_rig):
    p, t = table31_rig.profile, table31_rig.layout.tower
    chain = datum_chain(p, table31_rig.layout)
    d = p.datum
    # hand computation of the default (printed) chain, link by link, from the module's docstring
    height = t.shelf_top_z - t.shelf_thickness - t.column_base_z
    # each column joint: the pins' fit, and the slot's 0.05 mm fit over the pins' spacing turning the
    # column, which swings the optical axis (column_x away) sideways
    (ax, _), (bx, _) = column_dowel_points(t, p)
    dowels = DOWEL_FIT + 0.05 / abs(bx - ax) * t.column_x
    expect = [
        d.print_position + d.print_scale * t.column_x,  # bore to tongue dowels
        dowels,
        d.print_position + d.foot_flatness / (2 * t.column_foot_half) * height,  # column: pattern and lean
        dowels,
        d.print_position + d.print_scale * (t.column_x - t.holder_x[1]),  # shelf
        d.print_position + d.print_scale * (t.holder_top_z - t.shelf_top_z),  # holder
    ]
    assert [k.lateral for k in chain.links] == pytest.approx(expect, rel=1e-12)
    assert chain.lateral_worst == pytest.approx(sum(expect), rel=1e-12)
    assert chain.lateral_rss == pytest.approx(math.sqrt(sum(e * e for e in expect)), rel=1e-12)


def test_the_default_chain_needs_the_adjusters_and_they_reach(table31_rig):
    rows = {r["claim"]: r for r in check_datum_chain(table31_rig.profile, table31_rig.layout)}
    # a printed chain (0.2 % over ~200 mm spans) cannot hold 0.5 mm alone: the adjusters must take it up
    assert rows["needs_adjustment"]["adjust"]
    assert rows["lateral_within_travel"]["ok"] and rows["vertical_within_travel"]["ok"]


def test_a_poor_printer_breaks_the_chain(write_profile, table31_text):
    # 3 % scale error (an uncalibrated printer): ~6 mm on the base plate alone, beyond the 6 mm travel
    rig = Rig.from_profile(load_profile(write_profile(table31_text + "datum:\n  print_scale: 0.03\n")))
    rows = {r["claim"]: r for r in check_datum_chain(rig.profile, rig.layout)}
    assert not rows["lateral_within_travel"]["ok"]


def test_a_bought_extrusion_and_plate_change_the_chain(write_profile, table31_text):
    # the extrusion leans by its end squareness (0.1 mm over 40 mm) times its height; the plate's holes
    # are drilled through a template (0.05 mm) instead of printed over ~170 mm
    from rigcad.parts.datum import EXTRUSION_END_SQUARENESS, PLATE_HOLE_POSITION
    from rigcad.parts.tower import POCKET_GAP

    rig = Rig.from_profile(load_profile(write_profile(
        table31_text + "buy:\n  column: extrusion_40x40\n  shelf: aluminium_plate\n")))
    t = rig.layout.tower
    links = {k.name: k for k in datum_chain(rig.profile, rig.layout).links}
    height = t.shelf_top_z - t.shelf_thickness - t.column_base_z
    assert links["column"].lateral == pytest.approx(EXTRUSION_END_SQUARENESS / 40.0 * height, rel=1e-12)
    assert links["pocket, tongue to column"].lateral == POCKET_GAP
    assert links["shelf"].lateral == PLATE_HOLE_POSITION


def test_the_tongue_stands_on_the_bench_with_nut_traps(table31_rig):
    # the tower's weight goes into the bench: the tongue's underside is the bench level, and an M4 nut
    # (ISO 4032: a hexagon 7 mm across flats) fits each trap under a column bolt, 0.2 mm clear each flat
    import manifold3d as m3d

    from rigcad.export import mesh as M
    from rigcad.parts.recipe import HexPrism
    from rigcad.parts.tower import NUT_TRAP_TURN, _column_flange_points, nut_trap_depth

    t = table31_rig.layout.tower
    plate = M.build(table31_rig.recipe("base_plate").solid, 0.05)
    assert plate.bounding_box()[2] == pytest.approx(t.bench_z, abs=1e-9)
    for x, y in _column_flange_points(t, table31_rig.profile):
        nut = M.build(HexPrism((x, y, t.bench_z + 0.01), 7.0, nut_trap_depth(table31_rig.profile, t) - 0.02,
                               NUT_TRAP_TURN), 0.05)
        assert (plate ^ nut).volume() < 1e-9
        assert (plate ^ nut).status() == m3d.Error.NoError


def test_the_plate_has_the_calibration_parts_turn_mark_beside_the_collar(table31_rig):
    """The groove under the disc (rigcad.parts.base.azimuth_groove) that the calibration parts'
    notches turn to: open from below along +x (the tongue's side), just outside the holder's stop
    collar where a technician under the lifted rig sees both, and no deeper into the disc than
    stated (manifold3d's volume of the plate against a box where the groove runs)."""
    from rigcad.export import mesh as M
    from rigcad.parts.base import GROOVE_DEPTH_MM, GROOVE_GAP_MM, GROOVE_LENGTH_MM, GROOVE_WIDTH_MM
    from rigcad.parts.recipe import Box

    p = table31_rig.profile
    t, r0 = p.base_plate.thickness, p.sample_holder.stop_radius + GROOVE_GAP_MM
    plate = M.build(table31_rig.recipe("base_plate").solid, 0.05)

    def solid(lo, hi) -> float:
        return (plate ^ M.build(Box(lo, hi), 0.05)).volume()

    w, d, L = GROOVE_WIDTH_MM / 2, GROOVE_DEPTH_MM, GROOVE_LENGTH_MM
    assert solid((r0 + 0.01, -w + 0.01, -t - 0.5), (r0 + L - 0.01, w - 0.01, -t + d - 0.01)) < 1e-9  # the groove
    assert solid((r0, -w, -t + d), (r0 + L, w, -t + d + 0.5)) == pytest.approx(2 * w * L * 0.5, rel=1e-9)  # its roof
    beside = solid((r0, w, -t), (r0 + L, w + 1.0, -t + d))  # the disc on either side
    assert beside == pytest.approx(L * d, rel=1e-9)
    assert solid((-r0 - L, -w, -t), (-r0, w, -t + d)) == pytest.approx(2 * w * L * d, rel=1e-9)  # no mark at -x


def test_the_bill_orders_the_column_dowels_each_register_is_drilled_for(table31_rig):
    """The tower's dowel rows carry each end's register's own pin length (the register sizes its
    blind holes from it): a pin ordered shorter or longer than its hole is drilled for would stand
    short of the column's flange or bottom out before it is home."""
    from rigcad.parts.tower import column_register, hardware

    p, t = table31_rig.profile, table31_rig.layout.tower
    foot = column_register(t, p, t.column_base_z, p.tower.wall, "foot")
    top = column_register(t, p, t.shelf_top_z - t.shelf_thickness - p.tower.wall, p.tower.wall, "top")
    rows = [h for h in hardware(p, table31_rig.layout)
            if h["item"] == "dowel pin, ISO 8734 m6" and h.get("diameter_mm") == p.datum.dowel_diameter]
    ordered = sorted(length for h in rows for length in [h["length_mm"]] * h["quantity"])
    assert ordered == sorted([foot.length] * 2 + [top.length] * 2)
    assert foot.length != top.length  # the default rig's ends differ (16 and 12 mm): one row each
