"""Figures of the fabrication stage (matplotlib, Agg; PNG bytes without metadata, so the same
result gives the same bytes, as rigcad.plots). They draw results; they compute nothing.
(Candidates to move into rigcad/plots.py, which this stage does not edit.)"""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def staircase_map(points: np.ndarray, cusp: np.ndarray, layer: float, title: str) -> bytes:
    """Cusp height (um) over the mirror at its contour points: azimuth (deg) x height z (mm) in
    the part's working frame; ``points`` (n, 3) mm, ``cusp`` (n,) mm."""
    ok = np.isfinite(cusp)
    p, c = points[ok], cusp[ok] * 1000.0
    if len(p) > 60000:  # enough dots for the eye; a fixed stride keeps the picture deterministic
        s = int(np.ceil(len(p) / 60000))
        p, c = p[::s], c[::s]
    az = np.degrees(np.arctan2(p[:, 1], p[:, 0])) % 360.0
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    sc = ax.scatter(az, p[:, 2], c=c, s=1.5, cmap="viridis", vmin=0.0, vmax=layer * 1000.0, linewidths=0)
    fig.colorbar(sc, ax=ax, label="cusp height (um)")
    ax.set_xlim(0, 360)
    ax.set_xlabel("azimuth about the optical axis (deg)")
    ax.set_ylabel("height z (mm, working position)")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return _png(fig)
