"""Section 0 of the manual lists the figures that decide the optics (throw ratio, lens offset, camera pixel
pitch, the camera lens's closest focus) with where each came from, as it lists the assumed sizes: a figure
only assumed is said to be assumed there, not only inside a cell of the bill."""

from __future__ import annotations

import re
from types import SimpleNamespace

import rigcad
from rigcad.manual import document as D
from rigcad.profile.instruments import OPTICS_FIGURES


def _section0(profile) -> str:
    d = D.Doc()
    D.measure_first(d, SimpleNamespace(p=profile, files={}))
    return d.markdown()


def _row(md: str, key: str) -> str:
    return next(line for line in md.splitlines() if line.startswith(f"| `{key}`"))


def test_section_0_lists_the_optics_figures_with_their_origin(tmp_path):
    md = _section0(rigcad.load("achutha2006").profile)
    for key in ("projector.throw_ratio", "projector.lens_offset", "camera.pixel_pitch", "camera.min_working_distance"):
        assert key in OPTICS_FIGURES and f"| `{key}`" in md, key
    # the thesis's throw ratio is the profile's choice, at its line; the lens offset is the schema's assumption
    assert re.search(r"set in the profile \(`profiles/achutha2006\.yaml:\d+`\)", _row(md, "projector.throw_ratio"))
    assert "**assumed**" in _row(md, "projector.lens_offset") and "(`default`)" in _row(md, "projector.lens_offset")
    assert "**not known**" in _row(md, "camera.pixel_pitch")
    assert "**3 of 4 are assumed or not known**" in md  # lens offset, pixel pitch, closest focus


def test_a_camera_file_with_a_datasheet_fills_the_pixel_pitch_row(tmp_path):
    path = tmp_path / "basler.yaml"
    path.write_text("extends: achutha2006\ncamera:\n  model: basler_ace_u_aca2040_55uc\n", encoding="utf-8")
    md = _section0(rigcad.load(path).profile)
    row = _row(md, "camera.pixel_pitch")
    assert "3.45 um" in row and "datasheet" in row and "basler_ace_u_aca2040_55uc.yaml" in row, row
    assert "**2 of 4 are assumed or not known**" in md
