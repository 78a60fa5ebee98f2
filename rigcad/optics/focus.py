"""The focusing lens (thesis 3.1, item 6): a thin positive lens in front of the projector that brings
the paraboloid, a few hundred millimetres away, into the projector's own focus range (a business
projector focuses from about a metre out). Thin-lens optics, distances along the projector's
unfolded axis (mm), every one measured from the projector's COP unless said otherwise.

The projector focused at distance D forms its image D from its COP; a thin lens of focal length f,
``s`` from the COP, re-images it (Gaussian lens equation, real-is-positive, light converging onto
the image) at

    1/u = 1/f + 1/(D - s)          u: from the lens                                     (1)

so D = inf gives u = f, and the projector's focus range [D_min, D_max] maps onto a range of u. The
paraboloid spans u_near (its vertex) to u_far (its rim). :func:`focusing_lens` picks the catalogue
focal length whose range, in dioptres, is centred nearest to the paraboloid's, and checks that both
ends of the paraboloid are reachable by turning the projector's focus ring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.errors import GeometryError

#: Focal lengths (mm) of stock 50.8 mm (2 in) plano-convex singlets: the series the optics catalogues
#: share (Thorlabs LA1xxx, Edmund Optics, Newport KPX), from 75 mm (f/1.5) to 1 m.
CATALOGUE_FOCAL_LENGTHS = (75.0, 100.0, 125.0, 150.0, 175.0, 200.0, 250.0, 300.0, 400.0, 500.0, 750.0, 1000.0)


def image_distance(focal_length: float, lens_distance: float, focus: float) -> float:
    """Where (mm from the lens) the lens re-images the projector focused at ``focus`` mm (equation 1)."""
    inv = 1.0 / focal_length + (0.0 if math.isinf(focus) else 1.0 / (focus - lens_distance))
    return math.inf if inv <= 0 else 1.0 / inv


def focus_for(focal_length: float, lens_distance: float, image: float) -> float:
    """The projector focus distance (mm from its COP) that puts the image ``image`` mm from the lens
    (equation 1 solved for D); inf when ``image`` is at or beyond the lens's focal length (even focus
    at infinity images it no farther than f)."""
    inv = 1.0 / image - 1.0 / focal_length
    return math.inf if inv <= 0 else lens_distance + 1.0 / inv


@dataclass(frozen=True)
class FocusingLens:
    """The chosen lens (mm): its focal length, the paraboloid's near and far distances from the lens,
    the projector focus settings they need, and the projector's range."""

    focal_length: float
    lens_distance: float
    image_near: float
    image_far: float
    focus_near: float
    focus_far: float
    focus_min: float
    focus_max: float
    from_catalogue: bool

    def describe(self) -> dict:
        return {"focal_length_mm": self.focal_length, "lens_distance_mm": self.lens_distance,
                "paraboloid_from_lens_mm": [self.image_near, self.image_far],
                "projector_focus_mm": [self.focus_near, _finite(self.focus_far)],
                "projector_focus_range_mm": [self.focus_min, _finite(self.focus_max)],
                "from_catalogue": self.from_catalogue}


def _finite(v: float):
    return "inf" if math.isinf(v) else v


def _dioptres(d: float) -> float:
    return 0.0 if math.isinf(d) else 1.0 / d


def _lens(f: float, s: float, near: float, far: float, d_min: float, d_max: float, catalogue: bool) -> FocusingLens:
    return FocusingLens(f, s, near, far, focus_for(f, s, near), focus_for(f, s, far), d_min, d_max, catalogue)


def _reachable(lens: FocusingLens) -> bool:
    # both ends of the paraboloid need a focus setting inside the projector's range (1e-9 relative:
    # a setting exactly at the range's end is reachable)
    lo, hi = lens.focus_min * (1 - 1e-9), lens.focus_max * (1 + 1e-9)
    return all(lo <= d <= hi for d in (lens.focus_near, lens.focus_far))


def _ideal(near: float, far: float, focus_near: float, focus_far: float) -> float:
    """The focal length (mm) that re-images the middle of the projector's focus range (distances from
    the lens, mm) onto the middle of the paraboloid's (``near``..``far``), both middles in dioptres."""
    mid_target = 0.5 * (_dioptres(near) + _dioptres(far))
    mid_focus = 0.5 * (_dioptres(focus_near) + _dioptres(focus_far))
    return 1.0 / (mid_target - mid_focus)


def ideal_focal_length(profile, geometry) -> float:
    """The focal length (mm) centred best on the paraboloid, catalogue or not (what
    :func:`focusing_lens` rounds to the catalogue)."""
    s = profile.lens.distance
    near = geometry.cop_z - geometry.vertex_z - s
    far = math.hypot(geometry.rim_radius, geometry.cop_z - geometry.rim_z) - s
    return _ideal(near, far, profile.projector.focus_min - s, profile.projector.focus_max - s)


def focusing_lens(profile, geometry) -> FocusingLens:
    """The focusing lens for ``profile`` (its ``lens.focal_length`` when given, else the catalogue
    value centred best on the paraboloid, in dioptres) and ``geometry`` (profile.derived.Derived);
    raise GeometryError naming the key when the paraboloid cannot be brought into focus."""
    pj, ln = profile.projector, profile.lens
    s = ln.distance
    near = geometry.cop_z - geometry.vertex_z - s  # the vertex, on the axis
    far = math.hypot(geometry.rim_radius, geometry.cop_z - geometry.rim_z) - s  # the rim
    d_min, d_max = pj.focus_min, pj.focus_max
    if d_min - s <= 0 or d_max < d_min:
        raise GeometryError(f"projector.focus_min ({d_min:g} mm) must lie beyond the focusing lens (lens.distance "
                            f"{s:g} mm) and below projector.focus_max", where=profile.where("projector", "focus_min"))
    if ln.focal_length is not None:
        lens = _lens(ln.focal_length, s, near, far, d_min, d_max, False)
        if not _reachable(lens):
            raise GeometryError(
                f"lens.focal_length {ln.focal_length:g} mm needs the projector focused at {lens.focus_near:.0f}.."
                f"{lens.focus_far:.0f} mm, outside its range {d_min:g}..{d_max:g} mm (projector.focus_min, "
                "focus_max); leave lens.focal_length out to have it computed", where=profile.where("lens", "focal_length"))
        return lens
    ideal = _ideal(near, far, d_min - s, d_max - s)
    best = min(CATALOGUE_FOCAL_LENGTHS, key=lambda f: abs(1.0 / f - 1.0 / ideal))
    lens = _lens(best, s, near, far, d_min, d_max, True)
    if not _reachable(lens):
        raise GeometryError(
            f"no catalogue focusing lens brings the paraboloid ({near:.0f}..{far:.0f} mm from the lens) into the "
            f"projector's focus range {d_min:g}..{d_max:g} mm (projector.focus_min, focus_max): the nearest, f = {best:g} mm, needs "
            f"{lens.focus_near:.0f}..{lens.focus_far:.0f} mm (ideal f = {ideal:.1f} mm); give lens.focal_length",
            where=profile.where("projector", "focus_min"))
    return lens
