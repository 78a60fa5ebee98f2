"""The camera's lens as a bill line, when the profile names no lens file: the lens rigcad's camera
model stands for (rigcad.optics.camera: its focal length in pixels) turned into one to buy, in mm.

The lens aimed at is the one the check and ``design`` recommend: the focal length whose paraboloid
image spans DEFAULT_FILL of the sensor's short side (rigcad.optics.camera.CameraModel.focal_for_fill, in
pixels), in mm: times the sensor's pixel pitch (``camera.pixel_pitch``; when the profile does not give
it, the pitch of a 1/2-inch sensor across the camera's width, :data:`ASSUMED_SENSOR_WIDTH`, and the line
says so), rounded to the nearest catalogue lens among rigcad's shipped C-mount lens files whose
paraboloid image stays on the sensor. The line also states the image circle the lens
must cover (the sensor's diagonal) and the distance it must focus at (the camera's working distance,
its front to the paraboloid's vertex). A profile that names a lens file (``camera.lens``) already has
its line (rigcad.manual.bom.purchased): no line here. Kernel-free; mm.
"""

from __future__ import annotations

import math

#: The sensor width assumed when the camera gives no pixel pitch (mm): the 1/2-inch format (6.4 x 4.8 mm,
#: 8 mm diagonal) of the C-mount machine-vision cameras of the thesis's rig (the Prosilica EC 1350C's
#: class, whose datasheet rigcad does not have). Assumed: the line says so and names the key to set.
ASSUMED_SENSOR_WIDTH = 6.4


def catalogue() -> list[tuple[float, str]]:
    """The catalogue lenses: (focal length mm, lens file name) of rigcad's shipped lens files, shortest first."""
    from rigcad.profile.instruments import shipped
    from rigcad.units import parse_quantity

    return sorted((parse_quantity(i.figures["focal_length"], "length"), i.name)
                  for i in shipped("lens") if "focal_length" in i.figures)


def camera_lens(rig) -> dict | None:
    """The lens to buy (figures with units in the keys), or None when the profile names a lens file
    (its line is the bill's already) or the COP is at infinity (no camera image)."""
    from rigcad.optics.camera import DEFAULT_FILL, camera_model

    p = rig.profile
    if p.instrument("camera", "lens") is not None or rig.geometry.cop_at_infinity:
        return None
    cam = camera_model(p, rig.geometry)
    w, h = cam.resolution
    pitch, assumed = (cam.pixel_pitch, False) if cam.pixel_pitch else (ASSUMED_SENSOR_WIDTH / w, True)
    f_mm = cam.focal_length if cam.focal_length is not None else cam.focal_px * pitch
    fill_px, _ = cam.focal_for_fill(DEFAULT_FILL)
    fill_mm = fill_px * pitch
    on_sensor = [(f, n) for f, n in catalogue() if cam.image_radius_px * f / f_mm <= cam.room_px]
    if not on_sensor:
        return None
    f_buy, name = min(on_sensor, key=lambda fn: (abs(fn[0] - fill_mm), fn[0]))
    return {"focal_length_px": cam.focal_px, "focal_from": cam.focal_from, "pixel_pitch_mm": pitch,
            "pixel_pitch_assumed": assumed, "focal_length_mm": f_mm, "fill": DEFAULT_FILL,
            "fill_focal_length_px": fill_px, "fill_focal_length_mm": fill_mm, "buy_focal_length_mm": f_buy,
            "lens_file": name, "buy_fill": cam.fill * f_buy / f_mm,
            "image_radius_px": cam.image_radius_px * f_buy / f_mm, "room_px": cam.room_px,
            "image_circle_mm": pitch * math.hypot(w, h), "working_distance_mm": cam.working_distance,
            "resolution_px": [w, h]}


def bill_row(rig) -> dict | None:
    """The bill's optics row for :func:`camera_lens` (item, quantity, spec, source), or None."""
    lens = camera_lens(rig)
    if lens is None:
        return None
    w, _ = lens["resolution_px"]
    pitch = (f"{1e3 * lens['pixel_pitch_mm']:.3g} µm pixel pitch (**assumed**: a 1/2-inch sensor, "
             f"{ASSUMED_SENSOR_WIDTH:g} mm across its {w} px; set `camera.pixel_pitch` from the camera's datasheet)"
             if lens["pixel_pitch_assumed"] else f"{1e3 * lens['pixel_pitch_mm']:.3g} µm pixel pitch (`camera.pixel_pitch`)")
    spec = (f"**{lens['buy_focal_length_mm']:g} mm focal length, C-mount** (the camera's lens mount), for an image circle "
            f"of at least {lens['image_circle_mm']:.1f} mm (the sensor's diagonal: a lens rated for that format or "
            f"larger), focusing at {lens['working_distance_mm']:.0f} mm (the working distance, its front to the "
            f"paraboloid's vertex: its closest focus no farther). The lens whose paraboloid image spans "
            f"{lens['fill']:.0%} of the sensor's short side (as `rigcad check` and `rigcad design` recommend) is "
            f"{lens['fill_focal_length_px']:.0f} px x {pitch} = {lens['fill_focal_length_mm']:.1f} mm: the nearest "
            f"catalogue lens whose paraboloid image ({lens['image_radius_px']:.0f} px radius, "
            f"{lens['buy_fill']:.0%} of the short side) stays on the sensor ({lens['room_px']:.0f} px to its nearest "
            f"edge). Name it in the profile (`camera.lens: "
            f"{lens['lens_file']}`" + (", with `camera.pixel_pitch`" if lens["pixel_pitch_assumed"] else "")
            + f") and build again: until then the manual's camera pixel figures are the camera model's "
            f"{lens['focal_length_px']:.0f} px lens's ({lens['focal_from']}, {lens['focal_length_mm']:.1f} mm)")
    return {"item": f"camera lens: C-mount, {lens['buy_focal_length_mm']:g} mm focal length", "quantity": 1,
            "spec": spec, "source": "camera.lens (none: rigcad.optics.camera)"}


def with_camera_lens(rig, rows: list[dict]) -> list[dict]:
    """The bill's optics rows with the camera lens's (:func:`bill_row`) after the camera's own row."""
    row = bill_row(rig)
    if row is None:
        return list(rows)
    at = next((k + 1 for k, r in enumerate(rows) if r["item"].startswith("camera")), len(rows))
    return [*rows[:at], row, *rows[at:]]


__all__ = ["ASSUMED_SENSOR_WIDTH", "bill_row", "camera_lens", "catalogue", "with_camera_lens"]
