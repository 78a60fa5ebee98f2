"""The compiled mesh reading (rigcad.check.meshtrace) against the numpy passes it replaces
(trace3d._trace over the same Embree scenes, ``vectorised=True``): ray for ray on the default
profile's meshes (its tessellation tolerances), smooth and facet normals, aligned and misaligned,
with rays lost to every cause."""

from __future__ import annotations

import numpy as np
import pytest

from rigcad.check import meshtrace
from rigcad.check import trace3d as T
from rigcad.check.scene import mesh_optics, mirror_meshes, share_scenes
from rigcad.check.sources import annulus_rays, pixel_rays
from rigcad.optics.frames import Pose


@pytest.fixture(scope="module")
def default_meshes(rig):
    """The default profile's mirror meshes at its own tessellation tolerances (~0.8 M triangles)."""
    return mesh_optics(mirror_meshes(rig, None), "smooth")


def _rays(rig, seed):
    """Annulus rays, rays aimed beyond the rim and inside the occlusion limit, and stray rays from
    around the paraboloid in every direction (they reach every status, ESCAPED_AFTER_DOME too)."""
    dm, geo = rig.incidence, rig.geometry
    rng = np.random.default_rng(seed)
    a = annulus_rays(dm, 20000, seed)
    r_rim = dm.pixel_radius(np.array([dm.alpha_max]))[0]
    rho, phi = rng.uniform(0, 1.3 * r_rim, 5000), rng.uniform(0, 2 * np.pi, 5000)
    b = pixel_rays(dm, rho * np.cos(phi), rho * np.sin(phi))
    m = 120000
    o = np.stack([rng.uniform(-80, 80, m), rng.uniform(-80, 80, m), rng.uniform(geo.vertex_z - 40, geo.vertex_z, m)],
                 axis=-1)
    d = rng.normal(size=(m, 3))
    return np.vstack([a.origins, b.origins, o]), np.vstack([a.dirs, b.dirs, d / np.linalg.norm(d, axis=1)[:, None]])


def _angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))


@pytest.mark.parametrize("mode", ["smooth", "mesh"])
@pytest.mark.parametrize("misaligned", [False, True])
def test_compiled_mesh_reading_equals_the_numpy_passes(rig, default_meshes, mode, misaligned):
    optics = share_scenes(default_meshes, mode)
    if misaligned:
        optics = optics.placed(Pose.misaligned((0.4, -0.3, 0.6), 0.003, (0.6, 0.8, 0.0), (0, 0, rig.geometry.vertex_z)),
                               Pose.misaligned((-0.5, 0.2, -0.4), 0.002, (1.0, 0.0, 0.0)))
    o, d = _rays(rig, 7)
    fast = T.trace(optics, o, d)
    ref = T.trace(optics, o, d, vectorised=True)
    assert fast.kernels == {"mesh_compiled": len(o)} and ref.kernels == {"vectorised": len(o)}
    assert np.array_equal(fast.status, ref.status) and np.array_equal(fast.segment, ref.segment)
    # not vacuous: every status occurs (a ray lost on every segment, to every cause), most land
    counts = np.bincount(ref.status, minlength=len(T.STATUS_NAMES))
    assert np.all(counts > 0), counts
    assert set(ref.segment.tolist()) == {0, 1, 2, 3}
    for name in ("p1", "p2", "v", "landing"):
        a, b = getattr(fast, name), getattr(ref, name)
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
    for name in ("path_length", "miss"):
        assert np.array_equal(np.isnan(getattr(fast, name)), np.isnan(getattr(ref, name))), name
    # Aligned, both paths do the same IEEE operations in the same order (the identity poses skip the
    # rotation; numba compiles without fastmath, so LLVM contracts nothing into FMA): the same bits,
    # in this process on this machine, whatever the CPU.
    if not misaligned:
        for name in ("p1", "p2", "v", "landing", "path_length", "miss"):
            assert np.array_equal(getattr(fast, name), getattr(ref, name), equal_nan=True), name
    # Misaligned, the numpy passes rotate with matmul, which runs in BLAS: the CPU picks its kernel,
    # its summation order and whether it fuses multiply-adds, while _mesh_kernels sums the same
    # terms in a loop of its own. Each rotated coordinate may then differ by a few ulps (u = 1.1e-16:
    # ~1e-13 mm at <= 600 mm, ~1e-16 in a unit direction). The re-intersection and reflection keep that
    # size, times a modest grazing factor on the stray rays (measured worst: 5e-12 mm on p2, 4e-14 rad
    # on v, with OpenBLAS Prescott, numba generic, numpy SIMD off); the landing point and path length
    # divide by |v_z| once more (t3 = -p2_z / v_z), so they are compared as error x |v_z| (measured
    # worst 1.3e-11 mm). Each bound is ~4-8x the measured worst and
    # far below the tessellation error (micrometres).
    reached = ~np.isnan(ref.p1[:, 0])
    assert np.max(np.abs(fast.p1[reached] - ref.p1[reached])) < 4e-11
    reached = ~np.isnan(ref.p2[:, 0])
    assert np.max(np.abs(fast.p2[reached] - ref.p2[reached])) < 4e-11
    assert np.max(_angle(fast.v[reached], ref.v[reached])) < 4e-13
    ok = ref.ok
    vz = np.abs(ref.v[ok, 2])
    assert np.max(np.linalg.norm(fast.landing[ok] - ref.landing[ok], axis=1) * vz) < 1e-10
    assert np.max(np.abs(fast.path_length[ok] - ref.path_length[ok]) * vz) < 1e-10
    assert np.max(np.abs(fast.miss[ok] - ref.miss[ok])) < 4e-12  # measured worst 3.3e-13 mm


def test_every_cast_goes_through_the_timed_raw_call(rig, default_meshes):
    optics = share_scenes(default_meshes, "smooth")
    timer = optics.timer
    o, d = _rays(rig, 8)
    timer.embree_rays, timer.calls, timer.keep_inputs = 0, [], True
    try:
        tr = T.trace(optics, o, d)
    finally:
        timer.keep_inputs = False
    calls, timer.calls = timer.calls, []
    blocks = -(-len(o) // meshtrace.BLOCK)
    assert blocks > 1  # the rays span several blocks
    assert [c[0] for c in calls] == [optics.paraboloid, optics.dome, optics.paraboloid, optics.beam] * blocks
    assert timer.embree_rays == sum(len(c[1]) for c in calls)
    # cast 1 takes every ray, cast 2 those on the mirror, casts 3 and 4 those going down from the dome
    on_mirror = ~np.isnan(tr.p1[:, 0])
    down = ~np.isnan(tr.p2[:, 0]) & (tr.status != T.ESCAPED_AFTER_DOME)
    assert [sum(len(c[1]) for c in calls[k::4]) for k in range(4)] == [len(o), on_mirror.sum(), down.sum(), down.sum()]
    assert all(c[1].dtype == np.float32 and c[2].dtype == np.float32 for c in calls)
    assert all(c[3] is None for c in calls[0::4] + calls[1::4])
    # tmax of the return casts (as recorded before Embree's call): the distance to z = 0, float32
    t3 = -tr.p2[down, 2] / tr.v[down, 2]
    for k in (2, 3):
        tmax = np.concatenate([c[3] for c in calls[k::4]])
        assert tmax.dtype == np.float32 and np.allclose(tmax, t3, rtol=1e-6, atol=0)
    # the recorded inputs are the trace's own (not scratch reused by the next block)
    assert not any(np.shares_memory(calls[k][1], calls[k + 4][1]) for k in range(4))


def test_edge_cases_and_readings_left_to_numpy(rig, default_meshes):
    optics = share_scenes(default_meshes, "mesh")
    empty = T.trace(optics, np.zeros((0, 3)), np.zeros((0, 3)))
    assert empty.status.shape == (0,) and empty.p1.shape == (0, 3)
    # every ray misses the paraboloid: no later cast; same as numpy
    o = np.tile([0.0, 0.0, 300.0], (5, 1))
    d = np.tile([0.0, 0.0, 1.0], (5, 1))
    fast, ref = T.trace(optics, o, d), T.trace(optics, o, d, vectorised=True)
    assert np.all(fast.status == T.MISSED_PARABOLOID) and np.array_equal(fast.segment, ref.segment)
    assert np.all(np.isnan(fast.p2)) and np.all(np.isnan(fast.miss))
    # the exact-normal and float32 readings, and mixed optics, keep the numpy passes
    assert meshtrace.supports(optics)
    assert not meshtrace.supports(share_scenes(default_meshes, "exact_normals"))
    assert not meshtrace.supports(share_scenes(default_meshes, "smooth", refine=False))
    o, d = _rays(rig, 9)
    assert T.trace(share_scenes(default_meshes, "exact_normals"), o[:100], d[:100]).kernels == {"vectorised": 100}
