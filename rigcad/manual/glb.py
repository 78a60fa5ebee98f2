"""``rigcad view --glb``: the assembled rig as one binary glTF 2.0 file (``rig.glb``) for Blender,
YACV or any glTF viewer, as the glTF 2.0 specification has it: metres, +Y up.

Scene: one root node ``rig`` that turns rigcad's frame into glTF's (a rotation of -90 deg about x,
so rigcad's +z, the optical axis, becomes +Y, and a scale of 0.001: mm to m); under it one node
per in-rig part (``manual.assembly.picture_meshes``: the picture meshes the HTML view draws, in
their working positions, vertices in mm), named after the part, with a PBR material of that name
in the part's colour (the see-through dome at the view's 30 % opacity); and one node ``rays``: the
traced rays (``manual.view.traced_rays``) as line segments (mode LINES), with a vertex colour by
their incidence angle at the sample (viridis of theta / 90 deg, as the view) and a material
``rays``. The part colours are display (sRGB) colours; glTF's colour factors and vertex colours
are linear, so they are converted (IEC 61966-2-1's transfer function).

Triangles carry vertex normals, smooth across edges whose faces turn by less than
:data:`CREASE_ANGLE_DEG` and split at sharper ones (a box stays a box, the dome stays smooth).
Every buffer view declares its target, POSITION accessors their bounds, as the Khronos glTF
validator asks.

Written here rather than by trimesh's exporter: that one leaves buffer views without a target,
the rays' material unnamed and has no way to split normals at creases. The bytes are a function
of the meshes and rays alone (no clock, no dict order from hashing): same rig, same file.
"""

from __future__ import annotations

import json
import math
import struct

import numpy as np

from rigcad._version import __version__
from rigcad.manual.assembly import SEE_THROUGH_OPACITY, PartMesh, encloses, ray_colors

#: Faces meeting at an edge at a larger angle than this (deg) get their own normals there (a
#: crease); smaller turns are shaded smooth. 30 deg: Blender's auto-smooth default; the picture
#: meshes' curved surfaces turn by a few degrees a facet, their machined edges by 90.
CREASE_ANGLE_DEG = 30.0
#: rigcad's frame (mm, +z up) -> glTF's (m, +Y up): the root node's rotation (unit quaternion
#: x, y, z, w: -90 deg about x) and scale.
ROOT_ROTATION = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))
ROOT_SCALE = 0.001

_FLOAT, _UINT, _UBYTE = 5126, 5125, 5121
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_LINES, _TRIANGLES = 1, 4


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """Display (sRGB, 0..1) colour components to linear ones (IEC 61966-2-1)."""
    c = np.clip(np.asarray(c, float), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def creased_normals(vertices: np.ndarray, faces: np.ndarray, crease_deg: float = CREASE_ANGLE_DEG):
    """Vertices split at creases, with unit normals: (vertices (k, 3), normals (k, 3), faces (m, 3)).

    Each triangle corner's normal is the area-weighted mean of the normals of the faces around its
    vertex that turn from its own face by less than ``crease_deg``; corners of one vertex with the
    same normal share one output vertex. A corner of a zero-area face takes the mean of all faces
    around its vertex (+z if that is zero too): it draws nothing, but glTF wants unit normals."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    tri = v[f]
    weighted = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # (m, 3), length = 2 area
    length = np.linalg.norm(weighted, axis=1, keepdims=True)
    unit = np.divide(weighted, length, out=np.zeros_like(weighted), where=length > 0)
    corner_vertex = f.reshape(-1)  # (3m,) corner c belongs to face c // 3
    corner_face = np.repeat(np.arange(len(f)), 3)
    order = np.argsort(corner_vertex, kind="stable")
    sorted_vertex = corner_vertex[order]
    starts = np.searchsorted(sorted_vertex, sorted_vertex, side="left")
    ends = np.searchsorted(sorted_vertex, sorted_vertex, side="right")
    counts = ends - starts
    # every pair (corner a, corner b) at one vertex: a's face and b's face meet there
    a = np.repeat(np.arange(len(order)), counts)
    b = starts[a] + (np.arange(len(a)) - np.repeat(np.cumsum(counts) - counts, counts))
    fa, fb = corner_face[order[a]], corner_face[order[b]]
    smooth = np.einsum("ij,ij->i", unit[fa], unit[fb]) >= math.cos(math.radians(crease_deg))
    normal = np.zeros((len(order), 3))
    np.add.at(normal, a[smooth], weighted[fb[smooth]])
    everything = np.zeros((len(v), 3))
    np.add.at(everything, corner_vertex, weighted[corner_face])
    corner_normal = np.empty_like(normal)
    corner_normal[order] = normal
    n = np.linalg.norm(corner_normal, axis=1)
    flat = n == 0
    corner_normal[flat] = everything[corner_vertex[flat]]
    n = np.linalg.norm(corner_normal, axis=1)
    corner_normal[n == 0] = (0.0, 0.0, 1.0)
    corner_normal /= np.linalg.norm(corner_normal, axis=1, keepdims=True)
    n32 = corner_normal.astype("<f4")
    key = np.concatenate([corner_vertex[:, None].astype("<i8").view("<f4"), n32], axis=1)
    _, first, inverse = np.unique(np.ascontiguousarray(key).view(np.dtype((np.void, key.itemsize * 5))).ravel(),
                                  return_index=True, return_inverse=True)
    # output vertices in order of their first corner: deterministic, close to the input's order
    rank = np.empty(len(first), np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    new_faces = rank[inverse.ravel()].reshape(-1, 3)
    pick = np.sort(first)
    return v[corner_vertex[pick]], n32[pick].astype(float), new_faces


class _Buffer:
    """The GLB's binary chunk: buffer views (4-byte aligned, each with its target) and accessors."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, component: int, kind: str, target: int, *, bounds: bool = False,
            normalized: bool = False) -> int:
        blob = np.ascontiguousarray(array).tobytes()
        self.data += b"\0" * (-len(self.data) % 4)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob), "target": target})
        self.data += blob
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": int(len(array)), "type": kind}
        if normalized:
            acc["normalized"] = True
        if bounds:
            acc["min"] = [float(x) for x in array.min(axis=0)]
            acc["max"] = [float(x) for x in array.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def _material(name: str, rgb, alpha: float) -> dict:
    factor = [float(round(c, 6)) for c in srgb_to_linear(rgb)] + [float(alpha)]
    return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": factor, "metallicFactor": 0.0,
                                                   "roughnessFactor": 0.8},
            "alphaMode": "BLEND" if alpha < 1 else "OPAQUE", "doubleSided": True}


def rig_gltf(rig, meshes: list[PartMesh], rays: dict) -> tuple[dict, bytes]:
    """The glTF JSON document and its binary buffer for ``meshes`` (assembly.picture_meshes) and
    ``rays`` (view.traced_rays); see the module docstring."""
    buf = _Buffer()
    nodes: list[dict] = [{"name": "rig", "rotation": list(ROOT_ROTATION), "scale": [ROOT_SCALE] * 3, "children": []}]
    gl_meshes: list[dict] = []
    materials: list[dict] = []
    see_through = encloses(meshes)
    for m in meshes:
        vertices, normals, faces = creased_normals(m.vertices, m.faces)
        attributes = {"POSITION": buf.add(vertices.astype("<f4"), _FLOAT, "VEC3", _ARRAY_BUFFER, bounds=True),
                      "NORMAL": buf.add(normals.astype("<f4"), _FLOAT, "VEC3", _ARRAY_BUFFER)}
        indices = buf.add(faces.reshape(-1).astype("<u4"), _UINT, "SCALAR", _ELEMENT_ARRAY_BUFFER)
        materials.append(_material(m.name, m.color, SEE_THROUGH_OPACITY if m.name in see_through else 1.0))
        gl_meshes.append({"name": m.name, "primitives": [{"attributes": attributes, "indices": indices,
                                                          "material": len(materials) - 1, "mode": _TRIANGLES}]})
        nodes[0]["children"].append(len(nodes))
        nodes.append({"name": m.name, "mesh": len(gl_meshes) - 1})
    lines = np.asarray(rays["lines"], float)
    if len(lines):
        k, n = lines.shape[:2]
        segments = np.stack([lines[:, :-1], lines[:, 1:]], axis=2).reshape(-1, 3)  # 2 (n - 1) vertices a ray
        rgb = srgb_to_linear(ray_colors(rays["theta"]))
        rgba = np.column_stack([np.round(rgb * 255), np.full(k, 255.0)]).astype(np.uint8)
        colors = np.repeat(rgba, 2 * (n - 1), axis=0)
        attributes = {"POSITION": buf.add(segments.astype("<f4"), _FLOAT, "VEC3", _ARRAY_BUFFER, bounds=True),
                      "COLOR_0": buf.add(colors, _UBYTE, "VEC4", _ARRAY_BUFFER, normalized=True)}
        materials.append({"name": "rays", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                                                   "metallicFactor": 0.0, "roughnessFactor": 1.0}})
        gl_meshes.append({"name": "rays", "primitives": [{"attributes": attributes, "material": len(materials) - 1,
                                                          "mode": _LINES}]})
        nodes[0]["children"].append(len(nodes))
        nodes.append({"name": "rays", "mesh": len(gl_meshes) - 1})
    buf.data += b"\0" * (-len(buf.data) % 4)
    doc = {
        "asset": {"version": "2.0", "generator": f"rigcad {__version__}"},
        "scene": 0,
        "scenes": [{"name": rig.name, "nodes": [0], "extras": {
            "profile": rig.name, "units": "m (the parts' vertices are mm; node 'rig' scales them by 0.001)",
            "frame": "glTF's: +Y up. Node 'rig' turns rigcad's frame (sample point O at the origin, optical "
                     "axis +z) by -90 deg about x, so rigcad's +z is +Y",
            "rays": int(len(lines)), "rays_traced": int(rays["traced"])}}],
        "nodes": nodes,
        "meshes": gl_meshes,
        "materials": materials,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": len(buf.data)}],
    }
    return doc, bytes(buf.data)


def glb_bytes(rig, meshes: list[PartMesh], rays: dict) -> bytes:
    """The binary glTF (GLB container: 12-byte header, JSON chunk, BIN chunk) of :func:`rig_gltf`."""
    doc, binary = rig_gltf(rig, meshes, rays)
    text = json.dumps(doc, separators=(",", ":"), ensure_ascii=True).encode()
    text += b" " * (-len(text) % 4)  # the JSON chunk is padded with spaces, the BIN chunk with zeros
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text
            + struct.pack("<I4s", len(binary), b"BIN\x00") + binary)


__all__ = ["CREASE_ANGLE_DEG", "ROOT_ROTATION", "ROOT_SCALE", "creased_normals", "glb_bytes", "rig_gltf",
           "srgb_to_linear"]
