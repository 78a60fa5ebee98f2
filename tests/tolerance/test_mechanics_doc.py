"""docs/rig-mechanics.md's stack and loads tables, and the figures its prose draws from them, are
the code's for the default rig on the shipped printers."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from rigcad.fab import loads as L
from rigcad.fab import stack as S
from rigcad.fab.printers import load_printer

PAGE = Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md"


@pytest.fixture(scope="module")
def page() -> str:
    return PAGE.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def mk3s_stack(table31_rig):
    return S.stack(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))


def test_the_stack_table_is_the_codes(page, mk3s_stack):
    lines = S.table_lines(mk3s_stack)
    block = "\n".join(lines)
    assert block in page, ("docs/rig-mechanics.md's stack table is stale; the code's (rigcad.fab.stack.table_lines, "
                           "the default rig on the MK3S) is:\n" + block)
    seams = dict(mk3s_stack.seams)
    assert (f"estimated seams (the base plate {seams['base_plate']}, the column {seams['tower_column']}, "
            f"the shelf {seams['tower_shelf']})") in " ".join(page.split())


def test_the_loads_tables_are_the_codes(page, table31_rig):
    lines = L.loads(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s")).table_lines()
    block = "\n".join(lines)
    assert block in page, ("docs/rig-mechanics.md's loads tables are stale; the code's (rigcad.fab.loads.Loads."
                           "table_lines, the default rig on the MK3S) are:\n" + block)


def test_the_prose_figures_are_the_codes(page, table31_rig, mk3s_stack):
    text = " ".join(page.split())
    vantage = S.stack(table31_rig.profile, table31_rig.layout, load_printer("vantage_i"))
    n_axes = sum(len(e.axes) for e in mk3s_stack.elements)  # five elements' three, and the paraboloid's roll
    assert n_axes == 16
    assert f"refused on {len(mk3s_stack.refused)} of its {n_axes} axes** (on the Vantage i, which prints every part " \
           f"whole, on {len(vantage.refused)})" in text
    assert all(n == 0 for _, n in vantage.seams)
    v = {(x.element, x.axis): x for e in mk3s_stack.elements for x in e.axes}
    assert f"height stack ({v['paraboloid', 'vertical'].worst:.2f} mm)" in text
    assert f"clamp ({v['paraboloid', 'tilt'].worst * 57.29577951308232:.2f} deg)" in text
    assert f"camera's tilt ({v['camera', 'tilt'].worst * 57.29577951308232:.2f} deg)" in text
    seam = next(k for k in mk3s_stack.element("dome").links if k.kind == "seam")
    assert f"({seam.lateral:.2f} mm on the MK3S)" in text and f"seams across the base plate ({seam.lateral:.2f} mm" in text
    bolts = {b.joint: b for b in L.bolt_loads(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))}
    assert (f"would put {bolts['dome flange on the base plate'].hand_tight_mpa:.0f} MPa under the dome flange's large "
            f"washer and {bolts['column foot on the tongue'].hand_tight_mpa:.0f} MPa under the column's, past the "
            f"{L.BEARING_SHARE * L.MATERIALS['pla'].yield_strength:.0f} MPa creep allowance") in text
    assert f"(half of PLA's {L.MATERIALS['pla'].yield_strength:.0f} MPa yield)" in text
    for name, pe in (("prusa_mk3s", "0.2 % | 0.004 in | 0.2 / 0.3 mm | 0.15 mm"),
                     ("vantage_i", "0.2 % | 0.004 in | 0.2 / 0.3 mm | 0.007 in"),
                     ("form3", "0.2 % | 0.1 mm | 0.1 / 0.1 mm | the layer, 0.05 mm")):
        p = load_printer(name).process_errors
        row = re.search(rf"\| `{name}` \| ([^\n]*)", page).group(1)
        assert row.startswith(pe)
        nums = [float(x) for x in re.findall(r"\d+(?:\.\d+)?", pe)]
        inch = 25.4
        pos = nums[1] * (inch if "0.004 in" in pe else 1)
        assert (nums[0] / 100, pos, nums[2], nums[3]) == pytest.approx(
            (p.scale, p.position, p.hole_shrink_vertical, p.hole_shrink_horizontal))


def test_the_tower_figures_are_the_codes(page, table31_rig, mk3s_stack):
    """The datum chain's and the adjusters' tables and the tower's prose figures."""
    from rigcad.parts import tower as T
    from rigcad.parts.adjusters import adjusters
    from rigcad.parts.datum import datum_chain
    from rigcad.parts.washers import bearing_area, plain

    p, lay = table31_rig.profile, table31_rig.layout
    t = lay.tower
    text = " ".join(page.split())
    chain = datum_chain(p, lay)
    rows = [f"{k.lateral:.2f}" if k.lateral >= 0.01 else f"{k.lateral:.3f}" for k in chain.links]
    table = page[page.index("| link | lateral (mm) | vertical (mm) |"):page.index("`check_datum_chain` states")]
    got = [ln.split("|")[2].strip() for ln in table.splitlines()[2:-1] if ln.startswith("| ") and "sum" not in ln]
    assert got == rows
    assert [ln.split("|")[3].strip() for ln in table.splitlines()[2:-1] if "sum" not in ln and ln.startswith("| ")] == [
        f"{k.vertical:.2f}" if k.vertical else "0" for k in chain.links]
    assert f"**{chain.lateral_worst:.2f}** / {chain.lateral_rss:.2f} | **{chain.vertical_worst:.2f}**" in table
    assert f"0.1 mm over {2 * t.column_foot_half:.0f} mm x {t.shelf_top_z - t.shelf_thickness - t.column_base_z:.0f} mm" in table
    # the adjusters' table: range and resolution of each, in the code's order
    adj = page[page.index("| adjuster | serves |"):page.index("* **Splitter tip/tilt**")]
    lines = [ln for ln in adj.splitlines()[2:] if ln.startswith("| ")]
    assert len(lines) == len(adjusters(p, lay))
    for ln, a in zip(lines, adjusters(p, lay)):
        cells = [c.strip() for c in ln.strip("|").split("|")]
        f = math.degrees if a.unit == "rad" else float
        unit = "deg" if a.unit == "rad" else "mm"
        assert cells[1] == a.tolerance_key.split(".")[1] and cells[2] == f"{f(a.tolerance):g} {unit}"
        assert cells[3] == ("-" if a.range == 0 else f"{f(a.range):.2g} {unit}" if a.unit == "rad" else f"{a.range:g} mm")
        assert cells[4] == (f"{f(a.resolution):.2f} {unit}" if a.unit == "rad" else f"{a.resolution:g} mm")
    flat, vee = adjusters(p, lay)[:2]
    pts = T.seat_points(t, p)
    assert f"{pts['cone'][0] - pts['flat'][0]:.0f} mm lever (the axis turns 2x)" in lines[0]
    assert f"(the axis turns {float(vee.how.split('turns ')[1].split(' x')[0]):.2f}x)" in lines[1]
    assert f"0.5 mm pitch, doubled, within a quarter of 0.5 deg: {T.flat_lever(p):.0f} mm, taken {T.FLAT_LEVER_MARGIN:g} times" in text
    fine = T.fine_shims(p)
    assert (", ".join(f"{v:g}" for v in fine[:-1]) + f" and {fine[-1]:g} mm") in text
    assert f"every multiple of {min(fine):g} mm up to {sum(fine):g} mm" in text
    w = T.joint_washers(p, lay)
    slot = T.slot_openings(p, lay)["projector"]
    assert (f"the projector's {slot[1]:g} x {slot[2]:g} mm slots take an M4 large washer on an M5 one "
            f"({w['projector'].area_mm2:.0f} mm2, where a plain washer would bear "
            f"{bearing_area(plain('M4'), slot):.0f} mm2)") in text
    assert f"{T.slot_openings(p, lay)['camera'][1]:.1f} mm wide slot an M6 on an M10 ({w['camera'].area_mm2:.0f} mm2)" in text
    assert f"opened to {T.column_bolt_hole(t, p):.1f} mm" in text
    assert f"`tower.travel_across` {p.tower.travel_across:g} mm, `travel_along` {p.tower.travel_along:g} mm" in text
    # the stack's prose
    v = {(x.element, x.axis): x for e in mk3s_stack.elements for x in e.axes}
    assert f"already covers the stack with the printed pins ({v['cop', 'lateral'].worst:.2f} mm worst case)" in text
    assert f"camera's tilt ({math.degrees(v['camera', 'tilt'].worst):.2f} deg) is held" in text
    assert f"0.11 deg per eighth of a turn at most" in text and math.degrees(flat.resolution) < 0.115
    dowel = S.seam_link("base_plate", 1, load_printer("prusa_mk3s"), load_printer("prusa_mk3s").process_errors,
                        dowels=True)
    assert f"dowel's fit ({dowel.lateral:.2f} mm on the MK3S)" in text
    lean = math.degrees(2 * T.LAPPED_FLATNESS / p.tower.column_width)
    assert f"twice that over the {p.tower.column_width:g} mm tube ({lean:.2f} deg)" in text
    assert f"lapped flat to {T.LAPPED_FLATNESS:g} mm" in text
    assert f"unlapped ({p.datum.foot_flatness:g} mm) they would lean the column " \
           f"{math.degrees(2 * p.datum.foot_flatness / p.tower.column_width):.2f} deg" in text


def test_the_seat_pockets_prose_is_the_codes(page, table31):
    """The seat pockets' sizes and fits the page states, from rigcad.parts.tower.seat_pocket_fits."""
    from rigcad.parts import tower as T

    text = " ".join(page.split())
    fits = {f["pocket"]: f for f in T.seat_pocket_fits(table31, load_printer("prusa_mk3s").process_errors)}
    form3 = {f["pocket"]: f for f in T.seat_pocket_fits(table31, load_printer("form3").process_errors)}
    vee = fits["vee"]["hardware_mm"]
    flat = fits["flat"]["hardware_mm"]
    assert f"balls touching: {fits['cone']['hardware_mm'][0]:.2f} mm)" in text
    assert f"(two 3 mm pins: {vee[0]:g} x {vee[1]:g} mm)" in text and f"face) are drawn" in text
    assert f"gauge block's {flat[0]:g} x {flat[1]:g} mm face" in text
    assert f"drawn {T.SEAT_POCKET_SHRINK + T.SEAT_POCKET_CLEARANCE:g} mm over their hardware" in text
    assert f"(`SEAT_POCKET_SHRINK` {T.SEAT_POCKET_SHRINK:g} mm" in text
    assert f"(`SEAT_POCKET_CLEARANCE` {T.SEAT_POCKET_CLEARANCE:g} mm)" in text
    assert len({round(f["gap_mm"], 9) for f in fits.values()}) == 1 and len({round(f["gap_mm"], 9) for f in form3.values()}) == 1
    assert (f"prints {fits['cone']['gap_mm']:.1f} mm over its hardware on the MK3S and the Vantage i, "
            f"{form3['cone']['gap_mm']:.1f} mm on the Form 3") in text
    assert f"within the {T.SEAT_BOND[1]:g} mm the gap-filling epoxy fills" in text
    assert f"half the gap its cone's balls are bonded in ({fits['cone']['gap_mm'] / 2:.1f} mm on the MK3S" in text


def test_the_loads_prose_is_the_codes(page, table31_rig):
    """The bolts', flanges', thermal and shelf-option figures the Loads section's prose states."""
    from rigcad.parts import tower as T

    p, lay = table31_rig.profile, table31_rig.layout
    text = " ".join(page.split())
    mk3s = load_printer("prusa_mk3s")
    foot = T.column_foot_bolt(p, lay.tower)
    assert (f"the column foot's M4 bolts are {foot['length_mm']:g} mm long, end {foot['above_bench_mm']:.1f} mm above "
            f"the bench, and their nut traps are {foot['trap_depth_mm']:g} mm deep") in text
    assert (f"Four M4 x {foot['length_mm']:g} bolts hold it (their nuts in hexagonal traps, {T.NUT_TRAP:.1f} mm across "
            f"flats and {foot['trap_depth_mm']:g} mm deep") in text
    assert f"held by four M4 x {T.shelf_bolt_length(p):g} bolts up from under the flange" in text
    r = L.loads(p, lay, mk3s)
    opts = {o["option"]: o for o in r.shelf_options}
    shelf, column = r.deflections[1], r.deflections[2]
    assert f"its static tilt takes {100 * shelf.share:.0f} % of `tolerancing.projector_tilt`" in text
    assert (f"its bending stress is {opts['print']['stress_mpa']:.2f} MPa, "
            f"{100 * opts['print']['stress_mpa'] / L.MATERIALS['pla'].yield_strength:.1f} % of PLA's yield") in text
    assert f"the static tilt again: {100 * shelf.share:.0f} % of the tolerance" in text and shelf.share < 1
    assert f"Its first mode, {shelf.first_mode_hz:.0f} Hz, is above the column's {column.first_mode_hz:.0f} Hz sway" in text
    assert shelf.first_mode_hz > column.first_mode_hz
    al = opts["aluminium_plate"]
    assert f"it would take {100 * al['share']:.0f} % and ring at {al['first_mode_hz']:.0f} Hz" in text
    assert f"({al['thermal_across_mm']:.3f} mm across for +-3 K)" in text
    assert (f"with the preload {r.flanges[0].margin:.0f} times the most loaded bolt's pull (foot) and "
            f"{r.flanges[1].margin:.0f} times at the top") in text
    assert f"PLA {L.MATERIALS['pla'].expansion * 1e6:.0f}e-6 /K, Stratasys's data sheet" in text


def test_the_tilt_adjusters_prose_is_the_codes(page, table31_rig, mk3s_stack):
    """The camera's and the projector's tilt adjusters as the page states them."""
    from rigcad.parts import adjusters as A

    p, lay = table31_rig.profile, table31_rig.layout
    text = " ".join(page.split())
    cam, pj = A.camera_tilt(p, lay), A.projector_tilt(p, lay)
    v = {(x.element, x.axis): x for e in mk3s_stack.elements for x in e.axes}
    assert (f"in that plane: {math.degrees(cam.range):.1f} deg each way in steps of {math.degrees(cam.resolution):.2f} "
            f"deg, against the camera's {math.degrees(v['camera', 'tilt'].worst):.2f} deg stack") in text
    xs = sorted({round(x, 9) for x, _ in lay.tower.projector_feet})
    assert f"against its far feet ({xs[-1] - xs[0]:.0f} mm apart)" in text
    assert (f"take that back: {math.degrees(pj.range):.0f} deg each way in steps of "
            f"{math.degrees(pj.resolution):.2f} deg") in text
    assert v["camera", "tilt"].adjuster.name == cam.name
