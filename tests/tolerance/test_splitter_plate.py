"""The splitter plate in its grooves (rigcad.parts.tower.plate_play, PLATE_RETAINER; rigcad.fab.stack):
left loose it turns across the grooves' play and its reflected axis twice as far, a float no adjuster
holds, so the splitter's and the COP's tilt are refused; the retainer the holder declares (RTV dots cured
with the plate on its datum flank) takes the play out, with its purchase in the bill and its shop step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.errors import FabricationError
from rigcad.fab import stack as S
from rigcad.parts import tower as T


def _axes(report):
    return {(v.element, v.axis): v for e in report.elements for v in e.axes}


def test_the_play_is_the_grooves_as_cut(table31_rig):
    lay = table31_rig.layout
    p = lay.tower.plate
    # the groove's section as the holder cuts it (x-z corners: front -a, front +a, back +a, back -a)
    # its section is the same whatever its reach along y
    lines = T._groove(lay.tower, lay.tower.wall_y[1] + 1.0).solid.section.segments
    pts = np.array([ln.p0 for ln in lines])
    width = float(np.linalg.norm(pts[2] - pts[1]))  # front face to back face, across the plate
    length = float(np.linalg.norm(pts[1] - pts[0]))
    play, along = T.plate_play(table31_rig.profile, lay)
    # the review measured 1.50 mm between the flanks for the 1.1 mm plate, 50.4 mm long (splitter_holder.step)
    assert width == pytest.approx(1.50, abs=1e-9) and length == pytest.approx(50.4, abs=1e-9)
    assert play == pytest.approx(width - p.thickness, abs=1e-12) and along == pytest.approx(length, abs=1e-12)
    # by hand: atan(0.4 / 50.4) = 0.4547 deg, the review's "up to 0.46 deg"
    assert math.degrees(T.plate_float_tilt(table31_rig.profile, lay)) == pytest.approx(0.45470, abs=1e-4)


def test_unretained_the_plate_float_is_refused_whatever_the_adjusters(table31_rig, mk3s):
    p, lay = table31_rig.profile, table31_rig.layout
    declared = S.declared_locators(p, lay, mk3s.process_errors)
    loose = tuple(x for x in declared if x.name != "splitter plate retainer")
    assert len(loose) == len(declared) - 2  # the retainer is declared on the splitter's and the COP's chains
    v = _axes(S.stack(p, lay, mk3s, locators=loose))
    for e in ("splitter", "cop"):
        t = v[e, "tilt"]
        assert t.status == "refused" and t.dominating == S.PLATE_FLOATS, (e, t.reason)
        assert "after any setting" in t.reason and "retainer" in t.buy[0]
    # the reflected axis turns twice the plate's 0.455 deg: 0.909 deg against the 0.5 deg tolerance
    (link,) = [k for k in S.stack(p, lay, mk3s, locators=loose).element("splitter").links if k.name in S.PLATE_FLOATS]
    assert math.degrees(link.tilt) == pytest.approx(2 * 0.45470, abs=2e-4)
    # an adjuster of any range and resolution does not take a float out: it moves after the setting
    huge = (S.AdjusterSpec("planted tip-tilt", "splitter", "tilt", math.radians(20), 1e-6),)
    assert _axes(S.stack(p, lay, mk3s, locators=loose, adjusters=huge))["splitter", "tilt"].status == "refused"
    with pytest.raises(FabricationError, match=r"splitter tilt .*float 0\.909 deg after any setting.*buy: a retainer"):
        S.refuse(S.stack(p, lay, mk3s, locators=loose))


def test_the_retainer_takes_the_play_out(table31_rig, other_rig, mk3s):
    for rig in (table31_rig, other_rig):
        r = S.stack(rig.profile, rig.layout, mk3s)
        v = _axes(r)
        for e in ("splitter", "cop"):
            names = [k.name for k in r.element(e).links]
            assert not set(S.PLATE_FLOATS) & set(names) and "splitter plate on its datum flank" in names
            assert v[e, "tilt"].ok, v[e, "tilt"].reason


def test_the_retainer_is_bought_and_its_step_stated(table31_rig):
    rows = [h for h in T.hardware(table31_rig.profile, table31_rig.layout) if h["item"] == T.PLATE_RETAINER["item"]]
    assert len(rows) == 1
    (row,) = rows
    assert row["steps"] == ("beam_splitter",) and "neutral" in row["item"] and row["standard"].startswith("MIL-A-46146")
    assert "datum flank" in row["joins"] and "0.4 mm of play" in row["joins"]
