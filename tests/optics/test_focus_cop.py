"""The focusing lens moves the projector's COP as the paraboloid sees it and scales its pixels'
angles (rigcad.optics.focus.through_lens). Held against truths from outside the code: the Gaussian
lens equation for a thin lens, and an exact ray trace (Snell's law at both faces, written here) of
the plano-convex singlet the bill orders, curved side towards the projector."""

import math

import numpy as np
import pytest

from rigcad.optics.focus import LENS_INDEX, focusing_lens, through_lens
from rigcad.profile import derive


def _trace(angle: float, f: float, s: float, edge: float, diameter: float, n: float = LENS_INDEX):
    """One chief ray leaving the COP (the origin) at ``angle`` (rad) from the axis (+x), through the
    plano-convex lens centred ``s`` mm away (its edge ``edge`` thick at ``diameter``; surface radius
    f (n - 1), the curved face first): where it leaves the flat face and its direction (2D)."""
    radius = f * (n - 1)
    sag = radius - math.sqrt(radius ** 2 - (diameter / 2) ** 2)
    v1, v2 = s - edge / 2 - sag, s + edge / 2  # the curved vertex, the flat face
    centre = np.array([v1 + radius, 0.0])
    d = np.array([math.cos(angle), math.sin(angle)])
    oc = -centre
    b = oc @ d
    p = (-b - math.sqrt(b * b - (oc @ oc - radius ** 2))) * d  # the first hit on the sphere

    def refract(d, normal, eta):  # normal against the ray
        ci = -normal @ d
        return eta * d + (eta * ci - math.sqrt(1 - eta ** 2 * (1 - ci ** 2))) * normal

    d = refract(d, (p - centre) / radius, 1 / n)
    p = p + (v2 - p[0]) / d[0] * d
    return p, refract(d, np.array([-1.0, 0.0]), n)


def _seen_from(angle, *lens):
    """Where (x, mm; + towards the lens) the ray leaving the lens crosses the axis when extended back
    (the COP the paraboloid sees), and its tan over the ray's tan at the COP."""
    p, d = _trace(angle, *lens)
    return p[0] - p[1] / d[1] * d[0], (d[1] / d[0]) / math.tan(angle)


@pytest.mark.parametrize("f, s", [(300.0, 25.0), (100.0, 25.0), (75.0, 60.0), (500.0, 10.0)])
def test_a_thin_lens_moves_the_cop_to_its_virtual_image(f, s):
    """The thin lens (no thickness): the COP's image by the Gaussian lens equation (1/v - 1/u = 1/f,
    u = -s): virtual, v = s f / (s - f) on the projector's side; angles scale by u / v."""
    v = s * f / (s - f)
    shift, scale = through_lens(f, s)
    assert shift == pytest.approx(-v - s, rel=1e-12)  # the reviewer's thin-lens sum: 2.27 mm for (300, 25)
    assert 1 / scale == pytest.approx((-s) / v, rel=1e-12)
    assert through_lens(300.0, 25.0)[0] == pytest.approx(2.2727, abs=1e-4)


def test_the_ordered_lens_moves_the_cop_as_an_exact_trace_finds(table31):
    """The default rig's lens as the bill orders it (f = 300 mm N-BK7, 6 mm edge over 50 mm, curved
    side towards the projector), a real COP 25 mm from its centre: every chief ray, extended back from
    where it leaves the lens, crosses the axis 1.31 mm NEARER the lens than the real COP (the thin-lens
    sum's 2.27 mm away from it is the lens's thickness left out: its principal planes stand 2.7 mm
    apart), and its angle's tan is 1/1.071 of the COP's."""
    lens = focusing_lens(table31, derive(table31))
    args = (lens.focal_length, lens.lens_distance, table31.lens.thickness, table31.lens.diameter)
    assert args == (300.0, 25.0, 6.0, 50.0)
    shift, scale = through_lens(*args)
    x, ratio = _seen_from(math.radians(0.05), *args)  # paraxial
    assert -x == pytest.approx(shift, abs=1e-5)  # mm: a 0.05 deg ray is paraxial to ~2e-6 mm
    assert 1 / ratio == pytest.approx(scale, abs=1e-6)
    assert shift == pytest.approx(-1.311, abs=1e-3) and scale == pytest.approx(1.0713, abs=1e-4)
    rim = derive(table31).rim_angle_at_cop
    x, ratio = _seen_from(rim, *args)
    # the rim's ray (3.2 deg) meets the lens's spherical aberration: 0.007 mm, 5e-4 of the scale measured
    assert abs(-x - shift) < 0.02 and abs(1 / ratio - scale) < 1e-3


@pytest.mark.parametrize("degrees", [0.05, 1.0, 2.0, None])
def test_the_placed_projector_is_seen_at_the_design_cop(table31, degrees):
    """Where the tower places the projector (its real COP FocusingLens.cop_distance before the lens's
    centre, 26.14 mm for Table 3.1), every chief ray, traced exactly through the ordered lens (Snell at
    both faces) and extended back from where it leaves it, crosses the axis at the design COP,
    lens.distance (25 mm) before the lens's centre; and its angle's tan is the lensed pixel map's
    (LensedProjector.focal_px, rigcad.optics.focus.lensed_focal_px) over the bare one's."""
    from rigcad.optics.focus import lensed_focal_px

    geo = derive(table31)
    lens = focusing_lens(table31, geo)
    placed = (lens.focal_length, lens.cop_distance, table31.lens.thickness, table31.lens.diameter)
    assert lens.cop_distance == pytest.approx(26.138, abs=1e-3)
    angle = geo.rim_angle_at_cop if degrees is None else math.radians(degrees)
    x, ratio = _seen_from(angle, *placed)
    seen = lens.cop_distance - x  # the traced COP seen, before the lens's centre
    scale = lensed_focal_px(table31, geo) / geo.projector_focal_px
    if degrees == 0.05:  # paraxial: the closed form holds to the trace's round-off (measured 3e-7 mm, 4e-9)
        assert abs(seen - table31.lens.distance) < 1e-5 and abs(1 / ratio - scale) < 1e-6
    else:  # up to the rim's 3.2 deg the lens's spherical aberration: measured 0.0073 mm and 5.1e-4 at the rim
        assert abs(seen - table31.lens.distance) < 0.01 and abs(1 / ratio - scale) < 6e-4
    # the design COP within the tolerance the tower holds it to by a wide margin (it was 1.14 mm off)
    assert abs(seen - table31.lens.distance) < 0.01 * table31.tolerancing.projector_height


def test_the_projector_through_its_lens_shows_the_rim_where_a_trace_puts_it(table31):
    """The pixel radius of the paraboloid's rim through the lens (LensedProjector.pixel_radius) from
    the exact trace: the COP ray whose traced exit ray meets the rim, found by bisection, read in the
    projector's own pixels (focal_px tan of its angle at the real COP, where the tower puts it)."""
    geo = derive(table31)
    lens = focusing_lens(table31, geo)
    lensed = lens.projector(geo.projector_focal_px, geo.cop_z)
    args = (lens.focal_length, lens.cop_distance, table31.lens.thickness, table31.lens.diameter)
    # the rim's plane from the real COP, along the unfolded axis: the real COP stands behind the design's
    depth = geo.cop_z - geo.rim_z + (lens.cop_distance - lens.lens_distance)

    def height_at_rim(a):  # the exit ray's distance from the axis at the rim's plane
        p, d = _trace(a, *args)
        return p[1] + (depth - p[0]) * d[1] / d[0]

    lo, hi = 1e-4, 0.2
    for _ in range(80):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if height_at_rim(mid) < geo.rim_radius else (lo, mid)
    traced = geo.projector_focal_px * math.tan(lo)
    bare = geo.projector_focal_px * geo.rim_radius / (geo.cop_z - geo.rim_z)  # the design's map, no lens
    # 0.1 px: the paraxial model leaves out the spherical aberration at the rim (0.05 px measured, 5e-4 of it)
    assert lensed.pixel_radius(geo.rim_radius, geo.rim_z) == pytest.approx(traced, abs=0.1)
    assert traced / bare == pytest.approx(1.0757, abs=1e-3)  # the bare map's circle would be 7.6 % small


def test_a_design_ray_is_shown_through_the_lens_where_its_paraboloid_point_is(table31):
    """LensedProjector.ring_radius: the paraboloid point a design ray meets (found here by bisection
    along the ray against z = z_vertex - r^2 / (4 f_p)), seen from the lensed COP; the rim's angle
    gives the rim."""
    geo = derive(table31)
    lensed = focusing_lens(table31, geo).projector(geo.projector_focal_px, geo.cop_z)
    assert lensed.ring_radius(geo, geo.rim_angle_at_cop) == pytest.approx(
        lensed.pixel_radius(geo.rim_radius, geo.rim_z), rel=1e-12)
    for alpha in np.linspace(0.002, geo.rim_angle_at_cop, 7):
        lo, hi = 0.0, (geo.cop_z - geo.rim_z) / math.cos(alpha) + 1.0  # along the ray: above, then below the surface
        for _ in range(100):
            mid = (lo + hi) / 2
            r, z = mid * math.sin(alpha), geo.cop_z - mid * math.cos(alpha)
            lo, hi = (mid, hi) if z > geo.vertex_z - r * r / (4 * geo.focal_length) else (lo, mid)
        r, z = lo * math.sin(alpha), geo.cop_z - lo * math.cos(alpha)
        assert lensed.ring_radius(geo, alpha) == pytest.approx(lensed.pixel_radius(r, z), rel=1e-9)


@pytest.mark.parametrize("thick", [False, True])
def test_where_the_real_cop_must_stand_for_the_paraboloid_to_see_it_at_the_design(table31, thick):
    """cop_distance_for inverts through_lens: the COP placed where it says is seen at the design's
    distance, by the closed form and by the exact trace (thick lens); for Table 3.1 the projector
    stands 26.14 mm before the lens's centre, 1.14 mm farther than the 25 mm the paraboloid must see."""
    from rigcad.optics.focus import cop_distance_for

    size = (table31.lens.thickness, table31.lens.diameter) if thick else (0.0, 0.0)
    s = cop_distance_for(25.0, 300.0, *size)
    shift, _ = through_lens(300.0, s, *size)
    assert s + shift == pytest.approx(25.0, abs=1e-9)
    if thick:
        x, _ = _seen_from(math.radians(0.05), 300.0, s, *size)
        assert s - x == pytest.approx(25.0, abs=1e-5)  # the traced COP seen: 25 mm before the lens's centre
        assert s == pytest.approx(26.14, abs=0.01)
    else:
        assert s == pytest.approx(25.0 * 300.0 / 325.0, rel=1e-12)  # thin: s f / (f + s), the Gaussian inverse


def test_the_figures_docs_states(table31):
    """docs/calibration-focusing-lens.md's figures: the rim 100.3 px bare and 107.9 px through the
    placed lens (x 1.076), the COP 1.14 mm behind the design's (26.14 mm from the lens), the centre
    thickness 8.03 mm, the principal planes 2.7 mm apart, a 0.5 mm decentred lens moving the COP's
    image 0.04 mm."""
    geo = derive(table31)
    lens = focusing_lens(table31, geo)
    seen = lens.projector(geo.projector_focal_px, geo.cop_z)
    bare = geo.projector_focal_px * geo.rim_radius / (geo.cop_z - geo.rim_z)
    through = seen.ring_radius(geo, geo.rim_angle_at_cop)
    assert (round(bare, 1), round(through, 1), round(through / bare, 3)) == (100.3, 107.9, 1.076)
    assert (round(lens.cop_distance, 2), round(-seen.cop_shift, 2)) == (26.14, 1.14)
    assert (round(through_lens(300.0, 25.0, 6.0, 50.0)[0], 2), round(through_lens(300.0, 25.0, 6.0, 50.0)[1], 3)) == \
        (-1.31, 1.071)
    radius = 300.0 * (LENS_INDEX - 1)
    centre = 6.0 + radius - math.sqrt(radius ** 2 - 25.0 ** 2)
    assert round(centre, 2) == 8.03 and round(centre * (LENS_INDEX - 1) / LENS_INDEX, 1) == 2.7
    s_h = 25.0 - 3.0 - (centre - 6.0)
    assert round(0.5 * s_h / (300.0 - s_h), 2) == 0.04


def test_the_tower_puts_the_cop_the_paraboloid_sees_at_the_design_cop(table31_rig):
    """The COP tower as placed (rigcad.parts.tower.tower_layout): the chief rays from the projector's
    real COP (TowerLayout.projector_cop, looking -x), traced exactly through the ordered lens centred
    at TowerLayout.lens_x and extended back, cross the projector's axis at a point whose image in the
    splitter's front face is the design COP. Before the tower placed it through the lens, this point
    stood 1.31 mm off along the axis (tolerancing.projector_height: 1 mm)."""
    from rigcad.optics.splitter import mirror_point

    rig = table31_rig
    t, p = rig.layout.tower, rig.profile
    lens = focusing_lens(p, rig.geometry)
    distance = t.projector_cop[0] - t.lens_x  # the real COP before the lens's centre, along -x
    design = np.array([0.0, 0.0, rig.geometry.cop_z])
    for degrees, bound in ((0.05, 1e-5), (1.0, 0.01), (math.degrees(rig.geometry.rim_angle_at_cop), 0.01)):
        x, _ = _seen_from(math.radians(degrees), lens.focal_length, distance, p.lens.thickness, p.lens.diameter)
        seen = (t.projector_cop[0] - x, t.projector_cop[1], t.projector_cop[2])  # x: from the real COP towards -x
        err = float(np.linalg.norm(mirror_point(t.plate, seen) - design))
        # paraxial: the closed form to the trace's round-off; to the rim: the lens's spherical aberration
        # (0.0073 mm measured), a hundredth of tolerancing.projector_height
        assert err < bound, (degrees, err)
    assert err < 0.01 * p.tolerancing.projector_height


def test_the_basis_reads_the_projectors_pixels_through_the_lens_as_a_trace_does(table31_rig):
    """rigcad.basis draws the zonal images on the projector's pixel map through its lens: a pixel r px
    from the image centre leaves the real COP at atan(r / f) (f: the bare W x throw_ratio), and the
    exact trace through the placed lens sends it on from the design COP at the angle whose tan is
    r / f_map (basis.projector.device_map's focal length): within 6e-4 of it at the rim's radius (the
    lens's spherical aberration, measured 5.1e-4), 1e-6 paraxially. The bare map (f) errs by 7 %."""
    from rigcad.basis.projector import device_map
    from rigcad.optics.focus import lensed_focal_px

    rig = table31_rig
    g, p = rig.geometry, rig.profile
    m = device_map(rig, "projector")
    assert m.focal_px == lensed_focal_px(p, g) and m.cop_z == g.cop_z  # one home: optics.focus
    lens = focusing_lens(p, g)
    placed = (lens.focal_length, lens.cop_distance, p.lens.thickness, p.lens.diameter)
    rim_px = float(m.pixel_radius(np.array([m.alpha_max]))[0])
    for r, bound in ((0.5, 1e-6), (rim_px / 2, 3e-4), (rim_px, 6e-4)):
        _, d = _trace(math.atan(r / g.projector_focal_px), *placed)
        traced = d[1] / d[0]  # the tan of the ray leaving the lens
        assert abs(traced / (r / m.focal_px) - 1) < bound, (r, traced)
        assert abs(traced / (r / g.projector_focal_px) - 1) > 0.06  # the bare map is 7 % off
