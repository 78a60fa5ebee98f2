"""Which camera pixels the misalignment fit reads: none whose decoded point is pulled by an edge.

A camera pixel near one that did not decode sees the screen's edge, or a shadow's, in part of its
footprint (and the blur mixes in its dark neighbours), so its decoded point is pulled. Measured
against the tracer on the Table 3.1 rig (seeds 101, 102 and 105; the upper screen 25 mm up): 3
pixels along a row or a column from an undecoded pixel, the upper screen's points lie ~70 um
outward of the true ones on average (median error 35 um); 4 pixels and more away, within 3 um on
average (median error 8-17 um). With the fit reading the pixels 3 steps in (two erosions), the
fitted upper screen came out 15-23 um low on all six trials (seeds 101-106) and the measured
pixels' map p99 was 0.062-0.123 deg; with the map's own rule (maps.HEIGHT_EDGE_PX, three
erosions), within 5 um and 0.034-0.079 deg."""

from types import SimpleNamespace

import numpy as np
from scipy.ndimage import distance_transform_cdt, distance_transform_edt

from rigcad.calibrate import maps
from rigcad.calibrate.run import _fit_data


def _capture(shape, holes, u=None, v=None):
    """A decoded capture (what _fit_data reads): every pixel decoded but the ``holes`` (slices); its
    points (u, v) mm, all at the screen's centre (rays off the mirrors, through O) by default."""
    valid = np.ones(shape, bool)
    for h in holes:
        valid[h] = False
    zero = np.zeros(shape)
    return SimpleNamespace(valid=valid, u=zero if u is None else u, v=zero if v is None else v)


def test_the_direct_view_is_read_on_a_coarser_grid():
    """Pixels whose points say the screen was seen directly (fit.seen_direct: here the right half,
    on a line from a COP 427.5 mm up through 40 mm out on the sample plane) are read on every
    fit.DIRECT_STRIDE-th of the fit's rows and columns; the mirrored ones on every one. Neither path
    reads a pixel within the edge rule of the other's: there a footprint mixes both views."""
    from rigcad.calibrate.fit import DIRECT_STRIDE

    shape = (40, 48)
    cam = SimpleNamespace(shape=shape, design=SimpleNamespace(cop_z=427.5, alpha_max=0.056))
    plan = SimpleNamespace(heights=np.array([6.0, 25.0]), turns=np.zeros(2))
    right = np.zeros(shape, bool)
    right[:, 24:] = True
    captures = [_capture(shape, [], u=np.where(right, 40.0 * (1 - h / 427.5), 0.0)) for h in plan.heights]
    data = _fit_data(cam, plan, captures, 2)
    assert np.array_equal(data.direct, right.ravel()[data.pixels])
    # beyond the window counts as undecoded: the edge rule keeps rows and columns 3 .. n - 4
    rows, cols = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    inner = (rows >= 3) & (rows <= shape[0] - 4) & (cols >= 3) & (cols <= shape[1] - 4)
    on = lambda k: (rows % k == 0) & (cols % k == 0)  # noqa: E731
    # and where the two paths meet, each keeps the edge rule's distance from the other's pixels
    apart = (cols <= 23 - maps.HEIGHT_EDGE_PX) | (cols >= 24 + maps.HEIGHT_EDGE_PX)
    expect = inner & apart & np.where(right, on(2 * DIRECT_STRIDE), on(2))
    assert np.array_equal(np.sort(data.pixels), np.nonzero(expect.ravel())[0])
    assert data.direct.sum() == 45 and (~data.direct).sum() == 153  # 9 x 5 on the right, 17 x 9 on the left


def _steps(valid):
    """City-block steps from each pixel to the nearest undecoded one; beyond the window counts as
    undecoded (nothing is known there)."""
    return distance_transform_cdt(np.pad(valid, 1), metric="taxicab")[1:-1, 1:-1].ravel()


def test_the_fit_reads_no_pixel_the_map_s_rays_leave_out():
    shape = (60, 80)
    cam = SimpleNamespace(shape=shape, design=SimpleNamespace(cop_z=427.5, alpha_max=0.056))
    # the lower screen: a shadow in the middle; the upper: a shorter screen (the grazing rays pass its edge)
    captures = [_capture(shape, [np.s_[25:32, 30:41]]), _capture(shape, [np.s_[:, 62:], np.s_[:4, :]])]
    data = _fit_data(cam, SimpleNamespace(heights=np.array([6.0, 25.0]), turns=np.zeros(2)), captures, 1)
    for c in captures:
        # no pixel of the biased ring, 3 px along a row or a column from an undecoded one (module
        # docstring), nor any nearer: at least 4 steps (city-block) from every undecoded pixel
        assert _steps(c.valid)[data.pixels].min() == maps.HEIGHT_EDGE_PX + 1 == 4
        assert not np.any(distance_transform_edt(np.pad(c.valid, 1))[1:-1, 1:-1].ravel()[data.pixels] == 3)
    # and every pixel the rays read at both heights is read (the rule is the same, not stricter)
    both = np.all([_steps(c.valid) > maps.HEIGHT_EDGE_PX for c in captures], axis=0)
    assert np.array_equal(np.sort(data.pixels), np.nonzero(both)[0])
    # the decoded points travel with their pixels, height by height
    assert np.array_equal(data.screen_uv[:, 1, 0], captures[1].u.ravel()[data.pixels])
    assert np.array_equal(data.screen_uv[:, 0, 1], captures[0].v.ravel()[data.pixels])
