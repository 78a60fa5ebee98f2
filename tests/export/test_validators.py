"""Every exchange file rigcad writes, read by the independent validator its users' tools rely on
(docs/files.md has the table): the Khronos glTF validator (npm gltf-validator, run by Node.js) on
rig.glb, GDAL's OGR DXF driver (pyogrio) on the template DXFs, lib3mf in strict mode on every 3MF
(rigcad's own and the PrusaSlicer projects it passes on), OCCT's STEP reader and the header's
fields on STEP, trimesh on binary STL, a PNG chunk reader (every CRC, gAMA 1.0) and Pillow on the
data PNGs, and a G-code reader written here (every move on the bed, homing before moves, the
declared extrusion mode, the printer file's temperatures) on the G-code. Each validator must report
no error and no warning (the accepted ones are named with their reason), and each is shown a file
broken on purpose once and must fail it. The whole commands' files are read in the e2e tests."""

from __future__ import annotations

import io
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
VALIDATE_GLTF = Path(__file__).with_name("validate_gltf.js")
#: Where `make tools` installs the Khronos glTF validator (Makefile: GLTF_VALIDATOR).
GLTF_MODULES = Path(os.environ.get("GLTF_VALIDATOR_MODULES", ROOT / "build" / "node" / "node_modules"))
NODE = shutil.which("node") or shutil.which("nodejs")
needs_gltf_validator = pytest.mark.skipif(
    NODE is None or not (GLTF_MODULES / "gltf-validator" / "package.json").is_file(),
    reason="the Khronos glTF validator (Node.js + npm gltf-validator) is not installed: run `make tools`")
needs_slicer = pytest.mark.skipif(shutil.which("prusa-slicer") is None, reason="prusa-slicer is not installed")


@pytest.fixture(scope="module")
def rig():
    from rigcad.rig import load

    return load("achutha2006")


# -- glTF ------------------------------------------------------------------------------------------
def gltf_reports(paths: list[Path]) -> list[dict]:
    """The Khronos validator's report on each file (its JSON, one per file)."""
    run = subprocess.run([NODE, str(VALIDATE_GLTF), *map(str, paths)], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "GLTF_VALIDATOR_MODULES": str(GLTF_MODULES)})
    assert run.returncode == 0, run.stderr
    return [json.loads(line) for line in run.stdout.splitlines()]


def _counts(report: dict) -> dict:
    i = report["issues"]
    return {"errors": i["numErrors"], "warnings": i["numWarnings"], "infos": i["numInfos"], "hints": i["numHints"],
            "codes": sorted({m["code"] for m in i["messages"]})}


def _glb_split(data: bytes) -> tuple[dict, bytes]:
    n = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + n])
    m = struct.unpack_from("<I", data, 20 + n)[0]
    return doc, data[28 + n:28 + n + m]


def _glb_join(doc: dict, binary: bytes) -> bytes:
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    return (struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(binary)) + struct.pack("<I4s", len(text), b"JSON")
            + text + struct.pack("<I4s", len(binary), b"BIN\x00") + binary)


@pytest.fixture(scope="module")
def glb(rig):
    from rigcad.manual.assembly import picture_meshes
    from rigcad.manual.glb import glb_bytes
    from rigcad.manual.view import traced_rays

    meshes = picture_meshes(rig)
    return glb_bytes(rig, meshes, traced_rays(rig, 40)), meshes


@needs_gltf_validator
def test_rig_glb_passes_the_khronos_validator(glb, tmp_path):
    path = tmp_path / "rig.glb"
    path.write_bytes(glb[0])
    [report] = gltf_reports([path])
    # nothing accepted: no error, warning, info or hint (trimesh's exporter gave 39 hints)
    assert _counts(report) == {"errors": 0, "warnings": 0, "infos": 0, "hints": 0, "codes": []}, report["issues"]
    assert report["info"]["totalTriangleCount"] == sum(len(m.faces) for m in glb[1])


@needs_gltf_validator
def test_the_glTF_validator_fails_a_broken_glb(glb, tmp_path):
    doc, binary = _glb_split(glb[0])
    breaks = {}
    bad = json.loads(json.dumps(doc))
    bad["accessors"][0]["max"][0] += 1.0  # a bound that is not the data's
    breaks["ACCESSOR_MAX_MISMATCH"] = _glb_join(bad, binary)
    bad = json.loads(json.dumps(doc))
    normal = bad["meshes"][0]["primitives"][0]["attributes"]["NORMAL"]
    view = bad["bufferViews"][bad["accessors"][normal]["bufferView"]]
    wrong = bytearray(binary)
    wrong[view["byteOffset"]:view["byteOffset"] + 12] = struct.pack("<3f", 0.5, 0.0, 0.0)  # not unit length
    breaks["ACCESSOR_VECTOR3_NON_UNIT"] = _glb_join(bad, bytes(wrong))
    bad = json.loads(json.dumps(doc))
    del bad["bufferViews"][0]["target"]  # what trimesh's exporter wrote: a hint
    breaks["BUFFER_VIEW_TARGET_MISSING"] = _glb_join(bad, binary)
    paths = []
    for code, data in breaks.items():
        paths.append(tmp_path / f"{code}.glb")
        paths[-1].write_bytes(data)
    for code, report in zip(breaks, gltf_reports(paths)):
        assert code in _counts(report)["codes"], (code, _counts(report))


def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_glb_is_in_metres_with_y_up(glb):
    """glTF 2.0 (3.4): metres, +Y up. Read by hand: the root node's transform applied to each part's
    mm vertices puts rigcad's (x, y, z) mm at (x, z, -y) / 1000 m; trimesh, reading the file as an
    importer does, finds the same scene bounds."""
    data, meshes = glb
    doc, binary = _glb_split(data)
    root = doc["nodes"][doc["scenes"][doc["scene"]]["nodes"][0]]
    assert root["name"] == "rig" and set(root) <= {"name", "rotation", "scale", "children"}
    m = _quat_matrix(root["rotation"]) * np.asarray(root["scale"])[None, :]
    assert np.allclose(m, np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]]) / 1000, atol=1e-12)
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for child in root["children"]:
        node = doc["nodes"][child]
        acc = doc["accessors"][doc["meshes"][node["mesh"]]["primitives"][0]["attributes"]["POSITION"]]
        view = doc["bufferViews"][acc["bufferView"]]
        local = np.frombuffer(binary, "<f4", 3 * acc["count"], view["byteOffset"]).reshape(-1, 3).astype(float)
        world = local @ m.T
        lo, hi = np.minimum(lo, world.min(axis=0)), np.maximum(hi, world.max(axis=0))
        part = next((p for p in meshes if p.name == node["name"]), None)
        if part is not None:  # the part's height along the optical axis is its extent in Y, in metres
            # float32 positions: ~3e-5 mm apart at 500 mm, so 1e-7 m
            assert np.ptp(world[:, 1]) == pytest.approx(np.ptp(part.vertices[:, 2]) / 1000, abs=1e-7), part.name
    dome = next(p for p in meshes if p.name == "dome")
    # the dome stands on the sample plane (y = 0) and rises to its apex: 0.234 m on the default profile
    assert hi[1] >= dome.hi[2] / 1000 - 1e-6 and 0.1 < np.ptp([lo[1], hi[1]]) < 2.0  # a rig of some decimetres
    import trimesh

    scene = trimesh.load(io.BytesIO(data), file_type="glb")
    assert np.allclose(scene.bounds, [lo, hi], atol=1e-6)  # float32 positions


def test_glb_materials_are_named_and_normals_shade(glb):
    from rigcad.manual.glb import CREASE_ANGLE_DEG

    data, meshes = glb
    doc, binary = _glb_split(data)
    assert all(m.get("name") for m in doc["materials"])
    by_name = {m["name"]: m for m in doc["meshes"]}
    assert by_name["rays"]["primitives"][0]["mode"] == 1 and doc["materials"][
        by_name["rays"]["primitives"][0]["material"]]["name"] == "rays"

    def read(index, n):
        acc = doc["accessors"][index]
        view = doc["bufferViews"][acc["bufferView"]]
        dtype = {5126: "<f4", 5125: "<u4"}[acc["componentType"]]
        return np.frombuffer(binary, dtype, n * acc["count"], view["byteOffset"]).reshape(acc["count"], n) \
            if n > 1 else np.frombuffer(binary, dtype, acc["count"], view["byteOffset"])

    for part in meshes:
        prim = by_name[part.name]["primitives"][0]
        assert doc["materials"][prim["material"]]["name"] == part.name
        v, nrm = read(prim["attributes"]["POSITION"], 3).astype(float), read(prim["attributes"]["NORMAL"], 3)
        f = read(prim["indices"], 1).reshape(-1, 3)
        assert len(f) == len(part.faces)
        assert np.allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-6), part.name  # float32 unit vectors
        tri = v[f]
        face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        face /= np.linalg.norm(face, axis=1, keepdims=True)
        # a corner's normal averages faces within the crease angle of its own, so it stays inside that
        # cone (convexity); 1e-5 for the float32 positions of small facets
        cos = np.einsum("ijk,ik->ij", nrm[f].astype(float), face)
        assert cos.min() >= math.cos(math.radians(CREASE_ANGLE_DEG)) - 1e-5, (part.name, cos.min())
    beam = next(p for p in meshes if p.name == "beam")
    # a box (with its stop pin's hole in its top): every outer corner splits into its three faces' normals
    prim = by_name["beam"]["primitives"][0]
    pos = read(prim["attributes"]["POSITION"], 3).astype(float)
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    for corner in np.array(np.meshgrid(*zip(lo, hi))).T.reshape(-1, 3):
        assert np.sum(np.all(np.abs(pos - corner) < 1e-3, axis=1)) == 3, (corner, len(beam.faces))


# -- DXF ---------------------------------------------------------------------------------------------
def _wkb_points(wkb: bytes) -> np.ndarray:
    """The coordinates (n, 2) of a WKB point, line string or polygon (ISO or EWKB-style Z)."""
    order = "<" if wkb[0] == 1 else ">"
    (kind,) = struct.unpack_from(order + "I", wkb, 1)
    dims = 3 if (kind & 0x80000000 or 1000 <= kind % 0x80000000 < 2000) else 2
    base = (kind & 0x7FFFFFFF) % 1000
    if base == 1:
        return np.array(struct.unpack_from(order + "d" * dims, wkb, 5))[None, :2]
    if base == 2:
        (n,) = struct.unpack_from(order + "I", wkb, 5)
        return np.frombuffer(wkb, order + "f8", n * dims, 9).reshape(n, dims)[:, :2]
    raise AssertionError(f"unexpected WKB geometry type {kind}")


def gdal_read(path: Path) -> tuple[list[str], list[np.ndarray]]:
    """GDAL's OGR DXF driver on ``path``: each feature's layer and coordinates."""
    import pyogrio

    meta, _, geometry, fields = pyogrio.raw.read(path)
    layer = list(fields[meta["fields"].tolist().index("Layer")])
    return layer, [_wkb_points(g) for g in geometry]


def _templates(rig, tmp_path) -> dict[str, tuple[Path, object]]:
    """The template outlines `rigcad fab` writes: the gauged layer and the sanded surface, each template."""
    from rigcad.fab import outlines
    from rigcad.parts import templates

    out = {}
    for make in (templates.dome_template, templates.paraboloid_template):
        for label, depth in (("coated", templates.gauged_depth(rig.profile)), ("sanded", rig.layout.coating)):
            part = make(rig.profile, rig.layout, depth)
            o = outlines.outline(part, rig.profile.tessellation.chord_error)
            path = tmp_path / f"{part.name}_{label}.dxf"
            path.write_bytes(outlines.dxf_bytes(o))
            out[path.stem] = (path, o, part)
    return out


def test_gdal_reads_every_template_dxf(rig, tmp_path):
    import warnings

    from scipy.spatial import cKDTree

    from rigcad.parts.recipe import Curve

    for name, (path, o, part) in _templates(rig, tmp_path).items():
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            layers, geoms = gdal_read(path)
        # pyogrio turns GDAL's warnings (CE_Warning) into RuntimeWarnings: none
        assert not [w for w in said if issubclass(w.category, RuntimeWarning)], [str(w.message) for w in said]
        assert sorted(layers) == ["CURVES", "CURVES", "CUT", "NOTE"], (name, layers)
        [cut] = [g for la, g in zip(layers, geoms) if la == "CUT"]
        # GDAL closes the polyline: the same vertices, the first repeated at the end
        assert np.allclose(cut[:-1], o.polygon, atol=1e-9) and np.allclose(cut[-1], cut[0]), name
        dense = np.vstack([seg.dense(100_001) for seg in part.solid.section.segments if isinstance(seg, Curve)])
        for g in (g for la, g in zip(layers, geoms) if la == "CURVES"):
            # GDAL's own tessellation of the B-spline lies on the exact curves: within the
            # reference's spacing (~2.5 um: its nearest-vertex distance) and the spline's 2.4e-7 mm
            d, _ = cKDTree(dense).query(g)
            assert len(g) > 20 and d.max() < 3e-3, (name, len(g), d.max())


def test_gdal_refuses_a_broken_dxf(rig, tmp_path):
    import ezdxf
    import pyogrio

    path, o, _ = _templates(rig, tmp_path)["dome_template_coated"]
    # the file rigcad wrote before: the mirror curves as fit-point splines, no control points
    doc = ezdxf.readfile(path)
    msp = doc.modelspace()
    for sp in [e for e in msp if e.dxftype() == "SPLINE"]:
        msp.delete_entity(sp)
    for c in o.curves:
        msp.add_spline([(float(x), float(y), 0.0) for x, y in c], dxfattribs={"layer": "CURVES"})
    fit_only = tmp_path / "fit_points.dxf"
    doc.saveas(fit_only)
    refused = (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError, pyogrio.errors.FeatureError)
    with pytest.raises(refused, match="ogrdxflayer.cpp.*error at line"):  # as the issue saw it
        gdal_read(fit_only)
    cut_short = tmp_path / "cut_short.dxf"
    cut_short.write_bytes(path.read_bytes()[: len(path.read_bytes()) // 2])
    with pytest.raises(refused):
        gdal_read(cut_short)


# -- 3MF ---------------------------------------------------------------------------------------------
def lib3mf_strict(path: Path) -> tuple[list[str], list[str], dict]:
    """lib3mf (the 3MF Consortium's reader) in strict mode: its warnings, the objects' names and the
    model's metadata; raises on what it refuses."""
    import lib3mf

    wrapper = lib3mf.get_wrapper()
    model = wrapper.CreateModel()
    reader = model.QueryReader("3mf")
    reader.SetStrictModeActive(True)
    reader.ReadFromFile(str(path))
    warnings = [reader.GetWarning(i)[1] for i in range(reader.GetWarningCount())]
    objects, names = model.GetObjects(), []
    while objects.MoveNext():
        names.append(objects.GetCurrentObject().GetName())
    meta = model.GetMetaDataGroup()
    return warnings, names, {meta.GetMetaData(i).GetName(): meta.GetMetaData(i).GetValue()
                             for i in range(meta.GetMetaDataCount())}


def zip_dates(data: bytes) -> list[tuple[int, int, int]]:
    """(year, month, day) of every entry as the zip's central directory stores it (MS-DOS date)."""
    out, i = [], data.find(b"PK\x01\x02")
    while i >= 0:
        (d,) = struct.unpack_from("<H", data, i + 14)
        out.append((1980 + (d >> 9), (d >> 5) & 15, d & 31))
        i = data.find(b"PK\x01\x02", i + 4)
    return out


def _valid_dates(dates) -> bool:
    return bool(dates) and all(1 <= m <= 12 and 1 <= d <= 31 for _, m, d in dates)


@pytest.fixture(scope="module")
def lens_mount(rig):
    from rigcad.export import mesh
    from rigcad.parts import PARTS

    part = PARTS["lens_mount"](rig.profile, rig.layout)
    return mesh.mesh_arrays(mesh.build(part.solid, rig.profile.tessellation.chord_error))


def test_lib3mf_reads_rigcad_3mf_strictly(lens_mount, tmp_path):
    from rigcad.export.mesh import threemf_writer

    path = tmp_path / "lens_mount.3mf"
    threemf_writer(*lens_mount, "lens_mount")(path)
    warnings, names, meta = lib3mf_strict(path)
    assert warnings == [] and names == ["lens_mount"], (warnings, names)
    assert meta["Title"] == "lens_mount" and meta["Application"].startswith("rigcad ")
    assert _valid_dates(zip_dates(path.read_bytes())), zip_dates(path.read_bytes())  # lib3mf alone: 1980-00-00


def _rezip(data: bytes, edit) -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            dst.writestr(info, edit(info.filename, src.read(info.filename)))
    return out.getvalue()


def test_lib3mf_refuses_a_broken_3mf(lens_mount, tmp_path):
    from rigcad.export.mesh import threemf_writer

    good = tmp_path / "good.3mf"
    threemf_writer(*lens_mount, "lens_mount")(good)
    thumbnail = b'<Relationship Target="/Metadata/thumbnail.png" Id="rel9" Type="http://schemas.openxmlformats.org/' \
                b'package/2006/relationships/metadata/thumbnail"/></Relationships>'
    breaks = {  # PrusaSlicer 2.5's two defects, and a triangle naming a vertex that is not there
        "missing_part": lambda n, d: d.replace(b"</Relationships>", thumbnail) if n == "_rels/.rels" else d,
        "printable": lambda n, d: re.sub(rb"(<item [^>]*?)(/?>)", rb'\1 printable="1"\2', d) if n.endswith(".model")
        else d,
        "bad_index": lambda n, d: re.sub(rb'v1="\d+"', b'v1="99999999"', d, count=1) if n.endswith(".model") else d,
    }
    for name, edit in breaks.items():
        path = tmp_path / f"{name}.3mf"
        path.write_bytes(_rezip(good.read_bytes(), edit))
        with pytest.raises(Exception, match="Lib3MF"):
            lib3mf_strict(path)


def _raw_prusaslicer(tmp_path: Path, stl: bytes, name: str) -> tuple[bytes, bytes]:
    """G-code and 3MF of ``stl`` as PrusaSlicer's CLI writes them, before rigcad touches the 3MF."""
    from rigcad.fab import slicer as S
    from rigcad.fab.printers import load_printer

    job = S.slice_job(load_printer("prusa_mk3s"), name, stl, False, (125.0, 105.0))
    (tmp_path / f"{name}.stl").write_bytes(stl)
    (tmp_path / "piece.ini").write_text(job.ini)
    for args in (["--export-gcode", "--load", "piece.ini"], ["--export-3mf"]):
        out = "piece.gcode" if "--export-gcode" in args else "piece.3mf"
        subprocess.run(["prusa-slicer", *args, "--center", "125,105", "--output", out, f"{name}.stl"], cwd=tmp_path,
                       check=True, capture_output=True, timeout=600)
    return (tmp_path / "piece.gcode").read_bytes(), (tmp_path / "piece.3mf").read_bytes()


@pytest.mark.e2e
@needs_slicer
def test_prusaslicer_projects_pass_lib3mf_strict_after_repair(lens_mount, tmp_path):
    from rigcad.export.mesh import stl_bytes
    from rigcad.fab import slicer as S

    gcode, raw = _raw_prusaslicer(tmp_path, stl_bytes(*lens_mount, "lens_mount"), "lens_mount")
    (tmp_path / "raw.3mf").write_bytes(raw)
    with pytest.raises(Exception, match="Could not create OPC Part"):  # PrusaSlicer's own file, unrepaired
        lib3mf_strict(tmp_path / "raw.3mf")
    project = tmp_path / "project.3mf"
    project.write_bytes(S.project_3mf(raw, S.normalise(gcode), "lens_mount"))
    warnings, names, meta = lib3mf_strict(project)
    assert warnings == [] and names == ["lens_mount"] and meta["Title"] == "lens_mount", (warnings, names, meta)
    assert _valid_dates(zip_dates(project.read_bytes()))
    # and PrusaSlicer still opens it as a project: it slices it again
    again = subprocess.run(["prusa-slicer", "--export-gcode", "--output", "again.gcode", "project.3mf"], cwd=tmp_path,
                           capture_output=True, text=True, timeout=600)
    assert again.returncode == 0 and (tmp_path / "again.gcode").stat().st_size > 0, again.stderr


# -- STEP, STL, PNG -----------------------------------------------------------------------------------
def step_header(text: str) -> dict:
    """FILE_DESCRIPTION and FILE_NAME of a STEP file's HEADER, as lists of their string fields."""
    head = text[text.index("HEADER;"):text.index("ENDSEC;")]

    def strings(entity):
        body = re.search(entity + r"\s*\((.*?)\)\s*;", head, re.S).group(1)
        return [s.replace("''", "'") for s in re.findall(r"'((?:[^']|'')*)'", body)]

    return {"description": strings("FILE_DESCRIPTION"), "name": strings("FILE_NAME")}


def occt_read(path: Path) -> tuple[bool, int]:
    """OCCT's STEP reader on ``path``: (the shape is valid, its solids); raises when it cannot read it."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    from rigcad.parts._kernel import is_valid, solids

    reader = STEPControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise ValueError(f"{path}: OCCT cannot read it")
    reader.TransferRoots()
    shape = reader.OneShape()
    return is_valid(shape), solids(shape)


def test_step_header_names_the_part_and_rigcad(rig, tmp_path):
    from rigcad._version import __version__
    from rigcad.export.step import TIMESTAMP, reimport_check, step_writer
    from rigcad.parts import PARTS
    from rigcad.parts import _kernel as K

    part = PARTS["lens_mount"](rig.profile, rig.layout)
    shape = K.part_solid(part, rig.profile.tessellation.fit_tolerance, K.FitReport(), rig.profile)
    path = tmp_path / "lens_mount.step"
    step_writer([("lens_mount", shape, part.color)], "lens_mount")(path)
    h = step_header(path.read_text(encoding="latin-1"))
    # FILE_NAME(name, time_stamp, author, organization, preprocessor_version, originating_system, authorization)
    assert h["name"][0] == "lens_mount" and h["name"][1] == TIMESTAMP
    assert h["name"][2:4] == ["", ""]  # no 'Author', no 'Open CASCADE' as organisation
    assert h["name"][4].startswith("Open CASCADE STEP processor") and h["name"][5] == f"rigcad {__version__}"
    assert h["description"][0] == f"rigcad {__version__}: part lens_mount"
    reimport_check(path, K.volume(shape), 1)  # OCCT reads it back: one valid solid of the same volume
    broken = tmp_path / "broken.step"
    broken.write_text(path.read_text(encoding="latin-1").replace("ENDSEC;", "", 1), encoding="latin-1")
    from rigcad.errors import ExportError

    with pytest.raises(ExportError, match="cannot read"):
        reimport_check(broken, K.volume(shape), 1)


def stl_check(data: bytes) -> int:
    """A binary STL as strict readers take it: a header that does not start with 'solid' (readers
    would take the file for ASCII STL), a size of exactly 84 + 50 n bytes for its n triangles, and
    every facet normal a unit vector along its triangle's winding (or zero for a degenerate one).
    Returns n; raises ValueError naming the first fault."""
    if len(data) < 84:
        raise ValueError("shorter than the 84-byte header and count")
    if data[:5].lower() == b"solid":
        raise ValueError("the header starts with 'solid': readers take it for an ASCII STL")
    (n,) = struct.unpack_from("<I", data, 80)
    if len(data) != 84 + 50 * n:
        raise ValueError(f"{len(data)} bytes for {n} triangles: 84 + 50 n = {84 + 50 * n} expected")
    rec = np.frombuffer(data, [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")], n, 84)
    tri = rec["v"].astype(float)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(rec["n"].astype(float), axis=1)
    if not np.all(np.isclose(length, 1.0, atol=1e-6) | (np.linalg.norm(cross, axis=1) == 0)):
        raise ValueError("a facet normal that is not a unit vector")
    if np.any(np.einsum("ij,ij->i", cross, rec["n"].astype(float)) < 0):
        raise ValueError("a facet normal against its triangle's winding")
    return n


def test_stl_header_says_units_and_only_a_known_frame(lens_mount):
    import trimesh

    from rigcad._version import __version__
    from rigcad.export.mesh import RIG_FRAME, stl_bytes

    placed = stl_bytes(*lens_mount, "lens_mount_piece_1")
    assert placed[:80].rstrip() == f"rigcad {__version__} lens_mount_piece_1: mm".encode()
    as_built = stl_bytes(*lens_mount, "lens_mount", frame=RIG_FRAME)
    assert as_built[:80].rstrip() == f"rigcad {__version__} lens_mount: mm, {RIG_FRAME}".encode()
    assert stl_check(as_built) == stl_check(placed) == len(lens_mount[1])
    mesh = trimesh.load(io.BytesIO(as_built), file_type="stl")  # and trimesh, as a user's script reads it
    assert len(mesh.faces) == len(lens_mount[1]) and mesh.is_watertight
    for broken, fault in ((as_built[:-25], "bytes for"), (b"solid" + as_built[5:], "ASCII"),
                          (as_built[:84] + struct.pack("<3f", 0.0, 0.0, 2.0) + as_built[96:], "unit")):
        with pytest.raises(ValueError, match=fault):
            stl_check(broken)


def png_chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    """(type, body) of every chunk, each CRC checked (PNG 5.3); raises on a bad signature or CRC."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG signature")
    out, pos = [], 8
    while pos < len(data):
        n, kind = struct.unpack_from(">I4s", data, pos)
        body = data[pos + 8:pos + 8 + n]
        if zlib.crc32(kind + body) != struct.unpack_from(">I", data, pos + 8 + n)[0]:
            raise ValueError(f"chunk {kind!r}: CRC mismatch")
        out.append((kind, body))
        pos += 12 + n
    return out


def test_data_pngs_say_their_levels_are_linear():
    from PIL import Image

    from rigcad.export.png import gray_png

    for image in (np.arange(12, dtype=np.uint8).reshape(3, 4), np.arange(12, dtype=np.uint16).reshape(3, 4) * 5000):
        data = gray_png(image)
        kinds = [k for k, _ in png_chunks(data)]
        assert kinds == [b"IHDR", b"gAMA", b"IDAT", b"IEND"], kinds  # gAMA before the image data, no text or time
        assert dict(png_chunks(data))[b"gAMA"] == (100_000).to_bytes(4, "big")  # gamma 1.0: linear
        im = Image.open(io.BytesIO(data))
        assert im.info["gamma"] == 1.0 and np.array_equal(np.asarray(im), image)
        broken = bytearray(data)
        broken[41] ^= 0xFF  # gAMA's value (8 signature + 25 IHDR + 8 length and type): its CRC no longer holds
        with pytest.raises(ValueError, match="CRC"):
            png_chunks(bytes(broken))


# -- G-code ------------------------------------------------------------------------------------------
_WORD = re.compile(r"([A-Z])([-+]?\d*\.?\d+)")
#: The one place rigcad's G-code may leave the bed's rectangle: the MK3S start G-code (Prusa's
#: vendor preset) moves to y = -3 and draws its purge line there, in front of the bed's printable
#: area, which the printer's y axis reaches (its travel starts at -4 mm). Accepted, by its comments.
PURGE_COMMENTS = ("go outside print area", "intro line")
PURGE_Y_MIN = -4.0


def gcode_check(text: str, settings: dict) -> list[str]:
    """What a G-code reader on the printer would object to, against the printer file's slicer
    ``settings``: a move before homing (G28), a move outside the bed (bed_shape's box, 0..
    max_print_height; PURGE_COMMENTS excepted down to PURGE_Y_MIN), an extrusion before the
    declared extrusion mode or in the other mode (use_relative_e_distances: M83 relative, M82
    absolute), a heater set to a temperature the printer file does not give (S0, off, allowed).
    Returns the faults, each with its line number."""
    corners = np.array([[float(v) for v in c.split("x")] for c in settings["bed_shape"].split(",")])
    (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
    z1 = float(settings["max_print_height"])
    hot = {float(settings[k]) for k in ("temperature", "first_layer_temperature")} | {0.0}
    bed = {float(settings[k]) for k in ("bed_temperature", "first_layer_bed_temperature")} | {0.0}
    relative_e = settings["use_relative_e_distances"] == "1"
    faults, homed, e_mode, absolute, purge = [], False, None, True, False
    pos = {"X": 0.0, "Y": 0.0, "Z": 0.0}
    for n, raw in enumerate(text.splitlines(), 1):
        code, _, comment = raw.partition(";")
        words = code.split()
        if not words:
            continue
        cmd, args = words[0], dict(_WORD.findall(" ".join(words[1:])))
        if cmd == "G28":
            homed = True
        elif cmd in ("G90", "G91"):
            absolute = cmd == "G90"
        elif cmd in ("M82", "M83"):
            e_mode = cmd
            if (cmd == "M83") != relative_e:
                faults.append(f"line {n}: {cmd}, but the printer file says use_relative_e_distances = "
                              f"{settings['use_relative_e_distances']}")
        elif cmd in ("M104", "M109") and "S" in args and float(args["S"]) not in hot:
            faults.append(f"line {n}: hot end at {args['S']} degC; the printer file says {sorted(hot)}")
        elif cmd in ("M140", "M190") and "S" in args and float(args["S"]) not in bed:
            faults.append(f"line {n}: bed at {args['S']} degC; the printer file says {sorted(bed)}")
        elif cmd in ("G0", "G1"):
            axes = {k: float(v) for k, v in args.items() if k in "XYZ"}
            if axes and not homed:
                faults.append(f"line {n}: a move before homing (G28)")
            if "E" in args and e_mode is None:
                faults.append(f"line {n}: extrusion before the extrusion mode (M82/M83) is declared")
            for k, v in axes.items():
                pos[k] = v if absolute else pos[k] + v
            if "X" in axes or "Y" in axes:  # the head stays where the purge left it until it moves in x-y
                purge = any(c in comment for c in PURGE_COMMENTS)
            if not (x0 <= pos["X"] <= x1 and (y0 <= pos["Y"] or purge and PURGE_Y_MIN <= pos["Y"]) and pos["Y"] <= y1
                    and 0 <= pos["Z"] <= z1):
                faults.append(f"line {n}: at ({pos['X']:g}, {pos['Y']:g}, {pos['Z']:g}), off the bed")
    return faults


@pytest.fixture(scope="module")
def mk3s_gcode(lens_mount, tmp_path_factory):
    if shutil.which("prusa-slicer") is None:
        pytest.skip("prusa-slicer is not installed")
    from rigcad.export.mesh import stl_bytes
    from rigcad.fab import slicer as S
    from rigcad.fab.printers import load_printer

    printer = load_printer("prusa_mk3s")
    (res,), _ = S.slice_all([S.slice_job(printer, "lens_mount", stl_bytes(*lens_mount, "lens_mount"), False,
                                         (125.0, 105.0))], workers=1)
    return res.gcode.decode(), printer.slicer_config.effective()


@pytest.mark.e2e
def test_gcode_reader_passes_the_mk3s_gcode_and_fails_broken_ones(mk3s_gcode):
    text, settings = mk3s_gcode
    assert gcode_check(text, settings) == []
    first_move = next(i for i, ln in enumerate(text.splitlines()) if re.match(r"G1 .*[XYZ]", ln))
    lines = text.splitlines()
    broken = {
        "off the bed": text.replace("\nG1 X", "\nG1 X300 Y100\nG1 X", 1),
        "before homing": text.replace("G28 W", "G4", 1),
        "use_relative_e_distances": text.replace("\nM83", "\nM82", 1),
        "extrusion before": "\n".join(ln for ln in lines if not ln.startswith(("M83", "M82"))),
        "hot end at 290": text.replace("M104 S215", "M104 S290", 1),
        "bed at 110": text.replace("M140 S60", "M140 S110", 1),
    }
    assert first_move > 0
    # the purge line's exception is only for the purge: the same y = -3 elsewhere is off the bed
    broken["(100, -3"] = text.replace("; intro line", "", 2)
    for fault, bad in broken.items():
        found = gcode_check(bad, settings)
        assert any(fault in f for f in found), (fault, found[:3])


# -- the whole commands: every such file they write ---------------------------------------------------
@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """`rigcad build` (two parts), `rigcad view --glb`, `rigcad fab --gcode` (the two templates and one
    printed part), `rigcad basis --order 2` and `rigcad calibrate --kit` on the default profile, into
    one exports folder."""
    if shutil.which("prusa-slicer") is None:
        pytest.skip("prusa-slicer is not installed")
    out = tmp_path_factory.mktemp("written")
    for args in (["build", "achutha2006", "--parts", "lens_mount", "beam"],
                 ["view", "achutha2006", "--rays", "40", "--glb"],
                 ["fab", "achutha2006", "--printer", "prusa_mk3s", "--gcode", "--parts", "dome_template",
                  "paraboloid_template", "lens_mount"],
                 ["basis", "achutha2006", "--order", "2"],
                 ["calibrate", "achutha2006", "--kit"]):
        run = subprocess.run([sys.executable, "-m", "rigcad", *args, "--exports", str(out)], capture_output=True,
                             text=True, timeout=1200, cwd=ROOT)
        assert run.returncode == 0, (args, run.stderr)
    return out / "achutha2006"


@pytest.mark.e2e
@needs_gltf_validator
def test_every_file_the_commands_write_passes_its_validator(written):
    from rigcad.fab.printers import load_printer

    files = {}
    for path in sorted(p for p in written.rglob("*") if p.is_file()):
        files.setdefault(path.suffix, []).append(path)
    # what these commands write, each kind at least once
    assert {".glb", ".dxf", ".3mf", ".step", ".stl", ".gcode", ".png"} <= set(files), sorted(files)
    for report in gltf_reports(files[".glb"]):
        assert _counts(report) == {"errors": 0, "warnings": 0, "infos": 0, "hints": 0, "codes": []}, report["path"]
    for path in files[".dxf"]:
        layers, _ = gdal_read(path)
        assert sorted(layers) == ["CURVES", "CURVES", "CUT", "NOTE"], path
    for path in files[".3mf"]:  # rigcad's own (3mf/) and the PrusaSlicer projects (fab/prusa_mk3s/3mf/)
        warnings, names, meta = lib3mf_strict(path)
        assert warnings == [] and names == [path.stem] and meta["Title"] == path.stem, (path, warnings, names, meta)
        assert _valid_dates(zip_dates(path.read_bytes())), path
    for path in files[".step"]:
        text = path.read_text(encoding="latin-1")
        h = step_header(text)
        assert h["name"][0] == path.stem or path.name == "rig.step", (path, h)
        assert h["name"][5].startswith("rigcad ") and h["name"][2:4] == ["", ""], (path, h)
        valid, solids = occt_read(path)
        assert valid and solids >= 1, (path, valid, solids)
    for path in files[".stl"]:
        assert stl_check(path.read_bytes()) > 0, path
    settings = load_printer("prusa_mk3s").slicer_config.effective()
    for path in files[".gcode"]:
        assert gcode_check(path.read_text(), settings) == [], path
    for path in files[".png"]:
        chunks = dict(png_chunks(path.read_bytes()))  # every chunk's CRC
        if path.name.startswith("z_") or path.parent.name.startswith("patterns"):  # data: levels linear
            assert chunks.get(b"gAMA") == (100_000).to_bytes(4, "big"), path
    assert sum(p.name.startswith("z_") for p in files[".png"]) > 0 and any(p.parent.name == "patterns"
                                                                          for p in files[".png"])
