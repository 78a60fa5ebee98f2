"""The checkerboard step's comparison (rigcad.manual.calibration.camera_correspondence): the
paraboloid's image against the design, from closed forms, with the pass bands the camera's
tolerances give; the manual states the figures it computed."""

from __future__ import annotations

import math

from rigcad.manual import calibration as C


def test_the_rims_image_and_its_bands_from_closed_forms(table31_rig):
    p, g = table31_rig.profile, table31_rig.geometry
    corr = C.camera_correspondence(table31_rig)
    w, h = p.camera.resolution
    assert corr["principal_point_px"] == [w / 2, h / 2]  # the profile gives no principal point: the centre
    reach = g.cop_z - g.rim_z
    # pinhole at the COP: the rim (radius R, reach below the COP) images R / reach x f_px from the centre
    r = corr["focal_length_px"] * g.rim_radius / reach
    assert abs(corr["image_radius_px"] - r) < 1e-9 * r, (corr["image_radius_px"], r)  # same closed form: rounding
    # the camera module's own note: the rim about 134 px from the image centre for Table 3.1
    assert round(corr["image_radius_px"]) == 134
    t = p.tolerancing
    # a camera moved up by its height tolerance: the rim's image shrinks by R f / reach - R f / (reach + dh)
    exact = r - corr["focal_length_px"] * g.rim_radius / (reach + t.camera_height)
    radius_band = max(exact, C.EDGE_READ_PX)
    # first order against the exact change: within (dh / reach) of it, i.e. under 1 % here
    assert abs(corr["radius_tolerance_px"] - radius_band) <= radius_band * t.camera_height / reach + 1e-12
    # a camera moved across by its offset tolerance and tilted by its tilt tolerance
    shift = corr["focal_length_px"] * (t.camera_offset / reach + math.tan(t.camera_tilt))
    assert abs(corr["centre_tolerance_px"] - max(shift, C.EDGE_READ_PX)) < 1e-9 * shift
    assert corr["radius_tolerance_px"] >= C.EDGE_READ_PX and corr["centre_tolerance_px"] >= C.EDGE_READ_PX


def test_the_checkerboard_step_states_what_it_compares_and_what_passes(table31_rig):
    from rigcad.manual.document import Doc, _calibration_more

    class _Ctx:
        rig = table31_rig

    c, d = _Ctx(), Doc()
    _calibration_more(d, c, C.camera_crosses(table31_rig))
    text = " ".join(b[-1] if isinstance(b[-1], str) else " ".join(b[-1]) for b in d.blocks)
    corr = c.correspondence
    (x0, y0) = corr["principal_point_px"]
    for want in (f"**{x0:.1f}, {y0:.1f} px**", f"**{corr['image_radius_px']:.1f} px**",
                 f"within **{corr['centre_tolerance_px']:.1f} px**", f"within **{corr['radius_tolerance_px']:.1f} px**",
                 "No rigcad command reads it", "passes when"):
        assert want in text, want
