"""The 3D ray check stage: a Rig -> meshes and exact surfaces -> traces -> figures ->
tolerance table; ``exports/<profile>/check/{raycheck.json, spot.png, theta_map.png}``.

Readings traced on the same rays (seeded, uniform in projector-image area over the paraboloid's
useful annulus): ``analytic`` (exact surfaces, float64: the reference), and with meshes ``mesh``
(flat facets, what an STL says), ``smooth`` (interpolated vertex normals), ``exact_normals`` (exact
normal at the mesh hit) and ``mesh_float32`` (Embree's own float32 hit and normal, no refinement).
Spot radius = distance from O to a returning ray (mm); angle errors between arrival directions
(rad). Frame: mm, O at the origin, +z up.
"""

from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rigcad.check import montecarlo, tolerances
from rigcad.check.scene import Optics, analytic_optics, mesh_optics, mirror_meshes, mixed, placed_as, share_scenes
from rigcad.check.sources import annulus_rays, pixel_grid, pixel_rays, thin_lens_rays
from rigcad.optics.camera import camera_model
from rigcad.optics.incidence import DesignMap
from rigcad.check.result import STATUS_NAMES, Trace3D
from rigcad.check.trace3d import trace
from rigcad.profile.schema import Profile

#: Rays of the exact-normal reading (its foot points cost ~10 us a ray): enough for its maximum
#: to be stable to a few per cent (the error is smooth over the annulus).
EXACT_NORMAL_RAYS = 20_000
#: Chief rays of the thin-lens check (each with lens_azimuths edge rays).
THIN_LENS_RAYS = 5_000
#: Radial step (px) of the fan that measures pixels per degree: 0.05 px resolves the 1-1.3 px/deg
#: derivative to well under 1 %.
FAN_STEP_PX = 0.05


@dataclass
class RayCheck:
    """Everything the check computed; ``report`` is JSON-ready (units in keys), ``rows`` the
    tolerance table; arrays kept for the figures; ``timings_s`` the wall time of each stage (s),
    kept apart from the report so that raycheck.json is the same bytes on every run."""

    profile: Profile
    report: dict
    rows: list
    trace: Trace3D
    design_dirs: np.ndarray
    theta_map: np.ndarray | None
    status_map: np.ndarray | None
    fan: dict
    timings_s: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return all(r.ok for r in self.rows)


from rigcad.check.figures import _angles  # noqa: E402
from rigcad.units import DEG


def _losses(tr: Trace3D, rays_chief: np.ndarray, design_dirs: np.ndarray) -> dict:
    n = len(tr.status)
    phi = np.degrees(np.arctan2(rays_chief[:, 1], rays_chief[:, 0])) % 360
    theta = np.degrees(np.arccos(np.clip(design_dirs[:, 2], -1, 1)))
    out = {}
    for code, name in STATUS_NAMES.items():
        sel = tr.status == code
        if code == 0 or not sel.any():
            continue
        counts, _ = np.histogram(phi[sel], bins=12, range=(0, 360))
        out[name] = {
            "rays": int(sel.sum()), "fraction": float(sel.sum() / n),
            "segment": int(np.bincount(tr.segment[sel]).argmax()),
            "phi_deg_counts_per_30deg": counts.tolist(),
            "design_theta_deg_range": [float(np.nanmin(theta[sel])), float(np.nanmax(theta[sel]))]
            if np.isfinite(theta[sel]).any() else None,
        }
    return out


def reading(tr: Trace3D, design_dirs: np.ndarray, exact: Trace3D | None, chief: np.ndarray) -> dict:
    """Figures of one reading (units in keys)."""
    ok = tr.ok
    f = montecarlo.figures(tr, design_dirs, exact)
    th = tr.theta[ok]
    f["theta_min_deg"] = float(np.degrees(th.min())) if th.size else float("nan")
    f["theta_max_deg"] = float(np.degrees(th.max())) if th.size else float("nan")
    lost = ~ok
    f["lost_fraction"] = float(lost.mean())
    f["losses"] = _losses(tr, chief, design_dirs)
    if exact is not None:
        both = ok & exact.ok
        d = _angles(tr.arrival[both], exact.arrival[both])
        f["mesh_minus_exact_angle_rad"] = {"max": float(d.max()) if d.size else float("nan"),
                                           "rms": float(np.sqrt(np.mean(d ** 2))) if d.size else float("nan")}
        dm = np.abs(tr.miss[both] - exact.miss[both])
        f["mesh_minus_exact_spot_mm"] = {"max": float(dm.max()) if dm.size else float("nan")}
        f["status_agreement_with_exact"] = float(np.mean(tr.status == exact.status))
    return f


def pixels_per_degree(optics: Optics, design: DesignMap, azimuth: float = 45 * DEG, pose=None) -> dict:
    """Trace a radial fan of pixels at ``azimuth`` (off the beam) from the occlusion limit to the
    rim every FAN_STEP_PX px; theta against pixel radius and its derivative (px/deg)."""
    r_in, r_out = design.pixel_radius(np.array([design.alpha_min, design.alpha_max]))
    rho = np.arange(r_in, r_out, FAN_STEP_PX)
    tr = trace(optics, *_xy(design, rho, azimuth, pose))
    ok = tr.ok
    theta = np.degrees(tr.theta[ok])
    r = rho[ok]
    dpd = np.abs(np.gradient(r, theta)) if len(r) > 2 else np.array([np.nan])
    return {"pixel_radius_px": r, "theta_deg": theta, "px_per_deg": dpd,
            "summary": {"azimuth_deg": azimuth / DEG, "px_per_deg_min": float(np.min(dpd)),
                        "px_per_deg_mean": float((r.max() - r.min()) / (theta.max() - theta.min())),
                        "px_per_deg_max": float(np.max(dpd)), "fan_step_px": FAN_STEP_PX}}


def _xy(design, rho, azimuth, pose=None):
    rays = pixel_rays(design, rho * math.cos(azimuth), rho * math.sin(azimuth), pose)
    return rays.origins, rays.dirs


def run_raycheck(rig, exports: Path | None = None, rays: int | None = None, mode: str | None = None,
                 chord_error: float | None = None, normal_error: float | None = None,
                 monte_carlo: bool = True, grid: bool = True, builds: int | None = None,
                 optics_cache: dict | None = None, progress=None) -> RayCheck:
    """Run the 3D check of ``rig`` (a :class:`rigcad.rig.Rig`; see the module docstring).
    ``rays``/``mode``/``builds`` override the profile's raycheck and tolerancing settings;
    ``chord_error`` (mm)/``normal_error`` (rad) the mirror tessellation. ``optics_cache``: a dict
    reused across calls (tests) to keep BVHs. A moved rig (``rig.moved``) is traced where its
    components stand; the sensitivity table and the Monte Carlo perturb the design's alignment."""
    step = progress or (lambda label: None)
    profile = _overridden(rig.profile, rays, mode, chord_error, normal_error, builds)
    override_tess = chord_error is not None or normal_error is not None
    rc, tol = profile.raycheck, profile.tolerancing
    timings = {}
    with _timed(timings, "design_s", step, "design"):
        design = rig.incidence
        analytic = analytic_optics(rig)
    meshes = meshed = None
    if rc.mode != "analytic":
        step("meshes")
        meshes, meshed, timings["meshes_s"], timings["embree_build_s"] = _mesh_optics(
            rig, profile, exports, override_tess, optics_cache)
    check_optics = analytic if meshed is None else share_scenes(meshed, rc.mode)
    projector = rig.pose("projector")
    with _timed(timings, "pinhole_s", step, "pinhole"):
        src = annulus_rays(design, rc.rays, rc.seed, projector)
        ddirs = design.direction(src.chief)
        exact = trace(analytic, src.origins, src.dirs)
        readings, main = _pinhole_readings(analytic, meshed, src, ddirs, exact, rc.mode, rc.rays)
    with _timed(timings, "tower_s", step, "tower"):
        from rigcad.check.tower import tower_report  # the camera through the beam splitter; bundle clearance

        tower = tower_report(check_optics, rig, design, rc.rays, rc.seed + 17)
    with _timed(timings, "pixels_s", step, "pixels"):
        fan = pixels_per_degree(check_optics, design, pose=projector)
        theta_map, status_map, grid_report = _pixel_grid(check_optics, design, profile, projector) if grid \
            else (None, None, None)
    with _timed(timings, "thin_lens_s", step, "thin lens"):
        lens = _thin_lens(check_optics, design, profile, projector, exact)
    with _timed(timings, "misalignment_s", step, "misalignment"):
        misalignment = _misalignment(check_optics, rig, design, profile)
    mc = None
    if monte_carlo:
        with _timed(timings, "monte_carlo_s", step, "monte carlo"):
            mc = montecarlo.check_report(rig, tol.builds, tol.rays)  # the exact surfaces, as rigcad tolerance traces
    report = {
        "profile": {"name": profile.name, "sources": list(profile.sources)},
        "frame": "mm; sample point O at the origin; optical axis +z; projector pixel x to +x, rows to -y",
        "mode": rc.mode,
        "backend": check_optics.backend,
        "backends": {"analytic": analytic.backend, **({"mesh": meshed.backend} if meshed else {})},
        "rays": rc.rays, "seed": rc.seed,
        "meshes": None if meshes is None else _mesh_figures(meshes),
        "readings": readings,
        "pixels_per_degree": fan["summary"],
        # the 2D design's exact theta range (deg), against targets: the figure `rigcad design` reports
        "design_range": rig.design.report["measurable_range"],
        "pixel_grid": grid_report,
        "thin_lens": lens,
        "tower": tower,
        "misalignment": misalignment,
        "monte_carlo": mc,
        # the camera's lens and the paraboloid's image on its sensor (none with the COP at infinity)
        "camera": None if rig.geometry.cop_at_infinity else camera_model(profile, rig.geometry).as_dict(),
    }
    rows = tolerances.evaluate(profile, report)
    report["checks"] = [r.as_dict() for r in rows]
    report["passed"] = all(r.ok for r in rows)
    return RayCheck(profile, report, rows, main, ddirs, theta_map, status_map, fan, timings)


@contextmanager
def _timed(timings: dict, key: str, step, label: str):
    """One stage of the check: ``step(label)`` first, its wall time (s) in ``timings[key]`` after."""
    step(label)
    t0 = time.perf_counter()
    yield
    timings[key] = time.perf_counter() - t0


def _overridden(profile: Profile, rays, mode, chord_error, normal_error, builds) -> Profile:
    """The profile with the run's overrides of raycheck.rays and .mode, the mirrors' tessellation
    (chord error mm, normal error rad) and tolerancing.builds (None: the profile's own)."""
    if rays is not None:
        profile = replace(profile, raycheck=replace(profile.raycheck, rays=rays))
    if mode is not None:
        profile = replace(profile, raycheck=replace(profile.raycheck, mode=mode))
    if chord_error is not None or normal_error is not None:
        tess = profile.tessellation
        profile = replace(profile, tessellation=replace(
            tess, mirror_chord_error=tess.mirror_chord_error if chord_error is None else chord_error,
            mirror_normal_error=tess.mirror_normal_error if normal_error is None else normal_error))
    if builds is not None:
        profile = replace(profile, tolerancing=replace(profile.tolerancing, builds=builds))
    return profile


def _mesh_optics(rig, profile: Profile, exports: Path | None, override_tess: bool, optics_cache: dict | None):
    """The mirror meshes (the exported PLYs under ``exports``, else meshed at the profile's
    tolerances) and their smooth-normal optics placed as ``rig`` stands, with the seconds spent
    meshing and building the BVHs; kept in ``optics_cache`` by profile, tolerances and exports."""
    key = (profile.name, profile.tessellation.mirror_chord_error, profile.tessellation.mirror_normal_error,
           str(exports))
    cache = optics_cache if optics_cache is not None else {}
    if key not in cache:
        t0 = time.perf_counter()
        tess = profile.tessellation
        meshes = mirror_meshes(rig, exports, tess.mirror_chord_error, tess.mirror_normal_error) \
            if exports is None or override_tess else mirror_meshes(rig, exports)
        t1 = time.perf_counter()
        cache[key] = (meshes, mesh_optics(meshes, "smooth"), t1 - t0, time.perf_counter() - t1)
    meshes, meshed, meshes_s, embree_s = cache[key]
    return meshes, placed_as(meshed, rig), meshes_s, embree_s


def _mesh_figures(meshes) -> dict:
    """Where each mirror mesh came from, its tolerances and triangle counts."""
    return {"sources": meshes.sources(), "tolerances": meshes.tolerances,
            "triangles": {"paraboloid": len(meshes.paraboloid.faces), "dome": len(meshes.dome.faces),
                          "paraboloid_mount": len(meshes.mount.faces), "beam": len(meshes.beam.faces)}}


def _pinhole_readings(analytic: Optics, meshed: Optics | None, src, ddirs, exact: Trace3D, mode: str,
                      rays: int) -> tuple[dict, Trace3D]:
    """Every reading of the pinhole rays ``src`` (see the module docstring), against the exact
    trace ``exact``; and the trace of the reading checked (``mode``). With meshes: the float32 and
    exact-normal readings on the first EXACT_NORMAL_RAYS rays, and each mirror's mesh alone."""
    readings = {"analytic": reading(exact, ddirs, None, src.chief)}
    readings["analytic"]["kernels"] = exact.kernels  # which analytic kernel traced how many rays
    if meshed is None:
        return readings, exact
    main = exact
    for name in ("mesh", "smooth"):
        tr = trace(share_scenes(meshed, name), src.origins, src.dirs)
        readings[name] = reading(tr, ddirs, exact, src.chief)
        readings[name]["kernels"] = tr.kernels  # the compiled mesh passes or the numpy ones
        if name == mode:
            main = tr
    k = min(EXACT_NORMAL_RAYS, rays)
    sub = exact.__class__(*(v[:k] if isinstance(v, np.ndarray) else v
                            for v in (getattr(exact, f) for f in exact.__dataclass_fields__)))
    for name, optics in (("exact_normals", share_scenes(meshed, "exact_normals")),
                         ("mesh_float32", share_scenes(meshed, "mesh", refine=False)),
                         ("smooth_float32", share_scenes(meshed, "smooth", refine=False))):
        tr = trace(optics, src.origins[:k], src.dirs[:k])
        readings[name] = reading(tr, ddirs[:k], sub, src.chief[:k])
        readings[name]["rays_traced"] = k
    for part in ("paraboloid", "dome"):  # which mirror's mesh causes the error
        for name in ("mesh", "smooth"):
            tr = trace(mixed(analytic, share_scenes(meshed, name), part), src.origins, src.dirs)
            r = reading(tr, ddirs, exact, src.chief)
            readings[f"{name}_{part}_mesh_only"] = {k2: r[k2] for k2 in (
                "max_spot_radius_mm", "rms_spot_radius_mm", "mesh_minus_exact_angle_rad")}
    return readings, main


def _pixel_grid(optics: Optics, design: DesignMap, profile: Profile, projector) -> tuple:
    """Every projector pixel of the window around the paraboloid's image traced: the theta map
    (deg) and status map (rows x columns), and their figures."""
    r_out = float(design.pixel_radius(np.array([design.alpha_max]))[0])
    window = 2 * int(math.ceil(r_out)) + 8  # the paraboloid's image and a 4 px margin
    g, (h, w), (r0, c0) = pixel_grid(design, profile.projector.resolution, projector, window=window)
    gt = trace(optics, g.origins, g.dirs)
    theta_map = np.degrees(gt.theta).reshape(h, w)
    status_map = gt.status.reshape(h, w)
    gd = design.direction(g.chief)
    err = _angles(gt.arrival[gt.ok], gd[gt.ok])
    border = np.concatenate([status_map[0], status_map[-1], status_map[:, 0], status_map[:, -1]])
    width, height = profile.projector.resolution
    return theta_map, status_map, {
        "resolution": [width, height], "traced_window_px": [w, h], "window_origin_row_col": [r0, c0],
        "window_border_all_missed": bool(np.all(border == 1)),
        "pixels_total": width * height,
        "pixels_on_paraboloid": int(np.sum(gt.status != 1)),
        "pixels_reaching_sample": int(gt.ok.sum()),
        "pixels_lost": {STATUS_NAMES[k]: int(np.sum(gt.status == k)) for k in STATUS_NAMES if k > 1},
        "max_angle_error_rad": float(np.nanmax(err)) if np.isfinite(err).any() else float("nan"),
        "theta_min_deg": float(np.nanmin(theta_map)), "theta_max_deg": float(np.nanmax(theta_map)),
        "max_spot_radius_mm": float(np.nanmax(gt.miss)),
    }


def _thin_lens(optics: Optics, design: DesignMap, profile: Profile, projector, exact: Trace3D) -> dict:
    """The projector as a thin lens (thesis 3.2.2) focused at the mean source-to-sample path of the
    exact trace: edge rays around THIN_LENS_RAYS chief rays, their offset from the chief (rad) and
    their miss (mm)."""
    rc = profile.raycheck
    k = min(THIN_LENS_RAYS, rc.rays)
    chief = annulus_rays(design, k, rc.seed + 7, projector)
    ctr = trace(optics, chief.origins, chief.dirs)
    focal = float(np.nanmean(exact.path_length))  # thesis 3.2.2: mean source-to-sample path
    edge = thin_lens_rays(chief, focal, profile.projector.aperture, rc.lens_azimuths)
    etr = trace(optics, edge.origins, edge.dirs)
    c_arr = np.repeat(ctr.arrival, rc.lens_azimuths, axis=0)
    both = etr.ok & np.repeat(ctr.ok, rc.lens_azimuths)
    off = _angles(etr.arrival[both], c_arr[both])
    return {
        "aperture_mm": profile.projector.aperture, "focal_distance_mm": focal, "chief_rays": k,
        "edge_rays_per_chief": rc.lens_azimuths,
        "mean_abs_angular_offset_rad": float(off.mean()), "max_abs_angular_offset_rad": float(off.max()),
        "mean_miss_mm": float(np.nanmean(etr.miss)), "max_miss_mm": float(np.nanmax(etr.miss)),
        "edge_rays_lost_fraction": float(1 - etr.ok.mean()),
    }


def _misalignment(optics: Optics, rig, design: DesignMap, profile: Profile) -> dict:
    """The sensitivity of each component's alignment (the profile's probe move and tilt), and the
    figures of each light path under the misalignment the profile declares (None: none declared)."""
    mis, rc, tol = profile.misalignment, profile.raycheck, profile.tolerancing
    sens = montecarlo.sensitivity(optics, rig, design, mis.probe, mis.probe_tilt, tol.rays, rc.seed + 11)
    decl = montecarlo.declared(profile)
    declared_report = None
    if decl != montecarlo.Misalignment.none():
        declared_report = {}
        for device in ("projector", "camera"):
            tr, dd, md = montecarlo.trace_path(optics, rig, design, decl, device, tol.rays, rc.seed + 13)
            declared_report[device + "_path"] = montecarlo.figures(tr, dd, None, md)
    return {"probe_mm": mis.probe, "probe_tilt_rad": mis.probe_tilt, "sensitivity": sens, "declared": declared_report}


def write_raycheck(result: RayCheck, out_dir: Path, lock: Path | None = None,
                   made_from: str | None = None) -> list[Path]:
    """Write raycheck.json, spot.png, theta_map.png into ``out_dir``, published together
    (export.atomic.Staging, under ``lock``); ``made_from``: the SHA-256 of the profile as given
    (export.manifest.profile_digest; ``result.profile`` carries the run's overrides), recorded
    beside the folder. Returns the paths."""
    from rigcad import plots
    from rigcad.export.atomic import Staging, json_bytes

    out_dir = Path(out_dir)
    files = {"raycheck.json": json_bytes(result.report), "spot.png": plots.spot_diagram(result)}
    if result.theta_map is not None:
        files["theta_map.png"] = plots.theta_map(result)
    with Staging(out_dir, lock, made_from=made_from) as stage:
        for name, data in files.items():
            stage.write_bytes(out_dir / name, data)
        return stage.commit()
