"""The zonal basis on the rig's projector (thesis 3.3, 4.2.1): pixel solid angles against the zone's
closed form, which pixels light the sample against an independent light-path test, Gram matrices
over the lit pixels, the images themselves (orientation, preprocessing, PNG bytes read back by a
decoder written here)."""

from __future__ import annotations

import math
import struct
import zlib

import numpy as np
import pytest

from rigcad.basis.gram import off_identity, gram
from rigcad.basis.projector import (check_basis_order, illuminated, pixel_jacobian, projector_basis, trace_pixels,
                                    traced_jacobian, zone_of)
from rigcad.basis.zonal import angles_to_directions, basis_index
from rigcad.errors import BasisError
from rigcad.export.png import gray_png


@pytest.fixture(scope="module")
def rig(table31_rig):
    return table31_rig


@pytest.fixture(scope="module")
def design(rig):
    return trace_pixels(rig, "projector")


@pytest.fixture(scope="module")
def basis(rig):
    return projector_basis(rig, 6)


def test_zone_is_the_rigs_measurable_range(rig):
    zone = zone_of(rig)
    # alpha is the design's occlusion limit, as the 2D design reports it (not the thesis's 9 deg):
    # the same spline, so equal to round-off
    assert abs(math.degrees(zone.alpha_rad) - rig.design.report["measurable_range"]["theta_min_deg"]) < 1e-9
    assert zone.beta_rad == math.pi / 2
    assert zone_of(rig, math.radians(9)).alpha_rad == pytest.approx(math.radians(9), abs=0)
    with pytest.raises(BasisError, match=r"alpha_rad = 0\.1 .*occlusion limit"):
        zone_of(rig, 0.1)  # 5.7 deg: below what any pixel reaches


def test_pixel_solid_angles_sum_to_the_zone(rig, design):
    zone = zone_of(rig)
    closed = 2 * math.pi * (math.cos(zone.alpha_rad) - math.cos(zone.beta_rad))  # the zone's solid angle
    m = rig.incidence
    inside = design.in_zone(zone)
    total = design.jacobian_sr[inside].sum()
    # pixels are counted whole or not at all at the two zone edges (first order); measured +1.9e-4
    # relative (the lensed map, f = 1928 px), against an a-priori bound (the summed J of the straddling
    # pixels) of 1.8 %
    from rigcad.basis.projector import solid_angle_check

    check = solid_angle_check(rig, design, zone)
    assert abs(total - closed) < check["edge_bound_sr"], (total, closed, check)
    assert abs(total / closed - 1) < 1e-3, total / closed - 1
    # the same integral with every pixel cut into s x s sub-pixels converges to the closed form: the
    # Jacobian formula itself is right (a wrong factor would stall at that factor). Measured
    # relative errors 1.9e-4, 3.7e-5, 2.7e-5, 9.4e-6 for s = 1, 2, 4, 8: about first order, as for
    # a boundary error
    errors = []
    for s in (1, 2, 8):
        o = (np.arange(s) + 0.5) / s - 0.5
        dx, dy = (a.ravel() for a in np.meshgrid(o, o, indexing="ij"))
        J, ins = pixel_jacobian(m, (design.x_px[:, None] + dx).ravel(), (design.y_px[:, None] + dy).ravel())
        errors.append(abs(J[ins].sum() / s ** 2 / closed - 1))
    assert errors[2] < 1e-4 and errors[2] < errors[0] / 4, errors


def test_traced_jacobian_agrees_with_the_formula(design):
    # central differences of the *traced* arrival directions of neighbouring pixels (the 3D tracer,
    # independent of the spline's derivative) against J, wherever all four neighbours are traced
    Jt = traced_jacobian(design)
    sel = np.isfinite(Jt) & (design.jacobian_sr > 0)
    rel = np.abs(Jt[sel] / design.jacobian_sr[sel] - 1)
    assert sel.sum() > 25000  # most of the annulus is compared
    # measured 1.0e-4 at most (median 8e-5): the differences' O(h^2) truncation over a 1 px step
    assert rel.max() < 1e-3, rel.max()


def test_lit_pixels_agree_with_the_design_light_paths(rig, design):
    zone = zone_of(rig)
    inside = design.in_zone(zone)
    dirs = np.where(inside[:, None], design.design_dirs, [0.0, 0.0, 1.0])
    by_paths = illuminated(rig, dirs, zone) & inside
    by_tracer = design.ok & inside
    # the 3D tracer (exact surfaces, occluders as boxes and cylinders) and the 2D design's light paths
    # tested against the same solids agree on every one of the 36 436 pixel centres in the zone
    assert inside.sum() > 30000
    assert np.array_equal(by_paths, by_tracer), np.count_nonzero(by_paths != by_tracer)
    assert (~by_tracer & inside).sum() > 1000  # the beam does hide pixels: the comparison is not vacuous


def test_lit_solid_angle_matches_the_zone_minus_what_the_occluders_hide(rig, basis):
    zone = basis.zone
    # the blocked fraction by the independent light-path test on a midpoint grid in (cos theta, phi)
    n_t, n_p = 300, 1440
    x = math.cos(zone.beta_rad) + (np.arange(n_t) + 0.5) * (math.cos(zone.alpha_rad) - math.cos(zone.beta_rad)) / n_t
    T, P = np.meshgrid(np.arccos(x), (np.arange(n_p) + 0.5) * 2 * math.pi / n_p, indexing="ij")
    lit_fraction = illuminated(rig, angles_to_directions(T.ravel(), P.ravel()), zone).mean()
    delivered = basis.illumination.weight_sr.sum() / zone.solid_angle_sr
    # measured 0.95611 delivered against 0.95636 by the grid: the pixels' edges (supersampled 4 x 4)
    # and the grid's cells (0.28 deg) each err by a few 1e-4 of the zone along the shadow's edges
    assert abs(delivered - lit_fraction) < 1e-3, (delivered, lit_fraction)
    assert 0.9 < lit_fraction < 0.99  # the beam hides a few per cent (4.4 %, the build's occlusion report)


def test_gram_over_the_lit_pixels(basis):
    g = basis.report["gram"]
    for order in (2, 4, 6):
        r = g[f"order_{order}"]
        # reported after 8-bit quantisation: the beam's shadow dominates (measured 0.090, 0.097, 0.099);
        # without the occluders the pixel grid alone gives 1.7e-3, 3.1e-3, 4.4e-3
        assert 0.05 < r["analytic_8bit"]["max_abs"] < 0.2, r
        assert r["analytic_without_occluders"]["max_abs"] < 1e-2, r
        # the target: the re-orthonormalised set after 8-bit quantisation within 1e-2 of the
        # identity (measured 8.3e-5, 2.6e-4, 3.0e-4: half a level on each pixel)
        assert r["lowdin_8bit"]["max_abs"] < 1e-2, r
        # and it moves the functions to cover the shadow (measured max 5 %, 7 %, 8.5 %: the shadow's share)
        assert r["lowdin_deviation_from_analytic"]["max"] < 0.15, r
    # the report's figure is the Gram matrix of the written images, recomputed here
    G = gram(basis.displayed("analytic", 8), basis.illumination.sampling)
    assert np.array_equal(np.array(basis.report["gram_matrix_8bit"]), G)
    assert off_identity(G).max_abs == g["order_6"]["analytic_8bit"]["max_abs"]


def test_images_follow_the_pixel_convention(basis):
    # Z_1^1 ~ cos(phi): positive towards +x (image columns to the right); Z_1^-1 ~ sin(phi): towards
    # +y (image rows upwards); Z_0^0 is constant and positive
    px = basis.pixels
    width, height = px.resolution
    cols, rows = np.meshgrid(np.arange(width), np.arange(height))
    for k, (sx, sy) in ((basis_index(1, 1), (1, 0)), (basis_index(1, -1), (0, 1))):
        pos, neg = basis.image(k, "positive"), basis.image(k, "negative")
        x, y = cols + 0.5 - width / 2, height / 2 - rows - 0.5
        side = sx * x + sy * y
        assert np.all(side[pos > 0] > 0) and np.all(side[neg > 0] < 0), k
        assert not np.any((pos > 0) & (neg > 0))  # positive and negative parts are disjoint (4.2.1)
    z00 = basis.image(0, "positive")
    assert basis.image(0, "negative").max() == 0 and z00.max() > 0
    lit = np.zeros((height, width), bool)
    lit[px.row[basis.illumination.lit], px.col[basis.illumination.lit]] = True
    # black exactly where no light reaches the sample; Z_0^0 is constant, so every lit pixel shows it
    assert np.array_equal(z00 > 0, lit)


def test_preprocessing_uses_one_scale_and_both_depths(basis):
    for bits, dtype in ((8, np.uint8), (16, np.uint16)):
        q = basis.images[bits]
        levels = 2 ** bits - 1
        # one scale for all images (4.2.1): the largest |value| maps to the top level in exactly one image set
        assert q.scale == pytest.approx(np.max(np.abs(basis.values)), rel=0, abs=0)
        assert max(q.positive.max(), q.negative.max()) == levels
        img = basis.image(5, "positive", bits)
        assert img.dtype == dtype and img.shape == (768, 1024)
        # dequantised values stay within half a level of the analytic ones (round to nearest)
        err = np.abs(q.values() - basis.values).max()
        assert err <= 0.5 * q.scale / levels * (1 + 1e-12), (bits, err)


def _decode_png(data: bytes) -> np.ndarray:
    """A greyscale PNG decoder written here from the PNG specification (chunks, zlib, the five row
    filters), independent of the Pillow encoder under test."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header, gamma = 8, b"", None, None
    while pos < len(data):
        (n,), kind = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"gAMA":
            assert idat == b"", "gAMA after IDAT"  # PNG: gAMA before the image data
            (gamma,) = struct.unpack(">I", body)
        else:
            assert kind == b"IEND", kind  # no text or time chunks: the same bytes every run
        pos += 12 + n
    assert gamma == 100_000, gamma  # gAMA 1.0 (PNG stores gamma x 100000): the levels are linear
    width, height, depth, colour, _, _, interlace = header
    assert colour == 0 and interlace == 0 and depth in (8, 16)
    bpp = depth // 8
    raw = zlib.decompress(idat)
    stride = width * bpp
    out = np.zeros((height, stride), dtype=np.int64)
    prev = np.zeros(stride, dtype=np.int64)
    for r in range(height):
        f = raw[r * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, r * (stride + 1) + 1).astype(np.int64)
        cur = np.zeros(stride, dtype=np.int64)
        for i in range(stride):
            a = cur[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 0:
                pred = 0
            elif f == 1:
                pred = a
            elif f == 2:
                pred = b
            elif f == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (line[i] + pred) & 0xFF
        out[r], prev = cur, cur
    if bpp == 2:
        return (out[:, 0::2] << 8 | out[:, 1::2]).astype(np.uint16)
    return out.astype(np.uint8)


@pytest.mark.parametrize("bits", [8, 16])
def test_png_round_trip_through_an_independent_decoder(basis, bits):
    # a crop keeps the pure-Python decoder fast; the crop holds both signs and black pixels
    img = basis.image(basis_index(2, 1), "positive", bits)[330:420, 470:560]
    data = gray_png(img)
    assert np.array_equal(_decode_png(data), img)
    assert gray_png(img) == data  # same array, same bytes


def test_orders_outside_the_verified_range_are_refused():
    for bad in (-1, 13, 2.5, "six", True):
        with pytest.raises(BasisError, match=r"basis order = .*need an integer from 0 to 12"):
            check_basis_order(bad)
    assert check_basis_order(12) == 12
