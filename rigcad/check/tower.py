"""The COP tower in the 3D ray check: the camera's view through the beam splitter, and the ray
bundles' clearance from the tower (frame: mm, O at the origin, +z up; angles rad).

* :func:`camera_view` traces the camera's pinhole rays from its real (compensated) COP through the
  plate (``optics.splitter.transmit``) into the rig: the reading the raycheck targets are held to
  with the splitter in place. ``compensate=False`` puts the camera at the design COP, as if the
  plate's shift were ignored.
* :func:`bundle_clearance` folds the projector's useful bundle (the pinhole cone to the paraboloid's
  rim with the thin-lens aperture, thesis 3.2.2) at the splitter's front face and the camera's cone
  through the plate, and counts the rays that meet a tower part or another instrument before they
  reach the dome's top: zero, and zero again with the aperture widened by ``tower.clearance``.
"""

from __future__ import annotations

import numpy as np

from rigcad.check.figures import figures
from rigcad.check.sources import Rays, pixel_rays, thin_lens_rays
from rigcad.check.result import Trace3D
from rigcad.check.trace3d import trace
from rigcad.optics.splitter import transmit

#: Chief rays around the rim of the useful bundle, and aperture-edge rays per chief ray, of the
#: clearance check: 256 x 32 rays step 1.4 deg around the rim and 11 deg around the aperture, where a
#: part 5 mm off the bundle spans far more than one step.
RIM_RAYS = 256
EDGE_RAYS = 32
#: Chord error of the meshes the clearance check traces (mm): far below tower.clearance (5 mm).
CLEARANCE_CHORD_ERROR = 0.05
#: Instruments whose rays start inside them (a COP is inside its lens) or that the light crosses by
#: design (the splitter, the focusing lens), and the markers: not obstacles of the bundles.
NOT_OBSTACLES = {"projector": ("projector_lens", "projector_body", "beam_splitter", "focusing_lens"),
                 "camera": ("camera_lens", "camera_body", "beam_splitter", "focusing_lens")}


def through_splitter(rig, origins: np.ndarray, dirs: np.ndarray, compensate: bool = True):
    """Camera rays (origins at the design COP as placed by the rig's camera pose, unit dirs: (n, 3))
    from the camera's real COP (moved by the plate's compensation unless ``compensate`` is False)
    through the plate: returns exit points, directions (n, 3) and ``inside`` (n,)."""
    t = rig.layout.tower
    return transmit(t.plate, origins + (np.asarray(t.camera.offset) if compensate else 0.0), dirs)


def camera_rays(rig, design, count: int, seed: int, compensate: bool = True) -> tuple[Rays, np.ndarray, np.ndarray]:
    """The camera's seeded pinhole rays over the paraboloid's useful annulus, from its real COP (the
    design COP moved by the plate's compensation, and by the rig's camera misalignment), after the
    plate: returns the rays (exit points, directions), and per ray whether it crossed the plate
    inside its edges."""
    from rigcad.check.sources import annulus_rays

    rays = annulus_rays(design, count, seed, rig.pose("camera"))
    p, d, inside = through_splitter(rig, rays.origins, rays.dirs, compensate)
    return Rays(p, d, rays.chief, rays.pixel), inside, rays.origins


def camera_view(optics, rig, design, count: int, seed: int, compensate: bool = True) -> tuple[Trace3D, dict]:
    """Trace the camera through the splitter (module docstring); returns the trace and its figures
    (check.figures.figures, units in keys): the spot at O, the angle error against each pixel's design
    direction (uncalibrated) and against the design direction of the paraboloid point each ray hit
    (after the camera calibration of thesis 4.1.1, which maps camera pixels to paraboloid points)."""
    rays, inside, _ = camera_rays(rig, design, count, seed, compensate)
    tr = trace(optics, rays.origins, rays.dirs)
    pp = rig.pose("paraboloid")
    local, _ = pp.localize(tr.p1, tr.p1)
    f = figures(tr, design.direction(rays.chief), None, pp.globalize_dirs(design.direction_at(local)))
    f["rays_outside_the_plate"] = int(np.count_nonzero(~inside))
    f["compensated"] = compensate
    return tr, f


def _projector_bundle(rig, design, widen: float) -> tuple[np.ndarray, np.ndarray]:
    """Segments (a, b: (m, 3) mm) of the projector's folded bundle: rim chief rays and the axis with
    aperture-edge rays (aperture + 2 ``widen``), from the real projector side to the dome's top."""
    t = rig.layout.tower
    r_rim = float(design.pixel_radius(np.array([design.alpha_max]))[0])
    phi = 2 * np.pi * np.arange(RIM_RAYS) / RIM_RAYS
    chief = pixel_rays(design, np.append(r_rim * np.cos(phi), 0.0), np.append(r_rim * np.sin(phi), 0.0))
    focal = rig.geometry.cop_z  # aim the aperture rays at O: the rays converge towards the sample
    rays = thin_lens_rays(chief, focal, rig.profile.projector.aperture + 2 * widen, EDGE_RAYS)
    o = np.vstack([chief.origins, rays.origins])
    d = np.vstack([chief.dirs, rays.dirs])
    plate = t.plate
    n, c = np.asarray(plate.normal), np.asarray(plate.center)
    s = o + (((c - o) @ n) / (d @ n))[:, None] * d  # the front face: where the real beam folds
    real_o = o - 2.0 * ((o - c) @ n)[:, None] * n  # the aperture's image: on the real projector's side
    end = s + ((rig.layout.dome_top_z - s[:, 2]) / d[:, 2])[:, None] * d
    return np.vstack([real_o, s]), np.vstack([s, end])


def _camera_bundle(rig, design) -> tuple[np.ndarray, np.ndarray]:
    """Segments of the camera's pinhole cone to the rim (and the axis): COP to the plate, then from
    the plate down to the dome's top."""
    t = rig.layout.tower
    r_rim = float(design.pixel_radius(np.array([design.alpha_max]))[0])
    phi = 2 * np.pi * np.arange(RIM_RAYS) / RIM_RAYS
    chief = pixel_rays(design, np.append(r_rim * np.cos(phi), 0.0), np.append(r_rim * np.sin(phi), 0.0))
    cop = chief.origins + np.asarray(t.camera.offset)
    p, d, _ = transmit(t.plate, cop, chief.dirs)
    end = p + ((rig.layout.dome_top_z - p[:, 2]) / d[:, 2])[:, None] * d
    return np.vstack([cop, p]), np.vstack([p, end])


def _obstacles(rig) -> dict[str, object]:
    """Trimesh meshes of the tower's parts in the rig and of the instruments, by name."""
    from rigcad.parts.tower import TOWER_PARTS

    parts = [rig.recipe(n) for n in TOWER_PARTS if rig.recipe(n).in_rig] + list(rig.instruments)
    return {part.name: rig.mesh(part, CLEARANCE_CHORD_ERROR) for part in parts}


def _blocked(segments: tuple[np.ndarray, np.ndarray], meshes: dict) -> dict[str, int]:
    """Per mesh, the segments it cuts (a hit closer than the segment's end)."""
    a, b = segments
    length = np.linalg.norm(b - a, axis=1)
    d = (b - a) / length[:, None]
    out = {}
    for name, mesh in meshes.items():
        loc, ray, _ = mesh.ray.intersects_location(a, d, multiple_hits=False)
        hit = np.linalg.norm(loc - a[ray], axis=1) < length[ray]
        out[name] = int(np.unique(ray[hit]).size)
    return out


def bundle_clearance(rig, design) -> dict:
    """Rays of the projector's and the camera's bundles that meet a tower part or another instrument
    (module docstring); JSON-ready."""
    meshes = _obstacles(rig)
    widen = rig.profile.tower.clearance
    out = {"rim_rays": RIM_RAYS, "aperture_edge_rays": EDGE_RAYS, "clearance_mm": widen,
           "to_z_mm": rig.layout.dome_top_z}
    for device, segs in (("projector", _projector_bundle(rig, design, 0.0)),
                         ("projector_widened", _projector_bundle(rig, design, widen)),
                         ("camera", _camera_bundle(rig, design))):
        key = "camera" if device == "camera" else "projector"
        hits = _blocked(segs, {n: m for n, m in meshes.items() if n not in NOT_OBSTACLES[key]
                               and not n.endswith("_marker")})
        out[device] = {"segments": int(len(segs[0])), "blocked_by": {n: k for n, k in hits.items() if k},
                       "blocked": int(sum(hits.values()))}
    return out


def tower_report(optics, rig, design, count: int, seed: int) -> dict:
    """The tower's part of the ray check report: the camera through the splitter (compensated, and
    uncompensated for comparison), the compensation, and the bundles' clearance."""
    _, comp = camera_view(optics, rig, design, count, seed, compensate=True)
    _, raw = camera_view(optics, rig, design, count, seed, compensate=False)
    return {"splitter": rig.layout.tower.camera.as_dict(), "camera_through_splitter": comp,
            "camera_through_splitter_uncompensated": raw, "bundle_clearance": bundle_clearance(rig, design)}


__all__ = ["bundle_clearance", "camera_rays", "camera_view", "through_splitter", "tower_report"]
