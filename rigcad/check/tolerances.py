"""The tolerances the 3D ray check enforces: each a named profile key with its unit, the measured
value it is compared with, and on failure a message that names the key, its file:line and what
to change. :func:`evaluate` builds the table; :func:`raise_if_failed` turns failures into one
CheckError.

Internal numerical tolerances of the checker (not profile keys) are module constants beside the
code that uses them, each with its reason (rays.py, scene.py, raycheck.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import CheckError
from rigcad.units import DEG


@dataclass(frozen=True)
class Row:
    """One line of the check table. ``unit`` is mm, deg, px/deg or '' (fractions)."""

    name: str
    key: str
    measured: float
    limit: float
    relation: str  # "<=" or ">="
    unit: str
    where: str | None
    hint: str = ""

    @property
    def ok(self) -> bool:
        if not math.isfinite(self.measured):
            return False
        return self.measured <= self.limit if self.relation == "<=" else self.measured >= self.limit

    def as_dict(self) -> dict:
        return {"check": self.name, "profile_key": self.key, "measured": self.measured, "limit": self.limit,
                "relation": self.relation, "unit": self.unit, "where": self.where, "ok": self.ok,
                **({"hint": self.hint} if not self.ok and self.hint else {})}


def evaluate(profile, report: dict) -> list[Row]:
    """The table for a run_raycheck report."""
    rc, tg, tol, tess = profile.raycheck, profile.targets, profile.tolerancing, profile.tessellation
    w = profile.where
    r = report["readings"]
    main = r[rc.mode]
    tess_where = ", ".join(x for x in (w("tessellation", "mirror_chord_error"), w("tessellation", "mirror_normal_error")) if x) or "default"
    tess_hint = (f"mirror meshes at tessellation.mirror_chord_error {tess.mirror_chord_error:g} mm / "
                 f"mirror_normal_error {tess.mirror_normal_error:g} rad ({tess_where})")
    rows = [
        Row("spot radius (pinhole, max)", "raycheck.max_spot_radius", main["max_spot_radius_mm"], rc.max_spot_radius,
            "<=", "mm", w("raycheck", "max_spot_radius"),
            f"reading {rc.mode}; " + (tess_hint + ": tighten them" if rc.mode != "analytic" else "the design itself")),
        Row("angle error vs design (pinhole, max)", "raycheck.max_angle_error", main["max_angle_error_rad"] / DEG,
            rc.max_angle_error / DEG, "<=", "deg", w("raycheck", "max_angle_error"), f"reading {rc.mode}"),
    ]
    if "mesh" in r:
        rows.append(Row("spot radius, flat facets (STL-literal, max)", "raycheck.max_facet_spot_radius",
                        r["mesh"]["max_spot_radius_mm"], rc.max_facet_spot_radius, "<=", "mm",
                        w("raycheck", "max_facet_spot_radius"), tess_hint + ": tighten mirror_normal_error"))
    if rc.mode in ("mesh", "smooth"):
        e = main["mesh_minus_exact_angle_rad"]["max"]
        parts = {p: r[f"{rc.mode}_{p}_mesh_only"]["mesh_minus_exact_angle_rad"]["max"] for p in ("paraboloid", "dome")}
        worst = max(parts, key=parts.get)
        rows.append(Row("mesh minus exact angle error (max)", "raycheck.max_mesh_angle_error", e / DEG,
                        rc.max_mesh_angle_error / DEG, "<=", "deg", w("raycheck", "max_mesh_angle_error"),
                        f"{tess_hint}; the {worst} mesh alone gives {parts[worst] / DEG:.3g} deg: tighten "
                        "tessellation.mirror_normal_error and mirror_chord_error"))
    th_lo, th_hi = main["theta_min_deg"], main["theta_max_deg"]
    # measured: the traced end of the range itself; limit: the target widened by the coverage tolerance
    cov = rc.theta_coverage_tolerance / DEG
    rows.append(Row(f"smallest theta traced (targets.theta_min {tg.theta_min / DEG:g} + {cov:g})",
                    "raycheck.theta_coverage_tolerance", th_lo, tg.theta_min / DEG + cov, "<=", "deg",
                    w("raycheck", "theta_coverage_tolerance"),
                    f"traced theta from {th_lo:.2f} deg; targets.theta_min {tg.theta_min / DEG:g} deg"))
    rows.append(Row(f"largest theta traced (targets.theta_max {tg.theta_max / DEG:g} - {cov:g})",
                    "raycheck.theta_coverage_tolerance", th_hi, tg.theta_max / DEG - cov, ">=", "deg",
                    w("raycheck", "theta_coverage_tolerance"),
                    f"traced theta up to {th_hi:.2f} deg; targets.theta_max {tg.theta_max / DEG:g} deg"))
    if "design_range" in report:
        rows += theta_range_rows(profile, report["design_range"])
    rows.append(px_per_deg_row(profile, report["pixels_per_degree"]["px_per_deg_min"]))
    rows.append(Row("rays lost (occluded, escaped)", "raycheck.max_lost_fraction", main["lost_fraction"],
                    rc.max_lost_fraction, "<=", "", w("raycheck", "max_lost_fraction"),
                    "see readings.<mode>.losses for where; the beam's width sets most of it"))
    if report.get("camera"):
        rows += camera_rows(profile, report["camera"])
    tower = report.get("tower")
    if tower is not None:
        cam = tower["camera_through_splitter"]
        bs_where = w("beam_splitter", "thickness")
        rows.append(Row("camera via splitter: spot radius (max)", "raycheck.max_spot_radius",
                        cam["max_spot_radius_mm"], rc.max_spot_radius, "<=", "mm", w("raycheck", "max_spot_radius"),
                        f"the plate's astigmatism (beam_splitter.thickness, {bs_where or 'default'}): a thinner plate"))
        rows.append(Row("camera via splitter: angle error, calibrated (max)", "raycheck.max_angle_error",
                        cam["max_mirror_angle_error_rad"] / DEG, rc.max_angle_error / DEG, "<=", "deg",
                        w("raycheck", "max_angle_error"),
                        f"against the paraboloid point each camera ray meets (thesis 4.1.1); uncalibrated "
                        f"{cam['max_angle_error_rad'] / DEG:.3g} deg; a thinner beam_splitter.thickness"))
        bc = tower["bundle_clearance"]
        blocked = bc["projector"]["blocked"] + bc["projector_widened"]["blocked"] + bc["camera"]["blocked"]
        who = sorted({n for k in ("projector", "projector_widened", "camera") for n in bc[k]["blocked_by"]})
        rows.append(Row("tower parts in the ray bundles (rays)", "tower.clearance", float(blocked),
                        0.0, "<=", "", w("tower", "clearance"),
                        f"blocked by {', '.join(who)}: move them or raise tower.splitter_distance"))
    mc = report.get("monte_carlo")
    if mc is not None:
        rows.append(Row("Monte Carlo yield (spot and mirror angle targets)", "tolerancing.min_yield", mc["yield"],
                        tol.min_yield, ">=", "", w("tolerancing", "min_yield"),
                        f"p90 spot {mc['max_spot_radius_mm']['p90']:.3g} mm, p90 angle "
                        f"{mc['max_mirror_angle_error_rad']['p90'] / DEG:.3g} deg: tighten the tolerancing.* placements"))
    return rows


#: Slack (rad) of the design's theta range against the targets: a design "reaches" 90 deg when its
#: first ray is grazing to float precision (rigcad.optics.design's measurable range uses the same).
THETA_RANGE_SLACK = 1e-9


def theta_range_rows(profile, rng: dict) -> list[Row]:
    """The design's theta range (``rng``: the design report's ``measurable_range``, deg: the 2D
    design's exact range, what `rigcad design` reports) against ``targets.theta_min/theta_max``,
    within THETA_RANGE_SLACK only: the range is the design's own, not a sample of rays."""
    tg, w = profile.targets, profile.where
    lo, hi = rng["theta_min_deg"], rng["theta_max_deg"]
    slack = THETA_RANGE_SLACK / DEG
    return [
        Row("design's smallest theta", "targets.theta_min", lo,
            tg.theta_min / DEG + slack, "<=", "deg", w("targets", "theta_min"),
            f"the paraboloid's own shadow on the sample starts at {lo:.3g} deg (atan of its rim radius over "
            f"layout.sample_to_rim): raise layout.sample_to_rim or take a smaller paraboloid; targets.theta_min "
            f">= {_up(lo, 2)} deg would pass"),
        Row("design's largest theta", "targets.theta_max", hi,
            tg.theta_max / DEG - slack, ">=", "deg", w("targets", "theta_max"),
            f"the dome's rim ends the range at {hi:.3g} deg: a dome reaching lower (layout); targets.theta_max "
            f"<= {_down(hi, 2)} deg would pass"),
    ]


def px_per_deg_row(profile, px_per_deg_min: float) -> Row:
    """The projector's fewest pixels per degree of theta (the check's fan) against raycheck.min_px_per_deg."""
    return Row("pixels per degree (min along theta)", "raycheck.min_px_per_deg", px_per_deg_min,
               profile.raycheck.min_px_per_deg, ">=", "px/deg", profile.where("raycheck", "min_px_per_deg"),
               "projector.throw_ratio (a longer throw), projector.resolution or the paraboloid's size set it; "
               f"raycheck.min_px_per_deg <= {_down(px_per_deg_min, 3)} would pass")


def _up(value: float, digits: int) -> str:
    """``value`` rounded up at ``digits`` decimals (a bound that passes, shown short)."""
    return f"{math.ceil(value * 10 ** digits) / 10 ** digits:g}" if math.isfinite(value) else "nan"


def _down(value: float, digits: int) -> str:
    """``value`` rounded down at ``digits`` decimals."""
    return f"{math.floor(value * 10 ** digits) / 10 ** digits:g}" if math.isfinite(value) else "nan"


def camera_rows(profile, cam: dict) -> list[Row]:
    """The camera's rows from its model in the report (``report["camera"]``:
    rigcad.optics.camera.CameraModel.as_dict, closed forms on the profile's lens): how much of the
    sensor the paraboloid's image fills, and whether it is all on the sensor (the rim's image radius
    over the room from the principal point to the nearest edge, at most 1); with a known closest
    focus (camera.min_working_distance), whether the lens focuses on the paraboloid."""
    from rigcad.optics.camera import DEFAULT_FILL

    w = profile.where
    radius, short = cam["paraboloid_image_radius_px"], min(cam["resolution_px"])
    f_mm, f_px = cam["focal_length_mm"], cam["focal_length_px"]
    lens = (f"the {f_mm:.4g} mm lens" if f_mm is not None else f"the {f_px:.0f} px lens") + f" ({cam['focal_from']})"
    fill_px = f_px * DEFAULT_FILL / cam["paraboloid_image_fill_of_short_side"]  # r is linear in f
    fill = f"{fill_px * cam['pixel_pitch_mm']:.3g} mm" if cam["pixel_pitch_mm"] else f"{fill_px:.0f} px"
    rows = [Row(f"camera: paraboloid image {2 * radius:.0f} px, {cam['paraboloid_image_fill_of_short_side']:.0%} of "
                f"{short} px", "camera.focal_length", cam["reach_over_room"], 1.0, "<=", "",
                w("camera", "focal_length") or w("camera", "lens"),
                f"{lens} puts the rim {radius:.0f} px from the principal point, {radius / cam['reach_over_room']:g} px "
                f"from the sensor's nearest edge: {fill}, a {'shorter' if fill_px < f_px else 'longer'} "
                f"camera.focal_length, fills {DEFAULT_FILL:.0%}")]
    if cam["min_working_distance_mm"] is not None:
        rows.append(Row("camera: lens front to vertex vs closest focus", "camera.min_working_distance",
                        cam["working_distance_mm"], cam["min_working_distance_mm"], ">=", "mm",
                        w("camera", "min_working_distance"),
                        "the lens cannot focus this close: a lens with a shorter closest focus, or a close-up "
                        "ring / extension tube (then camera.min_working_distance is the combination's)"))
    return rows


def table(rows: list[Row]) -> str:
    """A readable fixed-width table of the rows."""
    lines = [f"{'check':<50} {'measured':>12} {'':2} {'limit':>10} {'unit':<7} {'':4}"]
    for row in rows:
        lines.append(f"{row.name:<50} {row.measured:>12.4g} {row.relation:2} {row.limit:>10.4g} {row.unit:<7} "
                     f"{'ok' if row.ok else 'FAIL'}")
    return "\n".join(lines)


def raise_if_failed(rows: list[Row], profile_name: str) -> None:
    """CheckError listing every failed row: key, file:line, measured vs limit, hint."""
    failed = [r for r in rows if not r.ok]
    if not failed:
        return
    parts = [f"{r.key} ({r.where or 'default'}): {r.name} {r.measured:.4g} {r.unit} not {r.relation} "
             f"{r.limit:.4g} {r.unit}; {r.hint}" for r in failed]
    raise CheckError(f"{profile_name}: {len(failed)} ray-check tolerance(s) not met: " + " | ".join(parts))
