"""The toleranced parameters: each movable component (projector, camera, paraboloid, dome) has a
lateral placement tolerance (``offset``, mm: uniform in a disc), a height tolerance (``height``,
mm: uniform in +-), and a tilt tolerance (``tilt``, rad: uniform 0..tol about a random horizontal
axis), the ``tolerancing.*`` keys of the profile (rigcad.profile.schema.TolerancingParams).

One-at-a-time moves (sensitivity, inverse limits) take the worst of two directions of each: an
offset along x and along y (the beam runs along x, so they differ), a height up and down, a tilt
about x and about y. Pivots as rigcad.optics.frames.Misalignment.pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.optics.frames import COMPONENTS, Misalignment

KINDS = ("offset", "height", "tilt")
#: Largest move an inverse limit searches (mm, rad): past these the rig is not a rig (the dome's
#: bolt holes are 4.5 mm; profile tilts stop at 10 deg).
SEARCH_CAP = {"offset": 50.0, "height": 50.0, "tilt": math.radians(10.0)}
#: First trial move when the profile tolerance is 0 (mm, rad).
DEFAULT_PROBE = {"offset": 0.1, "height": 0.1, "tilt": 1e-3}


@dataclass(frozen=True)
class Parameter:
    """One toleranced parameter: ``component`` and ``kind``; ``unit`` mm or rad."""

    component: str
    kind: str

    @property
    def name(self) -> str:
        return f"{self.component}_{self.kind}"

    @property
    def key(self) -> str:
        return f"tolerancing.{self.name}"

    @property
    def unit(self) -> str:
        return "rad" if self.kind == "tilt" else "mm"

    def tolerance(self, tol) -> float:
        """The profile's tolerance of this parameter (mm or rad)."""
        return float(getattr(tol, self.name))

    def moves(self, amount: float) -> list[Misalignment]:
        """The two one-at-a-time moves of size ``amount`` (see the module docstring)."""
        m = Misalignment.none()
        c = self.component
        if self.kind == "offset":
            return [m.with_(c, offset=(amount, 0.0, 0.0)), m.with_(c, offset=(0.0, amount, 0.0))]
        if self.kind == "height":
            return [m.with_(c, offset=(0.0, 0.0, amount)), m.with_(c, offset=(0.0, 0.0, -amount))]
        return [m.with_(c, tilt=amount, axis=(1.0, 0.0, 0.0)), m.with_(c, tilt=amount, axis=(0.0, 1.0, 0.0))]

    @property
    def devices(self) -> tuple[str, ...]:
        """The light paths a move of this component changes (the paraboloid and dome: both alike,
        so the projector's stands for them)."""
        return ("camera",) if self.component == "camera" else ("projector",)


PARAMETERS = tuple(Parameter(c, k) for c in COMPONENTS for k in KINDS)
