"""Calibration as thesis 4.1.1 does it, with the figures rigcad can compute for it.

- The projector's circle image: a bright disc at the projector's resolution whose edge is the
  paraboloid's rim as the projector shows it through its focusing lens, which stays in place as for
  the basis (rigcad.optics.focus.LensedProjector: the lens moves the COP the paraboloid sees and
  scales the pixels' angles; image centre on the optical axis), so that "the projected circle
  matches the circumference of the parabola base". Frame of the image: as rigcad.check.sources.pixel_grid
  (pixel centre x = column + 0.5 - width / 2, y = height / 2 - row - 0.5).
- What the film over the dome's base shows: the reflected light converges to the sample point O;
  light projected past the rim (a circle too large) falls straight onto the film outside the
  paraboloid's shadow, whose radius is computed here, and the beam's shadow strip with it.
- The projector crosses (on their mounting plate, on the shelf) and the backplate: aligned, both shadows are
  centred on the backplate at the axis height; a projector off the crosses' line by d mm separates
  the two shadows by d x (X / a - b / (s + a)) (a: projector to near cross, s: cross spacing,
  b: far cross to backplate, X = s + b), at the distance the shelf puts them from the projector.
- The camera crosses (hung at the paraboloid's vertex, on the base at z = 0): a camera off the axis
  by d mm sees them apart by d x (1 / (cop_z - z_vertex) - 1 / cop_z) rad.

Lengths mm, angles rad inside; figures written with their unit in the key.
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError
from rigcad.parts.base import bore_drawn

def circle_image(rig) -> tuple[bytes, dict]:
    """The calibration circle at the projector's resolution (8-bit grey PNG: 255 inside the rim's
    pixel radius, 0 outside; pixel centres tested) and its figures."""
    from PIL import Image

    if rig.geometry.cop_at_infinity:
        raise GeometryError("the calibration circle needs a finite COP (layout.cop_to_vertex)",
                            param="layout.cop_to_vertex")
    from rigcad.optics.focus import focusing_lens

    design, g = rig.incidence, rig.geometry
    width, height = rig.profile.projector.resolution
    lensed = focusing_lens(rig.profile, g).projector(g.projector_focal_px, g.cop_z)  # set with the lens in place
    radius = lensed.ring_radius(g, design.alpha_max)
    from rigcad.profile.derived import check_disc, projector_disc_room, projector_principal_point

    cx, cy = projector_principal_point(rig.profile.projector)  # the lens axis's pixel: the disc's centre
    x = np.arange(width) + 0.5 - cx
    y = cy - np.arange(height) - 0.5
    inside = x[None, :] ** 2 + y[:, None] ** 2 <= radius ** 2
    check_disc(rig.profile, radius)  # an offset lens: design's refusal and its remedy, for the lensed disc
    if radius > projector_disc_room(rig.profile.projector):
        raise GeometryError(f"the paraboloid's rim is {radius:.1f} px from the lens axis's pixel ({cx:g}, {cy:g}), "
                            f"outside the {width} x {height} px projector image with the focusing lens in place: a "
                            "lower projector.throw_ratio (zoom wider)", param="projector.throw_ratio")
    buf = io.BytesIO()
    Image.fromarray(np.where(inside, 255, 0).astype(np.uint8), mode="L").save(buf, format="PNG")
    info = {"resolution_px": [width, height], "centre_px_from_top_left": [cx, cy],
            "radius_px": radius, "lit_pixels": int(inside.sum()),
            "rim_angle_at_cop_deg": math.degrees(design.alpha_max),
            "occlusion_radius_px": lensed.ring_radius(g, design.alpha_min),
            "radius_without_lens_px": float(design.pixel_radius(np.array([design.alpha_max]))[0]),
            "lens_cop_shift_mm": lensed.cop_shift, "lens_pixel_scale": lensed.pixel_scale}
    return buf.getvalue(), info


def film_shadows(rig) -> dict:
    """What the projector throws straight onto the film at z = 0 past the paraboloid (mm): the
    paraboloid rim's shadow radius and the beam's shadow half-width (their images from the COP)."""
    g = rig.geometry
    zc = g.cop_z
    beam_top = rig.layout.beam_z[1]
    w = rig.profile.beam.width
    return {"paraboloid_shadow_radius_mm": g.rim_radius * zc / (zc - g.rim_z),
            "beam_shadow_half_width_mm": (w / 2) * zc / (zc - beam_top),
            "cop_z_mm": zc, "rim_z_mm": g.rim_z, "rim_radius_mm": g.rim_radius, "beam_top_z_mm": beam_top}


#: Matte drafting film (polyester) for the film test: thin enough to lie flat on the plate's top, matte
#: so the spot shows from below; the disc reaches FILM_MARGIN_MM past the bore to be taped down.
FILM_THICKNESS_MM = 0.075
FILM_MARGIN_MM = 20.0
#: Room (mm) under the base plate's underside to look up through its bore: a 45 deg mirror as wide as
#: the bore needs its width in height, and this much more for the hand and the phone.
VIEW_MARGIN_MM = 10.0


def film_setup(rig) -> dict:
    """How the film of the circle test lies at the sample plane (mm): on the base plate's top, which is
    the dome's base plane and the sample plane z = 0 by design, across the plate's bore (the sample
    holder taken out), centred by the camera_cross_base (its cross's top is z = 0, its body fits the
    bore as the holder does); seen from below through the bore, the rig lifted on three blocks. The
    tongue reaches lower than the disc by ``tongue_below_disc_mm``: the disc's blocks are that much
    taller than the tongue's. ``direct_light_seen``: whether light past the rim (outside the
    paraboloid's shadow) falls inside the bore."""
    p, t = rig.profile, rig.layout.tower
    bore = bore_drawn(p) / 2  # the bore as finished (bored to the sample holder's fit)
    view = 10.0 * math.ceil((2 * bore + VIEW_MARGIN_MM) / 10.0)
    below = (-p.base_plate.thickness) - t.bench_z if t is not None else 0.0
    shadow = film_shadows(rig)["paraboloid_shadow_radius_mm"]
    return {"bore_radius_mm": bore, "film_diameter_mm": 2 * (bore + FILM_MARGIN_MM),
            "film_thickness_mm": FILM_THICKNESS_MM, "plate_thickness_mm": p.base_plate.thickness,
            "block_under_disc_mm": view, "block_under_tongue_mm": view - below, "tongue_below_disc_mm": below,
            "paraboloid_shadow_radius_mm": shadow, "direct_light_seen": shadow < bore,
            "dome_bolts": len(rig.layout.bolt_angles)}


def projector_shadows(rig) -> dict:
    """The projector crosses' shadows on the backplate, as they stand on the shelf
    (rigcad.parts.crosses.cross_fixture): aligned, and per mm of the projector's offset across its axis."""
    from rigcad.parts.crosses import cross_fixture

    f = cross_fixture(rig.profile, rig.layout)
    s, b, L, a = f.spacing, f.backplate_distance, rig.profile.crosses.arm_length, f.projector_distance
    X = s + b
    return {"axis_height_mm": f.axis_height, "spacing_mm": s, "backplate_distance_mm": b, "arm_length_mm": L,
            "backplate_size_mm": f.backplate_size, "plate_length_mm": f.plate_x[1] - f.plate_x[0],
            "rows": [{"projector_to_near_cross_mm": a,
                      "near_shadow_arm_mm": L * (X + a) / a, "far_shadow_arm_mm": L * (X + a) / (s + a),
                      "separation_per_mm_offset": X / a - b / (s + a)}]}


def access(rig) -> list[dict]:
    """How each calibration item reaches its place, and what rigcad checked of it: one row per item
    (item, the way in, what moves out of its way, how that part goes back, the check). The checks are
    the ones the parts and the kit run (they raise GeometryError or ProfileError naming the key when
    an item cannot go in); this lists them for the manual."""
    from rigcad.parts.crosses import cross_fixture
    from rigcad.parts.dome import register

    p = rig.profile
    reg = register(p, rig.layout)
    lateral, _ = reg.repeatability
    back = (f"on its {len(reg.points)} register pins, within {1e3 * lateral:.0f} µm "
            f"(`tolerancing.dome_offset` {p.tolerancing.dome_offset:g} mm)")
    bore = f"the base plate's bore ({bore_drawn(p):g} mm), from below"
    rows = []
    if getattr(rig.layout, "tower", None) is not None:
        f = cross_fixture(p, rig.layout)
        rows.append({"item": "projector crosses, backplate and their plate", "way": "onto the shelf, from above",
                     "out_of_the_way": "the splitter holder (with the camera; its spring bolts undone first) and the "
                                       "focusing lens",
                     "back": "the holder on its kinematic seat, its spring bolts set back to the springs' length; the "
                             "lens in its pocket",
                     "checked": f"the plate ({f.plate_x[1] - f.plate_x[0]:.0f} mm) sits on the splitter seat's cone, vee and "
                                "flat on its three balls, short of the lens mount at either end of its slots; the "
                                "crosses' centres on the projector's axis"})
    rows += [
        {"item": "camera cross on the beam", "way": "onto the beam in the paraboloid's place",
         "out_of_the_way": "the dome (the beam and the paraboloid come off with it)", "back": back,
         "checked": "the same clamp as the paraboloid's, at its vertex height"},
        {"item": "camera cross in the base plate", "way": bore, "out_of_the_way": "the sample holder",
         "back": "the holder in the bore", "checked": "the holder's own body and collar"},
        {"item": "gray card and its foil", "way": "onto the sample holder's top, from above, the first time (to check "
         "it flush with the plate's top); afterwards on the holder, through " + bore,
         "out_of_the_way": "the dome the first time; afterwards the sample holder", "back": back + "; the holder in "
         "the bore", "checked": "the card's face flush with the plate's top (straightedge and feeler leaf); the "
         "holder's collar sets its height after"},
        {"item": "film at the sample plane, checkerboard disc", "way": "onto the base plate, from above",
         "out_of_the_way": "the dome", "back": back,
         "checked": "the disc cut to the dome's inside at the plate, less 1 mm"},
    ]
    if getattr(p, "calibration", None) is not None:
        from rigcad.calibrate.kit import check_screen_fits

        room = check_screen_fits(rig)
        rows.append({"item": "calibration screen on its spacers", "way": "spacer into " + bore + "; the screen on it, "
                     "from above", "out_of_the_way": "the dome", "back": back,
                     "checked": f"the screen fits the dome's inside at every spacer (a {room['body_diameter_mm']:.0f} mm "
                                "circle at the tightest)"})
        if p.calibration.upright_turns:
            rows.append({"item": "upright display on its stand", "way": bore, "out_of_the_way": "the sample holder",
                         "back": "the holder in the bore", "checked": "the display's module fits the stand's slot in "
                                                                        "the bore (rigcad calibrate --kit)"})
    return rows


def camera_crosses(rig) -> dict:
    """The camera crosses: heights and their angular separation per mm of camera offset."""
    g = rig.geometry
    per_mm = 1.0 / (g.cop_z - g.vertex_z) - 1.0 / g.cop_z
    return {"hung_cross_z_mm": g.vertex_z, "base_cross_z_mm": 0.0, "cop_z_mm": g.cop_z,
            "separation_mrad_per_mm_offset": 1e3 * per_mm,
            "hung_cross_arm_mrad": 1e3 * rig.profile.crosses.arm_length / (g.cop_z - g.vertex_z),
            "base_cross_arm_mrad": 1e3 * rig.profile.crosses.arm_length / g.cop_z}


__all__ = ["access", "camera_focus_and_lock", "circle_radius_px", "cop_height_check", "shared_cop", "shared_cop_text", "checker_text", "instrument_torques", "projector_focus", "projector_focus_text", "projector_lock", "gray_card_placement", "record_circle", "camera_correspondence", "camera_crosses", "circle_image", "circle_page", "film_setup", "film_shadows", "projector_shadows"]


def record_circle(rig, info: dict) -> str:
    """The circle step's last paragraph: record the measured circle (centre and radius, px from the
    image's top-left corner) where ``rigcad basis`` and ``rigcad calibrate --gray-card-kit`` read it
    (rigcad.basis.measured.CIRCLE_JSON, or their ``--circle CX CY R``)."""
    from rigcad.basis.measured import CIRCLE_JSON

    w, h = info["resolution_px"]
    return ("**Record the circle.** When the spot is a point on the mark, write down the centre and radius the page "
            "shows (h brings the read-out back): they are the projector's measured frame, and every later projector "
            f"image is drawn for them. Write them into `exports/{rig.name}/{CIRCLE_JSON}` as "
            f"`{{\"centre_px_from_top_left\": [CX, CY], \"radius_px\": R, \"resolution_px\": [{w}, {h}]}}` (or give "
            f"them as `--circle CX CY R` to each command): `rigcad basis {rig.name}` draws the basis images and "
            f"`rigcad calibrate {rig.name} --gray-card-kit` the reflectance step's for that circle, and each prints which "
            "circle it used (the design's when it found none).")

def gray_card_placement(rig, card: dict) -> str:
    """The gray card step's placement (``card``: rigcad.manual.document.gray_card_seat, mm): the card
    packed up to O on the sample holder's top and checked flush with the straightedge on the plate's top,
    which only the dome lifted off lays bare; afterwards the holder's collar, not the dome, sets the card's
    height, so it comes out and goes back with the holder from below, the dome on."""
    bolts = len(rig.layout.bolt_angles)
    top = -card["holder_top_z_mm"]
    return (f"**Where the card sits.** O, the sample point, is on the base plate's top face (z = 0). The sample "
            f"holder's top stands **{top:g} mm under it** (`sample_holder.sample_thickness`), at the bottom of the "
            f"bore's {card['bore_diameter_mm']:.1f} mm pocket, so that a sample of that thickness has its face at O. "
            "Measure the card's thickness with the caliper and cut a pack of the shim foil (the bill's: "
            f"{', '.join(f'{v:g}' for v in card['foil_mm'])} mm sheets, cut to a {card['card_diameter_mm']:g} mm "
            f"disc) of {top:g} mm less the card's thickness: on the holder's top, the card on it, its face is then at "
            f"O's height, to the thinnest foil's {card['foil_mm'][0]:g} mm. A card thicker than that pocket cannot "
            "reach O: use a thinner one. "
            f"**Set it the first time with the dome off**, the one way to reach the plate's top: take out the dome's "
            f"{bolts} flange screws and lift it off its register pins (as in the step before), the sample holder in "
            "its bore, its collar home. Lay the foil and the card on the holder's top from above and check with the "
            "steel straightedge across the bore, on the plate's top either side: a "
            f"{card['feeler_mm']:g} mm feeler leaf passes under it neither over the plate nor over the card (add or "
            "take out foil until it does). Set the dome back on its pins and screw it down to its torque (section 5). "
            "**Afterwards, the dome on:** the holder's collar, not the dome, sets the card's height, so to take the "
            "card out or put it back (the rig on its lifting blocks) draw the sample holder down out of the bore with "
            "the foil and the card on its top, and push it back up until its collar stops.")

#: The adjustable circle page: a full-screen canvas, the disc drawn in device pixels (the projector's
#: own pixels when the page fills its screen). Keys: arrows move by 1 px (Shift: 10 px), + and - change
#: the radius by 1 px (Shift: 10 px), 0 restores the design's circle, f toggles full screen, h hides
#: the read-out. window.rigcadCircle exposes the state to scripts (the browser test reads it).
_CIRCLE_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>@@TITLE@@</title>
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; script-src 'unsafe-inline'">
<style>html,body{margin:0;height:100%;background:#000;overflow:hidden}canvas{display:block;width:100vw;height:100vh}
#info{position:fixed;left:8px;top:6px;color:#f80;font:14px monospace;white-space:pre}</style></head>
<body><canvas id="c"></canvas><div id="info"></div>
<script>
"use strict";
const DESIGN = @@DESIGN@@;
const state = {cx: DESIGN.cx, cy: DESIGN.cy, r: DESIGN.r, info: true};
const canvas = document.getElementById("c"), info = document.getElementById("info");
function draw() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round(window.innerWidth * dpr), h = Math.round(window.innerHeight * dpr);
  canvas.width = w; canvas.height = h;
  const g = canvas.getContext("2d");
  g.fillStyle = "#000"; g.fillRect(0, 0, w, h);
  g.fillStyle = "#fff"; g.beginPath(); g.arc(state.cx, state.cy, Math.max(state.r, 0), 0, 2 * Math.PI); g.fill();
  const off = (w !== DESIGN.width || h !== DESIGN.height) ?
    "\\nscreen " + w + " x " + h + " px: not the projector's " + DESIGN.width + " x " + DESIGN.height + " px" : "";
  info.style.display = state.info ? "block" : "none";
  info.textContent = "centre (" + state.cx.toFixed(1) + ", " + state.cy.toFixed(1) + ") px from the top left\\n" +
    "radius " + state.r.toFixed(1) + " px (design " + DESIGN.r.toFixed(1) + " px)\\n" +
    "arrows: move, + -: radius (Shift: x10), 0: design, f: full screen, h: hide this" + off;
  window.rigcadCircle = {cx: state.cx, cy: state.cy, r: state.r, width: w, height: h};
}
window.addEventListener("keydown", (e) => {
  const step = e.shiftKey ? 10 : 1;
  const k = e.key;
  if (k === "ArrowLeft") state.cx -= step; else if (k === "ArrowRight") state.cx += step;
  else if (k === "ArrowUp") state.cy -= step; else if (k === "ArrowDown") state.cy += step;
  else if (k === "+" || k === "=") state.r += step; else if (k === "-" || k === "_") state.r = Math.max(0, state.r - step);
  else if (k === "0") { state.cx = DESIGN.cx; state.cy = DESIGN.cy; state.r = DESIGN.r; }
  else if (k === "h") state.info = !state.info;
  else if (k === "f") { if (document.fullscreenElement) document.exitFullscreen(); else document.documentElement.requestFullscreen(); }
  else return;
  e.preventDefault(); draw();
});
window.addEventListener("resize", draw);
draw();
</script></body></html>
"""


def circle_page(rig, info: dict) -> bytes:
    """The calibration circle as an adjustable full-screen page (see _CIRCLE_PAGE), starting at the
    design's circle (``info`` from :func:`circle_image`): self-contained, no request leaves it."""
    import html
    import json

    w, h = info["resolution_px"]
    design = {"cx": info["centre_px_from_top_left"][0], "cy": info["centre_px_from_top_left"][1],
              "r": round(info["radius_px"], 3), "width": w, "height": h}
    title = html.escape(f"{rig.name}: calibration circle ({w} x {h} px)")
    return _CIRCLE_PAGE.replace("@@TITLE@@", title).replace("@@DESIGN@@", json.dumps(design)).encode("utf-8")


# -- the calibration kit: every bought or made item section 6 uses, with what to buy ----------------
#: Section 6's steps (its subsections, as the manual heads them), in the order the manual gives them.
STEP_CROSSES = "Projector: the crosses and the backplate"
STEP_CIRCLE = "Projector: the circle on the paraboloid"
STEP_SEAT = "Projector: the splitter seat's three push screws"
STEP_FILM = "The film at the sample plane"
STEP_CAMERA = "Camera: the two crosses"
STEP_CHECKER = "Camera pixels to paraboloid points: the checkerboard"
STEP_GRAY = "Reflectance (thesis 4.1.2)"
STEP_AS_BUILT = "Calibrating the as-built rig (deflectometry)"
#: The optical acceptance test of the finishing (section 3) uses the film test's set-up and items too.
STEP_ACCEPTANCE = "Optical acceptance test"
#: The checkerboard's square (mm): 5 mm prints sharply on a laser printer and spans several camera
#: pixels in the paraboloid's image of the base plate.
CHECKER_SQUARE_MM = 5.0
#: ISO 216 A-series sheets (mm, short x long side), small to large: the checkerboard's paper.
A_SHEETS = (("A4", 210.0, 297.0), ("A3", 297.0, 420.0), ("A2", 420.0, 594.0), ("A1", 594.0, 841.0))
#: The lifting blocks' least footprint (mm, square): a rig on three blocks must not tip off one.
BLOCK_FOOTPRINT_MM = 60.0


@dataclass(frozen=True)
class KitItem:
    """One item of the calibration kit: as it is ordered (or made), how many, what to buy (size,
    standard or spec), the words section 6 names it by (lower case) and the steps (section 6's
    subsections) that use it."""

    item: str
    quantity: str
    spec: str
    words: tuple[str, ...]
    steps: tuple[str, ...]


def checkerboard(rig) -> dict:
    """The checkerboard disc that lies on the base plate inside the dome (mm): the dome's inside at the
    plate less 1 mm, whole squares across it, the bore's hole, and the smallest ISO A sheet it fits."""
    lay = rig.layout
    inside = float(lay.printed_dome.points(np.array([lay.u_inner_base]))[0, 0])  # the dome's inside at the plate
    r = math.floor(inside - 1.0)
    n = math.ceil(2 * r / CHECKER_SQUARE_MM)
    sheet = next((name for name, a, _ in A_SHEETS if a >= 2 * r), None)
    return {"dome_inside_diameter_mm": 2 * inside, "disc_diameter_mm": float(2 * r), "squares": n,
            "square_mm": CHECKER_SQUARE_MM, "hole_diameter_mm": bore_drawn(rig.profile),
            "sheet": sheet or "a plotter roll", "disc_radius_mm": float(r)}


#: How well a rim's edge is read by eye in an image viewer (px): to the nearest pixel. No band of the
#: checkerboard's comparison is drawn finer than this, which the reading could not judge.
EDGE_READ_PX = 1.0


def camera_correspondence(rig) -> dict:
    """What the checkerboard step compares (px, camera image; rigcad.optics.camera): the paraboloid's
    image, the calibrated circle projected on it, seen by the aligned camera, is a disc whose centre
    should be the principal point and whose radius the design's rim radius f_px tan(rim angle at the
    COP). Its pass band is what the camera's own tolerances move it by, to first order: a lateral offset
    ``tolerancing.camera_offset`` shifts the rim's image by f_px offset / (COP to rim plane) and a tilt
    ``tolerancing.camera_tilt`` by f_px tan(tilt), together the centre's band; a height error
    ``tolerancing.camera_height`` scales the radius by height / (COP to rim plane), the radius's band.
    Neither band is finer than EDGE_READ_PX.

    The disc is read against the checkerboard, which the camera sees directly (not through the mirrors:
    every ray through them lands on O, in the bore's hole) in a ring about it: the plate from the
    paraboloid's shadow out to where the dome's top opening cuts the view from the COP
    (``direct_ring_mm``, mm from O on z = 0; ``ring_px`` in each lens's pixels). ``lenses``: the figures
    for the camera model's focal length and, when the bill names a lens to buy
    (rigcad.manual.camera_lens), for that lens too (every figure scales with f_px)."""
    from rigcad.manual.camera_lens import camera_lens
    from rigcad.optics.camera import camera_model

    g, t, lay = rig.geometry, rig.profile.tolerancing, rig.layout
    cam = camera_model(rig.profile, g)
    reach = g.cop_z - g.rim_z  # the COP to the rim's plane (mm)
    shadow = g.rim_radius * g.cop_z / reach  # the paraboloid's shadow on the plate, seen from the COP
    dome = lay.printed_dome
    top_r, top_z = (float(v) for v in dome.points(np.array([dome.u_range[1]]))[0])
    outer = min(top_r * g.cop_z / (g.cop_z - top_z), checkerboard(rig)["disc_radius_mm"])

    def figures(name: str, f_px: float) -> dict:
        centre_band = f_px * (t.camera_offset / reach + math.tan(t.camera_tilt))
        radius_band = f_px * g.rim_radius / reach * t.camera_height / reach
        return {"lens": name, "focal_length_px": f_px, "image_radius_px": f_px * g.rim_radius / reach,
                "centre_tolerance_px": max(centre_band, EDGE_READ_PX),
                "radius_tolerance_px": max(radius_band, EDGE_READ_PX),
                "ring_px": [f_px * shadow / g.cop_z, f_px * outer / g.cop_z]}

    lenses = [figures("the camera model's", cam.focal_px)]
    buy = camera_lens(rig)
    if buy is not None and buy["buy_focal_length_mm"] != buy["focal_length_mm"]:
        lenses.append(figures(f"the bill's {buy['buy_focal_length_mm']:g} mm",
                              cam.focal_px * buy["buy_focal_length_mm"] / buy["focal_length_mm"]))
    out = {"principal_point_px": list(cam.principal_point), **{k: v for k, v in lenses[0].items() if k != "lens"}}
    out.update({"direct_ring_mm": [shadow, outer], "squares_across_ring": (outer - shadow) / CHECKER_SQUARE_MM,
                "lenses": lenses})
    out["image_radius_px"] = cam.image_radius_px
    return out


def checker_text(corr: dict) -> str:
    """The checkerboard step's comparison and pass (``corr``: :func:`camera_correspondence`): what the
    camera sees of the board (directly, in the ring about the paraboloid's image: the background the
    disc's edge is read against, thesis 4.1 and Figure 4.2) and the pass figures for each lens."""
    (x0, y0) = corr["principal_point_px"]
    inner, outer = corr["direct_ring_mm"]
    per_lens = "; ".join(
        f"with {lens['lens']} lens (f = {lens['focal_length_px']:.0f} px), the design's radius **{lens['image_radius_px']:.1f} px**, "
        f"the centre within **{lens['centre_tolerance_px']:.1f} px** of the principal point and the radius within "
        f"**{lens['radius_tolerance_px']:.1f} px** of that, the board's ring {lens['ring_px'][0]:.0f} to "
        f"{lens['ring_px'][1]:.0f} px from the centre" for lens in corr["lenses"])
    which = (" Use the figures of the lens on the camera: the first are the camera model's focal length, the second "
             "the lens the bill names to buy." if len(corr["lenses"]) > 1 else "")
    return ("**What is compared, and what passes.** Project the calibrated circle and take a picture with the camera: "
            "the paraboloid's image is a lit disc. The camera does not see the checkerboard through the mirrors (every "
            "ray through them lands on O, in the disc's hole over the bore): it sees it directly, through the dome's "
            f"top opening, in a ring about the lit disc, the plate from {inner:.1f} mm (the paraboloid's shadow) to "
            f"{outer:.1f} mm from O, about {corr['squares_across_ring']:.0f} squares across, crossed by the beam's "
            "shadow. That ring is the background the disc's bright edge is read against (thesis 4.1, Figure 4.2). No "
            "rigcad command reads it: in an image viewer that shows the pointer's pixel (GIMP's status bar, for one), "
            "read three points on the disc's edge far apart, where the lit disc meets the squares, and take the circle "
            f"through them (its centre and radius). The design puts the centre on the principal point (**{x0:.1f}, "
            f"{y0:.1f} px**). It passes when the centre and radius read are within the bands of the lens on the camera: "
            f"{per_lens} (the centre's band is what `tolerancing.camera_offset` and "
            "`camera_tilt` move it by, the radius's `tolerancing.camera_height`, never finer than the pixel an edge is "
            f"read to).{which} Outside either band the camera is off its place: go back to its crosses (and its shims "
            "for the radius). The circle's centre and radius, as read, are then the camera's correspondence: where "
            "the paraboloid's rim and vertex fall in its pixels.")


def projector_focus(rig) -> dict:
    """The projector's focus setting (mm from its COP, rigcad.optics.focus.focusing_lens): the paraboloid,
    through the focusing lens, needs the projector focused at ``focus_near`` (its vertex) to ``focus_far``
    (its rim); ``focus_mm`` is the setting midway between them in dioptres, which leaves both ends equally
    out of focus, set on a card without the lens (the lens then images that distance onto the paraboloid);
    ``from_front_mm``: the same from the lens barrel's front (``projector.pupil_depth`` behind it)."""
    from rigcad.optics.focus import focusing_lens

    lens = focusing_lens(rig.profile, rig.geometry)
    mid = 2.0 / (1.0 / lens.focus_near + 1.0 / lens.focus_far)
    return {"focus_near_mm": lens.focus_near, "focus_far_mm": lens.focus_far, "focus_mm": mid,
            "from_front_mm": mid - rig.profile.projector.pupil_depth, "lens_focal_length_mm": lens.focal_length}


def instrument_torques(rig, printer) -> dict:
    """The projector's and the camera's screws: (count, thread, torque N m) from the torque table
    (rigcad.fab.loads.bolt_loads), keyed "projector" and "camera"."""
    from rigcad.fab.loads import CAMERA_JOINT, PROJECTOR_JOINT, bolt_loads

    rows = {b.joint: b for b in bolt_loads(rig.profile, rig.layout, printer)}
    pj, cm = rows[PROJECTOR_JOINT], rows[CAMERA_JOINT]
    return {"projector": (pj.count, pj.thread, pj.torque_nm), "camera": (cm.count, cm.thread, cm.torque_nm)}


def projector_lock(rig, printer) -> str:
    """The crosses step, before the plate and the crosses come off: the projector's screws locked to the
    torque table's torque (:func:`instrument_torques`), the shadows checked again after."""
    n, thread, torque = instrument_torques(rig, printer)["projector"]
    return (f"**Lock the projector:** tighten its {n} {thread} screws crosswise with the torque screwdriver to "
            f"**{torque:.2f} N m** (section 5's torque table), in two passes, and project the white image again: the "
            "two shadows must still coincide on the backplate's cut cross; if tightening moved them, loosen, correct "
            "and tighten again.")


def projector_focus_text(rig) -> str:
    """The crosses step, the plate and crosses off, the holder still off and the focusing lens out: the
    projector focused with its own lens on a card at :func:`projector_focus`'s distance."""
    f = projector_focus(rig)
    return (f"**Focus the projector** now, the holder still off and the focusing lens out: through the f = "
            f"{f['lens_focal_length_mm']:g} mm lens the paraboloid needs the projector focused at "
            f"{f['focus_near_mm'] / 1e3:.2f} m (its vertex) to {f['focus_far_mm'] / 1e3:.2f} m (its rim) from its COP. "
            f"Show the circle page and hold a white card square to the beam where it runs on past the shelf's end, "
            f"**{f['from_front_mm'] / 1e3:.2f} m** from the lens barrel's front along the beam ({f['focus_mm'] / 1e3:.2f} m "
            "from the COP, `projector.pupil_depth` behind the front: midway in dioptres, both ends equally soft; a "
            "flat mirror may fold the beam if something stands in its way, the distance along the beam counts). Turn "
            "the projector's focus until the circle's edge is sharpest on the card, then tape its focus ring.")


def camera_focus_and_lock(rig, printer) -> str:
    """The camera crosses step's end: one focus rule (the hung cross, thesis 4.1: the camera's pixels are
    read as points of the paraboloid, whose vertex it marks) kept for the rest of the calibration and the
    measurements, and the camera's screws locked to the torque table's torque, the crosses checked after."""
    g = rig.geometry
    vertex = g.cop_z - g.vertex_z
    rim = math.hypot(g.rim_radius, g.cop_z - g.rim_z)
    n, thread, torque = instrument_torques(rig, printer)["camera"]
    return (f"**Focus the camera** on the hung cross, once (thesis 4.1): it stands at the paraboloid's vertex, "
            f"{vertex:.0f} mm from the COP (the rim {rim:.0f} mm), and the camera's pixels are read as points of the "
            "paraboloid (the next step's correspondence). Stop the lens down until the cross's arms stay "
            "sharp out to their ends. Then tape the focus ring and leave it for the rest of the calibration and every "
            "measurement: refocusing moves the lens's entrance pupil, the camera's COP, and changes its focal length "
            "in pixels, which the correspondence and `rigcad calibrate`'s fit both hold. "
            f"**Lock the camera:** tighten its {n} {thread} screws to **{torque:.2f} N m** (section 5's torque table), "
            "in two passes, and check that the two crosses still overlap symmetrically; if tightening moved them, "
            "loosen, correct and tighten again.")


def circle_radius_px(rig, dh: float = 0.0) -> float:
    """The paraboloid rim's radius (px) in the projector's image, seen through the focusing lens, with
    the projector's real COP ``dh`` mm farther from the lens along its axis than the tower puts it (the
    fold turns that into a COP ``dh`` x the lens's longitudinal magnification higher on the dome's axis):
    the focusing lens (rigcad.optics.focus.through_lens) moves the COP the paraboloid sees and scales the
    focal length in pixels; the rim at ``geometry.rim_radius``, ``rim_z``. ``dh`` = 0: the calibration
    circle's design radius (:func:`circle_image`)."""
    from rigcad.optics.focus import focusing_lens, through_lens

    g = rig.geometry
    lens = focusing_lens(rig.profile, g)
    u = lens.cop_distance + dh
    shift, scale = through_lens(lens.focal_length, u, lens.edge_thickness, lens.diameter)
    cop_z = g.cop_z + (u + shift - lens.lens_distance)  # the COP the paraboloid sees
    return g.projector_focal_px * scale * g.rim_radius / (cop_z - g.rim_z)


def cop_height_check(rig) -> dict:
    """What the measured circle's radius says about the projector COP's height (px, mm): the radius's
    change per mm of the projector moved along its axis, d R / d h = R (1 / (f - s) - m^2 / Z) with the
    lens's focal length f, s the real COP's distance to its front principal plane, m = f / (f - s) its
    pixel scale (m^2 the longitudinal magnification) and Z the seen COP's height above the rim's plane;
    the radius band of ``tolerancing.projector_height``; and the height one pixel of the page's read-out
    stands for."""
    from rigcad.optics.focus import focusing_lens

    g = rig.geometry
    lens = focusing_lens(rig.profile, g)
    from rigcad.optics.focus import LENS_INDEX as n

    f = lens.focal_length
    radius = f * (n - 1)
    sag = radius - math.sqrt(radius * radius - (lens.diameter / 2) ** 2)
    s = lens.cop_distance - lens.edge_thickness / 2 - sag
    m = f / (f - s)
    r0 = circle_radius_px(rig)
    per_mm = r0 * (1.0 / (f - s) - m * m / (g.cop_z - g.rim_z))
    tol = rig.profile.tolerancing.projector_height
    return {"radius_px": r0, "radius_px_per_mm": per_mm, "tolerance_mm": tol, "tolerance_px": abs(per_mm) * tol,
            "mm_per_px_read": 1.0 / abs(per_mm) if per_mm else math.inf, "read_px": EDGE_READ_PX,
            "cop_z_per_mm": m * m}


def shared_cop(rig) -> dict:
    """The projector's COP on the dome's axis, checked against the camera's (mm, px): the camera, set on
    the dome's axis by its crosses, sees the hung cross's shadow (the projector's white light, the
    paraboloid off) on the base plate exactly behind the cross when the projector's COP is its own (a
    light casts no shadow seen from where it stands). A projector ``d`` mm across the axis throws the
    hung cross's centre (height z_h) on z = 0 at d z_h / (Z - z_h) from O (Z the COP's height), which the
    camera sees f_cam d z_h / ((Z - z_h) Z) px from the cross's centre; the pass band is
    ``tolerancing.projector_offset`` so mapped, never finer than EDGE_READ_PX."""
    from rigcad.optics.camera import camera_model

    g, t = rig.geometry, rig.profile.tolerancing
    cam = camera_model(rig.profile, g)
    zh, z = g.vertex_z, g.cop_z
    mm = zh / (z - zh)
    px = cam.focal_px * mm / z
    return {"hung_cross_z_mm": zh, "shadow_mm_per_mm": mm, "camera_px_per_mm": px,
            "tolerance_mm": t.projector_offset, "shadow_tolerance_mm": mm * t.projector_offset,
            "tolerance_px": max(px * t.projector_offset, EDGE_READ_PX), "camera_focal_px": cam.focal_px}


def shared_cop_text(rig, printer) -> str:
    """The camera crosses step's last paragraph: the projector referenced to the dome's axis through
    the camera's COP (:func:`shared_cop`), re-locked, and what the circle's radius can say of the COP's
    height (:func:`cop_height_check`)."""
    c, h = shared_cop(rig), cop_height_check(rig)
    n, thread, torque = instrument_torques(rig, printer)["projector"]
    return ("**Projector and camera on one COP, on the dome's axis.** The projector's crosses put it on the shelf's "
            "seat, not on the dome; the camera is now on the dome's axis. Leave the hung cross and the base cross in, "
            "the paraboloid off, the focusing lens in and the holder on its seat, and show the circle page's design "
            "circle (0): a white disc about the projector's axis pixel, whose light runs down the axis past the hung "
            "cross onto the plate. Seen from the projector's own COP a light casts no visible shadow: in the camera's "
            "image the hung cross's shadow on the base cross lies exactly behind the hung cross when the two COPs are "
            f"one. A projector 1 mm across the axis throws the shadow's centre {c['shadow_mm_per_mm']:.2f} mm from O, "
            f"which the camera shows **{c['camera_px_per_mm']:.2f} px** from the hung cross's centre. It passes when "
            f"the shadow's centre is within **{c['tolerance_px']:.1f} px** of the hung cross's centre "
            f"(`tolerancing.projector_offset` = {c['tolerance_mm']:g} mm, {c['shadow_tolerance_mm']:.2f} mm at O). "
            f"If not, loosen the projector's {n} {thread} screws a quarter turn, move it in its slots (across its "
            "axis) or change its shims (height) until the shadow hides behind the cross, and tighten them again to "
            f"**{torque:.2f} N m**; then go back to the splitter seat's step and the circle (their figures are read "
            "on this projector). **Its height along the axis** (the COP's height, `tolerancing.projector_height` "
            f"= {h['tolerance_mm']:g} mm) the circle cannot check: through the focusing lens the rim's radius "
            f"changes by only {abs(h['radius_px_per_mm']):.3f} px per mm the projector moves along its axis "
            f"({h['tolerance_px']:.2f} px over the tolerance), so one pixel of the page's read-out stands for "
            f"{h['mm_per_px_read']:.0f} mm. A recorded radius more than 1 px from the design's "
            f"{h['radius_px']:.1f} px is not a height error (that would take {h['mm_per_px_read']:.0f} mm): it is a "
            "wrong throw ratio or lens, or a `projector.pupil_depth` off by tens of mm; find which before going on. "
            "The height rests on the projector's place along its own axis, which the fold and the lens turn into "
            f"{h['cop_z_per_mm']:.2f} mm of COP height per mm: on `projector.pupil_depth` measured as section 0 asks "
            "and on the tower's vertical stack (section 5), not on a calibration reading.")


def kit_items(rig) -> list[KitItem]:
    """Every item section 6 (the calibration) uses that is not a printed part of section 1 nor a tool of
    its tools list: what to buy, sized from the rig (the film and its blocks from :func:`film_setup`, the
    checkerboard from :func:`checkerboard`, the screens from ``calibration``)."""
    p = rig.profile
    f = film_setup(rig)
    cb = checkerboard(rig)
    holder = 2 * p.sample_holder.radius
    seat = (STEP_SEAT,) if getattr(rig.layout, "tower", None) is not None else ()  # the seat is watched on the film
    cal = getattr(p, "calibration", None)
    upright = (STEP_AS_BUILT,) if cal is not None and cal.upright_turns else ()  # driven from below the lifted rig
    items = [
        KitItem("Matte drafting film, polyester, one side matte", "1 sheet (A4)",
                f"{1e3 * f['film_thickness_mm']:g} µm thick; a disc of {f['film_diameter_mm']:.0f} mm is cut from it",
                ("drafting film", "film"), (*seat, STEP_CIRCLE, STEP_FILM, STEP_CAMERA, STEP_ACCEPTANCE)),
        KitItem("Low-tack masking tape, 19 mm", "1 roll", "paper, low tack (it comes off the plate clean)",
                ("tape",), (STEP_CROSSES, STEP_FILM, STEP_CAMERA, STEP_ACCEPTANCE)),  # the focus rings too
        KitItem("Fine pen for film", "1", "permanent fineliner, 0.1-0.3 mm line, that marks polyester",
                ("fine pen",), (STEP_FILM,)),
        KitItem("Blocks to lift the rig", "3",
                f"1 x {f['block_under_tongue_mm']:g} mm and 2 x {f['block_under_disc_mm']:g} mm tall, each at least "
                f"{BLOCK_FOOTPRINT_MM:g} x {BLOCK_FOOTPRINT_MM:g} mm, top and bottom flat and parallel (hardwood, "
                "aluminium or printed solid), cut to height within 0.5 mm", ("blocks",),
                (STEP_FILM, STEP_ACCEPTANCE, STEP_GRAY, *upright)),
        KitItem("Flat mirror for the view from below", "1",
                f"front- or back-surface mirror at least {10 * math.ceil(2 * f['bore_radius_mm'] / 10):g} mm square, "
                "propped at 45 deg on the bench (or a phone's camera looking up)", ("45 deg mirror",), (STEP_FILM,)),
        KitItem("Scalpel with No. 11 blades and a cutting mat", "1", "for the film and the checkerboard",
                ("scalpel",), (STEP_FILM, STEP_CHECKER)),
        KitItem("White LED torch", "1", f"a small torch (or a phone's), no taller than {f['block_under_disc_mm']:g} mm "
                "standing, to light the film from below", ("torch",), (STEP_ACCEPTANCE,)),
        KitItem("Black paper for the mask, and a leather punch", "1 sheet, 1 punch",
                f"matte black paper, 120-200 g/m²; a hollow punch of {2 * p.tolerancing.max_spot_radius:g} mm "
                "(`tolerancing.max_spot_radius`)", ("mask", "leather punch"), (STEP_ACCEPTANCE,)),
        KitItem("Matte paper for the checkerboard", "1 sheet",
                f"{cb['sheet']}, matte, laser-printed at 600 dpi: {cb['squares']} x {cb['squares']} squares of "
                f"{cb['square_mm']:g} mm, cut to a {cb['disc_diameter_mm']:.0f} mm disc with a "
                f"{cb['hole_diameter_mm']:.0f} mm hole", ("checkerboard",), (STEP_CHECKER,)),
        KitItem("Circle cutter (compass cutter)", "1", f"cuts circles of {cb['hole_diameter_mm'] / 2:.0f} to "
                f"{cb['disc_radius_mm']:.0f} mm radius in paper", ("circle cutter",), (STEP_CHECKER,)),
        KitItem("Gray card, 18 % diffuse reflectance", "1",
                f"photographic gray card (Kodak R-27 class), cut to a {holder:g} mm disc (the sample holder's "
                "diameter)", ("gray card",), (STEP_GRAY,)),
    ]
    if getattr(rig.layout, "tower", None) is not None:  # the crosses' plate sits on the splitter seat on its balls
        from rigcad.parts.crosses import cross_fixture

        (ball,) = cross_fixture(p, rig.layout).bought
        items.append(KitItem(f"Steel balls, {ball.size_mm['diameter']:g} mm, grade G10 ({ball.standard})",
                             str(ball.quantity), ball.role, ("steel balls",), (STEP_CROSSES,)))
    return items + _screen_items(rig)


def _screen_items(rig) -> list[KitItem]:
    """The calibration's screens and what drives them (:func:`kit_items`): the tablet and its printed
    spacers; the upright display, its stand and the computer that drives it, when ``calibration.upright_turns``."""
    p, items = rig.profile, []
    cal = getattr(p, "calibration", None)
    if cal is not None:
        from rigcad.calibrate.kit import display_spec, display_text, screen_room, upright_room
        from rigcad.calibrate.patterns import Sequence

        room = screen_room(rig)
        items += [
            KitItem("Tablet (the calibration screen)", "1",
                    display_text(display_spec(cal.screen_resolution, cal.screen_pitch)) + f", {cal.screen_thickness:g} "
                    f"mm from its back to its emitting surface, its body with the bezel and corners within a "
                    f"{room['body_diameter_mm']:.0f} mm circle; full brightness without auto-brightness; a browser "
                    "for the kit's slideshow (`calibration.screen_*`)", ("tablet",), (STEP_AS_BUILT,)),
            KitItem("Calibration spacers (printed by `rigcad calibrate --kit`: stl/calibration_spacer_<k>.stl)",
                    str(len(cal.spacer_heights)), "heights " + ", ".join(f"{v:g}" for v in cal.spacer_heights)
                    + " mm above the holder's seat (`calibration.spacer_heights`), printed as the sample holder is",
                    ("spacer",), (STEP_AS_BUILT,))]
        if cal.upright_turns:
            seq = Sequence.from_profile(cal, "upright")
            items += [
                KitItem("Upright display (a small display module)", "1",
                        display_text(display_spec(seq.resolution, cal.upright_pitch)) + ", module at most "
                        f"{cal.upright_thickness:g} mm thick with {cal.upright_border:g} mm of frame beyond the active area "
                        f"(its slot holds {2 * upright_room(p)['half_width_mm']:.1f} mm wide)", ("upright display",),
                        (STEP_AS_BUILT,)),
                KitItem("Upright display's stand (printed by `rigcad calibrate --kit`: "
                        "stl/calibration_upright_stand.stl)", "1", "printed as the sample holder is",
                        ("calibration_upright_stand",), (STEP_AS_BUILT,)),
                KitItem("Raspberry Pi (any model with the 40-pin header) with its power supply, a micro-SD card with "
                        "Raspberry Pi OS, a USB keyboard and female-female jumper wires, 30 cm", "1",
                        "drives the upright display from below the plate (SPI, the kernel's fbtft overlay for the "
                        "module's driver; fbi shows the frames)", ("raspberry pi",), (STEP_AS_BUILT,))]
    items.append(KitItem("Turntable: a ball-bearing lazy susan or a rotary table", "1",
                         "flat, turning without wobble, at least as wide as the dome's flange: the dome stands on it "
                         "upside down while the paraboloid is indicated in on its axis", ("turntable",),
                         (STEP_ACCEPTANCE,)))
    return items


#: The words the calibration's steps name their bought or made items by (lower case), kept apart from the
#: bill's lines so that a line missing from the bill shows: every word a step uses must be some line's.
ITEM_WORDS = ("drafting film", "film", "tape", "fine pen", "blocks", "45 deg mirror", "scalpel", "checkerboard",
              "circle cutter", "gray card", "tablet", "spacer", "upright display", "calibration_upright_stand",
              "torch", "mask", "leather punch", "plug", "steel balls", "raspberry pi", "turntable")


def kit_misses(sections: dict[str, str], items: list[KitItem]) -> list[str]:
    """What the calibration's text names without its bill line: for each step (heading -> text), every
    word of ITEM_WORDS the text uses must belong to a kit item that lists that step, and every step an
    item lists must name it (one line per miss; empty when the text and the bill agree)."""
    out = [f"{it.item!r}: its word {w!r} is not in ITEM_WORDS" for it in items for w in it.words if w not in ITEM_WORDS]
    for heading, text in sections.items():
        low = text.lower()
        for w in ITEM_WORDS:
            if re.search(rf"\b{re.escape(w)}s?\b", low) and not any(w in it.words and heading in it.steps for it in items):
                out.append(f"{heading!r} names {w!r}, and no bill line with that word lists that step")
    for it in items:
        for st in it.steps:
            if st not in sections:
                out.append(f"{it.item!r}: its step {st!r} is not in the calibration")
            elif not any(w in sections[st].lower() for w in it.words):
                out.append(f"{it.item!r}: {st!r} does not name it")
    return out


__all__ += ["CHECKER_SQUARE_MM", "ITEM_WORDS", "STEP_ACCEPTANCE", "KitItem", "checkerboard", "kit_items", "kit_misses"]


# -- the splitter seat: three push screws and two spring bolts --------------------------------------


def seat_lean(rig, screw: str) -> np.ndarray:
    """Which way (a unit (dx, dy) in the rig frame) the projector's axis, folded down the optical axis
    by the splitter, leans when ``screw`` ("flat" or "vee") is screwed in: its ball lifts the holder
    about the line through the other two (rigcad.parts.tower.seat_points), the plate's normal turns with
    it, and the axis reflected off the plate (the law of reflection, the projector looking -x) moves."""
    from rigcad.parts.tower import seat_points

    pts = seat_points(rig.layout.tower, rig.profile)
    others = {"flat": ("cone", "vee"), "vee": ("cone", "flat")}[screw]
    p1, p2 = (np.array([*pts[o], 0.0]) for o in others)
    arm = np.array([*pts[screw], 0.0]) - p1
    axis = (p2 - p1) / np.linalg.norm(p2 - p1)
    if np.cross(axis, arm)[2] < 0:  # turn the sense so the screw's ball rises (a right-hand turn about axis)
        axis = -axis
    n = np.asarray(rig.layout.tower.plate.normal, float)
    d = np.array([-1.0, 0.0, 0.0])
    reflect = lambda m: d - 2.0 * (d @ m) * m  # noqa: E731
    eps = 1e-6
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turned = n + eps * (k @ n)  # the normal turned by eps about the axis (first order)
    lean = (reflect(turned) - reflect(n))[:2] / eps
    return lean / np.linalg.norm(lean)


def splitter_seat(rig) -> dict | None:
    """The splitter seat's adjustment, as section 6 gives it: for the flat's and the vee's push screws
    (rigcad.parts.adjusters.splitter_adjusters: lever, the reflected axis's turn per step, range) the
    turn of the projector's axis per ``adjusters.turn_fraction`` of a turn (mrad), which way it leans
    (:func:`seat_lean`) and the shift (px) of the circle that re-centres the spot for it, along the
    projector image's rows (the plane of incidence, x) and columns (y), from the projector's focal length
    in pixels through the focusing lens; the holder's lift per step with all three screws together
    (the thread's pitch x turn_fraction), its nominal gap over the shelf (rigcad.parts.tower.seat_gap),
    and ``tolerancing.projector_tilt`` in px. None without the COP tower."""
    t = getattr(rig.layout, "tower", None)
    if t is None:
        return None
    from rigcad.optics.focus import focusing_lens
    from rigcad.parts.adjusters import splitter_adjusters
    from rigcad.parts.tower import seat_gap
    from rigcad.standards import THREADS

    p, g = rig.profile, rig.geometry
    a = p.adjusters
    px_per_rad = focusing_lens(p, g).projector(g.projector_focal_px, g.cop_z).focal_px
    screws = {}
    for adj, screw in zip(splitter_adjusters(p, rig.layout), ("flat", "vee")):
        lean = seat_lean(rig, screw)
        shift = px_per_rad * adj.resolution
        words = " and ".join(f"{'+' if v > 0 else '-'}{ax}" for ax, v in zip("xy", lean) if abs(v) > 0.05)
        screws[screw] = {"adjuster": adj.name, "how": adj.how, "axis_turn_per_step_mrad": 1e3 * adj.resolution,
                         "circle_shift_per_step_px": shift, "rows_px_per_step": shift * abs(lean[0]),
                         "columns_px_per_step": shift * abs(lean[1]), "range_each_way_mrad": 1e3 * adj.range,
                         "range_each_way_steps": adj.range / adj.resolution, "leans": words,
                         "lean_xy": [float(v) for v in lean]}
    pitch = THREADS[a.seat_thread].pitch
    return {"thread": a.seat_thread, "pitch_mm": pitch, "turn_fraction": a.turn_fraction,
            "lift_per_step_mm": pitch * a.turn_fraction, "travel_each_way_mm": a.seat_travel,
            "gap_mm": seat_gap(p), "px_per_mrad": px_per_rad * 1e-3,
            "tolerance_mrad": 1e3 * p.tolerancing.projector_tilt,
            "tolerance_px": px_per_rad * p.tolerancing.projector_tilt, "screws": screws}


__all__ += ["seat_lean", "splitter_seat"]
