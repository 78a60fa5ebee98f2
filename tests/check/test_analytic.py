"""The compiled analytic tracer (rigcad.check.analytic) against the vectorised exact path that
brackets every dome hit and polishes it by Newton (rays.ExactDome(correspondence=False)): ray for
ray, aligned (the kernel reading its table of the exact meridional trace) and misaligned (Newton
from the design's correspondence)."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from rigcad.check import _kernels as K
from rigcad.check import rays as R
from rigcad.check import trace3d as T
from rigcad.check.sources import annulus_rays, pixel_rays, thin_lens_rays
from rigcad.optics.frames import Pose


@pytest.fixture(scope="module")
def reference(analytic, rig):
    """The same exact surfaces traced by numpy passes, every dome hit by bracketing + Newton."""
    ref = copy.copy(analytic)
    ref.fast = None
    ref.dome = R.Group([R.ExactDome(rig.layout.design_dome, correspondence=False), analytic.dome.members[1]])
    return ref


def _angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))


def _rays(design_map, n, seed):
    """Annulus rays plus rays aimed beyond the rim and inside the occlusion limit (misses, escapes)."""
    a = annulus_rays(design_map, n, seed)
    rng = np.random.default_rng(seed)
    r_rim = design_map.pixel_radius(np.array([design_map.alpha_max]))[0]
    rho = rng.uniform(0, 1.3 * r_rim, n // 5)
    phi = rng.uniform(0, 2 * np.pi, n // 5)
    b = pixel_rays(design_map, rho * np.cos(phi), rho * np.sin(phi))
    return np.vstack([a.origins, b.origins]), np.vstack([a.dirs, b.dirs])


def test_status_codes_match_trace3d():
    assert (K.OK, K.MISSED_PARABOLOID, K.OCCLUDED_BY_MOUNT, K.OCCLUDED_BY_BEAM, K.OCCLUDED_BY_PARABOLOID,
            K.ESCAPED_TOP, K.MISSED_DOME, K.ESCAPED_AFTER_DOME) == tuple(range(8))
    assert (T.OK, T.MISSED_PARABOLOID, T.OCCLUDED_BY_MOUNT, T.OCCLUDED_BY_BEAM, T.OCCLUDED_BY_PARABOLOID,
            T.ESCAPED_TOP, T.MISSED_DOME, T.ESCAPED_AFTER_DOME) == tuple(range(8))


def test_aligned_kernel_agrees_with_the_exact_newton_path_ray_for_ray(analytic, reference, design_map):
    o, d = _rays(design_map, 20000, 11)
    fast = T.trace(analytic, o, d)
    ref = T.trace(reference, o, d)
    assert fast.kernels["pinhole_aligned"] > 0.95 * len(o), fast.kernels  # the table kernel ran
    assert np.array_equal(fast.status, ref.status) and np.array_equal(fast.segment, ref.segment)
    # not vacuous: rays reach O, and rays are lost to every cause this aim produces
    assert fast.ok.sum() > 15000 and len(set(fast.status.tolist())) >= 4, np.bincount(fast.status)
    ok = ref.ok
    for name in ("p1", "p2"):
        err = np.max(np.linalg.norm(getattr(fast, name)[ok] - getattr(ref, name)[ok], axis=1))
        # the bound for the aligned trace: 1e-9 mm (measured ~3e-13: the table's cubic
        # interpolation error, table_error, and float64 round-off at ~300 mm)
        assert err < 1e-9, (name, err)
    assert np.max(np.abs(fast.miss[ok] - ref.miss[ok])) < 1e-9
    # the return directions: 1e-12 rad (measured ~4e-15)
    assert np.max(_angle(fast.v[ok], ref.v[ok])) < 1e-12
    # the landing point is ill-conditioned at grazing incidence (t to z = 0 grows as 1/cos theta):
    # 1e-9 mm up to 80 deg
    steep = ok & (ref.theta < np.radians(80))
    assert np.max(np.linalg.norm(fast.landing[steep] - ref.landing[steep], axis=1)) < 1e-9
    assert analytic.fast.table_error["max_point_error_mm"] < 1e-11  # what the build itself measured


@pytest.mark.parametrize("case", ["shifted_cop", "all_moved", "thin_lens"])
def test_general_kernel_agrees_with_the_exact_newton_path(analytic, reference, design_map, rig, case):
    o, d = _rays(design_map, 10000, 12)
    placed, ref = analytic, reference
    if case == "shifted_cop":
        o = o + np.array([0.7, -0.3, 1.0])
    elif case == "all_moved":
        pp = Pose.misaligned((0.3, -0.2, 0.4), 0.004, (1.0, 1.0, 0.0), (0, 0, rig.geometry.vertex_z))
        dp = Pose.misaligned((0.5, 0.2, -0.3), 0.002, (0.0, 1.0, 0.0))
        placed, ref = analytic.placed(pp, dp), reference.placed(pp, dp)
    else:
        chief = annulus_rays(design_map, 2000, 13)
        lens = thin_lens_rays(chief, 400.0, 5.0, 4)
        o, d = lens.origins, lens.dirs
    fast = T.trace(placed, o, d)
    slow = T.trace(ref, o, d)
    assert fast.kernels["general_newton"] == len(o), fast.kernels
    if case != "thin_lens":  # rays inside the occlusion limit escape: Newton fails, the compiled bracketing runs
        assert fast.kernels["bracketed_fallback"] > 0, fast.kernels
    assert np.array_equal(fast.status, slow.status)
    ok = slow.ok
    assert ok.sum() > 0.8 * len(o) * (0.8 if case != "thin_lens" else 1.0)
    for name in ("p1", "p2"):
        # the bound for misaligned rigs: 1e-7 mm (both are Newton at round-off: ~1e-12 measured)
        assert np.max(np.linalg.norm(getattr(fast, name)[ok] - getattr(slow, name)[ok], axis=1)) < 1e-7
    assert np.max(np.abs(fast.miss[ok] - slow.miss[ok])) < 1e-7
    assert np.max(_angle(fast.v[ok], slow.v[ok])) < 1e-10  # rad: a hit 1e-12 mm off tilts the normal far less


def test_the_backend_and_the_kernels_are_recorded(analytic, design_map):
    rays = annulus_rays(design_map, 100, 1)
    tr = T.trace(analytic, rays.origins, rays.dirs)
    assert "numba" in analytic.backend
    assert sum(v for k, v in tr.kernels.items() if k != "bracketed_fallback") == 100
    vec = T.trace(analytic, rays.origins, rays.dirs, vectorised=True)
    assert vec.kernels == {"vectorised": 100}


def test_traces_report_their_rays_to_a_progress_counter(analytic, design_map):
    from rigcad.check.trace3d import counting

    rays = annulus_rays(design_map, 300, 2)
    seen = []
    with counting(seen.append):
        T.trace(analytic, rays.origins, rays.dirs)
        T.trace(analytic, rays.origins[:100], rays.dirs[:100], vectorised=True)
    T.trace(analytic, rays.origins, rays.dirs)  # outside the block: not counted
    assert seen == [300, 100]


@pytest.mark.parametrize("edit", [("cop_to_vertex: 27 cm", "cop_to_vertex: 32 cm"),
                                  ("tangent_angle: 20 deg", "tangent_angle: 26 deg")])
def test_kernels_agree_on_another_rig(table31_text, write_profile, edit):
    """The same agreement on rigs other than Table 3.1 (other flags, other occlusion limits)."""
    from rigcad.check.scene import analytic_optics
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    rig = Rig.from_profile(load_profile(write_profile(table31_text.replace(*edit))))
    fast_optics = analytic_optics(rig)
    ref = copy.copy(fast_optics)
    ref.fast = None
    ref.dome = R.Group([R.ExactDome(rig.layout.design_dome, correspondence=False), fast_optics.dome.members[1]])
    o, d = _rays(rig.incidence, 5000, 21)
    for pose in (None, Pose.misaligned((0.4, 0.1, 0.2), 0.002, (1.0, 0.0, 0.0))):
        a = T.trace(fast_optics.placed(dome_pose=pose) if pose else fast_optics, o, d)
        b = T.trace(ref.placed(dome_pose=pose) if pose else ref, o, d)
        assert a.kernels["pinhole_aligned" if pose is None else "general_newton"] > 0.9 * len(o), a.kernels
        assert np.array_equal(a.status, b.status), np.bincount(a.status != b.status)
        ok = b.ok
        assert ok.sum() > 3000
        bound = 1e-9 if pose is None else 1e-7  # mm: the bounds, aligned and misaligned
        assert np.max(np.linalg.norm(a.p2[ok] - b.p2[ok], axis=1)) < bound
        assert np.max(np.abs(a.miss[ok] - b.miss[ok])) < bound


def test_the_aligned_table_converges_at_fourth_order_and_a_coarse_one_is_not_used(analytic, rig, design_map):
    """The table's cubic splines: error falls as h^4 (the measured order, not the code's claim);
    a table too coarse for PINHOLE_POINT_TOL switches the aligned kernel off, and the general
    kernel traces the same rays to the same results."""
    from rigcad.check import analytic as A

    errors = {}
    for cells in (64, 128, 256):
        coarse = copy.copy(analytic.fast)
        coarse._build_table(rig.geometry, cells)
        errors[cells] = coarse.table_error["max_point_error_mm"]
        assert not coarse.pinhole and errors[cells] > A.PINHOLE_POINT_TOL
    for a, b in ((64, 128), (128, 256)):
        assert 3.7 < np.log2(errors[a] / errors[b]) < 4.3, errors
    fine = analytic.fast.table_error
    assert fine["cells"] == A.PINHOLE_CELLS and fine["max_point_error_mm"] < A.PINHOLE_POINT_TOL
    assert fine["max_direction_error_rad"] < A.PINHOLE_DIRECTION_TOL
    gated = copy.copy(analytic)
    gated.fast = coarse
    o, d = _rays(design_map, 3000, 5)
    a, b = T.trace(gated, o, d), T.trace(analytic, o, d)
    assert a.kernels["pinhole_aligned"] == 0 and a.kernels["general_newton"] == len(o)
    assert b.kernels["pinhole_aligned"] > 0.95 * len(o)
    assert np.array_equal(a.status, b.status)
    ok = a.ok
    assert np.max(np.linalg.norm(a.p2[ok] - b.p2[ok], axis=1)) < 1e-9


def test_a_ray_through_the_rim_is_found_by_both_paraboloid_tracers_on_every_cpu(rig):
    """Rays through the mirror's rim, each at an angle in the rim's plane, along the direction that is
    tangent to the kernel's bounding sphere there (the rim lies on that sphere), the point nudged
    0-3 ulps outwards: the hit sits on the rim up to rounding, which differs between CPUs. Both the
    numba kernel (sphere skip + quadratic) and rays.ExactParaboloid count it, within RIM_RTOL."""
    from rigcad.optics import paraboloid as P

    assert K.RIM_RTOL == P.RIM_RTOL  # the kernel restates the optics' margin (numba's cache)
    geo = rig.geometry
    f, zv, rim = geo.focal_length, geo.vertex_z, geo.rim_radius
    sag = rim * rim / (4 * f)
    origins, dirs = [], []
    for a in np.linspace(0.0, 2 * np.pi, 13)[:-1]:
        c, s = np.cos(a), np.sin(a)
        w = np.array([rim * c, rim * s, -0.5 * sag])  # rim point minus the sphere's centre
        d = np.array([0.5 * sag * c, 0.5 * sag * s, rim])  # in the meridian plane, normal to w
        d /= np.linalg.norm(d)
        for k in range(4):
            p = np.array([rim * c, rim * s, zv - sag])
            for _ in range(k):
                p[:2] = np.nextafter(p[:2], 2 * p[:2])  # outwards (a zero component stays)
            origins.append(p - 50.0 * d)
            dirs.append(d)
    o, d = np.array(origins), np.array(dirs)
    kernel = np.array([K._paraboloid_bounded(*o[i], *d[i], f, zv, rim, np.inf) for i in range(len(o))])
    exact = R.ExactParaboloid(f, zv, rim).intersect(o, d).t
    # 50 mm to the rim; 1e-9 mm: the quadratic's rounding at |o| ~ 300 mm (~1e-13 relative)
    assert np.all(np.abs(kernel - 50.0) < 1e-9), kernel
    assert np.all(np.abs(exact - 50.0) < 1e-9), exact
