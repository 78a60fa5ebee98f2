"""The instrument library: a profile picks an entry by name, its sourced sizes replace the assumed
defaults, and what stays assumed is listed for measuring."""

import pytest

from rigcad.errors import ProfileError
from rigcad.profile import load_profile
from rigcad.profile.instruments import CAMERA_SIZES, FIGURES, LIBRARY, PROJECTOR_SIZES, measurements, names


def test_the_library_has_three_current_projectors_and_three_cameras_each_sourced_or_marked():
    current = {k: [n for n in names(k) if "discontinued" not in LIBRARY[n].title] for k in ("projector", "camera")}
    assert len(current["projector"]) >= 3 and len(current["camera"]) >= 3
    for entry in LIBRARY.values():
        keys = PROJECTOR_SIZES if entry.kind == "projector" else CAMERA_SIZES
        assert set(entry.sizes) <= set(keys)
        assert set(entry.sources) == set(entry.sizes), entry.name  # every sourced size says where from
        assert all(src.startswith("http") for src in entry.sources.values())
    assert set(FIGURES) >= set(PROJECTOR_SIZES) | set(CAMERA_SIZES)  # every size has a figure


def test_a_model_fills_its_sourced_sizes_and_the_profile_wins(write_profile, table31_text):
    p = load_profile(write_profile(table31_text + "camera:\n  model: basler_ace_u_aca2040_55uc\n  body_height: 30 mm\n"))
    assert p.camera.body_width == 29.0 and p.camera.body_depth == 29.3  # from Basler's page
    assert p.camera.body_height == 30.0  # the profile's own measurement wins
    assert p.camera.resolution == (2048, 1536)
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
    assert "projector.model" in str(info.value) and "benq_mw632st" in str(info.value)


def test_each_measurement_sketch_draws_its_dimension_at_the_profiles_value(table31, write_profile, table31_text):
    """The figure's dimension runs between two points whose distance is the size itself (the
    profile's assumed value, not the sketch's arithmetic); a thread is a call-out at one hole; the
    camera's two holes are mount_spacing apart; a profile's own value moves the drawing."""
    import math

    from rigcad.profile.instruments import sketch

    for m in measurements(table31):
        s = sketch(table31, m)
        (x0, y0), (x1, y1) = s.dimension
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
