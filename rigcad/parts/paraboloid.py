"""The paraboloid mirror with its solid back, stem and the U clamp that grips the beam; and the
same stem and clamp under the camera-calibration cross that hangs in its place (thesis 4.1.1).

The clamp locates on the beam by two shim stops (rigcad.parts.locating.ShimStop): across the beam
(y), a flat-point set screw in a heat-set insert in the clamp's +y wall presses the beam against
the channel's -y wall through a pack of shim foil; along the beam (x), the clamp's -x end bears on a
dowel pin set (a slip fit in retaining compound) into the beam's top through a second pack. Foil out
or in moves the paraboloid in steps of the thinnest foil, each way up to the pack (rigcad.parts.locating.SHIM_PACK_MM). The
clamp's roof rests on the beam's top; the beam's seats in the dome set the height and the tilt
(rigcad.parts.dome.beam_seats)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.parts.dome import ROLL_BAR, roll_lever
from rigcad.parts.layout import RigLayout
from rigcad.parts.locating import (SHIM_PACK_MM, ShimStop, foil_step, slip_fit, set_screw_length, stepped_hole,
                                   teardrop_along_y)
from rigcad.parts.recipe import Box, Curve, Cylinder, Difference, Line, Part, Revolve, Section, Solid, Union_
from rigcad.profile.schema import Profile
from rigcad.standards import INSERTS, SHIM_FOIL, THREADS, dowel_diameter_for, longest_dowel, pre_ream_drill


#: The stem enters the clamp and the paraboloid's back by this much (mm) so that the booleans fuse
#: overlapping solids rather than faces that merely touch.
FUSE_OVERLAP = 0.5
#: The clamp's set screw: its thread (a heat-set insert takes it in the clamp's +y wall, which is the
#: insert's pocket and a millimetre thick).
SET_SCREW = "M3"
#: The x stop's pin (mm, ISO 8734): the largest standard pin up to half the beam's width, so the
#: beam keeps a quarter of its width of wall each side of the pin's hole.
PIN_SHARE = 0.5
#: The stop pin's blind hole keeps at least this floor (mm) over the beam's underside, so a drill run to
#: the stated depth does not break through (a 0.5 mm floor did, within a drill point's length).
PIN_FLOOR_MM = 1.0
#: The stop pin is a slip fit (rigcad.parts.locating.slip_fit) set in retaining compound: pressed (N7/m6)
#: in the beam's 1.5 mm walls it stressed the printed plastic to about 58 % of its yield (Lame).
RETAINER = "retaining compound, high strength (Loctite 638 class)"


@dataclass(frozen=True)
class Mount:
    """The paraboloid's mounting hardware, stated once (mm): its solid ``back`` below the rim, the
    ``stem`` from the clamp's top to the back, and the U ``clamp`` on the beam (its outer box; the
    ``channel`` is the slot the beam sits in). The recipes and the occluders read these."""

    back: Cylinder
    stem: Cylinder
    clamp: Box
    channel: Box
    #: The x stop's dowel pin, standing up from the beam's top at the clamp's -x end (its pack between).
    pin: Cylinder
    #: The set screw's heat-set insert pocket through the clamp's +y wall (a teardrop along y).
    insert_pocket: Solid
    #: The set screw where it stands out of the clamp's +y face at its farthest (the y pack at its
    #: thickest), as a box: it shadows rays too.
    screw: Box
    #: The set screw's length (mm, ISO 4026) and the pin's (mm, ISO 8734).
    screw_length: int
    pin_length: int

    def occluders(self, with_back: bool = True) -> tuple[tuple[str, Box | Cylinder], ...]:
        """Named convex stand-ins for tracing light past the mount (the clamp as its outer box, its set
        screw inside it; the stop pin as its cylinder)."""
        return ((("back", self.back),) if with_back else ()) + (("stem", self.stem), ("clamp", self.clamp),
                                                                ("pin", self.pin), ("set screw", self.screw))

    @property
    def pin_hole(self) -> Solid:
        """The pin's blind hole in the beam, open at the beam's top: printed at the drill's size before
        the reamer (rigcad.standards.pre_ream_drill), drilled, reamed to the press fit
        (rigcad.parts.locating.slip_fit) and the pin set in retaining compound; its floor (PIN_FLOOR_MM at
        least) stops the pin walking down and the drill breaking through."""
        p = self.pin
        drill = pre_ream_drill(2 * p.radius)
        return stepped_hole(p.base[0], p.base[1], p.base[2] - 0.5, ((drill / 2, p.height + 0.5 - self.pin_proud + 1.0),))

    @property
    def pin_depth(self) -> float:
        """How deep the pin's blind hole runs into the beam from its top (mm)."""
        return self.pin.height + 0.5 - self.pin_proud

    @property
    def pin_floor(self) -> float:
        """What the pin's blind hole leaves over the beam's underside (mm): at least PIN_FLOOR_MM."""
        return self.pin.base[2] - 0.5 - self.channel.lo[2] - 1.0

    @property
    def pin_proud(self) -> float:
        """How far the pin stands above the beam's top (mm): the clamp's roof."""
        return self.clamp.hi[2] - self.channel.hi[2]


def mount(profile: Profile, layout: RigLayout, top_z: float | None = None) -> Mount:
    """The mount under the paraboloid (``top_z``: the stem's top, default the back's bottom)."""
    pm, beam = profile.paraboloid_mount, profile.beam
    z0, z1 = layout.beam_z
    c = profile.dome_shell.slot_clearance
    p, w = SHIM_PACK_MM, beam.width / 2
    half_len = pm.clamp_length / 2
    ins = INSERTS[SET_SCREW]
    side = ins.pocket_depth + 1.0  # the +y wall: the insert's pocket and a millimetre
    lo_y, hi_y = -w - p, w + p + c  # the channel: the pack at -y, room for the beam to move the pack's way at +y
    half_out = clamp_half_width(profile)  # both walls as thick: the clamp stays square under its stem
    clamp_top = z1 + pm.clamp_wall
    back_z = layout.paraboloid_back_z
    top = back_z if top_z is None else top_z
    rim = layout.printed_paraboloid.points(np.array([layout.printed_paraboloid.u_range[0]]))[0]
    d = dowel_diameter_for(PIN_SHARE * beam.width)
    pin_len = longest_dowel(pm.clamp_wall + beam.height - 0.5 - PIN_FLOOR_MM)  # its hole (0.5 past its end) keeps the floor
    pin_x = -half_len - p - d / 2
    r_s = THREADS[SET_SCREW].major / 2
    mid = 0.5 * (z0 + z1)
    pocket = teardrop_along_y((0.0, hi_y + side - ins.pocket_depth / 2 + 0.5, mid), ins.hole / 2, ins.pocket_depth + 1.0)
    bore = teardrop_along_y((0.0, hi_y + side / 2, mid), THREADS[SET_SCREW].clearance / 2, side + 2.0)
    screw = set_screw_length(SET_SCREW, side, c, 2 * p + c)
    return Mount(
        back=Cylinder((0.0, 0.0, back_z), float(rim[0]), float(rim[1]) - back_z),
        stem=Cylinder((0.0, 0.0, clamp_top), pm.stem_radius, top - clamp_top),
        clamp=Box((-half_len, -half_out, z0), (half_len, half_out, clamp_top)),
        channel=Box((-half_len - 1, lo_y, z0 - 1), (half_len + 1, hi_y, z1)),
        pin=Cylinder((pin_x, 0.0, clamp_top - pin_len), d / 2, pin_len),
        insert_pocket=Union_((pocket, bore)),
        screw=Box((-r_s, hi_y + side, mid - r_s), (r_s, hi_y + side + max(0.1, screw - side - c), mid + r_s)),
        screw_length=screw, pin_length=pin_len,
    )


def clamp_half_width(profile: Profile) -> float:
    """Half the clamp's width across the beam (mm): the beam, the y pack's travel, the slot clearance
    and the +y wall that holds the set screw's insert (the insert's pocket and a millimetre)."""
    return (profile.beam.width / 2 + SHIM_PACK_MM + profile.dome_shell.slot_clearance
            + INSERTS[SET_SCREW].pocket_depth + 1.0)


def stops(profile: Profile, layout: RigLayout) -> tuple[ShimStop, ShimStop]:
    """The clamp's two shim stops on the beam (x: its end on the pin; y: the beam on the channel's
    -y wall), as the tolerance stack reads them: each moves the paraboloid one for one."""
    step = foil_step()
    m = mount(profile, layout)
    return (ShimStop("paraboloid along the beam (x): shim foil between the clamp's end and the beam's stop pin",
                     "paraboloid", "x", SHIM_PACK_MM, step, SHIM_PACK_MM,
                     f"{SHIM_PACK_MM:g} mm of foil at the design setting; the clamp slid onto the pin and locked by "
                     f"its set screw"),
            ShimStop("paraboloid across the beam (y): shim foil between the beam and the clamp's -y wall",
                     "paraboloid", "y", SHIM_PACK_MM, step, SHIM_PACK_MM,
                     f"{SHIM_PACK_MM:g} mm of foil at the design setting; the {SET_SCREW} x {m.screw_length} set "
                     "screw presses the beam onto it"))


def hardware(profile: Profile, layout: RigLayout) -> list[dict]:
    """The paraboloid's stops' and the beam's seats' bought hardware as rows (mm; units in keys; the
    form of rigcad.parts.tower.hardware, which the manual's bill and steps read): the clamp's set
    screw and insert, the beam's stop pin, the seats' set screws and inserts, the shim foil; ``steps``:
    the assembly steps (by part) that fit each item."""
    from rigcad.parts.dome import SEAT_SCREW, beam_seats

    m, seats = mount(profile, layout), beam_seats(profile, layout)
    d = 2 * m.pin.radius
    foil = ", ".join(f"{t:g}" for t in SHIM_FOIL)
    return [
        {"item": "set screw, flat point (ISO 4026)", "thread": SET_SCREW, "length_mm": m.screw_length, "quantity": 1,
         "steps": ("paraboloid",), "joins": "the paraboloid's clamp to the beam: in the insert in the clamp's +y wall, "
                                            "it presses the beam onto the y stop's shim foil"},
        {"item": f"heat-set insert (ruthex, {INSERTS[SET_SCREW].length:g} mm long)", "thread": SET_SCREW,
         "length_mm": None, "quantity": 1 + 4, "steps": ("paraboloid", "dome"),
         "joins": "the set screws' inserts: one in the clamp's +y wall, two in each of the beam's seats"},
        {"item": f"dowel pin, ISO 8734 m6 (hardened steel; slip fit in {d:g} {slip_fit(d).hole}, set in retaining "
                 "compound)", "thread": None,
         "length_mm": m.pin_length, "diameter_mm": d, "quantity": 1, "steps": ("beam",),
         "joins": f"the paraboloid's x stop: the beam's blind hole prints at {pre_ream_drill(d):g} mm; drill it "
                  f"{pre_ream_drill(d):g} mm, {m.pin_depth:g} mm deep (a depth stop: its floor, "
                  f"{m.pin_floor:g} mm, stays), ream it {d:g} {slip_fit(d).hole} "
                  f"(a {d:g} mm {slip_fit(d).hole} hand reamer), wet the pin with {RETAINER} and slide it in until "
                  f"{m.pin_proud:g} mm stands proud of its top: {slip_fit(d).describe()}"},
        {"item": "set screw, flat point (ISO 4026)", "thread": SEAT_SCREW, "length_mm": seats.screw_length,
         "quantity": 4, "steps": ("beam",), "joins": "the beam on its two seats: in each seat one down through its "
                                                     "roof, one across through its +y wall"},
        {"item": f"{ROLL_BAR.name}, cut {ROLL_BAR.length:g} mm long", "thread": None,
         "length_mm": ROLL_BAR.length, "quantity": 2, "steps": ("beam",),
         "joins": f"the beam's roll bars: one across each seat's tunnel under the beam, its ends on foil packs "
                  f"{roll_lever():g} mm apart (the paraboloid's roll about the beam: "
                  f"{math.degrees(foil_step() / roll_lever()):.3f} deg per {foil_step():g} mm of foil); slid into the "
                  "slot at the tunnel's bottom before the beam, deburred, its ends square"},
        {"item": f"shim foil, stainless steel 1.4310 (EN 10140), {foil} mm, one sheet each", "thread": None,
         "length_mm": None, "quantity": 1, "steps": ("beam", "paraboloid"),
         "joins": f"the packs of the paraboloid's stops ({SHIM_PACK_MM:g} mm each at the design setting: under each "
                  f"end of each seat's roll bar, in {ROLL_BAR.pad:g} mm strips, between the beam and the clamp's -y "
                  "wall, between the clamp's end and the pin), cut to the faces with scissors"},
    ]


def stem_and_clamp(m: Mount) -> Solid:
    """The mount's stem on its U clamp (open at the bottom), as one solid."""
    s = m.stem
    stem = Cylinder((s.base[0], s.base[1], s.base[2] - FUSE_OVERLAP), s.radius, s.height + 2 * FUSE_OVERLAP)
    return Union_((Difference(m.clamp, (m.channel, m.insert_pocket)), stem))


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
                "paraboloid mirror on its stem; the U clamp sits on the beam at the design height, its end on "
                "the beam's stop pin and the beam pressed on its -y wall by a set screw, each through a pack of "
                "shim foil (they set it along and across the beam)",
                mirrors=(("paraboloid", layout.design_paraboloid),), occluders=hardware.occluders())


def setting_text(profile: Profile, layout: RigLayout) -> str:
    """The manual's step for setting the paraboloid on its stops from a calibration (what the lab
    reads, and how much foil moves it how far): one paragraph, the figures the stops' own."""
    from rigcad.parts.dome import beam_seats

    seats, step = beam_seats(profile, layout), foil_step()
    per_tilt = seats.span * math.radians(0.01)
    # the roll about the beam: foil under one end of each seat's roll bar against its other end, over the
    # bar's lever (the beam's own width is too short a lever for the thinnest foil: docs/rig-mechanics.md)
    lever = roll_lever()
    roll_per = lever * math.radians(0.1)
    tol = profile.tolerancing
    return (
        f"Set the paraboloid from a calibration: `rigcad calibrate {profile.name} --images <folder>` prints, last, "
        "'against the dome's axis: paraboloid off by x .., y .., z .. mm, tilted x .., y .. deg' "
        "(calibration.json: against_the_dome.parameters.paraboloid_*). Move it back when an offset exceeds "
        f"its tolerance ({tol.paraboloid_offset:g} mm sideways, {tol.paraboloid_height:g} mm in height, "
        f"{math.degrees(tol.paraboloid_tilt):g} deg) and twice its standard error. Foil comes in "
        f"{', '.join(f'{t:g}' for t in SHIM_FOIL)} mm; build each change from them. "
        f"x: loosen the clamp's set screw, take out of the pack between the clamp's -x end and the beam's pin as "
        f"much foil as x reads (add as much when x is negative): 0.01 mm of foil moves it 0.01 mm, in steps of "
        f"{step:g} mm; slide the clamp back onto the pin and tighten. y: add as much foil as y reads to the pack "
        f"between the beam and the clamp's -y wall (take out when negative). z: take as much foil as z reads "
        f"out of the packs under both ends of both seats' roll bars (add when negative); a change at one seat moves "
        f"the paraboloid half as much ({step / 2:g} mm per {step:g} mm foil). Tilt y (the -x side high when "
        f"positive): take {per_tilt:.3f} mm of foil per 0.01 deg out of the -x seat's packs (under both ends of its "
        f"roll bar), or add it at the +x seat, then restore the height. Tilt x (the +y side high when positive; a "
        f"roll about the beam): add foil under the -y ends of both seats' roll bars, or take it from under their +y "
        f"ends (the other way when negative), {roll_per:.4f} mm per 0.1 deg over the bars' {lever:g} mm lever: the "
        f"thinnest foil ({step:g} mm) rolls it {math.degrees(step / lever):.3f} deg, so it lands within "
        f"{math.degrees(step / lever) / 2:.3f} deg of level; change both seats alike (one alone twists the beam), "
        "then restore the height. Loosen the seats' set screws before changing their packs; tighten the roof "
        "screws first and then the side screws only until the beam touches its -y wall (pressed harder they roll it "
        "off the bars). "
        "Capture and calibrate again.")
