"""The calibration kit from the profile: the screen's patterns as PNGs at its resolution, the
spacers as printed parts (the sample holder's recipe, :func:`rigcad.parts.base.holder_body`, cut
to each spacer's height: the same recipe objects, meshed and written by the same exporters as every
part, with a manifest), and the manual's page (:func:`manual_page`: placing the screen, the
capture order and the naming scheme, exposure advice)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence


def pattern_png(seq: Sequence, name: str) -> bytes:
    """One frame as an 8-bit grey PNG at the screen's resolution, its levels marked linear
    (rigcad.export.png: gAMA 1.0; the screen is to show them through a linear response)."""
    from rigcad.export.png import gray_png

    return gray_png(seq.image(name))


def spacer(profile, k: int):
    """Spacer ``k`` as a recipe Part: the holder's plug (stop collar under the plate) whose top, where
    the screen's back rests, stands ``spacer_heights[k]`` above the holder's seat."""
    from rigcad.parts.base import holder_body
    from rigcad.parts.recipe import Part

    h = profile.calibration.spacer_heights[k]
    top = -profile.sample_holder.sample_thickness + h
    return Part(f"calibration_spacer_{k}", holder_body(profile, top, spacer_marks()), (0.3, 0.6, 0.3),
                f"calibration spacer {k}: replaces the sample holder; the screen's back rests {h:g} mm above "
                "the holder's seat; its collar's wide notch faces the base plate's groove, the narrow one after "
                "the half turn", in_rig=False)


def spacer_marks() -> tuple[tuple[float, float], ...]:
    """A spacer's collar notches (rigcad.parts.base.holder_body): the wide one at +x, set at the base
    plate's groove for its first capture; the narrow one opposite, there after the half turn."""
    from rigcad.parts.base import NOTCH_MM, WIDE_NOTCH_MM

    return (0.0, WIDE_NOTCH_MM), (math.pi, NOTCH_MM)


def stand_marks(turns: int) -> tuple[tuple[float, float], ...]:
    """The upright stand's collar notches (rigcad.parts.base.holder_body): turn j's at -360 j / turns
    deg, so that the stand turned to put it at the base plate's groove (+x) faces its display towards
    360 j / turns deg (:class:`rigcad.calibrate.upright.Uprights`); turn 0's is the wide one."""
    from rigcad.parts.base import NOTCH_MM, WIDE_NOTCH_MM

    return tuple((-2 * math.pi * j / turns, WIDE_NOTCH_MM if j == 0 else NOTCH_MM) for j in range(turns))


#: The upright stand's slot: clearance around the display's module (mm, each side), and the least wall
#: the stand's cylinder keeps around it.
SLOT_CLEARANCE_MM = 0.2
SLOT_WALL_MM = 1.0
#: How far above the sample plane the stand's back holds the upright display (mm).
STAND_BACK_MM = 12.0
#: The slot's floor keeps this much (mm) under the module's frame, beyond the active area's edge, at
#: each side of the cable channel that runs down from it through the stand: the module stands on those
#: two ledges, its flat cable down the channel and out below the base plate.
CABLE_LEDGE_MM = 2.0


def upright_room(profile) -> dict:
    """Where the upright display's module stands in its stand (mm): its slot's farthest corner from
    the axis (the module's face ``upright_offset`` out, its body ``upright_thickness`` behind it,
    ``upright_border`` beyond the active area at each side, plus the slot's clearance) against the
    stand's radius (the sample holder's) less a wall. ``fits``: the slot stays inside the stand."""
    cal, holder = profile.calibration, profile.sample_holder
    half = Sequence.from_profile(cal, "upright").size_mm[0] / 2 + cal.upright_border + SLOT_CLEARANCE_MM
    front = cal.upright_offset + SLOT_CLEARANCE_MM
    back = cal.upright_offset - cal.upright_thickness - SLOT_CLEARANCE_MM
    corner = max(math.hypot(front, half), math.hypot(back, half))
    cable = half - cal.upright_border - SLOT_CLEARANCE_MM - CABLE_LEDGE_MM
    return {"corner_mm": corner, "room_mm": holder.radius - SLOT_WALL_MM, "half_width_mm": half,
            "front_mm": front, "back_mm": back, "fits": corner <= holder.radius - SLOT_WALL_MM,
            "cable_half_mm": max(cable, 0.0)}


def check_upright_fits(profile) -> dict:
    """:func:`upright_room`, refused with a ProfileError naming ``calibration.upright_offset`` when the
    upright display's module cannot stand in the holder's bore."""
    from rigcad.errors import ProfileError

    room = upright_room(profile)
    if profile.calibration.upright_turns and not room["fits"]:
        cal = profile.calibration
        raise ProfileError(
            f"calibration.upright_offset {cal.upright_offset:g} mm: the upright display's module "
            f"({2 * (room['half_width_mm'] - SLOT_CLEARANCE_MM):.1f} mm wide with its border, "
            f"{cal.upright_thickness:g} mm thick) would reach {room['corner_mm']:.1f} mm from the axis, but its stand in the "
            f"holder's bore keeps {room['room_mm']:.1f} mm (sample_holder.radius less a {SLOT_WALL_MM:g} mm wall): "
            "bring it nearer the axis, or choose a narrower display (calibration.upright_resolution)",
            where=profile.where("calibration", "upright_offset"))
    return room


def upright_stand(profile):
    """The upright display's stand as a recipe Part: the holder's plug (stop collar under the plate)
    whose top stands ``upright_depth`` under the sample plane, with a slot whose floor holds the
    module's lower edge so its active area starts there, and a back rising :data:`STAND_BACK_MM`
    above the plane behind the module. Drawn for turn 0 (the display's face towards +x)."""
    from rigcad.parts.base import holder_body
    from rigcad.parts.recipe import Box, Cylinder, Difference, Part, Union_

    cal = profile.calibration
    r = profile.sample_holder.radius
    top, floor = -cal.upright_depth, -cal.upright_depth - cal.upright_border
    room = upright_room(profile)
    half, front, back = room["half_width_mm"], room["front_mm"], room["back_mm"]
    body = holder_body(profile, top, stand_marks(cal.upright_turns))
    rise = Difference(Cylinder((0.0, 0.0, top - 1.0), r, STAND_BACK_MM - top + 1.0),
                      (Box((back, -r - 1.0, top - 2.0), (r + 1.0, r + 1.0, STAND_BACK_MM + 1.0)),))
    slot = Box((back, -half, floor), (front, half, STAND_BACK_MM + 1.0))
    bottom = -profile.base_plate.thickness - profile.sample_holder.stop_thickness
    cable = Box((back, -room["cable_half_mm"], bottom - 1.0), (front, room["cable_half_mm"], floor + 1.0))
    return Part("calibration_upright_stand", Difference(Union_((body, rise)), (slot, cable)), (0.6, 0.45, 0.2),
                f"calibration stand for the upright display: replaces the sample holder; the display's module stands "
                f"in its slot, face out {cal.upright_offset:g} mm from the axis, its active area from {cal.upright_depth:g} mm "
                "under the sample plane; its cable runs down the channel under the slot, out below the plate",
                in_rig=False)


def screen_room(rig) -> dict:
    """Where the screen lies inside the dome (mm): the display's half diagonal (its corners' distance
    from the axis when it lies centred) against the dome's inside radius, the least over the heights
    the screen spans at each spacer (its back to its emitting surface, clipped at the sample plane
    where the dome starts). ``fits``: the display clears the dome at every spacer; the body, a bezel
    wider, must fit in ``body_diameter_mm`` (the manual says so)."""
    p = rig.profile
    cal = p.calibration
    pts = rig.dome.points  # the mirror surface (r, z), rising from the sample plane
    size = Sequence.from_profile(cal).size_mm
    half_diagonal = math.hypot(*size) / 2
    rows = []
    for k, top in enumerate(M.nominal_heights(p)):
        z = np.linspace(max(top - cal.screen_thickness, 0.0), max(top, 0.0), 65)
        r = np.interp(z, pts[:, 1], pts[:, 0])
        i = int(np.argmin(r))
        rows.append({"spacer": k, "z_mm": float(z[i]), "dome_radius_mm": float(r[i])})
    tight = min(rows, key=lambda row: row["dome_radius_mm"])
    return {"display_mm": list(size), "half_diagonal_mm": half_diagonal,
            "tightest": tight, "body_diameter_mm": 2 * tight["dome_radius_mm"],
            "fits": half_diagonal < tight["dome_radius_mm"]}


def check_screen_fits(rig) -> dict:
    """:func:`screen_room`, refused with a ProfileError naming ``calibration.screen_resolution`` when
    the display's corners would reach into the dome: no screen so placed can lie there."""
    from rigcad.errors import ProfileError

    room = screen_room(rig)
    if not room["fits"]:
        cal, t = rig.profile.calibration, room["tightest"]
        (dw, dh), d = room["display_mm"], room["half_diagonal_mm"]
        raise ProfileError(
            f"calibration.screen_resolution {cal.screen_resolution[0]} x {cal.screen_resolution[1]} px at "
            f"calibration.screen_pitch {cal.screen_pitch:g} mm is a {dw:.1f} x {dh:.1f} mm display whose corners lie "
            f"{d:.1f} mm from the axis, but the dome's inside is {t['dome_radius_mm']:.1f} mm from the axis at "
            f"z = {t['z_mm']:.1f} mm, where spacer {t['spacer']} ({cal.spacer_heights[t['spacer']]:g} mm) puts the "
            f"screen: choose a screen whose display diagonal (and body) is under {room['body_diameter_mm']:.0f} mm",
            where=rig.profile.where("calibration", "screen_resolution"))
    return room


def _dome_off(rig) -> str:
    """How the screens get inside the dome: it lifts off its register (rigcad.parts.dome.register)."""
    from rigcad.parts.dome import flange_joint, register

    reg, joint = register(rig.profile, rig.layout), flange_joint(rig.profile, rig.layout)
    lateral, turn = reg.repeatability
    return (f"- The screen goes in with the dome off: take out the dome's {joint.count} flange screws and lift it "
            f"straight up off its {len(reg.points)} register pins (the beam and the paraboloid ride with it, in its "
            "slots; two hands, level), put the spacer in the bore and the screen on it, then lower the dome back over "
            f"the pins and screw it down. The register puts it back within {1e3 * lateral:.0f} µm and "
            f"{1e3 * math.degrees(turn):.1f} mdeg (`tolerancing.dome_offset` is {rig.profile.tolerancing.dome_offset:g} "
            "mm), so every capture sees the same dome.")


def manual_page(rig, refinish: list[str] | None = None) -> str:
    """The manual's page on the calibration (Markdown); ``refinish``: the finishing recipe's stages by name, for
    what to do when the dome's slopes fail (:func:`_when_it_fails`)."""
    p = rig.profile
    cal = p.calibration
    seq = Sequence.from_profile(cal)
    plan = M.Plan.of(p)
    frames = seq.names()
    steps = _flat_steps(cal, plan)
    side = min(seq.size_mm)
    reach = math.degrees(math.atan((side / 2) / max(plan.heights)))
    room = check_screen_fits(rig)
    def across(angle: float) -> str:
        return f"{math.degrees(angle):g} deg, {side * math.tan(angle):.2f} mm across its {side:.0f} mm side"

    pair = [c for c in range(len(plan)) if plan.repeats(c) is not None]
    twice = " and ".join(str(plan.spacers[c]) for c in pair)
    half_turn = (f"a capture turned a half turn turns the wedge with it, so the two captures of "
                 f"spacer{'s' * (len(pair) > 1)} {twice} average it out, and the map's tilt is how the screen settles when laid "
                 f"again (within {across(cal.screen_seating)}, `calibration.screen_seating`)." if pair
                 else "the map's tilt is that wedge (`calibration.half_turn: highest` averages it out).")
    return f"""# Calibrating the as-built rig (deflectometry)

What it measures: each camera pixel's incidence direction at the sample, through the paraboloid and
the dome as they were built and placed; the fit of the misalignment; the dome's residual slopes.

## The kit
{_screen_kit(rig, room)}
- The spacers (`stl/calibration_spacer_<k>.stl`): each replaces the sample holder in the base plate's bore.
  Turn it, from below, by the notches in its collar's rim: the wide one faces the groove under the
  base plate (on the tongue's side, +x) for its first capture, the narrow one after its half turn:
  {_within(p)}.
  Lay the screen face up on its top, centred on the axis and square to the base plate by eye: within
  {M.PLACEMENT_MM:g} mm and {math.degrees(M.PLACEMENT_TURN_RAD):g} deg is enough, the fit finds where it lies at each spacer.
- Lay it flat. No image shows the sample plane: the images cannot tell a screen tilted on its spacer
  from a rig tilted over the sample, so the screen's tilt on the holder's seat is the map's. The
  spacer's faces and the screen's back make a wedge (up to {across(cal.screen_tilt)},
  `calibration.screen_tilt`); {half_turn}
  Clean the spacer's top and the screen's back; a screen that rocks on a camera bump needs a flat
  plate under it, counted in `screen_thickness`.
{_dome_off(rig)}
{_upright_kit(p, len(plan))}
## Capture order
In turn:
{steps}{_upright_steps(p, len(plan))}

and for each, the {len(frames)} frames in this order (the names of `patterns/`): {', '.join(frames[:4])}, ...,
{frames[-1]}. Name each camera image `<capture>_<frame>.png` (or .tif, 8 or 16 bit, grey or colour) at the
camera's full resolution, {p.camera.resolution[0]} x {p.camera.resolution[1]} px, all in one folder; then
`rigcad calibrate {p.name} --images <folder>`.
Store each image as the camera gives it, not flipped or turned: the kit's `conventions.png` shows how
the image's columns and rows, the screen's axes at each turn and the patterns are read.
{_upright_by_eye(p)}
## Exposure
- One exposure for every frame of a capture: set it on the white frame so the brightest lit pixels sit at
  80-90 % of full scale (a saturated white is refused; so is an all-dark one). The brightest are the
  ring around the paraboloid's image, where the camera sees the screen directly through the dome's
  top opening, with no mirror's loss: set the exposure there. Keep that ring in the images: the fit
  reads it, and it fixes the camera's place. The paraboloid's image inside it is dimmer: each
  mirror reflects {100 * p.coating.reflectance:.0f} % (`coating.reflectance`), so it gets
  {100 * p.coating.reflectance ** 2:.0f} % of the ring's light. That is expected; do not raise the exposure for it.
{_upright_exposure(p)}- Keep the room dark: stray light lowers the fringes' modulation (pixels under
  {cal.min_modulation:g} modulation are not decoded).
- Leave the camera's focus where section 6 set it, on the hung cross, its ring taped: refocusing moves the
  camera's COP (its lens's entrance pupil) and changes its focal length in pixels, which the fit holds.
  The screens, seen through the two mirrors, may look a little soft: that is harmless.
- The screen reaches rays up to {reach:.0f} deg from the axis at the highest spacer: beyond that
  {"the lower spacer's and then the upright display's captures take over" if cal.upright_turns else
   "the corrected map is filled from the fit"}.

{_what_passes(rig)}
{_when_it_fails(rig, refinish)}
{_after_the_fit(p.tolerancing)}{_setting_the_paraboloid(rig)}
{_measuring_the_seating(p)}"""


#: Displays of a known format, by (resolution (width, height) px, pitch in 0.1 µm): what to ask for by name.
KNOWN_DISPLAYS = {((2266, 1488), 779): "the display of Apple's iPad mini (6th generation and later)",
                  ((240, 320), 1275): "a 2.0-inch IPS SPI module with an ST7789 driver (e.g. Waveshare's 2inch LCD "
                                     "Module)"}


def display_spec(resolution, pitch: float) -> dict:
    """What to buy for a display the calibration shows its frames on unscaled: its resolution (px), pitch
    (mm), density (ppi), active area (mm) and diagonal (inches), and the display of that format by name
    (KNOWN_DISPLAYS) when rigcad knows one."""
    w, h = resolution
    return {"resolution_px": [w, h], "pitch_mm": pitch, "ppi": 25.4 / pitch, "size_mm": [w * pitch, h * pitch],
            "diagonal_in": math.hypot(w, h) * pitch / 25.4,
            "known_as": KNOWN_DISPLAYS.get(((w, h), round(1e4 * pitch)))}


def display_text(spec: dict) -> str:
    """A display's buying line (:func:`display_spec`)."""
    (w, h), (a, b) = spec["resolution_px"], spec["size_mm"]
    size = f"{spec['diagonal_in']:.1f}"
    return (f"{'an' if size.startswith(('8', '11', '18')) else 'a'} {size}-inch display of exactly {w} x {h} px at "
            f"{spec['pitch_mm']:g} mm pitch "
            f"({spec['ppi']:.0f} ppi, {a:.1f} x {b:.1f} mm)" + (f": {spec['known_as']}" if spec["known_as"] else ""))


def _screen_kit(rig, room: dict) -> str:
    """The kit's item for the flat screen: what to buy, how it lies in the dome, and how its frames
    advance while the dome is on (rigcad.calibrate.slideshow)."""
    from rigcad.calibrate.slideshow import DELAY_S, HOLD_S

    cal = rig.profile.calibration
    spec = display_spec(cal.screen_resolution, cal.screen_pitch)
    frames = len(Sequence.from_profile(cal).names())
    return f"""- A flat screen (a tablet): {display_text(spec)}; the frames are drawn for those pixels,
  so a screen of another resolution or pitch cannot show them: set `calibration.screen_resolution` and
  `screen_pitch` to yours and run `--kit` again. {cal.screen_thickness:g} mm from its back to its emitting
  surface (`screen_thickness`). It lies inside the dome: its body, bezel and corners included, must fit in a
  {room['body_diameter_mm']:.0f} mm circle (the dome's inside at z = {room['tightest']['z_mm']:.1f} mm, where spacer
  {room['tightest']['spacer']} puts it): lay it on a circle of that size drawn on paper before you buy.
  Set it to its full brightness, no night shift, no auto-brightness, auto-lock off, and a linear (gamma 1)
  response if it offers one.
- Its frames advance by themselves, with the dome on: nobody may touch the screen once it lies on its
  spacer (a touch moves it), and the dome stays on its register for a whole capture. Open
  `patterns/slideshow.html` on the tablet (it holds the {frames} frames), and press Start before the dome
  goes back on: it counts down {DELAY_S} s (the buttons change it), then shows each frame full screen,
  unscaled, for {HOLD_S} s, in capture order, then black. Set the camera's interval timer to {HOLD_S} s and
  start it {HOLD_S / 2:g} s after the white frame appears in its live view: {frames} pictures, one in the middle
  of each frame; name them in that order."""


def _flat_steps(cal, plan) -> str:
    """The capture order's steps for the flat screen, one per spacer and turn (Markdown list)."""
    turned = (", turned a half turn (the spacer in its bore, its narrow notch at the groove, and the screen on it, "
              "each by 180 deg)")
    return "\n".join(
        f"{c + 1}. spacer {k} ({cal.spacer_heights[k]:g} mm)"
        f"{turned if plan.repeats(c) is not None else ', its wide notch at the groove'}: "
        f"screen surface {z:g} mm above the sample point; files `{label}_<frame>.png`"
        for c, (k, z, label) in enumerate(zip(plan.spacers, plan.heights, plan.labels)))


def _upright_kit(p, flat: int) -> str:
    """The kit's item for the upright display (empty without ``calibration.upright_turns``)."""
    cal = p.calibration
    if not cal.upright_turns:
        return ""
    seq = Sequence.from_profile(cal, "upright")
    (w, h), (w_mm, h_mm) = seq.resolution, seq.size_mm
    spec = display_spec((w, h), cal.upright_pitch)
    return f"""- A small display stood on edge, the upright display: {display_text(spec)}, its module
  {cal.upright_thickness:g} mm thick with {cal.upright_border:g} mm of frame beyond the active area at the sides
  and below. Its stand (`stl/calibration_upright_stand.stl`) replaces the sample holder in the bore: stand
  the module in the slot, face out, on the slot's floor, against the stand's back, its flat cable down the
  channel under the slot and out below the base plate; the active area then starts {cal.upright_depth:g} mm
  under the sample plane, {cal.upright_offset:g} mm from the axis. It meets the rays that reach the sample
  near grazing, which pass under the flat screen or meet it past its edge.
- The upright display is driven from outside, below the plate (the rig on its lifting blocks, the dome
  on throughout): a Raspberry Pi with the module on its SPI pins as a framebuffer (the kernel's
  fbtft overlay for its driver), showing the PNGs of `patterns_upright/` full screen, unscaled, in the
  order of `patterns_upright/order.txt` (`fbi -T 1 -d /dev/fb1 -a -noverbose $(cat order.txt)`, run in that
  folder; the space bar steps to the next frame). Step it once per camera picture from the Pi's keyboard.
"""


def _upright_steps(p, flat: int) -> str:
    """The capture order's steps for the upright display (empty without ``calibration.upright_turns``)."""
    cal = p.calibration
    if not cal.upright_turns:
        return ""
    step = 360 / cal.upright_turns
    return "\n" + "\n".join(
        f"{flat + j + 1}. the upright display in its stand, "
        + ("its wide notch at the groove (its face towards +x, the projector's side)" if j == 0 else
           f"turned on by {step:g} deg, counter-clockwise seen from above: the {_ordinal(j)} notch counter-clockwise "
           f"from the wide one, seen from below, at the groove (its face towards {step * j:g} deg)")
        + f": files `u{j}_<frame>.png`" for j in range(cal.upright_turns))


def _ordinal(n: int) -> str:
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def _within(p) -> str:
    """How closely a notch set on the base plate's groove by eye turns a plug: half the groove's width
    at the collar's rim."""
    from rigcad.parts.base import GROOVE_WIDTH_MM

    off = GROOVE_WIDTH_MM / 2
    return (f"a notch centred on the groove by eye, to {off:g} mm, sets the turn within "
            f"{math.degrees(off / p.sample_holder.stop_radius):.1f} deg")


def _upright_by_eye(p) -> str:
    """What the upright display's turns need (empty without ``calibration.upright_turns``)."""
    cal = p.calibration
    if not cal.upright_turns:
        return ""
    return f"""
The stand's collar has a notch for each turn, the wide one for the first: set each turn from
below with its notch centred on the base plate's groove. The fit finds where it stands (within
{math.degrees(cal.upright_tilt):g} deg of lean or turn and {M.PLACEMENT_MM:g} mm sideways), against the rays the flat
captures measured. A turn far from its notch is refused, naming its file.
"""


def _upright_exposure(p) -> str:
    """The exposure advice for the upright display (empty without ``calibration.upright_turns``)."""
    if not p.calibration.upright_turns:
        return ""
    return """- The upright display's captures light nothing but the paraboloid's image (the display is edge on to
  the direct view): set their exposure on that image, to the same 80-90 % of full scale.
"""


def _measuring_the_seating(p) -> str:
    """The calibration page's section on measuring ``calibration.screen_seating`` (rigcad.calibrate.seating)."""
    return f"""## Measuring how the screen settles
The map's tilt over the sample plane is known as well as the screen settles when laid again on its
spacer: `calibration.screen_seating`, {math.degrees(p.calibration.screen_seating):g} deg in this profile, a value stated, not
measured. To measure it, leave the rig as it is and repeat the whole capture three to five times,
lifting the screen and the spacers off and laying them again each time; calibrate each capture into
a folder of its own (`rigcad calibrate {p.name} --images <capture k> --exports <k>`). Then
`rigcad calibrate {p.name} --seating <1>/{p.name}/calibrate <2>/{p.name}/calibrate ...`
compares each screen's tilt against the dome between them, says how the screen settles (per axis,
with a 95 % interval) and the value to state as `screen_seating`, and refuses captures between
which the rig moved. A seat that settles tighter than the profile states makes the map's frame
tighter when the profile says so; one that settles looser must be stated, or the frame's standard
errors claim too much.
"""


def _setting_the_paraboloid(rig) -> str:
    """How the offsets the fit prints move the paraboloid on its shim stops (rigcad.parts.paraboloid)."""
    from rigcad.parts.paraboloid import setting_text

    return "\n" + setting_text(rig.profile, rig.layout) + "\n"


#: The placements against the dome the pass criterion judges, by the name the report gives each
#: (calibration.json's ``against_the_dome``) -> the ``tolerancing`` key that bounds it.
PLACEMENT_TOLERANCES = {f"{part}_{axis}": f"{part}_{key}" for part in ("paraboloid", "camera")
                        for axis, key in (("dx_mm", "offset"), ("dy_mm", "offset"), ("dz_mm", "height"),
                                          ("tilt_x_deg", "tilt"), ("tilt_y_deg", "tilt"))}
#: How many standard errors a placement must stay inside its tolerance to pass (about 95 % one-sided
#: confidence for a normal error: a reading that lands within tolerance by less cannot tell).
PASS_STANDARD_ERRORS = 2.0


def dome_farthest_from_o(rig) -> float:
    """D (mm): the design dome's farthest point from O, on its meridian sampled at 2001 points."""
    pts = rig.layout.design_dome.points(rig.layout.design_dome.sample(2001))
    return float(np.max(np.hypot(pts[:, 0], pts[:, 1])))


def dome_slope_tolerance(rig) -> float:
    """The dome's slope tolerance (mrad): a slope error e turns a ray by 2 e, which lands 2 e D from O, D
    the dome's farthest point from O (:func:`dome_farthest_from_o`); e stays within
    ``tolerancing.max_spot_radius`` / (2 D). The one home of the figure the optical acceptance test holds
    before the calibration (rigcad.manual.finishing.slope_acceptance) and the calibration's pass criterion."""
    return 1e3 * rig.profile.tolerancing.max_spot_radius / (2.0 * dome_farthest_from_o(rig))


def pass_criterion(rig) -> dict:
    """What a calibration (``rigcad calibrate --images``) must show to pass: each placement against the
    dome within its tolerance (report units: mm, deg) by :data:`PASS_STANDARD_ERRORS` standard errors,
    and the dome's residual slope p99 (mrad) within :func:`dome_slope_tolerance`."""
    tol = rig.profile.tolerancing
    bounds = {}
    for name, key in PLACEMENT_TOLERANCES.items():
        v = getattr(tol, key)
        bounds[name] = math.degrees(v) if name.endswith("_deg") else v
    return {"placements": bounds, "standard_errors": PASS_STANDARD_ERRORS,
            "residual_slope_p99_mrad": dome_slope_tolerance(rig)}


#: What to do when a criterion fails, by how it fails (the manual's 'When it fails' says how, per adjuster).
RESEAT = "re-seat it: move it back by the offset, then capture again"
UNRESOLVED = "unresolved: capture again (both half turns of each spacer)"
REFINISH = "sand the dome's marked area back to its template, coat it again, capture again"


def checks(rig, report: dict) -> list[dict]:
    """``report`` (a calibration.json, as read) against :func:`pass_criterion`, one row per criterion:
    ``check`` (the report's name), ``passed``, ``value``, ``standard_error`` (None for the slope), ``figure``
    (what is held to the bound: |value| + k standard errors, or the slope p99), ``bound``, ``unit`` (mm, deg or
    mrad), ``key`` (the profile key that sets the bound) and ``action`` (what to do when it fails, else "")."""
    crit = pass_criterion(rig)
    k, out = crit["standard_errors"], []
    params = report["against_the_dome"]["parameters"]
    for name, bound in crit["placements"].items():
        v, se = float(params[name]["value"]), float(params[name]["standard_error"])
        figure = abs(v) + k * se
        ok = bool(figure <= bound)
        act = "" if ok else RESEAT if abs(v) > max(bound, k * se) else UNRESOLVED
        out.append({"check": name, "passed": ok, "value": v, "standard_error": se, "figure": figure, "bound": bound,
                    "unit": "deg" if name.endswith("_deg") else "mm", "key": f"tolerancing.{PLACEMENT_TOLERANCES[name]}",
                    "action": act})
    slope, bound = float(report["residual_slopes"]["residual_slope_p99_mrad"]), crit["residual_slope_p99_mrad"]
    ok = bool(slope <= bound)
    out.append({"check": "residual_slope_p99_mrad", "passed": ok, "value": slope, "standard_error": None,
                "figure": slope, "bound": bound, "unit": "mrad", "key": "tolerancing.max_spot_radius",
                "action": "" if ok else REFINISH})
    return out


def judge(rig, report: dict) -> list[tuple[str, bool, str]]:
    """:func:`checks` as (check, passed, what it found and what to do) per placement and for the dome's slopes."""
    out = []
    for c in checks(rig, report):
        if c["standard_error"] is None:
            text = f"{c['value']:.3g} mrad against {c['bound']:.3g} mrad"
        else:
            text = f"{c['value']:+.4g} ± {c['standard_error']:.2g} against ±{c['bound']:g}"
        out.append((c["check"], c["passed"], text + (f": {c['action']}" if c["action"] else "")))
    return out


def verdict_line(rig, report: dict) -> str:
    """One line: PASS, or FAIL with each failing check (:func:`judge`)."""
    fails = [f"{name} {text}" for name, ok, text in judge(rig, report) if not ok]
    return "calibration: PASS (docs: the manual's 'What passes')" if not fails else "calibration: FAIL: " + "; ".join(fails)


def check_line(c: dict, k: float) -> str:
    """One criterion's line as ``rigcad calibrate`` prints it: PASS or FAIL, the figure against its bound."""
    if c["standard_error"] is None:
        figure, bound = f"{c['figure']:.3g} mrad", f"{c['bound']:.3g} mrad"
    else:
        figure = f"|{c['value']:+.4g}| + {k:g} x {c['standard_error']:.2g} = {c['figure']:.4g} {c['unit']}"
        bound = f"±{c['bound']:g} {c['unit']}"
    return (f"{'PASS' if c['passed'] else 'FAIL'} {c['check']}: {figure} {'within' if c['passed'] else 'over'} "
            f"{bound} ({c['key']})" + (f": {c['action']}" if c["action"] else ""))


def verdict(rig, report: dict) -> dict:
    """The calibration's verdict for calibration.json and the command's output: ``passed``, ``lines`` (one per
    criterion, :func:`check_line`), ``line`` (the verdict in one line) and ``checks`` (:func:`checks`)."""
    rows, k = checks(rig, report), pass_criterion(rig)["standard_errors"]
    fails = [c["check"] for c in rows if not c["passed"]]
    line = (f"calibration: PASS ({len(rows)} of {len(rows)} criteria)" if not fails else
            f"calibration: FAIL ({len(fails)} of {len(rows)} criteria: {', '.join(fails)}; the manual's 'When it "
            "fails' says what to turn or redo)")
    return {"passed": not fails, "line": line, "lines": [check_line(c, k) for c in rows], "checks": rows,
            "criterion": f"each placement against the dome within its tolerance by {k:g} standard errors (|value| + "
                         f"{k:g} x standard_error within the bound); the dome's residual slope p99 within the slope "
                         "the optical acceptance test holds"}


def _what_passes(rig) -> str:
    """The calibration page's pass criterion (:func:`pass_criterion`), with what to do when it fails."""
    crit = pass_criterion(rig)
    k = crit["standard_errors"]
    rows = "\n".join(f"- `{name}`: within ±{bound:g} {'deg' if name.endswith('_deg') else 'mm'} "
                     f"(`tolerancing.{PLACEMENT_TOLERANCES[name]}`)" for name, bound in crit["placements"].items())
    return f"""## What passes
The calibration passes when every line below holds (calibration.json holds each figure): each
placement against the dome (`against_the_dome`) inside its tolerance by {k:g} standard errors at
least (|value| + {k:g} x standard_error within the bound), and the dome's residual slopes at most
the slope that throws a ray `tolerancing.max_spot_radius` off O from the dome's farthest point (the
bound the optical acceptance test holds).

{rows}
- `residual_slopes`' `residual_slope_p99_mrad`: at most {crit['residual_slope_p99_mrad']:.3g} mrad

`rigcad calibrate {rig.profile.name} --images <folder>` prints each line above as PASS or FAIL with its
figure against its bound, then the verdict; it writes them into calibration.json's `verdict` and exits 1
on FAIL. When one fails ('When it fails' below says what to turn, by how much): a placement out by more than its bound (and by more than {k:g} standard errors) is
re-seated as below, then the rig is captured and calibrated again; a placement inside its bound
but with too wide a standard error is captured again (both half turns of each spacer, the room
dark); a slope p99 over its bound marks the dome's area that `maps.png` shows in its residual
slope panel: sand it back to its template, coat it again and calibrate again.
"""


def remedies(rig) -> dict[str, dict]:
    """What to turn for each placement the calibration judges when it is out (the check's name -> ``adjuster``,
    ``how`` it moves the part, ``per_step`` (the check's unit moved by one ``step``), ``range`` each way and
    ``resolution`` in the check's unit), read from the adjusters' and the stops' own declarations
    (rigcad.parts.adjusters, rigcad.parts.paraboloid.stops, rigcad.parts.dome.beam_seats): nothing restated."""
    from rigcad.parts import adjusters as A
    from rigcad.parts.dome import beam_seats
    from rigcad.parts.paraboloid import foil_step, stops
    from rigcad.parts.tower import seat_points
    from rigcad.standards import THREADS

    p, lay = rig.profile, rig.layout
    foil = foil_step()
    x, y = stops(p, lay)
    height, tilt, roll = beam_seats(p, lay).stops()

    def row(adjuster, how, per, step, rng, res, unit):
        k = math.degrees(1.0) if unit == "deg" else 1.0
        return {"adjuster": adjuster, "how": how, "per_step": per * k, "step": step, "range": rng * k,
                "resolution": res * k, "unit": unit}

    out = {"paraboloid_dx_mm": row(x.name, x.how, foil, f"{foil:g} mm of foil", x.range, x.resolution, "mm"),
           "paraboloid_dy_mm": row(y.name, y.how, foil, f"{foil:g} mm of foil", y.range, y.resolution, "mm"),
           "paraboloid_dz_mm": row(height.name, height.how, foil / 2, f"{foil:g} mm of foil at one seat", height.range,
                                   height.resolution, "mm"),
           "paraboloid_tilt_y_deg": row(tilt.name, tilt.how, tilt.resolution, f"{foil:g} mm of foil", tilt.range,
                                        tilt.resolution, "deg"),
           "paraboloid_tilt_x_deg": row(roll.name, roll.how, roll.resolution, f"{foil:g} mm of foil", roll.range,
                                        roll.resolution, "deg")}
    if getattr(lay, "tower", None) is None:
        return out
    slots = {a.name: a for a in A.slot_adjusters(p, lay)}
    flat = A.camera_tilt(p, lay)
    turn = f"{p.adjusters.turn_fraction:g} turn"
    for name, key, step in (("camera_dx_mm", "camera across (x)", "slide in its slot"),
                            ("camera_dy_mm", "camera across (y)", "shim"),
                            ("camera_dz_mm", "camera along the axis", "slide in its slot")):
        a = slots[key]
        out[name] = row(a.name, a.how, a.resolution, f"{a.resolution:g} mm {step}", a.range, a.resolution, "mm")
    out["camera_tilt_y_deg"] = row(flat.name, flat.how, flat.resolution, turn, flat.range, flat.resolution, "deg")
    # the seat's vee screw turns the holder (and the camera's bracket on it) about the cone-flat line: the share
    # of that line along x is the camera's turn about x (the rest, about y, the flat screw takes back)
    pts = seat_points(lay.tower, p)
    arm = A._lever(pts["vee"], pts["cone"], pts["flat"])
    (x1, y1), (x2, y2) = pts["cone"], pts["flat"]
    along_x = abs(x2 - x1) / math.hypot(x2 - x1, y2 - y1)
    step = THREADS[p.adjusters.seat_thread].pitch * p.adjusters.turn_fraction
    out["camera_tilt_x_deg"] = row(
        "camera tilt across its bracket's plane: the seat's vee screw turns the holder and bracket",
        f"{p.adjusters.seat_thread} push screw over the vee's ball, on a {arm:.1f} mm lever about the cone-flat line "
        f"({along_x:.2f} of its turn about x, {math.sqrt(1 - along_x ** 2):.2f} about y: take that back with the flat "
        "screw); it turns the splitter too: align the projector again after it (section 6's crosses, the splitter "
        "seat, the circle)",
        along_x * step / arm, turn, along_x * p.adjusters.seat_travel / arm, along_x * step / arm, "deg")
    return out


def _when_it_fails(rig, refinish: list[str] | None = None) -> str:
    """The calibration page's section on a failed calibration: per failing line what to turn by how much
    (:func:`remedies`), a line unresolved, and the dome's slopes: the finishing recipe from the sanding on
    (``refinish``: its stages' names, rigcad.manual.finishing.recipe's, which the manual and ``--kit`` pass
    down: this floor does not import the manual; without them the page names the recipe alone)."""
    rows = []
    for name, r in remedies(rig).items():
        rows.append(f"- `{name}` out: {r['adjuster']} ({r['how']}). A step ({r['step']}) moves it {r['per_step']:.3g} "
                    f"{r['unit']}: turn or change it by |value| / {r['per_step']:.3g} steps, towards zero; it reaches "
                    f"±{r['range']:.3g} {r['unit']} each way, to within {r['resolution']:.3g} {r['unit']}.")
    first, redo = (refinish[0], "; ".join(refinish[1:])) if refinish else (
        "its first stage", "each of its stages after the first, in its order")
    bound = dome_slope_tolerance(rig)
    return f"""## When it fails
`rigcad calibrate {rig.profile.name} --images <folder>` exits 1 on FAIL, its files written all the same; each FAIL
line names what to do. Work through them in this order, then capture and calibrate again:

1. A line marked *unresolved* (its value inside the bound, but not by two standard errors): nothing is
   moved. Capture again, both half turns of each spacer, the room dark, the exposure as above.
2. A placement *re-seat it* (out by more than its bound): move the part back by the value the line prints,
   with the adjuster below (the paraboloid's stops as the paragraph after 'After the fit' says, in detail):

{chr(10).join(rows)}

3. `residual_slope_p99_mrad` over {bound:.3g} mrad: the dome's slopes, which no adjuster moves. `maps.png`'s
   residual slope panel marks the area. Sand it back and coat it again, by the finishing recipe (the
   manual's 'Finishing recipe, stage by stage'), from its first stage on, on that area only:
   lift the dome off its register (what it carries comes with it), take the paraboloid off the beam, and
   sand the marked area through the mirror coat back to the template's gap ({first}); then redo the
   recipe's stages after it: {redo}. The slope test before the mirror coat (the optical acceptance test,
   on the polished coat) must pass again before the mirror coat goes on. Then set the paraboloid back, the
   dome on its pins, and capture and calibrate again.
"""


def _after_the_fit(tol) -> str:
    """The calibration page's last section: what the fit says to adjust, against the tolerances."""
    parts = "; ".join(f"{c}: {getattr(tol, f'{c}_offset'):g} mm sideways, {getattr(tol, f'{c}_height'):g} mm "
                      f"in height, {math.degrees(getattr(tol, f'{c}_tilt')):g} deg" for c in ("paraboloid", "camera"))
    return f"""## After the fit: what to adjust
The command prints, and `calibration.json`'s `against_the_dome` holds, where the paraboloid and the
camera stand against the dome's axis: each one's offset (mm) along x, y and z, and its tilt (deg)
as turns about x and y, each with its standard error, in the rig's frame (+z up, the projector on
the +x side, the beam along x). That is the placement the images fix. A part off by more than its tolerance ({parts}) and by
more than twice its standard error is worth re-seating: move it back by the offset, then capture
and calibrate again. The same parts under `fit` are placed against the sample plane; they carry the
rig's tilt over that plane too, which only the screen's seating fixes, so their standard errors are
wider.
"""


def write_kit(rig, out: Path, say=lambda msg: None, refinish: list[str] | None = None) -> dict:
    """Write the kit into ``out`` (published atomically): patterns/<frame>.png, stl/ and step/
    calibration_spacer_<k>, calibration.md, conventions.png (the capture conventions drawn:
    :mod:`rigcad.calibrate.conventions`), manifest.json (each file's SHA-256, the parts' volumes);
    with ``upright_turns``, patterns_upright/<frame>.png and calibration_upright_stand too."""
    from rigcad.export import mesh as EM
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest, sha256_hex
    from rigcad.export.step import reimport_check, step_writer
    from rigcad.parts import _kernel as K

    from rigcad.calibrate.upright import Uprights

    p = rig.profile
    check_screen_fits(rig)
    check_upright_fits(p)
    seq = Sequence.from_profile(p.calibration)
    ups = Uprights.of(p)
    files, parts = {}, {}
    with Staging(out, lock=profile_lock(out.parent.parent, p.name) if out.parent.name == p.name else None,
                 made_from=profile_digest(p)) as st:
        for name in seq.names():
            data = pattern_png(seq, name)
            st.write_bytes(out / "patterns" / f"{name}.png", data)
            files[f"patterns/{name}.png"] = sha256_hex(data)
            if len(ups):
                data = pattern_png(ups.seq, name)
                st.write_bytes(out / "patterns_upright" / f"{name}.png", data)
                files[f"patterns_upright/{name}.png"] = sha256_hex(data)
        from rigcad.calibrate.slideshow import slideshow_page

        show = slideshow_page(f"{p.name}: calibration screen", [(n, pattern_png(seq, n)) for n in seq.names()],
                              seq.resolution)
        st.write_bytes(out / "patterns" / "slideshow.html", show)
        files["patterns/slideshow.html"] = sha256_hex(show)
        if len(ups):
            order = ("".join(f"{n}.png\n" for n in seq.names())).encode()
            st.write_bytes(out / "patterns_upright" / "order.txt", order)
            files["patterns_upright/order.txt"] = sha256_hex(order)
        tools = [spacer(p, k) for k in range(len(p.calibration.spacer_heights))]
        for part in tools + ([upright_stand(p)] if len(ups) else []):
            say(part.name)
            shape = K.part_solid(part, p.tessellation.fit_tolerance, K.FitReport(), p)
            step_path = out / "step" / f"{part.name}.step"
            st.write_with(step_path, step_writer([(part.name, shape, part.color)], part.name))
            check = reimport_check(st.temp_path(step_path), K.volume(shape), 1)
            mesh = rig.mesh(part)
            stl = EM.stl_bytes(np.asarray(mesh.vertices), np.asarray(mesh.faces), part.name)
            st.write_bytes(out / "stl" / f"{part.name}.stl", stl)
            files[f"stl/{part.name}.stl"] = sha256_hex(stl)
            files[f"step/{part.name}.step"] = sha256_hex(st.temp_path(step_path).read_bytes())
            parts[part.name] = {"description": part.description, "volume_mm3": K.volume(shape),
                                "step_reimport": check}
        page = manual_page(rig, refinish).encode()
        st.write_bytes(out / "calibration.md", page)
        files["calibration.md"] = sha256_hex(page)
        from rigcad.calibrate import conventions

        picture = conventions.figure(conventions.facts(rig))
        st.write_bytes(out / "conventions.png", picture)
        files["conventions.png"] = sha256_hex(picture)
        manifest = {"profile": p.name, "screen_resolution_px": list(p.calibration.screen_resolution),
                    **({"upright_resolution_px": list(p.calibration.upright_resolution)} if len(ups) else {}),
                    "frames_in_capture_order": seq.names(), "parts": parts, "files": files}
        st.write_bytes(out / "manifest.json", json_bytes(manifest))
        st.commit()
    return manifest
