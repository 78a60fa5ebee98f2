"""The paraboloid mirror with its solid back, stem and the U clamp that grips the beam; and the
same stem and clamp under the camera-calibration cross that hangs in its place (thesis 4.1.1)."""

from __future__ import annotations

import numpy as np

from rigcad.parts.layout import RigLayout
from rigcad.parts.recipe import Box, Curve, Cylinder, Difference, Line, Part, Revolve, Section, Solid, Union_
from rigcad.profile.schema import Profile


def stem_and_clamp(profile: Profile, layout: RigLayout, top_z: float) -> Solid:
    """A stem from ``top_z`` down to a U clamp that sits on the beam (open at the bottom)."""
    mount, beam = profile.paraboloid_mount, profile.beam
    z0, z1 = layout.beam_z
    c = profile.dome_shell.slot_clearance
    half_len = mount.clamp_length / 2
    half_out = beam.width / 2 + c + mount.clamp_wall
    clamp_top = z1 + mount.clamp_wall
    clamp = Difference(Box((-half_len, -half_out, z0), (half_len, half_out, clamp_top)),
                       (Box((-half_len - 1, -beam.width / 2 - c, z0 - 1), (half_len + 1, beam.width / 2 + c, z1)),))
    stem = Cylinder((0.0, 0.0, clamp_top - 0.5), mount.stem_radius, top_z - clamp_top + 1.0)
    return Union_((clamp, stem))


def paraboloid(profile: Profile, layout: RigLayout) -> Part:
    """Printed paraboloid: its convex face is the coated mirror moved inward by the coating."""
    m = layout.printed_paraboloid
    u_rim, u_vertex = m.u_range
    rim = tuple(float(v) for v in m.points(np.array([u_rim]))[0])
    vertex = tuple(float(v) for v in m.points(np.array([u_vertex]))[0])
    back = layout.paraboloid_back_z
    section = Section((
        Line((0.0, back), (rim[0], back)),
        Line((rim[0], back), rim),
        Curve(m, u_rim, u_vertex),
        Line(vertex, (0.0, back)),
    ))
    body = Union_((Revolve(section), stem_and_clamp(profile, layout, back)))
    return Part("paraboloid", body, (0.75, 0.78, 0.85),
                "paraboloid mirror on its stem; the U clamp sits on the beam at the design height",
                mirrors=(("paraboloid", layout.design_paraboloid),))
