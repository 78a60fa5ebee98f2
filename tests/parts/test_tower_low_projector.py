"""A low projector raises the shelf, and the splitter holder on its seat, up to the beam splitter: the
newcomer's DLP pico (tests/cli/newcomer/, ``projector.pupil_height`` 20 mm) puts the holder's underside
2.5 mm under the plate's lowest edge. The plate slides into the holder's grooves along -y, over the +y
flange and its spring bolt (nut, washers and spring 24 mm tall): both must stay out of its way in, as
the assembly check judges it (its own attempt on the step, on the parts' meshes, with what the step
needs in place: rigcad.manual.gate._ways_in; no export), and the seat must still hold its camera."""

from __future__ import annotations

from pathlib import Path

import pytest

NEWCOMER = Path(__file__).parents[1] / "cli" / "newcomer"


@pytest.fixture(scope="module")
def rig_with(tmp_path_factory):
    """mylab (tests/cli/newcomer) with its projector's ``pupil_height`` set to the given mm."""
    from rigcad.profile import load_profile
    from rigcad.rig import load

    tmp = tmp_path_factory.mktemp("low_projector")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("RIGCAD_PROFILES", str(NEWCOMER))

        def make(pupil_height: float):
            path = tmp / f"low{pupil_height:g}.yaml"
            path.write_text(f"extends: mylab\nprojector:\n  pupil_height: {pupil_height:g} mm\n")
            return load(load_profile(str(path)))

        yield make


# 20 mm: the pico as measured (the +y flange notched by the groove, its bolt behind the plate); 35 mm: the
# bolt behind the plate, the flange under it; 50 mm: as the default rig (55 mm) is built, nothing moved.
@pytest.mark.parametrize("pupil_height", [20.0, 35.0, 50.0])
def test_the_plate_goes_into_a_low_projectors_holder(rig_with, pupil_height):
    from rigcad.manual.gate import _ways_in

    rig = rig_with(pupil_height)
    ways = _ways_in(rig, rig.profile, "beam_splitter")
    assert ways is not None, "the step beam_splitter is missing or waits for a part that never comes"
    # the check's own refusal: every way in the check tries runs into something (> CLEARANCE_MM, 0.05 mm)
    assert not all(ways.values()), f"pupil_height {pupil_height:g} mm: the plate is blocked every way: {ways}"
    assert ways[(0.0, -1.0, 0.0)] == 0.0, f"the plate's own way in (-y) is blocked: {ways}"


def test_only_the_bolt_in_the_plates_way_moves(rig_with):
    """The -y bolt never stands in the plate's way: it stays 8 mm inside the holder's back end, and so do
    both on the default rig (its parts unchanged); the +y one on the pico's rig stands behind the plate's
    lowest edge by the spring's radius and play on the bolt, and the seat still takes the 10 N side pull
    at the camera (rigcad.fab.seat_hold.check refuses it otherwise)."""
    from rigcad.fab import seat_hold
    from rigcad.parts import tower

    rig = rig_with(20.0)
    t = rig.layout.tower
    (xm, ym), (xp, yp) = tower._holder_flange_points(t, rig.profile)
    assert ym < 0 < yp and xm == pytest.approx(t.holder_x[0] + 8.0)
    plate_x0 = tower._plate_extent(t.plate)[0]
    # the spring's outer radius 4.5 mm plus its play on the M4 bolt (6.2 - 4) / 2 = 1.1 mm: 5.6 mm behind
    assert xp + 5.6 <= plate_x0, (xp, plate_x0)
    seat_hold.check(rig.profile, rig.layout)
    high = rig_with(55.0)
    pts = tower._holder_flange_points(high.layout.tower, high.profile)
    assert [x for x, _ in pts] == pytest.approx([high.layout.tower.holder_x[0] + 8.0] * 2)
