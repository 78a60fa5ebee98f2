"""Base plate (bolted to the dome's flange, its top face is the sample plane z = 0) and the
sample holder that slides into its bore so the sample's top surface lands on z = 0.

The bore is the sample point O, the datum of everything: drawn at its finished size, it prints under
by the printer's hole shrink and is bored H7; the holder is turned from aluminium bar to f7, the ISO 286
sliding fit (rigcad.parts.locating.holder_fit): the sample sits on the bore's axis to half that fit's
largest clearance, a link of every element's tolerance stack (rigcad.fab.stack). The camera's cross
and the calibration kit's plugs are printed, ``sample_holder.clearance`` each side under the finished
bore."""

from __future__ import annotations

import math

from rigcad.parts import breadboard
from rigcad.parts.dome import flange_joint, register
from rigcad.parts.joints import Datum, datums_of
from rigcad.parts.layout import RigLayout
from rigcad.parts.locating import holder_fit
from rigcad.parts.recipe import Box, Cylinder, Difference, Part, Union_
from rigcad.parts.tower import COLLAR_BENCH_GAP_MM, column_datums, column_joint_cuts, tongue_underside_cuts
from rigcad.profile.schema import Profile


def base_plate(profile: Profile, layout: RigLayout) -> Part:
    """The rig's datum: a disc bolted to the dome's flange, bored for the sample holder, with a tongue
    out to the COP tower's column, whose foot it locates by two dowels and holds by four bolts (nuts
    in hexagonal traps underneath). The tongue reaches down to the bench (COLLAR_BENCH_GAP_MM under
    the sample holder's stop collar): the tower's weight goes into the bench, not through the disc; two feet
    under the rim (:func:`feet`) make it three supports."""
    t = profile.base_plate.thickness
    holder = profile.sample_holder
    plate = Cylinder((0.0, 0.0, -t), layout.plate_r, t)
    tw = layout.tower
    half = tw.column_foot_half
    x0 = math.sqrt(layout.plate_r ** 2 - half ** 2) - 1.0  # 1 mm inside the disc's rim: one solid
    tongue = Box((x0, -half, tw.bench_z), (tw.column_x + half, half, 0.0))  # down to the bench: the tower's weight
    bore = Cylinder((0.0, 0.0, -t - 1.0), bore_drawn(profile) / 2, t + 2.0)
    groove = azimuth_groove(profile, tw.bench_z)
    inserts = flange_joint(profile, layout).thread_holes()  # the dome's screws' insert pockets, as the joint declares
    pins = register(profile, layout).lower_holes()  # the dome's register pins, pressed in (none printed when drilled in place)
    holes = inserts + pins
    joint = (*column_joint_cuts(tw, profile, tw.bench_z, -tw.bench_z, "top"), *tongue_underside_cuts(tw, profile, tw.bench_z))
    # the datum features a split keeps off: the sample bore (O), the dome's insert pockets and register pins,
    # the column's dowel holes (or the extrusion's pocket) in the tongue; each is also one of the cuts above
    datums = (Datum("sample bore", "bore", bore), *datums_of("insert", "flange insert pocket", inserts),
              *datums_of("register", "dome register pin hole", register(profile, layout).lower_zones()),
              *column_datums(tw, profile, tw.bench_z, -tw.bench_z, "top", "tongue"))
    b = breadboard.board(profile)
    pads = (*feet(profile, layout), *(breadboard.pads(profile, layout) if b else ()))
    anchors = breadboard.holes(profile, layout) if b else ()
    on_board = "" if b is None else (
        f"; it stands on the {b.title}: the sample point over a tapped hole, the tongue along a row of holes, "
        f"screwed down on the grid through its pad and the boss under the disc")
    fit = holder_fit(2 * holder.radius, where=profile.where("sample_holder", "radius"))
    desc = ("base plate, the rig's datum: the dome's flange screws into its heat-set inserts; the sample holder slides "
            f"into its bore, drawn at {bore_drawn(profile):g} mm, printed under by the printer's hole shrink and "
            f"bored (or reamed) to {fit.size:g} {fit.hole} on a mill, square to the plate's top face, before anything "
            "is fitted "
            "(the groove under the disc on the tongue's side is the calibration parts' turn mark); "
            "its tongue locates the tower's column " + (
                f"by two {profile.datum.dowel_diameter:g} mm dowels (pressed into blind holes reamed N7) and four bolts"
                if profile.buy.column == "print" else "(an extrusion) in a square pocket, an M8 bolt into its core")
            + on_board + ("; it stands on three feet: the tongue's underside and two pads under the disc's rim, "
                          if b is None else "; its tongue, its two feet under the disc's rim and the boss bear on the "
                          "board, ") + f"the sample holder's collar {COLLAR_BENCH_GAP_MM:g} mm clear of the "
            + ("bench" if b is None else "board"))
    return Part("base_plate", Difference(Union_((plate, tongue, *pads)), (bore, groove, *holes, *joint, *anchors)),
                (0.55, 0.57, 0.6), desc, datums=datums)


#: The base plate's two printed feet under the disc's rim (with the tongue, the rig's three supports):
#: their azimuths (rad from +x, the tongue's side; 120 deg each side, so the three supports stand about
#: equally round O), their radius, and how far (mm) each stays inside the disc's rim.
FOOT_AZIMUTHS = (2.0 * math.pi / 3.0, -2.0 * math.pi / 3.0)
FOOT_RADIUS_MM, FOOT_RIM_INSET_MM = 10.0, 4.0
#: A foot reaches this far (mm) up into the disc (one solid), short of the dome's insert pockets above it.
FOOT_OVERLAP_MM = 0.5


def feet(profile: Profile, layout: RigLayout) -> tuple[Cylinder, ...]:
    """The disc's two feet (:data:`FOOT_AZIMUTHS`): printed pads from the bench (the tongue's underside,
    ``layout.tower.bench_z``) up into the disc, FOOT_RIM_INSET_MM inside its rim. With the tongue they are
    the rig's three supports; the sample holder's collar stands COLLAR_BENCH_GAP_MM over the bench."""
    t, bench = profile.base_plate.thickness, layout.tower.bench_z
    r = layout.plate_r - FOOT_RIM_INSET_MM - FOOT_RADIUS_MM
    return tuple(Cylinder((r * math.cos(a), r * math.sin(a), bench), FOOT_RADIUS_MM, -t + FOOT_OVERLAP_MM - bench)
                 for a in FOOT_AZIMUTHS)


#: The turn mark under the base plate: a groove across the disc's underside along +x (the tongue's
#: side), from just outside the sample holder's stop collar. A plug that stands in the bore at set
#: turns (the calibration spacers, the upright display's stand: rigcad.calibrate.kit) carries notches
#: in its collar's rim, and a turn is set, from below, by the notch that faces the groove.
#: Width, depth into the disc, length, and its gap from the collar's rim (mm).
GROOVE_WIDTH_MM, GROOVE_DEPTH_MM, GROOVE_LENGTH_MM, GROOVE_GAP_MM = 1.0, 0.6, 10.0, 0.5
#: A collar's notches (vertical half-cylinders cut into its rim, through its thickness): a turn's own
#: mark, and the wide one that marks the first turn (mm, radius).
NOTCH_MM, WIDE_NOTCH_MM = 0.8, 1.6


def azimuth_groove(profile: Profile, bench_z: float) -> Box:
    """The base plate's turn mark (:data:`GROOVE_WIDTH_MM`): cut from below the bench level (``bench_z``,
    through anything under the disc there) to its depth into the disc."""
    t = profile.base_plate.thickness
    r0 = profile.sample_holder.stop_radius + GROOVE_GAP_MM
    w = GROOVE_WIDTH_MM / 2
    return Box((r0, -w, min(bench_z, -t) - 1.0), (r0 + GROOVE_LENGTH_MM, w, -t + GROOVE_DEPTH_MM))


def bore_drawn(profile: Profile) -> float:
    """The sample bore as drawn (mm, its diameter): its finished size, bored (or reamed) to the fit's hole
    (:func:`rigcad.parts.locating.holder_fit`); a printed hole comes out smaller by the printer's hole
    shrink (rigcad.parts.process), which is the boring's stock."""
    return 2 * profile.sample_holder.radius


def holder_drawn(profile: Profile, turned: bool) -> float:
    """A plug's body as drawn (mm, its diameter): ``turned`` (the sample holder, which stands for the
    sample point O: turned from bar), the finished size, turned to the fit's shaft; else (the camera's
    cross and the calibration kit's plugs, printed) ``sample_holder.clearance`` each side under the
    finished bore."""
    d = 2 * profile.sample_holder.radius
    return d if turned else d - 2 * profile.sample_holder.clearance


def holder_body(profile: Profile, top_z: float, marks: tuple[tuple[float, float], ...] = (),
                turned: bool = False) -> Cylinder | Union_ | Difference:
    """Holder cylinder up to ``top_z`` with its stop collar under the plate (its body :func:`holder_drawn`:
    ``turned`` to the sliding fit, else a printed plug's clearance). ``marks``: notches in the
    collar's rim as (azimuth rad from +x, radius mm) (:data:`NOTCH_MM`): the plug turned so that
    one faces the base plate's groove (:func:`azimuth_groove`) stands at that notch's turn."""
    t = profile.base_plate.thickness
    h = profile.sample_holder
    body = Cylinder((0.0, 0.0, -t), holder_drawn(profile, turned) / 2, top_z + t)
    collar = Cylinder((0.0, 0.0, -t - h.stop_thickness), h.stop_radius, h.stop_thickness)
    if not marks:
        return Union_((body, collar))
    ring = h.stop_radius - h.radius  # a notch keeps within the collar's ring, clear of the body
    notches = tuple(Cylinder((h.stop_radius * math.cos(a), h.stop_radius * math.sin(a), -t - h.stop_thickness - 1.0),
                             min(r, ring / 2), h.stop_thickness + 2.0) for a, r in marks)
    return Union_((body, Difference(collar, notches)))


def sample_holder(profile: Profile, layout: RigLayout) -> Part:
    h = profile.sample_holder
    top = -h.sample_thickness
    return Part("sample_holder", holder_body(profile, top, turned=True), (0.2, 0.45, 0.7),
                f"sample holder for a {h.sample_thickness:g} mm sample: its top surface lands on the design point; "
                + turning_text(profile), bought=holder_stock(profile))


#: Turning allowance (mm) on the bar's diameter over the holder's collar, and on its length (facing both ends
#: and parting off).
BAR_ALLOWANCE_MM, BAR_LENGTH_ALLOWANCE_MM = 4.0, 5.0
#: The holder bar's linear thermal expansion (1/K): EN AW-6082 T6, 23.4e-6 /K (20-100 C; suppliers' data
#: sheets, EN 755-2's alloy). Against the printed bore's (rigcad.fab.loads.MATERIALS) it sets how much the
#: bore closes on the holder in a cold lab: the holder's fit keeps clearance there (rigcad.parts.locating).
HOLDER_BAR_EXPANSION = 23.4e-6


def holder_stock(profile: Profile) -> str:
    """The bar the sample holder is turned from, as one orders it (aluminium EN AW-6082, the collar's
    diameter and the holder's length with their allowances, rounded up to whole millimetres)."""
    h, t = profile.sample_holder, profile.base_plate.thickness
    length = t - h.sample_thickness + h.stop_thickness
    return (f"aluminium round bar EN AW-6082 T6, {math.ceil(2 * h.stop_radius + BAR_ALLOWANCE_MM):d} mm diameter x "
            f"{math.ceil(length + BAR_LENGTH_ALLOWANCE_MM):d} mm: turned to the drawing")


def turning_text(profile: Profile) -> str:
    """The shop step for the sample holder, the sample point O in the bore: turned from bar on a lathe, its
    body to the fit's shaft (:func:`rigcad.parts.locating.holder_fit`) and its top face square to it, so
    that it sits on the bore's axis to half the fit's largest clearance."""
    fit = holder_fit(2 * profile.sample_holder.radius, where=profile.where("sample_holder", "radius"))
    lo, hi = fit.clearance
    return (f"turned from bar on a lathe ({holder_stock(profile)}): its body {fit.size:g} {fit.shaft} (measured with "
            f"an outside micrometer), its top face square to it, in the base plate's bore bored to {fit.size:g} {fit.hole} "
            "(a boring bar on the lathe's faceplate, or a boring head on a mill; checked with the holder itself): "
            f"{fit.describe()}, so it sits within {hi / 2:.3f} mm of the bore's axis")


def base_cross(profile: Profile, layout: RigLayout) -> Part:
    """Camera calibration: a plug in place of the sample holder with a raised cross whose top is z = 0."""
    cr = profile.crosses
    body = holder_body(profile, -cr.thickness)
    arm = min(cr.arm_length, profile.sample_holder.radius - 1.0)
    bw = cr.bar_width / 2
    bars = (Box((-arm, -bw, -cr.thickness), (arm, bw, 0.0)), Box((-bw, -arm, -cr.thickness), (bw, arm, 0.0)))
    return Part("camera_cross_base", Union_((body, *bars)), (0.9, 0.5, 0.1),
                "camera calibration: cross on the base plate's centre (replaces the sample holder)", in_rig=False)
