"""The decoding's own bias (rigcad.calibrate.bias) against the renderer and the decoder it predicts:
frames rendered by exact footprint integration over a curved pixel -> screen map, blurred and
decoded by the N-step formula, independently of the harmonic model the bias uses."""

import numpy as np
from scipy.ndimage import binary_erosion, gaussian_filter

from rigcad.calibrate.bias import SUB_RAYS, map_bias
from rigcad.calibrate.decode import decode
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.simulate import sub_edges, sub_offsets

SEQ = Sequence(periods=(64, 8), steps=4, gray_bits=6, resolution=(1200, 1000), pitch=0.1)
SHAPE = (48, 56)
BLUR_PX = 0.7


def _exact(col: np.ndarray, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A curved map (screen px) like the rig's near grazing: footprints 2-4 screen px, bending, and
    a ripple of ~7 camera px (the sanding's rings on the dome)."""
    cx = 300 + 2.5 * col + 0.03 * col ** 2 + 0.01 * col * row + 0.8 * np.sin(2 * np.pi * row / 7)
    cy = 250 + 3.0 * row + 0.025 * row ** 2 + 0.6 * np.sin(2 * np.pi * (col + row) / 9)
    return cx, cy


def _decoded_capture():
    s = SUB_RAYS
    rows, cols = np.meshgrid(np.arange(SHAPE[0]), np.arange(SHAPE[1]), indexing="ij")
    off = sub_offsets(s)
    oc, orow = [a.ravel() for a in np.meshgrid(off, off)]
    cx, cy = _exact((cols.ravel()[:, None] + oc).ravel(), (rows.ravel()[:, None] + orow).ravel())
    n = rows.size
    edges = sub_edges(cx.reshape(n, s, s), cy.reshape(n, s, s), SHAPE)
    means = SEQ.footprint_means(SEQ.names(), cx, cy, edges)
    images = {name: gaussian_filter((0.05 + 0.8 * m.reshape(n, s * s).mean(axis=1)).reshape(SHAPE), BLUR_PX)
              for name, m in means.items()}
    return decode(SEQ, images, 0.1), _exact(cols.ravel().astype(float), rows.ravel().astype(float))


def test_the_measured_map_s_own_bias_is_removed():
    """The bias predicted from the decoded map at the capture's blur, subtracted: the decoded points
    within a third of their distance from the exact map's (median), and the tail shrinks too."""
    decoded, (ex, ey) = _decoded_capture()
    inner = binary_erosion(decoded.valid, iterations=3).ravel()
    assert inner.sum() > 1500
    truth = np.stack([SEQ.to_mm("x", ex), SEQ.to_mm("y", ey)], axis=-1)[inner]
    raw = np.stack([decoded.u.ravel(), decoded.v.ravel()], axis=-1)[inner]
    bias = map_bias([decoded], SHAPE, SEQ, BLUR_PX)[inner, 0]
    err_raw = np.linalg.norm(raw - truth, axis=1)
    err = np.linalg.norm(raw - bias - truth, axis=1)
    assert np.median(err_raw) > 0.005  # the blur across the curved map biases the decoded points (mm)
    assert np.median(err) < np.median(err_raw) / 3 and np.percentile(err, 99) < 0.9 * np.percentile(err_raw, 99)
