"""The design's figures for the optimiser in about a millisecond: the same rig as ``Rig.from_profile``
+ ``run_design``, read off the closed-form dome instead of the certified integration.

Why it is the same dome: the dome that returns every COP ray to O has one optical path length for
every ray (Malus-Dupin; ``optics.dome.equal_path_t``); the DOP853 profile agrees with it to 2e-9 mm
(tests/optics). So the fast path evaluates the closed form t(s) and its exact derivative (the dome
ODE's right-hand side, ``optics.dome.dt_ds``) at Gauss-Legendre nodes in the paraboloid radius s,
from the occlusion limit to the rim, and integrates over them. Its one accuracy knob is ``nodes``:
the quadrature converges spectrally (measured in bench/optimize.py and tests/optimize against the
certified Rig), 48 nodes give the px/deg figures to ~1e-9 relative.

Figures (units in the names): theta range (deg), projector pixels per degree of theta (min, max,
theta-uniform mean and its coefficient of variation), the dome's mirror envelope (mm), its printed
outline (the meridians behind the coating and the wall, the flange) for the printer fit, the wall's
volume and the pixels the mount hides (``occluded_fraction``: the fraction of the projector pixels
of the useful annulus whose light path crosses the beam, clamp or stem boxes: the losses
``rigcad check`` counts in ``raycheck.max_lost_fraction``). Frame: mm, O at the origin, +z; rad inside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from rigcad.errors import GeometryError
from rigcad.optics.design import MIN_THETA_SPAN_DEG, cop_bundle_radius
from rigcad.optics.dome import dt_ds, equal_path_t, occlusion_s, reflected_rays, start
from rigcad.parts.dome import seat_top
from rigcad.parts.layout import flange_extent
from rigcad.parts.paraboloid import clamp_half_width
from rigcad.profile.derived import Derived
from rigcad.profile.schema import Profile

#: Gauss-Legendre nodes in s of the fast path (see the module docstring and bench/optimize.py).
DEFAULT_NODES = 48
#: Points of the printed meridians used for the printer fit (evenly spaced in s; the fit's
#: extents are maxima over them, which converge at second order: 96 points err by < 0.05 mm on
#: the Table 3.1 dome, against the 1 mm bed margin).
OUTLINE_POINTS = 96


@dataclass(frozen=True)
class Outline:
    """The printed dome's meridian section (mm, (r, z) rows): ``outer`` the outside of the wall
    above the flange, ``inner`` the printed mirror surface (behind the coating), and the flange's
    corners; what the printer fit revolves."""

    outer: np.ndarray
    inner: np.ndarray
    flange: np.ndarray
    #: The beam's two seats (rigcad.parts.dome.beam_seats: blocks standing on the plate at the flange's
    #: rim, up to over the beam), as their outer edge (r, z): revolved with the rest, so the printer
    #: fit counts them wherever a sector puts them (it may then miss a fit, never claim a false one).
    seats: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    def points(self) -> np.ndarray:
        return np.concatenate([self.outer, self.inner, self.flange, self.seats])


@dataclass(frozen=True)
class FastDesign:
    """Figures of one design (see the module docstring); ``outline`` for the printer fit."""

    figures: dict
    outline: Outline


@lru_cache(maxsize=8)
def _legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(n)


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = _legendre(n)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def _peak(values: np.ndarray, x: np.ndarray) -> float:
    """Largest value of a smooth sampled function: the parabola through the largest sample and its
    neighbours (second-order sampling error becomes fourth order)."""
    i = int(np.argmax(values))
    if 0 < i < len(values) - 1:
        x0, x1, x2 = x[i - 1], x[i], x[i + 1]
        y0, y1, y2 = values[i - 1], values[i], values[i + 1]
        denom = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / denom
        b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / denom
        if a < 0:
            xv = -b / (2 * a)
            if x0 <= xv <= x2 or x2 <= xv <= x0:
                c = y1 - a * x1 * x1 - b * x1
                return float(a * xv * xv + b * xv + c)
    return float(values[i])


def _dome(geo: Derived, s: np.ndarray, path_length: float):
    """Dome points D (n, 2), dD/ds, theta and dtheta/ds (rad, rad/mm), reflected rays, at radii s."""
    r = reflected_rays(geo, s)
    t = equal_path_t(geo, s, path_length)
    D = r.P + t[:, None] * r.u
    dt = dt_ds(geo, s, t)
    dD = r.dP + dt[:, None] * r.u + t[:, None] * r.du
    rr = np.sum(D * D, axis=-1)
    theta = np.arctan2(D[:, 0], D[:, 1])
    dtheta = (D[:, 1] * dD[:, 0] - D[:, 0] * dD[:, 1]) / rr
    return D, theta, dtheta, r


def _outward(D: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The dome's outward unit normal at D for incoming direction u: the mirror's normal bisects the
    reversed incoming ray and the direction to O, so outward is unit(u - unit(-D))."""
    w = -D / np.linalg.norm(D, axis=-1, keepdims=True)
    n = u - w
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _blocked_quadrant(P: np.ndarray, D: np.ndarray, boxes) -> np.ndarray:
    """Azimuth (rad, within one quadrant) of the directions at each theta whose path P -> D -> O
    crosses one of ``boxes`` ((a, b, z0, z1): |x| <= a, |y| <= b, z0 <= z <= z1, centred on the axis).

    Exact for boxes centred on the axis: a path point at radius r and azimuth phi lies in the box's
    band when |r cos phi| <= a and |r sin phi| <= b, i.e. phi in [acos(a/r), asin(b/r)] (first
    quadrant), an interval that shrinks as r grows; so a segment's crossing of the band blocks the
    interval of its smallest radius there. Returns the length of the union of the intervals, (n,)."""
    box = np.asarray(boxes, float)  # (k, 4): a, b, z0, z1
    a, b, z0, z1 = (box[:, i][None, None, :] for i in range(4))
    A = np.stack([P, np.zeros_like(D)], axis=1)[:, :, None, :]  # (n, 2 segments, 1, 2)
    B = D[:, None, None, :]
    Az, Bz = A[..., 1], B[..., 1]
    dz = Bz - Az
    flat = dz == 0
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (z0 - Az) / dz, (z1 - Az) / dz
    lo = np.where(flat, 0.0, np.clip(np.minimum(ta, tb), 0.0, 1.0))
    hi = np.where(flat, np.where((Az >= z0) & (Az <= z1), 1.0, -1.0), np.clip(np.maximum(ta, tb), 0.0, 1.0))
    Ar, dr = A[..., 0], B[..., 0] - A[..., 0]
    r = np.maximum(np.minimum(Ar + lo * dr, Ar + hi * dr), 1e-12)  # r is linear along the segment
    i_lo = np.arccos(np.minimum(1.0, a / r))
    i_hi = np.arcsin(np.minimum(1.0, b / r))
    ok = (hi > lo) & (i_hi > i_lo)
    lo = np.where(ok, i_lo, 0.0).reshape(len(P), -1)
    hi = np.where(ok, i_hi, 0.0).reshape(len(P), -1)
    order = np.argsort(lo, axis=1)
    lo, hi = np.take_along_axis(lo, order, 1), np.take_along_axis(hi, order, 1)
    total = np.zeros(len(P))
    reach = np.zeros(len(P))  # end of the union swept so far
    for k in range(lo.shape[1]):
        total += np.maximum(hi[:, k] - np.maximum(lo[:, k], reach), 0.0)
        reach = np.maximum(reach, hi[:, k])
    return total


def mount_boxes(profile: Profile, geo: Derived) -> tuple[dict, list[tuple[float, float, float, float]]]:
    """The beam, clamp and stem as (a, b, z0, z1) boxes (mm), placed as ``parts.layout`` and
    ``parts.paraboloid.mount`` place them (a test compares), and the beam's height for the layout's
    rule that it clears the flange."""
    coating = float(sum(t for _, t in profile.coating.layers))
    pm, beam, shell = profile.paraboloid_mount, profile.beam, profile.dome_shell
    rim_z = geo.rim_z - coating * math.sin(geo.tangent_angle)  # the printed rim: behind the coating
    back_z = rim_z - pm.back_thickness
    beam_top = back_z - pm.stem_length
    beam_bottom = beam_top - beam.height
    clamp_top = beam_top + pm.clamp_wall
    half_out = clamp_half_width(profile)  # the clamp's stops and its set screw's wall (parts.paraboloid)
    boxes = [(1e9, beam.width / 2, beam_bottom, beam_top),
             (pm.clamp_length / 2, half_out, beam_bottom, clamp_top),
             (pm.stem_radius, pm.stem_radius, clamp_top, back_z)]
    return {"beam_bottom_z_mm": beam_bottom, "beam_top_z_mm": beam_top, "paraboloid_back_z_mm": back_z}, boxes


def _pixel_radius(geo: Derived, rays, dtheta, n: int):
    """The projector pixel radius rho(s) = f_px s / (cop_z - Pz(s)) at the ``n`` nodes and the two
    ends (px), its derivative d rho / ds (px/mm), and the pixels per degree of theta there."""
    deg = math.pi / 180.0
    sq = rays.s[: n + 2]
    h = geo.cop_z - rays.P[: n + 2, 1]
    rho = geo.projector_focal_px * sq / h
    drho = geo.projector_focal_px * (h - sq * sq / (2 * geo.focal_length)) / (h * h)
    dps = np.abs(drho) / (np.abs(dtheta[: n + 2]) / deg)  # px per degree of theta, at each node
    return rho, drho, dps


def _printed_outline(profile: Profile, Do, u):
    """The printed dome's outline from the design surface ``Do`` (its rays' directions ``u``): the
    surface behind the coating, then the wall, and the flange; with the outer and inner curves, the
    flange's outer radius (mm) and the dome's material volume (mm3: Pappus on the thin wall, plus
    the flange ring)."""
    shell = profile.dome_shell
    coating = float(sum(t for _, t in profile.coating.layers))
    normal = _outward(Do, u)
    inner = Do + coating * normal
    outer = inner + shell.wall * normal
    fl_in = float(np.interp(shell.flange_thickness, outer[:, 1], outer[:, 0])) if outer[0, 1] < shell.flange_thickness \
        else float(outer[0, 0])
    fl_out, _ = flange_extent(fl_in, outer, shell, lambda z: np.interp(z, outer[:, 1], outer[:, 0]))
    outline = Outline(outer=outer[outer[:, 1] >= shell.flange_thickness], inner=inner[inner[:, 1] >= 0.0],
                      flange=np.array([[fl_out, 0.0], [fl_out, shell.flange_thickness], [fl_in, shell.flange_thickness],
                                       [float(np.interp(0.0, inner[:, 1], inner[:, 0])), 0.0]]))
    seg = np.linalg.norm(np.diff(inner, axis=0), axis=-1)
    r_mid = 0.5 * (inner[1:, 0] + inner[:-1, 0]) + 0.5 * shell.wall * 0.5 * (normal[1:, 0] + normal[:-1, 0])
    volume = float(np.sum(2 * math.pi * r_mid * seg * shell.wall)) \
        + math.pi * (fl_out ** 2 - fl_in ** 2) * shell.flange_thickness
    return outline, outer, inner, fl_out, volume


def fast_design(profile: Profile, geo: Derived, nodes: int = DEFAULT_NODES) -> FastDesign:
    """The figures of ``profile`` (geometry ``geo`` from ``derive``); raises GeometryError for the
    impossible rigs ``Rig.from_profile`` and ``run_design`` refuse (a test checks they agree)."""
    if geo.cop_at_infinity:
        raise GeometryError("the optimiser needs a finite COP (projector pixels): give layout.cop_to_vertex a length",
                            where=profile.where("layout", "cop_to_vertex"))
    st = start(geo)  # raises for a rim ray that never reaches the sample plane, or lands inside the rim
    L = st.path_length
    s_end = occlusion_s(geo, L)
    s, w = _gauss(s_end, geo.rim_radius, nodes)
    ends = np.array([s_end, geo.rim_radius])
    so = np.linspace(geo.rim_radius, s_end, OUTLINE_POINTS)  # the outline, from the base up
    n = nodes
    D_all, theta, dtheta, rays = _dome(geo, np.concatenate([s, ends, so]), L)
    D = D_all[: n + 2]
    if not np.all(np.isfinite(D)):
        raise GeometryError("the dome profile is not finite: the paraboloid reflects rays back onto themselves",
                            where=profile.where("paraboloid", "tangent_angle"))
    deg = math.pi / 180.0
    theta_lo, theta_hi = float(theta[n]), float(theta[n + 1])  # at s_end (occlusion limit), at the rim
    span_deg = (theta_hi - theta_lo) / deg
    if span_deg < MIN_THETA_SPAN_DEG:
        raise GeometryError(f"the design measures only {span_deg:.3g} deg of incidence angle",
                            where=profile.where("layout", "sample_to_rim"))
    rho, drho, dps = _pixel_radius(geo, rays, dtheta, n)
    span_px = float(rho[-1] - rho[-2])
    mean = span_px / span_deg  # = the theta-uniform mean of dps (its integral over theta is the pixel span)
    second = float(np.sum(w * dps[:n] ** 2 * np.abs(dtheta[:n]) / deg)) / span_deg
    cv = math.sqrt(max(second - mean * mean, 0.0)) / mean
    Do = D_all[n + 2:]
    outline, outer, inner, fl_out, volume = _printed_outline(profile, Do, rays.u[n + 2:])

    # the mirror envelope (maxima refined between samples) and the top opening
    width = 2.0 * _peak(np.concatenate([Do[:, 0]]), so)
    height = _peak(Do[:, 1], so)
    end = D[n]
    bundle = cop_bundle_radius(geo, float(end[1]), profile.projector.aperture)

    # the pixels the mount hides: pixel-area weights over the annulus, rho drho ds
    info, boxes = mount_boxes(profile, geo)
    outline = replace(outline, seats=np.array([[fl_out, 0.0], [fl_out, seat_top(profile, info["beam_top_z_mm"])]]))
    blocked = 4.0 * _blocked_quadrant(rays.P[:n], D[:n], boxes) / (2 * math.pi)
    area_w = w * rho[:n] * np.abs(drho[:n])
    occluded = float(np.sum(area_w * blocked) / np.sum(area_w))
    solid_w = w * np.sin(theta[:n]) * np.abs(dtheta[:n])
    occluded_sr = float(np.sum(solid_w * blocked) * 2 * math.pi)
    shell = profile.dome_shell

    figures = {
        "theta_min_deg": theta_lo / deg,
        "theta_max_deg": theta_hi / deg,
        "px_per_deg_mean": mean,
        "px_per_deg_cv": cv,
        "px_per_deg_min": float(dps.min()),
        "px_per_deg_max": float(dps.max()),
        "useful_px": span_px,
        "vertex_to_rim_px": geo.pixels_vertex_to_rim,
        "dome_width_mm": width,
        "dome_height_mm": height,
        "dome_outer_width_mm": 2.0 * max(float(outer[:, 0].max()), fl_out),
        "dome_outer_height_mm": float(max(outer[:, 1].max(), inner[:, 1].max())),
        "dome_volume_mm3": volume,
        "cop_z_mm": geo.cop_z,
        "optical_path_mm": L,
        "top_clearance_mm": float(end[0] - bundle),
        "cop_above_dome_mm": float(geo.cop_z - height),
        "beam_above_flange_mm": info["beam_bottom_z_mm"] - shell.flange_thickness,
        "occluded_fraction": occluded,
        "occluded_solid_angle_sr": occluded_sr,
        "focal_length_mm": geo.focal_length,
        "rim_radius_mm": geo.rim_radius,
    }
    return FastDesign(figures, outline)
