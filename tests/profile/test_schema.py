import math

import pytest

from rigcad.errors import ProfileError
from rigcad.profile import derive, load_profile


def test_table31_profile_resolves(table31):
    assert table31.layout.cop_to_vertex == pytest.approx(270.0)
    assert table31.layout.sample_to_rim == pytest.approx(135.0)
    assert table31.paraboloid.tangent_angle == pytest.approx(math.radians(20))
    assert table31.projector.resolution == (1024, 768)
    assert table31.projector.aperture == pytest.approx(5.0)


def test_derived_paraboloid_matches_its_definition(table31_geometry):
    g = table31_geometry
    # Independent of derive(): the surface z = z_v - r^2/(4f) evaluated at the rim by finite
    # differences must have the tangent angle and vertical extent the profile asked for.
    r, f, h = g.rim_radius, g.focal_length, 1e-6
    def z(x):
        return g.vertex_z - x * x / (4 * f)
    slope = (z(r + h) - z(r - h)) / (2 * h)
    assert math.atan2(1.0, abs(slope)) == pytest.approx(math.radians(20), abs=1e-8)  # FD error ~h^2
    assert g.vertex_z - z(r) == pytest.approx(22.5, abs=1e-12)
    assert g.rim_z == pytest.approx(135.0)
    assert g.cop_z == pytest.approx(135.0 + 22.5 + 270.0)
    # Radius of curvature at the vertex is 2f, about 6 mm (the ray-checker issue quotes this figure).
    assert g.vertex_radius_of_curvature == pytest.approx(5.96, abs=0.01)


def test_focal_length_and_rim_radius_alternative(write_profile):
    path = write_profile("""
        paraboloid: {focal_length: 2.98067245721537 mm, rim_radius: 16.3786605419791 mm}
        layout: {cop_to_vertex: 27 cm, sample_to_rim: 13.5 cm}
    """)
    g = derive(load_profile(path))
    assert g.vertical_extent == pytest.approx(22.5, rel=1e-12)
    assert g.tangent_angle == pytest.approx(math.radians(20), rel=1e-12)


@pytest.fixture
def TABLE31(table31_text):
    return table31_text


def _err(write_profile, text):
    with pytest.raises(ProfileError) as info:
        load_profile(write_profile(text))
    return str(info.value)


def test_unknown_key_names_file_line_and_suggestion(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31 + "dome:\n  tolerence: 1e-9 mm\n")
    assert "p.yaml:8" in msg and "dome.tolerence" in msg and "did you mean 'tolerance'" in msg


def test_unknown_section(write_profile, TABLE31):
    assert "unknown section 'lay_out'" in _err(write_profile, TABLE31 + "lay_out: {}\n")


def test_missing_value(write_profile):
    msg = _err(write_profile, "paraboloid: {vertical_extent: 2.25 cm, tangent_angle: 20 deg}\n"
                              "layout: {cop_to_vertex: 27 cm}\n")
    assert "missing required key layout.sample_to_rim" in msg and "p.yaml:2" in msg


def test_empty_value(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31.replace("13.5 cm", ""))
    assert "layout.sample_to_rim: has no value" in msg and "p.yaml:6" in msg


@pytest.mark.parametrize("angle", ["0 deg", "90 deg", "-5 deg", "120 deg"])
def test_tangent_angle_outside_open_interval(write_profile, angle, TABLE31):
    msg = _err(write_profile, TABLE31.replace("20 deg", angle))
    assert "paraboloid.tangent_angle" in msg and "> 0 deg and < 90 deg" in msg and "p.yaml:3" in msg


@pytest.mark.parametrize("value", ["0 cm", "-13.5 cm"])
def test_zero_or_negative_size(write_profile, value, TABLE31):
    msg = _err(write_profile, TABLE31.replace("13.5 cm", value))
    assert "layout.sample_to_rim" in msg and "> 0 mm" in msg


def test_wrong_unit(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31.replace("27 cm", "27 deg"))
    assert "layout.cop_to_vertex" in msg and "unit of angle" in msg and "p.yaml:5" in msg


def test_mixed_paraboloid_spec(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31.replace("tangent_angle: 20 deg", "rim_radius: 16 mm"))
    assert "either vertical_extent and tangent_angle" in msg


def test_target_range_order(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31 + "targets: {theta_min: 50 deg, theta_max: 40 deg}\n")
    assert "targets.theta_min" in msg


def test_cop_at_infinity_is_allowed_but_not_elsewhere(write_profile, TABLE31):
    load_profile(write_profile(TABLE31.replace("27 cm", "inf")))
    assert "must be finite" in _err(write_profile, TABLE31.replace("13.5 cm", "inf"))


def test_instrument_defaults_are_the_thesis_resolutions_and_assumed_sizes(table31):
    # Resolutions are the thesis's (3.1); every body size's doc says it is assumed.
    from dataclasses import fields

    assert table31.camera.resolution == (1360, 1024)
    for section in ("projector", "camera", "lens", "beam_splitter"):
        obj = getattr(table31, section)
        for f in fields(obj):
            if (f.name.startswith(("body_", "lens_", "pupil_")) or f.name in ("diameter", "thickness", "width")) \
                    and (section, f.name) != ("beam_splitter", "thickness"):
                assert "assumed" in f.metadata["spec"].doc, f"{section}.{f.name} must say it is assumed"
    # the splitter is bought: its thickness is the catalogue's (1.1 mm float glass), not assumed
    assert table31.beam_splitter.thickness == pytest.approx(1.1)
    assert table31.tower.splitter_distance == pytest.approx(70.0)


def test_tower_travel_must_cover_the_tolerances(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31 + "tower:\n  travel_across: 0.3 mm\n")
    assert "tower.travel_across" in msg and "tolerancing.camera_offset" in msg and "p.yaml:8" in msg
    msg = _err(write_profile, TABLE31 + "tolerancing:\n  projector_height: 3 mm\n")
    assert "tower.travel_along" in msg and "tolerancing.projector_height" in msg


def test_unknown_mount_thread_lists_the_valid_ones(write_profile, TABLE31):
    msg = _err(write_profile, TABLE31 + "camera:\n  mount_thread: M7\n")
    assert "camera.mount_thread" in msg and "1/4-20 UNC" in msg
