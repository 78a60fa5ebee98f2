"""The 2D optical design stage: profile -> paraboloid, dome profile, traced checks, derived figures.

Frame: meridional plane, sample point O at the origin, optical axis +z, lengths in mm, angles in
rad inside (the report states degrees where its key says ``_deg``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError, ProfileError, RigcadError
from rigcad.optics.dome import DomeProfile, build_dome, reflected_rays, start
from rigcad.optics.misalignment import COMPONENT_OFFSETS, Offsets, convergence_error, misaligned_trace, offsets_for
from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.vec import unit
from rigcad.optics.thin_lens import ThinLensResult, thin_lens_check
from rigcad.optics.trace2d import STATUS_NAMES, DomeCurve, Trace, parallel_rays, trace
from rigcad.profile.derived import Derived
from rigcad.profile.schema import Profile
from rigcad.units import DEG


@dataclass(frozen=True)
class Design:
    """Everything the design stage computed. ``report`` is JSON-ready (units in keys)."""

    profile: Profile
    geometry: Derived
    paraboloid: Paraboloid
    dome: DomeProfile
    curve: DomeCurve
    chief_origins: np.ndarray
    chief_dirs: np.ndarray
    aligned: Trace
    thin_lens: ThinLensResult | None
    table: dict[str, np.ndarray]
    report: dict


def chief_rays(geo: Derived, para: Paraboloid, dome: DomeProfile, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` chief rays aimed evenly across the useful annulus of the paraboloid, both sides."""
    half = max(count // 2, 1)
    edges = np.linspace(dome.occlusion_s, geo.rim_radius, half + 1)
    x = 0.5 * (edges[:-1] + edges[1:])
    x = np.concatenate([-x[::-1], x])
    if geo.cop_at_infinity:
        return parallel_rays(x, geo.vertex_z + 1.0)
    cop = np.array([0.0, geo.cop_z])
    return np.tile(cop, (len(x), 1)), unit(para.point(x) - cop)


def cop_bundle_radius(geo: Derived, z: float, aperture: float) -> float:
    """Radius at height z of the bundle of rays from the lens (diameter ``aperture`` at the COP) to the rim."""
    if geo.cop_at_infinity:
        return geo.rim_radius
    frac = (z - geo.rim_z) / (geo.cop_z - geo.rim_z)
    return geo.rim_radius * (1.0 - frac) + 0.5 * aperture * frac


def profile_table(geo: Derived, dome: DomeProfile) -> dict[str, np.ndarray]:
    """Columns of the profile CSV, one row per dome point, units in the names."""
    rays = reflected_rays(geo, dome.s)
    pts = dome.points
    path = rays.source + dome.t + np.linalg.norm(pts, axis=-1)
    if geo.cop_at_infinity:
        pixel = np.full_like(dome.s, np.nan)
        cop_angle = np.zeros_like(dome.s)
    else:
        cop_angle = np.arctan2(dome.s, geo.cop_z - rays.P[:, 1])
        pixel = geo.projector_focal_px * np.tan(cop_angle)
    return {
        "paraboloid_r_mm": dome.s,
        "paraboloid_z_mm": rays.P[:, 1],
        "dome_r_mm": pts[:, 0],
        "dome_z_mm": pts[:, 1],
        "reflected_distance_mm": dome.t,
        "incidence_theta_deg": dome.theta / DEG,
        "cop_angle_deg": cop_angle / DEG,
        "projector_pixel": pixel,
        "optical_path_mm": path,
    }


def _stat(values: np.ndarray) -> dict[str, float]:
    v = values[np.isfinite(values)]
    if v.size == 0:
        return {"min": float("nan"), "max": float("nan")}
    return {"min": float(v.min()), "max": float(v.max())}


#: A smooth dome's curve (quintic spline through its rows) must return the chief rays to O within
#: this fraction of the optical path; rows are doubled until it does (pointed paraboloids need more).
CURVE_MISS_RTOL = 1e-9
MAX_ROWS = 1 << 17
#: The share of the curve's allowance (CURVE_MISS_RTOL x path) an explicit dome.tolerance may take.
TOLERANCE_SHARE = 0.5
#: Doubling the rows must cut the curve's miss below this fraction, or the rows are the limit.
STALL_RATIO = 0.5
#: A design whose incidence angles span less than this is refused: it measures nothing useful.
MIN_THETA_SPAN_DEG = 1.0


def converged_dome(profile: Profile, geo: Derived) -> DomeProfile:
    """The profile's dome, with at least ``dome.table_rows`` rows and as many more (doubling) as its
    smooth curve needs to trace every chief ray to O within CURVE_MISS_RTOL of the optical path."""
    dp = profile.dome
    rows = dp.table_rows
    para = Paraboloid(geo.focal_length, geo.vertex_z, geo.rim_radius)
    if dp.tolerance is not None and dp.method in ("dop853", "rk45"):
        need = TOLERANCE_SHARE * CURVE_MISS_RTOL * start(geo).path_length
        if dp.tolerance > need:  # no number of rows could bring the curve within its requirement
            raise ProfileError(
                f"dome.tolerance = {dp.tolerance:g} mm is looser than this rig's dome can be: its curve must return "
                f"every chief ray to O within {CURVE_MISS_RTOL:g} of the {start(geo).path_length:.0f} mm optical path "
                f"({2 * need:.2g} mm); ask for a tolerance well below that, e.g. {need / 10:.1g} mm, or leave it unset",
                where=profile.where("dome", "tolerance"))
    previous = None
    while True:
        try:
            dome = build_dome(geo, dp.method, tolerance=dp.tolerance, euler_steps=dp.euler_steps, rows=rows)
        except RigcadError as err:
            located = err.located(profile.marks)
            if located is err:
                raise
            raise located from err
        span = float(np.degrees(np.ptp(dome.theta)))
        if span < MIN_THETA_SPAN_DEG:
            raise GeometryError(
                f"the design measures only {span:.3g} deg of incidence angle (theta {np.degrees(dome.theta.min()):.2f}.."
                f"{np.degrees(dome.theta.max()):.2f} deg): the paraboloid's rim is too close to the sample plane or its "
                "rim ray too flat; raise layout.sample_to_rim or lower paraboloid.tangent_angle",
                where=profile.where("layout", "sample_to_rim"))
        if dome.kind != "smooth":
            return dome
        origins, dirs = chief_rays(geo, para, dome, profile.misalignment.rays)
        tr = trace(para, DomeCurve.from_profile(dome), origins, dirs)
        miss = np.abs(tr.miss[tr.ok])
        need = CURVE_MISS_RTOL * dome.path_length
        if not miss.size or miss.max() <= need:
            return dome
        worst = float(miss.max())
        if previous is not None and worst > STALL_RATIO * previous and dp.tolerance is not None:
            # more rows no longer help (a quintic spline's error falls ~32x per doubling): the rows
            # themselves are off by the integrator's tolerance
            raise ProfileError(
                f"dome.tolerance = {dp.tolerance:g} mm leaves the dome's curve {worst:.2g} mm off the sample point "
                f"however many rows it has ({previous:.2g} mm with half as many); the curve needs {need:.2g} mm: ask for "
                f"dome.tolerance <= {dp.tolerance * need / worst / 2:.1g} mm, or leave it unset", where=profile.where("dome", "tolerance"))
        if rows >= MAX_ROWS:
            raise GeometryError(
                f"the dome's curve still misses the sample point by {worst:.2g} mm with {rows} rows: the design "
                "is too close to degenerate to build reliably; change layout.sample_to_rim or paraboloid.tangent_angle",
                where=profile.where("dome", "table_rows"))
        previous = worst
        rows = min(2 * rows - 1, MAX_ROWS)


def profile_entry(profile: Profile) -> dict:
    """The report's ``profile`` entry: its name, the files it came from and every resolved parameter."""
    return {"name": profile.name, "sources": list(profile.sources), "parameters": profile.as_dict()}


def run_design(rig, progress=None) -> Design:
    """Trace and check the 2D design of ``rig`` (a :class:`rigcad.rig.Rig`: its geometry, converged
    dome and curve). Raises GeometryError for an impossible rig."""
    step = progress or (lambda label: None)
    profile, geo, para, dome, curve = rig.profile, rig.geometry, rig.paraboloid, rig.dome, rig.curve
    aperture = profile.projector.aperture
    top_aperture = _top_aperture(profile, geo, dome)

    step("chief rays")
    origins, dirs = chief_rays(geo, para, dome, profile.misalignment.rays)
    aligned = trace(para, curve, origins, dirs)
    if not aligned.ok.any():
        lost = {STATUS_NAMES[k]: int(np.sum(aligned.status == k)) for k in STATUS_NAMES if k}
        raise GeometryError(f"no chief ray of the design returns to the sample point ({lost}): check the layout "
                            "(layout.sample_to_rim, layout.cop_to_vertex) and the paraboloid's size",
                            where=profile.where("layout", "sample_to_rim"))

    step("thin lens")
    lens = None
    if not geo.cop_at_infinity and aperture > 0:
        lens = thin_lens_check(para, curve, np.array([0.0, geo.cop_z]), dirs, aperture)

    step("misalignment")
    misalignment = _misalignment(profile, para, curve, origins, dirs, aligned)
    table = profile_table(geo, dome)
    report = {
        "profile": profile_entry(profile),
        "frame": "meridional plane; sample point O at the origin; optical axis +z; lengths mm",
        "paraboloid": geo.as_dict(),
        "dome": {
            "method": dome.method,
            "kind": dome.kind,
            "tolerance_mm": dome.tolerance,
            "points": int(len(dome.s)),
            "error_estimate_mm": dome.error_estimate,
            "error_vs_equal_path_mm": dome.error_vs_equal_path,
            "stats": dome.stats,
            "start_r_mm": float(dome.points[0, 0]),
            "end_paraboloid_r_mm": dome.occlusion_s,
        },
        "measurable_range": _measurable_range(profile, geo, dome),
        "envelope": {
            "width_mm": float(2 * dome.points[:, 0].max()),
            "height_mm": float(dome.points[:, 1].max()),
            "base_radius_mm": float(dome.points[0, 0]),
            "width_in": float(2 * dome.points[:, 0].max() / 25.4),
            "height_in": float(dome.points[:, 1].max() / 25.4),
            "note": "mirror (design) surface; the printed part adds coating and wall",
        },
        "top_aperture": top_aperture,
        "paths": _paths(dome, table, aligned),
        "pixels": _pixels(profile, geo, dome, table),
        "convergence": _convergence(aligned),
        "thin_lens": None if lens is None else lens.summary(),
        "misalignment": misalignment,
    }
    return Design(profile, geo, para, dome, curve, origins, dirs, aligned, lens, table, report)


def _top_aperture(profile: Profile, geo: Derived, dome: DomeProfile) -> dict:
    """The dome's top opening (it ends at the occlusion limit) and its clearance (mm) around the
    projector's ray bundle there. Raises GeometryError when the bundle would be cut or the centre
    of projection lies inside the dome."""
    top = dome.points[np.argmax(dome.points[:, 1])]
    end = dome.points[-1]
    bundle = cop_bundle_radius(geo, float(end[1]), profile.projector.aperture)
    clearance = float(end[0] - bundle)
    if clearance <= 0:
        raise GeometryError(
            f"the dome's top opening (radius {end[0]:.2f} mm at z = {end[1]:.1f} mm) would cut the projector's "
            f"ray bundle (radius {bundle:.2f} mm there): increase layout.cop_to_vertex",
            where=profile.where("layout", "cop_to_vertex"))
    if not geo.cop_at_infinity and geo.cop_z <= top[1]:
        raise GeometryError(
            f"the centre of projection (z = {geo.cop_z:.1f} mm) lies inside the dome (top at {top[1]:.1f} mm): "
            "increase layout.cop_to_vertex", where=profile.where("layout", "cop_to_vertex"))
    return {"radius_mm": float(end[0]), "z_mm": float(end[1]), "projector_bundle_radius_mm": bundle,
            "clearance_mm": clearance}


def _misalignment(profile: Profile, para: Paraboloid, curve: DomeCurve, origins, dirs, aligned: Trace) -> dict:
    """How far the chief rays miss O when each component moves by the profile's probe offset, and
    under the offsets the profile declares for each light path (mm)."""
    mis = profile.misalignment
    cache: dict[Offsets, dict] = {}

    def case(off: Offsets) -> dict:
        if off not in cache:
            cache[off] = convergence_error(misaligned_trace(para, curve, origins, dirs, off), aligned)
        return cache[off]

    sensitivity = {name: case(offsets_for(name, mis.probe)) for name in COMPONENT_OFFSETS}
    declared = {}
    for device in ("projector", "camera"):
        off = Offsets(cop_dx=getattr(mis, f"{device}_dx"), cop_dz=getattr(mis, f"{device}_dz"),
                      paraboloid_dx=mis.paraboloid_dx, dome_dx=mis.dome_dx)
        if off != Offsets():
            declared[device + "_path"] = case(off)
    return {"probe_mm": mis.probe,
            "note": "camera and projector share the COP: a pinhole offset of either moves the same rays",
            "sensitivity": sensitivity, "declared": declared}


def _measurable_range(profile: Profile, geo: Derived, dome: DomeProfile) -> dict:
    """The incidence angles the dome covers against the profile's targets (deg)."""
    theta_min, theta_max = float(dome.theta.min()), float(dome.theta.max())
    tg = profile.targets
    # A design "reaches" 90 deg when its first ray is grazing to float precision.
    covers = theta_min <= tg.theta_min + 1e-12 and theta_max >= tg.theta_max - 1e-9
    return {"theta_min_deg": theta_min / DEG, "theta_max_deg": theta_max / DEG,
            "occlusion_theta_deg": geo.occlusion_theta / DEG,
            "target_theta_min_deg": tg.theta_min / DEG, "target_theta_max_deg": tg.theta_max / DEG,
            "targets_met": bool(covers)}


def _paths(dome: DomeProfile, table: dict, aligned: Trace) -> dict:
    """The optical path (mm): the design's, the chief rays' spread, and its three legs."""
    ok = aligned.ok
    return {
        "optical_path_mm": dome.path_length,
        "chief_ray_path_spread_mm": float(np.ptp(aligned.path_length[ok])) if ok.any() else None,
        "cop_to_paraboloid_mm": _stat(table["optical_path_mm"] - dome.t - np.linalg.norm(dome.points, axis=-1)),
        "paraboloid_to_dome_mm": _stat(dome.t),
        "dome_to_sample_mm": _stat(np.linalg.norm(dome.points, axis=-1)),
    }


def _pixels(profile: Profile, geo: Derived, dome: DomeProfile, table: dict) -> dict:
    """The projector's pixels over the measurable range: useful pixels and pixels per degree of
    incidence angle (None with the centre of projection at infinity)."""
    theta = dome.theta
    pixels = table["projector_pixel"]
    far = geo.cop_at_infinity
    dpix = np.abs(np.gradient(pixels, theta / DEG)) if not far else np.full_like(theta, np.nan)
    span_deg = (float(theta.max()) - float(theta.min())) / DEG
    return {
        "projector_resolution": list(profile.projector.resolution),
        "projector_focal_px": geo.projector_focal_px,
        "vertex_to_rim_px": None if far else geo.pixels_vertex_to_rim,
        "useful_px": None if far else float(pixels.max() - pixels.min()),
        "px_per_deg_mean": None if far else float((pixels.max() - pixels.min()) / span_deg),
        "px_per_deg_min": None if far else float(dpix.min()),
        "px_per_deg_max": None if far else float(dpix.max()),
    }


def _convergence(aligned: Trace) -> dict:
    """How the chief rays return to O: counts, losses by cause, and the miss (mm)."""
    ok = aligned.ok
    return {
        "rays": int(len(aligned.status)),
        "rays_ok": int(ok.sum()),
        "rays_lost": {STATUS_NAMES[k]: int(np.sum(aligned.status == k)) for k in STATUS_NAMES if k},
        "rms_miss_mm": float(np.sqrt(np.mean(aligned.miss[ok] ** 2))) if ok.any() else None,
        "max_miss_mm": float(np.abs(aligned.miss[ok]).max()) if ok.any() else None,
        "note": "miss = distance from O to each returning ray (2D trace against the smooth curve or polyline)",
    }
