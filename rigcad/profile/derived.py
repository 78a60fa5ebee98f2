"""Values derived from a profile, computed once (millimetres, radians, frame: sample point O at the
origin, optical axis +z, meridional plane x-z).

The paraboloid is z(r) = vertex_z - r^2 / (4 f): convex, vertex up towards the COP, rim lowest.
The tangent angle tau is measured between the rim's meridional tangent and the optical axis, so
tan(tau) = 2 f / rim_radius and vertical_extent = rim_radius^2 / (4 f) (thesis Table 3.1, with the
reading documented in docs/design.md: Figure 3.5 is lost).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from rigcad.errors import GeometryError
from rigcad.profile.schema import Profile


@dataclass(frozen=True)
class Derived:
    """Geometry every later stage uses. Lengths in mm, angles in rad, z along the optical axis."""

    focal_length: float
    rim_radius: float
    vertical_extent: float
    tangent_angle: float
    vertex_z: float
    rim_z: float
    focus_z: float
    cop_z: float
    #: Radius of curvature at the vertex, 2 f.
    vertex_radius_of_curvature: float
    #: Polar angle (from +z, seen from O) of the paraboloid's rim: directions below it are occluded.
    occlusion_theta: float
    #: Angle between the axis and the ray from the COP to the rim (0 for a COP at infinity).
    rim_angle_at_cop: float
    #: Projector focal length in pixels: width_px * throw_ratio.
    projector_focal_px: float
    #: Projector pixels from the vertex's image to the rim's image (inf COP: not defined, NaN).
    pixels_vertex_to_rim: float

    @property
    def cop_at_infinity(self) -> bool:
        return math.isinf(self.cop_z)

    def as_dict(self) -> dict[str, float | str | None]:
        """Named with units, for JSON."""
        units = {"tangent_angle": "_rad", "occlusion_theta": "_rad", "rim_angle_at_cop": "_rad",
                 "projector_focal_px": "", "pixels_vertex_to_rim": ""}
        out: dict[str, float | str | None] = {}
        for key, value in asdict(self).items():
            if isinstance(value, float) and math.isinf(value):
                value = "inf"
            elif isinstance(value, float) and math.isnan(value):
                value = None
            out[key + units.get(key, "_mm")] = value
        return out


#: Fewest projector pixels from the paraboloid's vertex to its rim (the thesis's rig has ~100): below
#: this the rig lights the sample from a handful of directions, and its dome cannot be certified.
MIN_PIXELS_ACROSS = 10


def projector_principal_point(projector) -> tuple[float, float]:
    """Where the projector's lens axis meets its image (px from the image's top-left corner, x right,
    y down, in the projector's own orientation): the centre, moved down by ``lens_offset`` half heights
    (an image thrown above its axis has the axis below its centre; 100 %: on the bottom edge). The rig
    holds the projector's lens axis on its own, so the paraboloid's image is a disc about this pixel."""
    w, h = projector.resolution
    return w / 2, h / 2 * (1.0 + projector.lens_offset)


def projector_disc_room(projector) -> float:
    """The largest disc about the lens axis's pixel that the projector's image holds (px): the
    distance from :func:`projector_principal_point` to the image's nearest edge (<= 0: the axis is
    on or below the image's edge)."""
    (x, y), (w, h) = projector_principal_point(projector), projector.resolution
    return min(x, w - x, y, h - y)


def check_disc(profile: Profile, pixels: float) -> None:
    """Refuse a projector whose image does not hold the paraboloid's disc of ``pixels`` radius about
    its lens axis: its rim's pixels (the grazing directions) or all of them would light nothing. ``derive``
    judges the disc without the focusing lens; the manual's calibration circle judges it again with the lens
    (rigcad.manual.calibration.circle_image), by this same rule and message."""
    pj = profile.projector
    room = projector_disc_room(pj)
    # a centred image is judged by the later checks (the design's openings, the px/deg fan), which name
    # what is wrong with an extreme geometry more precisely than the disc would
    if pj.lens_offset == 0 or not math.isfinite(pixels) or pixels <= room:
        return
    (w, h), off = pj.resolution, pj.lens_offset
    best = 1.0 - 2.0 * pixels / h  # the largest offset whose image still holds the disc below the axis
    if pixels <= w / 2 and best >= 0 and room <= 0:  # no disc about an axis off the image: no throw ratio helps
        way = (f"the axis lies outside the image, so no projector.throw_ratio can help: it needs a projector with its "
               f"lens shift set to at most {best:.0%} (projector.lens_offset)")
    elif pixels <= w / 2 and best >= 0:
        way = (f"it needs an offset of at most {best:.0%} (projector.lens_offset: a lens shift set nearer the centre, "
               "or another projector), or a lower projector.throw_ratio (zoom wider)")
    else:
        way = ("a projector with a lens shift set to the centre (projector.lens_offset: 0) and a shorter throw, "
               "or a smaller paraboloid image (a smaller paraboloid, or a larger layout.cop_to_vertex)")
    axis = f"its lens axis at row {h / 2 * (1 + off):.0f} of {h} (projector.lens_offset {off:.0%})"
    raise GeometryError(f"the projector's {w} x {h} px image cannot hold the paraboloid's image, a disc {pixels:.0f} px "
                        f"in radius about {axis}: {max(room, 0.0):.0f} px from there to the image's nearest edge; "
                        + way, where=profile.where("projector", "lens_offset"))


def derive(profile: Profile) -> Derived:
    """Compute the paraboloid and layout figures; raise GeometryError naming the parameter."""
    par = profile.paraboloid
    if par.focal_length is not None:
        f, r_rim = par.focal_length, par.rim_radius
        d_p = r_rim**2 / (4.0 * f)
        tau = math.atan2(2.0 * f, r_rim)
    else:
        d_p, tau = par.vertical_extent, par.tangent_angle
        r_rim = 2.0 * d_p * math.tan(tau)
        f = d_p * math.tan(tau) ** 2
    rim_z = profile.layout.sample_to_rim
    vertex_z = rim_z + d_p
    cop_z = vertex_z + profile.layout.cop_to_vertex
    if not all(math.isfinite(v) and v > 0 for v in (f, r_rim, d_p)):
        raise GeometryError(
            f"paraboloid gives focal length {f:g} mm, rim radius {r_rim:g} mm, vertical extent {d_p:g} mm: "
            "each must be finite and > 0", where=profile.where("paraboloid", "tangent_angle"))
    rim_angle = 0.0 if math.isinf(cop_z) else math.atan2(r_rim, cop_z - rim_z)
    focal_px = profile.projector.resolution[0] * profile.projector.throw_ratio
    pixels = math.nan if math.isinf(cop_z) else focal_px * math.tan(rim_angle)
    if math.isfinite(pixels) and pixels < MIN_PIXELS_ACROSS:
        keys = ("focal_length", "rim_radius") if par.focal_length is not None else ("tangent_angle", "vertical_extent")
        raise GeometryError(
            f"the paraboloid spans {pixels:.3g} projector pixels from vertex to rim (rim radius {r_rim:.3g} mm seen "
            f"from {cop_z - rim_z:.4g} mm): at least {MIN_PIXELS_ACROSS} are needed to light the sample from distinct "
            f"directions; raise paraboloid.{keys[0]} or paraboloid.{keys[1]}, or lower layout.cop_to_vertex",
            where=profile.where("paraboloid", keys[0]))
    check_disc(profile, pixels)
    return Derived(
        focal_length=f, rim_radius=r_rim, vertical_extent=d_p, tangent_angle=tau,
        vertex_z=vertex_z, rim_z=rim_z, focus_z=vertex_z - f, cop_z=cop_z,
        vertex_radius_of_curvature=2.0 * f,
        occlusion_theta=math.atan2(r_rim, rim_z),
        rim_angle_at_cop=rim_angle,
        projector_focal_px=focal_px, pixels_vertex_to_rim=pixels,
    )
