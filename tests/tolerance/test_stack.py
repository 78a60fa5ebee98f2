"""The tolerance stack of the printed rig (rigcad.fab.stack): a planted worst link on each optical
element is named and refused; a worse printed process makes rigcad refuse naming the links that
dominate; adjusters and locating features enter as data; the tables and records agree."""

from __future__ import annotations

import json
import math

import pytest

from rigcad.errors import FabricationError
from rigcad.fab import stack as S
from rigcad.fab.printers import load_printer


@pytest.fixture(scope="module")
def mk3s():
    return load_printer("prusa_mk3s")


@pytest.fixture(scope="module")
def vantage():
    return load_printer("vantage_i")


def _planted(element: str, axis: str, value: float) -> S.Locator:
    link = S.Link(f"planted on the {element}", "printed", "a link planted by the test", buy="buy: the planted cure",
                  **{axis: value})
    return S.Locator("plant", element, (), link)


@pytest.mark.parametrize("element", S.ELEMENTS)
@pytest.mark.parametrize("axis", S.AXES)
def test_a_planted_worst_link_is_named_and_refused(table31_rig, vantage, element, axis):
    p, lay = table31_rig.profile, table31_rig.layout
    loc, adj = _fixed_rig(p, lay, vantage)  # every element held or adjusted: the planted link alone fails
    base = S.stack(p, lay, vantage, locators=loc, adjusters=adj)
    assert base.ok
    big = 50.0 if axis != "tilt" else math.radians(20)  # past every adjuster's range
    planted = S.stack(p, lay, vantage, locators=loc + (_planted(element, axis, big),), adjusters=adj)
    v = dict(zip(S.AXES, planted.element(element).axes))[axis]
    assert v.status == "refused" and v.dominating[0] == f"planted on the {element}"
    assert v.worst == pytest.approx(dict(zip(S.AXES, base.element(element).axes))[axis].worst + big)
    assert "buy: the planted cure" in v.buy
    with pytest.raises(FabricationError) as err:
        S.refuse(planted)
    assert f"planted on the {element}" in str(err.value) and "\n" not in str(err.value)
    # the other elements do not see it
    for e in S.ELEMENTS:
        if e != element:
            assert planted.element(e).axes == base.element(e).axes


def test_the_stack_sums_its_links_worst_case_and_rss(table31_rig, mk3s):
    r = S.stack(table31_rig.profile, table31_rig.layout, mk3s)
    for e in r.elements:
        for axis, v in zip(S.AXES, e.axes):
            vals = [(getattr(k, axis), k.count) for k in e.links]
            if any(math.isinf(x) for x, _ in vals):
                assert math.isinf(v.worst)
                continue
            assert v.worst == pytest.approx(sum(n * x for x, n in vals), rel=1e-12)
            assert v.rss == pytest.approx(math.sqrt(sum(n * x * x for x, n in vals)), rel=1e-12)


def test_seams_enter_the_tower_chain_at_the_pins_float(table31_rig, mk3s):
    p, lay = table31_rig.profile, table31_rig.layout
    pe, pin = mk3s.process_errors, mk3s.alignment_pin
    none = S.stack(p, lay, mk3s, seams={})
    two = S.stack(p, lay, mk3s, seams={"tower_shelf": 2})
    # a 1.9 mm hole shrinks 0.3 mm below the 1.75 mm pin: drilled to 1.9 mm, so the float is the drawn 0.15 mm
    per_seam = pin.clearance + 2 * pe.position
    for element in ("cop", "splitter", "camera"):
        assert two.element(element).axes[0].worst == pytest.approx(none.element(element).axes[0].worst + 2 * per_seam)
    assert two.element("dome").axes == none.element("dome").axes


def test_the_default_rig_is_refused_and_says_why(table31_rig, mk3s):
    # without the locating features the parts declare (tests/tolerance/test_paraboloid_dome_stack.py has them)
    r = S.stack(table31_rig.profile, table31_rig.layout, mk3s, locators=())
    status = {(v.element, v.axis): v for e in r.elements for v in e.axes}
    # nothing holds the paraboloid along the beam
    assert status["paraboloid", "lateral"].status == "refused"
    assert set(status["paraboloid", "lateral"].dominating) == {"beam along its slots", "clamp along the beam"}
    # the tower's elements are held or adjusted on every axis (tests/tolerance/test_tower_stack.py), but for
    # the splitter plate's play in its grooves with no retainer (tests/tolerance/test_splitter_plate.py)
    assert all(status[e, a].ok for e in ("cop", "splitter", "camera") for a in S.AXES
               if (e, a) not in (("cop", "tilt"), ("splitter", "tilt")))
    assert status["splitter", "tilt"].dominating == S.PLATE_FLOATS
    assert status["camera", "tilt"].status == "held" and status["cop", "vertical"].status == "adjusted"
    with pytest.raises(FabricationError, match=r"paraboloid lateral \(tolerancing.paraboloid_offset\).*beam along"):
        S.refuse(r)


def _fixed_rig(profile, layout, printer):
    """The default rig with what a designer would add: locating features for the paraboloid, the dome
    and the splitter, and adjusters sized at 1.05x the stack on the printer's stated process."""
    tiny = S.Link("located", "joint", "a stated locating feature", 0.02, 0.0, 1e-4)
    loc = (S.Locator("paraboloid locator", "paraboloid", S.PARABOLOID_FLOATS, tiny),
           S.Locator("dome register", "dome", S.DOME_FLOATS, tiny),
           *(S.Locator("kinematic seat", e, S.SEAT_FLOATS, tiny) for e in ("cop", "splitter", "camera")),
           *(S.Locator("plate retainer", e, S.PLATE_FLOATS, tiny) for e in ("cop", "splitter")))
    first = S.stack(profile, layout, printer, locators=loc, adjusters=())
    adj = tuple(S.AdjusterSpec(f"{v.element} {v.axis} adjuster", v.element, v.axis, 1.05 * v.worst,
                               0.2 * v.tolerance) for e in first.elements for v in e.axes)
    return loc, adj


def test_a_worse_process_is_refused_naming_the_dominating_links(table31_rig, vantage):
    p, lay = table31_rig.profile, table31_rig.layout
    loc, adj = _fixed_rig(p, lay, vantage)
    good = S.stack(p, lay, vantage, locators=loc, adjusters=adj)
    assert good.ok, [v.reason for v in good.refused]
    S.refuse(good)  # no error
    worse = S.stack(p, lay, S.with_process(vantage, scale=0.003, hole_shrink_vertical=0.3,
                                           hole_shrink_horizontal=0.3), locators=loc, adjusters=adj)
    assert not worse.ok
    refused = {(v.element, v.axis): v for v in worse.refused}
    # the scale grows the printed spans: the base plate's 195 mm to the tongue, the column's height
    assert ("cop", "lateral") in refused and "base plate" in refused["cop", "lateral"].dominating
    assert ("cop", "vertical") in refused and refused["cop", "vertical"].dominating[0] == "column"
    with pytest.raises(FabricationError) as err:
        S.refuse(worse)
    msg = str(err.value)
    assert "dominated by base plate" in msg and "buy: buy.column: extrusion_40x40" in msg
    assert "short of the stack" in msg


def test_a_bought_column_and_shelf_take_their_links_out(write_profile, table31_text, vantage):
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    rig = Rig.from_profile(load_profile(write_profile(
        table31_text + "buy:\n  column: extrusion_40x40\n  shelf: aluminium_plate\n")))
    r = S.stack(rig.profile, rig.layout, vantage)
    kinds = {k.name: k.kind for k in r.element("cop").links}
    assert kinds["column"] == "bought" and kinds["shelf"] == "bought"


def test_tables_and_records_agree(table31_rig, mk3s):
    r = S.stack(table31_rig.profile, table31_rig.layout, mk3s)
    lines = S.table_lines(r)
    rec = json.loads(json.dumps(S.record(r)))
    assert len(lines) == 2 + sum(len(S.ELEMENT_AXES[e]) for e in S.ELEMENTS)  # the paraboloid's roll: a fourth
    rows = [a for e in rec["elements"] for a in e["axes"]]
    for line, row in zip(lines[2:], rows):
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert cells[1] == row["axis"] and cells[6] == row["status"]
        unit = "deg" if row["axis"] in S.ANGLES else "mm"
        worst = row[f"worst_{unit}"]
        assert cells[2] == ("free" if worst is None else f"{worst:.2f} {unit}")
    assert rec["ok"] is r.ok and rec["process_errors"]["scale_percent"] == pytest.approx(0.2)


def test_a_locator_naming_no_link_is_refused(table31_rig, mk3s):
    bad = S.Locator("register", "dome", ("no such link",), S.Link("x", "joint", ""))
    with pytest.raises(FabricationError, match="no link no such link on the dome's chain"):
        S.stack(table31_rig.profile, table31_rig.layout, mk3s, locators=(bad,))


def test_seams_from_a_fab_record():
    record = {
        "base_plate": {"split": {"pieces": 4}, "datum_seams": [{"between": ["bore", "dowel 1"], "count": 1},
                                                               {"between": ["bore", "dowel 2"], "count": 2}]},
        "tower_shelf": {"split": {"pieces": 4}},  # no datum features declared: conservative n - 1
        "tower_column": {"split": {"pieces": 1}},
        "dome": {"split": {"pieces": 4}},  # its sectors are each bolted down
    }
    assert S.seams_from_fab(record) == {"base_plate": 2, "tower_shelf": 3, "tower_column": 0, "dome": 0}


def test_the_dome_register_the_parts_declare_is_on_the_domes_chain(table31_rig, mk3s):
    from rigcad.parts.locating import DowelRegister

    (reg,) = [j for j in table31_rig.recipes["dome"].joints if isinstance(j, DowelRegister)]
    r = S.stack(table31_rig.profile, table31_rig.layout, mk3s)
    names = [k.name for k in r.element("dome").links]
    assert not set(S.DOME_FLOATS) & set(names)  # the bolts' float is gone: the pins locate
    (link,) = [k for k in r.element("dome").links if k.name.startswith("dome register")]
    # drilled in place through the flange once the dome is indicated in: the round hole's print error is gone
    assert link.lateral == pytest.approx(reg.repeatability[0] + (0.0 if reg.drilled else mk3s.process_errors.position))
    # with no locators given, the bolts' float is back
    bare = S.stack(table31_rig.profile, table31_rig.layout, mk3s, locators=())
    assert set(S.DOME_FLOATS) <= {k.name for k in bare.element("dome").links}
