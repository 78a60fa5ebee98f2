"""The decoding's own bias: where the camera decodes a screen point, minus where its pixel's centre
ray meets the screen, predicted from the measured map itself and subtracted before the fit.

A camera pixel does not decode the screen point of its centre ray. It integrates the pattern over
its footprint (its sub-rays), and the lens's defocus blur mixes in its neighbours' footprints;
across a strongly curved pixel -> screen map (near grazing, and wherever the dome's sanding ripple
bends it) the phase of that mixture is not the centre ray's phase. The fit and the raxels, built on
centre rays, would read that bias as misalignment and surface error.

Predicting the decode needs no images. Footprint integration and blur are linear in the displayed
pattern, and the N-step phase of a sinusoid of period P is the argument of its first harmonic; so
the phase a pixel decodes is the argument of the blurred sum over its sub-rays of
sinc(a / P) sinc(b / P) exp(2 pi i c / P): c the sub-ray's screen coordinate (px), a and b its
footprint's extents along the axis (the parallelogram's mean of the exponential; the screen pixels'
staircase adds a common factor), zero where a sub-ray misses the screen.

Which map: the exact map E is the one that decodes to the measured map D, so E <- D - bias(E) from
E = D, the sub-rays from E's second-order Taylor expansion over the camera window (finite
differences), :data:`ITERATIONS` rounds. The fitted model's own map (a rig moved as a whole, no
surface error) was tried first and made the corrected map worse: the bias is dominated by the
surface error's curvature, which that model lacks (docs/calibrate-notes.md has the figures).

The blur is the lens's Gaussian sigma in camera pixels, as the profile states it
(``calibration.sim_blur``: the simulation's; a real capture states its lens's from a focus test).
It is not estimated from the captures."""

from __future__ import annotations

import numpy as np

from rigcad.calibrate.patterns import AXES, Sequence

#: Sub-rays per camera pixel side: the pixel's own area, as the simulation renders it.
SUB_RAYS = 3
#: Rounds of the fixed point E <- D - bias(E) (:func:`map_bias`).
ITERATIONS = 1


def _harmonic(cx: np.ndarray, cy: np.ndarray, edges: np.ndarray, seq: Sequence, axis: int, period: int,
              n: int, s: int) -> np.ndarray:
    """Per camera pixel, the sum over its ``s * s`` sub-rays of the pattern's first harmonic (complex)."""
    w, h = seq.resolution
    c = cx if axis == 0 else cy
    on = np.isfinite(cx) & np.isfinite(cy) & (cx >= 0) & (cx < w) & (cy >= 0) & (cy < h)
    damp = np.sinc(edges[:, 0, axis] / period) * np.sinc(edges[:, 1, axis] / period)
    z = np.where(on, damp * np.exp(2j * np.pi * np.nan_to_num(c) / period), 0.0)
    return z.reshape(n, s * s).sum(axis=1)


def map_bias(decoded: list, shape: tuple[int, int], seq: Sequence, blur_px: float,
             iterations: int = ITERATIONS) -> np.ndarray:
    """(window pixels, heights, 2) mm: decoded minus exact screen point per pixel and height, from
    the ``decoded`` captures (:class:`rigcad.calibrate.decode.Decoded` over a window of ``shape``)
    by the fixed point of the module docstring; NaN where a pixel or its neighbours did not decode.
    ``blur_px``: the lens's Gaussian sigma (camera px)."""
    from rigcad.calibrate.simulate import sub_offsets

    off = sub_offsets(SUB_RAYS)
    oc, orow = [a.ravel() for a in np.meshgrid(off, off)]
    n = int(np.prod(shape))
    out = np.zeros((n, len(decoded), 2))
    for k, d in enumerate(decoded):
        measured = [c.reshape(shape) for c in seq.from_mm(d.u, d.v)]
        levels = {a: d.axes[a].level.ravel() for a in AXES}
        exact = measured
        for _ in range(iterations):
            sub = [_taylor(e, oc, orow) for e in exact]
            shift = _shift(sub, [e.ravel() for e in exact], shape, seq, levels, blur_px)
            out[:, k] = shift
            exact = [m - np.nan_to_num(sh.reshape(shape) / (seq.pitch if a == 0 else -seq.pitch))
                     for a, (m, sh) in enumerate(zip(measured, shift.T))]
    return out


def _taylor(e: np.ndarray, oc: np.ndarray, orow: np.ndarray) -> np.ndarray:
    """A window map ``e`` (rows, cols) at sub-pixel offsets (columns ``oc``, rows ``orow``): (n * s * s,)."""
    ec, er = np.gradient(e, axis=1), np.gradient(e, axis=0)
    ecc, err, ecr = np.gradient(ec, axis=1), np.gradient(er, axis=0), np.gradient(ec, axis=0)
    f = [a.ravel()[:, None] for a in (e, ec, er, ecc, err, ecr)]
    return (f[0] + f[1] * oc + f[2] * orow + 0.5 * f[3] * oc ** 2 + 0.5 * f[4] * orow ** 2 + f[5] * oc * orow).ravel()


def _shift(sub: tuple, exact: tuple, shape: tuple[int, int], seq: Sequence, levels: dict,
           blur_px: float) -> np.ndarray:
    """(n, 2) mm: decoded minus exact screen point on one screen, from the sub-rays' screen
    coordinates ``sub`` (cx, cy) and the centre rays' ``exact`` (cx, cy) (px); ``levels`` per axis."""
    from scipy.ndimage import gaussian_filter

    from rigcad.calibrate.simulate import sub_edges

    s, n = SUB_RAYS, int(np.prod(shape))
    cx, cy = sub
    edges = sub_edges(cx.reshape(n, s, s), cy.reshape(n, s, s), shape)
    out = np.full((n, 2), np.nan)
    for a, axis in enumerate(AXES):
        for j, period in enumerate(seq.periods):
            pick = levels[axis] == j
            if not pick.any():
                continue
            z = _harmonic(cx, cy, edges, seq, a, period, n, s).reshape(shape)
            if blur_px > 0:
                z = gaussian_filter(z.real, blur_px) + 1j * gaussian_filter(z.imag, blur_px)
            turn = np.angle(z.ravel() * np.exp(-2j * np.pi * exact[a] / period)) / (2 * np.pi)
            shift = np.where(np.abs(z.ravel()) > 0, turn * period, np.nan)  # screen px
            out[pick, a] = shift[pick] * (seq.pitch if a == 0 else -seq.pitch)
    return out
