"""The camera's lens in the bill (rigcad.manual.camera_lens): a profile that knows its lens only in
pixels (the thesis's, f = 2389 px) gets a lens to buy in mm: the catalogue lens nearest the one whose
paraboloid image spans 90 % of the sensor's short side (what `check` and `design` recommend), from the
pixel pitch (given, or assumed and said so), with its mount, image circle and working distance; a
profile that names a lens file keeps that file's line and gets no second one."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from rigcad.manual import bom as B
from rigcad.manual import camera_lens as L
from rigcad.optics.camera import camera_model
from rigcad.profile import derive, load_profile

CATALOGUE_MM = (8.0, 12.0, 16.0, 25.0)  # the shipped lens files c_mount_<f>mm.yaml, read by hand


def _rig(write_profile, table31_text, extra: str = "", name: str = "lens"):
    p = load_profile(write_profile(table31_text + extra, name))
    return SimpleNamespace(profile=p, geometry=derive(p), name=name)


def test_the_catalogue_is_the_shipped_lens_files():
    assert tuple(f for f, _ in L.catalogue()) == CATALOGUE_MM
    assert dict(L.catalogue())[12.0] == "c_mount_12mm"


def test_the_thesis_camera_gets_a_lens_in_mm_from_an_assumed_pitch(table31_rig):
    lens = L.camera_lens(table31_rig)
    cam = camera_model(table31_rig.profile, table31_rig.geometry)
    assert cam.focal_length is None and cam.pixel_pitch is None, "the thesis's lens is known in pixels only"
    pitch = 6.4 / 1360  # a 1/2-inch sensor's 6.4 mm width over the camera's 1360 px
    assert lens["pixel_pitch_assumed"] and lens["pixel_pitch_mm"] == pytest.approx(pitch, rel=1e-12)
    f_mm = cam.focal_px * pitch  # 2389 px x 4.71 um = 11.2 mm
    assert lens["focal_length_mm"] == pytest.approx(f_mm, rel=1e-12) and 11.0 < f_mm < 11.5
    # the paraboloid's image radius is linear in f: 90 % of the short side (1024 px) over its fill at 2389 px
    fill = cam.image_radius_px / 512.0
    f_fill = f_mm * 0.9 / fill  # 11.2 mm x 0.9 / 0.261 = 38.7 mm
    assert lens["fill_focal_length_mm"] == pytest.approx(f_fill, rel=1e-12) and 38.0 < f_fill < 39.5
    on_sensor = [f for f in CATALOGUE_MM if cam.image_radius_px * f / f_mm <= 512.0]
    nearest = min(on_sensor, key=lambda f: abs(f - f_fill))
    assert lens["buy_focal_length_mm"] == nearest == 25.0
    assert lens["buy_fill"] == pytest.approx(fill * 25.0 / f_mm, rel=1e-12)  # 58 % of the short side
    # the image circle is the sensor's diagonal; the working distance the camera model's (COP to vertex less pupil)
    assert lens["image_circle_mm"] == pytest.approx(pitch * math.hypot(1360, 1024), rel=1e-12)
    p = table31_rig.profile
    assert lens["working_distance_mm"] == pytest.approx(p.layout.cop_to_vertex - p.camera.pupil_depth, rel=1e-12)
    # the line says what to buy, and which figure is assumed, and which key sets it
    row = L.bill_row(table31_rig)
    assert row["item"] == "camera lens: C-mount, 25 mm focal length"
    for words in ("**25 mm focal length, C-mount**", "image circle of at least 8.0 mm", "focusing at 255 mm",
                  "**assumed**", "`camera.pixel_pitch`", "`camera.lens: c_mount_25mm`", "= 38.7 mm", "90%",
                  "58% of the short side", "2389 px lens's (derived, 11.2 mm)"):
        assert words in row["spec"], (words, row["spec"])


def test_the_line_follows_the_given_pitch(write_profile, table31_text):
    rig = _rig(write_profile, table31_text, "camera:\n  pixel_pitch: 3.45 um\n")
    lens = L.camera_lens(rig)
    cam = camera_model(rig.profile, rig.geometry)
    f_mm = cam.focal_px * 3.45e-3  # 8.24 mm
    assert not lens["pixel_pitch_assumed"] and lens["focal_length_mm"] == pytest.approx(f_mm, rel=1e-12)
    # 90 % of the short side: 8.24 mm x 0.9 / 0.261 = 28.4 mm; 25 mm is the nearest catalogue lens on the sensor
    assert lens["fill_focal_length_mm"] == pytest.approx(f_mm * 0.9 / cam.fill, rel=1e-12)
    assert lens["buy_focal_length_mm"] == 25.0
    assert "assumed" not in L.bill_row(rig)["spec"]


def test_a_named_lens_file_keeps_its_own_line_and_gets_no_second(write_profile, table31_text):
    rig = _rig(write_profile, table31_text, "camera:\n  pixel_pitch: 3.45 um\n  lens: c_mount_16mm\n", "named")
    assert L.camera_lens(rig) is None
    rows = B.purchased(rig)
    assert [r["item"] for r in L.with_camera_lens(rig, rows)] == [r["item"] for r in rows]
    assert sum(r["item"].startswith("camera lens") for r in rows) == 1, "bom lists the named file's lens"


def test_the_bill_of_the_thesis_rig_has_its_lens_after_the_camera(table31_rig):
    rows = L.with_camera_lens(table31_rig, B.purchased(table31_rig))
    items = [r["item"] for r in rows]
    lens = items.index("camera lens: C-mount, 25 mm focal length")
    assert items[lens - 1].startswith("camera"), items
    # planted back: without the lens line the bill names no camera lens
    assert not any(i.startswith("camera lens") for i in items[:lens] + items[lens + 1:])
