"""Calibration crosses (thesis 4.1.1, Figures 4.1, 4.2).

Projector: two crosses on the projector's mounting plate, centred at the optical-axis height, and
a backplate that catches their shadows; they stand in the bench frame (mounting plate top z = 0,
projector axis along +x at ``crosses.projector_axis_height``). Camera: a cross hung on the beam in
place of the paraboloid (rig frame), and one on the base plate (``base.base_cross``).
"""

from __future__ import annotations

from rigcad.parts.layout import RigLayout
from rigcad.parts.paraboloid import mount, stem_and_clamp
from rigcad.parts.recipe import Box, Difference, Part, Union_
from rigcad.profile.schema import Profile

FOOT = (20.0, 30.0, 3.0)  # mm: a foot wide enough to stand the cross upright on the plate
FENCE = (2.0, 1.5, 0.2)  # mm: wall, height and clearance of the locating fences on the mounting plate
PLATE_THICKNESS = 6.0  # mm


def projector_cross(profile: Profile, layout: RigLayout) -> Part:
    c = profile.crosses
    h, L, bw, t = c.projector_axis_height, c.arm_length, c.bar_width / 2, c.thickness / 2
    horizontal = Box((-t, -L, h - bw), (t, L, h + bw))
    vertical = Box((-t, -bw, 0.0), (t, bw, h + L))  # also the post down to the foot
    foot = Box((-FOOT[0] / 2, -FOOT[1] / 2, 0.0), (FOOT[0] / 2, FOOT[1] / 2, FOOT[2]))
    return Part("projector_cross", Union_((horizontal, vertical, foot)), (0.9, 0.5, 0.1),
                f"projector calibration cross (print 2): centre {h:g} mm above the mounting plate; place them "
                f"{c.projector_spacing:g} mm apart on the projector's axis", quantity=2, in_rig=False)


def projector_backplate(profile: Profile, layout: RigLayout) -> Part:
    c = profile.crosses
    x0 = c.projector_spacing + c.backplate_distance
    s = c.backplate_size
    plate = Box((x0, -s / 2, 0.0), (x0 + 3.0, s / 2, c.projector_axis_height + s / 2))
    foot = Box((x0 - FOOT[0] / 2, -s / 2, 0.0), (x0 + 3.0 + FOOT[0] / 2, s / 2, FOOT[2]))
    return Part("projector_backplate", Union_((plate, foot)), (0.95, 0.95, 0.95),
                "backplate catching the projector crosses' shadows (aligned when they coincide)", in_rig=False)


def _footprints(profile: Profile) -> list[tuple[float, float, float, float]]:
    """(x0, x1, y0, y1) of every foot standing on the mounting plate: two crosses, the backplate."""
    c = profile.crosses
    x_back = c.projector_spacing + c.backplate_distance
    s = c.backplate_size
    feet = [(x - FOOT[0] / 2, x + FOOT[0] / 2, -FOOT[1] / 2, FOOT[1] / 2) for x in (0.0, c.projector_spacing)]
    feet.append((x_back - FOOT[0] / 2, x_back + 3.0 + FOOT[0] / 2, -s / 2, s / 2))
    return feet


def projector_mounting_plate(profile: Profile, layout: RigLayout) -> Part:
    """The plate the projector crosses and the backplate stand on, with fences that locate their
    feet on the projector's axis (x) at the design spacing; its top face is z = 0."""
    wall, height, gap = FENCE
    feet = _footprints(profile)
    x0 = min(f[0] for f in feet) - gap - wall - 10.0
    x1 = max(f[1] for f in feet) + gap + wall + 10.0
    y = max(f[3] for f in feet) + gap + wall + 10.0
    plate = Box((x0, -y, -PLATE_THICKNESS), (x1, y, 0.0))
    fences = tuple(
        Difference(Box((a - gap - wall, b0 - gap - wall, 0.0), (b + gap + wall, b1 + gap + wall, height)),
                   (Box((a - gap, b0 - gap, -1.0), (b + gap, b1 + gap, height + 1.0)),))
        for a, b, b0, b1 in feet)
    return Part("projector_mounting_plate", Union_((plate, *fences)), (0.55, 0.57, 0.6),
                "mounting plate for the projector crosses and backplate: fences place them on the axis, "
                f"{profile.crosses.projector_spacing:g} mm apart; the axis is "
                f"{profile.crosses.projector_axis_height:g} mm above its top face", in_rig=False)


def camera_cross_hung(profile: Profile, layout: RigLayout) -> Part:
    c = profile.crosses
    top = layout.geometry.vertex_z  # the camera focuses on this cross: it sits at the paraboloid's vertex height
    L, bw = c.arm_length, c.bar_width / 2
    bars = (Box((-L, -bw, top - c.thickness), (L, bw, top)), Box((-bw, -L, top - c.thickness), (bw, L, top)))
    stem = stem_and_clamp(mount(profile, layout, top - c.thickness))
    return Part("camera_cross_hung", Union_((*bars, stem)), (0.9, 0.5, 0.1),
                "camera calibration: cross hung on the beam in place of the paraboloid, at its vertex height",
                in_rig=False)


__all__ = ["camera_cross_hung", "projector_backplate", "projector_cross", "projector_mounting_plate"]
