"""MERL isotropic BRDF tables (Matusik et al. 2003, "A data-driven reflectance model"): read, write, tabulate, look up.

File layout (as read by MERL's published reference reader, ``read_brdf`` / ``lookup_brdf_val``):
a header of three native int32 (little-endian on the x86 machines that wrote the database)
``90, 90, 180`` (theta_half, theta_diff, phi_diff resolutions; the reader only checks their product),
then three channels R, G, B of 90*90*180 float64 each, in C order over (theta_half, theta_diff,
phi_diff). Stored values times the channel scale (1/1500, 1.15/1500, 1.66/1500) are the BRDF in 1/sr.
Negative stored values mark cells below the horizon.

Parametrisation (Rusinkiewicz half/difference angles), for unit wi, wo in the local frame
(normal +z, tangent +x): h = (wi + wo)/|wi + wo|, theta_half = acos(h_z), phi_half = atan2(h_y, h_x);
the difference vector is wi rotated by -phi_half about +z then by -theta_half about +y;
theta_diff = acos(d_z), phi_diff = atan2(d_y, d_x). The table is isotropic (phi_half ignored) and
reciprocal (phi_diff and phi_diff + pi share a cell, so phi_diff lives in [0, pi)).
Indices, as the reference reader computes them (truncation towards zero, then clamping):
theta_half: floor(sqrt(theta_half/(pi/2)) * 90) (0 when theta_half <= 0), theta_diff:
floor(theta_diff/(pi/2) * 90), phi_diff: floor(phi_diff/pi * 180) after adding pi when negative.

Tables here are arrays (3, 90, 90, 180) float64 in 1/sr ("physical units").
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np

from rigcad.errors import BasisError

N_THETA_HALF = 90
N_THETA_DIFF = 90
N_PHI_DIFF = 180
SHAPE = (3, N_THETA_HALF, N_THETA_DIFF, N_PHI_DIFF)
#: Per-channel factor from stored value to BRDF (1/sr), as the reference reader defines them.
CHANNEL_SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)
_HEADER = np.dtype("<i4")
_DATA = np.dtype("<f8")
_N = N_THETA_HALF * N_THETA_DIFF * N_PHI_DIFF


def _scales() -> np.ndarray:
    return np.array(CHANNEL_SCALE).reshape(3, 1, 1, 1)


def read_merl(path: str | os.PathLike, *, physical: bool = True) -> np.ndarray:
    """Read a MERL .binary file: (3, 90, 90, 180) float64, in 1/sr (``physical``) or as stored.

    Read as data, header first (the rules of rigcad.export.readback, which this pure module may not
    import): opened without blocking, a regular file (a FIFO, a device or a folder is named as such);
    its 12-byte header exactly 90, 90, 180 (the reference reader checks only the product, but every
    index here is of that grid); its size, from ``fstat``, the header's (a bigger, sparse or endless
    file is refused before its data is read); every value finite (negative marks a cell below the
    horizon). Raises BasisError naming the file. The physical values are ``stored * scale`` computed
    in float64, as the reference reader does. That product is not invertible bit for bit (two stored
    doubles can scale to one), so a file is reproduced byte for byte only through ``physical=False``
    on both ends; see :func:`write_merl`.
    """
    import stat

    p = Path(path)
    shown = repr(str(p))
    expected = 12 + 3 * _N * 8
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise BasisError(f"MERL file {shown}: missing") from None
    except OSError as err:
        raise BasisError(f"MERL file {shown} cannot be read: {err.strerror}") from None
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode) else "a device"
            raise BasisError(f"MERL file {shown} is {kind}, not a file")
        head = fh.read(12)
        if len(head) < 12:
            raise BasisError(f"MERL file {shown} has {len(head)} bytes: need a 12-byte header and data")
        dims = np.frombuffer(head, dtype=_HEADER, count=3)
        if dims.tolist() != [N_THETA_HALF, N_THETA_DIFF, N_PHI_DIFF]:
            n = int(dims[0]) * int(dims[1]) * int(dims[2])
            raise BasisError(f"MERL file {shown} header dims {dims.tolist()} (product {n}): need 90, 90, 180 "
                             f"(theta_half, theta_diff, phi_diff; a product of {_N})")
        if st.st_size != expected:
            raise BasisError(f"MERL file {shown} has {st.st_size} bytes: need {expected} (header + 3 x {_N} doubles)")
        data = fh.read(expected - 11)  # one byte past the table: a file that grew is refused too
    if len(data) != expected - 12:
        raise BasisError(f"MERL file {shown} has {12 + len(data)} bytes: need {expected} (header + 3 x {_N} doubles)")
    table = np.frombuffer(data, dtype=_DATA).astype(float).reshape(SHAPE)
    bad = int(np.count_nonzero(~np.isfinite(table)))
    if bad:
        raise BasisError(f"MERL file {shown} holds {bad} NaN or infinite values: need finite BRDF values "
                         "(negative marks a cell below the horizon)")
    return table * _scales() if physical else table


def write_merl(path: str | os.PathLike, table: np.ndarray, *, physical: bool = True) -> Path:
    """Write a table (3, 90, 90, 180) as a MERL .binary file atomically; returns the path written.

    ``physical``: the table is in 1/sr and is divided by the channel scales; among the stored
    doubles that scale back to the same value the one nearest the quotient is chosen, so
    ``read_merl(write_merl(p, t)) == t`` bit for bit for any t that a read produced. With
    ``physical=False`` the table is written as stored values unchanged, which reproduces a file's
    bytes exactly. Header: int32 90, 90, 180, little-endian; data little-endian float64.
    """
    t = np.asarray(table, dtype=float)
    if t.shape != SHAPE:
        raise BasisError(f"MERL table has shape {t.shape}: need {SHAPE} (channel, theta_half, theta_diff, phi_diff)")
    if not np.all(np.isfinite(t)):
        raise BasisError("MERL table has non-finite values: need finite BRDF values (negative marks below horizon)")
    stored = _to_stored(t) if physical else t
    p = Path(path)
    payload = (np.array([N_THETA_HALF, N_THETA_DIFF, N_PHI_DIFF], dtype=_HEADER).tobytes()
               + np.ascontiguousarray(stored, dtype=_DATA).tobytes())
    fd, tmp = tempfile.mkstemp(prefix=p.name + ".", suffix=".tmp", dir=p.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(payload)
        os.replace(tmp, p)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        raise BasisError(f"MERL file {str(p)!r} cannot be written: {err.strerror}") from err
    return p


def _to_stored(t: np.ndarray) -> np.ndarray:
    """Stored values whose product with the channel scale reproduces ``t`` exactly where possible."""
    s = _scales()
    q = t / s
    best = q.copy()
    found = (q * s) == t
    # the nearest quotient misses by an ulp or two in a few percent of cells: search its neighbours
    for step in (1, -1, 2, -2):
        cand = q.copy()
        for _ in range(abs(step)):
            cand = np.nextafter(cand, np.inf if step > 0 else -np.inf)
        hit = ~found & ((cand * s) == t)
        best[hit] = cand[hit]
        found |= hit
    return best


def half_diff_angles(wi: np.ndarray, wo: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(theta_half, phi_half, theta_diff, phi_diff) in radians for unit wi, wo (..., 3) in the local frame."""
    wi = np.asarray(wi, dtype=float)
    wo = np.asarray(wo, dtype=float)
    wi, wo = np.broadcast_arrays(wi, wo)
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[..., 2], -1.0, 1.0))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    # rotate wi by -phi_h about z, then by -theta_h about y
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    x1 = c * wi[..., 0] - s * wi[..., 1]
    y1 = s * wi[..., 0] + c * wi[..., 1]
    z1 = wi[..., 2]
    c, s = np.cos(-theta_h), np.sin(-theta_h)
    x2 = c * x1 + s * z1
    z2 = -s * x1 + c * z1
    theta_d = np.arccos(np.clip(z2, -1.0, 1.0))
    phi_d = np.arctan2(y1, x2)
    return theta_h, phi_h, theta_d, phi_d


def directions_from_half_diff(theta_half: np.ndarray, theta_diff: np.ndarray, phi_diff: np.ndarray,
                              phi_half: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Unit (wi, wo), each (..., 3), with the given half/difference angles (radians): the inverse map."""
    th, td, pd, ph = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta_half, theta_diff, phi_diff, phi_half)))
    d = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], axis=-1)
    # rotate d by +theta_half about y, then by +phi_half about z (undoing half_diff_angles)
    c, s = np.cos(th), np.sin(th)
    x1 = c * d[..., 0] + s * d[..., 2]
    z1 = -s * d[..., 0] + c * d[..., 2]
    c, s = np.cos(ph), np.sin(ph)
    wi = np.stack([c * x1 - s * d[..., 1], s * x1 + c * d[..., 1], z1], axis=-1)
    h = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    wo = 2.0 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
    return wi, wo


#: Cells (in units of one cell) within which a value counts as on a cell boundary: the directions the
#: rig and the tests use put angles exactly on boundaries (in-plane pairs: phi_diff 0 or +-pi; whole
#: degrees), and their last bits, which differ between CPUs (numpy's SIMD trigonometry, BLAS), would
#: pick the cell. 1e-9 cell is ~2e-11 rad: far above rounding, far below any measured direction's error.
CELL_SNAP = 1e-9


def _cells(x: np.ndarray, n: int) -> np.ndarray:
    """Cell index of cell coordinates ``x`` (trunc, clipped to 0..n-1), a value within CELL_SNAP of a
    boundary taken as on it (the cell above, as the reference reader does for the exact value)."""
    k = np.rint(x)
    x = np.where(np.abs(x - k) <= CELL_SNAP, k, x)
    return np.clip(np.trunc(x), 0, n - 1).astype(np.intp)


def cell_indices(theta_half: np.ndarray, theta_diff: np.ndarray, phi_diff: np.ndarray) -> tuple[np.ndarray, ...]:
    """Integer cell indices (i_theta_half, i_theta_diff, i_phi_diff) as the reference reader computes them,
    but for values within CELL_SNAP of a boundary (:func:`_cells`) and phi_diff = +-pi, which reciprocity
    (phi_diff and phi_diff + pi are one cell) puts with 0 in cell 0 (the reader: -pi in 0, +pi in 179)."""
    th = np.asarray(theta_half, dtype=float)
    with np.errstate(invalid="ignore"):
        r = np.sqrt(np.maximum(th, 0.0) / (math.pi / 2.0) * N_THETA_HALF * N_THETA_HALF)
    i_th = np.where(th <= 0.0, 0, _cells(r, N_THETA_HALF)).astype(np.intp)
    i_td = _cells(np.asarray(theta_diff, dtype=float) / (math.pi * 0.5) * N_THETA_DIFF, N_THETA_DIFF)
    x = np.asarray(phi_diff, dtype=float) / math.pi * N_PHI_DIFF
    k = np.rint(x)
    x = np.mod(np.where(np.abs(x - k) <= CELL_SNAP, k, x), N_PHI_DIFF)  # [-180, 180] -> [0, 180): +pi rule
    i_pd = _cells(x, N_PHI_DIFF)
    return i_th, i_td, i_pd


def lookup(table: np.ndarray, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """BRDF values (..., 3) RGB of a table (3, 90, 90, 180) at unit directions wi, wo (..., 3): nearest cell."""
    t = np.asarray(table)
    if t.shape != SHAPE:
        raise BasisError(f"MERL table has shape {t.shape}: need {SHAPE}")
    th, _, td, pd = half_diff_angles(wi, wo)
    i, j, k = cell_indices(th, td, pd)
    return np.moveaxis(t[:, i, j, k], 0, -1)


def cell_centres() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta_half, theta_diff, phi_diff) in radians at the centre of every cell in index space, each (90, 90, 180).

    theta_half = ((i + 1/2)/90)^2 pi/2 (the inverse of the square-root index map), theta_diff =
    (j + 1/2)/90 pi/2, phi_diff = (k + 1/2)/180 pi.
    """
    i = (np.arange(N_THETA_HALF) + 0.5) / N_THETA_HALF
    j = (np.arange(N_THETA_DIFF) + 0.5) / N_THETA_DIFF
    k = (np.arange(N_PHI_DIFF) + 0.5) / N_PHI_DIFF
    return np.meshgrid(i * i * (math.pi / 2.0), j * (math.pi / 2.0), k * math.pi, indexing="ij")


def tabulate(brdf: Callable[[np.ndarray, np.ndarray], np.ndarray], *, below_horizon: float = 0.0,
             chunk: int = 90 * 180) -> np.ndarray:
    """A MERL table (3, 90, 90, 180) of a closed-form BRDF evaluated at every cell centre (phi_half = 0).

    ``brdf(wi, wo)`` takes (n, 3) arrays and returns (n,) (grey: copied to R, G, B) or (n, 3).
    Cells whose centre direction pair has wi or wo at or below the horizon get ``below_horizon``
    (0 by default; the MERL database stores negative values there). Note that a query whose own
    directions are above the horizon can still fall in such a cell near grazing (a cell spans up to
    ~2 deg in theta_half), where lookup returns ``below_horizon``.
    """
    th, td, pd = cell_centres()
    wi, wo = directions_from_half_diff(th.ravel(), td.ravel(), pd.ravel())
    out = np.empty((wi.shape[0], 3))
    for s in range(0, wi.shape[0], chunk):
        v = np.asarray(brdf(wi[s:s + chunk], wo[s:s + chunk]), dtype=float)
        n = wi[s:s + chunk].shape[0]
        if v.shape == (n,):
            v = np.repeat(v[:, None], 3, axis=1)
        elif v.shape != (n, 3):
            raise BasisError(f"brdf returned shape {v.shape} for {n} direction pairs: need ({n},) or ({n}, 3)")
        out[s:s + chunk] = v
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    out[below] = below_horizon
    return np.ascontiguousarray(out.T.reshape(SHAPE))
