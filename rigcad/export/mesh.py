"""Printable meshes: recipe -> manifold3d solid -> STL, at an absolute chord error in mm.

The same recipe tree that the B-rep comes from (rigcad.parts.recipe) is meshed here directly:
sections are sampled within the chord error, revolutions get enough sectors for it at their
largest radius, booleans are manifold3d's (exact, robust, ~100x faster than OCCT's mesher on the
dome at 0.018 mm). manifold3d guarantees a watertight, manifold result or reports an error.
"""

from __future__ import annotations

import math
from pathlib import Path

import manifold3d as m3d
import numpy as np

from rigcad._version import __version__
from rigcad.errors import ExportError
from rigcad.parts.recipe import Box, Cylinder, Difference, HexPrism, Prism, Revolve, Solid, Translate, Union_


#: Chord error (mm) of the meshes drawn for pictures (the part renders, the manual's views and
#: figures): only for looking at; ~0.1 % of the dome's size, and keeps the whole rig at a few ten
#: thousand triangles.
PICTURE_CHORD_ERROR = 0.3


def segments_for(radius: float, chord_error: float) -> int:
    """Sectors of a full turn so that a circle of ``radius`` mm stays within ``chord_error`` mm."""
    if radius <= chord_error:
        return 8
    return max(8, math.ceil(math.pi / math.acos(1.0 - chord_error / radius)))


def _cross_section(section, chord_error: float) -> m3d.CrossSection:
    poly = section.polygon(chord_error)
    cs = m3d.CrossSection([poly])
    if cs.is_empty():
        raise ExportError("a part's cross-section is empty after meshing (self-intersecting outline?)")
    return cs


def build(solid: Solid, chord_error: float) -> m3d.Manifold:
    """The manifold of a recipe tree, every surface within ``chord_error`` mm of the exact one.

    A revolved surface's facet deviates by up to its meridional sagitta plus its circumferential
    one, so each gets half of the budget.
    """
    if isinstance(solid, Revolve):
        half = chord_error / 2
        cs = _cross_section(solid.section, half)
        r_max = float(np.max(solid.section.polygon(half)[:, 0]))
        return m3d.Manifold.revolve(cs, circular_segments=segments_for(r_max, half))
    if isinstance(solid, Prism):
        cs = _cross_section(solid.section, chord_error)
        t = solid.thickness
        # extrude along +z, then map (X, Y, Z) -> (X, t/2 - Z, Y): a proper rotation (det +1)
        mat = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, t / 2], [0.0, 1.0, 0.0, 0.0]]
        return m3d.Manifold.extrude(cs, t).transform(mat)
    if isinstance(solid, Box):
        lo, hi = np.array(solid.lo), np.array(solid.hi)
        return m3d.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))
    if isinstance(solid, Cylinder):
        n = segments_for(solid.radius, chord_error)
        return m3d.Manifold.cylinder(solid.height, solid.radius, solid.radius, n).translate(solid.base)
    if isinstance(solid, HexPrism):  # flat faces: exact
        cs = m3d.CrossSection([np.asarray(solid.corners(), float)])
        return m3d.Manifold.extrude(cs, solid.height).translate((0.0, 0.0, solid.base[2]))
    if isinstance(solid, Union_):
        return m3d.Manifold.batch_boolean([build(s, chord_error) for s in solid.items], m3d.OpType.Add)
    if isinstance(solid, Difference):
        return m3d.Manifold.batch_boolean([build(solid.base, chord_error)] + [build(s, chord_error) for s in solid.cuts],
                                          m3d.OpType.Subtract)
    if isinstance(solid, Translate):
        return build(solid.solid, chord_error).translate(solid.offset)
    raise TypeError(f"unknown recipe node {type(solid).__name__}")


def mesh_arrays(man: m3d.Manifold) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) float64 mm, triangles (m, 3) int64) of a manifold; raises if it is invalid."""
    if man.status() != m3d.Error.NoError or man.is_empty():
        raise ExportError(f"mesh boolean failed: manifold3d status {man.status()}")
    mesh = man.to_mesh64()
    return np.asarray(mesh.vert_properties, dtype=float)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)


def genus(vertices: np.ndarray, faces: np.ndarray) -> int:
    """Handles of a closed triangle mesh (0 for a sphere, 1 for a torus; summed over its bodies as
    manifold3d's ``Manifold.genus`` does): 1 - chi/2 with chi = V - E + F, edges counted once."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    chi = len(vertices) - len(np.unique(edges, axis=0)) + len(faces)
    return 1 - int(chi / 2)  # chi is even for closed orientable surfaces; truncation as in C++


#: The frame of the parts as built (export.build): what their STL headers say after the unit.
RIG_FRAME = "sample point O at origin, optical axis +z"


def stl_bytes(vertices: np.ndarray, faces: np.ndarray, name: str, frame: str | None = None) -> bytes:
    """Binary STL (float32, as the format has it) with facet normals; deterministic header:
    ``rigcad <version> <name>: mm`` and, when given, the ``frame`` the vertices are in (the
    rig's, :data:`RIG_FRAME`, for the parts as built; none for a piece in print position, whose
    frame is the printer's), cut to the format's 80 bytes."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = n
    rec["v"] = tri
    text = f"rigcad {__version__} {name}: mm" + (f", {frame}" if frame else "")
    header = text.encode("ascii", "replace")[:80].ljust(80, b" ")
    return header + np.uint32(len(faces)).tobytes() + rec.tobytes()


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Signed volume (mm^3) of a closed triangle mesh (divergence theorem)."""
    tri = vertices[faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


#: Date of every entry of the 3MF zips rigcad writes: the earliest a zip can hold (1980-01-01), so
#: no clock leaks in. lib3mf leaves the date fields zero, which reads as 1980-00-00, not a date.
ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)


def dated_zip(data: bytes) -> bytes:
    """The zip ``data`` with every entry dated :data:`ZIP_EPOCH`, deflated, mode 0644, in the same
    order with the same contents (rewritten by Python's zipfile)."""
    import io
    import zipfile

    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w") as dst:
        for entry in src.infolist():
            info = zipfile.ZipInfo(entry.filename, ZIP_EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            dst.writestr(info, src.read(entry.filename))
    return out.getvalue()


def threemf_writer(vertices: np.ndarray, faces: np.ndarray, name: str):
    """A writer(path) for a 3MF file (lib3mf, the 3MF Consortium's library), units mm: one object
    named ``name``, the model titled ``name`` and its Application ``rigcad <version>``.

    lib3mf stamps random UUIDs on objects and build items; they are fixed here (UUID5 of the
    part's name and geometry) so the same part gives the same bytes; its zip entries get a valid
    fixed date (:func:`dated_zip`).
    """
    import hashlib
    import uuid

    import lib3mf

    digest = hashlib.sha256(np.ascontiguousarray(vertices).tobytes() + np.ascontiguousarray(faces).tobytes()).hexdigest()
    ids = [str(uuid.uuid5(uuid.NAMESPACE_URL, f"rigcad/{name}/{digest}/{k}")) for k in range(3)]

    def writer(path) -> None:
        wrapper = lib3mf.get_wrapper()
        model = wrapper.CreateModel()
        model.SetUnit(lib3mf.ModelUnit.MilliMeter)
        meta = model.GetMetaDataGroup()
        meta.AddMetaData("", "Title", name, "string", False)
        meta.AddMetaData("", "Application", f"rigcad {__version__}", "string", False)
        mesh = model.AddMeshObject()
        mesh.SetName(name)
        # one copy each from numpy's buffers: lib3mf's Position is 3 float32, its Triangle 3 uint32
        pos = (lib3mf.Position * len(vertices)).from_buffer_copy(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        tris = (lib3mf.Triangle * len(faces)).from_buffer_copy(np.ascontiguousarray(faces, dtype="<u4").tobytes())
        mesh.SetGeometry(pos, tris)
        mesh.SetUUID(ids[0])
        item = model.AddBuildItem(mesh, wrapper.GetIdentityTransform())
        item.SetUUID(ids[1])
        model.SetBuildUUID(ids[2])
        # into memory, then written by Python: a full disk is then an OSError rigcad reports, never
        # lib3mf's native abort while writing the file ("Could not deflate data", exit 134)
        data = dated_zip(bytes(model.QueryWriter("3mf").WriteToBuffer()))
        Path(path).write_bytes(data)

    return writer
