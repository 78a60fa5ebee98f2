"""docs/rig-mechanics.md's stack and loads tables, and the figures its prose draws from them, are
the code's for the default rig on the shipped printers."""

from __future__ import annotations

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
    assert f"refused on {len(mk3s_stack.refused)} of its 15 axes** (on the Vantage i, which prints every part " \
           f"whole, on {len(vantage.refused)})" in text
    assert all(n == 0 for _, n in vantage.seams)
    v = {(x.element, x.axis): x for e in mk3s_stack.elements for x in e.axes}
    assert f"height stack ({v['paraboloid', 'vertical'].worst:.2f} mm)" in text
    assert f"clamp ({v['paraboloid', 'tilt'].worst * 57.29577951308232:.2f} deg)" in text
    assert f"camera's tilt ({v['camera', 'tilt'].worst * 57.29577951308232:.2f} deg)" in text
    seam = next(k for k in mk3s_stack.element("dome").links if k.kind == "seam")
    assert f"({seam.lateral:.2f} mm on the MK3S)" in text and f"seams across the base plate ({seam.lateral:.2f} mm" in text
    bolts = {b.joint: b for b in L.bolt_loads(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))}
    assert (f"would put {bolts['dome flange on the base plate'].hand_tight_mpa:.0f} MPa under a washer and "
            f"{bolts['column foot on the tongue'].hand_tight_mpa:.0f} MPa under the tongue's nut") in text
    assert f"past PLA's {L.MATERIALS['pla'].yield_strength:.0f} MPa yield" in text
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
