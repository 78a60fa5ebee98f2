"""The camera as a camera (rigcad.optics.camera): the lens's focal length and principal point set
the paraboloid's image on the sensor, the camera's incidence map, the calibration's camera model
and the basis's camera pixels; without a lens the camera keeps the derived one (the lens that
frames the paraboloid as the projector does)."""

import math

import numpy as np
import pytest

from rigcad.check import tolerances
from rigcad.optics.camera import camera_model
from rigcad.profile import derive, load_profile


def camera_rows(profile):
    """The check's camera rows as a check report of ``profile`` holds them (``report["camera"]``)."""
    return tolerances.camera_rows(profile, camera_model(profile, derive(profile)).as_dict())

#: Table 3.1 (thesis): the paraboloid's vertical extent and tangent angle, the COP to the vertex.
D_P, TAU, D_CP = 22.5, math.radians(20.0), 270.0


def _camera_profile(write_profile, table31_text, extra: str, name: str = "cam"):
    """Table 3.1 with the Basler acA2040-55uc's 3.45 um sensor set to 2448 x 2048 px (the issue's
    camera) and ``extra`` camera keys."""
    return load_profile(write_profile(table31_text + "camera:\n  model: basler_ace_u_aca2040_55uc\n"
                                      "  resolution: [2448, 2048]\n" + extra, name))


def _rim_tan() -> float:
    """tan of the angle between the axis and the COP's ray to the rim, by hand: the rim radius
    2 d_p tan(tau) (the paraboloid z = -r^2 / 4f with tan(tau) = 2f / r at the rim), seen from the
    COP d_cp + d_p above the rim's plane."""
    return 2 * D_P * math.tan(TAU) / (D_CP + D_P)


def test_a_12_mm_lens_on_a_2448_x_2048_sensor_of_3_45_um_pixels_fills_a_fifth_of_it(write_profile, table31_text):
    p = _camera_profile(write_profile, table31_text, "  lens: c_mount_12mm\n")
    cam = camera_model(p, derive(p))
    diameter = 2 * (12.0 / 3.45e-3) * _rim_tan()  # f in pixels x tan(rim angle), both sides
    assert diameter == pytest.approx(389.54, abs=0.01)  # the "~390 px disc"
    # the model's figures against the closed form (float64 rounding only: 1e-12 relative)
    assert 2 * cam.image_radius_px == pytest.approx(diameter, rel=1e-12)
    assert cam.fill == pytest.approx(diameter / 2048, rel=1e-12) and cam.on_sensor
    assert cam.focal_from == "lens file c_mount_12mm" and cam.focal_length == 12.0
    # the check row states it
    (row,) = camera_rows(p)
    assert row.name == "camera: paraboloid image 390 px, 19% of 2048 px" and row.ok
    assert row.measured == pytest.approx(diameter / 2 / 1024, rel=1e-12)  # radius over the room to the edge
    # the lens that fills 90 % of the short side: f = 0.9 x 1024 px / tan(rim angle) x pitch
    f_px, f_mm = cam.focal_for_fill(0.9)
    assert f_mm == pytest.approx(0.9 * 1024 / _rim_tan() * 3.45e-3, rel=1e-12)
    assert f_mm == pytest.approx(56.78, abs=0.01)
    fitted = _camera_profile(write_profile, table31_text, f"  focal_length: {f_mm!r} mm\n", "fitted")
    assert camera_model(fitted, derive(fitted)).fill == pytest.approx(0.9, rel=1e-12)


def test_a_lens_too_long_for_the_sensor_or_too_close_to_focus_fails_its_row(write_profile, table31_text):
    p = _camera_profile(write_profile, table31_text, "  focal_length: 100 mm\n  min_working_distance: 300 mm\n")
    image, focus = camera_rows(p)
    # 2 x 100 / 0.00345 x tan = 3246 px across the 2048 px side: the rim leaves the sensor
    assert not image.ok and image.measured == pytest.approx(100 / 3.45e-3 * _rim_tan() / 1024, rel=1e-12)
    # the lens's front stands D_CP less its pupil depth (15 mm, the default) from the vertex: 255 mm < 300 mm
    assert not focus.ok and focus.measured == pytest.approx(D_CP - 15.0) and focus.limit == 300.0
    assert "p.yaml" not in image.where and "cam.yaml:" in image.where  # the profile's line to edit


def test_without_a_lens_the_camera_keeps_the_derived_one(table31):
    cam = camera_model(table31, derive(table31))
    # the projector's f (1024 px x throw ratio 1.75) scaled by the heights, 1024 / 768 px: as before the lens
    assert cam.focal_px == 1024 * 1.75 * 1024 / 768 and cam.focal_from == "derived"
    assert cam.focal_length is None and cam.principal_point == (680.0, 512.0)
    assert 2 * cam.image_radius_px == pytest.approx(2 * cam.focal_px * _rim_tan(), rel=1e-12)
    assert round(2 * cam.image_radius_px) == 268 and round(100 * cam.fill) == 26  # docs/design.md states these


def test_two_lenses_give_two_incidence_maps_and_the_calibration_takes_the_lens(write_profile, table31_text):
    """The camera's incidence map (pixel -> incidence angle at the sample) of a 12 mm and a 16 mm
    lens: different at the same pixel, the same at pixels whose radii scale as the focal lengths
    (one design map of the COP ray's angle, read through two lenses); the calibration's camera model
    and the basis's camera pixels read the lens's focal length."""
    from rigcad.basis.projector import device_map
    from rigcad.calibrate.conventions import facts
    from rigcad.calibrate.model import Camera
    from rigcad.check.sources import pixel_rays
    from rigcad.rig import Rig

    rigs = {f: Rig.from_profile(_camera_profile(write_profile, table31_text, f"  lens: c_mount_{f}mm\n", f"l{f}"))
            for f in (12, 16)}
    cams = {f: Camera.of(rig) for f, rig in rigs.items()}
    for f, cam in cams.items():
        assert cam.design.focal_px == pytest.approx(f / 3.45e-3, rel=1e-12)  # the calibration's model
        assert device_map(rigs[f], "camera").focal_px == cam.design.focal_px  # the basis's camera pixels
        assert facts(rigs[f])["camera"]["focal_px"] == cam.design.focal_px  # and the pixel conventions written

    def theta(f, x_px):
        d = cams[f].design.direction(pixel_rays(cams[f].design, np.asarray(x_px, float), np.zeros(len(x_px))).dirs)
        return np.degrees(np.arccos(d[:, 2]))

    x12 = np.linspace(60.0, 190.0, 14)  # inside the 12 mm lens's annulus (its rim at 194.8 px)
    same_pixel = np.abs(theta(12, x12) - theta(16, x12))
    assert same_pixel.min() > 1.0  # degrees: the two maps differ at every pixel
    # at the pixel 16/12 as far out the 16 mm lens sees the same COP ray: the same angle (float64
    # rounding of the table lookups: below 1e-9 deg)
    assert np.max(np.abs(theta(12, x12) - theta(16, x12 * 16 / 12))) < 1e-9


def test_the_principal_point_centres_the_calibration_window_and_the_basis_pixels(write_profile, table31_text):
    from rigcad.basis.projector import trace_pixels
    from rigcad.calibrate.model import Camera
    from rigcad.rig import Rig

    rig = Rig.from_profile(_camera_profile(write_profile, table31_text,
                                           "  lens: c_mount_12mm\n  principal_point: [1100.5, 800.5]\n", "pp"))
    cam = Camera.of(rig)
    at = np.flatnonzero((cam.x_px == 0.0) & (cam.y_px == 0.0))  # the pixel whose centre is the principal point
    assert len(at) == 1
    row, col = divmod(int(at[0]), cam.shape[1])
    assert (cam.row0 + row, cam.col0 + col) == (800, 1100)
    assert abs(cam.row0 + cam.shape[0] / 2 - 800.5) <= 1 and abs(cam.col0 + cam.shape[1] / 2 - 1100.5) <= 1
    px = trace_pixels(rig, "camera", stride=4)
    r0, c0, h, w = px.window
    assert abs(r0 + h / 2 - 800.5) <= 1 and abs(c0 + w / 2 - 1100.5) <= 1
    assert px.border_all_missed()  # the window about the moved axis holds the whole paraboloid image
    assert np.all(np.hypot(px.x_px, px.y_px) == np.hypot(px.col + 0.5 - 1100.5, 800.5 - px.row - 0.5))


def test_design_says_the_fill_and_the_lens_for_the_fraction_asked(write_profile, table31_text, capsys):
    from rigcad.cli.design import _suggest_lens, fill_fraction
    from rigcad.rig import Rig

    rig = Rig.from_profile(_camera_profile(write_profile, table31_text, "  lens: c_mount_12mm\n"))
    _suggest_lens(rig, fill_fraction("50%"))
    out = capsys.readouterr().out
    f_mm = 0.5 * 1024 / _rim_tan() * 3.45e-3  # by hand: 31.5 mm
    assert out.startswith("camera: the 12 mm lens (lens file c_mount_12mm) images the paraboloid 390 px across, "
                          "19% of the 2048 px short side; 50% needs a ")
    assert f"a {f_mm:.3g} mm lens" in out and f"{f_mm:.3g}" == "31.5"
