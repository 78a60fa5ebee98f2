"""rigcad basis draws the zonal images for the rig as measured (rigcad.basis.measured): the
calibration circle read in the projector's pixels, the deflectometric fit's rig on which each lit
pixel's light is traced; a wrong or foreign file is refused in one line naming the file and key."""

import json
import math

import numpy as np
import pytest

from rigcad.basis.measured import (CALIBRATION_JSON, CIRCLE_JSON, Measured, check_circle, load_measured, read_fit)
from rigcad.basis.projector import projector_basis
from rigcad.calibrate.model import RIG_NAMES
from rigcad.errors import BasisError


@pytest.fixture(scope="module")
def design(table31_rig):
    return projector_basis(table31_rig, 1)


def _lit(basis):
    px, lit = basis.illumination.pixels, basis.illumination.lit
    return px.row[lit], px.col[lit]


def _calibration(values: dict) -> dict:
    """A calibration.json's fit as rigcad calibrate writes it (fit.as_dict: angles in deg)."""
    params = {n.replace("_rad", "_deg"): {"value": values.get(n, 0.0), "standard_error": 0.01} for n in RIG_NAMES}
    return {"fit": {"parameters": params, "rms_residual_mm": 0.001},
            "camera_window": {"row0": 300, "col0": 400, "shape": [420, 420]}}


def test_a_measured_circle_moves_and_scales_the_zones(table31_rig, design):
    """The circle measured 10 px right of the image centre and 5 % larger: the lit pixels (the zones'
    support) move 10 px right, their radius grows 5 %; the design's circle gives the design's images."""
    r_design = design.illumination.pixels.focal_px * math.tan(table31_rig.incidence.alpha_max)
    w, h = table31_rig.profile.projector.resolution
    circle = check_circle(table31_rig, (w / 2 + 10, h / 2), 1.05 * r_design, "test")
    moved = projector_basis(table31_rig, 1, measured=Measured(circle=circle))
    rows0, cols0 = _lit(design)
    rows1, cols1 = _lit(moved)
    assert cols1.mean() - cols0.mean() == pytest.approx(10.0, abs=0.01)  # symmetric support: exactly the shift
    assert rows1.mean() - rows0.mean() == pytest.approx(0.0, abs=0.01)
    # the outermost lit pixel's radius: one pixel's quantisation (1 px of ~108) on top of the 5 %
    rad0 = np.hypot(cols0 + 0.5 - w / 2, rows0 + 0.5 - h / 2).max()
    rad1 = np.hypot(cols1 + 0.5 - w / 2 - 10, rows1 + 0.5 - h / 2).max()
    assert rad1 / rad0 == pytest.approx(1.05, abs=1.5 / rad0)
    same = projector_basis(table31_rig, 1, measured=Measured(circle=check_circle(table31_rig, (w / 2, h / 2), r_design, "t")))
    assert np.array_equal(same.values, design.values)


def test_a_planted_fit_moves_the_directions_the_images_show(table31_rig, design, tmp_path):
    """A calibration.json whose fit moves the paraboloid 0.5 mm in x: the images show each lit pixel's
    zonal values at the direction it lights the sample from on that rig (traced), which differ from the
    design's; a zero fit gives back the design's directions (the trace agrees with the design map)."""
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(_calibration({"paraboloid_dx_mm": 0.5})))
    theta = read_fit(table31_rig, path)
    assert theta[0] == 0.5 and sum(abs(v) for v in theta) == 0.5
    moved = projector_basis(table31_rig, 1, measured=Measured(theta=theta, fit_source=str(path)))
    s0, s1 = design.illumination.sampling, moved.illumination.sampling
    both = s0.valid & s1.valid
    shift = np.degrees(np.abs(s1.theta_rad[both] - s0.theta_rad[both]))
    # a 0.5 mm shift of the paraboloid turns the light by degrees (measured: 3.06 deg at most, 1.89 median)
    assert shift.max() > 1.0 and np.median(shift) > 1.0, shift.max()
    assert not np.allclose(moved.values, design.values)
    assert moved.report["measured"]["fit"]["parameters"]["paraboloid_dx_mm"] == 0.5
    path.write_text(json.dumps(_calibration({})))
    still = projector_basis(table31_rig, 1, measured=Measured(theta=read_fit(table31_rig, path), fit_source="zero"))
    s2 = still.illumination.sampling
    both = s0.valid & s2.valid
    # the traced arrival against the design map's spline: the map's own error (measured 1.1e-10 rad)
    assert np.abs(s2.theta_rad[both] - s0.theta_rad[both]).max() < 1e-8


def test_files_found_beside_are_read_and_as_designed_ignores_them(table31_rig, tmp_path):
    folder = tmp_path / table31_rig.name / "calibrate"
    folder.mkdir(parents=True)
    w, h = table31_rig.profile.projector.resolution
    (tmp_path / table31_rig.name / CIRCLE_JSON).write_text(json.dumps(
        {"centre_px_from_top_left": [w / 2 + 3, h / 2 - 2], "radius_px": 108.5, "resolution_px": [w, h]}))
    (tmp_path / table31_rig.name / CALIBRATION_JSON).write_text(json.dumps(_calibration({"dome_dz_mm": 0.2})))
    m = load_measured(table31_rig, tmp_path)
    assert m.circle.centre_px == (w / 2 + 3, h / 2 - 2) and m.circle.radius_px == 108.5
    assert m.theta[RIG_NAMES.index("dome_dz_mm")] == 0.2
    assert load_measured(table31_rig, tmp_path, as_designed=True) == Measured()
    flag = load_measured(table31_rig, tmp_path, circle=(w / 2, h / 2, 107.0), as_designed=True)
    assert flag.circle.centre_px == (w / 2, h / 2) and flag.theta is None


@pytest.mark.parametrize("text, words", [
    ("{\"centre_px_from_top_left\": [512, 384]}", "not a measured circle: it needs the keys"),
    ("{\"centre_px_from_top_left\": [512, 384], \"radius_px\": 300}", "radius is 300, outside"),
    ("{\"centre_px_from_top_left\": [2000, 384], \"radius_px\": 108}", "centre x is 2000, outside 0..1024 px"),
    ("{\"centre_px_from_top_left\": [512, 384], \"radius_px\": 108, \"resolution_px\": [1280, 800]}",
     "measured on another projector"),
    ("[1, 2", "circle.json"),
])
def test_a_wrong_circle_file_is_refused_naming_file_and_key(table31_rig, tmp_path, text, words):
    (tmp_path / table31_rig.name / "calibrate").mkdir(parents=True)
    (tmp_path / table31_rig.name / CIRCLE_JSON).write_text(text)
    with pytest.raises(BasisError) as info:
        load_measured(table31_rig, tmp_path)
    msg = str(info.value)
    assert "circle.json" in msg and words in msg and "\n" not in msg, msg


def test_a_wrong_or_foreign_calibration_is_refused_naming_file_and_key(table31_rig, tmp_path):
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps({"fit": {"rms_residual_mm": 0.1}}))
    with pytest.raises(BasisError, match=r"calibration.json: fit.parameters: missing; not a report of rigcad calibrate"):
        load_measured(table31_rig, tmp_path, calibration=path)
    bad = _calibration({})
    del bad["fit"]["parameters"]["camera_tilt_y_deg"]
    path.write_text(json.dumps(bad))
    with pytest.raises(BasisError, match=r"fit.parameters.camera_tilt_y_deg: missing"):
        load_measured(table31_rig, tmp_path, calibration=tmp_path)  # the folder holding it
    path.write_text(json.dumps(_calibration({"paraboloid_dz_mm": 80.0})))
    with pytest.raises(BasisError, match=r"fit.parameters.paraboloid_dz_mm is 80, outside -20..20 mm"):
        load_measured(table31_rig, tmp_path, calibration=path)
    big = _calibration({})
    big["camera_window"]["shape"] = [2048, 2448]
    path.write_text(json.dumps(big))
    with pytest.raises(BasisError, match=r"camera_window.shape .*larger than this profile's 1360 x 1024 px camera"):
        load_measured(table31_rig, tmp_path, calibration=path)
    with pytest.raises(BasisError, match=r"--calibration .*: no calibration.json there"):
        load_measured(table31_rig, tmp_path, calibration=tmp_path / "nowhere")


def test_a_calibration_found_beside_made_from_another_profile_version_is_refused(table31_rig, tmp_path):
    """calibrate/ records the profile it was made from (calibrate.made_from.json); found beside, a
    calibration of another version of the profile is refused, named with --calibration it is used."""
    from rigcad.export.manifest import profile_digest

    folder = tmp_path / table31_rig.name / "calibrate"
    folder.mkdir(parents=True)
    (folder / "calibration.json").write_text(json.dumps(_calibration({"dome_dz_mm": 0.2})))
    record = tmp_path / table31_rig.name / "calibrate.made_from.json"
    record.write_text(json.dumps({"profile_sha256": profile_digest(table31_rig.profile)}))
    assert load_measured(table31_rig, tmp_path).theta is not None  # this profile's: read
    record.write_text(json.dumps({"profile_sha256": "0" * 64}))
    with pytest.raises(BasisError, match=r"calibration.json: made from another version of profile achutha2006"):
        load_measured(table31_rig, tmp_path)
    assert load_measured(table31_rig, tmp_path, calibration=folder).theta is not None
