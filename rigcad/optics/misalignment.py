"""2D misalignment study (thesis 3.2.2): move one component, trace the design's chief rays, and
measure how far they converge from the sample point O.

Camera and projector both sit at the COP (the beam splitter folds one onto the other); in a
pinhole model a horizontal or vertical offset of either moves the COP the same way, so the two
share one trace and are reported under both names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.paraboloid import Paraboloid
from rigcad.optics.trace2d import DomeCurve, Trace, trace

COMPONENT_OFFSETS = ("camera_dx", "camera_dz", "projector_dx", "projector_dz", "paraboloid_dx", "dome_dx")


@dataclass(frozen=True)
class Offsets:
    """Displacements (mm) of the COP, the paraboloid and the dome in the meridional plane."""

    cop_dx: float = 0.0
    cop_dz: float = 0.0
    paraboloid_dx: float = 0.0
    dome_dx: float = 0.0


def offsets_for(component: str, amount: float) -> Offsets:
    """The :class:`Offsets` that move ``component`` (a name in COMPONENT_OFFSETS) by ``amount`` mm."""
    device, axis = component.split("_")
    if device in ("camera", "projector"):
        return Offsets(cop_dx=amount) if axis == "dx" else Offsets(cop_dz=amount)
    return Offsets(paraboloid_dx=amount) if device == "paraboloid" else Offsets(dome_dx=amount)


def convergence_point(tr: Trace, dirs_back: np.ndarray) -> np.ndarray:
    """Least-squares point closest to all returning ray lines (2,), or NaN if under two rays."""
    ok = tr.ok
    if np.count_nonzero(ok) < 2:
        return np.array([np.nan, np.nan])
    D = tr.dome_point[ok]
    v = dirs_back[ok]
    n = np.stack([-v[:, 1], v[:, 0]], axis=-1)  # line normals
    A = n.T @ n
    b = n.T @ np.sum(n * D, axis=-1)
    return np.linalg.lstsq(A, b, rcond=None)[0]


def misaligned_trace(paraboloid: Paraboloid, dome: DomeCurve, origins: np.ndarray, chief_dirs: np.ndarray,
                     offsets: Offsets) -> Trace:
    """Trace the chief rays (origins and pixel directions, (n, 2)) through the displaced system.

    The source offsets move every origin: the COP itself, or for a COP at infinity the parallel
    rays' start points (where a vertical offset changes nothing).
    """
    moved = origins + np.array([offsets.cop_dx, offsets.cop_dz])
    para = Paraboloid(paraboloid.focal_length, paraboloid.vertex_z, paraboloid.rim_radius,
                      paraboloid.dx + offsets.paraboloid_dx)
    return trace(para, dome.shifted(offsets.dome_dx), moved, chief_dirs)


def convergence_error(tr: Trace, reference: Trace) -> dict[str, float]:
    """Figures of a misaligned trace against the aligned ``reference`` (mm, rad)."""
    ok = tr.ok
    miss = np.abs(tr.miss[ok])
    theta_err = np.abs(tr.theta - reference.theta)[ok & reference.ok]
    dirs = np.stack([-np.sin(tr.theta), -np.cos(tr.theta)], axis=-1)
    point = convergence_point(tr, dirs)
    return {
        "rms_miss_mm": float(np.sqrt(np.mean(miss**2))) if miss.size else float("nan"),
        "max_miss_mm": float(miss.max()) if miss.size else float("nan"),
        "convergence_point_x_mm": float(point[0]),
        "convergence_point_z_mm": float(point[1]),
        "max_theta_error_rad": float(theta_err.max()) if theta_err.size else float("nan"),
        "rays_lost": int(np.count_nonzero(~ok)),
        "rays": int(ok.size),
    }
