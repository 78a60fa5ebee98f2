"""The camera as a camera: its sensor (resolution, pixel pitch), its lens (focal length, principal
point, closest focus) and what it makes of the paraboloid (closed forms: pinhole camera at the COP,
looking down the optical axis; mm, radians, pixels).

The camera shares the projector's centre of projection (COP) through the beam splitter (thesis
3.1, Figure 3.4). Its focal length in pixels is, in this order of precedence:

* ``camera.focal_length`` (the profile's, else the lens file's, ``camera.lens``) over
  ``camera.pixel_pitch``: f_px = f / pitch;
* else *derived*: the lens that frames the paraboloid as the projector does, the same field of view
  across the sensor's height, f_px = f_projector_px x camera height / projector height (what rigcad
  assumed before the lens was modelled: 2389 px for Table 3.1, the rim 134 px from the image centre).

The paraboloid's image is a disc about the principal point (the optical axis meets the paraboloid's
vertex): its rim, seen at angle ``rim_angle_at_cop`` from the axis, lands r = f_px tan(rim angle)
from the principal point. ``fill`` is the disc's diameter over the sensor's short side; ``reach`` is
r over the room from the principal point to the nearest sensor edge (<= 1: all of it on the sensor).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError

#: The fraction of the sensor's short side ``rigcad design`` suggests the paraboloid's image fill:
#: room for the rim's blur and the tolerances' shift (tolerancing.camera_*) inside the frame.
DEFAULT_FILL = 0.9


@dataclass(frozen=True)
class CameraModel:
    """The camera of one profile. ``principal_point`` is (x, y) px from the image's top-left corner
    (x along columns, y down rows); ``focal_from`` says where the focal length came from ("profile",
    "lens file <name>", or "derived"); lengths in mm (None where the pitch is unknown)."""

    resolution: tuple[int, int]
    pixel_pitch: float | None
    focal_px: float
    focal_length: float | None
    focal_from: str
    principal_point: tuple[float, float]
    #: The paraboloid rim's image radius (px) about the principal point.
    image_radius_px: float
    #: From the lens's front to the paraboloid's vertex (mm): COP to vertex less the pupil's depth.
    working_distance: float
    min_working_distance: float | None

    @property
    def short_side_px(self) -> int:
        return min(self.resolution)

    @property
    def fill(self) -> float:
        """The paraboloid image's diameter over the sensor's short side."""
        return 2.0 * self.image_radius_px / self.short_side_px

    @property
    def room_px(self) -> float:
        """From the principal point to the nearest sensor edge (px)."""
        (x, y), (w, h) = self.principal_point, self.resolution
        return min(x, w - x, y, h - y)

    @property
    def reach(self) -> float:
        """The image's radius over :attr:`room_px`: at most 1 when the whole disc is on the sensor."""
        return self.image_radius_px / self.room_px

    @property
    def on_sensor(self) -> bool:
        return self.reach <= 1.0

    def focal_for_fill(self, fraction: float = DEFAULT_FILL) -> tuple[float, float | None]:
        """The focal length whose paraboloid image spans ``fraction`` of the sensor's short side:
        (px, mm or None without the pixel pitch). Scales the current one: r is linear in f."""
        if not (math.isfinite(fraction) and 0 < fraction <= 1):
            raise GeometryError(f"fill fraction {fraction!r}: need 0 < fraction <= 1 of the sensor's short side")
        f_px = self.focal_px * fraction / self.fill
        return f_px, (f_px * self.pixel_pitch if self.pixel_pitch else None)

    def as_dict(self) -> dict:
        """Named with units, for JSON and the reports."""
        return {"resolution_px": list(self.resolution), "pixel_pitch_mm": self.pixel_pitch,
                "focal_length_px": self.focal_px, "focal_length_mm": self.focal_length, "focal_from": self.focal_from,
                "principal_point_px": list(self.principal_point), "paraboloid_image_radius_px": self.image_radius_px,
                "paraboloid_image_fill_of_short_side": self.fill, "reach_over_room": self.reach,
                "on_sensor": self.on_sensor, "working_distance_mm": self.working_distance,
                "min_working_distance_mm": self.min_working_distance}


def derived_focal_px(profile, geo) -> float:
    """The lens that frames the paraboloid as the projector does (px): the projector's focal length
    in its pixels scaled by the ratio of the two heights in pixels."""
    return geo.projector_focal_px * profile.camera.resolution[1] / profile.projector.resolution[1]


def camera_model(profile, geo) -> CameraModel:
    """The camera of ``profile`` (validated) with its derived geometry ``geo``
    (:class:`rigcad.profile.derived.Derived`); a COP at infinity has no camera image (GeometryError)."""
    cam = profile.camera
    if geo.cop_at_infinity:
        raise GeometryError("the camera needs a finite COP (layout.cop_to_vertex)", param="layout.cop_to_vertex")
    if cam.focal_length is not None:
        f_px, f_mm = cam.focal_length / cam.pixel_pitch, cam.focal_length
        lens = profile.instrument("camera", "lens")
        origin = ("profile" if profile.set_by("camera", "focal_length") == "profile"
                  else f"lens file {lens.name}" if lens is not None else "instrument")
    else:
        f_px = derived_focal_px(profile, geo)
        f_mm, origin = (f_px * cam.pixel_pitch if cam.pixel_pitch else None), "derived"
    w, h = cam.resolution
    pp = cam.principal_point if cam.principal_point is not None else (w / 2, h / 2)
    return CameraModel(resolution=(w, h), pixel_pitch=cam.pixel_pitch, focal_px=f_px, focal_length=f_mm,
                       focal_from=origin, principal_point=(float(pp[0]), float(pp[1])),
                       image_radius_px=f_px * math.tan(geo.rim_angle_at_cop),
                       working_distance=profile.layout.cop_to_vertex - cam.pupil_depth,
                       min_working_distance=cam.min_working_distance)


__all__ = ["DEFAULT_FILL", "CameraModel", "camera_model", "derived_focal_px"]
