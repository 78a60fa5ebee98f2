"""The staircase measured from actual slices against the closed form t |cos theta| on shapes
whose normals are known exactly: a sphere (every angle) and a cone (one angle)."""

from __future__ import annotations

import math

import manifold3d as m3d
import numpy as np

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
