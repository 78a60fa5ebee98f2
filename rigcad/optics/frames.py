"""Rigid placements of the rig's bodies (kernel-free): a :class:`Pose` (rotation and translation,
with paired ``localize``/``globalize``) and a :class:`Misalignment` of the four movable components
(projector, camera, paraboloid, dome). Frame: mm, sample point O at the origin, optical axis +z;
tilts in radians. Every perturbed rig is its own frozen value; nothing shared is moved in place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Pose:
    """A rigid placement: global = rotation @ local + translation (mm)."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @classmethod
    def misaligned(cls, offset=(0.0, 0.0, 0.0), tilt: float = 0.0, tilt_axis=(0.0, 1.0, 0.0),
                   pivot=(0.0, 0.0, 0.0)) -> "Pose":
        """Tilt by ``tilt`` rad about ``tilt_axis`` through ``pivot``, then shift by ``offset`` mm."""
        axis = np.asarray(tilt_axis, float)
        axis = axis / np.linalg.norm(axis)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rot = np.eye(3) + math.sin(tilt) * k + (1 - math.cos(tilt)) * (k @ k)  # Rodrigues
        pivot = np.asarray(pivot, float)
        return cls(rot, pivot + np.asarray(offset, float) - rot @ pivot)

    @property
    def is_identity(self) -> bool:
        return bool(np.array_equal(self.rotation, np.eye(3)) and not np.any(self.translation))

    def localize(self, points: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and directions (n, 3) from the global frame into this body's frame."""
        if self.is_identity:
            return points, dirs
        return (points - self.translation) @ self.rotation, dirs @ self.rotation

    def globalize_points(self, points: np.ndarray) -> np.ndarray:
        return points if self.is_identity else points @ self.rotation.T + self.translation

    def globalize_dirs(self, dirs: np.ndarray) -> np.ndarray:
        return dirs if self.is_identity else dirs @ self.rotation.T



COMPONENTS = ("projector", "camera", "paraboloid", "dome")
DOFS = ("dx", "dz", "tilt")  # x and y are equivalent by symmetry (the beam aside)


@dataclass(frozen=True)
class Misalignment:
    """Offsets (mm, (3,)) and tilts (rad, with a unit horizontal axis) of the four components."""

    offsets: dict
    tilts: dict
    axes: dict

    @classmethod
    def none(cls) -> "Misalignment":
        return cls({c: (0.0, 0.0, 0.0) for c in COMPONENTS}, {c: 0.0 for c in COMPONENTS},
                   {c: (0.0, 1.0, 0.0) for c in COMPONENTS})

    def with_(self, component: str, offset=None, tilt=None, axis=None) -> "Misalignment":
        o, t, a = dict(self.offsets), dict(self.tilts), dict(self.axes)
        if offset is not None:
            o[component] = tuple(offset)
        if tilt is not None:
            t[component] = float(tilt)
        if axis is not None:
            a[component] = tuple(axis)
        return Misalignment(o, t, a)

    def pose(self, component: str, geo) -> Pose:
        """The component's pose; tilts pivot about the COP (camera, projector), the paraboloid's
        vertex, or the sample point O (dome). ``geo``: the rig's derived geometry."""
        if not any(self.offsets[component]) and self.tilts[component] == 0.0:
            return Pose()
        return Pose.misaligned(self.offsets[component], self.tilts[component], self.axes[component],
                               self.pivot(component, geo))

    @staticmethod
    def pivot(component: str, geo) -> tuple[float, float, float]:
        """The point (mm) ``component``'s tilt turns it about, as designed: the COP (camera,
        projector), the paraboloid's vertex, or the sample point O (dome)."""
        return {"projector": (0, 0, geo.cop_z), "camera": (0, 0, geo.cop_z),
                "paraboloid": (0, 0, geo.vertex_z), "dome": (0, 0, 0)}[component]
