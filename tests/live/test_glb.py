"""`rigcad view --glb`: one binary glTF, read back by trimesh and, independently, by parsing the
GLB container by hand (glTF 2.0: a 12-byte header, a JSON chunk, a BIN chunk): a named node per
in-rig part with its triangle count and colour (linear, as glTF has it), and the rays as line primitives (mode 1) with two
vertices per segment. Same profile, same bytes."""

from __future__ import annotations

import io
import json
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("glb")
    run = subprocess.run([sys.executable, "-m", "rigcad", "view", "achutha2006", "--exports", str(out),
                          "--rays", "40", "--glb"], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    return out / "achutha2006" / "view" / "rig.glb", run.stdout


def _chunks(data: bytes) -> tuple[dict, bytes]:
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    n, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    doc = json.loads(data[20:20 + n])
    m, kind2 = struct.unpack_from("<I4s", data, 20 + n)
    assert kind2 == b"BIN\x00"
    return doc, data[28 + n:28 + n + m]


def test_the_glb_holds_every_part_by_name_and_the_rays_as_lines(written):
    from rigcad.manual.assembly import picture_meshes
    from rigcad.manual.view import traced_rays
    from rigcad.rig import load

    path, stdout = written
    assert "rig.glb" in stdout
    data = path.read_bytes()
    rig = load("achutha2006")
    meshes = picture_meshes(rig)
    rays = traced_rays(rig, 40)
    doc, _ = _chunks(data)
    nodes = {n["name"]: n for n in doc["nodes"] if "name" in n}
    assert {m.name for m in meshes} | {"rays"} <= set(nodes)
    line = doc["meshes"][nodes["rays"]["mesh"]]["primitives"][0]
    assert line["mode"] == 1  # LINES
    k, points = rays["lines"].shape[:2]
    assert doc["accessors"][line["attributes"]["POSITION"]]["count"] == 2 * k * (points - 1)
    assert "COLOR_0" in line["attributes"]

    import trimesh

    scene = trimesh.load(io.BytesIO(data), file_type="glb")
    for m in meshes:
        got = scene.geometry[m.name]
        assert len(got.faces) == len(m.faces), m.name
        assert np.allclose(got.bounds, [m.lo, m.hi], atol=1e-3), m.name  # float32 in the file
        rgba = got.visual.material.baseColorFactor
        # glTF's colour factors are linear, the parts' colours sRGB (IEC 61966-2-1's transfer function)
        c = np.asarray(m.color)
        linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        assert np.allclose(rgba[:3], np.round(255 * linear), atol=1), m.name  # trimesh reads them as 8 bit
    assert isinstance(scene.geometry["rays"], trimesh.path.Path3D)


def test_same_profile_same_bytes(written):
    from rigcad.manual.assembly import picture_meshes
    from rigcad.manual.glb import glb_bytes
    from rigcad.manual.view import traced_rays
    from rigcad.rig import load

    rig = load("achutha2006")
    assert glb_bytes(rig, picture_meshes(rig), traced_rays(rig, 40)) == written[0].read_bytes()
