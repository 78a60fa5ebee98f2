"""3D misalignment: component poses, the sensitivity table, and the seeded Monte Carlo tolerance
analysis (thesis 3.2.2: offsets of camera, projector, paraboloid and dome, here also vertical
offsets and tilts, in 3D).

Pivots of the tilts: the COP for camera and projector (their pixel rays turn about it), the vertex
for the paraboloid, the sample point O for the dome (it stands on the base plate). Each build is
its own set of frozen poses; nothing shared is perturbed in place.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.check.rays import _cross, _dot
from rigcad.check.scene import Optics
from rigcad.check.sources import annulus_rays
from rigcad.optics.frames import COMPONENTS, DOFS, Misalignment
from rigcad.optics.incidence import DesignMap
from rigcad.check.trace3d import Trace3D, convergence_point, trace

def declared(profile) -> Misalignment:
    """The misalignment the profile declares (misalignment.*: dx, dz and tilts about +y)."""
    mis = profile.misalignment
    m = Misalignment.none()
    for c in ("camera", "projector"):
        m = m.with_(c, offset=(getattr(mis, f"{c}_dx"), 0.0, getattr(mis, f"{c}_dz")), tilt=getattr(mis, f"{c}_tilt"))
    m = m.with_("paraboloid", offset=(mis.paraboloid_dx, 0.0, 0.0), tilt=mis.paraboloid_tilt)
    return m.with_("dome", offset=(mis.dome_dx, 0.0, 0.0), tilt=mis.dome_tilt)


def trace_path(optics: Optics, rig, design: DesignMap, mis: Misalignment, device: str,
               count: int, seed: int, aligned=None) -> tuple[Trace3D, np.ndarray, np.ndarray]:
    """Trace ``count`` seeded pinhole rays of ``device`` (projector or camera; the camera's through
    the beam splitter, check.tower.through_splitter) through the misaligned rig; returns the trace,
    the design arrival direction of each ray's pixel, and the design direction of the paraboloid
    point it hit (rotated with the paraboloid). ``aligned``: (rays, design directions) of
    ``annulus_rays(design, count, seed)`` made once by a caller that traces many builds (the same
    numbers: the source pose is applied to them here)."""
    pose = mis.pose(device, rig.geometry)
    if aligned is None:
        rays = annulus_rays(design, count, seed, pose)
        ddirs = design.direction(rays.chief)
        origins, dirs = rays.origins, rays.dirs
    else:
        rays, ddirs = aligned
        origins, dirs = rays.origins, rays.dirs
        if not pose.is_identity:
            origins, dirs = pose.globalize_points(origins), pose.globalize_dirs(dirs)
    if device == "camera":  # the camera looks through the beam splitter, from its compensated COP
        from rigcad.check.tower import through_splitter

        origins, dirs, _ = through_splitter(rig, origins, dirs)
    pp = mis.pose("paraboloid", rig.geometry)
    placed = optics.placed(pp, mis.pose("dome", rig.geometry))
    tr = trace(placed, origins, dirs)
    local, _ = pp.localize(tr.p1, tr.p1)
    return tr, ddirs, pp.globalize_dirs(design.direction_at(local))


def figures(tr: Trace3D, design_dirs: np.ndarray, reference: Trace3D | None = None,
            mirror_dirs: np.ndarray | None = None) -> dict:
    """Spot and angle figures of a trace (mm, rad; units in keys). ``max_angle_error_rad``: against
    the design direction of each ray's pixel (uncalibrated); ``max_mirror_angle_error_rad``:
    against the design direction of the paraboloid point each ray hit (what remains after
    calibration maps pixels to paraboloid points)."""
    ok = tr.ok
    miss = tr.miss[ok]
    x = convergence_point(tr)
    err = _angles(tr.arrival[ok], design_dirs[ok])
    out = {
        "rays": int(ok.size),
        "rays_ok": int(ok.sum()),
        "max_spot_radius_mm": float(miss.max()) if miss.size else float("nan"),
        "rms_spot_radius_mm": float(np.sqrt(np.mean(miss ** 2))) if miss.size else float("nan"),
        "convergence_point_mm": [float(v) for v in x],
        "convergence_offset_mm": float(np.linalg.norm(x)),
        "max_angle_error_rad": float(np.nanmax(err)) if err.size else float("nan"),
        "rms_angle_error_rad": float(np.sqrt(np.nanmean(err ** 2))) if err.size else float("nan"),
    }
    if mirror_dirs is not None:
        e2 = _angles(tr.arrival[ok], mirror_dirs[ok])
        out["max_mirror_angle_error_rad"] = float(np.nanmax(e2)) if e2.size else float("nan")
    if reference is not None:
        both = ok & reference.ok
        d = _angles(tr.arrival[both], reference.arrival[both])
        out["max_angle_change_rad"] = float(d.max()) if d.size else float("nan")
    return out


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles (rad) between unit rows of a and b (n, 3), accurate for small angles."""
    return np.arctan2(np.linalg.norm(_cross(a, b), axis=1), _dot(a, b))


def sensitivity(optics: Optics, rig, design: DesignMap, probe: float, probe_tilt: float,
                count: int, seed: int) -> dict:
    """Per component and degree of freedom: the figures at ``probe`` mm (``probe_tilt`` rad) and
    per unit (mm of convergence error per mm or per mrad)."""
    base, ddirs, _ = trace_path(optics, rig, design, Misalignment.none(), "projector", count, seed)
    table = {}
    for comp in COMPONENTS:
        device = "camera" if comp == "camera" else "projector"
        for dof in DOFS:
            m = Misalignment.none()
            if dof == "dx":
                m, amount, unit = m.with_(comp, offset=(probe, 0, 0)), probe, "mm"
            elif dof == "dz":
                m, amount, unit = m.with_(comp, offset=(0, 0, probe)), probe, "mm"
            else:
                m, amount, unit = m.with_(comp, tilt=probe_tilt), probe_tilt * 1e3, "mrad"
            tr, _, mdirs = trace_path(optics, rig, design, m, device, count, seed)
            f = figures(tr, ddirs, base, mdirs)
            f["probe"] = f"{amount:g} {unit}"
            f[f"spot_shift_mm_per_{unit}"] = f["convergence_offset_mm"] / amount
            f[f"max_spot_radius_mm_per_{unit}"] = f["max_spot_radius_mm"] / amount
            f[f"max_angle_change_rad_per_{unit}"] = f["max_angle_change_rad"] / amount
            f[f"max_mirror_angle_error_rad_per_{unit}"] = f["max_mirror_angle_error_rad"] / amount
            table[f"{comp}_{dof}"] = f
    return table


def sample_build(rng: np.random.Generator, tol) -> Misalignment:
    """One random build within the tolerances (see TolerancingParams)."""
    m = Misalignment.none()
    for c in COMPONENTS:
        lateral, height, tilt = getattr(tol, f"{c}_offset"), getattr(tol, f"{c}_height"), getattr(tol, f"{c}_tilt")
        r = lateral * np.sqrt(rng.uniform())
        a = rng.uniform(0, 2 * np.pi)
        b = rng.uniform(0, 2 * np.pi)
        m = m.with_(c, offset=(r * np.cos(a), r * np.sin(a), rng.uniform(-height, height)),
                    tilt=rng.uniform(0, tilt), axis=(np.cos(b), np.sin(b), 0.0))
    return m


def monte_carlo(optics: Optics, rig, design: DesignMap, tol) -> dict:
    """``tol.builds`` seeded random builds; per build, the worse of the projector's and the camera's
    path: largest spot radius (mm) and mirror angle error (rad, see :func:`figures`: per-pixel
    errors of a misplaced source are calibrated away, thesis 4.1); the yield meeting both targets."""
    rng = np.random.default_rng(tol.seed)
    spot, angle, offset, pixel_angle = [], [], [], []
    for b in range(tol.builds):  # a loop over builds; each traces its rays vectorised
        m = sample_build(rng, tol)
        worst = {"max_spot_radius_mm": 0.0, "max_mirror_angle_error_rad": 0.0, "convergence_offset_mm": 0.0,
                 "max_angle_error_rad": 0.0}
        for device in ("projector", "camera"):
            tr, ddirs, mdirs = trace_path(optics, rig, design, m, device, tol.rays, tol.seed + 1 + b)
            f = figures(tr, ddirs, None, mdirs)
            for k in worst:
                worst[k] = max(worst[k], f[k]) if np.isfinite(f[k]) else float("inf")
        spot.append(worst["max_spot_radius_mm"])
        angle.append(worst["max_mirror_angle_error_rad"])
        offset.append(worst["convergence_offset_mm"])
        pixel_angle.append(worst["max_angle_error_rad"])
    spot, angle, offset, pixel_angle = np.array(spot), np.array(angle), np.array(offset), np.array(pixel_angle)
    good = (spot <= tol.max_spot_radius) & (angle <= tol.max_angle_error)

    def dist(v):
        return {"mean": float(np.mean(v)), "p50": float(np.percentile(v, 50)), "p90": float(np.percentile(v, 90)),
                "p99": float(np.percentile(v, 99)), "max": float(np.max(v))}

    return {
        "builds": int(tol.builds),
        "seed": int(tol.seed),
        "rays_per_build_and_path": int(tol.rays),
        "distribution": "offsets uniform in a disc (x-y) and in +-height (z); tilt uniform 0..tol about a "
                        "random horizontal axis; camera and projector paths traced, the worse kept",
        "max_spot_radius_mm": dist(spot),
        "max_mirror_angle_error_rad": dist(angle),
        "max_pixel_angle_error_rad_uncalibrated": dist(pixel_angle),
        "convergence_offset_mm": dist(offset),
        "target_max_spot_radius_mm": tol.max_spot_radius,
        "target_max_mirror_angle_error_rad": tol.max_angle_error,
        "yield": float(np.mean(good)),
        "min_yield": tol.min_yield,
        "per_build": {"max_spot_radius_mm": spot.tolist(), "max_mirror_angle_error_rad": angle.tolist()},
    }
