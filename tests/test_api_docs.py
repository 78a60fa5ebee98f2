"""docs/api.md is executable: every ```python block runs, in order, in one namespace, in an empty
folder (so profiles come from the package's search path, not the repository)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)


def test_the_page_has_examples():
    assert len(blocks()) >= 6  # an empty page would make the test below vacuous


def test_every_example_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("RIGCAD_PROFILES", raising=False)
    namespace: dict = {}
    for i, code in enumerate(blocks()):
        try:
            exec(compile(code, f"{DOC.name}[block {i}]", "exec"), namespace)
        except Exception as err:  # noqa: BLE001 - report which block failed, with its text
            pytest.fail(f"docs/api.md block {i} failed: {type(err).__name__}: {err}\n{code}")
    out = capsys.readouterr().out
    assert "achutha2006" in out and "10.66 x 9.05 in" in out  # the thesis rig's ~11 x 9 in dome
    assert (tmp_path / "exports" / "achutha2006" / "step" / "beam.step").is_file()
    _check_the_numbers(namespace)


def _check_the_numbers(ns: dict) -> None:
    """What the examples print, against references from outside the code that computed them."""
    import math

    rig = ns["rig"]
    # Table 3.1: vertical extent h = 22.5 mm, tangent angle 20 deg at the rim. For z = -r^2 / (4 f)
    # the rim slope r / (2 f) = tan(90 - 20 deg) and h = r^2 / (4 f): f = h / tan^2(70 deg),
    # rim radius 2 h / tan(70 deg). Both closed forms, to rounding.
    t = math.tan(math.radians(70.0))
    assert rig.geometry.focal_length == pytest.approx(22.5 / t**2, rel=1e-12)
    assert rig.geometry.rim_radius == pytest.approx(2 * 22.5 / t, rel=1e-12)
    # the drilled holder: the 2 mm radius cylinder spans z = -15..5 mm and the holder z = -15..-1 mm
    # (its bounding box), so the hole removes pi 2^2 x 14 mm^3 (OCCT integrates the exact faces:
    # relative error ~1e-9; 1e-7 allows for its quadrature)
    bb = ns["holder"].bounding_box()
    assert (bb.min.Z, bb.max.Z) == pytest.approx((-15.0, -1.0), abs=1e-9)
    assert ns["holder"].volume - ns["drilled"].volume == pytest.approx(math.pi * 4 * 14, rel=1e-7)
    # CadQuery's view is the same B-rep (one OCP solid): the same volume to rounding
    assert ns["wp"].val().Volume() == pytest.approx(ns["paraboloid"].volume, rel=1e-12)
    # the beam's mesh (manifold3d, from the recipe) against its B-rep (OpenCascade): a box with its
    # stop pin's round hole, so within area x the chord error of it (flat but for the hole)
    beam = rig.part("beam")
    assert ns["mesh"].is_watertight and len(ns["mesh"].faces) > 12
    assert abs(ns["mesh"].volume - beam.volume) <= ns["mesh"].area * rig.profile.tessellation.chord_error
    # the paraboloid's mesh is within the chord error e of its curved faces: the volumes differ by
    # at most area x e (measured 0.15 %, 20 mm^3 of 13,382)
    pmesh = rig.part("paraboloid").mesh()
    e = rig.profile.tessellation.chord_error
    assert abs(pmesh.volume - ns["paraboloid"].volume) <= pmesh.area * e
