"""The zonal basis as the rig's projector shows it (thesis 3.3 and 4.2.1): one image per basis
function, from the rig's own map of projector pixels to incidence directions.

This module wires a :class:`rigcad.rig.Rig` to the pure maths of rigcad.basis (zonal.py and gram.py
work on plain arrays and know nothing of the rig): it may import the rig's stages (optics, check);
the pure modules may not import it (tests/basis/test_independence.py).

Frame and units: mm, the sample point O at the origin, optical axis +z; incidence directions
(theta, phi) in the sample's frame (normal +z, tangent +x), radians; solid angles in sr; basis
values in 1/sqrt(sr). Errors are :class:`rigcad.errors.BasisError`.

Pixels (rigcad.optics.incidence): pixel (column i, row j) of a W x H image has its centre at
x = i + 0.5 - W/2, y = H/2 - j - 0.5 px; its pinhole ray leaves the centre of projection (COP) at
the angle a = atan(r / f) from the axis (r = hypot(x, y), f the focal length in px) and at the
azimuth psi = atan2(y, x); the design brings it to O from theta = T(a) (T: the design's quintic
spline through its profile table), phi = psi. The projector is seen through its focusing lens,
which the tower places so that the paraboloid sees its COP at the design COP: its f is the lensed
one (rigcad.optics.focus.lensed_focal_px, x 1.0757 for Table 3.1), not the bare projector's
W x throw_ratio. A measured calibration circle (:class:`MeasuredCircle`) moves the image centre to
the circle's and scales f so the rim falls on the circle's radius.

Solid angle of a pixel (the map's Jacobian): d omega = sin(theta) d theta d phi, with
d theta = T'(a) da, da = f / (f^2 + r^2) dr, d phi = d psi and dx dy = r dr d psi, so

    d omega = J(x, y) dx dy,    J = sin(T(a)) |T'(a)| f / ((f^2 + r^2) r)    [sr per px^2].

A pixel's design solid angle is J at its centre (midpoint rule: second order inside the annulus;
at the zone's two edges pixels lie partly outside, a first-order error, measured by
:func:`solid_angle_check` against the closed form 2 pi (cos alpha - cos beta)).

Which pixels light the sample is the rig's own truth: every pixel centre is traced through the
exact surfaces and the occluders its part recipes declare (``check.scene.analytic_optics`` and
``check.trace3d.trace``). A pixel is *lit* when its centre ray reaches O and its design direction
lies in the zone; every other pixel is black (off the paraboloid, out through the dome's top,
behind the beam or the paraboloid's mount, or outside the zone), except on edges: a pixel beside a
pixel of the other kind (the beam's edges, the rim, the occlusion limit) is traced at
SUPERSAMPLE x SUPERSAMPLE sub-pixel points, and if any part of it reaches O from the zone it is lit
with Z at the mean direction of that part and that part's solid angle (the J-weighted sum over its
sub-points). Elsewhere a pixel is wholly lit or dark (every occluder is many pixels wide). These
solid angles weigh the discrete inner product (Gram matrix) and the simulated acquisition
(rigcad.basis.acquire).

Zone: alpha = the map's incidence angle at its inner edge (the occlusion limit; the design
report's ``measurable_range.theta_min_deg``, 6.92 deg for Table 3.1, where thesis 3.3 used 9 deg),
beta = 90 deg.

Preprocessing (thesis 4.2.1, :func:`rigcad.basis.gram.quantise_images`): one scale for all images
of a set (its largest |value|), positive and negative parts as separate images, 8 and 16 bit,
rounded to nearest. The latitude-longitude maps of 4.2.1 are the same functions on a theta x phi
grid of cell centres over the zone (row 0 next to the normal, column 0 at phi = 0).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from rigcad.basis.gram import (IlluminationSampling, QuantisedImages, Reorthonormalised, basis_images, gram,
                               off_identity, quantise_images, reorthonormalise)
from rigcad.basis.zonal import Zone, basis_indices, check_order, direction_angles, zonal_basis
from rigcad.errors import BasisError
from rigcad.optics.incidence import camera_focal_px, camera_principal_point  # noqa: F401  (camera_focal_px named
# here too: the basis's callers import it from here)

#: Sub-points per side of a pixel on an edge (its lit part in steps of 1/16): the error of the lit
#: part's solid angle is then ~1/8 of a pixel row along the edges.
SUPERSAMPLE = 4
#: Pixels traced beyond the rim's image on every side; the report checks that they all miss the
#: paraboloid (so that the window holds every pixel that can light the sample).
WINDOW_MARGIN_PX = 4
#: Highest order accepted: the zonal basis is verified orthonormal to this order (docs/basis.md), and
#: it already means 169 functions, 676 projector images.
MAX_ORDER = 12
#: Orders whose Gram figures basis.json always reports (thesis 3.3.1: 4 for matte, up to 6 for specular).
GRAM_ORDERS = (2, 4, 6)
#: Cell of the latitude-longitude maps (deg): finer than the rig's ~1 pixel per degree (thesis 3.2.1).
LATLONG_STEP_DEG = 1.0
#: Image depths written (thesis 4.2.1 used 8 bit).
BITS = (8, 16)
DEVICES = ("projector", "camera")
#: Stages :func:`projector_basis` reports to its ``progress`` callback.
BASIS_STEPS = 5

Progress = Callable[[str], None] | None


def progress_step(progress: Progress) -> Callable[[str], None]:
    """``progress`` itself, or a callback that does nothing (the stages call it after each step)."""
    return progress or (lambda label: None)


# -- the zone and the device maps --------------------------------------------------------------------
def zone_of(rig, alpha_rad: float | None = None) -> Zone:
    """The measurable zone of ``rig``: alpha = the incidence map's angle at its inner edge (the
    occlusion limit) unless ``alpha_rad`` is given, beta = pi/2. ``alpha_rad`` must lie between the
    occlusion limit and pi/2: below it no pixel reaches the sample."""
    m = rig.incidence
    lowest = float(m.spline(m.alpha_min))
    if alpha_rad is None:
        return Zone(lowest, math.pi / 2)
    a = float(alpha_rad)
    if not (math.isfinite(a) and lowest - 1e-12 <= a < math.pi / 2):
        raise BasisError(f"zone alpha_rad = {alpha_rad!r} ({math.degrees(a):.4g} deg): need {lowest:.6g} <= "
                         f"alpha_rad < pi/2 ({math.degrees(lowest):.4g} deg is the rig's occlusion limit, the "
                         "lowest incidence angle its pixels reach)", param="basis.alpha")
    return Zone(max(a, lowest), math.pi / 2)


def device_map(rig, device: str, focal_px: float | None = None):
    """The design's incidence map (:class:`rigcad.optics.incidence.DesignMap`) read in ``device``'s
    pixels: the projector's through its focusing lens (rigcad.optics.focus.lensed_focal_px), or the
    camera's (same COP and map, :func:`camera_focal_px`)."""
    from rigcad.optics.focus import lensed_focal_px

    if device not in DEVICES:
        raise BasisError(f"device {device!r}: need one of {', '.join(DEVICES)}")
    m = rig.incidence
    if focal_px is None and device == "projector":
        return dataclasses.replace(m, focal_px=lensed_focal_px(rig.profile, rig.geometry))
    f = float(focal_px) if focal_px is not None else camera_focal_px(rig)
    if not (math.isfinite(f) and f > 0):
        raise BasisError(f"{device} focal_px = {focal_px!r}: need a positive focal length in pixels")
    return dataclasses.replace(m, focal_px=f)


def pixel_jacobian(design, x_px: np.ndarray, y_px: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(J, inside): the solid angle per px^2 (sr) of the map at image points (x, y) px (module
    docstring), and whether each lies in the map's annulus (J = 0 outside)."""
    x, y = np.asarray(x_px, float), np.asarray(y_px, float)
    f = design.focal_px
    r = np.hypot(x, y)
    a = np.arctan2(r, f)
    inside = (a >= design.alpha_min) & (a <= design.alpha_max)
    ac = np.clip(a, design.alpha_min, design.alpha_max)
    theta = design.spline(ac)
    dtheta = design.spline.derivative()(ac)
    with np.errstate(divide="ignore", invalid="ignore"):
        J = np.sin(theta) * np.abs(dtheta) * f / ((f * f + r * r) * r)
    return np.where(inside, J, 0.0), inside


# -- tracing a device's pixels -------------------------------------------------------------------------
@dataclass(frozen=True)
class PixelMap:
    """A device's pixels through one rig, every ``stride``-th row and column of a centred window
    that holds the paraboloid's image. Per traced pixel (arrays (n,) or (n, 3), row-major over the
    traced grid ``shape``): image ``row``/``col``, centre ``x_px``/``y_px``, the design arrival
    direction ``design_dirs`` (unit, from O towards the light; NaN outside the map's annulus), the
    design solid angle ``jacobian_sr`` (J x 1 px^2; 0 outside), the trace3d ``status`` of the centre
    ray and its traced ``arrival`` direction (NaN where lost). ``as_built``: traced where the rig's
    components stand (a moved rig); otherwise at their design poses. ``focal_px``: the device's
    focal length in its pixels."""

    device: str
    as_built: bool
    focal_px: float
    resolution: tuple[int, int]
    window: tuple[int, int, int, int]
    stride: int
    shape: tuple[int, int]
    row: np.ndarray
    col: np.ndarray
    x_px: np.ndarray
    y_px: np.ndarray
    design_dirs: np.ndarray
    jacobian_sr: np.ndarray
    status: np.ndarray
    arrival: np.ndarray
    #: where the optical axis meets the image (x, y px from its top-left corner): x_px, y_px are from it
    centre: tuple[float, float] | None = None

    @property
    def size(self) -> int:
        return int(self.x_px.size)

    @property
    def ok(self) -> np.ndarray:
        """Centre rays that reach O."""
        from rigcad.check.result import OK

        return self.status == OK

    def design_angles(self) -> tuple[np.ndarray, np.ndarray]:
        """Design (theta_rad, phi_rad) per pixel (NaN outside the annulus)."""
        return direction_angles(self.design_dirs)

    def in_zone(self, zone: Zone) -> np.ndarray:
        """Pixels whose design direction lies in ``zone`` (edges included)."""
        theta, _ = self.design_angles()
        with np.errstate(invalid="ignore"):
            return np.isfinite(theta) & zone.contains(np.nan_to_num(theta, nan=-1.0))

    def border_all_missed(self) -> bool:
        """Every pixel on the traced window's border misses the paraboloid (the window is big enough)."""
        from rigcad.check.result import MISSED_PARABOLOID

        s = self.status.reshape(self.shape)
        border = np.concatenate([s[0], s[-1], s[:, 0], s[:, -1]])
        return bool(np.all(border == MISSED_PARABOLOID))


def _optics(rig, as_built: bool):
    """The rig's exact surfaces and occluders, at the rig's poses (as built) or the design's."""
    from rigcad.check.scene import analytic_optics

    optics = analytic_optics(rig)
    return optics if as_built else optics.placed()


def trace_pixels(rig, device: str = "projector", *, as_built: bool = False, stride: int = 1,
                 focal_px: float | None = None, optics=None, centre: tuple[float, float] | None = None) -> PixelMap:
    """Trace ``device``'s pixel centres through ``rig`` (see :class:`PixelMap`); ``optics``: the
    analytic optics to reuse (placed as ``as_built`` asks); ``centre``: where the optical axis meets
    the image (px from its top-left; default the camera's principal point, the projector's lens axis,
    rigcad.profile.derived.projector_principal_point; a measured calibration circle's centre, rigcad.basis.measured)."""
    from rigcad.check.sources import pixel_rays
    from rigcad.check.trace3d import trace
    from rigcad.profile.derived import projector_principal_point

    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise BasisError(f"pixel stride = {stride!r}: need an integer >= 1 (1 traces every pixel)")
    design = device_map(rig, device, focal_px)
    resolution = tuple(getattr(rig.profile, device).resolution)
    width, height = resolution
    r_out = float(design.pixel_radius(np.array([design.alpha_max]))[0])
    side = 2 * math.ceil(r_out) + 2 * WINDOW_MARGIN_PX
    w, h = min(width, side), min(height, side)
    # about the device's principal point (the camera's lens may move it; the projector's lens offset moves
    # its own below the image's centre), kept on the device ((W - w) // 2 for the centre)
    cx, cy = (centre if centre is not None else camera_principal_point(rig) if device == "camera"
              else projector_principal_point(rig.profile.projector))
    c0 = min(max(math.floor(cx - w / 2), 0), width - w)
    r0 = min(max(math.floor(cy - h / 2), 0), height - h)
    rows = np.arange(r0 + stride // 2, r0 + h, stride)
    cols = np.arange(c0 + stride // 2, c0 + w, stride)
    jj, ii = np.meshgrid(rows, cols, indexing="ij")
    row, col = jj.ravel(), ii.ravel()
    x = col + 0.5 - cx
    y = cy - row - 0.5
    rays = pixel_rays(design, x, y, rig.pose(device) if as_built else None)
    tr = trace(optics if optics is not None else _optics(rig, as_built), rays.origins, rays.dirs)
    J, _ = pixel_jacobian(design, x, y)
    return PixelMap(device, as_built, float(design.focal_px), resolution, (int(r0), int(c0), int(h), int(w)), int(stride),
                    (len(rows), len(cols)), row, col, x, y, design.direction(rays.chief), J, tr.status,
                    np.where(tr.ok[:, None], tr.arrival, np.nan), (float(cx), float(cy)))


def traced_jacobian(pixels: PixelMap) -> np.ndarray:
    """Solid angle per pixel (sr) from the traced arrival directions u of neighbouring centres:
    |u . (u_x x u_y)| with central differences (one-sided at the grid's edge; stride^2 px^2 per
    sample); NaN where a neighbour is lost. Used as a ratio (as built / design) to carry the
    design's J over to a moved rig: the ratio cancels the differences' own O(1/r^2) error."""
    u = pixels.arrival.reshape(pixels.shape + (3,))
    ux = np.gradient(u, axis=1)
    uy = np.gradient(u, axis=0)
    J = np.abs(np.einsum("ijk,ijk->ij", u, np.cross(ux, uy)))
    return J.ravel() / pixels.stride ** 2


def _dilated(mask: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``mask`` (n,) on a grid ``shape`` grown by one cell in each of the 8 directions."""
    m = mask.reshape(shape)
    v = m.copy()
    v[1:, :] |= m[:-1, :]
    v[:-1, :] |= m[1:, :]
    out = v.copy()
    out[:, 1:] |= v[:, :-1]
    out[:, :-1] |= v[:, 1:]
    return out.ravel()


def _supersampled(rig, pixels: PixelMap, which: np.ndarray, optics, supersample: int, zone: Zone | None,
                  scale: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pixels ``which`` (n,) traced at supersample^2 sub-pixel points: the solid angle (sr) of their
    light that reaches O (the sum of J at the sub-points that arrive, over supersample^2, times
    ``scale`` per pixel) and its mean direction (J-weighted, unit; NaN where nothing arrives). With
    ``zone`` a sub-point counts only if its design direction lies in the zone (the design: what the
    images light), and the directions are the design's; without, every arriving sub-ray counts with
    its traced arrival direction (as built)."""
    from rigcad.check.sources import pixel_rays
    from rigcad.check.trace3d import trace

    idx = np.nonzero(which)[0]
    weight = np.zeros(pixels.size)
    mean = np.full((pixels.size, 3), np.nan)
    if len(idx) == 0:
        return weight, mean
    o = (np.arange(supersample) + 0.5) / supersample - 0.5
    dx, dy = (a.ravel() for a in np.meshgrid(o, o, indexing="ij"))
    x = (pixels.x_px[idx, None] + dx[None, :]).ravel()
    y = (pixels.y_px[idx, None] + dy[None, :]).ravel()
    design = device_map(rig, pixels.device, pixels.focal_px)
    rays = pixel_rays(design, x, y, rig.pose(pixels.device) if pixels.as_built else None)
    tr = trace(optics, rays.origins, rays.dirs)
    J, _ = pixel_jacobian(design, x, y)
    if zone is not None:
        dirs = design.direction(rays.chief)
        theta, _ = direction_angles(dirs)
        arrives = tr.ok & np.isfinite(theta) & zone.contains(np.nan_to_num(theta, nan=-1.0))
    else:
        dirs, arrives = tr.arrival, tr.ok
    jw = np.where(arrives, J, 0.0).reshape(len(idx), -1)
    s = 1.0 if scale is None else scale[idx]
    weight[idx] = jw.sum(axis=1) / supersample ** 2 * s
    acc = (np.where(arrives[:, None], dirs, 0.0).reshape(len(idx), -1, 3) * jw[..., None]).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean[idx] = acc / np.linalg.norm(acc, axis=1, keepdims=True)
    return weight, mean


@dataclass(frozen=True)
class Illumination:
    """What the projector's lit pixels deliver to O on one rig, per traced pixel (n,): ``lit`` (the
    pixels the design's images light), ``weight_sr`` (solid angle of the light that arrives, sr) and
    ``sampling``, the :class:`IlluminationSampling` of the directions it arrives from (the design's,
    or, ``as_built``, the traced ones of a moved rig) with those weights, valid where light arrives.
    ``edge_pixels``: how many pixels were supersampled."""

    pixels: PixelMap
    lit: np.ndarray
    weight_sr: np.ndarray
    sampling: IlluminationSampling
    as_built: bool
    edge_pixels: int


def illumination(rig, zone: Zone, *, as_built: bool = False, design: PixelMap | None = None,
                 supersample: int = SUPERSAMPLE) -> Illumination:
    """The projector's illumination of O on ``rig`` (module docstring).

    The design decides what is shown (``design``: the design PixelMap, traced here if not given): a
    pixel whose centre ray reaches O from a direction in the zone shows Z at that direction with its
    solid angle J; a pixel on an edge (next to a pixel of the other kind) is supersampled and, if any
    part of it reaches O from the zone, shows Z at the mean design direction of that part, with that
    part's solid angle. ``as_built``: the same images on a moved rig: each lit pixel's light arrives
    from its traced direction, with the design's J times the ratio of the traced Jacobians (as built
    / design, :func:`traced_jacobian`), and pixels on an edge of either rig are supersampled on the
    moved rig (every sub-ray that reaches O counts, whatever its direction)."""
    if design is None:
        design = trace_pixels(rig, "projector")
    centre = design.ok & design.in_zone(zone)
    edge = _dilated(centre, design.shape) & _dilated(~centre, design.shape)
    w_e, d_e = _supersampled(rig, design, edge, _optics(rig, False), supersample, zone)
    weight = np.where(edge, w_e, np.where(centre, design.jacobian_sr, 0.0))
    dirs = np.where(edge[:, None], d_e, design.design_dirs)
    lit = weight > 0
    edges = int(edge.sum())
    if as_built:
        optics = _optics(rig, True)
        built = trace_pixels(rig, "projector", as_built=True, optics=optics, focal_px=design.focal_px,
                             centre=design.centre)
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = traced_jacobian(built) / traced_jacobian(design)
        ratio = np.where(np.isfinite(ratio), ratio, 1.0)
        cand = lit & (edge | ~built.ok | _dilated(~built.ok, built.shape))
        w_c, d_c = _supersampled(rig, built, cand, optics, supersample, None, ratio)
        weight = np.where(cand, w_c, np.where(lit & built.ok, design.jacobian_sr * ratio, 0.0))
        dirs = np.where(cand[:, None], d_c, built.arrival)
        edges += int(cand.sum())
    valid = lit & (weight > 0) & np.all(np.isfinite(dirs), axis=1)
    theta, phi = direction_angles(np.where(valid[:, None], dirs, [0.0, 0.0, 1.0]))
    weight = np.where(valid, weight, 0.0)
    sampling = IlluminationSampling(np.where(valid, theta, 0.0), np.where(valid, phi, 0.0), weight, valid)
    return Illumination(design, lit, weight, sampling, as_built, edges)


# -- the design light path, independently of the tracer ------------------------------------------------
def illuminated(rig, directions: np.ndarray, zone: Zone | None = None) -> np.ndarray:
    """Whether light from incidence directions ``directions`` (n, 3) reaches O on the rig as designed,
    without the 3D tracer: each direction's design light path (COP -> P on the paraboloid -> D on the
    dome -> O, in its meridional plane; ``parts.occlusion.design_path``) against every occluder the
    part recipes declare (boxes and cylinders, exactly), and the direction inside ``zone`` (default
    :func:`zone_of`). The truth for eq. 4.3 over what the rig lights (tests check it against the
    tracer pixel by pixel)."""
    from rigcad.optics.solids import segments_hit_box, segments_hit_cylinder
    from rigcad.parts.occlusion import design_path
    from rigcad.parts.recipe import Box

    zone = zone or zone_of(rig)
    theta, phi = direction_angles(np.asarray(directions, float))
    inside = zone.contains(theta)
    P, D = design_path(rig.design.table, np.where(inside, theta, zone.alpha_rad), phi)
    O = np.zeros_like(D)
    blocked = np.zeros(len(D), dtype=bool)
    for group in rig.occluders.values():
        for _, solid in group:
            for a, b in ((P, D), (D, O)):
                if isinstance(solid, Box):
                    blocked |= segments_hit_box(a, b, np.array(solid.lo, float), np.array(solid.hi, float))
                else:
                    x, y, z = solid.base
                    blocked |= segments_hit_cylinder(a, b, solid.radius, z, z + solid.height, (x, y))
    return inside & ~blocked


# -- images, Gram matrices, lat-long maps -----------------------------------------------------------------
def solid_angle_check(rig, design: PixelMap, zone: Zone) -> dict:
    """The pixels' design solid angles (J at each centre) against the zone's closed form
    2 pi (cos alpha - cos beta) (sr), occluders ignored: ``pixel_sum_sr`` over the pixels whose
    centre lies in the zone, its ``relative_error``, and ``edge_bound_sr``: the summed J of the
    pixels that straddle a zone edge (corners on both sides). Each such pixel is counted whole or not
    at all, so the sum's discretisation error lies within that bound plus the interior's
    second-order midpoint error (``interior_midpoint_estimate_sr``: the same sum with 2 x 2 points
    per pixel, minus the centre sum, over the pixels wholly inside)."""
    m = device_map(rig, design.device, design.focal_px)

    def theta_at(x, y):
        a = np.arctan2(np.hypot(x, y), m.focal_px)
        ok = (a >= m.alpha_min) & (a <= m.alpha_max)
        th = m.spline(np.clip(a, m.alpha_min, m.alpha_max))
        return np.where(ok, th, np.nan)

    inside = design.in_zone(zone)
    total = float(design.jacobian_sr[inside].sum())
    corner_in = []
    for dx in (-0.5, 0.5):
        for dy in (-0.5, 0.5):
            th = theta_at(design.x_px + dx, design.y_px + dy)
            corner_in.append(np.isfinite(th) & zone.contains(np.nan_to_num(th, nan=-1.0)))
    corner_in = np.array(corner_in)
    straddle = corner_in.any(axis=0) & ~corner_in.all(axis=0)
    # J where the centre is outside the annulus: the nearest annulus value (a bound, not a weight)
    f = m.focal_px
    r = np.hypot(design.x_px, design.y_px)
    ac = np.clip(np.arctan2(r, f), m.alpha_min, m.alpha_max)
    rc = f * np.tan(ac)
    j_edge = np.sin(m.spline(ac)) * np.abs(m.spline.derivative()(ac)) * f / ((f * f + rc * rc) * rc)
    interior = corner_in.all(axis=0)
    sub = np.zeros(design.size)
    for dx in (-0.25, 0.25):
        for dy in (-0.25, 0.25):
            sub += 0.25 * pixel_jacobian(m, design.x_px + dx, design.y_px + dy)[0]
    closed = zone.solid_angle_sr
    return {"zone_closed_form_sr": closed, "pixel_sum_sr": total, "relative_error": total / closed - 1.0,
            "pixels_in_zone": int(inside.sum()), "edge_pixels": int(straddle.sum()),
            "edge_bound_sr": float(j_edge[straddle].sum()),
            "interior_midpoint_estimate_sr": float(np.sum(sub[interior] - design.jacobian_sr[interior])),
            "formula": "J = sin(T(a)) |T'(a)| f / ((f^2 + r^2) r) sr per px^2 at the pixel centre; "
                       "a = atan(r / f), r the centre's distance from the image centre (px), f the focal "
                       "length (px), T the design's incidence angle of a COP ray at angle a"}


def _gram_figures(values: np.ndarray, sampling: IlluminationSampling, free: IlluminationSampling,
                  free_values: np.ndarray) -> dict:
    """Off-identity figures of one set's discrete Gram matrices (see ProjectorBasis.report)."""

    def oi(G):
        o = off_identity(G)
        return {"max_offdiag": o.max_offdiag, "max_diag_deviation": o.max_diag_deviation, "max_abs": o.max_abs}

    out = {"functions": int(values.shape[1]),
           "analytic": oi(gram(values, sampling)),
           "analytic_without_occluders": oi(gram(free_values, free))}
    for bits in BITS:
        out[f"analytic_{bits}bit"] = oi(gram(quantise_images(values, bits).values(), sampling))
    ro = reorthonormalise(values, sampling, "lowdin", reference=values)
    for bits in BITS:
        out[f"lowdin_{bits}bit"] = oi(gram(quantise_images(ro.functions, bits).values(), sampling))
    out["lowdin_deviation_from_analytic"] = {"max": float(ro.deviation.max()),
                                             "rms": float(np.sqrt(np.mean(ro.deviation ** 2)))}
    return out


def check_basis_order(order) -> int:
    """``order`` as an int in 0..MAX_ORDER, or BasisError naming the value and the valid range."""
    try:
        L = check_order(order)
    except BasisError:
        raise BasisError(f"basis order = {order!r}: need an integer from 0 to {MAX_ORDER} (the largest l; "
                         "thesis 3.3.1: 4 for matte materials, up to 6 for specular or anisotropic ones)",
                         param="basis.order") from None
    if L > MAX_ORDER:
        raise BasisError(f"basis order = {order!r}: need an integer from 0 to {MAX_ORDER} (orthonormality is "
                         f"verified to order {MAX_ORDER}; order {L} would be {(L + 1) ** 2} functions)",
                         param="basis.order")
    return L


@dataclass(frozen=True)
class ProjectorBasis:
    """The zonal basis up to ``order`` as the rig's projector shows it (module docstring).

    Over the traced window's pixels (n = ``illumination.pixels.size``): ``values`` (n, K), Z_k at
    each lit pixel's design direction (1/sqrt(sr); 0 where black); ``images[bits]`` the 4.2.1
    preprocessing of those values (:class:`QuantisedImages`, positive and negative parts (K, n));
    ``lowdin``, the set re-orthonormalised on the lit pixels under their solid angles (Loewdin:
    the orthonormal set closest to the analytic one), and ``lowdin_images[bits]``. ``latlong``
    (K, n_theta, n_phi) float32: the latitude-longitude maps at cell centres ``latlong_theta_rad``
    x ``latlong_phi_rad``, and ``latlong_images[bits]`` their preprocessing. ``report``: the figures
    basis.json holds (units in keys)."""

    profile: str
    order: int
    zone: Zone
    illumination: Illumination
    values: np.ndarray
    images: dict
    lowdin: Reorthonormalised
    lowdin_images: dict
    latlong: np.ndarray
    latlong_theta_rad: np.ndarray
    latlong_phi_rad: np.ndarray
    latlong_images: dict
    report: dict

    @property
    def pixels(self) -> PixelMap:
        return self.illumination.pixels

    @property
    def indices(self) -> np.ndarray:
        """(K, 2) (l, m) of each function, in basis order k = l^2 + l + m."""
        return basis_indices(self.order)

    def _quantised(self, kind: str, bits: int) -> QuantisedImages:
        sets = {"analytic": self.images, "lowdin": self.lowdin_images, "latlong": self.latlong_images}
        if kind not in sets or bits not in BITS:
            raise BasisError(f"image kind {kind!r}, bits {bits!r}: need kind in {', '.join(sets)} and bits in {BITS}")
        return sets[kind][bits]

    def image(self, k: int, part: str = "positive", bits: int = 8, kind: str = "analytic") -> np.ndarray:
        """The full projector frame (height, width) of function ``k``'s ``part`` (positive or
        negative), uint8 or uint16 levels (``bits``), ``kind`` analytic or lowdin; black off the lit pixels."""
        if part not in ("positive", "negative"):
            raise BasisError(f"image part {part!r}: need 'positive' or 'negative'")
        q = self._quantised(kind, bits)
        px = self.pixels
        width, height = px.resolution
        out = np.zeros((height, width), dtype=q.positive.dtype)
        out[px.row, px.col] = getattr(q, part)[k]
        return out

    def latlong_image(self, k: int, part: str = "positive", bits: int = 8) -> np.ndarray:
        """Function ``k``'s latitude-longitude map (n_theta, n_phi) after 4.2.1 preprocessing."""
        if part not in ("positive", "negative"):
            raise BasisError(f"image part {part!r}: need 'positive' or 'negative'")
        q = self._quantised("latlong", bits)
        return getattr(q, part)[k].reshape(self.latlong.shape[1:])

    def displayed(self, kind: str = "analytic", bits: int = 8) -> np.ndarray:
        """Signed values (n, K) the projector shows (positive minus negative image, in 1/sqrt(sr))."""
        return self._quantised(kind, bits).values()


def latlong_grid(zone: Zone, step_deg: float = LATLONG_STEP_DEG) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres (theta_rad (n_theta,), phi_rad (n_phi,)) of the latitude-longitude maps: the
    zone cut into ceil(span / step) equal rows from alpha to beta, and round(360 / step) columns from phi = 0."""
    if not (math.isfinite(step_deg) and 0 < step_deg <= 10):
        raise BasisError(f"latitude-longitude step_deg = {step_deg!r}: need 0 < step_deg <= 10 degrees")
    span = zone.beta_rad - zone.alpha_rad
    n_theta = max(1, math.ceil(span / math.radians(step_deg) - 1e-9))
    n_phi = max(1, round(360.0 / step_deg))
    theta = zone.alpha_rad + (np.arange(n_theta) + 0.5) * span / n_theta
    return theta, (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi


def projector_basis(rig, order: int = 6, *, alpha_rad: float | None = None,
                    latlong_step_deg: float = LATLONG_STEP_DEG, progress: Progress = None,
                    measured=None) -> ProjectorBasis:
    """The projector images of the zonal basis up to ``order`` for ``rig`` as designed (module
    docstring), or as ``measured`` (rigcad.basis.measured.Measured: the calibration circle read in the
    projector's pixels, the deflectometric fit's moved rig on which each lit pixel's light is traced),
    their Gram matrices over the lit pixels and the latitude-longitude maps. ``alpha_rad``: the zone's
    lower edge (default: the rig's occlusion limit). ``progress(label)`` is called after each of
    BASIS_STEPS stages."""
    from rigcad.basis.measured import measured_rig, projector_frame

    L = check_basis_order(order)
    step = progress_step(progress)
    zone = zone_of(rig, alpha_rad)
    focal, centre = projector_frame(rig, measured)
    rig = measured_rig(rig, measured)
    design = trace_pixels(rig, "projector", focal_px=focal, centre=centre)
    step("projector pixels traced")
    illum = illumination(rig, zone, design=design, as_built=measured is not None and measured.theta is not None)
    step("edge pixels supersampled")
    s = illum.sampling
    values = basis_images(s, L, zone)
    images = {b: quantise_images(values, b) for b in BITS}
    lowdin = reorthonormalise(values, s, "lowdin", reference=values)
    lowdin_images = {b: quantise_images(lowdin.functions, b) for b in BITS}
    step("images")
    grams = _gram_orders(design, zone, s, values, L)
    step("Gram matrices")
    th, ph = latlong_grid(zone, latlong_step_deg)
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    ll = zonal_basis(TH.ravel(), PH.ravel(), L, zone)
    latlong_images = {b: quantise_images(ll, b) for b in BITS}
    latlong = np.ascontiguousarray(ll.T.reshape(-1, len(th), len(ph)).astype(np.float32))
    step("latitude-longitude maps")
    report = {
        "profile": rig.name,
        "order": L,
        "functions": (L + 1) ** 2,
        "thesis": "zonal basis eqs. 3.1-3.3 (thesis 3.3); preprocessing 4.2.1; Gram matrix over the lit pixels",
        "frame": "incidence directions in the sample's frame: normal +z, tangent +x (projector image x); "
                 "phi from +x towards +y; image values of Z_l^m in 1/sqrt(sr)",
        "zone": {"alpha_deg": math.degrees(zone.alpha_rad), "beta_deg": math.degrees(zone.beta_rad),
                 "solid_angle_sr": zone.solid_angle_sr,
                 "alpha_from": "the incidence map's inner edge (occlusion limit)" if alpha_rad is None else "given",
                 "design_report_theta_min_deg": rig.design.report["measurable_range"]["theta_min_deg"]},
        "projector": _projector_figures(design, illum, zone),
        "solid_angle": solid_angle_check(rig, design, zone),
        "preprocessing": {
            "thesis": "4.2.1: one scale for all images of the set, positive and negative parts as separate "
                      "images, rounded to the nearest level",
            "bits": list(BITS),
            "scale_per_sqrt_sr": images[8].scale,
            "lowdin_scale_per_sqrt_sr": lowdin_images[8].scale,
            "latlong_scale_per_sqrt_sr": latlong_images[8].scale,
            "level_meaning": "level q of a b-bit image stands for q * scale / (2^b - 1)",
        },
        "gram": {
            "definition": "G = V^T W V over the lit pixels: V the displayed values (1/sqrt(sr)), W their "
                          "solid angles (sr); identity for an orthonormal set",
            "variants": "analytic: unquantised Z_l^m; analytic_8bit/16bit: after 4.2.1 preprocessing; "
                        "analytic_without_occluders: every pixel whose centre lies in the zone, J weights, "
                        "no beam or mount (the pixel grid's own effect); lowdin_8bit/16bit: the set "
                        "re-orthonormalised on the lit pixels (Loewdin), then preprocessed",
            **grams,
        },
        "gram_matrix_8bit": gram(images[8].values(), s).tolist(),
        "lowdin_transform": lowdin.transform.tolist(),
        "lowdin_note": "the re-orthonormalised set is values @ lowdin_transform; responses to the analytic "
                       "images times lowdin_transform are coefficients in that set",
        "latlong": _latlong_figures(zone, th, ph),
        "functions_index": [{"k": k, "l": int(l), "m": int(m)} for k, (l, m) in enumerate(basis_indices(L))],
        "measured": {"about": "what the images were drawn for besides the design (rigcad.basis.measured): the "
                              "calibration circle, the deflectometric fit's rig; empty: as designed",
                     **({} if measured is None else measured.describe())},
    }
    return ProjectorBasis(rig.name, L, zone, illum, values, images, lowdin, lowdin_images, latlong, th, ph,
                          latlong_images, report)


def _gram_orders(design, zone, sampling, values, order: int) -> dict:
    """The Gram figures (:func:`_gram_figures`) of the basis truncated at each order of GRAM_ORDERS up
    to ``order`` and at ``order``, against the pixels whose centre lies in the zone without occluders."""
    inside = design.in_zone(zone)
    theta, phi = design.design_angles()
    free = IlluminationSampling(np.where(inside, theta, 0.0), np.where(inside, phi, 0.0),
                                np.where(inside, design.jacobian_sr, 0.0), inside)
    free_values = basis_images(free, order, zone)
    orders = sorted({o for o in GRAM_ORDERS if o <= order} | {order})
    return {f"order_{o}": _gram_figures(values[:, :(o + 1) ** 2], sampling, free, free_values[:, :(o + 1) ** 2])
            for o in orders}


def _projector_figures(design, illum, zone) -> dict:
    """The projector's pixels: traced window, status counts, in the zone, lit, supersampled at the
    edge, the lit solid angle (sr) and the pitch (deg)."""
    from rigcad.check.result import STATUS_NAMES

    width, height = design.resolution
    r0, c0, h, w = design.window
    return {
        "resolution_px": [width, height], "focal_length_px": design.focal_px,
        "traced_window_row_col_rows_cols": [r0, c0, h, w],
        "window_border_all_missed": design.border_all_missed(),
        "pixels_traced": design.size,
        "pixels_by_status": {STATUS_NAMES[k]: int(np.sum(design.status == k)) for k in STATUS_NAMES},
        "pixels_in_zone": int(design.in_zone(zone).sum()),
        "pixels_lit": int(illum.lit.sum()),
        "edge_pixels_supersampled": illum.edge_pixels, "supersample_per_side": SUPERSAMPLE,
        "lit_solid_angle_sr": float(illum.weight_sr.sum()),
        "lit_fraction_of_zone": float(illum.weight_sr.sum() / zone.solid_angle_sr),
        "pitch_deg": math.degrees(illum.sampling.pitch_rad()),
        "pitch_note": "side of a square of the median lit pixel's solid angle",
    }


def _latlong_figures(zone, th, ph) -> dict:
    """The latitude-longitude maps' grid: step, rows and columns, first cells (deg)."""
    step = th[1] - th[0] if len(th) > 1 else zone.beta_rad - zone.alpha_rad
    return {"step_deg": math.degrees(step), "rows_theta": len(th), "columns_phi": len(ph),
            "theta_first_deg": math.degrees(th[0]), "theta_last_deg": math.degrees(th[-1]),
            "phi_first_deg": math.degrees(ph[0]),
            "layout": "row 0 next to the normal (theta = alpha), columns from phi = 0 towards +y"}


# -- files ---------------------------------------------------------------------------------------------
def image_name(l: int, m: int, part: str) -> str:
    """File name of Z_l^m's positive or negative image: ``z_<l>_<m signed>_<pos|neg>.png``."""
    return f"z_{l}_{m:+d}_{'pos' if part == 'positive' else 'neg'}.png"


def write_basis(basis: ProjectorBasis, out_dir: str | Path, *, lowdin_images: bool = False,
                progress: Progress = None, lock: Path | None = None, made_from: str | None = None,
                also=None) -> list[Path]:
    """Write ``basis`` into ``out_dir`` (exports/<profile>/basis): projector/{8bit,16bit}/ (the frames
    to project), latlong/{8bit,16bit}/ and latlong_float32.npy (the 4.2.1 maps), with
    ``lowdin_images`` projector_lowdin/{8bit,16bit}/ (the re-orthonormalised set), contact_sheet.png,
    latlong_sheet.png and basis.json (the report and the list of files). All published together
    (atomic), with what ``also(staging, out_dir)`` stages (the simulation: files it returns are listed
    in basis.json too); whatever an earlier run wrote that this one does not is removed. ``progress(label)``
    is called once per function and once at the end. ``lock``: the lock every run writing under
    exports/<profile> holds (export.atomic.profile_lock; default one beside ``out_dir``);
    ``made_from``: the SHA-256 of the profile the basis was made from (export.manifest.profile_digest),
    recorded beside the folder. Returns the written paths."""
    import io

    from rigcad import plots
    from rigcad.export.atomic import Staging, json_bytes
    from rigcad.export.png import gray_png

    step = progress_step(progress)
    out = Path(out_dir)
    kinds = [("analytic", "projector")] + ([("lowdin", "projector_lowdin")] if lowdin_images else [])
    written = []
    # one run's files only: no image, simulation or sheet of an earlier run is carried over
    with Staging(out, lock, carry=lambda rel: False, made_from=made_from) as st:
        for k, (l, m) in enumerate(basis.indices):
            for part in ("positive", "negative"):
                name = image_name(int(l), int(m), part)
                for bits in BITS:
                    for kind, folder in kinds:
                        written.append(st.write_bytes(out / folder / f"{bits}bit" / name,
                                                      gray_png(basis.image(k, part, bits, kind))))
                    written.append(st.write_bytes(out / "latlong" / f"{bits}bit" / name,
                                                  gray_png(basis.latlong_image(k, part, bits))))
            step(f"Z_{l}^{m} written")
        buf = io.BytesIO()
        np.save(buf, basis.latlong, allow_pickle=False)
        written.append(st.write_bytes(out / "latlong" / "latlong_float32.npy", buf.getvalue()))
        written.append(st.write_bytes(out / "contact_sheet.png", plots.basis_contact_sheet(basis)))
        written.append(st.write_bytes(out / "latlong_sheet.png", plots.basis_latlong_sheet(basis)))
        if also is not None:
            written += list(also(st, out))
        files = sorted(p.relative_to(out).as_posix() for p in written)
        report = {**basis.report, "files": files, "lowdin_images_written": lowdin_images}
        written.append(st.write_bytes(out / "basis.json", json_bytes(report)))
        paths = st.commit()
    step("contact sheets and basis.json written")
    return paths
