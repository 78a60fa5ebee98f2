"""Instruments as data files: a profile names a projector, camera, lens or splitter file by name;
its figures replace the assumed defaults but for the keys the profile sets; each figure says where
it came from (the profile's file:line, the instrument file's, or a default); what stays assumed is
listed for measuring; bad files are refused in one line naming their file:line."""

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rigcad.errors import ProfileError
from rigcad.profile import load_profile
from rigcad.profile.instruments import (CAMERA_SIZES, FIGURE_KEYS, FIGURES, NAMED_BY, PROJECTOR_SIZES, measurements,
                                        shipped)

ROOT = Path(__file__).resolve().parents[2]

#: A lab's own camera and lens, the graduate student's of the issue: a 2448 x 2048 sensor of 3.45 um
#: pixels with a 12 mm lens (the camera file states its pixel pitch with a source, the lens file not).
LAB_CAMERA = """
kind: camera
title: Lab camera, 2448 x 2048, 3.45 um
resolution: [2448, 2048]
pixel_pitch: 3.45 um
body_width: 29 mm
sources:
  pixel_pitch: the maker's datasheet, page 3
"""
LAB_LENS = """
kind: lens
title: Lab 12 mm C-mount lens
focal_length: 12 mm
min_working_distance: 100 mm
"""


def _lab(tmp_path: Path, profile: str, camera: str = LAB_CAMERA, lens: str = LAB_LENS) -> Path:
    """A lab folder: the profile, and its instruments/ beside it (no code, no search path change)."""
    (tmp_path / "instruments").mkdir(exist_ok=True)
    (tmp_path / "instruments" / "lab_cam.yaml").write_text(textwrap.dedent(camera).lstrip())
    (tmp_path / "instruments" / "lab_12mm.yaml").write_text(textwrap.dedent(lens).lstrip())
    path = tmp_path / "lab.yaml"
    path.write_text(textwrap.dedent(profile).lstrip())
    return path


LAB_PROFILE = """
paraboloid:
  vertical_extent: 2.25 cm
  tangent_angle: 20 deg
layout:
  cop_to_vertex: 27 cm
  sample_to_rim: 13.5 cm
camera:
  model: lab_cam
  lens: lab_12mm
  body_height: 30 mm
"""


def test_the_shipped_files_give_each_figure_with_its_source():
    files = shipped()
    kinds = {k: [f for f in files if f.kind == k and "discontinued" not in f.title] for k in NAMED_BY}
    assert len(kinds["projector"]) >= 3 and len(kinds["camera"]) >= 3  # current models to choose from
    assert kinds["lens"] and kinds["splitter"]
    for f in files:
        assert set(f.figures) <= set(FIGURE_KEYS[f.kind]), f.name
        assert set(f.sources) == set(f.figures), f.name  # a shipped figure always says where it was read
        assert f.file == f"profiles/instruments/{f.name}.yaml"
    assert set(FIGURES) >= set(PROJECTOR_SIZES) | set(CAMERA_SIZES)  # every size has a figure


def test_a_model_fills_its_figures_and_the_profile_wins(write_profile, table31_text):
    p = load_profile(write_profile(table31_text + "camera:\n  model: basler_ace_u_aca2040_55uc\n  body_height: 30 mm\n"))
    assert p.camera.body_width == 29.0 and p.camera.body_depth == 29.3  # from Basler's page
    assert p.camera.body_height == 30.0  # the profile's own measurement wins
    assert p.camera.resolution == (2048, 1536) and p.camera.pixel_pitch == pytest.approx(3.45e-3)
    assert p.set_by("camera", "body_height") == "profile" and p.set_by("camera", "body_width") == "instrument"
    assert p.origin("camera", "body_width") == "profiles/instruments/basler_ace_u_aca2040_55uc.yaml:8"  # body_width: 29 mm
    assert p.source("camera", "body_width").startswith("https://docs.baslerweb.com/aca2040-55uc/")
    assert p.source("camera", "body_height") is None  # the profile's, not the datasheet's
    keys = [m.key for m in measurements(p)]
    assert "camera.body_width" not in keys and "camera.body_height" not in keys
    assert "camera.pupil_depth" in keys  # the lens is the lab's: never sourced


def test_the_default_profile_lists_every_assumed_size_with_its_figure(table31):
    ms = measurements(table31)
    # the thesis's instruments are sourced for nothing: every size of both is to be measured
    assert len(ms) == len(PROJECTOR_SIZES) + len(CAMERA_SIZES)
    m = next(m for m in ms if m.key == "projector.pupil_height")
    assert m.assumed == 55.0 and m.unit == "mm" and m.view == "side"
    assert m.between == ("bottom (mounting) face", "optical axis (centre of the lens barrel)")


def test_an_unknown_model_is_refused_with_the_valid_names(write_profile, table31_text):
    with pytest.raises(ProfileError) as info:
        load_profile(write_profile(table31_text + "projector:\n  model: benq_mw632\n"))
    text = str(info.value)
    assert "projector.model" in text and "did you mean 'benq_mw632st'" in text and "p.yaml:8" in text
    assert "instruments" in text  # where it looked, and where a lab adds its own


def test_a_labs_own_camera_and_lens_are_used_without_code_and_say_where_each_figure_came_from(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the lab works in its own folder: files are named from there
    p = load_profile(_lab(tmp_path, LAB_PROFILE))
    assert p.camera.resolution == (2448, 2048) and p.camera.focal_length == 12.0
    assert p.camera.min_working_distance == 100.0
    assert p.origin("camera", "pixel_pitch") == "instruments/lab_cam.yaml:4"  # the lab folder's file, its line
    assert p.source("camera", "pixel_pitch") == "the maker's datasheet, page 3"
    assert p.origin("camera", "focal_length") == "instruments/lab_12mm.yaml:3"
    assert p.origin("camera", "body_height") == "lab.yaml:10" and p.origin("camera", "body_depth") == "default"
    assert p.instrument("camera", "lens").title == "Lab 12 mm C-mount lens"
    # the command says the same, a key set by the profile is not "(assumed)"
    out = subprocess.run([sys.executable, "-m", "rigcad", "profile", "show", "lab.yaml"], cwd=tmp_path,
                         capture_output=True, text=True, check=True).stdout
    row = {line.split()[0]: line for line in out.splitlines()[out.splitlines().index("[camera]"):] if line.strip()}
    assert "instruments/lab_cam.yaml:4" in row["pixel_pitch"] and "lab.yaml:10" in row["body_height"]
    assert "(assumed)" not in row["body_height"] and "(assumed)" not in row["body_width"]
    assert "(assumed)" in row["body_depth"] and "default" in row["body_depth"]
    assert "camera.pixel_pitch" in out.split("[sources]")[1] and "the maker's datasheet, page 3" in out
    assert "camera.lens: lab_12mm = Lab 12 mm C-mount lens (instruments/lab_12mm.yaml)" in out


def test_the_bill_names_the_chosen_instruments_and_assumes_nothing_set(tmp_path):
    from types import SimpleNamespace

    from rigcad.manual.bom import purchased

    rows = {r["item"].split(":")[0]: r for r in purchased(SimpleNamespace(profile=load_profile(_lab(tmp_path, LAB_PROFILE))))}
    assert rows["camera"]["item"] == "camera: Lab camera, 2448 x 2048, 3.45 um"
    assert rows["camera lens"]["item"] == "camera lens: Lab 12 mm C-mount lens"
    assert "body height 30 mm;" in rows["camera"]["spec"]  # the lab's measurement, not "(assumed)"
    assert "body width 29 mm;" in rows["camera"]["spec"]  # the camera file's
    assert "body depth 59 mm (assumed)" in rows["camera"]["spec"]


@pytest.mark.parametrize("camera, message, line", [
    ("kind: lens\ntitle: x\n", "kind: lens, but camera.model", 1),
    ("kind: camera\ntitle: x\nbody_widht: 29 mm\n", "unknown key 'body_widht' in a camera file (did you mean "
                                                       "'body_width'?)", 3),
    ("kind: camera\ntitle: x\npixel_pitch: 3.45\n", "camera.pixel_pitch: ", 3),
    ("kind: camera\ntitle: x\npixel_pitch: 3.45 um\nsources:\n  pixel_pich: p. 3\n", "sources.pixel_pich: not a "
                                                                                       "figure", 5),
    ("kind: camera\ntitle: x\nresolution: [2448, 2048\n", "YAML syntax", 4),
    ("kind: camera\nresolution: [2448, 2048]\n", "title: a camera file names what it is", 1),
    ("- a list\n", "an instrument file is a mapping", 1),
])
def test_a_bad_instrument_file_is_refused_at_its_line(tmp_path, camera, message, line):
    with pytest.raises(ProfileError) as info:
        load_profile(_lab(tmp_path, LAB_PROFILE, camera=camera))
    assert message in str(info.value)
    assert str(info.value).startswith(f"instruments/lab_cam.yaml:{line}: ") or f"lab_cam.yaml:{line}" in str(info.value)
    assert "\n" not in str(info.value)


def test_an_instrument_is_named_never_reached_by_a_path(tmp_path):
    for name in ("../lab_cam", "/etc/passwd", "instruments/lab_cam"):
        with pytest.raises(ProfileError) as info:
            load_profile(_lab(tmp_path, LAB_PROFILE.replace("model: lab_cam", f"model: {name}")))
        assert "camera.model" in str(info.value) and "not an instrument's name" in str(info.value)


def test_a_lens_in_millimetres_needs_the_pixel_pitch_and_the_principal_point_lies_on_the_sensor(tmp_path,
                                                                                                write_profile,
                                                                                                table31_text):
    with pytest.raises(ProfileError) as info:
        load_profile(write_profile(table31_text + "camera:\n  focal_length: 12 mm\n"))
    assert "camera.focal_length 12 mm needs camera.pixel_pitch" in str(info.value) and "p.yaml:8" in str(info.value)
    with pytest.raises(ProfileError) as info:
        load_profile(write_profile(table31_text + "camera:\n  principal_point: [1400, 300]\n", "pp"))
    assert "camera.principal_point [1400, 300] px is not on the 1360 x 1024 px sensor" in str(info.value)
    p = load_profile(write_profile(table31_text + "camera:\n  principal_point: [700.5, 500]\n", "pp2"))
    assert p.camera.principal_point == (700.5, 500.0)


def test_a_file_in_the_search_path_serves_every_profile(tmp_path, monkeypatch, write_profile, table31_text):
    """A lab's folder on $RIGCAD_PROFILES holds instruments/ for every profile, wherever it is."""
    lab = tmp_path / "labfolder"
    (lab / "instruments").mkdir(parents=True)
    (lab / "instruments" / "lab_cam.yaml").write_text(textwrap.dedent(LAB_CAMERA).lstrip())
    monkeypatch.setenv("RIGCAD_PROFILES", str(lab))
    p = load_profile(write_profile(table31_text + "camera:\n  model: lab_cam\n"))
    assert p.camera.resolution == (2448, 2048)
    assert p.origin("camera", "resolution").endswith("labfolder/instruments/lab_cam.yaml:3")


def test_each_measurement_sketch_draws_its_dimension_at_the_profiles_value(table31, write_profile, table31_text):
    """The figure's dimension runs between two points whose distance is the size itself (the
    profile's assumed value, not the sketch's arithmetic); a thread is a call-out at one hole; the
    camera's two holes are mount_spacing apart; a profile's own value moves the drawing."""
    import math

    from rigcad.profile.instruments import sketch

    for m in measurements(table31):
        s = sketch(table31, m)
        (x0, y0), (x1, y1) = s.dimension
        if m.key == "projector.mount_holes":  # from the COP to the first hole of the assumed pattern
            from rigcad.profile.instruments import mount_pattern

            along, across = mount_pattern(table31.projector)[0]
            assert math.hypot(x1 - x0, y1 - y0) == pytest.approx(math.hypot(along, across), abs=1e-9)
            assert m.assumed in s.label and len(s.circles) == len(mount_pattern(table31.projector))
            continue
        if isinstance(m.assumed, str):
            assert (x0, y0) == (x1, y1) and m.assumed in s.label  # a call-out naming the assumed thread
            continue
        assert math.hypot(x1 - x0, y1 - y0) == pytest.approx(m.assumed, abs=1e-9), m.key
        assert f"{m.assumed:g} mm" in s.label
    holes = [c for c in sketch(table31, next(m for m in measurements(table31) if m.key == "camera.mount_spacing")).circles]
    assert abs(holes[1][1][0] - holes[0][1][0]) == pytest.approx(table31.camera.mount_spacing)
    prof = load_profile(write_profile(table31_text + "projector:\n  pupil_lateral: 12 mm\n", "lateral"))
    top = sketch(prof, next(m for m in measurements(table31) if m.key == "projector.pupil_lateral"))
    (_, a), (_, b) = top.dimension
    assert abs(b - a) == pytest.approx(12.0)


def test_the_default_profile_names_the_shipped_files():
    p = load_profile(ROOT / "profiles" / "achutha2006.yaml")
    assert p.instrument("camera").file == "profiles/instruments/prosilica_ec1350c.yaml"
    assert p.instrument("projector").name == "benq_pb6210" and p.instrument("camera", "lens") is None


def test_a_size_label_says_who_set_it(tmp_path, table31):
    """The label a part or a bill line gives an instrument's size comes from who set it, never from
    the key's doc: assumed, set in the profile, from a file, or partly assumed naming the keys."""
    from rigcad.profile.instruments import size_origin

    body = ("body_width", "body_height", "body_depth")
    assert size_origin(table31, "camera", body) == "assumed size"
    lab = load_profile(_lab(tmp_path, LAB_PROFILE))
    assert size_origin(lab, "camera", body) == "size partly assumed (body_depth)"
    assert size_origin(lab, "camera", ("body_width",)) == "size from lab_cam"
    assert size_origin(lab, "camera", ("body_width", "body_height")) == "size from lab_cam and the profile"
    assert size_origin(lab, "camera", ("body_height",)) == "size set in the profile"


def test_a_labs_own_projector_is_used_and_billed(tmp_path, monkeypatch):
    """The issue's pico projector, 1280 x 720 with its throw ratio from its datasheet, as a file in the
    lab's folder: the profile names it, the design reads its figures, the bill names it."""
    from types import SimpleNamespace

    from rigcad.manual.bom import purchased
    from rigcad.profile import derive

    monkeypatch.chdir(tmp_path)
    path = _lab(tmp_path, LAB_PROFILE + "projector:\n  model: pico_dlp_720p\n")
    (tmp_path / "instruments" / "pico_dlp_720p.yaml").write_text(
        "kind: projector\ntitle: Pico DLP 720p\nresolution: [1280, 720]\nthrow_ratio: 1.4\n"
        "sources:\n  throw_ratio: the maker's datasheet (1.4:1)\n")
    p = load_profile(path)
    assert p.projector.resolution == (1280, 720) and p.projector.throw_ratio == 1.4
    assert p.origin("projector", "throw_ratio") == "instruments/pico_dlp_720p.yaml:4"
    assert p.source("projector", "throw_ratio") == "the maker's datasheet (1.4:1)"
    assert derive(p).projector_focal_px == 1280 * 1.4  # the design's projector is the file's
    items = [r["item"] for r in purchased(SimpleNamespace(profile=p))]
    assert "projector: Pico DLP 720p" in items and "camera: Lab camera, 2448 x 2048, 3.45 um" in items


@pytest.mark.parametrize("content, message", [
    (b"kind: camera\n" + b"#" * (300 * 1024), "larger than 256 KiB, the limit for an instrument file"),
    (b"kind: camera\ntitle: \x07\n", "control character U+0007"),
    ("kind: camera".encode("utf-16"), "UTF-16"),
    (b"a: &a [x]\n" + b"".join(b"a%d: &a%d [*a%d, *a%d, *a%d, *a%d]\n" % (i + 1, i + 1, i, i, i, i) for i in range(12)),
     "alias bomb"),
])
def test_a_hostile_instrument_file_crosses_the_loaders_boundary(tmp_path, content, message):
    """The same boundary as a profile's (rigcad.profile.loader): refused in one line naming the file,
    never read whole, never echoed."""
    path = _lab(tmp_path, LAB_PROFILE)
    (tmp_path / "instruments" / "lab_cam.yaml").write_bytes(content)
    with pytest.raises(ProfileError) as info:
        load_profile(path)
    assert message in str(info.value) and "lab_cam.yaml" in str(info.value) and "\n" not in str(info.value)
