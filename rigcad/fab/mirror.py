"""A printed mirror surface as an exact surface of revolution, for the fabrication stage: signed
distance of 3D points to it, its normals, and which faces of a part's mesh lie on it.

Frame: the part's working position (mm, sample point at the origin, optical axis +z). Signed
distances are positive on the reflecting side (in the air in front of the mirror), negative
into the part's material.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.optics.surfaces import Meridian


@dataclass(frozen=True)
class MirrorSurface:
    """The printed mirror ``printed`` (a Meridian behind the design surface by the coating),
    with ``design`` the coated surface it carries (for the optics)."""

    name: str
    printed: Meridian
    design: Meridian

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (n,) mm of 3D points (n, 3) to the printed surface (+ = reflecting side)."""
        points = np.asarray(points, dtype=float)
        return self.printed.distance(np.stack([np.hypot(points[:, 0], points[:, 1]), points[:, 2]], axis=-1))

    def normals(self, points: np.ndarray) -> np.ndarray:
        """Unit normals (n, 3) of the surface at the feet of ``points`` (n, 3), reflecting side."""
        points = np.asarray(points, dtype=float)
        r = np.hypot(points[:, 0], points[:, 1])
        u = self.printed.foot_points(np.stack([r, points[:, 2]], axis=-1))
        n2 = self.printed.normals(u)
        phi = np.arctan2(points[:, 1], points[:, 0])
        return np.stack([n2[:, 0] * np.cos(phi), n2[:, 0] * np.sin(phi), n2[:, 1]], axis=-1)


@dataclass(frozen=True)
class MirrorFaces:
    """The faces of a mesh on a mirror: indices, centroids (n, 3), areas (n,) mm^2, exact unit
    normals (n, 3) at the centroids (reflecting side)."""

    index: np.ndarray
    centroids: np.ndarray
    areas: np.ndarray
    normals: np.ndarray

    @property
    def area(self) -> float:
        return float(self.areas.sum())


def mirror_faces(vertices: np.ndarray, faces: np.ndarray, mirror: MirrorSurface, tol: float) -> MirrorFaces:
    """Faces of the mesh (part frame) whose three vertices lie within ``tol`` mm of the printed
    mirror and whose outward normal faces its reflecting side (within 25 deg, far wider than the
    facets' deviation at the chord error and far narrower than any other face of a part)."""
    d = np.abs(mirror.signed_distance(vertices))
    on = (d[faces] < tol).all(axis=1)
    tri = vertices[faces[on]]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cross, axis=1)
    keep = area2 > 0
    tri, cross, area2, idx = tri[keep], cross[keep], area2[keep], np.nonzero(on)[0][keep]
    centroid = tri.mean(axis=1)
    exact = mirror.normals(centroid)
    facing = np.einsum("ij,ij->i", cross / area2[:, None], exact) > np.cos(np.radians(25.0))
    return MirrorFaces(idx[facing], centroid[facing], 0.5 * area2[facing], exact[facing])
