"""The dome (thesis 3.1, 3.4): the integrated profile revolved, printed behind the coating, with a
wall, a bolted base flange, and the slots the mounting beam passes through and rests in."""

from __future__ import annotations

import math

import numpy as np

from rigcad.errors import GeometryError
from rigcad.parts.joints import ScrewJoint
from rigcad.parts.locating import DowelRegister, bolt_hole
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


def _pins(layout: RigLayout) -> tuple[tuple[float, float], tuple[float, float]]:
    """The register's pins (x, y; mm): the round hole's at +x, the slot's at -x, on the bolt circle."""
    r = layout.bolt_circle_r
    return (r, 0.0), (-r, 0.0)


def register(profile: Profile, layout: RigLayout) -> DowelRegister:
    """The dome's register on the base plate: two ``datum.dowel_diameter`` pins pressed into the plate
    on the x axis at the bolt circle (the bolts stand half a pitch off it), the round hole at +x, the
    slot at -x (along x: it takes the print's scale error over the flange's width). The dome lifts off
    and goes back on them: the calibration screens go in on the plate while it is off."""
    shell, d = profile.dome_shell, profile.datum
    pins = _pins(layout)
    slot = 2 * (2 * d.print_position + d.print_scale * 2 * layout.bolt_circle_r)
    reg = DowelRegister("dome_register", "dome", "base_plate", d.dowel_diameter, pins,
                        (0.0, shell.flange_thickness), (-profile.base_plate.thickness, 0.0), slot,
                        "datum.dowel_diameter")
    bolt_r = flange_bolt_hole(profile, layout) / 2
    for x, y in flange_joint(profile, layout).points:
        for (px, py) in reg.points:
            gap = math.hypot(x - px, y - py) - bolt_r - d.dowel_diameter / 2 - slot / 2
            if gap < profile.tower.wall:
                raise GeometryError(f"the dome's register pin at ({px:.1f}, {py:.1f}) mm comes within {gap:.1f} mm of a "
                                    f"flange bolt: fewer bolts (dome_shell.bolts) or thinner pins (datum.dowel_diameter)",
                                    where=profile.where("dome_shell", "bolts"))
    return reg


def flange_bolt_hole(profile: Profile, layout: RigLayout) -> float:
    """The flange's bolt holes (mm): ``dome_shell.bolt_diameter``, opened where the print's errors
    need it (rigcad.parts.locating.bolt_hole, at the farthest bolt from the register's round pin): the
    register locates the dome, the bolts only clamp it."""
    d = profile.datum
    joint = flange_joint(profile, layout)
    (px, py) = _pins(layout)[0]
    far = max(math.hypot(x - px, y - py) for x, y in joint.points)
    return max(profile.dome_shell.bolt_diameter, bolt_hole(joint.thread, far, d.print_position, d.print_scale))


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
    joint, reg = flange_joint(profile, layout), register(profile, layout)
    holes = joint.clearance_holes(flange_bolt_hole(profile, layout))
    lateral, _ = reg.repeatability
    return Part("dome", Difference(Revolve(section), (slot, *holes, *reg.upper_holes())), (0.82, 0.82, 0.86),
                "dome: mirror surface inside (paint it), wall, base flange on two dowels in the base plate (a round "
                f"hole and a slot: it lifts off and goes back to within {lateral:g} mm) and bolted to it, beam slots",
                mirrors=(("dome", layout.design_dome),), joints=(joint, reg))
