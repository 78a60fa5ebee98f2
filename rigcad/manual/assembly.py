"""The assembled rig as the manual and the 3D view show it: every part of ``rig.recipes`` that
stands in the rig (``Part.in_rig``), meshed coarsely for pictures, in its working position, with
an exploded-view offset and an assembly order.

Nothing here restates a part's size: the meshes come from the recipes (manifold3d, the STL's
mesher) and the offsets from the meshes' bounding boxes, so a part added to ``rigcad.parts``
appears in the view, the exploded pictures and the manual's assembly steps without a change here.

Exploded view (one rule, every part): the base part is the widest part at or below the sample
plane (its top at z <= 0: the base plate). Parts above it are taken by their top (z max) from low
to high, and each is lifted until its bottom clears, by a gap, every part placed before it whose
x-y footprint it overlaps, so the enclosing dome ends up above the paraboloid and the beam while a
column beside the rig stays on the bench; parts below the base go down the same way. The
instruments (``rig.instruments``: projector, camera, lenses, splitter, shim stacks) join the parts;
the centre-of-projection markers are shown but never moved or assembled. Frame: mm, sample point O at the origin, optical axis +z.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError

#: Gap between exploded parts, as a fraction of the assembled rig's height.
EXPLODE_GAP = 0.08
#: The order the thesis's rig goes together (parts known today); parts not listed follow, by height.
KNOWN_ORDER = ("base_plate", "sample_holder", "beam", "paraboloid", "dome")
#: Opacity of a part that encloses others (:func:`encloses`: the dome) in the 3D views.
SEE_THROUGH_OPACITY = 0.3


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
    bought: bool = False  #: an instrument or optic (``rig.instruments``), not printed
    marker: bool = False  #: a centre-of-projection marker: shown in the view, not assembled

    @property
    def lo(self) -> np.ndarray:
        return self.vertices.min(axis=0)

    @property
    def hi(self) -> np.ndarray:
        return self.vertices.max(axis=0)


def picture_meshes(rig, chord_error: float | None = None) -> list[PartMesh]:
    """Every in-rig part of ``rig`` (a :class:`rigcad.rig.Rig`) as a PartMesh, in assembly order,
    meshed at ``chord_error`` mm (default the picture chord, export.mesh.PICTURE_CHORD_ERROR)."""
    from rigcad.export.mesh import PICTURE_CHORD_ERROR

    chord_error = PICTURE_CHORD_ERROR if chord_error is None else chord_error
    raw = []
    # the instruments are bought, but for the shim stacks: those are the printed tower_shim
    bought = {p.name for p in getattr(rig, "instruments", ()) if "shim" not in p.name}
    for part in [*rig.recipes.values(), *getattr(rig, "instruments", ())]:
        if not part.in_rig:
            continue
        mesh = rig.mesh(part, chord_error)
        raw.append((part, np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)))
    if not raw:
        raise GeometryError(f"{rig.name}: no part stands in the rig (every recipe has in_rig = False)")
    markers = {p.name for p, _, _ in raw if p.name.endswith("_marker")}
    offsets = explode_offsets({p.name: (v.min(axis=0), v.max(axis=0)) for p, v, _ in raw if p.name not in markers})
    meshes = {p.name: PartMesh(p.name, v, f, tuple(p.color), p.description, p.quantity,
                               offsets.get(p.name, np.zeros(3)), p.name in bought, p.name in markers)
              for p, v, f in raw}
    order = assembly_order({n: (m.lo, m.hi) for n, m in meshes.items() if not m.marker}, bought)
    return [meshes[n] for n in order] + [meshes[n] for n in sorted(markers)]


def hex_color(color) -> str:
    """An RGB colour (3 floats in 0..1, clipped) as ``#rrggbb``: how a part's colour is shown."""
    return "#" + "".join(f"{int(round(255 * min(max(c, 0.0), 1.0))):02x}" for c in color)


def ray_colors(theta: np.ndarray) -> np.ndarray:
    """The colour (k, 3) of rays arriving at incidence angles ``theta`` (k,) rad, as every view of
    the assembled rig draws them: viridis of theta / 90 deg."""
    from matplotlib import colormaps

    if not len(theta):
        return np.zeros((0, 3))
    return np.asarray(colormaps["viridis"](np.degrees(np.asarray(theta, float)) / 90.0))[:, :3]


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
    placed = {base: (boxes[base][0], boxes[base][1])}

    def overlaps(a, b) -> bool:  # x-y footprints overlap: only then does one part stack on the other
        return bool(np.all(a[0][:2] < b[1][:2]) and np.all(b[0][:2] < a[1][:2]))

    above = sorted((n for n in boxes if n != base and 0.5 * (boxes[n][0][2] + boxes[n][1][2]) >= centre),
                   key=lambda n: (boxes[n][1][2], n))
    below = sorted((n for n in boxes if n != base and n not in above), key=lambda n: (-boxes[n][0][2], n))
    for n in above:
        under = [hi[2] for lo, hi in placed.values() if overlaps((lo, hi), boxes[n])]
        dz = max([0.0] + [top + gap - boxes[n][0][2] for top in under])
        out[n] = np.array([0.0, 0.0, dz])
        placed[n] = (boxes[n][0] + out[n], boxes[n][1] + out[n])
    for n in below:
        over = [lo[2] for lo, hi in placed.values() if overlaps((lo, hi), boxes[n])]
        dz = min([0.0] + [bottom - gap - boxes[n][1][2] for bottom in over])
        out[n] = np.array([0.0, 0.0, dz])
        placed[n] = (boxes[n][0] + out[n], boxes[n][1] + out[n])
    return out


def assembly_order(boxes: dict[str, tuple[np.ndarray, np.ndarray]], bought=frozenset()) -> list[str]:
    """The base part first, then the thesis's rig order for the parts it has (KNOWN_ORDER), then
    any other part from the lowest bottom to the highest (what a part stands on goes in first; at
    the same height printed parts before bought ones)."""
    base = _base(boxes)
    known = [n for n in KNOWN_ORDER if n in boxes and n != base]
    rest = sorted((n for n in boxes if n != base and n not in known),
                  key=lambda n: (round(float(boxes[n][0][2])), n in bought, n))
    return [base, *known, *rest]


def steps(meshes: list[PartMesh]) -> list[list[int]]:
    """Assembly steps: indices into ``meshes`` (markers left out); parts named alike but for a
    trailing number (projector_shims_1..4) go in one step."""
    import re

    out: list[list[int]] = []
    stems: dict[str, int] = {}
    for i, m in enumerate(meshes):
        if m.marker:
            continue
        stem = re.sub(r"_\d+$", "", m.name)
        if stem != m.name and stem in stems:
            out[stems[stem]].append(i)
            continue
        stems[stem] = len(out)
        out.append([i])
    return out


def step_offsets(meshes: list[PartMesh], done: list[int], new: list[int]) -> dict[int, np.ndarray]:
    """Where the parts of one step are drawn before they go in: lifted (or lowered, for a part below
    the base) just clear of the parts already in place whose x-y footprint they overlap."""
    if not done:
        return {i: np.zeros(3) for i in new}
    lo = np.min([meshes[i].lo for i in new], axis=0)
    hi = np.max([meshes[i].hi for i in new], axis=0)
    size = max(float(np.ptp([meshes[i].hi[2] for i in done] + [meshes[i].lo[2] for i in done])), 1.0)
    gap = EXPLODE_GAP * size
    down = all(meshes[i].explode[2] < 0 for i in new)
    dz = 0.0
    for i in done:
        m = meshes[i]
        if np.all(m.lo[:2] < hi[:2]) and np.all(lo[:2] < m.hi[:2]):
            dz = min(dz, m.lo[2] - gap - hi[2]) if down else max(dz, m.hi[2] + gap - lo[2])
    return {i: np.array([0.0, 0.0, dz]) for i in new}


def encloses(meshes: list[PartMesh]) -> set[str]:
    """Parts whose bounding box holds another part's whole bounding box (the dome holds the
    paraboloid): drawn see-through in the view, cut away in the pictures."""
    out = set()
    for a in meshes:
        for b in meshes:
            if a is not b and np.all(a.lo <= b.lo) and np.all(b.hi <= a.hi):
                out.add(a.name)
    return out


#: The half turn about x that stands a part upside down (y -> -y, z -> -z): a lifted dome on the bench.
UPSIDE_DOWN = np.diag([1.0, -1.0, -1.0])


def lifted_view(meshes: list[PartMesh], done: list[int], encloser: str) -> tuple[list[PartMesh], list[int], np.ndarray]:
    """A step's picture when it is done with ``encloser`` (the dome) lifted off its register and stood upside
    down: every mesh turned a half turn about x (UPSIDE_DOWN, about the origin), the parts in place kept to the
    encloser and what rides with it (the parts in place standing no lower than its base with their centre over it:
    the beam on its seats; the base plate under it stays), and the way in
    straight down (-z) into its open base, now on top. Returns (meshes, done, direction)."""
    import dataclasses

    turned = [dataclasses.replace(m, vertices=m.vertices @ UPSIDE_DOWN.T) for m in meshes]
    outer = next(i for i in done if meshes[i].name == encloser)
    lo, hi = meshes[outer].lo, meshes[outer].hi
    def rides(m: PartMesh) -> bool:
        centre = 0.5 * (m.lo + m.hi)
        return bool(m.lo[2] >= lo[2] - 1e-6 and np.all(lo[:2] <= centre[:2]) and np.all(centre[:2] <= hi[:2]))

    riding = [i for i in done if i == outer or rides(meshes[i])]
    return turned, riding, np.array([0.0, 0.0, -1.0])


def group_description(members, lead: str, meshes_by_name: dict) -> str:
    """What a step says its parts are: the ``lead`` part's description or, when the step puts in several
    parts named alike but for a trailing number (projector_shims_1..4, one per foot), each one's in their
    numbers' order, so a figure that belongs to one part (the shims under one foot) is said for each part
    and never read as the whole step's; descriptions that are the same are said once."""
    import re

    def stem(name: str) -> str:
        return re.sub(r"_\d+$", "", name)

    def number(name: str) -> int:
        m = re.search(r"_(\d+)$", name)
        return int(m.group(1)) if m else 0

    alike = sorted((n for n in members if stem(n) == stem(lead)), key=number) or [lead]
    return "; ".join(dict.fromkeys(meshes_by_name[n].description for n in alike))


__all__ = ["PartMesh", "assembly_order", "encloses", "explode_offsets", "group_description", "lifted_view", "UPSIDE_DOWN", "hex_color", "picture_meshes", "ray_colors",
           "step_offsets", "steps"]
