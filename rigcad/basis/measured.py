"""The rig as measured, for the zonal images: what ``rigcad basis`` reads back from the calibration.

Two measurements move the zones the projector's images draw (rigcad.basis.projector):

* **the calibration circle** (thesis 4.1.1; the manual's section 6 sets it through the focusing
  lens with ``calibration/circle.html``, which shows its centre and radius): where the paraboloid's
  rim stands in the projector's image. Its centre becomes the image point of the optical axis (the
  design: the image's centre) and its radius the rim's (the design: ``f tan(alpha_max)`` through the
  lens, rigcad.optics.focus.lensed_focal_px), so the focal length in pixels is radius / tan(alpha_max).
  Given as ``rigcad basis --circle CX CY R`` (pixels from the image's top-left corner, as the page
  shows them) or read from ``<exports>/<profile>/calibrate/circle.json`` ({"centre_px_from_top_left":
  [cx, cy], "radius_px": r, "resolution_px": [w, h]}, the keys of the manual's circle record).
* **the deflectometric fit** (``rigcad calibrate``'s ``calibration.json``, its ``fit.parameters``: the
  paraboloid's, the dome's and the camera's offsets (mm) and tilts (deg) in the sample frame,
  rigcad.calibrate.model.RIG_NAMES): the rig is moved by them (rigcad.calibrate.model.moved) and each
  lit pixel's light is traced on the moved rig, so its image shows the zonal functions at the
  direction it really lights the sample from (``illumination(..., as_built=True)``).

A file that is not one of these, or was made for another rig, is refused in one line naming the
file and the key (BasisError); none is ever replaced by the design silently.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from rigcad.errors import BasisError

#: Where ``rigcad calibrate`` writes its report, and where a lab puts the circle it measured, inside
#: the profile's exports folder: read when no flag names them.
CALIBRATION_JSON = "calibrate/calibration.json"
CIRCLE_JSON = "calibrate/circle.json"
#: The largest calibration.json read (rigcad's own are ~83 KB; its correlation matrix grows with the
#: screens captured) and the largest circle.json (a few lines).
CALIBRATION_MAX_BYTES = 8 << 20
CIRCLE_MAX_BYTES = 64 << 10
#: A measured circle's radius may differ from the design's rim through the lens by this fraction:
#: the tolerances move the rim by a few per cent; a circle 20 % off is another rig's (another
#: projector's resolution or lens) or a mistyped figure.
CIRCLE_RADIUS_SLACK = 0.2
#: A fitted offset (mm) or tilt (deg) past these is no rig that ``rigcad calibrate`` fits (its fit
#: starts at the design and moves each component within a few tolerances): another rig's report.
FIT_MAX_MM = 20.0
FIT_MAX_DEG = 10.0


@dataclass(frozen=True)
class MeasuredCircle:
    """The calibration circle as measured: centre (px from the image's top-left corner), radius (px),
    and where it came from (a flag or a file)."""

    centre_px: tuple[float, float]
    radius_px: float
    source: str


@dataclass(frozen=True)
class Measured:
    """What the basis draws the rig as: a measured circle (or None: the design's), the fitted rig
    parameters (rigcad.calibrate.model.RIG_NAMES order, mm and rad; None: as designed) and their file."""

    circle: MeasuredCircle | None = None
    theta: tuple[float, ...] | None = None
    fit_source: str | None = None

    def describe(self) -> dict:
        """For basis.json: what was read, from where (mm, deg, px)."""
        out: dict = {}
        if self.circle is not None:
            out["circle"] = {"centre_px_from_top_left": list(self.circle.centre_px), "radius_px": self.circle.radius_px,
                             "source": self.circle.source}
        if self.theta is not None:
            from rigcad.calibrate.model import RIG_NAMES

            out["fit"] = {"source": self.fit_source,
                          "parameters": {n.replace("_rad", "_deg"): (math.degrees(v) if n.endswith("_rad") else v)
                                         for n, v in zip(RIG_NAMES, self.theta)}}
        return out


def _design_radius(rig) -> float:
    """The rim's radius (px) in the projector's image through its lens, as designed."""
    from rigcad.optics.focus import lensed_focal_px

    return lensed_focal_px(rig.profile, rig.geometry) * math.tan(rig.incidence.alpha_max)


def check_circle(rig, centre, radius, source: str, key: str = "--circle") -> MeasuredCircle:
    """A measured circle (``centre`` (cx, cy) px from the top-left, ``radius`` px) checked against the
    projector of ``rig``: inside its image, the radius within CIRCLE_RADIUS_SLACK of the design's."""
    from rigcad.export.readback import number_in

    w, h = rig.profile.projector.resolution
    cx = number_in(centre[0], f"{source}: {key} centre x", 0, w, "px", BasisError,
                   f" (the projector's image is {w} x {h} px)")
    cy = number_in(centre[1], f"{source}: {key} centre y", 0, h, "px", BasisError,
                   f" (the projector's image is {w} x {h} px)")
    design = _design_radius(rig)
    lo, hi = design * (1 - CIRCLE_RADIUS_SLACK), design * (1 + CIRCLE_RADIUS_SLACK)
    r = number_in(radius, f"{source}: {key} radius", lo, hi, "px", BasisError,
                  f": the design's rim through the lens is {design:.1f} px (another projector or lens? a mistyped "
                  "figure?)")
    if cx - r < 0 or cy - r < 0 or cx + r > w or cy + r > h:
        raise BasisError(f"{source}: {key}: a circle of {r:.1f} px about ({cx:g}, {cy:g}) runs off the {w} x {h} px "
                         "projector image")
    return MeasuredCircle((cx, cy), r, source)


def read_circle(rig, path: Path) -> MeasuredCircle:
    """The circle a lab measured, from a circle.json (module docstring)."""
    from rigcad.export.readback import read_json, shown

    data, _ = read_json(path, "a circle.json", CIRCLE_MAX_BYTES, BasisError)
    p = shown(path)
    keys = ("centre_px_from_top_left", "radius_px")
    if not isinstance(data, dict) or any(k not in data for k in keys):
        raise BasisError(f"{p}: not a measured circle: it needs the keys {', '.join(keys)} (and resolution_px), as "
                         "calibration/circle.html shows them")
    centre = data["centre_px_from_top_left"]
    if not isinstance(centre, list) or len(centre) != 2:
        raise BasisError(f"{p}: centre_px_from_top_left: need [x, y] in pixels from the image's top-left corner")
    if "resolution_px" in data and data["resolution_px"] != list(rig.profile.projector.resolution):
        w, h = rig.profile.projector.resolution
        raise BasisError(f"{p}: resolution_px {str(data['resolution_px'])[:40]}: measured on another projector; "
                         f"this profile's is [{w}, {h}] (projector.resolution)")
    return check_circle(rig, centre, data["radius_px"], p, "centre_px_from_top_left/radius_px")


def read_fit(rig, path: Path) -> tuple[float, ...]:
    """The rig parameters (RIG_NAMES order; mm, rad) of a ``rigcad calibrate`` report (its
    ``fit.parameters``, offsets in mm and tilts in deg, each {value, standard_error}); refused when it
    is no such report, lacks a parameter, or was made for another camera or rig."""
    from rigcad.calibrate.model import RIG_NAMES
    from rigcad.export.readback import number_in, read_json, shown

    data, _ = read_json(path, "a calibration.json", CALIBRATION_MAX_BYTES, BasisError)
    p = shown(path)
    params = data.get("fit", {}).get("parameters") if isinstance(data, dict) and isinstance(data.get("fit"), dict) \
        else None
    if not isinstance(params, dict):
        raise BasisError(f"{p}: fit.parameters: missing; not a report of rigcad calibrate (its calibration.json)")
    window = data.get("camera_window")
    if isinstance(window, dict) and isinstance(window.get("shape"), list) and len(window["shape"]) == 2:
        w, h = rig.profile.camera.resolution
        rows, cols = window["shape"]
        if not (isinstance(rows, int) and isinstance(cols, int) and rows <= h and cols <= w):
            raise BasisError(f"{p}: camera_window.shape {str(window['shape'])[:40]}: larger than this profile's "
                             f"{w} x {h} px camera (camera.resolution): a calibration of another rig")
    theta = []
    for name in RIG_NAMES:
        key = name.replace("_rad", "_deg")
        entry = params.get(key)
        if not isinstance(entry, dict) or "value" not in entry:
            raise BasisError(f"{p}: fit.parameters.{key}: missing; a calibration.json of rigcad calibrate gives "
                             f"each of {len(RIG_NAMES)} rig parameters ({RIG_NAMES[0].replace('_rad', '_deg')} ...)")
        deg = name.endswith("_rad")
        v = number_in(entry["value"], f"{p}: fit.parameters.{key}", -(FIT_MAX_DEG if deg else FIT_MAX_MM),
                      FIT_MAX_DEG if deg else FIT_MAX_MM, "deg" if deg else "mm", BasisError,
                      " (no rig rigcad calibrate fits: another rig's report?)")
        theta.append(math.radians(v) if deg else v)
    return tuple(theta)


def load_measured(rig, exports, circle=None, calibration=None, as_designed: bool = False) -> Measured:
    """What ``rigcad basis`` draws the rig as: ``circle`` ((cx, cy, r) px from the flag) or the
    circle.json found beside; ``calibration`` (a calibration.json, or the folder holding it) or the one
    found beside; ``as_designed``: neither found beside is read (a flag still is)."""
    folder = Path(exports) / rig.name
    c = None
    if circle is not None:
        c = check_circle(rig, circle[:2], circle[2], "--circle")
    elif not as_designed and (folder / CIRCLE_JSON).exists():
        c = read_circle(rig, folder / CIRCLE_JSON)
    path = None
    if calibration is not None:
        path = Path(calibration)
        if path.is_dir():
            path = path / "calibration.json"
        if not path.exists():
            raise BasisError(f"--calibration {calibration}: no calibration.json there (rigcad calibrate writes "
                             f"{CALIBRATION_JSON} under the exports folder)")
    elif not as_designed and (folder / CALIBRATION_JSON).exists():
        path = folder / CALIBRATION_JSON
        _check_made_from(rig, path)
    theta = read_fit(rig, path) if path is not None else None
    return Measured(c, theta, None if path is None else str(path))


def _check_made_from(rig, path: Path) -> None:
    """A calibration found beside must have been made from this profile (its folder's made_from record)."""
    from rigcad.export.atomic import read_made_from
    from rigcad.export.manifest import profile_digest
    from rigcad.export.readback import shown

    made = read_made_from(path.parent)
    if made is not None and made != profile_digest(rig.profile):
        raise BasisError(f"{shown(path)}: made from another version of profile {rig.name} (its "
                         f"{path.parent.name}.made_from.json): calibrate again, name it with --calibration to use it anyway, "
                         "or run rigcad basis --as-designed")


def measured_rig(rig, measured: Measured | None):
    """``rig`` moved by the fitted parameters (rigcad.calibrate.model.moved), or ``rig`` itself."""
    if measured is None or measured.theta is None:
        return rig
    import numpy as np

    from rigcad.calibrate.model import moved

    return moved(rig, np.asarray(measured.theta, float))


def projector_frame(rig, measured: Measured | None) -> tuple[float | None, tuple[float, float] | None]:
    """(focal length px, image centre (cx, cy) px from the top-left) the projector's pixels are read
    in: the measured circle's, or (None, None) for the design's (the lensed focal length, the image's
    centre)."""
    if measured is None or measured.circle is None:
        return None, None
    c = measured.circle
    return c.radius_px / math.tan(rig.incidence.alpha_max), c.centre_px


__all__ = ["CALIBRATION_JSON", "CIRCLE_JSON", "Measured", "MeasuredCircle", "check_circle", "load_measured",
           "measured_rig", "projector_frame", "read_circle", "read_fit"]
