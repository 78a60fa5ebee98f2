"""The dome (thesis 3.1, 3.4): the integrated profile revolved, printed behind the coating, with a
wall, a bolted base flange, and the slots the mounting beam passes through and rests in."""

from __future__ import annotations

import math

import numpy as np

from rigcad.errors import GeometryError
from rigcad.parts.joints import ScrewJoint
from rigcad.parts.layout import RigLayout, u_at_height
from rigcad.parts.recipe import Box, Curve, Difference, Line, Part, Revolve, Section
from rigcad.profile.schema import Profile
from rigcad.standards import thread_for_hole


def _pt(m, u) -> tuple[float, float]:
    return tuple(float(v) for v in m.points(np.array([u]))[0])


def flange_joint(profile: Profile, layout: RigLayout) -> ScrewJoint:
    """The dome's flange on the base plate: ``dome_shell.bolts`` screws on the flange's bolt circle,
    down through the flange into heat-set inserts in the plate (the plate stands on the bench: no
    nut fits under it); the thread is the largest whose clearance hole is ``dome_shell.bolt_diameter``."""
    shell = profile.dome_shell
    try:
        thread = thread_for_hole(shell.bolt_diameter).name
    except ValueError as err:
        raise GeometryError(str(err), where=profile.where("dome_shell", "bolt_diameter")) from err
    r = layout.bolt_circle_r
    points = tuple((r * math.cos(a), r * math.sin(a)) for a in layout.bolt_angles)
    return ScrewJoint("dome_flange", "dome", "base_plate", thread, points, (0.0, shell.flange_thickness),
                      (-profile.base_plate.thickness, 0.0), "insert", "dome_shell.bolt_diameter")


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
    joint = flange_joint(profile, layout)
    holes = joint.clearance_holes(shell.bolt_diameter)
    return Part("dome", Difference(Revolve(section), (slot, *holes)), (0.82, 0.82, 0.86),
                "dome: mirror surface inside (paint it), wall, base flange bolted to the base plate, beam slots",
                mirrors=(("dome", layout.design_dome),), joints=(joint,))
