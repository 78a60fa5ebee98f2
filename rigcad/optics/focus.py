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

The lens also moves the projector's centre of projection as the paraboloid sees it, and scales the
angles of its pixels (:func:`through_lens`). A chief ray leaving the real COP at angle a, s_H from the
lens's front principal plane H, leaves the back one H' with slope tan a (1 - s_H / f), so every
chief ray seems to come from one point, the COP's virtual image s_H f / (f - s_H) before H':

    shift = s_H^2 / (f - s_H) - (H' - H)      away from the lens, from the real COP          (2)

and the projector's focal length in pixels grows by f / (f - s_H). The lens is the plano-convex
singlet the bill orders, its curved side towards the projector: H on the curved vertex, H' at t / n
before the flat face (t its centre thickness: the edge ``lens.thickness`` plus the curved face's
sag over ``lens.diameter``; n its glass's index), so H' - H = t (n - 1) / n. A thin lens (t = 0,
s_H = s) gives s^2 / (f - s): 2.27 mm for Table 3.1 (f = 300 mm, s = 25 mm). The thick one moves
the other way: its principal planes stand 2.7 mm apart, and the COP appears 1.31 mm nearer the
lens, its pixels' angles x 1/1.071 (tests/optics/test_focus_cop.py: an exact Snell trace agrees to
2e-6 mm paraxially, 0.007 mm at the rim's angle).

So the COP tower does not put the real COP at the design COP: it keeps the lens's centre
``lens.distance`` before the design COP (folded onto the projector's axis) and puts the real COP
:func:`cop_distance_for` that before the lens's centre (26.14 mm for Table 3.1's 25 mm), where the
paraboloid, through the lens, sees it at the design COP (:attr:`FocusingLens.cop_distance`). Seen
through its lens, the placed projector is a pinhole at the design COP whose focal length in pixels
is f / (f - s_H) times its own (x 1.0757 for Table 3.1): :func:`lensed_focal_px`, the one home of the
projector's pixel map through its lens (rigcad.basis draws the zonal images on it; the circle of
thesis 4.1.1 is set with the lens in place, rigcad.manual.calibration).
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
    edge_thickness: float = 0.0  #: mm, at ``diameter`` (0, 0: a thin lens)
    diameter: float = 0.0

    @property
    def cop_distance(self) -> float:
        """Where (mm before the lens's centre) the tower puts the projector's real COP so that the
        paraboloid, through this lens, sees it ``lens_distance`` before the lens's centre: at the
        design COP (:func:`cop_distance_for`)."""
        return cop_distance_for(self.lens_distance, self.focal_length, self.edge_thickness, self.diameter)

    def describe(self) -> dict:
        shift, scale = self.through()
        return {"focal_length_mm": self.focal_length, "lens_distance_mm": self.lens_distance,
                "projector_cop_from_lens_mm": self.cop_distance,
                "paraboloid_from_lens_mm": [self.image_near, self.image_far],
                "projector_focus_mm": [self.focus_near, _finite(self.focus_far)],
                "projector_focus_range_mm": [self.focus_min, _finite(self.focus_max)],
                "from_catalogue": self.from_catalogue,
                "cop_shift_mm": _finite(shift), "pixel_scale": _finite(scale)}

    def through(self) -> tuple[float, float]:
        """(COP shift away from the lens, mm; growth of the projector's focal length in pixels) of
        this lens with the projector's real COP where the tower puts it, :attr:`cop_distance` before
        the lens's centre (:func:`through_lens`): the shift takes it to ``lens_distance``."""
        return through_lens(self.focal_length, self.cop_distance, self.edge_thickness, self.diameter)

    def projector(self, focal_px: float, cop_z: float) -> "LensedProjector":
        """The projector seen through this lens as the tower places it, with ``focal_px`` (px) of its
        own: a pinhole at the design COP, height ``cop_z`` (mm, rig frame: the projector's axis folded
        onto the optical axis, the lens ``lens_distance`` below the COP), its real COP
        :attr:`cop_distance` - ``lens_distance`` above it, and its focal length in pixels through the lens."""
        shift, scale = self.through()
        return LensedProjector(cop_z, focal_px * scale, shift, scale)


@dataclass(frozen=True)
class LensedProjector:
    """The projector and its focusing lens as one pinhole (paraxial): ``cop_z`` (mm) where its chief
    rays seem to come from (the design COP, where the tower puts it), ``focal_px`` its focal length in
    pixels, ``cop_shift`` (mm) how far that point stands beyond the real COP (away from the lens;
    negative: nearer), ``pixel_scale`` the focal length's growth through the lens."""

    cop_z: float
    focal_px: float
    cop_shift: float
    pixel_scale: float

    def pixel_radius(self, r: float, z: float) -> float:
        """How far (px) from the image centre the projector, through its lens, shows the point at
        radius ``r`` and height ``z`` (mm, below the COP) of the rig."""
        return self.focal_px * r / (self.cop_z - z)

    def ring_radius(self, geometry, alpha: float) -> float:
        """How far (px) from the image centre the projector, through its lens, shows the paraboloid's
        point that the design's chief ray at ``alpha`` (rad from the axis at the COP the paraboloid
        sees) meets: the rim for the rim's angle (``geometry``: profile.derived.Derived; the
        paraboloid z = z_vertex - r^2 / (4 f_p), thesis 3.2)."""
        t, fp = math.tan(alpha), geometry.focal_length
        h = self.cop_z - geometry.vertex_z  # the COP seen above the vertex
        r = 2 * h * t / (1 + math.sqrt(1 - h * t * t / fp))  # the nearer root of r^2 t / (4 fp) - r + h t = 0
        return self.pixel_radius(r, geometry.vertex_z - r * r / (4 * fp))


#: The focusing lens's glass: N-BK7 at 587.6 nm, what the bill orders (rigcad.parts.tower.hardware).
LENS_INDEX = 1.5168


def cop_distance_for(seen: float, focal_length: float, edge_thickness: float = 0.0, diameter: float = 0.0,
                     index: float = LENS_INDEX) -> float:
    """Where (mm before the lens's centre) the projector's real COP must stand for the paraboloid to
    see it ``seen`` mm before the lens's centre, through the lens of :func:`through_lens` (its
    inverse): with u the real COP's distance to the front principal plane, the COP seen stands
    u f / (f - u) before the back one, so u = c f / (f + c), c = ``seen`` less the back principal
    plane's distance before the lens's centre."""
    f, n = focal_length, index
    radius = f * (n - 1)
    sag = radius - math.sqrt(radius * radius - (diameter / 2) ** 2)
    front = edge_thickness / 2 + sag  # the front principal plane (the curved vertex) before the lens's centre
    back = front - (edge_thickness + sag) * (n - 1) / n  # the back one, t (n - 1) / n after it
    c = seen - back
    return front + c * f / (f + c)


def lensed_focal_px(profile, geometry) -> float:
    """The projector's focal length in pixels (px) as the paraboloid sees it through its focusing
    lens, placed by the tower (:meth:`FocusingLens.projector`): its pixel map is the design's, read
    about the design COP with this focal length instead of ``geometry.projector_focal_px``."""
    return placed_lens(profile, geometry).projector(geometry.projector_focal_px, geometry.cop_z).focal_px


def through_lens(focal_length: float, lens_distance: float, edge_thickness: float = 0.0, diameter: float = 0.0,
                 index: float = LENS_INDEX) -> tuple[float, float]:
    """The focusing lens's effect on the projector whose COP stands ``lens_distance`` (s, mm) before
    the lens's centre (module docstring, equation 2): (the shift of the COP away from the lens, mm;
    the growth of the focal length in pixels). The lens: a plano-convex singlet of ``focal_length``
    (its effective focal length, f = R / (n - 1)) and ``index``, its curved side towards the
    projector, ``edge_thickness`` thick at its ``diameter``; both 0: a thin lens. Paraxial. Both inf
    when the front principal plane stands f from the COP (the lens collimates the chief rays)."""
    f, n = focal_length, index
    radius = f * (n - 1)
    half = diameter / 2
    if half >= radius:
        raise GeometryError(f"a plano-convex lens of f = {f:g} mm (surface radius {radius:.1f} mm in glass of "
                            f"index {n:g}) cannot be {diameter:g} mm across", param="lens.diameter")
    sag = radius - math.sqrt(radius * radius - half * half)
    centre = edge_thickness + sag
    s = lens_distance - edge_thickness / 2 - sag  # the COP to the front principal plane (the curved vertex)
    if f == s:
        return math.inf, math.inf
    return s * s / (f - s) - centre * (n - 1) / n, f / (f - s)


def _finite(v: float):
    return "inf" if math.isinf(v) else v


def _dioptres(d: float) -> float:
    return 0.0 if math.isinf(d) else 1.0 / d


def _lens(f: float, s: float, near: float, far: float, d_min: float, d_max: float, catalogue: bool,
          edge_thickness: float = 0.0, diameter: float = 0.0) -> FocusingLens:
    return FocusingLens(f, s, near, far, focus_for(f, s, near), focus_for(f, s, far), d_min, d_max, catalogue,
                        edge_thickness, diameter)


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


def placed_lens(profile, geometry) -> FocusingLens:
    """The focusing lens the COP tower places the projector through (:func:`focusing_lens`'s choice),
    whether or not the projector can focus through it: that is :func:`focusing_lens`'s verdict, given
    where the lens is bought (the bill) and judged by the optimiser, not where the tower is laid out."""
    return focusing_lens(profile, geometry, judge=False)


def focusing_lens(profile, geometry, *, judge: bool = True) -> FocusingLens:
    """The focusing lens for ``profile`` (its ``lens.focal_length`` when given, else the catalogue
    value centred best on the paraboloid, in dioptres) and ``geometry`` (profile.derived.Derived);
    raise GeometryError naming the key when the paraboloid cannot be brought into focus (``judge``
    False: the choice alone, :func:`placed_lens`)."""
    pj, ln = profile.projector, profile.lens
    s = ln.distance
    near = geometry.cop_z - geometry.vertex_z - s  # the vertex, on the axis
    far = math.hypot(geometry.rim_radius, geometry.cop_z - geometry.rim_z) - s  # the rim
    d_min, d_max = pj.focus_min, pj.focus_max
    if judge and (d_min - s <= 0 or d_max < d_min):
        raise GeometryError(f"projector.focus_min ({d_min:g} mm) must lie beyond the focusing lens (lens.distance "
                            f"{s:g} mm) and below projector.focus_max", where=profile.where("projector", "focus_min"))
    if ln.focal_length is not None:
        lens = _lens(ln.focal_length, s, near, far, d_min, d_max, False, ln.thickness, ln.diameter)
        if judge and not _reachable(lens):
            raise GeometryError(
                f"lens.focal_length {ln.focal_length:g} mm needs the projector focused at {lens.focus_near:.0f}.."
                f"{lens.focus_far:.0f} mm, outside its range {d_min:g}..{d_max:g} mm (projector.focus_min, "
                "focus_max); leave lens.focal_length out to have it computed", where=profile.where("lens", "focal_length"))
        return lens
    # the power (1/mm) centred best, in dioptres (1 / _ideal's focal length, without its division)
    power = 0.5 * (_dioptres(near) + _dioptres(far)) - 0.5 * (_dioptres(d_min - s) + _dioptres(d_max - s))
    best = min(CATALOGUE_FOCAL_LENGTHS, key=lambda f: abs(1.0 / f - power))
    lens = _lens(best, s, near, far, d_min, d_max, True, ln.thickness, ln.diameter)
    if judge and not _reachable(lens):
        ideal = _ideal(near, far, d_min - s, d_max - s)
        raise GeometryError(
            f"no catalogue focusing lens brings the paraboloid ({near:.0f}..{far:.0f} mm from the lens) into the "
            f"projector's focus range {d_min:g}..{d_max:g} mm (projector.focus_min, focus_max): the nearest, f = {best:g} mm, needs "
            f"{lens.focus_near:.0f}..{lens.focus_far:.0f} mm (ideal f = {ideal:.1f} mm); give lens.focal_length",
            where=profile.where("projector", "focus_min"))
    return lens
