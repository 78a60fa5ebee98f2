"""Whether the COP tower's shelf can carry the projector by its own mounting holes.

The projector stands on a stack of shims at each of its mounting holes (``projector.mount_holes``,
rigcad.profile.instruments.mount_pattern: each hole along its optical axis back from its COP and
across it), held by a screw up from under the shelf through a slot that lets the hole move by
``tower.travel_along`` along the axis and ``tower.travel_across`` across it (rigcad.parts.tower). The
shelf carries a pattern when:

* it has at least three holes not in one line: the body rests on three stacks or more and cannot
  rock (a hole at least MIN_OFF_LINE off the line through the two farthest apart);
* every hole lies on the body's bottom face, its clearance hole's radius in from the edges;
* no two shim stacks overlap (holes at least SHIM_SIDE apart along or across);
* under the shelf, each slot's screw head and washers, anywhere over the slot's travel, clear the
  column's top flange and the bundle's hole by ``tower.clearance`` and stay on the shelf; on top,
  each shim stack, anywhere over the travel, clears the lens mount's foot.

:func:`check_mount` raises a GeometryError naming ``projector.mount_holes``, the file:line that set it
(or that the pattern is the assumed one), the hole and the valid range. Frame: rig frame, mm (the
projector looks -x; across is +y).
"""

from __future__ import annotations

import math

from rigcad.errors import GeometryError
from rigcad.parts.tower import SHIM_SIDE, _lens_foot, _shelf_extent, clearance_hole, joint_washers
from rigcad.profile.instruments import mount_pattern

#: A hole must stand this far (mm) off the line through the two farthest apart for the body to rest
#: on its stacks without rocking about that line: a third of a shim's side.
MIN_OFF_LINE = SHIM_SIDE / 3


def _where(profile) -> str | None:
    return profile.where("projector", "mount_holes")


def _fail(profile, message: str) -> GeometryError:
    assumed = profile.set_by("projector", "mount_holes") == "default"
    hint = " (the assumed pattern: measure yours and set projector.mount_holes)" if assumed else ""
    return GeometryError(f"projector.mount_holes: {message}{hint}", where=_where(profile), param="projector.mount_holes")


def _rect_overlap(a, b) -> bool:
    """Open rectangles (x0, x1, y0, y1) overlap."""
    return a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]


def _rect_circle(rect, cx: float, cy: float, r: float) -> bool:
    """Rectangle (x0, x1, y0, y1) and circle overlap."""
    dx = max(rect[0] - cx, 0.0, cx - rect[1])
    dy = max(rect[2] - cy, 0.0, cy - rect[3])
    return dx * dx + dy * dy < r * r


def check_mount(profile, tower) -> None:
    """Raise GeometryError (module docstring) when the shelf of ``tower`` (a TowerLayout) cannot carry
    the projector's mounting pattern."""
    pj, tw = profile.projector, profile.tower
    holes = mount_pattern(pj)
    feet = list(tower.projector_feet)
    n = len(feet)
    if n < 3:
        raise _fail(profile, f"{n} hole{'s' if n != 1 else ''}; the projector stands on a shim stack at each hole "
                             "and needs at least three, not in one line")
    (i, j) = max(((a, b) for a in range(n) for b in range(a + 1, n)),
                 key=lambda ab: math.dist(feet[ab[0]], feet[ab[1]]))
    (x0, y0), (x1, y1) = feet[i], feet[j]
    span = math.dist(feet[i], feet[j])
    off = max(abs((x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)) / span for x, y in feet) if span > 0 else 0.0
    if off < MIN_OFF_LINE:
        raise _fail(profile, f"the holes lie within {off:.1f} mm of one line; at least one must stand "
                             f"{MIN_OFF_LINE:g} mm off it, or the body rocks on its stacks")
    r = clearance_hole(pj.mount_thread) / 2
    back = pj.lens_length - pj.pupil_depth
    left = -pj.pupil_lateral - pj.body_width / 2
    along = (back + r, back + pj.body_depth - r)
    across = (left + r, left + pj.body_width - r)
    for k, (a, c) in enumerate(holes):
        if not (along[0] <= a <= along[1] and across[0] <= c <= across[1]):
            raise _fail(profile, f"hole {k + 1} at [{a:g}, {c:g}] mm is not on the body's bottom face; valid: along "
                                 f"{along[0]:.1f}..{along[1]:.1f} mm, across {across[0]:.1f}..{across[1]:.1f} mm "
                                 "(projector.body_depth, body_width, lens_length, pupil_depth, pupil_lateral)")
    for a in range(n):
        for b in range(a + 1, n):
            if abs(feet[a][0] - feet[b][0]) < SHIM_SIDE and abs(feet[a][1] - feet[b][1]) < SHIM_SIDE:
                raise _fail(profile, f"holes {a + 1} and {b + 1} are closer than a shim's side ({SHIM_SIDE:g} mm) both "
                                     "along and across: their shim stacks would overlap; valid: at least "
                                     f"{SHIM_SIDE:g} mm apart along or across")
    washer = max(w.outer for w in joint_washers(profile, _Layout(tower))["projector"].washers) / 2
    head = (tw.travel_along + washer, tw.travel_across + washer)
    fh = tower.column_foot_half
    flange = (tower.column_x - fh - tw.clearance, tower.column_x + fh + tw.clearance, -fh - tw.clearance,
              fh + tw.clearance)
    sx0, sx1, sy0, sy1 = _shelf_extent(tower, profile)
    lx0, lx1, lhy, _ = _lens_foot(tower, profile)
    lens = (lx0 - tw.clearance, lx1 + tw.clearance, -lhy - tw.clearance, lhy + tw.clearance)
    stack = (tw.travel_along + SHIM_SIDE / 2, tw.travel_across + SHIM_SIDE / 2)
    for k, (x, y) in enumerate(feet):
        under = (x - head[0], x + head[0], y - head[1], y + head[1])
        at = f"hole {k + 1} at [{holes[k][0]:g}, {holes[k][1]:g}] mm"
        if _rect_overlap(under, flange):
            raise _fail(profile, f"{at}: its screw's head and washers under the shelf ({2 * washer:.0f} mm across, "
                                 f"+-{tw.travel_along:g} mm along) would meet the column's top flange (x = "
                                 f"{flange[0] + tw.clearance:.1f}..{flange[1] - tw.clearance:.1f} mm); valid: along at most "
                                 f"{flange[0] - head[0] - tower.projector_cop[0]:.1f} mm, or across beyond "
                                 f"+-{fh + tw.clearance + head[1]:.1f} mm")
        if _rect_circle(under, 0.0, 0.0, tower.bundle_radius_at_shelf + tw.clearance):
            raise _fail(profile, f"{at}: its screw's head and washers would reach into the shelf's hole for the ray "
                                 f"bundle (radius {tower.bundle_radius_at_shelf:.1f} mm about the optical axis)")
        if not (sx0 + tw.wall <= under[0] and under[1] <= sx1 - tw.wall and sy0 + tw.wall <= under[2]
                and under[3] <= sy1 - tw.wall):
            raise _fail(profile, f"{at}: its slot and washers (+-{head[0]:.1f} x +-{head[1]:.1f} mm) would run off the "
                                 f"shelf (x = {sx0:.1f}..{sx1:.1f} mm, y = {sy0:.1f}..{sy1:.1f} mm)")
        if _rect_overlap((x - stack[0], x + stack[0], y - stack[1], y + stack[1]), lens):
            raise _fail(profile, f"{at}: its shim stack ({SHIM_SIDE:g} mm square, +-{tw.travel_along:g} mm along) "
                                 f"would stand on the lens mount's foot (x = {lx0:.1f}..{lx1:.1f} mm)")


class _Layout:
    """The little of a RigLayout that rigcad.parts.tower.joint_washers reads: its ``tower``."""

    def __init__(self, tower) -> None:
        self.tower = tower


__all__ = ["MIN_OFF_LINE", "check_mount"]
