"""The calibration kit from the profile: the screen's patterns as PNGs at its resolution, the
spacers as printed parts (the sample holder's recipe, :func:`rigcad.parts.base.holder_body`, cut
to each spacer's height: the same recipe objects, meshed and written by the same exporters as every
part, with a manifest), and the manual's page (:func:`manual_page`: placing the screen, the
capture order and the naming scheme, exposure advice)."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence


def pattern_png(seq: Sequence, name: str) -> bytes:
    """One frame as an 8-bit grey PNG at the screen's resolution."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(seq.image(name), mode="L").save(buf, format="PNG")
    return buf.getvalue()


def spacer(profile, k: int):
    """Spacer ``k`` as a recipe Part: the holder's plug (stop collar under the plate) whose top, where
    the screen's back rests, stands ``spacer_heights[k]`` above the holder's seat."""
    from rigcad.parts.base import holder_body
    from rigcad.parts.recipe import Part

    h = profile.calibration.spacer_heights[k]
    top = -profile.sample_holder.sample_thickness + h
    return Part(f"calibration_spacer_{k}", holder_body(profile, top), (0.3, 0.6, 0.3),
                f"calibration spacer {k}: replaces the sample holder; the screen's back rests {h:g} mm above "
                "the holder's seat", in_rig=False)


def screen_room(rig) -> dict:
    """Where the screen lies inside the dome (mm): the display's half diagonal (its corners' distance
    from the axis when it lies centred) against the dome's inside radius, the least over the heights
    the screen spans at each spacer (its back to its emitting surface, clipped at the sample plane
    where the dome starts). ``fits``: the display clears the dome at every spacer; the body, a bezel
    wider, must fit in ``body_diameter_mm`` (the manual says so)."""
    p = rig.profile
    cal = p.calibration
    pts = rig.dome.points  # the mirror surface (r, z), rising from the sample plane
    w, h = cal.screen_resolution
    half_diagonal = cal.screen_pitch * math.hypot(w, h) / 2
    rows = []
    for k, top in enumerate(M.nominal_heights(p)):
        z = np.linspace(max(top - cal.screen_thickness, 0.0), max(top, 0.0), 65)
        r = np.interp(z, pts[:, 1], pts[:, 0])
        i = int(np.argmin(r))
        rows.append({"spacer": k, "z_mm": float(z[i]), "dome_radius_mm": float(r[i])})
    tight = min(rows, key=lambda row: row["dome_radius_mm"])
    return {"display_mm": [w * cal.screen_pitch, h * cal.screen_pitch], "half_diagonal_mm": half_diagonal,
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


def manual_page(rig) -> str:
    """The manual's page on the calibration (Markdown)."""
    p = rig.profile
    cal = p.calibration
    seq = Sequence.from_profile(cal)
    plan = M.Plan.of(p)
    w, h = cal.screen_resolution
    frames = seq.names()
    turned = ", turned a half turn (the spacer in its bore and the screen on it, each by 180 deg)"
    steps = "\n".join(
        f"{c + 1}. spacer {k} ({cal.spacer_heights[k]:g} mm){turned if plan.repeats(c) is not None else ''}: "
        f"screen surface {z:g} mm above the sample point; files `{label}_<frame>.png`"
        for c, (k, z, label) in enumerate(zip(plan.spacers, plan.heights, plan.labels)))
    reach = math.degrees(math.atan((min(w, h) * cal.screen_pitch / 2) / max(plan.heights)))
    room = check_screen_fits(rig)
    side = min(w, h) * cal.screen_pitch
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
- A flat screen (a tablet): {w} x {h} px at {cal.screen_pitch:g} mm pitch, {cal.screen_thickness:g} mm from its
  back to its emitting surface. It lies inside the dome: its body, bezel included, must fit in a
  {room['body_diameter_mm']:.0f} mm circle (the dome's inside at z = {room['tightest']['z_mm']:.1f} mm, where spacer
  {room['tightest']['spacer']} puts it). Set it to its full brightness, no night shift, no auto-brightness, and a
  linear (gamma 1) response if it offers one; show each PNG of `patterns/` full screen, unscaled.
- The spacers (`stl/calibration_spacer_<k>.stl`): each replaces the sample holder in the base plate's bore;
  lay the screen face up on its top, centred on the axis and square to the base plate by eye: within
  {M.PLACEMENT_MM:g} mm and {math.degrees(M.PLACEMENT_TURN_RAD):g} deg is enough, the fit finds where it lies at each spacer.
- Lay it flat. No image shows the sample plane: the images cannot tell a screen tilted on its spacer
  from a rig tilted over the sample, so the screen's tilt on the holder's seat is the map's. The
  spacer's faces and the screen's back make a wedge (up to {across(cal.screen_tilt)},
  `calibration.screen_tilt`); {half_turn}
  Clean the spacer's top and the screen's back; a screen that rocks on a camera bump needs a flat
  plate under it, counted in `screen_thickness`.

## Capture order
In turn:
{steps}

and for each, the {len(frames)} frames in this order (the names of `patterns/`): {', '.join(frames[:4])}, ...,
{frames[-1]}. Name each camera image `<capture>_<frame>.png` (or .tif, 8 or 16 bit, grey or colour) at the
camera's full resolution, {p.camera.resolution[0]} x {p.camera.resolution[1]} px, all in one folder; then
`rigcad calibrate {p.name} --images <folder>`.

## Exposure
- One exposure for every frame of a capture: set it on the white frame so the brightest lit pixels sit at
  80-90 % of full scale (a saturated white is refused; so is an all-dark one). The brightest are the
  ring around the paraboloid's image, where the camera sees the screen directly through the dome's
  top opening, with no mirror's loss: set the exposure there. Keep that ring in the images: the fit
  reads it, and it fixes the camera's place. The paraboloid's image inside it is dimmer: each
  mirror reflects {100 * p.coating.reflectance:.0f} % (`coating.reflectance`), so it gets
  {100 * p.coating.reflectance ** 2:.0f} % of the ring's light. That is expected; do not raise the exposure for it.
- Keep the room dark: stray light lowers the fringes' modulation (pixels under
  {cal.min_modulation:g} modulation are not decoded).
- Focus between the two screen heights; a little defocus is harmless.
- The screen reaches rays up to {reach:.0f} deg from the axis at the highest spacer: beyond that the
  corrected map is filled from the fit.

{_after_the_fit(p.tolerancing)}"""


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


def write_kit(rig, out: Path, say=lambda msg: None) -> dict:
    """Write the kit into ``out`` (published atomically): patterns/<frame>.png, stl/ and step/
    calibration_spacer_<k>, calibration.md, manifest.json (each file's SHA-256, the spacers' volumes)."""
    from rigcad.export import mesh as EM
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest, sha256_hex
    from rigcad.export.step import reimport_check, step_writer
    from rigcad.parts import _kernel as K

    p = rig.profile
    check_screen_fits(rig)
    seq = Sequence.from_profile(p.calibration)
    files, parts = {}, {}
    with Staging(out, lock=profile_lock(out.parent.parent, p.name) if out.parent.name == p.name else None,
                 made_from=profile_digest(p)) as st:
        for name in seq.names():
            data = pattern_png(seq, name)
            st.write_bytes(out / "patterns" / f"{name}.png", data)
            files[f"patterns/{name}.png"] = sha256_hex(data)
        for k in range(len(p.calibration.spacer_heights)):
            part = spacer(p, k)
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
        page = manual_page(rig).encode()
        st.write_bytes(out / "calibration.md", page)
        files["calibration.md"] = sha256_hex(page)
        manifest = {"profile": p.name, "screen_resolution_px": list(p.calibration.screen_resolution),
                    "frames_in_capture_order": seq.names(), "parts": parts, "files": files}
        st.write_bytes(out / "manifest.json", json_bytes(manifest))
        st.commit()
    return manifest
