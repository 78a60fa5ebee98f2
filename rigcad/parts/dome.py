"""The dome (thesis 3.1, 3.4): the integrated profile revolved, printed behind the coating, with a
wall, a bolted base flange, and the slots the mounting beam passes through and rests in."""

from __future__ import annotations

import math

import numpy as np

from rigcad.parts.layout import RigLayout, u_at_height
from rigcad.parts.recipe import Box, Curve, Cylinder, Difference, Line, Part, Revolve, Section
from rigcad.profile.schema import Profile


def _pt(m, u) -> tuple[float, float]:
    return tuple(float(v) for v in m.points(np.array([u]))[0])


def bolt_holes(layout: RigLayout, diameter: float, z0: float, height: float) -> tuple[Cylinder, ...]:
    """Vertical holes on the flange's bolt circle, from z0 up ``height`` mm."""
    r = layout.bolt_circle_r
    return tuple(Cylinder((r * math.cos(a), r * math.sin(a), z0), diameter / 2, height) for a in layout.bolt_angles)


def dome(profile: Profile, layout: RigLayout) -> Part:
    """Printed dome: inner face = the coated mirror surface moved behind by the coating (and forward
    by the layout's sanding stock: ``as_printed_dome``)."""
    shell = profile.dome_shell
    inner, outer = layout.as_printed_dome, layout.dome_outer
    u_base = u_at_height(inner, 0.0) if layout.dome_stock else layout.u_inner_base
    u_top_in = inner.u_range[1]
    top_in = _pt(inner, u_top_in)
    # The top edge runs along the mirror's normal: the outer curve's end is the inner's end moved by the wall.
    top_out = _pt(outer, u_top_in)
    u_fl = layout.u_outer_flange
    t_f = shell.flange_thickness
    fl_in = _pt(outer, u_fl)
    r_out = layout.flange_outer_r
    base_in = _pt(inner, u_base)
    section = Section((
        Curve(inner, u_base, u_top_in),
        Line(top_in, top_out),
        Curve(outer, u_top_in, u_fl),
        Line(fl_in, (r_out, t_f)),
        Line((r_out, t_f), (r_out, 0.0)),
        Line((r_out, 0.0), base_in),
    ))
    z0, z1 = layout.beam_z
    c = shell.slot_clearance
    half_w = profile.beam.width / 2 + c
    reach = layout.slot_r + 5.0
    slot = Box((-reach, -half_w, z0), (reach, half_w, z1 + c))  # the beam rests on the slot's floor
    holes = bolt_holes(layout, shell.bolt_diameter, -1.0, t_f + 2.0)
    return Part("dome", Difference(Revolve(section), (slot, *holes)), (0.82, 0.82, 0.86),
                "dome: mirror surface inside (paint it), wall, base flange bolted to the base plate, beam slots",
                mirrors=(("dome", layout.design_dome),))
