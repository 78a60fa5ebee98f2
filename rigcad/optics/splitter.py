"""The plate beam splitter (thesis 3.1 item 4, Figure 3.4): a glass plate at 45 deg on the optical
axis whose coated front face reflects the projector down onto the paraboloid, while the camera
looks down through the plate (kernel-free, numpy; mm, rad; frame: O at the origin, +z up).

The reflected (projector) path leaves the coating without entering the glass: the projector's COP
is the mirror image of the design COP in the front face. The transmitted (camera) path crosses the
glass twice; a parallel plate keeps each ray's direction and shifts it sideways by the closed form

    d(i) = t sin(i) (1 - cos(i) / sqrt(n^2 - sin(i)^2))        (i: angle of incidence on the plate)

(every optics text; Smith, *Modern Optical Engineering*, "plane parallel plates"), 0.33 mm for a
1 mm N-BK7 plate at 45 deg. Because d depends on i, the rays of one pinhole do not meet again in one
virtual point (a tilted plate is astigmatic): the design puts the camera where the least-squares
virtual point of the bundle it uses lands on the design COP (:func:`camera_cop`), and the ray
checker traces the camera's rays through the plate (:func:`transmit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def lateral_shift(thickness: float, index: float, incidence: float) -> float:
    """Sideways shift (mm) of a ray crossing a parallel plate of ``thickness`` mm and refractive
    ``index`` at ``incidence`` rad (closed form, module docstring); measured perpendicular to the ray."""
    s = math.sin(incidence)
    return thickness * s * (1.0 - math.cos(incidence) / math.sqrt(index * index - s * s))


@dataclass(frozen=True)
class Plate:
    """A parallel glass plate: its coated front face passes through ``center`` (3,) mm with unit
    ``normal`` (3,) pointing out of the glass on the coated side; the back face lies ``thickness``
    mm behind. ``half_width`` (along ``width_dir``) and ``half_length`` (along normal x width_dir)
    bound the plate (mm)."""

    center: tuple[float, float, float]
    normal: tuple[float, float, float]
    width_dir: tuple[float, float, float]
    thickness: float
    index: float
    half_width: float
    half_length: float

    @property
    def length_dir(self) -> np.ndarray:
        return np.cross(np.asarray(self.normal, float), np.asarray(self.width_dir, float))

    def corners(self) -> np.ndarray:
        """The front face's four corners (4, 3) mm."""
        c, w, l_ = np.asarray(self.center, float), np.asarray(self.width_dir, float), self.length_dir
        return np.array([c + a * self.half_width * w + b * self.half_length * l_
                         for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def splitter_plate(cop_z: float, splitter_distance: float, width: float, length: float, thickness: float,
                   index: float) -> Plate:
    """The rig's splitter: front face centred on the axis ``splitter_distance`` mm below the COP at
    ``cop_z``, at 45 deg, facing +x (the projector's side) and down (the paraboloid's): normal
    (1, 0, -1)/sqrt 2; its width along y."""
    r = 1.0 / math.sqrt(2.0)
    return Plate((0.0, 0.0, cop_z - splitter_distance), (r, 0.0, -r), (0.0, 1.0, 0.0), thickness, index,
                 width / 2, length / 2)


def _plane_hit(origins: np.ndarray, dirs: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Points where rays (n, 3) meet the plane through ``point`` with ``normal`` (NaN if parallel)."""
    den = dirs @ normal
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((point - origins) @ normal) / den
    return origins + t[:, None] * dirs


def _refract(d: np.ndarray, n: np.ndarray, eta: float) -> np.ndarray:
    """Snell refraction of unit directions d (n, 3) at a face with unit normal n (3,) facing the
    incoming ray (d . n < 0), index ratio eta = n_from / n_to. Vector form (Heckbert)."""
    cos_i = -(d @ n)
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    if np.any(k < 0):
        raise ValueError("total internal reflection inside the splitter plate")
    return eta * d + (eta * cos_i - np.sqrt(k))[:, None] * n


def transmit(plate: Plate, origins: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rays (origins, unit dirs: (n, 3)) coming from behind the plate, refracted into the back face
    and out of the front face. Returns the exit points on the front face and the exit directions
    (n, 3) and ``inside`` (n,): the ray crossed the front face within the plate's edges."""
    n = np.asarray(plate.normal, float)
    c = np.asarray(plate.center, float)
    back = c - plate.thickness * n
    p_in = _plane_hit(origins, dirs, back, n)
    # both faces: the normal facing rays that come from behind is -n (n points out of the front face)
    d_in = _refract(dirs, -n, 1.0 / plate.index)
    p_out = _plane_hit(p_in, d_in, c, n)
    d_out = _refract(d_in, -n, plate.index)
    rel = p_out - c
    inside = (np.abs(rel @ np.asarray(plate.width_dir, float)) <= plate.half_width) & \
             (np.abs(rel @ plate.length_dir) <= plate.half_length)
    return p_out, d_out / np.linalg.norm(d_out, axis=1, keepdims=True), inside


def mirror_point(plate: Plate, point) -> np.ndarray:
    """The image (3,) of ``point`` in the plate's front (reflecting) face."""
    n = np.asarray(plate.normal, float)
    p = np.asarray(point, float)
    return p - 2.0 * ((p - np.asarray(plate.center, float)) @ n) * n


def virtual_source(origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """The point (3,) nearest to every line (origins, unit dirs: (n, 3)) in least squares."""
    eye = np.eye(3)
    proj = eye[None] - dirs[:, :, None] * dirs[:, None, :]  # (n, 3, 3): I - d d^T
    return np.linalg.solve(proj.sum(axis=0), np.einsum("nij,nj->i", proj, origins))


def cone_dirs(half_angle: float, rings: int = 24, sectors: int = 48) -> np.ndarray:
    """Unit directions (m, 3) filling the cone of ``half_angle`` rad about -z (the camera's view of
    the paraboloid), uniform in solid-angle rings, the chief ray included."""
    a = half_angle * np.sqrt((np.arange(rings) + 0.5) / rings)
    phi = 2 * np.pi * np.arange(sectors) / sectors
    A, F = np.meshgrid(a, phi, indexing="ij")
    d = np.stack([np.sin(A) * np.cos(F), np.sin(A) * np.sin(F), -np.cos(A)], axis=-1).reshape(-1, 3)
    return np.vstack([[0.0, 0.0, -1.0], d])


def virtual_offset(plate: Plate, dirs: np.ndarray) -> np.ndarray:
    """Where the least-squares virtual source of a pinhole at the origin's bundle ``dirs`` (m, 3)
    sits relative to the pinhole, seen through ``plate`` (3,) mm. A plate is the same everywhere, so
    this is the same wherever the pinhole stands (in front of the plate's back face)."""
    c = np.asarray(plate.center, float)
    n = np.asarray(plate.normal, float)
    start = c - (plate.thickness + 100.0) * n  # any point behind the plate
    p, d, _ = transmit(plate, np.tile(start, (len(dirs), 1)), dirs)
    return virtual_source(p, d) - start


@dataclass(frozen=True)
class CameraPlacement:
    """Where the camera's real COP goes so that it sees the rig through the splitter as if from the
    design COP: ``cop`` (3,) mm; ``offset`` = cop - design COP (3,) mm; ``chief_shift_mm``: the
    closed-form sideways shift of the chief ray at 45 deg; ``residual_mm``: RMS distance of the
    bundle's transmitted rays from the design COP once placed (the plate's astigmatism)."""

    cop: tuple[float, float, float]
    offset: tuple[float, float, float]
    chief_shift_mm: float
    residual_mm: float

    def as_dict(self) -> dict:
        return {"camera_cop_mm": list(self.cop), "compensation_offset_mm": list(self.offset),
                "chief_ray_shift_closed_form_mm": self.chief_shift_mm,
                "bundle_rms_distance_from_cop_mm": self.residual_mm}


def camera_cop(plate: Plate, cop_z: float, half_angle: float) -> CameraPlacement:
    """The compensated camera COP: the design COP (0, 0, cop_z) less the virtual offset of the
    cone of ``half_angle`` rad about -z (module docstring)."""
    dirs = cone_dirs(half_angle)
    off = virtual_offset(plate, dirs)
    cop = np.array([0.0, 0.0, cop_z]) - off
    p, d, _ = transmit(plate, np.tile(cop, (len(dirs), 1)), dirs)
    rel = np.array([0.0, 0.0, cop_z]) - p
    dist = np.linalg.norm(rel - (rel * d).sum(axis=1, keepdims=True) * d, axis=1)
    inc = math.acos(abs(float(np.asarray(plate.normal) @ np.array([0.0, 0.0, -1.0]))))
    return CameraPlacement(tuple(float(v) for v in cop), tuple(float(v) for v in -off),
                           lateral_shift(plate.thickness, plate.index, inc), float(np.sqrt(np.mean(dist ** 2))))


__all__ = ["CameraPlacement", "Plate", "camera_cop", "cone_dirs", "lateral_shift", "mirror_point",
           "splitter_plate", "transmit", "virtual_offset", "virtual_source"]
