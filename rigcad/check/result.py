"""What a 3D trace returns, whichever tracer ran it (the numpy passes in rigcad.check.trace3d, the
compiled analytic kernels in rigcad.check.analytic, the compiled mesh passes in
rigcad.check.meshtrace): the per-ray status codes and the :class:`Trace3D` arrays. The tracers
import this module; it imports none of them."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

OK, MISSED_PARABOLOID, OCCLUDED_BY_MOUNT, OCCLUDED_BY_BEAM, OCCLUDED_BY_PARABOLOID, ESCAPED_TOP, \
    MISSED_DOME, ESCAPED_AFTER_DOME = range(8)
STATUS_NAMES = {
    OK: "ok",
    MISSED_PARABOLOID: "missed_paraboloid",
    OCCLUDED_BY_MOUNT: "hit_paraboloid_mount_from_the_source",
    OCCLUDED_BY_BEAM: "occluded_by_beam",
    OCCLUDED_BY_PARABOLOID: "occluded_by_paraboloid_on_return",
    ESCAPED_TOP: "escaped_through_dome_top",
    MISSED_DOME: "missed_dome_below_its_base",
    ESCAPED_AFTER_DOME: "escaped_after_dome",
}


@dataclass
class Trace3D:
    """Per ray (n,): ``status`` (STATUS_NAMES), ``segment`` where it was lost (0 = not lost),
    paraboloid and dome hit points ``p1``, ``p2`` (n, 3) mm (NaN where not reached), the final
    direction ``v`` (n, 3), ``landing`` (n, 3) on z = 0, total ``path_length`` mm, and ``miss``: the
    distance from O to the returning ray's line (mm; the convergence error, well conditioned even
    at grazing incidence, where the landing point is not). ``kernels``: rays per kernel of the
    analytic tracer (rigcad.check.analytic), ``{"mesh_compiled": n}`` for the compiled mesh reading
    (rigcad.check.meshtrace), or ``{"vectorised": n}`` for the numpy path."""

    status: np.ndarray
    segment: np.ndarray
    p1: np.ndarray
    p2: np.ndarray
    v: np.ndarray
    landing: np.ndarray
    path_length: np.ndarray
    miss: np.ndarray
    kernels: dict = field(default_factory=dict)

    @classmethod
    def allocate(cls, n: int, kernels: dict | None = None) -> "Trace3D":
        """Uninitialised arrays for n rays, for a compiled kernel to fill (every entry written)."""
        return cls(np.empty(n, np.int64), np.empty(n, np.int8), *(np.empty((n, 3)) for _ in range(4)), np.empty(n),
                   np.empty(n), dict(kernels or {}))

    @property
    def arrays(self) -> tuple:
        """The per-ray arrays in the kernels' argument order (status, segment, p1, p2, v, landing,
        path_length, miss)."""
        return (self.status, self.segment, self.p1, self.p2, self.v, self.landing, self.path_length, self.miss)

    @property
    def ok(self) -> np.ndarray:
        return self.status == OK

    @property
    def arrival(self) -> np.ndarray:
        """Unit directions (n, 3) from O towards where each ray comes from (-v)."""
        return -self.v

    @property
    def theta(self) -> np.ndarray:
        """Incidence angle (rad) from +z of each arriving ray (NaN where lost)."""
        a = self.arrival
        return np.where(self.ok, np.arctan2(np.hypot(a[:, 0], a[:, 1]), a[:, 2]), np.nan)

    @property
    def phi(self) -> np.ndarray:
        """Azimuth (rad, from +x towards +y) of each arriving ray (NaN where lost)."""
        a = self.arrival
        return np.where(self.ok, np.arctan2(a[:, 1], a[:, 0]), np.nan)
