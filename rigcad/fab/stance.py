"""How the rig stands on the bench (``datum.mount: base_plate``), measured on the parts' meshes (mm, rig frame).

The bench is the plane through the rig's lowest point. A part touches it where its mesh has faces facing
down within BENCH_TOUCH_MM of that plane; each connected set of such faces is one support patch. The rig
stands without rocking when those patches span a polygon round its centre of mass: the mass of each part in
the rig at its mesh's centroid (printed: its shell, the mesh's area times the printer's perimeters' skin,
solid, and the rest at the printer's infill share (rigcad.fab.loads.skin), of the printer's material; bought:
its stated mass (rigcad.parts.recipe.Part.mass_kg: an extrusion), else its volume of the aluminium the
sample holder is turned from, rigcad.fab.loads.ALUMINIUM_DENSITY), and
the projector and the camera (rigcad.fab.loads masses) at their bodies' centres. The margin is the
horizontal distance from the centre of mass to the support polygon's nearest edge; the tip angle, the tilt
of the bench that would bring the centre of mass over that edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.fab import loads
from rigcad.fab.printers import Printer

#: A face within this height (mm) of the rig's lowest point, facing down, touches the bench (a mesh's
#: flat faces lie on their plane to float64 rounding; nothing else comes within 0.01 mm of it).
BENCH_TOUCH_MM = 0.01
#: A face faces down when its normal's z is below this (within 2.6 deg of straight down).
DOWN_NZ = -0.999


@dataclass(frozen=True)
class Patch:
    """One support: the part, its faces' area (mm2), its centroid (x, y; mm) and its corners' hull (k, 2)."""

    part: str
    area_mm2: float
    centroid: tuple[float, float]
    outline: np.ndarray


@dataclass(frozen=True)
class Stance:
    """The rig on the bench: the bench's height (mm), the support patches, the polygon they span
    ((k, 2) mm, counter-clockwise), the mass (kg) and centre of mass (x, y, z; mm), the margin (mm, the
    centre of mass's distance inside the polygon's nearest edge; negative outside), the tip angle (rad)
    and each part's lowest point's height over the bench (mm)."""

    bench_z: float
    patches: tuple[Patch, ...]
    polygon: np.ndarray
    mass_kg: float
    centre_of_mass: tuple[float, float, float]
    margin_mm: float
    tip_angle: float
    clearance_mm: dict[str, float]


def _patches(name: str, mesh, bench_z: float) -> list[Patch]:
    """The down-facing faces of ``mesh`` on the bench plane, grouped into connected patches."""
    import trimesh

    z = mesh.vertices[mesh.faces][:, :, 2]
    on = np.flatnonzero((z.max(axis=1) <= bench_z + BENCH_TOUCH_MM) & (mesh.face_normals[:, 2] < DOWN_NZ))
    if not len(on):
        return []
    groups = trimesh.graph.connected_components(mesh.face_adjacency, nodes=on, min_len=1)
    out = []
    for g in groups:
        faces = np.asarray(g, dtype=int)
        area = mesh.area_faces[faces]
        centres = mesh.triangles_center[faces][:, :2]
        pts = mesh.vertices[np.unique(mesh.faces[faces])][:, :2]
        out.append(Patch(name, float(area.sum()), tuple(float(v) for v in area @ centres / area.sum()), pts))
    return sorted(out, key=lambda p: (p.part, p.centroid))


def _polygon_margin(points: np.ndarray, point: np.ndarray) -> tuple[np.ndarray, float]:
    """The convex hull of ``points`` (n, 2) (counter-clockwise, (k, 2)) and ``point``'s distance inside its
    nearest edge (mm; negative outside)."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    eq = hull.equations  # unit outward normals n and offsets d: n . p + d <= 0 inside
    return points[hull.vertices], float(np.min(-(eq[:, :2] @ point + eq[:, 2])))


def part_mass(part, mesh, printer: Printer) -> float:
    """A part's mass (kg) from its ``mesh``: a bought part's stated mass or its volume of aluminium; a printed
    part's shell (area x the printer's side skin, at most its volume) solid and its core at the infill share,
    of the printer's material (rigcad.fab.loads.skin: the slicer settings, else the assumed skin)."""
    volume = abs(float(mesh.volume))
    if part.bought:
        return part.mass_kg if part.mass_kg is not None else loads.ALUMINIUM_DENSITY * volume
    skin = loads.skin(printer)
    shell = min(volume, float(mesh.area) * skin.side)
    return printer.material_density_g_cm3 * 1e-6 * (shell + skin.infill * (volume - shell))


def stance(rig, printer: Printer, masses: dict[str, float] | None = None) -> Stance:
    """How ``rig`` stands on the bench (module docstring); ``masses`` (kg) replace the projector's and the
    camera's assumed masses as in rigcad.fab.loads. Meshes at the pictures' chord error (0.3 mm: the
    masses' volumes within a fraction of a per cent)."""
    from rigcad.export.mesh import PICTURE_CHORD_ERROR

    meshes = {n: rig.mesh(n, PICTURE_CHORD_ERROR) for n, p in rig.recipes.items() if p.in_rig}
    bench_z = min(float(m.vertices[:, 2].min()) for m in meshes.values())
    patches = tuple(p for n, m in meshes.items() for p in _patches(n, m, bench_z))
    weights = [part_mass(rig.recipes[n], m, printer) for n, m in meshes.items()]
    centres = [np.asarray(m.center_mass, dtype=float) for m in meshes.values()]
    t = rig.layout.tower
    for key, box in (("projector", t.projector_box), ("camera", t.camera_box)):
        weights.append(loads._mass(rig.profile, key, masses))
        centres.append(0.5 * (np.asarray(box[0], dtype=float) + np.asarray(box[1], dtype=float)))
    w = np.asarray(weights)
    com = (w[:, None] * np.asarray(centres)).sum(axis=0) / w.sum()
    if not patches:
        polygon, margin = np.zeros((0, 2)), -math.inf
    else:
        pts = np.concatenate([p.outline for p in patches])
        polygon, margin = _polygon_margin(pts, com[:2])
    clearance = {n: float(m.vertices[:, 2].min()) - bench_z for n, m in meshes.items()}
    return Stance(bench_z, patches, polygon, float(w.sum()), tuple(float(v) for v in com), margin,
                  math.atan2(margin, com[2] - bench_z), clearance)


__all__ = ["BENCH_TOUCH_MM", "Patch", "Stance", "part_mass", "stance"]
