"""The narrow mounting beam (thesis Figure 3.3): spans the dome through its wall slots, rests on
their floors, and carries the paraboloid's clamp at the design height."""

from __future__ import annotations

from rigcad.parts.layout import RigLayout
from rigcad.parts.recipe import Box, Part
from rigcad.profile.schema import Profile


def beam(profile: Profile, layout: RigLayout) -> Part:
    z0, z1 = layout.beam_z
    half = layout.beam_half_length
    w = profile.beam.width / 2
    box = Box((-half, -w, z0), (half, w, z1))
    return Part("beam", box, (0.35, 0.35, 0.38), "mounting beam along x through the dome's slots",
                occluders=(("beam", box),))
