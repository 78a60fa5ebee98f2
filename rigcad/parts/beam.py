"""The narrow mounting beam (thesis Figure 3.3): spans the dome through its wall slots, rests on the
two seats outside them on a bought roll bar in each (rigcad.parts.dome.beam_seats, ROLL_BAR: the
paraboloid's roll is set there, on the bars' lever, not on the beam's narrow width), and carries the paraboloid's clamp at the
design height, its end against a dowel pin set into the beam's top (rigcad.parts.paraboloid)."""

from __future__ import annotations

from rigcad.parts.layout import RigLayout
from rigcad.parts.recipe import Box, Difference, Part
from rigcad.profile.schema import Profile


def beam(profile: Profile, layout: RigLayout) -> Part:
    from rigcad.parts.dome import beam_seats
    from rigcad.parts.paraboloid import mount

    z0, z1 = layout.beam_z
    # it reaches through its seats (a dome whose wall leans out puts them past the slots' overhang)
    half = max(layout.beam_half_length, max(abs(b.lo[0]) for b in beam_seats(profile, layout).blocks) + 1.0)
    w = profile.beam.width / 2
    box = Box((-half, -w, z0), (half, w, z1))
    pin = mount(profile, layout).pin_hole
    return Part("beam", Difference(box, (pin,)), (0.35, 0.35, 0.38),
                "mounting beam along x through the dome's slots, on its two seats; the paraboloid's stop pin "
                f"(ISO 8734, {2 * mount(profile, layout).pin.radius:g} mm) set into its top in retaining compound, drilled and reamed to a slip fit",
                occluders=(("beam", box),))
