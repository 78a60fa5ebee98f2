"""docs/files.md, docs/watch.md's glTF paragraph and docs/basis.md's lat-long grid state what the
code and the pins are: the readers' versions (Makefile, pyproject.toml, the installed GDAL), the
glTF root node's turn and scale and the crease angle, the STEP time stamp, the lat-long steps."""

from __future__ import annotations

import math
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _page(name: str) -> str:
    return " ".join((ROOT / "docs" / name).read_text(encoding="utf-8").split())


def test_files_page_names_the_pinned_readers():
    import pyogrio

    page = _page("files.md")
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    pyproject = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    gltf = re.search(r"^GLTF_VALIDATOR_VERSION := (\S+)$", makefile, re.M).group(1)
    assert f"`gltf-validator` {gltf}" in page
    for package in ("pyogrio", "lib3mf"):
        pin = re.search(rf'"{package}==([^"]+)"', pyproject).group(1)
        assert f"{package} {pin}" in page, package
    assert f"GDAL {pyogrio.__gdal_version_string__}" in page  # the GDAL inside the pinned pyogrio wheel


def test_pages_state_the_code_s_constants():
    from rigcad.export.step import TIMESTAMP
    from rigcad.manual.glb import CREASE_ANGLE_DEG, ROOT_ROTATION, ROOT_SCALE

    files, watch = _page("files.md"), _page("watch.md")
    x, y, z, w = ROOT_ROTATION
    turn = math.degrees(2 * math.atan2(x, w))  # a turn about x alone: y = z = 0
    assert y == z == 0 and f"by {turn:.0f} deg about x" in files and f"by {turn:.0f} deg about x" in watch
    assert f"scales it by {ROOT_SCALE:g}" in files and f"scales it by {ROOT_SCALE:g}" in watch
    assert f"edges sharper than {CREASE_ANGLE_DEG:g} deg" in watch
    assert f"`{TIMESTAMP}`" in files


def test_basis_page_states_the_latlong_grid():
    from rigcad.basis.projector import latlong_grid, zone_of
    from rigcad.rig import load

    theta, phi = latlong_grid(zone_of(load("achutha2006")))
    page = _page("basis.md")
    step_theta, step_phi = math.degrees(theta[1] - theta[0]), math.degrees(phi[1] - phi[0])
    assert (f"{len(phi)} columns of {step_phi:.0f} deg in phi, and the zone cut into {len(theta)} equal rows of "
            f"{step_theta:.3f} deg in theta, at most 1 deg each") in page
