"""Calibration crosses (thesis 4.1.1, Figures 4.1, 4.2).

Projector: two crosses and a backplate that catches their shadows, standing in the fences of a
mounting plate that lies on the projector's shelf, in the room the splitter holder leaves when it is
lifted off its seat: from the shelf's end to the focusing lens's mount. Everything about where they
stand comes from the tower's layout (``cross_fixture``): the crosses' centres are on the projector's
axis (its height above the shelf, its line y = 0), so they fit where the manual puts them by
construction. Camera: a cross hung on the beam in place of the paraboloid (rig frame), and one on
the base plate (``base.base_cross``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.parts.layout import RigLayout
from rigcad.parts.paraboloid import mount, stem_and_clamp
from rigcad.parts.recipe import Box, Difference, Part, Union_
from rigcad.parts.tower import _lens_foot, _shelf_extent, seat_gap, seat_points
from rigcad.profile.schema import Profile

#: A cross's foot (mm): along the axis, across it, thick; wide enough across to stand the cross upright.
FOOT = (12.0, 30.0, 3.0)
FENCE = (2.0, 1.5, 0.2)  # mm: wall, height and clearance of the locating fences on the mounting plate
#: The backplate's wall (mm).
BACKPLATE_WALL = 3.0
#: Plate under the seat's pocket (mm): what is left of the mounting plate over the splitter seat.
PLATE_FLOOR = 3.0
#: Margin (mm) kept between fences, and between a fence and the plate's end.
MARGIN = 2.0
#: Gap (mm) between the plate's end and the lens mount's foot, and around the pocket over the seat.
GAP = 0.5
#: The tabs that locate the plate across the axis on the lens mount's foot (mm): wall, reach along x.
TAB = (3.0, 6.0)
#: Depth (mm) of the cross cut into the backplate's face at the axis (the alignment mark).
MARK_DEPTH = 0.6
#: The backplate catches the near cross's shadow with this much to spare.
SHADOW_SPARE = 1.2


@dataclass(frozen=True)
class CrossFixture:
    """Where the projector crosses stand (rig frame, mm): the mounting plate on the shelf, the
    splitter holder lifted off; the projector's axis runs along -x at ``axis_z`` on y = 0."""

    plate_x: tuple[float, float]  #: the plate's ends (the shelf's end, the lens mount's foot)
    plate_half_width: float
    shelf_top_z: float  #: the plate's underside
    plate_top_z: float
    pocket_x: tuple[float, float]  #: the pocket over the splitter seat (its balls stay on the shelf)
    pocket_half_width: float
    pocket_depth: float
    tab_y: tuple[float, float]  #: inner, outer |y| of the tabs either side of the lens mount's foot
    near_x: float  #: the near cross's centre (the projector's side)
    far_x: float
    backplate_x: float  #: the backplate's face (towards the projector)
    backplate_size: float
    axis_z: float  #: the projector's axis
    cop_x: float  #: the projector's real COP

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


def cross_fixture(profile: Profile, layout: RigLayout) -> CrossFixture:
    """Place the projector crosses in the room the splitter holder leaves on the shelf.

    The plate runs from the shelf's end to the lens mount's foot (it is pushed against the foot, and
    two tabs either side of the foot centre it on y = 0); a pocket in its underside clears the
    splitter seat's balls (as high as the holder's own gap over the shelf); the backplate stands at
    the shelf's end, the far cross just in front of it, the near cross at the lens mount's end. The
    crosses' centres are on the projector's axis. Raises GeometryError when the room is too short."""
    t = layout.tower
    if t is None:
        raise GeometryError("the projector crosses stand on the tower's shelf, and this rig has no tower")
    c = profile.crosses
    shelf_x0 = _shelf_extent(t, profile)[0]
    foot_x0, _, foot_hy, _ = _lens_foot(t, profile)
    x0, x1 = shelf_x0, foot_x0 - GAP
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
    pocket_depth = seat_gap(profile)
    top = t.shelf_top_z + pocket_depth + PLATE_FLOOR
    if axis_z - top < c.arm_length + FENCE[1]:
        raise GeometryError(f"the projector's axis is {axis_z - t.shelf_top_z:.1f} mm above its shelf: too low for "
                            f"crosses of {c.arm_length:g} mm arms on their plate", where=profile.where("crosses", "arm_length"))
    xs, ys = zip(*seat_points(t, profile).values())
    reach = 2 * profile.adjusters.seat_ball + GAP  # what the seat puts on the shelf around each point
    a = t.projector_cop[0] - near_x
    near_arm = c.arm_length * (near_x - back_x + a) / a
    size = 2 * 5.0 * math.ceil(SHADOW_SPARE * near_arm / 5.0)
    half = max(size / 2, FOOT[1] / 2 + fgap + wall, foot_hy + TAB[0] + fgap) + 5.0
    return CrossFixture(
        plate_x=(x0, x1), plate_half_width=half, shelf_top_z=t.shelf_top_z, plate_top_z=top,
        pocket_x=(max(x0 - 1.0, min(xs) - reach), min(x1 + 1.0, max(xs) + reach)),
        pocket_half_width=min(half - wall, max(abs(y) for y in ys) + reach), pocket_depth=pocket_depth,
        tab_y=(foot_hy + fgap, foot_hy + fgap + TAB[0]), near_x=near_x, far_x=far_x, backplate_x=back_x,
        backplate_size=size, axis_z=axis_z, cop_x=t.projector_cop[0])


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
    """The plate the projector crosses and the backplate stand on, laid on the shelf in the splitter
    holder's place: fences locate their feet on the projector's axis, a pocket in its underside clears
    the seat, and two tabs either side of the lens mount's foot centre it across the axis."""
    f = cross_fixture(profile, layout)
    wall, height, gap = FENCE
    (x0, x1), hy, z0, z1 = f.plate_x, f.plate_half_width, f.shelf_top_z, f.plate_top_z
    plate = Box((x0, -hy, z0), (x1, hy, z1))
    (ty0, ty1), tx = f.tab_y, x1 + GAP + TAB[1]
    tabs = (Box((x1, ty0, z0), (tx, ty1, z1)), Box((x1, -ty1, z0), (tx, -ty0, z1)))
    pocket = Box((f.pocket_x[0], -f.pocket_half_width, z0 - 1.0), (f.pocket_x[1], f.pocket_half_width, z0 + f.pocket_depth))
    fences = tuple(
        Difference(Box((a - gap - wall, b0 - gap - wall, z1), (b + gap + wall, b1 + gap + wall, z1 + height)),
                   (Box((a - gap, b0 - gap, z1 - 1.0), (b + gap, b1 + gap, z1 + height + 1.0)),))
        for a, b, b0, b1 in _footprints(f))
    return Part("projector_mounting_plate", Difference(Union_((plate, *tabs, *fences)), (pocket,)), (0.55, 0.57, 0.6),
                "mounting plate for the projector crosses and backplate, laid on the shelf in the splitter holder's "
                f"place against the lens mount's foot: fences place them on the projector's axis, {f.spacing:.1f} mm "
                f"apart; the axis is {f.axis_height:.1f} mm above its top face", in_rig=False)


def camera_cross_hung(profile: Profile, layout: RigLayout) -> Part:
    c = profile.crosses
    top = layout.geometry.vertex_z  # the camera focuses on this cross: it sits at the paraboloid's vertex height
    L, bw = c.arm_length, c.bar_width / 2
    bars = (Box((-L, -bw, top - c.thickness), (L, bw, top)), Box((-bw, -L, top - c.thickness), (bw, L, top)))
    stem = stem_and_clamp(mount(profile, layout, top - c.thickness))
    return Part("camera_cross_hung", Union_((*bars, stem)), (0.9, 0.5, 0.1),
                "camera calibration: cross hung on the beam in place of the paraboloid, at its vertex height",
                in_rig=False)


__all__ = ["CrossFixture", "camera_cross_hung", "cross_fixture", "projector_backplate", "projector_cross",
           "projector_mounting_plate"]
