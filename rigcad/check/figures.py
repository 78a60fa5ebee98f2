"""Spot and angle figures of a 3D trace (mm, rad; units in keys), shared by the ray check, the
tower's camera view and the Monte Carlo. Frame: mm, sample point O at the origin, +z up."""

from __future__ import annotations

import numpy as np

from rigcad.check.rays import _cross, _dot
from rigcad.check.trace3d import Trace3D, convergence_point


def figures(tr: Trace3D, design_dirs: np.ndarray, reference: Trace3D | None = None,
            mirror_dirs: np.ndarray | None = None) -> dict:
    """Spot and angle figures of a trace (mm, rad; units in keys). ``max_angle_error_rad``: against
    the design direction of each ray's pixel (uncalibrated); ``max_mirror_angle_error_rad``:
    against the design direction of the paraboloid point each ray hit (what remains after
    calibration maps pixels to paraboloid points)."""
    ok = tr.ok
    miss = tr.miss[ok]
    x = convergence_point(tr)
    err = _angles(tr.arrival[ok], design_dirs[ok])
    out = {
        "rays": int(ok.size),
        "rays_ok": int(ok.sum()),
        "max_spot_radius_mm": float(miss.max()) if miss.size else float("nan"),
        "rms_spot_radius_mm": float(np.sqrt(np.mean(miss ** 2))) if miss.size else float("nan"),
        "convergence_point_mm": [float(v) for v in x],
        "convergence_offset_mm": float(np.linalg.norm(x)),
        "max_angle_error_rad": float(np.nanmax(err)) if err.size else float("nan"),
        "rms_angle_error_rad": float(np.sqrt(np.nanmean(err ** 2))) if err.size else float("nan"),
    }
    if mirror_dirs is not None:
        e2 = _angles(tr.arrival[ok], mirror_dirs[ok])
        out["max_mirror_angle_error_rad"] = float(np.nanmax(e2)) if e2.size else float("nan")
    if reference is not None:
        both = ok & reference.ok
        d = _angles(tr.arrival[both], reference.arrival[both])
        out["max_angle_change_rad"] = float(d.max()) if d.size else float("nan")
    return out


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles (rad) between unit rows of a and b (n, 3), accurate for small angles."""
    return np.arctan2(np.linalg.norm(_cross(a, b), axis=1), _dot(a, b))
