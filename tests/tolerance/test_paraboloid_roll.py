"""The paraboloid's roll (its tilt about the beam's axis) is an axis of the tolerance stack of its own,
beside its tilt along the beam: the printed faces it rolls on (the beam's underside and the clamp's roof,
each across the beam's width; the seats' floors across the roll bars' lever) enter it, and the roll bars
in the beam's seats (rigcad.parts.ROLL_BAR) adjust it."""

import math

import pytest

from rigcad.fab import stack as ST
from rigcad.fab.printers import load_printer
from rigcad.parts.dome import ROLL_BAR, beam_seats, roll_lever
from rigcad.parts.adjusters import paraboloid_roll, paraboloid_roll_needed
from rigcad.parts.locating import foil_step


@pytest.fixture(scope="module")
def mk3s(table31_rig):
    return ST.stack(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))


def _axis(report, axis):
    return next(v for v in report.element("paraboloid").axes if v.axis == axis)


def test_the_roll_is_the_faces_it_rolls_on(table31_rig, mk3s):
    p, lay = table31_rig.profile, table31_rig.layout
    proc = load_printer("prusa_mk3s").process_errors
    lever = ROLL_BAR.length - ROLL_BAR.pad  # between the middles of the end strips
    # by hand: the beam's underside and the clamp's roof across the beam's width, the seats' floors and the
    # bars' thickness band across the bars' lever, the base plate's flatness across the flange
    want = (2 * proc.position / p.beam.width + (proc.position + ROLL_BAR.thickness_tolerance) / lever
            + p.datum.foot_flatness / (2 * lay.flange_outer_r))
    v = _axis(mk3s, "roll")
    assert v.worst == pytest.approx(want, rel=1e-12)  # the same sum, computed two ways
    assert math.degrees(v.worst) > 1.9  # 0.97 deg per face on the beam's width (0.1016 mm across 6 mm)
    assert v.tolerance_key == "paraboloid_tilt" and v.worst > v.tolerance
    assert set(v.dominating) == {"beam's underside across its roll bars", "clamp's roof across the beam's top"}
    # the adjuster entry states the same range it needs, on the profile's print accuracy
    assert paraboloid_roll_needed(p, lay, proc.position) == pytest.approx(v.worst, rel=1e-12)


def test_the_roll_bars_adjust_it_within_a_quarter_of_the_tolerance(table31_rig, mk3s, other_rig):
    v = _axis(mk3s, "roll")
    assert v.status == "adjusted" and v.adjuster.name.startswith("paraboloid roll about the beam")
    tol = table31_rig.profile.tolerancing.paraboloid_tilt
    lever = roll_lever()
    assert v.adjuster.resolution == pytest.approx(foil_step() / lever, rel=1e-12)
    assert v.adjuster.resolution <= ST.RESOLUTION_SHARE * tol  # 0.044 deg <= 0.05 deg
    assert v.adjuster.range >= v.worst
    a = paraboloid_roll(table31_rig.profile, table31_rig.layout)
    assert a.ok and a.range == v.adjuster.range
    # the second rig (other instruments) too, and the tilt along the beam is untouched by the roll links
    o = _axis(ST.stack(other_rig.profile, other_rig.layout, load_printer("prusa_mk3s")), "roll")
    assert o.status == "adjusted"
    assert f"{math.degrees(_axis(mk3s, 'tilt').worst):.2f}" == "0.48"  # as before the roll entered the stack


def test_the_range_is_what_the_beam_can_turn_in_its_tunnels(table31_rig):
    p, lay = table31_rig.profile, table31_rig.layout
    seats = beam_seats(p, lay)
    t = seats.roll_room
    # the beam's section turned by its room just spans the tunnel's width (the tunnel's own box)
    width = seats.tunnels[0].hi[1] - seats.tunnels[0].lo[1]
    assert p.beam.width * math.cos(t) + p.beam.height * math.sin(t) == pytest.approx(width, abs=1e-9)
    stop = next(s for s in seats.stops() if s.axis == "roll")
    assert stop.range == pytest.approx(min(2 * seats.pack / roll_lever(), t), rel=1e-12)
    # each bar lies across the beam under it, in its seat's block, within the slot cut for it
    z0 = lay.beam_z[0]
    for bar, block in zip(seats.bars, seats.blocks):
        assert bar.hi[2] == pytest.approx(z0) and bar.hi[1] - bar.lo[1] == ROLL_BAR.length
        assert block.lo[0] <= bar.lo[0] and bar.hi[0] <= block.hi[0]
        assert block.lo[1] < bar.lo[1] and bar.hi[1] < block.hi[1]


def test_the_bars_cast_no_shadow(table31_rig):
    """The bars stand outside the dome's mirror at every height they span: the light, reflected inside the
    mirror, never reaches them (the beam inside the dome keeps its width and its shadow)."""
    lay = table31_rig.layout
    seats = beam_seats(table31_rig.profile, lay)
    pts = lay.as_printed_dome.points(lay.as_printed_dome.sample(4001))
    for bar in seats.bars:
        band = (pts[:, 1] >= bar.lo[2] - 5.0) & (pts[:, 1] <= bar.hi[2] + 5.0)
        mirror_r = float(pts[band, 0].max())
        near = min(abs(bar.lo[0]), abs(bar.hi[0]))  # the bar's nearest x to the axis (its y only moves it out)
        assert near > mirror_r, (near, mirror_r)


def _with(table31_rig, without=()):
    p, lay = table31_rig.profile, table31_rig.layout
    proc = load_printer("prusa_mk3s").process_errors
    adj = tuple(a for a in (*ST.default_adjusters(p, lay), *ST.located_adjusters(p, lay, proc))
                if a.axis not in without)
    return ST.stack(p, lay, load_printer("prusa_mk3s"), adjusters=adj)


def test_without_the_roll_bars_the_roll_is_refused(table31_rig):
    rep = _with(table31_rig, without=("roll",))
    v = _axis(rep, "roll")
    assert v.status == "refused" and v.adjuster is None
    assert any("tip-tilt mount" in b for b in v.buy)
    with pytest.raises(Exception, match=r"paraboloid roll \(tolerancing.paraboloid_tilt\).*beam's underside"):
        ST.refuse(rep)
    # a tilt adjuster along the beam does not serve the roll
    assert _axis(rep, "tilt").status == "adjusted"


def test_an_adjuster_across_the_beam_alone_is_too_coarse(table31_rig):
    p = table31_rig.profile
    narrow = ST.AdjusterSpec("foil side by side under the beam", "paraboloid", "roll", 1.5 / p.beam.width,
                             foil_step() / p.beam.width)
    adj = (*ST.default_adjusters(p, table31_rig.layout),
           *(a for a in ST.located_adjusters(p, table31_rig.layout, load_printer("prusa_mk3s").process_errors)
             if a.axis != "roll"), narrow)
    v = _axis(ST.stack(p, table31_rig.layout, load_printer("prusa_mk3s"), adjusters=adj), "roll")
    assert v.status == "refused" and "resolution" in v.reason
