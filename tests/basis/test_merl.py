"""MERL BRDF tables: a file built here from the published layout, read, written back byte for byte, looked up."""

from __future__ import annotations

import math
import os
import struct

import numpy as np
import pytest

from rigcad.basis.brdf import CookTorrance, Lambert
from rigcad.basis.merl import (SHAPE, cell_indices, directions_from_half_diff, half_diff_angles, lookup, read_merl,
                               tabulate, write_merl)
from rigcad.basis.zonal import angles_to_directions
from rigcad.errors import BasisError

# The published layout, restated here rather than imported: three int32 dims, then R, G, B blocks of
# 90*90*180 doubles in C order over (theta_half, theta_diff, phi_diff), stored value * scale = BRDF.
SCALES = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)


def published_file_bytes() -> tuple[bytes, np.ndarray]:
    """Bytes of a MERL file whose stored values come from a closed form of the cell-centre angles."""
    i = (np.arange(90) + 0.5) / 90
    th = (i * i * (math.pi / 2))[:, None, None]           # theta_half index = sqrt(theta_half / (pi/2)) * 90
    td = ((np.arange(90) + 0.5) / 90 * (math.pi / 2))[None, :, None]
    pd = ((np.arange(180) + 0.5) / 180 * math.pi)[None, None, :]
    smooth = (1.0 + np.cos(th)) * (1.0 + 0.3 * np.sin(td)) * (2.0 + np.cos(2.0 * pd))
    stored = np.stack([smooth * 1500.0 * (c + 1) / 3 for c in range(3)])
    data = struct.pack("<3i", 90, 90, 180)
    for c in range(3):
        data += struct.pack(f"<{90 * 90 * 180}d", *stored[c].ravel())
    return data, stored


@pytest.fixture(scope="module")
def published(tmp_path_factory):
    data, stored = published_file_bytes()
    path = tmp_path_factory.mktemp("merl") / "closed_form.binary"
    path.write_bytes(data)
    return path, data, stored


def test_read_matches_the_published_layout(published):
    path, _, stored = published
    assert np.array_equal(read_merl(path, physical=False), stored)
    phys = read_merl(path)
    assert phys.shape == SHAPE
    for c in range(3):
        # physical = stored * scale in float64, exactly as the reference reader computes it: bit for bit
        assert np.array_equal(phys[c], stored[c] * SCALES[c]), c


def test_stored_round_trip_is_byte_exact(published, tmp_path):
    path, data, _ = published
    out = write_merl(tmp_path / "copy.binary", read_merl(path, physical=False), physical=False)
    assert out.read_bytes() == data


def test_physical_round_trip(published, tmp_path):
    path, data, stored = published
    phys = read_merl(path)
    out = write_merl(tmp_path / "phys.binary", phys)
    # the table a read produced comes back bit for bit
    assert np.array_equal(read_merl(out), phys)
    back = read_merl(out, physical=False)
    differ = back != stored
    # stored * scale is not injective in float64 (two doubles can scale to one), so through physical
    # units some stored values come back as the other preimage: at most 2 ulps away (the search
    # width of write_merl; measured: 1 ulp) and a minority of cells (measured 12.5 % here, 11.6 % for
    # uniformly random stored values)
    assert np.all(np.abs(back - stored) <= 2 * np.spacing(stored)), "more than 2 ulps off"
    assert differ.mean() < 0.2, differ.mean()
    assert len(out.read_bytes()) == len(data)


def test_lookup_indices_by_hand():
    # stored value encodes its own cell: i * 1e6 + j * 1e3 + k (exact in float64)
    i, j, k = np.meshgrid(np.arange(90), np.arange(90), np.arange(180), indexing="ij")
    table = np.broadcast_to((i * 1e6 + j * 1e3 + k).astype(float), SHAPE)

    def cell(wi, wo):
        v = lookup(table, wi, wo)[0]
        return int(v // 1e6), int(v % 1e6 // 1e3), int(v % 1e3)

    d = angles_to_directions
    r = math.radians
    # in-plane pair 40.5 / 19.5 deg: theta_half 30 deg -> floor(sqrt(1/3) * 90) = 51; theta_diff 10.5 -> 10;
    # the difference vector stays in the x-z plane on the +x side: phi_diff 0 -> k = 0
    assert cell(d(r(40.5), 0.0), d(r(19.5), 0.0)) == (51, 10, 0)

    # a general pair from the definition: difference vector d at (theta_d, phi_d), tilted by theta_half about +y
    # (phi_half = 0), wi = R_y(theta_half) d, wo = 2 (wi.h) h - wi
    th, td, pd = r(30.0), r(45.5), r(100.5)
    dv = np.array([math.sin(td) * math.cos(pd), math.sin(td) * math.sin(pd), math.cos(td)])
    h = np.array([math.sin(th), 0.0, math.cos(th)])
    wi = np.array([math.cos(th) * dv[0] + math.sin(th) * dv[2], dv[1], -math.sin(th) * dv[0] + math.cos(th) * dv[2]])
    wo = 2 * (wi @ h) * h - wi
    # theta_half 30 deg -> 51, theta_diff 45.5 deg -> 45, phi_diff 100.5 deg -> 100
    assert cell(wi, wo) == (51, 45, 100)
    # swapping wi and wo turns phi_diff by pi (to -79.5 deg); the +pi rule puts it in the same cell
    assert cell(wo, wi) == (51, 45, 100)


def test_half_diff_map_inverts():
    rng = np.random.default_rng(2)
    v = rng.normal(size=(2, 500, 3))
    v[..., 2] = np.abs(v[..., 2])
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    th, ph, td, pd = half_diff_angles(v[0], v[1])
    wi, wo = directions_from_half_diff(th, td, pd, ph)
    # rotations of unit vectors: round-off only
    assert np.max(np.abs(wi - v[0])) < 1e-12 and np.max(np.abs(wo - v[1])) < 1e-12


def test_tabulated_lambert_looks_up_rho_over_pi(tmp_path):
    table = tabulate(Lambert(0.5))
    rng = np.random.default_rng(4)
    n = 5000
    # directions up to 80 deg: the cells they fall in have centres displaced by under ~3 deg, so never below
    # the horizon (where tabulate stores 0)
    wi = angles_to_directions(rng.uniform(0, math.radians(80), n), rng.uniform(0, 2 * math.pi, n))
    wo = angles_to_directions(rng.uniform(0, math.radians(80), n), rng.uniform(0, 2 * math.pi, n))
    vals = lookup(table, wi, wo)
    assert np.all(vals == 0.5 / math.pi)
    # and through a file: physical round trip keeps the value bit for bit
    assert np.all(lookup(read_merl(write_merl(tmp_path / "lambert.binary", table)), wi, wo) == 0.5 / math.pi)


def test_tabulate_evaluates_at_cell_centres():
    f = CookTorrance(0.3, 0.8, ks=0.7, kd=0.3)
    table = tabulate(f)
    i, j, k = 40, 20, 33
    th, td, pd = ((i + 0.5) / 90) ** 2 * math.pi / 2, (j + 0.5) / 90 * math.pi / 2, (k + 0.5) / 180 * math.pi
    wi, wo = directions_from_half_diff(th, td, pd)
    # the cell's value is the model at the cell's centre directions (same arithmetic: exact)
    assert table[1, i, j, k] == f(wi, wo)
    assert cell_indices(np.array(th), np.array(td), np.array(pd)) == (i, j, k)


def test_bad_files_are_refused(tmp_path):
    p = tmp_path / "bad.binary"
    p.write_bytes(struct.pack("<3i", 90, 90, 360) + bytes(8))
    with pytest.raises(BasisError, match=r"header dims \[90, 90, 360\]"):
        read_merl(p)
    p.write_bytes(struct.pack("<3i", 90, 90, 180) + bytes(80))
    with pytest.raises(BasisError, match="has 92 bytes"):
        read_merl(p)
    with pytest.raises(BasisError, match="missing.binary': missing"):
        read_merl(tmp_path / "missing.binary")
    with pytest.raises(BasisError, match="shape"):
        write_merl(tmp_path / "x.binary", np.zeros((3, 90, 90, 90)))


def test_in_plane_pairs_land_in_one_cell_on_every_cpu():
    """In-plane pairs (phi_diff 0 or +-pi) turned about the normal by phi_half: the difference
    vector's y is 0 up to rounding, either sign, so arctan2 gives 0 or -0 (+-pi) by the last bits,
    which differ between CPUs. Reciprocity makes phi_diff and phi_diff + pi one cell: cell 0 for all,
    and whole-degree theta_diff (a cell boundary) in its upper cell whichever way it rounded."""
    r = math.radians
    k_seen, j_seen = set(), set()
    for ph in np.linspace(0.0, 2 * np.pi, 37)[:-1]:
        for swap in (False, True):
            wi, wo = directions_from_half_diff(r(30.0), r(20.0), np.pi if swap else 0.0, ph)
            th, _, td, pd = half_diff_angles(wi, wo)
            i, j, k = cell_indices(th, td, pd)
            k_seen.add(int(k))
            j_seen.add(int(j))
    assert k_seen == {0}, k_seen
    assert j_seen == {20}, j_seen  # theta_diff exactly 20 deg: the boundary goes to the cell above


@pytest.mark.parametrize("dims", [(-90, -90, 180), (1, 1, 1_458_000), (180, 90, 90)])
def test_a_header_of_another_grid_is_refused_before_the_data(tmp_path, dims):
    """The reference reader checks only the product; every index here is of the 90 x 90 x 180 grid."""
    p = tmp_path / "other.binary"
    p.write_bytes(struct.pack("<3i", *dims) + bytes(3 * 90 * 90 * 180 * 8))
    with pytest.raises(BasisError, match=rf"header dims \[{dims[0]}, {dims[1]}, {dims[2]}\].*need 90, 90, 180"):
        read_merl(p)


def test_nan_data_and_oversized_files_are_refused(tmp_path):
    import resource

    table = np.full(SHAPE, 0.5)
    table[1, 2, 3, 4] = np.nan
    p = tmp_path / "nan.binary"
    p.write_bytes(struct.pack("<3i", 90, 90, 180) + table.astype("<f8").tobytes())
    with pytest.raises(BasisError, match="holds 1 NaN or infinite values"):
        read_merl(p)
    big = tmp_path / "big.binary"
    with open(big, "wb") as fh:  # an 8 GiB sparse file: refused from its size, nothing read
        fh.write(struct.pack("<3i", 90, 90, 180))
        fh.truncate(8 << 30)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(BasisError, match=r"has 8589934592 bytes: need 34992012 \(header"):
        read_merl(big)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100 * 1024  # KiB: far under 8 GiB
    fifo = tmp_path / "fifo.binary"
    os.mkfifo(fifo)
    with pytest.raises(BasisError, match="is a FIFO, not a file"):
        read_merl(fifo)
