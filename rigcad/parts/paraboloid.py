"""The paraboloid mirror with its solid back, stem and the U clamp that grips the beam; and the
same stem and clamp under the camera-calibration cross that hangs in its place (thesis 4.1.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.parts.layout import RigLayout
from rigcad.parts.recipe import Box, Curve, Cylinder, Difference, Line, Part, Revolve, Section, Solid, Union_
from rigcad.profile.schema import Profile


#: The stem enters the clamp and the paraboloid's back by this much (mm) so that the booleans fuse
#: overlapping solids rather than faces that merely touch.
FUSE_OVERLAP = 0.5


@dataclass(frozen=True)
class Mount:
    """The paraboloid's mounting hardware, stated once (mm): its solid ``back`` below the rim, the
    ``stem`` from the clamp's top to the back, and the U ``clamp`` on the beam (its outer box; the
    ``channel`` is the slot the beam sits in). The recipes and the occluders read these."""

    back: Cylinder
    stem: Cylinder
    clamp: Box
    channel: Box

    def occluders(self, with_back: bool = True) -> tuple[tuple[str, Box | Cylinder], ...]:
        """Named convex stand-ins for tracing light past the mount (the clamp as its outer box)."""
        return ((("back", self.back),) if with_back else ()) + (("stem", self.stem), ("clamp", self.clamp))


def mount(profile: Profile, layout: RigLayout, top_z: float | None = None) -> Mount:
    """The mount under the paraboloid (``top_z``: the stem's top, default the back's bottom)."""
    pm, beam = profile.paraboloid_mount, profile.beam
    z0, z1 = layout.beam_z
    c = profile.dome_shell.slot_clearance
    half_len = pm.clamp_length / 2
    half_out = beam.width / 2 + c + pm.clamp_wall
    clamp_top = z1 + pm.clamp_wall
    back_z = layout.paraboloid_back_z
    top = back_z if top_z is None else top_z
    rim = layout.printed_paraboloid.points(np.array([layout.printed_paraboloid.u_range[0]]))[0]
    return Mount(
        back=Cylinder((0.0, 0.0, back_z), float(rim[0]), float(rim[1]) - back_z),
        stem=Cylinder((0.0, 0.0, clamp_top), pm.stem_radius, top - clamp_top),
        clamp=Box((-half_len, -half_out, z0), (half_len, half_out, clamp_top)),
        channel=Box((-half_len - 1, -beam.width / 2 - c, z0 - 1), (half_len + 1, beam.width / 2 + c, z1)),
    )


def stem_and_clamp(m: Mount) -> Solid:
    """The mount's stem on its U clamp (open at the bottom), as one solid."""
    s = m.stem
    stem = Cylinder((s.base[0], s.base[1], s.base[2] - FUSE_OVERLAP), s.radius, s.height + 2 * FUSE_OVERLAP)
    return Union_((Difference(m.clamp, (m.channel,)), stem))


def paraboloid(profile: Profile, layout: RigLayout) -> Part:
    """Printed paraboloid: its convex face is the coated mirror moved inward by the coating (and
    outward by the layout's sanding stock, ``as_printed_paraboloid``: the stock's layer meets the
    rim along the mirror's normal, so the back keeps its size)."""
    body, m = layout.printed_paraboloid, layout.as_printed_paraboloid
    u_rim, u_vertex = m.u_range
    rim0 = tuple(float(v) for v in body.points(np.array([u_rim]))[0])
    rim = tuple(float(v) for v in m.points(np.array([u_rim]))[0])
    vertex = tuple(float(v) for v in m.points(np.array([u_vertex]))[0])
    back = layout.paraboloid_back_z
    edge = (Line((rim0[0], back), rim0), Line(rim0, rim)) if layout.paraboloid_stock else (Line((rim[0], back), rim),)
    section = Section((
        Line((0.0, back), (rim0[0], back)),
        *edge,
        Curve(m, u_rim, u_vertex),
        Line(vertex, (0.0, back)),
    ))
    hardware = mount(profile, layout)
    body = Union_((Revolve(section), stem_and_clamp(hardware)))
    return Part("paraboloid", body, (0.75, 0.78, 0.85),
                "paraboloid mirror on its stem; the U clamp sits on the beam at the design height",
                mirrors=(("paraboloid", layout.design_paraboloid),), occluders=hardware.occluders())
