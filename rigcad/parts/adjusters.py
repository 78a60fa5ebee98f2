"""The tower's adjusters, sized from the tolerance analysis (kernel-free; mm and rad).

Each adjuster moves one thing along one direction; its *range* is how far it moves each way from
the nominal placement and its *resolution* the smallest step a hand sets reliably:

* a screw: its pitch times the fraction of a turn a hand sets with a hex key
  (``adjusters.turn_fraction``, assumed 1/8 turn), over the lever arm it acts on;
* a slot: how finely a hand slides a part against a caliper or a feeler gauge
  (``adjusters.hand_slide``, assumed 0.1 mm);
* a shim stack: the thinnest shim of its bought set (rigcad.parts.tower.fine_shims: stainless shim
  stock between the printed shims, which give the range).

Each serves a tolerance of ``tolerancing`` (the Monte Carlo's placement limits): a setting can be
brought within one step of its target, so the resolution must not exceed the tolerance; and the
range must cover what the datum chain (rigcad.parts.datum) can leave out of place, so that every
rig built within the assumed print accuracy can be aligned.

The splitter's seat is kinematic (Kelvin's cone, vee and flat, rigcad.parts.tower.seat_points):
turning one screw rotates the holder about the line through the other two balls. A tilt delta of
the plate turns the reflected (projector's) axis by 2 delta (the law of reflection), so the
splitter's adjusters serve ``tolerancing.projector_tilt`` through that factor of two.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.parts.datum import datum_chain
from rigcad.parts.tower import fine_shims, projector_screws, seat_points
from rigcad.standards import THREADS



@dataclass(frozen=True)
class Adjuster:
    """One adjuster: what it moves and how, the tolerance it serves (``tolerance_key``, value and
    unit, mm or rad), its range each way and its resolution (same unit), and the range it needs
    (the datum chain's error, or the printed part's)."""

    name: str
    how: str
    tolerance_key: str
    tolerance: float
    unit: str
    range: float
    resolution: float
    needed_range: float

    @property
    def ok(self) -> bool:
        return self.resolution <= self.tolerance and self.range >= self.needed_range

    def describe(self) -> dict:
        scale, unit = (180 / math.pi, "deg") if self.unit == "rad" else (1.0, "mm")
        return {"name": self.name, "how": self.how, "serves": self.tolerance_key,
                f"tolerance_{unit}": self.tolerance * scale, f"range_each_way_{unit}": self.range * scale,
                f"resolution_{unit}": self.resolution * scale, f"needed_range_{unit}": self.needed_range * scale,
                "ok": self.ok}


def _lever(p, a, b) -> float:
    """Distance (mm) from point ``p`` to the line through ``a`` and ``b`` (x, y)."""
    (px, py), (ax, ay), (bx, by) = p, a, b
    return abs((bx - ax) * (ay - py) - (ax - px) * (by - ay)) / math.hypot(bx - ax, by - ay)


def reflected_turn(normal, axis, incoming=(-1.0, 0.0, 0.0)) -> float:
    """How fast (rad per rad) the reflection of the ``incoming`` direction (the projector's axis, -x)
    in a mirror of unit ``normal`` turns when the mirror turns about the unit ``axis``: |dr/d delta|
    with r = d - 2 (d.n) n and dn = axis x n (first order). 2 for an axis in the mirror's plane
    perpendicular to the plane of incidence; 1 for the plate at 45 deg turned about x (the axis
    half along its normal)."""
    n, u, d = (np.asarray(v, float) for v in (normal, axis, incoming))
    dn = np.cross(u / np.linalg.norm(u), n)
    dr = -2 * ((d @ dn) * n + (d @ n) * dn)
    return float(np.linalg.norm(dr))


def splitter_adjusters(profile, layout) -> list[Adjuster]:
    """The seat's three screws: the flat's screw tilts the plate in the plane of incidence (its 45 deg),
    the vee's screw about the other axis; the cone's screw, with both, sets its height. Each turns
    the holder about the line through the other two balls; the projector's axis turns by that times
    :func:`reflected_turn` (2 about the cone-vee line, less about the cone-flat line)."""
    t, a, tol = layout.tower, profile.adjusters, profile.tolerancing
    pts = seat_points(t, profile)
    step = THREADS[a.seat_thread].pitch * a.turn_fraction
    # the printed grooves' angle error: each face print_position off across the plate's length
    groove = 2 * profile.datum.print_position / profile.beam_splitter.length
    out = []
    for screw, (o1, o2), what in (("flat", ("cone", "vee"), "in the plane of incidence (its 45 deg)"),
                                  ("vee", ("cone", "flat"), "across the plane of incidence")):
        arm = _lever(pts[screw], pts[o1], pts[o2])
        (x1, y1), (x2, y2) = pts[o1], pts[o2]
        k = reflected_turn(t.plate.normal, (x2 - x1, y2 - y1, 0.0))
        out.append(Adjuster(
            f"splitter tilt {what}",
            f"{a.seat_thread} x {THREADS[a.seat_thread].pitch:g} mm push screw over the {screw} ball, "
            f"{a.turn_fraction:g} turn, on a {arm:.1f} mm lever; the reflected axis turns {k:.2f} x the plate",
            "tolerancing.projector_tilt", tol.projector_tilt, "rad",
            k * a.seat_travel / arm, k * step / arm, 2 * groove))
    return out


def _slot(name, how, key, tol, travel, need, hand) -> Adjuster:
    return Adjuster(name, how, key, tol, "mm", travel, hand, need)


def slot_adjusters(profile, layout) -> list[Adjuster]:
    """The camera's and projector's slots and shim stacks, against their placement tolerances and
    the datum chain's lateral and vertical errors."""
    t, tw, tol, a = layout.tower, profile.tower, profile.tolerancing, profile.adjusters
    chain = datum_chain(profile, layout)
    lat, vert = chain.lateral_worst, chain.vertical_worst
    shims = t.shims_nominal * tw.shim_thickness
    slot = f"in a slot, set against a caliper or feeler gauge ({a.hand_slide:g} mm)"
    fine = fine_shims(profile)
    stack = (f"{tw.shim_thickness:g} mm printed shims and a bought set of {', '.join(f'{v:g}' for v in fine)} mm "
             "stainless shims")
    return [
        _slot("camera along the axis", "two screws " + slot, "tolerancing.camera_height", tol.camera_height,
              tw.travel_along, vert, a.hand_slide),
        _slot("camera across (x)", "two screws " + slot, "tolerancing.camera_offset", tol.camera_offset,
              tw.travel_across, lat, a.hand_slide),
        _slot("camera across (y)", stack + " between camera and bracket", "tolerancing.camera_offset",
              tol.camera_offset, shims, lat, fine[0]),
        _slot("projector along its axis (its COP along the optical axis)", "four screws " + slot,
              "tolerancing.projector_height", tol.projector_height, tw.travel_along, vert, a.hand_slide),
        _slot("projector across (y)", "four screws " + slot, "tolerancing.projector_offset", tol.projector_offset,
              tw.travel_across, lat, a.hand_slide),
        _slot("projector height (its COP across, x)", stack + " under its four feet", "tolerancing.projector_offset",
              tol.projector_offset, shims, lat, fine[0]),
    ]


def camera_mount_tilt(profile) -> Adjuster:
    """The two-point camera mount: the camera's axis stays within the hand's setting error across the
    two screws' spacing (no pivot); against ``tolerancing.camera_tilt``. Its range is not a travel:
    0 needed, 0 given."""
    cm, a, tol = profile.camera, profile.adjusters, profile.tolerancing
    return Adjuster("camera tilt held by its two screws",
                    f"two {cm.mount_thread} screws {cm.mount_spacing:g} mm apart in one slot, each set to "
                    f"{a.hand_slide:g} mm", "tolerancing.camera_tilt", tol.camera_tilt, "rad", 0.0,
                    a.hand_slide / cm.mount_spacing, 0.0)


def camera_tilt(profile, layout) -> Adjuster:
    """The camera's tilt in its bracket's plane (the x-z plane: where the tower's lean, the column's glue
    faces, the shelf's sag and the camera's two screws all tilt it): the seat's flat screw turns the holder,
    and the camera's bracket on it, about the cone-vee line (along y), so the camera's axis turns as much
    as the holder (once: it looks through the plate, it is not reflected). Range and resolution: the flat
    screw's travel and step over its lever, against ``tolerancing.camera_tilt``; the range it needs is the
    tower's tilt links and the two screws' setting (rigcad.fab.stack reads it as the camera's tilt
    adjuster). Set first, it moves the projector's reflected axis by twice the turn: the projector's own
    tilt then takes that back (:func:`projector_tilt`)."""
    t, a, tol = layout.tower, profile.adjusters, profile.tolerancing
    pts = seat_points(t, profile)
    step = THREADS[a.seat_thread].pitch * a.turn_fraction
    arm = _lever(pts["flat"], pts["cone"], pts["vee"])
    cm = profile.camera
    return Adjuster("camera tilt in its bracket's plane: the seat's flat screw turns the holder and bracket",
                    f"{a.seat_thread} x {THREADS[a.seat_thread].pitch:g} mm push screw over the flat's ball, "
                    f"{a.turn_fraction:g} turn, on a {arm:.1f} mm lever: the holder, its bracket and the camera turn "
                    "together about the cone-vee line; set before the camera's slot and the projector's shims",
                    "tolerancing.camera_tilt", tol.camera_tilt, "rad", a.seat_travel / arm, step / arm,
                    a.hand_slide / cm.mount_spacing)


def projector_tilt(profile, layout) -> Adjuster:
    """The projector's own tilt in the plane of incidence (about y): the bought shims of its near feet's
    stacks against its far feet's (rigcad.parts.tower.fine_shims); its reflected axis turns as much. It
    takes back what the seat's flat screw turned the plate by when it set the camera's tilt
    (:func:`camera_tilt`: twice the camera's turn on the reflected axis). Range: the nominal printed stack
    under one pair of feet against none under the other; resolution: the thinnest bought shim; both over the
    feet's spacing along the projector's axis."""
    t, tw, tol = layout.tower, profile.tower, profile.tolerancing
    xs = sorted({round(x, 9) for x, _ in t.projector_feet})
    span = xs[-1] - xs[0]
    fine = fine_shims(profile)
    return Adjuster("projector tilt in the plane of incidence: its near feet's shims against its far feet's",
                    f"the bought shims ({fine[0]:g} mm the thinnest) of the stacks under its near feet against those "
                    f"under its far feet, {span:.0f} mm apart along its axis; the printed shims for the range",
                    "tolerancing.projector_tilt", tol.projector_tilt, "rad",
                    t.shims_nominal * tw.shim_thickness / span, fine[0] / span,
                    2 * camera_tilt(profile, layout).needed_range)


def paraboloid_roll_needed(profile, layout, position: float) -> float:
    """The paraboloid's roll about its beam that the printed faces it rolls on can leave (rad, worst case)
    when each prints flat to ``position`` mm: the clamp's roof and the beam's underside across the beam's
    width, the seats' floors across the roll bars' lever, the bars' thickness band over that lever, and
    the base plate's flatness (``datum.foot_flatness``) across the flange (rigcad.fab.stack sums the same
    links on a printer's process)."""
    from rigcad.parts.dome import ROLL_BAR, roll_lever

    lever = roll_lever()
    return (2 * position / profile.beam.width + (position + ROLL_BAR.thickness_tolerance) / lever
            + profile.datum.foot_flatness / (2 * layout.flange_outer_r))


def paraboloid_roll(profile, layout) -> Adjuster:
    """The paraboloid's roll about its beam (the y-z plane): shim foil under the roll bars' -y ends against
    their +y ends in both beam seats (rigcad.parts.dome.beam_seats, ROLL_BAR), the thinnest foil over the
    bars' lever, against ``tolerancing.paraboloid_tilt``; the range it needs, the printed faces' roll on the
    profile's print accuracy (``datum.print_position``: :func:`paraboloid_roll_needed`)."""
    from rigcad.parts.dome import beam_seats

    stop = next(s for s in beam_seats(profile, layout).stops() if s.axis == "roll")
    return Adjuster("paraboloid roll about the beam", stop.how, "tolerancing.paraboloid_tilt",
                    profile.tolerancing.paraboloid_tilt, "rad", stop.range, stop.resolution,
                    paraboloid_roll_needed(profile, layout, profile.datum.print_position))


def adjusters(profile, layout) -> list[Adjuster]:
    """Every adjuster of the tower, with its range and resolution against the tolerance it serves, and
    the paraboloid's roll (its one adjuster set by hand that no shim stop of the mount's covers)."""
    return [*splitter_adjusters(profile, layout), *slot_adjusters(profile, layout), camera_tilt(profile, layout),
            projector_tilt(profile, layout), camera_mount_tilt(profile), paraboloid_roll(profile, layout)]


__all__ = ["Adjuster", "adjusters", "camera_mount_tilt", "camera_tilt", "paraboloid_roll", "paraboloid_roll_needed", "projector_tilt", "projector_screws", "slot_adjusters", "splitter_adjusters"]
