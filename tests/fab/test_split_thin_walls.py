"""Split pins where the wall is thin (rigcad.fab.split): a two-sector split's plane is one face (a beam
cut in its middle takes its pins across its whole section); a face whose outline narrows along the pin
(a disc's chord near its rim) takes its pins from the section along the pin's whole length; a split
mirror's meridional face too thin for any pin is left without pins and says what holds it; what is
still refused names every pin size tried and the way out. Small synthetic parts: a few seconds."""

from __future__ import annotations

import math

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.errors import FabricationError
from rigcad.fab import split as SP
from rigcad.fab.printers import AlignmentPin

#: The MK3S's and the MINI's pin (1.75 mm filament in a 1.9 mm hole, 6 mm each way) and their FDM wall.
FILAMENT = AlignmentPin(1.75, 0.15, 6.0)
WALL = 1.5
#: The pin the Form 3's base plate takes (its 2 mm pin's next ISO 8734 size, 0.1 mm clearance, 5 mm each way),
#: with its resin wall (rigcad.fab.split.MIN_WALL).
RESIN = AlignmentPin(1.5, 0.1, 5.0)


class Bore:
    """A cylindrical mirror on the inside of a tube: signed distance r_mirror - r (negative behind it)."""

    def __init__(self, r):
        self.r = r

    def signed_distance(self, p):
        return self.r - np.hypot(p[:, 0], p[:, 1])


def _walls_hold(man, pins, pin, wall):
    """Every hole widened by its wall lies inside the part (rigcad.fab.split._inside, the mesh test)."""
    return all(SP._inside(man, np.array(p.centre), np.array(p.axis), pin.hole_radius + wall, pin.depth, wall)
               for p in pins)


def test_a_beam_cut_in_two_through_the_axis_takes_its_pins_across_its_section():
    # the default beam's section: 6 mm wide, 10 mm tall, cut by the plane at 88.75 deg through the axis
    beam = m3d.Manifold.cube((301.6, 6.0, 10.0), True).translate((0.0, 0.0, 119.0))
    plan = SP.SplitPlan(2, 1, math.radians(88.75), (114.0, 124.0))
    pins = SP.place_pins(beam, plan, FILAMENT, None, wall=WALL)
    # one face (the whole plane), two pins; each half-plane alone (3 mm wide) had no room for one
    assert len(pins) == 2 and len({p.face for p in pins}) == 1, [p.face for p in pins]
    assert _walls_hold(beam, pins, FILAMENT, WALL)
    # 1.9 + 2 x 1.5 = 4.9 mm of the 6 mm: the holes straddle the axis's plane y = 0
    assert all(abs(p.centre[1]) < 0.56 for p in pins), [p.centre for p in pins]


def _disc_plate():
    """The Form 3 base plate's case: a 10 mm plate, radius 152 mm, cut at x = 137.5 mm and y = -47.25 mm."""
    return m3d.Manifold.cylinder(10.0, 152.0, 152.0, 720).translate((0.0, 0.0, -10.0)), SP.GridPlan((137.5,), (-47.25,))


def test_a_face_narrowing_along_the_pin_takes_pins_from_the_section_along_it():
    plate, plan = _disc_plate()
    # the face x = 137.5, y < -47.25 is 17.5 mm wide, but 5.6 mm further along the pin only 4 mm: its own
    # outline's eroded edge puts the holes where they run out through the rim
    with pytest.raises(FabricationError, match=r"^x cut 137\.5 mm, y slab 1, z slab 1: fewer than two pin positions"):
        SP.place_pins(plate, plan, RESIN, None, wall=SP.MIN_WALL, swept=False)
    pins = SP.place_pins(plate, plan, RESIN, None, wall=SP.MIN_WALL)
    face = [p for p in pins if p.face == "x cut 137.5 mm, y slab 1, z slab 1"]
    assert len(face) >= 2 and _walls_hold(plate, pins, RESIN, SP.MIN_WALL)


def test_every_pin_size_is_tried_on_the_faces_own_sections_before_any_swept_one(monkeypatch):
    # the swept sections are a second pass over every pin size: a part whose faces all place on their own
    # sections (every part the MK3S splits) never reaches it, so its pins are what they were
    plate, plan = _disc_plate()
    tried = []
    place = SP.place_pins

    def recorded(man, plan, pin, *args, swept=True, **kwargs):
        tried.append((pin.diameter, swept))
        return place(man, plan, pin, *args, swept=swept, **kwargs)

    monkeypatch.setattr(SP, "place_pins", recorded)
    _, pins, _ = SP.split_part(plate, "plate", plan, AlignmentPin(2.0, 0.1, 5.0), None, wall=SP.MIN_WALL)
    # the 2 mm pin finds no two places on the rim's face either way; the 1.5 mm on the swept section
    assert tried == [(2.0, False), (1.5, False), (1.0, False), (2.0, True), (1.5, True)], tried
    assert {p.diameter for p in pins} == {1.5}


def test_a_mirror_shell_too_thin_for_any_pin_is_glued_without_pins():
    # a 4.4 mm shell behind a mirror: a 1 mm pin's 1.4 mm float hole + 2 x 1.5 mm walls fills it exactly
    shell = m3d.Manifold.cylinder(40.0, 54.4, 54.4, 360) - m3d.Manifold.cylinder(42.0, 50.0, 50.0, 360).translate(
        (0.0, 0.0, -1.0))
    plan = SP.SplitPlan(4, 1, math.radians(45.0), (0.0, 40.0))
    pin = AlignmentPin(1.75, 0.4, 6.0)  # a mirror's float pin
    pinless: list = []
    pieces, pins, _ = SP.split_part(shell, "shell", plan, pin, Bore(50.0), [], wall=WALL, pinless=pinless)
    assert len(pieces) == 4 and pins == []
    assert [s["face"] for s in pinless] == [f"sector plane {a:.1f} deg, band 1" for a in (45, 135, 225, 315)]
    assert all("printed-stage template" in s["held_by"] and "of the pins tried (1.75, 1.5, 1 mm)" in s["why"]
               for s in pinless), pinless
    # without a mirror (no gauge holds the seam) the same shell is refused, naming every size and the way out
    with pytest.raises(FabricationError) as err:
        SP.split_part(shell, "shell", plan, pin, None, [], wall=WALL)
    msg = str(err.value)
    assert msg.startswith("sector plane 45.0 deg, band 1: ") and "from 1.75 mm down to 1 mm" in msg, msg
    assert "no alignment_pin.diameter fits" in msg and "--printer" in msg and "thinner pins" not in msg, msg


def test_a_mirror_face_with_room_keeps_its_pins():
    # a 9 mm shell: every face takes two pins, none is left out
    shell = m3d.Manifold.cylinder(40.0, 59.0, 59.0, 360) - m3d.Manifold.cylinder(42.0, 50.0, 50.0, 360).translate(
        (0.0, 0.0, -1.0))
    pinless: list = []
    _, pins, _ = SP.split_part(shell, "shell", SP.SplitPlan(4, 1, math.radians(45.0), (0.0, 40.0)),
                               AlignmentPin(1.75, 0.4, 6.0), Bore(50.0), [], wall=WALL, pinless=pinless)
    assert pinless == [] and len(pins) == 8


def test_a_band_above_a_cut_fits_with_the_tongue_it_carries():
    # a 295 mm tube on a 180 mm tall printer, too wide to lie down: two bands; the cut at 40 % leaves a
    # 177 mm upper band that fits as a cell but not with its 6 mm tongue under the cut (183 mm)
    from types import SimpleNamespace

    from rigcad.export import mesh as M
    from rigcad.fab import choice
    from rigcad.fab.printers import BuildVolume

    tube = m3d.Manifold.cylinder(295.0, 50.0, 50.0, 180) - m3d.Manifold.cylinder(297.0, 46.0, 46.0, 180).translate(
        (0.0, 0.0, -1.0))
    printer = SimpleNamespace(usable=(120.0, 120.0, 180.0), alignment_pin=FILAMENT, name="tall",
                              build_volume=BuildVolume(120.0, 120.0, 180.0))
    v, _ = M.mesh_arrays(tube)
    plan = choice.split_plan(tube, v, True, None, printer)
    assert plan.bands == 2, plan
    pieces, _, _ = SP.split_part(tube, "tube", plan, FILAMENT, None, [], wall=WALL)
    for pc in pieces:  # each piece as made, standing upright (the fit the plan judged)
        lo, hi = np.asarray(pc.manifold.bounding_box())[[2, 5]]
        assert hi - lo <= 180.0, (pc.name, hi - lo)  # the printer's height
