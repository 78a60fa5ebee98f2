"""docs/rig-mechanics.md's figures for the paraboloid's roll about its beam are the profile's, the
printer's and the roll bars': the printed faces it rolls on, why foil under the beam alone cannot set
it, and what the roll bars (rigcad.parts.dome.ROLL_BAR) reach; the calibration's "Tilt x" step says the
same."""

from __future__ import annotations

import math
from pathlib import Path

from rigcad.fab import stack as ST
from rigcad.fab.printers import load_printer
from rigcad.fab.stack import RESOLUTION_SHARE
from rigcad.parts.dome import beam_seats, roll_lever
from rigcad.parts.locating import foil_step
from rigcad.parts.paraboloid import setting_text

PAGE = Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md"


def _text() -> str:
    return " ".join(PAGE.read_text(encoding="utf-8").split())


def test_the_roll_figures_are_the_profiles(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    text = _text()
    pos = load_printer("prusa_mk3s").process_errors.position
    width, tol = p.beam.width, p.tolerancing.paraboloid_tilt
    face = pos / width  # one printed face flat to the position error across the beam's width (rad)
    assert (f"printed flat to {pos:.2f} mm across the beam's {width:g} mm width on the MK3S (the beam's underside "
            f"on its seats, the clamp's roof on the beam's top), {math.degrees(face):.2f} deg each against the "
            f"{math.degrees(tol):g} deg of") in text
    v = next(a for a in ST.stack(p, lay, load_printer("prusa_mk3s")).element("paraboloid").axes if a.axis == "roll")
    assert f"{math.degrees(v.worst):.2f} deg worst case, {math.degrees(v.rss):.2f} deg RSS" in text
    fine = RESOLUTION_SHARE * tol
    assert f"cannot set it to a quarter of that ({math.degrees(fine):.2f} deg)" in text
    # the widest lever foil under the beam alone can have is the beam's width
    assert (f"the thinnest foil ({foil_step():g} mm) over the beam's whole width turns it "
            f"{math.degrees(foil_step() / width):.2f} deg") in text
    assert foil_step() / width > fine  # why the bars: too coarse
    assert f"a {math.degrees(fine):.2f} deg step in that foil needs a lever of {foil_step() / fine:.0f} mm" in text
    lever = roll_lever()
    assert f"its two ends on foil packs {lever:g} mm apart" in text and lever >= foil_step() / fine
    assert f"rolls the paraboloid {math.degrees(foil_step() / lever):.3f} deg per {foil_step():g} mm" in text
    room = beam_seats(p, lay).roll_room
    assert f"range {math.degrees(min(v.adjuster.range, room)):.1f} deg each way" in text
    assert f"{math.degrees(v.adjuster.resolution):.2f} deg steps" in text


def test_the_calibration_says_how_to_set_the_roll(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    lever = roll_lever()
    step = foil_step() / lever  # the thinnest foil under one end of the bars, against the other end
    half = step / 2  # a setting lands within half a step of the reading
    assert half < RESOLUTION_SHARE * p.tolerancing.paraboloid_tilt
    assert f"it lands within {math.degrees(half):.3f} deg of level" in _text()
    step_text = setting_text(p, lay)
    # the sign: tilt x > 0 lifts the +y side (rigcad.calibrate.conventions), so foil goes under the -y ends
    assert "Tilt x (the +y side high when positive" in step_text
    assert "add foil under the -y ends of both seats' roll bars" in step_text
    assert f"{lever * math.radians(0.1):.4f} mm per 0.1 deg" in step_text
    assert f"rolls it {math.degrees(step):.3f} deg, so it lands within {math.degrees(half):.3f} deg" in step_text


def test_the_shadow_a_wide_beam_would_cast_is_the_occlusion_models(table31_rig):
    """The way out not taken, measured: the beam widened to the roll bars' lever inside the dome, through
    the same occlusion model the parts page's beam figure comes from."""
    from rigcad.optics.design import profile_table
    from rigcad.parts.occlusion import blocked_solid_angle
    from rigcad.parts.recipe import Box

    occ = dict(table31_rig.occluders)
    table = profile_table(table31_rig.geometry, table31_rig.dome)
    half = roll_lever() / 2
    wide = tuple((n, Box((s.lo[0], -half, s.lo[2]), (s.hi[0], half, s.hi[2])) if n == "beam" else s)
                 for n, s in occ["beam"])
    narrow, widened = blocked_solid_angle(occ, table), blocked_solid_angle({**occ, "beam": wide}, table)
    assert widened["blocked_fraction"] > 4 * narrow["blocked_fraction"]  # 26 mm against 6 mm: about their ratio
    text = _text()
    assert (f"shadow it did: {100 * narrow['blocked_fraction']:.2f} % of the measurable zone's incidence directions, "
            f"where a beam {roll_lever():g} mm wide inside the dome (the lever, in the beam itself) would hide "
            f"{100 * widened['blocked_fraction']:.2f} %") in text
