import numpy as np

from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.vec import reflect, unit

PARA = Paraboloid(focal_length=2.98, vertex_z=157.5, rim_radius=16.38, dx=0.7)


def test_intersect_agrees_with_dense_sampling():
    rng = np.random.default_rng(3)
    n = 200
    origins = np.column_stack([rng.uniform(-30, 30, n), rng.uniform(170, 450, n)])
    targets = np.column_stack([rng.uniform(-16, 17, n), rng.uniform(130, 150, n)])
    dirs = unit(targets - origins)
    lam = PARA.intersect(origins, dirs)
    # Reference: march along each ray and find the first sign change of z - z_surface(x).
    ls = np.linspace(0, 400, 400001)
    for i in range(n):
        pts = origins[i] + ls[:, None] * dirs[i]
        inside = np.abs(pts[:, 0] - PARA.dx) <= PARA.rim_radius
        below = (pts[:, 1] <= PARA.z(pts[:, 0])) & inside
        hit = np.argmax(below) if below.any() else None
        if hit is None:
            assert np.isnan(lam[i]), i
        else:
            # the march resolves the hit to its 1 um step (plus grazing slop near the rim)
            assert abs(lam[i] - ls[hit]) < 2e-3, (i, lam[i], ls[hit])


def test_normals_are_perpendicular_to_the_surface():
    x = np.linspace(-16 + PARA.dx, 16 + PARA.dx, 33)
    h = 1e-6
    tangent = unit(PARA.point(x + h) - PARA.point(x - h))
    assert np.max(np.abs(np.sum(tangent * PARA.normal(x), axis=1))) < 1e-8  # central-difference error ~h^2


def test_reflection_keeps_length_and_flips_normal_component():
    rng = np.random.default_rng(0)
    d = unit(rng.normal(size=(50, 2)))
    n = unit(rng.normal(size=(50, 2)))
    r = reflect(d, n)
    assert np.allclose(np.linalg.norm(r, axis=1), 1.0, atol=1e-14)
    assert np.allclose(np.sum(r * n, axis=1), -np.sum(d * n, axis=1), atol=1e-14)


def test_parallel_rays_reflect_through_the_focus():
    # Closed form: a paraboloid sends axis-parallel rays through (virtually) its focus.
    p = Paraboloid(focal_length=3.0, vertex_z=100.0, rim_radius=16.0)
    x = np.linspace(-15.5, 15.5, 21)
    origins = np.column_stack([x, np.full_like(x, 200.0)])
    dirs = np.tile([0.0, -1.0], (len(x), 1))
    P = origins + p.intersect(origins, dirs)[:, None] * dirs
    u = reflect(dirs, p.normal(P[:, 0]))
    rel = p.focus - P
    miss = np.abs(rel[:, 0] * u[:, 1] - rel[:, 1] * u[:, 0])
    assert miss.max() < 1e-12 * 100  # float64 round-off on 100 mm coordinates


def test_rays_through_the_rim_count_whichever_way_they_rounded():
    """The design's rays pass exactly through the rim (the dome's occlusion end is defined by the
    ray that grazes it; the outermost COP ray hits it): their crossing with the rim chord or the
    surface rounds a few ulps either way, differently on different CPUs. Within RIM_RTOL of the rim
    both intersect (a hit) and blocks (the surface or the rim chord) count them."""
    corner = np.array([PARA.dx + PARA.rim_radius, PARA.rim_z])
    src = np.array([PARA.dx, PARA.rim_z + 200.0])  # above, inside: down through the rim corner
    u = unit((corner - src)[None])[0]
    dirs = [u]
    for k in range(1, 4):  # turned k ulps outwards (the crossing falls just beyond the rim)
        dirs.append(np.array([np.nextafter(dirs[-1][0], np.inf), dirs[-1][1]]))
    dirs = np.array(dirs)
    origins = np.tile(src, (len(dirs), 1))
    lam = PARA.intersect(origins, dirs)
    assert np.all(np.isfinite(lam)) and np.all(np.abs(lam - np.linalg.norm(corner - src)) < 1e-9), lam
    # from below the chord, up and outwards through the corner
    below = np.array([PARA.dx + PARA.rim_radius - 10.0, PARA.rim_z - 10.0])
    v = unit((corner - below)[None])[0]
    vs = [v]
    for k in range(1, 4):
        vs.append(np.array([np.nextafter(vs[-1][0], np.inf), vs[-1][1]]))
    vs = np.array(vs)
    assert PARA.blocks(np.tile(below, (len(vs), 1)), vs, np.full(len(vs), 100.0)).all()


def test_blocks_segments_through_the_rim_chord_or_the_surface_and_no_others():
    """Segments built from where they cross the body's rim chord (z = rim_z, |x - dx| <= rim) at a
    known distance l: blocked when they reach it (l < length, from 0.5 mm or 10 mm below), not when
    they stop 0.5 mm short, not when the crossing lies outside the rim; a segment through the surface
    is blocked, one that stops 0.5 mm before the surface is not."""
    v = unit(np.array([[0.3, 1.0]]))[0]
    rim, dx, zc = PARA.rim_radius, PARA.dx, PARA.rim_z
    cases = []  # (origin, direction, length, blocked)
    for x_at_chord, l in ((dx - rim + 4.0, 10.0), (dx + rim - 0.5, 0.5), (dx + 2.0, 10.0)):
        origin = np.array([x_at_chord, zc]) - l * v
        cases += [(origin, v, l + 0.5, True), (origin, v, l - 0.4, False)]
    outside = np.array([dx + rim + 0.5, zc]) - 10.0 * v
    cases.append((outside, v, 10.5, False))
    down = np.array([0.0, -1.0])
    above = np.array([dx + 5.0, PARA.z(dx + 5.0) + 3.0])  # 3 mm above the surface, going down
    cases += [(above, down, 3.5, True), (above, down, 2.5, False)]
    origins = np.array([c[0] for c in cases])
    dirs = np.array([c[1] for c in cases])
    lengths = np.array([c[2] for c in cases])
    expected = np.array([c[3] for c in cases])
    assert np.array_equal(PARA.blocks(origins, dirs, lengths), expected)


def _first_hit_exact(p, origin, direction):
    """The ray's first positive root of (X + l d_x)^2 + 4 f (z0 + l d_z - z_v) = 0 in 60-digit decimals
    (the float inputs taken exactly), textbook formula: the reference for float64 accuracy."""
    from decimal import Decimal, getcontext

    getcontext().prec = 60
    D = Decimal
    X = D(float(origin[0])) - D(p.dx)
    dx, dz = D(float(direction[0])), D(float(direction[1]))
    a = dx * dx
    b = 2 * X * dx + 4 * D(p.focal_length) * dz
    c = X * X + 4 * D(p.focal_length) * (D(float(origin[1])) - D(p.vertex_z))
    sq = (b * b - 4 * a * c).sqrt()
    return min(r for r in ((-b - sq) / (2 * a), (-b + sq) / (2 * a)) if r > 0)


def test_intersect_is_float_accurate_for_a_steep_ray_just_above_the_surface():
    """A near-vertical ray (a = d_x^2 ~ 1e-8) from 0.5 mm above the surface: the far root is ~1e9 mm
    away, the near one ~0.5 mm; the cancellation-free formula gets the near one to float precision
    (the textbook formula would lose ~1e-7 mm to cancellation), and a hit 0.5 mm away is a hit."""
    d = unit(np.array([[1e-4, -1.0], [-2e-4, -1.0], [3e-5, -1.0]]))
    x = np.array([3.0, -9.0, 12.0]) + PARA.dx
    origins = np.column_stack([x, PARA.z(x) + 0.5])
    lam = PARA.intersect(origins, d)
    exact = np.array([float(_first_hit_exact(PARA, o, v)) for o, v in zip(origins, d)])
    assert np.all((exact > 0.49) & (exact < 0.51))
    assert np.max(np.abs(lam - exact)) < 1e-12, lam - exact


def test_a_horizontal_ray_through_the_vertex_touches_it():
    """Tangent at the vertex: the discriminant is exactly 0 (a double root), still a hit, at the vertex."""
    origin = np.array([[PARA.dx - 3.0, PARA.vertex_z]])
    lam = PARA.intersect(origin, np.array([[1.0, 0.0]]))
    assert lam[0] == 3.0
