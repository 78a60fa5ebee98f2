"""Intersectors: Embree against the float64 brute-force reference hit for hit, the float64
refinement, the exact surfaces against their own definitions."""

from __future__ import annotations

import numpy as np
import pytest

from rigcad.check import rays as R
from rigcad.check.sources import annulus_rays


def _paraboloid_rays(design_map, n, seed):
    r = annulus_rays(design_map, n, seed)
    return r.origins, r.dirs


def test_embree_is_the_backend_and_agrees_with_the_float64_reference_hit_for_hit(coarse_meshes, design_map):
    # Not skipped when embreex is missing: it is a pinned dependency, so its absence is a failure.
    R.require_embree()
    mesh = coarse_meshes.paraboloid
    # (the reference tests every ray against every triangle, ~25 ms a ray: 440 rays)
    o, d = _paraboloid_rays(design_map, 320, 1)
    # add rays that miss (beyond the rim) so that misses are compared too
    o2, d2 = _paraboloid_rays(design_map, 120, 2)
    d2[:, :2] *= 1.3
    o, d = np.vstack([o, o2]), R.unit(np.vstack([d, d2]))
    emb = R.EmbreeMesh([mesh], "vertex").intersect(o, d)
    ref = R.NumpyMesh([mesh], "vertex").intersect(o, d)
    hit = np.isfinite(ref.t)
    # not vacuous: most rays hit, some miss
    assert hit.sum() > 300 and (~hit).sum() > 20, (hit.sum(), (~hit).sum())
    assert np.array_equal(np.isfinite(emb.t), hit), "Embree and the reference disagree on which rays hit"
    # both re-intersect the same triangle in float64 (or, on an edge, its neighbour: same plane
    # to within the facet angle x the float32 edge error): distances agree to 1e-9 mm
    assert np.max(np.abs(emb.t[hit] - ref.t[hit])) < 1e-9
    # interpolated normals: same barycentrics up to rounding, 1e-9 rad. The angle between unit
    # vectors as atan2(|a x b|, a . b): well conditioned at 0, where arccos(a . b) cannot resolve
    # below sqrt(2 eps) ~ 1.5e-8 rad
    a, b = emb.normal[hit], ref.normal[hit]
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    assert np.max(angle) < 1e-9, np.max(angle)


def test_float64_refinement_beats_embrees_float32_hit(coarse_meshes, design_map):
    mesh = coarse_meshes.dome
    o, d = _paraboloid_rays(design_map, 3000, 3)
    para = R.ExactParaboloid(*_para_args(coarse_meshes))
    h = para.intersect(o, d)
    ok = np.isfinite(h.t)
    p = o[ok] + h.t[ok, None] * d[ok]
    u = d[ok] - 2 * np.sum(d[ok] * h.normal[ok], axis=1)[:, None] * h.normal[ok]
    refined = R.EmbreeMesh([mesh], "facet").intersect(p, u)
    raw = R.EmbreeMesh([mesh], "facet", refine=False).intersect(p, u)
    both = np.isfinite(refined.t) & np.isfinite(raw.t)
    assert both.sum() > 2500
    err_raw = np.abs(raw.t[both] - refined.t[both])
    # float32 at ~200 mm resolves ~1.5e-5 mm: the raw distances differ by about that, never by
    # more than a few hundred ulps (1e-2 mm would be a wrong triangle)
    assert 1e-8 < np.median(err_raw) < 1e-3, np.median(err_raw)
    # Embree's Ng is our right-hand facet normal, same sign (float32 rounding: ~1e-7 in cos)
    cosang = np.sum(raw.normal[both] * refined.normal[both], axis=1)
    assert np.min(cosang) > 1 - 1e-6


def _para_args(meshes):
    m = meshes.paraboloid.meridian
    return m._focal_length, m._vertex_z, -m.u_range[0]


def test_exact_surfaces_hit_their_own_definitions(rig, design_map, analytic):
    geo = rig.geometry
    o, d = _paraboloid_rays(design_map, 5000, 4)
    para = R.ExactParaboloid(geo.focal_length, geo.vertex_z, geo.rim_radius)
    h = para.intersect(o, d)
    assert np.all(np.isfinite(h.t)), "every ray aimed at the useful annulus hits the paraboloid"
    p = o + h.t[:, None] * d
    resid = p[:, 2] - (geo.vertex_z - (p[:, 0] ** 2 + p[:, 1] ** 2) / (4 * geo.focal_length))
    # closed form in float64 at z ~ 150 mm: rounding, 1e-11 mm
    assert np.max(np.abs(resid)) < 1e-10
    u = d - 2 * np.sum(d * h.normal, axis=1)[:, None] * h.normal
    dome = R.ExactDome(rig.layout.design_dome)
    hd = dome.intersect(p, u)
    ok = np.isfinite(hd.t)
    assert ok.mean() > 0.99, "rays from the useful annulus reach the dome"
    q = p[ok] + hd.t[ok, None] * u[ok]
    rz = np.stack([np.hypot(q[:, 0], q[:, 1]), q[:, 2]], axis=-1)
    m = rig.layout.design_dome
    table_u = m.sample(20001)
    uu = np.interp(rz[:, 1], m.points(table_u)[:, 1], table_u)  # z rises monotonically along the dome
    # Newton on the spline: the hit lies on the meridian to 1e-9 mm (its radius at the hit's height)
    from scipy.optimize import brentq  # independent of the checker's Newton: a root of z(u) = z_hit
    for k in range(0, len(q), 500):
        uk = brentq(lambda v: m.points(np.array([v]))[0, 1] - rz[k, 1], uu[k] - 0.05, uu[k] + 0.05, xtol=1e-15)
        assert abs(m.points(np.array([uk]))[0, 0] - rz[k, 0]) < 1e-9


def test_occluder_primitives():
    box = R.Box((-1, -1, -1), (1, 1, 1))
    o = np.array([[-5.0, 0, 0], [-5.0, 3, 0], [0.0, 0, 0]])
    d = np.array([[1.0, 0, 0], [1.0, 0, 0], [0, 0, 1.0]])
    h = box.intersect(o, d)
    assert h.t[0] == 4.0 and np.isinf(h.t[1]) and h.t[2] == 0.0
    cyl = R.ZCylinder(2.0, 0.0, 1.0)
    h = cyl.intersect(np.array([[-5.0, 0, 0.5], [-5.0, 0, 1.5]]), np.array([[1.0, 0, 0], [1.0, 0, 0]]))
    assert abs(h.t[0] - 3.0) < 1e-12 and np.isinf(h.t[1])


@pytest.mark.parametrize("shift_mm", [0.0, 1.0])
def test_axisymmetric_fast_path_agrees_with_the_general_dome_intersection(rig, analytic, design_map, shift_mm,
                                                                         monkeypatch):
    """The exact dome first tries Newton from the design's own correspondence (exact when aligned);
    the general bracketing path must give the same hits, and an aligned rig must never need it."""
    from rigcad.check.sources import annulus_rays
    from rigcad.optics.vec import reflect_rows as reflect

    dome = analytic.dome.members[0]
    src = annulus_rays(design_map, 5000, 3)
    origins = src.origins + np.array([shift_mm, 0.0, 0.0])  # a shifted COP: rays off the correspondence
    h1 = analytic.paraboloid.intersect(origins, src.dirs)
    on = h1.part == 0
    o = origins[on] + h1.t[on, None] * src.dirs[on]
    u = reflect(src.dirs[on], h1.normal[on])
    general_calls = []
    bracketed = type(dome)._bracketed

    def counting(self, oo, dd):
        general_calls.append(len(oo))
        return bracketed(self, oo, dd)

    monkeypatch.setattr(type(dome), "_bracketed", counting)
    fast = dome.intersect(o, u)
    idx, t_general, _ = bracketed(dome, o, u)
    assert np.array_equal(np.sort(np.nonzero(fast.part == 0)[0]), np.sort(idx))  # same rays hit
    # same hits: both are Newton-polished on the same spline (round-off on ~300 mm coordinates)
    assert np.max(np.abs(fast.t[idx] - t_general)) < 1e-9
    if shift_mm == 0.0:
        assert sum(general_calls) == 0  # aligned: every ray takes the fast path


def test_table_lookup_is_np_interp():
    from rigcad.optics.incidence import _lookup

    grid = np.linspace(0.05, 0.3, 4097)
    values = np.sin(7 * grid)
    x = np.concatenate([np.random.default_rng(1).uniform(0.0, 0.4, 5000), [np.nan, grid[0], grid[-1]]])
    # same linear interpolation (ends clamped like np.interp), computed without a binary search
    assert np.allclose(_lookup(x, (grid, values)), np.interp(x, grid, values), rtol=0, atol=1e-15, equal_nan=True)
