"""Figures of the 3D ray check (matplotlib, Agg; no metadata, same result -> same bytes). They draw
what a RayCheck holds and compute nothing new. (rigcad/plots.py holds the other stages' figures;
these live here until they move there.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigcad.export.atomic import write_bytes
from rigcad.plots import _png, plt


def spot_diagram(result, path: Path) -> Path:
    """Left: where the returning rays cross the sample plane z = 0 (um), theta <= 80 deg (nearer
    grazing the landing point is ill-conditioned); right: the spot radius (distance from O to each
    ray) against theta."""
    tr = result.trace
    ok = tr.ok
    theta = np.degrees(tr.theta[ok])
    land = tr.landing[ok] * 1e3
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    sel = theta <= 80
    sc = a.scatter(land[sel, 0], land[sel, 1], c=theta[sel], s=1, cmap="viridis")
    fig.colorbar(sc, ax=a, label="theta (deg)")
    a.set_aspect("equal")
    a.set_xlabel("x on the sample (um)")
    a.set_ylabel("y on the sample (um)")
    rep = result.report
    a.set_title(f"{rep['profile']['name']}: landing points, mode {rep['mode']}")
    b.semilogy(theta, np.maximum(tr.miss[ok] * 1e3, 1e-9), ",", alpha=0.5)
    b.set_xlabel("theta (deg)")
    b.set_ylabel("distance from O to the ray (um)")
    b.set_title("spot radius per ray")
    b.grid(True, alpha=0.3)
    return write_bytes(Path(path), _png(fig))


def theta_map(result, path: Path) -> Path:
    """Incidence angle theta per projector pixel over the traced window, lost pixels grey; and
    theta against pixel radius along the fan (with px/deg)."""
    tm = result.theta_map
    g = result.report["pixel_grid"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    r0, c0 = g["window_origin_row_col"]
    h, w = tm.shape
    a.imshow(np.where(result.status_map > 1, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2,
             extent=(c0, c0 + w, r0 + h, r0), interpolation="nearest")
    im = a.imshow(tm, cmap="viridis", extent=(c0, c0 + w, r0 + h, r0), interpolation="nearest")
    fig.colorbar(im, ax=a, label="theta (deg)")
    a.set_xlabel("projector column (px)")
    a.set_ylabel("projector row (px)")
    a.set_title("incidence angle per pixel (grey: occluded)")
    f = result.fan
    b.plot(f["theta_deg"], f["pixel_radius_px"], "-")
    b2 = b.twinx()
    b2.plot(f["theta_deg"], f["px_per_deg"], "r-", lw=0.8)
    b2.set_ylabel("pixels per degree", color="r")
    b.set_xlabel("theta (deg)")
    b.set_ylabel("pixel radius from the axis (px)")
    b.set_title(f"fan at azimuth {f['summary']['azimuth_deg']:.0f} deg")
    b.grid(True, alpha=0.3)
    return write_bytes(Path(path), _png(fig))
