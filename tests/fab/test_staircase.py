"""The staircase measured from actual slices against the closed form t |cos theta| on shapes
whose normals are known exactly: a sphere (every angle) and a cone (one angle)."""

from __future__ import annotations

import math

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.fab.orientation import Orientation
from rigcad.fab.staircase import closed_form_cusp, slice_layers, step_map


class Sphere:
    """Exact sphere of radius R at the origin, as a 'mirror' for step_map (outward = + side)."""

    def __init__(self, radius):
        self.r = radius

    def signed_distance(self, p):
        return np.linalg.norm(p, axis=1) - self.r

    def normals(self, p):
        return p / np.linalg.norm(p, axis=1, keepdims=True)


class Cone:
    """Exact cone z = h - r / tan(half) (apex up), lateral surface only."""

    def __init__(self, radius, height):
        self.r, self.h = radius, height
        self.n2 = np.array([height, radius]) / math.hypot(radius, height)  # (n_r, n_z), outward

    def signed_distance(self, p):
        rho = np.hypot(p[:, 0], p[:, 1])
        d = rho * self.n2[0] + p[:, 2] * self.n2[1] - self.r * self.n2[0]
        return np.where(p[:, 2] > 1e-6, d, np.inf)  # the base disc is not this surface

    def normals(self, p):
        phi = np.arctan2(p[:, 1], p[:, 0])
        return np.stack([self.n2[0] * np.cos(phi), self.n2[0] * np.sin(phi), np.full(len(p), self.n2[1])], axis=-1)


def _steps(man, surface, direction, layer, tol):
    rot = Orientation("t", direction).rotation()
    layers, shift = slice_layers(man, rot, layer)
    return layers, step_map(layers, rot, shift, surface, tol)


def test_sphere_slices_match_the_closed_form_within_5_percent():
    radius, layer = 40.0, 0.2
    man = m3d.Manifold.sphere(radius, 720)  # facets within R (1 - cos(pi/720)) = 0.38 um of the sphere
    layers, s = _steps(man, Sphere(radius), (0.0, 0.0, 1.0), layer, 0.01)
    assert layers.count == math.ceil(2 * radius / layer)
    ok = np.isfinite(s.cusp_slices)
    # away from the equator (cusp -> 0, relative error undefined) and from the poles (the last
    # layers' contours are tiny circles where the flat-surface closed form does not hold)
    band = ok & (s.cusp_closed > 0.1 * layer) & (s.cusp_closed < 0.98 * layer)
    rel = abs(s.cusp_slices[band].mean() - s.cusp_closed[band].mean()) / s.cusp_closed[band].mean()
    assert rel < 0.05, f"mean cusp from slices differs from t|cos theta| by {rel:.2%}"  # the 5 %
    # point by point: 5 % of a layer is the same bound in absolute terms
    err = np.abs(s.cusp_slices[band] - s.cusp_closed[band])
    assert np.percentile(err, 99) < 0.05 * layer, f"p99 point error {np.percentile(err, 99):.4f} mm"


def test_tilted_sphere_gives_the_same_map_as_upright():
    """A sphere is the same in every build direction: the mean cusp cannot depend on it."""
    radius, layer = 30.0, 0.15
    man = m3d.Manifold.sphere(radius, 480)
    _, up = _steps(man, Sphere(radius), (0.0, 0.0, 1.0), layer, 0.01)
    _, tilted = _steps(man, Sphere(radius), (1.0, 0.0, 1.0), layer, 0.01)
    a, b = np.nanmean(up.cusp_slices), np.nanmean(tilted.cusp_slices)
    assert abs(a - b) / a < 0.05, (a, b)  # same 5 % as the closed-form check


def test_cone_has_one_cusp_height():
    radius, height, layer = 30.0, 40.0, 0.2
    cone = m3d.Manifold.cylinder(height, radius, 0.0, 720)
    surface = Cone(radius, height)
    _, s = _steps(cone, surface, (0.0, 0.0, 1.0), layer, 0.01)
    expected = layer * surface.n2[1]  # t cos(theta), theta the angle between the normal and z
    ok = np.isfinite(s.cusp_slices) & (s.points[:, 2] < height - 2 * layer)  # not the apex's last layers
    rel = abs(np.median(s.cusp_slices[ok]) - expected) / expected
    assert rel < 0.05, f"cone cusp {np.median(s.cusp_slices[ok]):.5f} vs {expected:.5f} mm"  # the 5 %
    # the stepped surface straddles the true one: peak and valley are each half the cusp
    assert abs(np.median(s.peak[ok]) - expected / 2) < 0.05 * layer  # 5 % of a layer, as above
    assert abs(np.median(s.valley[ok]) + expected / 2) < 0.05 * layer


def test_closed_form_is_layer_times_cosine():
    n = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.6, 0.0, 0.8], [0.0, 0.6, -0.8]])
    c = closed_form_cusp(n, (0, 0, 1), 0.2)
    assert np.allclose(c, [0.2, 0.0, 0.16, 0.16], atol=1e-15)  # exact arithmetic up to rounding


# --- the summaries over faces and maps, on hand-made faces (closed forms) ------------------------

from rigcad.fab.mirror import MirrorFaces  # noqa: E402
from rigcad.fab.staircase import StepMap, optical_effect, polishing_allowance, surface_staircase  # noqa: E402


def _faces(normals, areas, centroids):
    n = len(areas)
    return MirrorFaces(np.arange(n), np.asarray(centroids, float), np.asarray(areas, float), np.asarray(normals, float))


def test_surface_staircase_is_the_area_weighted_closed_form():
    # a face facing the build direction (cusp t) of 1 mm2 and a wall along it (cusp 0) of 3 mm2
    f = _faces([[0, 0, 1], [1, 0, 0]], [1.0, 3.0], np.zeros((2, 3)))
    s = surface_staircase(f, (0.0, 0.0, 2.0), 0.2)  # the direction need not be a unit vector
    # mean 0.2/4, rms sqrt(0.04/4) = 0.1, max 0.2; 75 % of the area has cusp 0, so the 95th percentile is 0.2
    assert math.isclose(s["cusp_mean_mm"], 0.05, rel_tol=1e-15) and math.isclose(s["cusp_rms_mm"], 0.1, rel_tol=1e-15)
    assert s["cusp_max_mm"] == 0.2 and s["cusp_p95_mm"] == 0.2


def test_optical_effect_of_ideal_steps_on_two_faces():
    th = 0.3
    # face A normal to the build direction z, face B tilted by 0.3 rad; both 1 mm2, both 100 mm from O
    f = _faces([[0, 0, 1], [math.sin(th), 0, math.cos(th)]], [1.0, 1.0], [[0, 0, 100.0], [100.0, 0, 0]])
    e = optical_effect(f, (0.0, 0.0, 5.0), "dome")
    # treads: A error 0 (area 1), B error 0.3 (area cos 0.3); risers: B error pi/2 - 0.3 (area sin 0.3),
    # A's riser has no area. Area fractions of the total 1 + cos 0.3 + sin 0.3:
    tot = 1 + math.cos(th) + math.sin(th)
    fa, fb, fr = 1 / tot, math.cos(th) / tot, math.sin(th) / tot  # 0.444, 0.424, 0.131
    assert math.isclose(e["normal_error_median_deg"], math.degrees(th), rel_tol=1e-12)  # cdf 0.444, 0.869
    assert math.isclose(e["normal_error_p90_deg"], 90 - math.degrees(th), rel_tol=1e-12)
    assert math.isclose(e["ray_angle_error_median_deg"], 2 * math.degrees(th), rel_tol=1e-12)  # reflection doubles
    assert math.isclose(e["ray_angle_error_p90_deg"], 2 * (90 - math.degrees(th)), rel_tol=1e-12)
    assert math.isclose(e["area_fraction_within_1mrad"], fa, rel_tol=1e-12)
    h = e["histogram_normal_error_deg"]
    assert h["edges"] == list(range(0, 91, 10))
    # 0 deg in [0, 10), 17.2 deg in [10, 20), 72.8 deg in [70, 80)
    assert np.allclose(h["area_fraction"], [fa, fb, 0, 0, 0, 0, 0, fr, 0], rtol=1e-12, atol=0)
    # the median ray misses O by L tan(2 x 0.3 rad)
    assert math.isclose(e["miss_at_sample_median_mm"], 100 * math.tan(2 * th), rel_tol=1e-12)
    assert "miss_at_sample_median_mm" not in optical_effect(f, (0.0, 0.0, 1.0), "paraboloid")


def test_the_miss_at_the_sample_pairs_each_face_with_its_own_distance():
    # face A (normal to z) 100 mm from O, face B (tilted 0.3 rad) 50 mm from O: the median error is
    # B's tread, so the median miss is B's distance times tan(2 x 0.3 rad), not A's
    th = 0.3
    f = _faces([[0, 0, 1], [math.sin(th), 0, math.cos(th)]], [1.0, 1.0], [[0, 0, 100.0], [50.0, 0, 0]])
    e = optical_effect(f, (0.0, 0.0, 1.0), "dome")
    assert math.isclose(e["miss_at_sample_median_mm"], 50 * math.tan(2 * th), rel_tol=1e-12), e


def _map(cusp_slices, cusp_closed, peak, valley):
    n = len(peak)
    return StepMap((0.0, 0.0, 1.0), 0.2, np.zeros((n, 3)), np.asarray(cusp_slices, float), np.asarray(cusp_closed, float),
                   np.asarray(peak, float), np.asarray(valley, float))


def test_step_map_summary_and_polishing_allowance_by_hand():
    m = _map([0.1, np.nan, 0.3], [0.1, 0.2, 0.2], [0.1, 0.05, 0.02], [-0.05, -0.12, 0.01])
    s = m.summary()
    # the top layer's NaN is left out: slices (0.1, 0.3), closed form (0.1, 0.2) at the same points
    assert s["contour_points"] == 3
    assert math.isclose(s["cusp_from_slices_mean_mm"], 0.2) and s["cusp_from_slices_max_mm"] == 0.3
    assert math.isclose(s["cusp_closed_form_mean_mm"], 0.15)
    assert math.isclose(s["slices_vs_closed_form_mean_rel_diff"], 1 / 3)
    assert math.isclose(s["slices_vs_closed_form_max_abs_diff_mm"], 0.1)
    assert math.isclose(s["slices_vs_closed_form_p95_abs_diff_mm"], 0.095)  # linear between 0 and 0.1
    assert s["stepped_surface_peak_mm"] == 0.1 and s["stepped_surface_valley_mm"] == -0.12
    p = polishing_allowance(m)
    # sand peak to valley where it is deepest (0.05 + 0.12), add the deepest valley's 0.12 mm of stock
    assert math.isclose(p["sanding_depth_mm"], 0.17) and p["stock_to_add_mm"] == 0.12
    assert polishing_allowance(_map([0.1], [0.1], [0.3], [0.1]))["stock_to_add_mm"] == 0.0  # no valley below
    empty = _map([], [], [], [])
    assert polishing_allowance(empty) == {"sanding_depth_mm": 0.0, "stock_to_add_mm": 0.0}
    assert empty.summary()["cusp_from_slices_mean_mm"] is None and empty.summary()["stepped_surface_peak_mm"] is None


# --- slicing, the segment search and the step map on hand-made geometry (exact expectations) -----

from rigcad.fab.staircase import Layers, _segment_distance  # noqa: E402


def test_slice_layers_of_a_tetrahedron_off_the_origin():
    # a right-corner tetrahedron: base triangle (legs 4 and 3 mm) at z = 2 with its corner at (5, 7), apex
    # 1.1 mm above the corner. At height h the section is the base scaled by s = 1 - h / 1.1 about the
    # corner: a triangle of three vertices (a contour of three is a polygon). The part is lifted to the
    # bed by z only, and the layer tops are the first layer then one layer each up to the part's top.
    tet = m3d.Manifold.hull_points([(5.0, 7.0, 2.0), (9.0, 7.0, 2.0), (5.0, 10.0, 2.0), (5.0, 7.0, 3.1)])
    layers, shift = slice_layers(tet, np.eye(3), 0.2, first_layer=0.3)
    assert np.array_equal(shift, [0.0, 0.0, -2.0])  # printer = part + (0, 0, -2): on the bed, x and y kept
    # tops 0.3, 0.5, 0.7, 0.9, 1.1: mid-planes half a layer below each top (the first: half the first layer)
    assert np.allclose(layers.heights, [0.15, 0.4, 0.6, 0.8, 1.0], rtol=0, atol=1e-12)
    assert layers.layer == 0.2 and layers.count == 5
    for h, polys in zip(layers.heights, layers.contours):
        s = 1 - h / 1.1
        assert len(polys) == 1 and polys[0].shape == (3, 2)
        want = np.array([(5.0, 7.0), (5.0 + 4 * s, 7.0), (5.0, 7.0 + 3 * s)])
        got = polys[0][np.lexsort(polys[0].T[::-1])]
        # manifold3d intersects the edges to ~1e-9 mm here (measured 3e-9): 1e-6 mm is far below the 0.1 mm scale
        assert np.allclose(got, want[np.lexsort(want.T[::-1])], rtol=0, atol=1e-6), (got, want)
    # a part thinner than its first layer is one layer, whose mid-plane is half its first layer up
    slab = m3d.Manifold.cube((4.0, 3.0, 0.25))
    thin, _ = slice_layers(slab, np.eye(3), 0.2, first_layer=0.3)
    assert thin.count == 1 and np.allclose(thin.heights, [0.15], rtol=0, atol=1e-12)
    # without a first layer of its own, every layer is 0.2 mm: 1.1 mm is 6 layers (the last ends at 1.2)
    even, _ = slice_layers(tet, np.eye(3), 0.2)
    assert np.allclose(even.heights, 0.1 + 0.2 * np.arange(6), rtol=0, atol=1e-12)


def _brute_segment_distance(points, a, b):
    """Distance from each point to each segment by the closed form (projection inside the segment:
    perpendicular distance, else the nearer end), minimum over all segments."""
    out = []
    for p in points:
        best = math.inf
        for s, e in zip(a, b):
            d = e - s
            u = float((p - s) @ d) / float(d @ d)
            if 0.0 <= u <= 1.0:
                dist = abs(d[0] * (p - s)[1] - d[1] * (p - s)[0]) / math.hypot(*d)
            else:
                dist = min(math.hypot(*(p - s)), math.hypot(*(p - e)))
            best = min(best, dist)
        out.append(best)
    return np.array(out)


def test_segment_distance_equals_the_distance_to_the_polygon():
    # a 60-gon of radius 10 mm (edges 1.05 mm) and points up to 0.5 mm either side of it: the nearest
    # point is sometimes inside an edge and sometimes a vertex (points beyond an edge's ends)
    ang = 2 * math.pi * np.arange(60) / 60
    a = 10.0 * np.column_stack([np.cos(ang), np.sin(ang)])
    b = np.roll(a, -1, axis=0)
    rng = np.random.default_rng(11)
    phi, rho = rng.uniform(0, 2 * math.pi, 400), rng.uniform(9.5, 10.5, 400)
    pts = np.column_stack([rho * np.cos(phi), rho * np.sin(phi)])
    got, ref = _segment_distance(pts, a, b), _brute_segment_distance(pts, a, b)
    # the same distances by two formulas: round-off of products of O(10) mm
    assert np.max(np.abs(got - ref)) < 1e-12, np.max(np.abs(got - ref))


class _ConeInPrinter:
    """A cone around the printer's z axis, radius R0 - (z - z0) delta / t, as a 'mirror' seen in
    the part frame (part -> printer: rotation @ p + shift); + side outward."""

    def __init__(self, rotation, shift, r0, z0, delta, t):
        self.rot, self.shift, self.r0, self.z0, self.slope = rotation, shift, r0, z0, delta / t
        self.norm = math.sqrt(1 + self.slope ** 2)

    def signed_distance(self, p):
        q = p @ self.rot.T + self.shift
        rho = np.hypot(q[:, 0], q[:, 1])
        return (rho - (self.r0 - (q[:, 2] - self.z0) * self.slope)) / self.norm  # distance to the meridian line

    def normals(self, p):
        q = p @ self.rot.T + self.shift
        phi = np.arctan2(q[:, 1], q[:, 0])
        n = np.column_stack([np.cos(phi), np.sin(phi), np.full(len(q), self.slope)]) / self.norm
        return n @ self.rot  # printer -> part


def _cone_layers(n_gon, count, t, r0, delta, gap=None):
    """Layer k: a regular n-gon of circumradius r0 - k delta turned by k half-steps (slicers' vertices
    do not line up layer to layer), plus a small square at the centre that is not on the mirror;
    layer ``gap`` is empty (a layer with no contour). Mid-planes (k + 1/2) t."""
    contours = []
    for k in range(count):
        ang = 2 * math.pi * np.arange(n_gon) / n_gon + k * math.pi / n_gon
        gon = (r0 - k * delta) * np.column_stack([np.cos(ang), np.sin(ang)])
        square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
        contours.append([] if k == gap else [gon, square])
    return Layers(t, (np.arange(count) + 0.5) * t, contours)


def test_step_map_of_a_stepped_cone_by_hand():
    n_gon, count, t, r0, delta = 12, 6, 0.2, 10.0, 0.1
    rot = Orientation("t", (1.0, 0.0, 1.0), spin=0.4).rotation()
    shift = np.array([3.0, -2.0, 5.0])
    cone = _ConeInPrinter(rot, shift, r0, 0.5 * t, delta, t)
    layers = _cone_layers(n_gon, count, t, r0, delta)
    s = step_map(layers, rot, shift, cone, 1e-9)
    # every polygon vertex is on the cone, no vertex of the centre squares is
    assert s.points.shape == (count * n_gon, 3) and np.max(np.abs(cone.signed_distance(s.points))) < 1e-12
    assert s.direction == pytest.approx(tuple(rot.T @ [0.0, 0.0, 1.0]), abs=1e-15) and s.layer == t
    # a vertex of layer k is r_k from the axis on the bisector of an edge of layer k + 1 (turned by half
    # a step): the horizontal step is r_k - r_(k+1) cos(pi / n), the cusp t D / sqrt(t^2 + D^2)
    r = r0 - delta * np.arange(count)
    step = r[:-1] - r[1:] * math.cos(math.pi / n_gon)
    cusp = np.repeat(t * step / np.sqrt(t * t + step * step), n_gon)
    assert np.allclose(s.cusp_slices[:-n_gon], cusp, rtol=1e-12, atol=0)
    assert np.all(np.isnan(s.cusp_slices[-n_gon:]))  # the top layer has no next layer
    # closed form t |n . D|: the cone's normal makes cos theta = (delta/t) / sqrt(1 + (delta/t)^2) with z
    assert np.allclose(s.cusp_closed, t * delta / math.hypot(t, delta), rtol=1e-12, atol=0)
    # the step's corners half a layer above and below: +- (delta / 2) / sqrt(1 + (delta/t)^2)
    half = 0.5 * delta / math.hypot(1.0, delta / t)
    assert np.allclose(s.peak, half, rtol=1e-9, atol=0) and np.allclose(s.valley, -half, rtol=1e-9, atol=0)


def test_step_map_keeps_every_kth_vertex_and_skips_an_empty_layer():
    n_gon, count, t, r0, delta = 12, 6, 0.2, 10.0, 0.1
    rot, shift = np.eye(3), np.zeros(3)
    cone = _ConeInPrinter(rot, shift, r0, 0.5 * t, delta, t)
    # 96 contour vertices (12-gon and square per layer): at most 32 points -> every 3rd vertex of each
    # layer's 16: 0, 3, 6, 9 on the 12-gon, 12 and 15 on the square (not on the mirror)
    few = step_map(_cone_layers(n_gon, count, t, r0, delta), rot, shift, cone, 1e-9, max_points=32)
    assert len(few.points) == 4 * count
    # at most 6: every 16th vertex, the first of each layer: one point per layer
    one = step_map(_cone_layers(n_gon, count, t, r0, delta), rot, shift, cone, 1e-9, max_points=6)
    assert len(one.points) == count and np.sum(np.isfinite(one.cusp_slices)) == count - 1
    # layer 3 empty: layers 0, 1 and 4 have a next layer; 2 (below the gap) and 5 (the top) do not
    gap = step_map(_cone_layers(n_gon, count, t, r0, delta, gap=3), rot, shift, cone, 1e-9)
    assert len(gap.points) == (count - 1) * n_gon
    finite = np.isfinite(gap.cusp_slices).reshape(count - 1, n_gon).all(axis=1)
    assert finite.tolist() == [True, True, False, True, False]


def test_step_map_with_no_point_on_the_mirror_is_empty():
    t = 0.2
    far = _ConeInPrinter(np.eye(3), np.zeros(3), 50.0, 0.0, 0.1, t)  # 40 mm outside every contour
    s = step_map(_cone_layers(12, 4, t, 10.0, 0.1), np.eye(3), np.zeros(3), far, 1e-3)
    assert s.direction == (0.0, 0.0, 1.0) and s.layer == t and s.points.shape == (0, 3)
    for a in (s.cusp_slices, s.cusp_closed, s.peak, s.valley):
        assert isinstance(a, np.ndarray) and a.shape == (0,)
    assert s.summary()["contour_points"] == 0 and polishing_allowance(s)["sanding_depth_mm"] == 0.0


def test_optical_effect_p90_below_the_largest_error():
    # A facing z, B tilted 0.1 rad, 1 mm2 each: area fractions (1, cos 0.1, sin 0.1) / total = 0.477, 0.475,
    # 0.048 for errors 0, 0.1 and pi/2 - 0.1 rad: the 90th percentile is B's tread, not the largest error
    th = 0.1
    f = _faces([[0, 0, 1], [math.sin(th), 0, math.cos(th)]], [1.0, 1.0], [[0, 0, 100.0], [100.0, 0, 0]])
    e = optical_effect(f, (0.0, 0.0, 1.0), "paraboloid")
    assert math.isclose(e["normal_error_p90_deg"], math.degrees(th), rel_tol=1e-12)
    assert math.isclose(e["ray_angle_error_p90_deg"], 2 * math.degrees(th), rel_tol=1e-12)


def test_faces_facing_the_build_direction_have_no_error():
    # unit normals along the unit build direction: |n . D| is 1 up to rounding, and may round above 1
    # (for (1, 1, 1) / sqrt(3) it does on x86-64 with numpy's dot); the error is 0, never NaN
    dirs = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 2.0], [2.0, 1.0, 3.0], [1.0, 4.0, 4.0]])
    for d in dirs:
        n = d / np.linalg.norm(d)
        e = optical_effect(_faces([n], [1.0], [[0.0, 0.0, 100.0]]), tuple(d), "dome")
        assert e["normal_error_median_deg"] == 0.0 and e["area_fraction_within_1mrad"] == 1.0, (d, e)
        assert e["histogram_normal_error_deg"]["area_fraction"][0] == 1.0 and e["miss_at_sample_median_mm"] == 0.0


def test_a_ray_turned_past_89_degrees_misses_by_l_tan_89():
    # one face at 44.6 deg to z: its tread (error 44.6 deg) holds the larger area cos 44.6 > sin 44.6, so
    # it is the median; the reflected ray turns by 89.2 deg, clipped at 89 deg: miss L tan(89 deg)
    th = math.radians(44.6)
    f = _faces([[math.sin(th), 0, math.cos(th)]], [1.0], [[0.0, 0.0, 100.0]])
    e = optical_effect(f, (0.0, 0.0, 1.0), "dome")
    assert math.isclose(e["normal_error_median_deg"], 44.6, rel_tol=1e-12)
    assert math.isclose(e["miss_at_sample_median_mm"], 100 * math.tan(math.radians(89.0)), rel_tol=1e-12)


def test_step_map_summary_without_a_closed_form_cusp():
    # walls along the build direction: closed-form cusp 0, so the relative difference is undefined (None);
    # an empty map has no figure at all
    s = _map([0.01, 0.02], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]).summary()
    assert s["slices_vs_closed_form_mean_rel_diff"] is None and s["cusp_closed_form_mean_mm"] == 0.0
    empty = _map([], [], [], []).summary()
    assert empty["contour_points"] == 0 and all(v is None for k, v in empty.items() if k != "contour_points"), empty
