"""Calibration crosses (thesis 4.1.1, Figures 4.1, 4.2).

Projector: two crosses and a backplate that catches their shadows, standing in the fences of a
mounting plate that sits on the projector's shelf in the splitter holder's place, when the holder is
lifted off its seat. The crosses define the axis the projector is aligned TO, so the plate registers
on what stays fixed on the shelf: three steel balls pressed into its underside sit on the splitter
seat's cone, vee and flat (rigcad.parts.tower.splitter_seat) exactly where the holder's balls sit,
held there by the fixture's own weight. Nothing adjustable locates it: the focusing lens's mount,
which slides in its slots for focus, is never touched (the plate stops short of its foot at either
end of its travel). Everything about where they stand comes from the tower's layout
(``cross_fixture``): the crosses' centres are on the projector's design axis (its height above the
shelf, its line y = 0), so they fit where the manual puts them by construction. Camera: a cross hung
on the beam in place of the paraboloid (rig frame), and one on the base plate (``base.base_cross``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.parts.layout import RigLayout
from rigcad.parts.paraboloid import mount, stem_and_clamp
from rigcad.parts.joints import Bought
from rigcad.parts.recipe import Box, Cylinder, Difference, Part, Union_
from rigcad.parts.tower import _lens_foot, _shelf_extent, seat_geometry, splitter_seat
from rigcad.profile.schema import Profile

#: A cross's foot (mm): along the axis, across it, thick; wide enough across to stand the cross upright.
FOOT = (12.0, 30.0, 3.0)
FENCE = (2.0, 1.5, 0.2)  # mm: wall, height and clearance of the locating fences on the mounting plate
#: The backplate's wall (mm).
BACKPLATE_WALL = 3.0
#: Plate over each ball's pocket (mm): what is left of the mounting plate above a ball.
PLATE_FLOOR = 3.0
#: Wall (mm) of plate kept round a ball's pocket, out to the plate's side.
BALL_WALL = 2.0
#: Margin (mm) kept between fences, and between a fence and the plate's end.
MARGIN = 2.0
#: Gap (mm) between the plate and what it must not touch: the lens mount's foot at the near end of its
#: slots, and the seat's balls, pins and gauge block under the plate's underside.
GAP = 0.5
#: The fixture's centre of mass must lie this far (mm) inside the triangle of the seat's three
#: contacts, or its weight would not hold the plate on all three (a knock would tip it off one).
TIP_MARGIN = 5.0
#: Depth (mm) of the cross cut into the backplate's face at the axis (the alignment mark).
MARK_DEPTH = 0.6
#: The backplate catches the near cross's shadow with this much to spare.
SHADOW_SPARE = 1.2


@dataclass(frozen=True)
class CrossFixture:
    """Where the projector crosses stand (rig frame, mm): the mounting plate on the splitter seat, the
    splitter holder lifted off; the projector's axis runs along -x at ``axis_z`` on y = 0."""

    plate_x: tuple[float, float]  #: the plate's ends (the shelf's end; short of the lens mount's foot)
    plate_half_width: float
    shelf_top_z: float
    underside_z: float  #: the plate's underside, clear over the seat's cone, vee and flat
    plate_top_z: float
    balls: tuple[tuple[str, float, float], ...]  #: (the seat contact it sits on, x, y) of each ball under the plate
    ball_diameter: float
    ball_centre_z: float  #: the balls' centres, seated: where the holder's balls sit at its nominal setting
    near_x: float  #: the near cross's centre (the projector's side)
    far_x: float
    backplate_x: float  #: the backplate's face (towards the projector)
    backplate_size: float
    axis_z: float  #: the projector's axis
    cop_x: float  #: the projector's real COP
    lens_foot_x: float  #: the lens mount foot's -x face at the near end of its slots

    @property
    def axis_height(self) -> float:
        """The crosses' centres above the plate's top (mm)."""
        return self.axis_z - self.plate_top_z

    @property
    def spacing(self) -> float:
        return self.near_x - self.far_x

    @property
    def backplate_distance(self) -> float:
        """From the far cross to the backplate's face (mm)."""
        return self.far_x - self.backplate_x

    @property
    def projector_distance(self) -> float:
        """From the projector's COP to the near cross (mm)."""
        return self.cop_x - self.near_x


    @property
    def bought(self) -> tuple[Bought, ...]:
        """What the plate needs besides its print: its three balls, as ordered."""
        return (Bought(f"{self.ball_diameter:g} mm steel ball, grade G10", "ISO 3290-1", len(self.balls),
                       {"diameter": self.ball_diameter},
                       "pressed into the crosses' mounting plate's underside (a drop of retaining compound): the plate "
                       "sits on the splitter seat's cone, vee and flat as the holder does"),)


def cross_fixture(profile: Profile, layout: RigLayout) -> CrossFixture:
    """Place the projector crosses on the splitter seat, in the room the splitter holder leaves.

    Three balls in the plate's underside sit on the seat's contacts (rigcad.parts.tower.splitter_seat:
    cone, vee, flat) at the height the holder's balls sit at its nominal setting, so the plate stands
    where the holder stood, on the shelf's fixed hard points; its underside clears the cone's balls,
    the vee's pins and the flat's block by GAP. The plate runs from the shelf's end to GAP short of
    the lens mount's foot at the near end of its slots (``tower.travel_along``): it never touches
    the mount. The backplate stands at the shelf's end, the far cross just in front of it, the near
    cross at the plate's other end; the crosses' centres are on the projector's design axis. Raises
    GeometryError when the room is too short, the axis too low, or the fixture's weight would not
    hold it on all three contacts."""
    t = layout.tower
    if t is None:
        raise GeometryError("the projector crosses stand on the tower's shelf, and this rig has no tower")
    c = profile.crosses
    shelf_x0 = _shelf_extent(t, profile)[0]
    foot_x = _lens_foot(t, profile)[0] - profile.tower.travel_along  # the foot's face at the near end of its slots
    x0, x1 = shelf_x0, foot_x - GAP
    wall, _, fgap = FENCE
    block = FOOT[0] + 2 * (fgap + wall)  # a cross's fence, along x
    back_block = BACKPLATE_WALL + FOOT[0] + 2 * (fgap + wall)
    need = back_block + 2 * block + 4 * MARGIN
    if x1 - x0 < need:
        raise GeometryError(
            f"the projector crosses need {need:.1f} mm of shelf between its end and the lens mount, and there are "
            f"{x1 - x0:.1f} mm; move the lens away from the splitter (lens.distance) or lengthen the crosses' room",
            where=profile.where("lens", "distance"))
    near_x = x1 - MARGIN - block / 2
    back_x = x0 + MARGIN + fgap + wall + FOOT[0] / 2 + BACKPLATE_WALL  # the backplate's face
    far_x = back_x + FOOT[0] / 2 + fgap + wall + MARGIN + block / 2
    axis_z = t.projector_cop[2]
    g = seat_geometry(profile)
    contacts = splitter_seat(profile, layout).contacts
    balls = tuple((k.kind, k.x, k.y) for k in contacts)
    ball_z = contacts[0].ball_z
    stays = max(g.cone_floor + g.ball, g.vee_floor + g.pin, 0.0)  # the cone's balls, the vee's pins, the flat's block
    underside = t.shelf_top_z + stays + GAP
    top = ball_z + g.ball / 2 + PLATE_FLOOR
    if underside >= ball_z:
        raise GeometryError(f"the crosses' plate cannot hold its {g.ball:g} mm balls: the seat's cone and vee stand "
                            f"{stays:.2f} mm over the shelf, above the balls' centres; use larger balls "
                            "(adjusters.seat_ball)", where=profile.where("adjusters", "seat_ball"))
    if axis_z - top < c.arm_length + FENCE[1]:
        raise GeometryError(f"the projector's axis is {axis_z - t.shelf_top_z:.1f} mm above its shelf: too low for "
                            f"crosses of {c.arm_length:g} mm arms on their plate", where=profile.where("crosses", "arm_length"))
    a = t.projector_cop[0] - near_x
    near_arm = c.arm_length * (near_x - back_x + a) / a
    size = 2 * 5.0 * math.ceil(SHADOW_SPARE * near_arm / 5.0)
    reach = max(abs(y) for _, _, y in balls) + g.ball / 2 + BALL_WALL
    half = max(size / 2, FOOT[1] / 2 + fgap + wall, reach) + 5.0
    f = CrossFixture(
        plate_x=(x0, x1), plate_half_width=half, shelf_top_z=t.shelf_top_z, underside_z=underside, plate_top_z=top,
        balls=balls, ball_diameter=g.ball, ball_centre_z=ball_z, near_x=near_x, far_x=far_x, backplate_x=back_x,
        backplate_size=size, axis_z=axis_z, cop_x=t.projector_cop[0], lens_foot_x=foot_x)
    _check_standing(f, profile)
    return f


def centre_of_mass_x(f: CrossFixture, profile: Profile) -> float:
    """Where (x, mm) the fixture's weight acts: the plate, the backplate and the two crosses as the
    boxes they are made of, uniform density (fences and the balls' pockets, small and spread along
    the plate, left out). Every part is symmetric about y = 0, so its y is 0."""
    c = profile.crosses
    bars = (2 * c.arm_length + (f.axis_z + c.arm_length - f.plate_top_z)) * c.bar_width * c.thickness
    cross = bars + FOOT[0] * FOOT[1] * FOOT[2]
    s = f.backplate_size
    backplate = BACKPLATE_WALL * s * (f.axis_z + s / 2 - f.plate_top_z)
    back_foot = (BACKPLATE_WALL + FOOT[0]) * s * FOOT[2]
    plate = (f.plate_x[1] - f.plate_x[0]) * 2 * f.plate_half_width * (f.plate_top_z - f.underside_z)
    parts = ((plate, sum(f.plate_x) / 2), (cross, f.near_x), (cross, f.far_x),
             (backplate, f.backplate_x - BACKPLATE_WALL / 2), (back_foot, f.backplate_x - (BACKPLATE_WALL + FOOT[0]) / 2 + FOOT[0] / 2))
    return sum(v * x for v, x in parts) / sum(v for v, _ in parts)


def _check_standing(f: CrossFixture, profile: Profile) -> None:
    """The fixture's weight (at :func:`centre_of_mass_x`, y = 0) must act TIP_MARGIN inside the
    triangle of the seat's contacts, or it would not rest on all three."""
    x = centre_of_mass_x(f, profile)
    pts = [(bx, by) for _, bx, by in f.balls]
    inside = []
    for (ax, ay), (bx, by) in zip(pts, pts[1:] + pts[:1]):
        n = math.hypot(bx - ax, by - ay)
        inside.append(((bx - ax) * (0.0 - ay) - (by - ay) * (x - ax)) / n)  # signed distance to each side
    if not (all(d >= TIP_MARGIN for d in inside) or all(d <= -TIP_MARGIN for d in inside)):
        raise GeometryError(f"the projector crosses' fixture weighs on the splitter seat at x = {x:.1f} mm, not "
                            f"{TIP_MARGIN:g} mm inside its cone, vee and flat: it would tip off one; shorten the crosses' "
                            "arms (crosses.arm_length)", where=profile.where("crosses", "arm_length"))


def _foot(xc: float, z: float, length: float = FOOT[0]) -> Box:
    return Box((xc - length / 2, -FOOT[1] / 2, z), (xc + length / 2, FOOT[1] / 2, z + FOOT[2]))


def projector_cross(profile: Profile, layout: RigLayout) -> Part:
    """The near cross in place (the far one is the same part, ``CrossFixture.spacing`` nearer the
    backplate): its centre on the projector's axis."""
    f = cross_fixture(profile, layout)
    c = profile.crosses
    x, z0, bw, t, L = f.near_x, f.plate_top_z, c.bar_width / 2, c.thickness / 2, c.arm_length
    horizontal = Box((x - t, -L, f.axis_z - bw), (x + t, L, f.axis_z + bw))
    vertical = Box((x - t, -bw, z0), (x + t, bw, f.axis_z + L))  # also the post down to the foot
    return Part("projector_cross", Union_((horizontal, vertical, _foot(x, z0))), (0.9, 0.5, 0.1),
                f"projector calibration cross (print 2): its centre {f.axis_height:.1f} mm above the mounting plate, "
                f"on the projector's axis; they stand {f.spacing:.1f} mm apart in the plate's fences",
                quantity=2, in_rig=False, shaped_by=("crosses.arm_length", "crosses.bar_width", "crosses.thickness"))


def projector_backplate(profile: Profile, layout: RigLayout) -> Part:
    """The backplate at the shelf's end, a cross cut into its face where the axis meets it."""
    f = cross_fixture(profile, layout)
    s, z0, x = f.backplate_size, f.plate_top_z, f.backplate_x
    w = profile.crosses.bar_width / 2
    plate = Box((x - BACKPLATE_WALL, -s / 2, z0), (x, s / 2, f.axis_z + s / 2))
    foot = Box((x - BACKPLATE_WALL - FOOT[0] / 2, -s / 2, z0), (x + FOOT[0] / 2, s / 2, z0 + FOOT[2]))
    mark = (Box((x - MARK_DEPTH, -s / 2 + 5.0, f.axis_z - w / 2), (x + 1.0, s / 2 - 5.0, f.axis_z + w / 2)),
            Box((x - MARK_DEPTH, -w / 2, f.axis_z - s / 2 + 5.0), (x + 1.0, w / 2, f.axis_z + s / 2 - 5.0)))
    return Part("projector_backplate", Difference(Union_((plate, foot)), mark), (0.95, 0.95, 0.95),
                "backplate catching the projector crosses' shadows, a cross cut into its face on the projector's "
                "axis (aligned when the two shadows coincide on it)", in_rig=False)


def _footprints(f: CrossFixture) -> list[tuple[float, float, float, float]]:
    """(x0, x1, y0, y1) of every foot standing on the mounting plate: two crosses, the backplate."""
    feet = [(x - FOOT[0] / 2, x + FOOT[0] / 2, -FOOT[1] / 2, FOOT[1] / 2) for x in (f.far_x, f.near_x)]
    s = f.backplate_size
    feet.append((f.backplate_x - BACKPLATE_WALL - FOOT[0] / 2, f.backplate_x + FOOT[0] / 2, -s / 2, s / 2))
    return feet


def projector_mounting_plate(profile: Profile, layout: RigLayout) -> Part:
    """The plate the projector crosses and the backplate stand on, set on the splitter seat in the
    holder's place: three ball pockets in its underside (the balls pressed in sit on the seat's cone,
    vee and flat), fences on its top that locate the feet on the projector's axis."""
    f = cross_fixture(profile, layout)
    wall, height, gap = FENCE
    (x0, x1), hy, z0, z1 = f.plate_x, f.plate_half_width, f.underside_z, f.plate_top_z
    plate = Box((x0, -hy, z0), (x1, hy, z1))
    r = f.ball_diameter / 2
    pockets = tuple(Cylinder((x, y, z0 - 1.0), r, f.ball_centre_z + r - z0 + 1.0) for _, x, y in f.balls)
    fences = tuple(
        Difference(Box((a - gap - wall, b0 - gap - wall, z1), (b + gap + wall, b1 + gap + wall, z1 + height)),
                   (Box((a - gap, b0 - gap, z1 - 1.0), (b + gap, b1 + gap, z1 + height + 1.0)),))
        for a, b, b0, b1 in _footprints(f))
    return Part("projector_mounting_plate", Difference(Union_((plate, *fences)), pockets), (0.55, 0.57, 0.6),
                "mounting plate for the projector crosses and backplate, set on the splitter seat in the holder's place: "
                f"the {len(f.balls)} balls of the calibration kit ({f.ball_diameter:g} mm steel) pressed into its underside sit on the seat's cone, vee "
                f"and flat; fences place the crosses on the projector's axis, {f.spacing:.1f} mm apart; the axis is "
                f"{f.axis_height:.1f} mm above its top face", in_rig=False)


def camera_cross_hung(profile: Profile, layout: RigLayout) -> Part:
    c = profile.crosses
    top = layout.geometry.vertex_z  # the camera focuses on this cross: it sits at the paraboloid's vertex height
    L, bw = c.arm_length, c.bar_width / 2
    bars = (Box((-L, -bw, top - c.thickness), (L, bw, top)), Box((-bw, -L, top - c.thickness), (bw, L, top)))
    stem = stem_and_clamp(mount(profile, layout, top - c.thickness))
    return Part("camera_cross_hung", Union_((*bars, stem)), (0.9, 0.5, 0.1),
                "camera calibration: cross hung on the beam in place of the paraboloid, at its vertex height",
                in_rig=False)


__all__ = ["CrossFixture", "camera_cross_hung", "centre_of_mass_x", "cross_fixture", "projector_backplate", "projector_cross",
           "projector_mounting_plate"]
