"""The assembled rig as the manual and the 3D view show it: every part of ``rig.recipes`` that
stands in the rig (``Part.in_rig``), meshed coarsely for pictures, in its working position, with
an exploded-view offset and an assembly order.

Nothing here restates a part's size: the meshes come from the recipes (manifold3d, the STL's
mesher) and the offsets from the meshes' bounding boxes, so a part added to ``rigcad.parts``
appears in the view, the exploded pictures and the manual's assembly steps without a change here.

Exploded view (one rule, every part): the base part is the widest part at or below the sample
plane (its top at z <= 0: the base plate). Parts above it are taken by their top (z max) from low
to high, and each is lifted until its bottom clears, by a gap, everything lifted before it, so
the enclosing dome ends up above the paraboloid and the beam; parts below the base go down the
same way. Frame: mm, sample point O at the origin, optical axis +z.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError

#: Chord error (mm) of the picture meshes: the view and the manual's pictures need no print
#: accuracy; 0.3 mm is what the part renders use (export.build.RENDER_CHORD_ERROR), ~0.1 % of the
#: dome's size, and keeps the whole rig at a few ten thousand triangles.
VIEW_CHORD_ERROR_MM = 0.3
#: Gap between exploded parts, as a fraction of the assembled rig's height.
EXPLODE_GAP = 0.08
#: The order the thesis's rig goes together (parts known today); parts not listed follow, by height.
KNOWN_ORDER = ("base_plate", "sample_holder", "beam", "paraboloid", "dome")


@dataclass(frozen=True)
class PartMesh:
    """One part in the assembly: picture mesh (vertices (n, 3) mm float64, faces (m, 3) int),
    colour, quantity and the exploded-view offset (3,) mm."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    color: tuple[float, float, float]
    description: str
    quantity: int
    explode: np.ndarray

    @property
    def lo(self) -> np.ndarray:
        return self.vertices.min(axis=0)

    @property
    def hi(self) -> np.ndarray:
        return self.vertices.max(axis=0)


def rig_meshes(rig, chord_error: float = VIEW_CHORD_ERROR_MM) -> list[PartMesh]:
    """Every in-rig part of ``rig`` (a :class:`rigcad.rig.Rig`) as a PartMesh, in assembly order."""
    from rigcad.export import mesh as M

    raw = []
    for name, part in rig.recipes.items():
        if not part.in_rig:
            continue
        v, f = M.mesh_arrays(M.build(part.solid, chord_error))
        raw.append((part, np.asarray(v, float), np.asarray(f, np.int64)))
    if not raw:
        raise GeometryError(f"{rig.name}: no part stands in the rig (every recipe has in_rig = False)")
    offsets = explode_offsets({p.name: (v.min(axis=0), v.max(axis=0)) for p, v, _ in raw})
    meshes = {p.name: PartMesh(p.name, v, f, tuple(p.color), p.description, p.quantity, offsets[p.name])
              for p, v, f in raw}
    return [meshes[n] for n in assembly_order({n: (m.lo, m.hi) for n, m in meshes.items()})]


def _base(boxes: dict[str, tuple[np.ndarray, np.ndarray]]) -> str:
    """The part everything else is placed on: the widest (x-y footprint) part whose top is at or
    below the sample plane; without one, the lowest part."""
    under = [n for n, (lo, hi) in boxes.items() if hi[2] <= 1e-6]
    if under:
        return max(under, key=lambda n: (np.prod(boxes[n][1][:2] - boxes[n][0][:2]), n))
    return min(boxes, key=lambda n: (boxes[n][0][2], n))


def explode_offsets(boxes: dict[str, tuple[np.ndarray, np.ndarray]]) -> dict[str, np.ndarray]:
    """Exploded-view offsets (3,) mm per part from the parts' bounding boxes (lo, hi) (see the
    module docstring): along z only, the base part stays."""
    base = _base(boxes)
    lo_all = min(lo[2] for lo, _ in boxes.values())
    hi_all = max(hi[2] for _, hi in boxes.values())
    gap = EXPLODE_GAP * (hi_all - lo_all)
    centre = 0.5 * (boxes[base][0][2] + boxes[base][1][2])
    out = {base: np.zeros(3)}
    above = sorted((n for n in boxes if n != base and 0.5 * (boxes[n][0][2] + boxes[n][1][2]) >= centre),
                   key=lambda n: (boxes[n][1][2], n))
    below = sorted((n for n in boxes if n != base and n not in above), key=lambda n: (-boxes[n][0][2], n))
    top = boxes[base][1][2]
    for n in above:
        dz = max(0.0, top + gap - boxes[n][0][2])
        out[n] = np.array([0.0, 0.0, dz])
        top = max(top, boxes[n][1][2] + dz)
    bottom = boxes[base][0][2]
    for n in below:
        dz = min(0.0, bottom - gap - boxes[n][1][2])
        out[n] = np.array([0.0, 0.0, dz])
        bottom = min(bottom, boxes[n][0][2] + dz)
    return out


def assembly_order(boxes: dict[str, tuple[np.ndarray, np.ndarray]]) -> list[str]:
    """The base part first, then the thesis's rig order for the parts it has (KNOWN_ORDER), then
    any other part from the lowest top to the highest."""
    base = _base(boxes)
    known = [n for n in KNOWN_ORDER if n in boxes and n != base]
    rest = sorted((n for n in boxes if n != base and n not in known), key=lambda n: (boxes[n][1][2], n))
    return [base, *known, *rest]


__all__ = ["PartMesh", "VIEW_CHORD_ERROR_MM", "assembly_order", "explode_offsets", "rig_meshes"]
