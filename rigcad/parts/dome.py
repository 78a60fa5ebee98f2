"""The dome (thesis 3.1, 3.4): the integrated profile revolved, printed behind the coating, with a
wall, a bolted base flange, the slots the mounting beam passes through, and the beam's two seats.

Each seat is a block standing on the flange outside the wall at a slot, within the flange's radius
(the dome's footprint on a bed does not grow): the beam passes through its tunnel and rests on a
bought steel roll bar (:data:`ROLL_BAR`) laid across it in a wide slot at the tunnel's bottom, the bar on
two packs of shim foil on the slot's floor, one under each of its ends; a set screw in the roof presses
the beam onto the bar's middle and the bar onto both packs, and a set screw in the +y wall the beam
against the tunnel's -y wall (heat-set inserts take both; the side screw only snug, so that it does not
roll the beam off the bar). The bars' packs together set the paraboloid's height, one seat's
against the other's its tilt along the beam, and the -y ends' packs against the +y ends' its roll about the
beam, over the bar's lever (:func:`roll_lever`) rather than the beam's narrow width, which is too short for
the thinnest foil to step a quarter of ``tolerancing.paraboloid_tilt`` (rigcad.parts.locating.ShimStop).
The bars stand outside the dome's mirror, as the seats do: the light inside it never reaches them, so
the beam inside the dome stays as narrow as the thesis hangs the paraboloid on.

The dome is centred on the sample bore by indicating it in, and its register is then drilled in place
(rigcad.parts.locating): a dial test indicator on an arm turning in the bore sweeps the mirror's
lower edge; the flange's bolt holes leave it :data:`INDICATE_TRAVEL_MM` of travel each way for that."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from rigcad.errors import GeometryError
from rigcad.parts.joints import ScrewJoint, datums_of
from rigcad.parts.locating import (INDICATOR_MM, PRESS_IN_COMPOUND, SHIM_PACK_MM, DowelRegister, ShimStop, bolt_hole, foil_step,
                                   holder_fit, reamers, set_screw_length, stepped_hole, teardrop_along_y)
from rigcad.parts.layout import RigLayout, u_at_height
from rigcad.parts.washers import on_limiter
from rigcad.parts.recipe import Box, Curve, Cylinder, Difference, Line, Part, Revolve, Section, Union_
from rigcad.profile.schema import Profile
from rigcad.standards import INSERTS, THREADS, thread_for_hole

#: How far the dome may be moved on the base plate each way when it is indicated in from the sample
#: bore (mm): its flange's bolt holes leave this much beyond the print's errors. It covers the base
#: plate's print errors and glue seams between its bore and its inserts (0.81 mm worst case on the
#: MK3S by rigcad.fab.stack's estimate; the stack refuses a printer whose seams need more).
INDICATE_TRAVEL_MM = 1.0
#: The seats' set screws' thread (heat-set inserts in the seats' roofs and +y walls).
SEAT_SCREW = "M3"
#: The least radial depth of a seat (mm): room for its set screws' inserts (a 4 mm hole, 4.6 mm over
#: the knurl) and 2 mm walls.
SEAT_DEPTH_MM = 9.0  # also holds the roll bar's 8 mm width (ROLL_BAR)


@dataclass(frozen=True)
class RollBar:
    """A bought flat bar laid across the beam in a seat (mm): ``width`` along the beam (x),
    ``thickness`` (z), ``length`` across it (y); ``thickness_tolerance``: the bar's thickness band
    (its two ends differ by at most this); ``pad``: the width of the foil strip under each end."""

    name: str
    width: float
    thickness: float
    length: float
    thickness_tolerance: float
    pad: float


#: The seats' roll bars: bright drawn steel flat bar 8 x 3 mm (EN 10278, thickness h11: 0/-0.060 mm at
#: 3 mm, ISO 286-2 IT11 up to 3 mm), cut 30 mm long, each end on a 4 mm wide strip of foil.
ROLL_BAR = RollBar("bright steel flat bar 8 x 3 mm (EN 10278, h11)", 8.0, 3.0, 30.0, 0.060, 4.0)


def roll_lever() -> float:
    """The roll bar's lever (mm): between the middles of the foil strips under its two ends."""
    return ROLL_BAR.length - ROLL_BAR.pad


def _pt(m, u) -> tuple[float, float]:
    return tuple(float(v) for v in m.points(np.array([u]))[0])


def flange_joint(profile: Profile, layout: RigLayout) -> ScrewJoint:
    """The dome's flange on the base plate: ``dome_shell.bolts`` screws on the flange's bolt circle,
    down through the flange into heat-set inserts in the plate (the plate stands on the bench: no
    nut fits under it); the thread is the largest whose clearance hole is ``dome_shell.bolt_diameter``.
    The joint locates the dome, a datum, so each bolt runs through a steel compression limiter
    (rigcad.parts.joints: the sleeve stands on the insert's top, the flange keeps only its squeeze)."""
    shell = profile.dome_shell
    try:
        thread = thread_for_hole(shell.bolt_diameter).name
    except ValueError as err:
        raise GeometryError(str(err), where=profile.where("dome_shell", "bolt_diameter")) from err
    r = layout.bolt_circle_r
    points = tuple((r * math.cos(a), r * math.sin(a)) for a in layout.bolt_angles)
    return ScrewJoint("dome_flange", "dome", "base_plate", thread, points, (0.0, shell.flange_thickness),
                      (-profile.base_plate.thickness, 0.0), "insert", "dome_shell.bolt_diameter", datum=True,
                      limiter=True)


def _pins(layout: RigLayout) -> tuple[tuple[float, float], tuple[float, float]]:
    """The register's pins (x, y; mm): the round hole's at +y, the slot's at -y, on the bolt circle
    (clear of the beam's seats at +-x, which stand over the flange there)."""
    r = layout.bolt_circle_r
    return (0.0, r), (0.0, -r)


def register(profile: Profile, layout: RigLayout) -> DowelRegister:
    """The dome's register on the base plate: two ``datum.dowel_diameter`` pins pressed into the plate
    on the y axis at the bolt circle (the bolts stand half a pitch off it), the round hole at +y, the
    slot at -y (along y: it takes the print's scale error over the flange's width). It is drilled in
    place: the dome is indicated in from the sample bore first, then the plate is drilled and reamed
    through the flange's hole and slot. The dome lifts off and goes back on the pins: the calibration
    screens go in on the plate while it is off."""
    shell, d = profile.dome_shell, profile.datum
    pins = _pins(layout)
    slot = 2 * (2 * d.print_position + d.print_scale * 2 * layout.bolt_circle_r)
    reg = DowelRegister("dome_register", "dome", "base_plate", d.dowel_diameter, pins,
                        (0.0, shell.flange_thickness), (-profile.base_plate.thickness, 0.0), slot,
                        "datum.dowel_diameter", drilled=True)
    bolt_r = flange_bolt_hole(profile, layout) / 2
    for x, y in flange_joint(profile, layout).points:
        for (px, py) in reg.points:
            gap = math.hypot(x - px, y - py) - bolt_r - d.dowel_diameter / 2 - slot / 2
            if gap < profile.tower.wall:
                raise GeometryError(f"the dome's register pin at ({px:.1f}, {py:.1f}) mm comes within {gap:.1f} mm of a "
                                    f"flange bolt: fewer bolts (dome_shell.bolts) or thinner pins (datum.dowel_diameter)",
                                    where=profile.where("dome_shell", "bolts"))
    return replace(reg, procedure=indicating_text(profile, layout, reg))


def flange_bolt_room(profile: Profile, layout: RigLayout) -> float:
    """The room each flange bolt needs (mm): ``dome_shell.bolt_diameter``, opened where the print's
    errors need it (rigcad.parts.locating.bolt_hole, at the farthest bolt from the register's round pin),
    and by :data:`INDICATE_TRAVEL_MM` each way, so that the dome can be indicated in from the bore: the
    register locates the dome, the bolts only clamp it. The hole is wider by the compression limiter's
    walls (:func:`flange_bolt_hole`)."""
    d = profile.datum
    joint = flange_joint(profile, layout)
    (px, py) = _pins(layout)[0]
    far = max(math.hypot(x - px, y - py) for x, y in joint.points)
    printed = max(profile.dome_shell.bolt_diameter, bolt_hole(joint.thread, far, d.print_position, d.print_scale))
    return printed + 2 * INDICATE_TRAVEL_MM


def flange_bolt_hole(profile: Profile, layout: RigLayout) -> float:
    """The flange's bolt holes as drawn (mm): the bolt's room (:func:`flange_bolt_room`) widened by the
    compression limiter's walls (ScrewJoint.clearance_holes: the sleeve rides on the bolt and keeps that
    room around it). GeometryError, naming ``dome_shell.flange_width``, when the hole or the washer over it
    (:func:`flange_washers`) leaves the flange under 1 mm of material at its wall or its rim."""
    joint = flange_joint(profile, layout)
    hole = 2 * joint.clearance_holes(flange_bolt_room(profile, layout))[0].radius
    washer = on_limiter(joint.thread, hole, joint.limiter_part, joint.param).bearing.outer
    r, need = layout.bolt_circle_r, max(hole, washer) / 2 + 1.0
    if r - need < layout.flange_inner_r or r + need > layout.flange_outer_r:
        raise GeometryError(f"the dome's flange ({layout.flange_inner_r:.1f} to {layout.flange_outer_r:.1f} mm) leaves "
                            f"under 1 mm round its {hole:.2f} mm bolt holes (a {joint.limiter_part.outer:g} mm "
                            f"compression limiter in each) and their {washer:g} mm washers on the {r:.1f} mm bolt "
                            f"circle: widen dome_shell.flange_width to {2 * need + 1.0:.0f} mm or more",
                            where=profile.where("dome_shell", "flange_width"))
    return hole


def flange_washers(profile: Profile, layout: RigLayout):
    """The washer under each flange bolt's head (rigcad.parts.washers.on_limiter: the bolt's own large
    washer, seated all round on its compression limiter, over the opened hole)."""
    joint = flange_joint(profile, layout)
    return on_limiter(joint.thread, flange_bolt_hole(profile, layout), joint.limiter_part, joint.param)


def indicate_travel(profile: Profile, layout: RigLayout, shrink: float = 0.0) -> float:
    """How far the dome can be moved on the plate each way when indicated in (mm): the bolt holes'
    room round the compression limiters (the holes printed ``shrink`` mm under their drawn size) less
    what the print's errors already take."""
    d = profile.datum
    joint = flange_joint(profile, layout)
    (px, py) = _pins(layout)[0]
    far = max(math.hypot(x - px, y - py) for x, y in joint.points)
    used = bolt_hole(joint.thread, far, d.print_position, d.print_scale) - THREADS[joint.thread].major
    return max(0.0, (flange_bolt_hole(profile, layout) - shrink - joint.limiter_part.outer - used) / 2)


def indicating(profile: Profile, layout: RigLayout) -> ShimStop:
    """The dome's centring as the tolerance stack reads it: indicated in from the bore to the dial
    indicator's graduation and held there by the register drilled in place (its pins' fit), over
    :func:`indicate_travel` each way."""
    return ShimStop("dome indicated in from the sample bore, its register drilled in place", "dome", "lateral",
                    indicate_travel(profile, layout), INDICATOR_MM + register(profile, layout).repeatability[0], 0.0,
                    f"a dial test indicator ({INDICATOR_MM:g} mm) on an arm turning in the sample bore sweeps the "
                    "mirror's lower edge; tap the dome over until it reads within one graduation all round, bolt it, "
                    "drill and ream the plate through the flange's round hole and slot, press the pins in")


@dataclass(frozen=True)
class BeamSeats:
    """The beam's two seats on the dome (mm, rig frame): the ``blocks`` (one at +x, one at -x), the
    ``tunnels`` the beam passes through, the set screws' insert ``pockets`` and bores, the screws'
    length (ISO 4026), where the screws press (``x``, each side), the seats' ``span`` (between the
    screws), the pack under each end of each roll bar (``pack``) and the ``bars`` at the design setting
    (:data:`ROLL_BAR`, across the beam under it)."""

    blocks: tuple[Box, Box]
    tunnels: tuple[Box, Box]
    pockets: tuple
    screw_length: int
    x: float
    span: float
    pack: float
    bars: tuple[Box, Box]
    #: How far the beam can roll in its tunnels before its section's corners meet both walls (rad).
    roll_room: float

    def stops(self) -> tuple[ShimStop, ShimStop, ShimStop]:
        """Height (every pack alike), tilt along the beam (one seat's packs against the other's) and roll
        about the beam (the roll bars' -y ends' packs against their +y ends', both seats alike)."""
        step, lever = foil_step(), roll_lever()
        return (ShimStop("paraboloid height: shim foil under the roll bars in both seats", "paraboloid", "vertical",
                         self.pack, step / 2, self.pack,
                         f"{self.pack:g} mm of foil under each end of each seat's roll bar at the design setting; a "
                         "change at one seat moves the paraboloid half as much"),
                ShimStop("paraboloid tilt along the beam: shim foil under one seat's roll bar against the other's",
                         "paraboloid", "tilt", 2 * self.pack / self.span, step / self.span, self.pack,
                         f"foil taken from one seat and added to the other over the {self.span:.0f} mm between "
                         "their screws"),
                ShimStop("paraboloid roll about the beam: shim foil under the roll bars' -y ends against their +y ends",
                         "paraboloid", "roll", min(2 * self.pack / lever, self.roll_room), step / lever, self.pack,
                         f"foil taken from under one end of both seats' roll bars and added under the other ends, "
                         f"over the bars' {lever:g} mm lever ({ROLL_BAR.name}, {ROLL_BAR.length:g} mm long, across "
                         "the beam; the beam's section rolls at most "
                         f"{math.degrees(self.roll_room):.1f} deg in its tunnels)"))


def seat_top(profile: Profile, beam_top: float) -> float:
    """The beam seats' top (mm above the plate) for a beam whose top is at ``beam_top``: the roof's
    shim pack and clearance over the beam, and the roof's insert under it (the optimiser's fast
    outline reads it too: rigcad.optimize.fast)."""
    return beam_top + SHIM_PACK_MM + profile.dome_shell.slot_clearance + INSERTS[SEAT_SCREW].pocket_depth + 1.0


def beam_seats(profile: Profile, layout: RigLayout) -> BeamSeats:
    """The beam's seats (see the module): within the flange's rim where it leaves :data:`SEAT_DEPTH_MM`
    outside the mirror, else reaching past it onto the base plate (the beam then reaches through
    them: rigcad.parts.beam)."""
    shell, beam = profile.dome_shell, profile.beam
    z0, z1 = layout.beam_z
    c, p, w = shell.slot_clearance, SHIM_PACK_MM, beam.width / 2
    ins = INSERTS[SEAT_SCREW]
    side = ins.pocket_depth + 1.0
    bar, half_bar = ROLL_BAR, ROLL_BAR.length / 2
    # the block holds the roll bar's slot (its ends' travel and the clearance each side) inside a wall
    y_side = w + 2 * c + side  # the tunnel's +y wall's outer face: its set screw's insert stands in it
    y_lo, y_hi = -max(w, half_bar + c) - shell.wall, max(y_side, half_bar + c + shell.wall)
    floor, roof = z0 - bar.thickness - p, z1 + p + c
    top = seat_top(profile, z1)
    # the surface as designed, not as stocked: the seats are datums and keep their place whatever
    # sanding stock the printer asks for (the stock only brings the mirror forward)
    u = layout.printed_dome.sample(4001)
    pts = layout.printed_dome.points(u)
    band = (pts[:, 1] >= shell.flange_thickness) & (pts[:, 1] <= top)
    x_in = float(pts[band, 0].max()) + 1.0  # a millimetre outside the mirror wherever the block stands
    # within the flange's rim where it leaves room (the footprint does not grow), else past it, on the plate
    x_out = max(math.sqrt(layout.flange_outer_r ** 2 - max(-y_lo, y_hi) ** 2) - 0.5, x_in + SEAT_DEPTH_MM)
    xm = 0.5 * (x_in + x_out)
    blocks, tunnels, pockets, bars = [], [], [], []
    for s in (1.0, -1.0):
        lo, hi = sorted((s * x_in, s * x_out))
        blocks.append(Box((lo, y_lo, 0.0), (hi, y_hi, top)))  # standing on the plate, through the flange
        tunnels.append(Box((lo - 1.0, -w, floor), (hi + 1.0, w + 2 * c, roof)))
        # the roll bar's slot across the tunnel's bottom: room for an end to rise by a whole pack
        pockets.append(Box((lo - 1.0, -half_bar - c, floor), (hi + 1.0, half_bar + c, z0 + p + c)))
        bars.append(Box((s * xm - bar.width / 2, -half_bar, z0 - bar.thickness), (s * xm + bar.width / 2, half_bar, z0)))
        # the roof's screw: its bore up from the tunnel, the insert's pocket over it, open at the top
        pockets += [stepped_hole(s * xm, 0.0, roof - 1.0, ((THREADS[SEAT_SCREW].clearance / 2, top - ins.pocket_depth - roof + 1.0),
                                                             (ins.hole / 2, ins.pocket_depth + 1.0))),
                    # the +y screw's insert where a side wall would hold it, reached from the block's +y face
                    # (its far side holds the roll bar's slot) through a bore the insert's size
                    teardrop_along_y((s * xm, 0.5 * (y_side - ins.pocket_depth + y_hi + 1.0), 0.5 * (z0 + z1)),
                                     ins.hole / 2, y_hi + 1.0 - (y_side - ins.pocket_depth)),
                    teardrop_along_y((s * xm, w + 2 * c + side / 2, 0.5 * (z0 + z1)),
                                     THREADS[SEAT_SCREW].clearance / 2, side + 2.0)]
    screw = set_screw_length(SEAT_SCREW, side, c, 2 * p + c)
    # the beam's w x h section turned by t spans w cos t + h sin t across: the tunnel's width bounds the roll
    diag = math.hypot(beam.width, beam.height)
    room = math.asin(min(1.0, (beam.width + 2 * c) / diag)) - math.atan2(beam.width, beam.height)
    return BeamSeats(tuple(blocks), tuple(tunnels), tuple(pockets), screw, xm, 2 * xm, p, tuple(bars), room)


def dome(profile: Profile, layout: RigLayout) -> Part:
    """Printed dome: inner face = the coated mirror surface moved behind by the coating (and forward
    by the layout's sanding stock: ``as_printed_dome``)."""
    shell = profile.dome_shell
    inner, outer = layout.as_printed_dome, layout.dome_outer
    u_base = layout.u_inner_base
    if layout.dome_stock:  # where the stocked surface meets the plate; stocked past the coating, its start
        # stands microns above the plate (the base line closes the section under it)
        u_base = inner.u_range[0] if _pt(inner, inner.u_range[0])[1] >= 0.0 else u_at_height(inner, 0.0)
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
    c, p = shell.slot_clearance, SHIM_PACK_MM
    half_w = profile.beam.width / 2 + 2 * c
    reach = layout.slot_r + 5.0
    # the beam bears on its seats only: the slot leaves it the packs' travel up and down
    slot = Box((-reach, -half_w, z0 - p - c), (reach, half_w, z1 + p + c))
    joint, reg, seats = flange_joint(profile, layout), register(profile, layout), beam_seats(profile, layout)
    holes = joint.clearance_holes(flange_bolt_room(profile, layout))  # wider by the limiters' walls
    stack = flange_washers(profile, layout)
    joint = replace(joint, washer_spec="a " + " on ".join(w.name() for w in stack.washers), washer_mm=stack.thickness,
                    spring_washer=True)  # the torque table's spring washer (rigcad.fab.loads: the flange's creep)
    lateral, _ = reg.repeatability
    body = Union_((Revolve(section), *seats.blocks))
    datums = datums_of("seat", "beam seat", seats.tunnels)
    return Part("dome", Difference(body, (slot, *seats.tunnels, *seats.pockets, *holes, *reg.upper_holes())),
                (0.82, 0.82, 0.86),
                "dome: mirror surface inside (paint it), wall, base flange indicated in from the sample bore, on two "
                f"dowels drilled in place in the base plate (a round hole and a slot: it lifts off and goes back to "
                f"within {lateral:g} mm) and bolted to it; beam slots and the beam's two seats (shim foil under and "
                "beside the beam, set screws)",
                mirrors=(("dome", layout.design_dome),), joints=(joint, reg), datums=datums)


def indicating_text(profile: Profile, layout: RigLayout, reg: DowelRegister | None = None) -> str:
    """The manual's shop step for centring the dome on the sample bore and drilling its register in
    place: one paragraph, the figures the parts' own."""
    reg = register(profile, layout) if reg is None else reg
    hole = flange_bolt_hole(profile, layout)
    joint = flange_joint(profile, layout)
    thread, washer = joint.thread, flange_washers(profile, layout).bearing
    return (
        f"{joint.limiter_step()}. "
        f"Centre the dome on the sample bore before its register pins go in: stand it on the base plate, its "
        f"{thread} bolts snug (a quarter of their torque) through the sleeves in its {hole:.2f} mm holes, on "
        f"{washer.size} large washers ({washer.standard}, {washer.outer:g} mm: seated on the sleeves); put a dial "
        f"test indicator ({INDICATOR_MM:g} mm graduation) on an arm on the sample holder, turning in the sample "
        f"bore ({holder_fit(2 * profile.sample_holder.radius).describe()}: the bore bored and the holder turned "
        "to it first), its tip on the mirror's lower edge; turn it round and tap the dome over "
        f"until the reading varies by no more than one graduation (it has {INDICATE_TRAVEL_MM:g} mm of travel "
        f"each way). Tighten the bolts to their torque; check again. With {reamers(reg.diameter)}: drill the "
        f"plate {reg.drill:g} mm through the flange's round hole (printed at {reg.drill:g} mm: the drill opens it "
        f"too) and its slot, {reg.lower_depth:.1f} mm deep (a depth stop on the drill: blind holes, whose floors "
        f"keep the pins from walking), ream both plate holes {reg.diameter:g} {reg.press.hole} through the flange "
        f"with the machine reamer in a hand drill at its lowest speed, the flange's holes guiding it, to the depth "
        f"stop ({reg.reaming_text()}); lift the dome off, ream the flange's round hole {reg.diameter:g} "
        f"{reg.slip.hole}, {reg.gauge_step()} File its slot until a pin slides along it but not across. Press the "
        f"pins ({reg.item}) into the plate with a vise, {PRESS_IN_COMPOUND}, until {reg.upper_engagement:g} mm "
        "stands proud: "
        f"{reg.press.describe()}; the flange slides on them, {reg.slip.describe()}. {reg.repeat_step()}")
