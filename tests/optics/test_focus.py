"""The focusing lens: the thin-lens equation against its closed forms, and the catalogue choice."""

import math

import pytest

from rigcad.errors import GeometryError
from rigcad.optics.focus import CATALOGUE_FOCAL_LENGTHS, focus_for, focusing_lens, image_distance
from rigcad.profile import derive, load_profile


def test_image_distance_is_the_gaussian_lens_equation():
    f, s = 300.0, 25.0
    # focused at infinity: the image sits in the lens's focal plane
    assert image_distance(f, s, math.inf) == pytest.approx(f, rel=1e-15)
    # two thin lenses in contact add in dioptres: focus D - s = 1200 mm, f = 300 mm -> 1/u = 1/300 + 1/1200
    assert image_distance(f, s, 1225.0) == pytest.approx(240.0, rel=1e-12)
    # the inverse: the focus that images 240 mm from the lens is 1225 mm from the COP
    assert focus_for(f, s, 240.0) == pytest.approx(1225.0, rel=1e-12)
    # at or beyond f, only focus at infinity (or past it) reaches: inf
    assert math.isinf(focus_for(f, s, 300.0)) and math.isinf(focus_for(f, s, 400.0))


def test_the_default_lens_brings_the_paraboloid_into_the_projector_range(table31, table31_geometry):
    lens = focusing_lens(table31, table31_geometry)
    g = table31_geometry
    assert lens.focal_length in CATALOGUE_FOCAL_LENGTHS and lens.from_catalogue is True
    # the paraboloid from the lens: vertex d_cp - s, rim from the COP by Pythagoras
    s = table31.lens.distance
    assert lens.image_near == pytest.approx(g.cop_z - g.vertex_z - s, rel=1e-12)
    assert lens.image_far == pytest.approx(math.hypot(g.rim_radius, g.cop_z - g.rim_z) - s, rel=1e-12)
    # independent check of both ends: the projector focused where the lens says re-images onto the ends
    for focus, image in ((lens.focus_near, lens.image_near), (lens.focus_far, lens.image_far)):
        assert table31.projector.focus_min <= focus <= table31.projector.focus_max
        # 1/u = 1/f + 1/(D - s), written out here, not through the module
        assert 1.0 / (1.0 / lens.focal_length + 1.0 / (focus - s)) == pytest.approx(image, rel=1e-12)
    # its neighbours in the catalogue sit farther from the dioptric middle of the projector's range
    mid = 0.5 * (1 / (table31.projector.focus_min - s) + 1 / (table31.projector.focus_max - s))
    mid_target = 0.5 * (1 / lens.image_near + 1 / lens.image_far)
    ideal = 1 / (mid_target - mid)
    assert all(abs(1 / lens.focal_length - 1 / ideal) <= abs(1 / f - 1 / ideal) for f in CATALOGUE_FOCAL_LENGTHS)


def test_a_projector_that_cannot_focus_close_enough_names_the_key(write_profile, table31_text):
    # a projector focusing from 9 m to 9.001 m only: the paraboloid's ends (~245 and ~268 mm from the
    # lens) need focus settings more than a millimetre apart with any catalogue lens
    p = load_profile(write_profile(table31_text + "projector:\n  focus_min: 9 m\n  focus_max: 9.001 m\n"))
    with pytest.raises(GeometryError) as info:
        focusing_lens(p, derive(p))
    assert "projector.focus_min" in str(info.value)


def test_a_given_focal_length_out_of_range_is_refused(write_profile, table31_text):
    p = load_profile(write_profile(table31_text + "lens:\n  focal_length: 100 mm\n"))
    with pytest.raises(GeometryError) as info:
        focusing_lens(p, derive(p))
    assert "lens.focal_length" in str(info.value)


def test_a_given_reachable_focal_length_is_used_as_given(write_profile, table31_text, table31, table31_geometry):
    import json

    chosen = focusing_lens(table31, table31_geometry)
    p = load_profile(write_profile(table31_text + f"lens:\n  focal_length: {chosen.focal_length:g} mm\n"))
    lens = focusing_lens(p, derive(p))
    s = p.lens.distance
    assert (lens.focal_length, lens.lens_distance, lens.from_catalogue) == (chosen.focal_length, s, False)
    for focus, image in ((lens.focus_near, lens.image_near), (lens.focus_far, lens.image_far)):
        # D = s + 1 / (1/u - 1/f), the lens equation written out here
        assert focus == pytest.approx(s + 1.0 / (1.0 / image - 1.0 / lens.focal_length), rel=1e-12)
    # what the manifest records is strict JSON, with an infinite range end written "inf"
    d = json.loads(json.dumps(_by_hand(1.0, 2.0, 3.0, math.inf).describe(), allow_nan=False))
    assert d["projector_focus_range_mm"] == [3.0, "inf"] and d["projector_focus_mm"] == [1.0, 2.0]


def _by_hand(near, far, lo, hi):
    from rigcad.optics.focus import FocusingLens

    return FocusingLens(200.0, 25.0, 250.0, 270.0, near, far, lo, hi, True)


def test_a_focus_setting_at_the_end_of_the_range_is_reachable():
    from rigcad.optics.focus import _reachable

    lo, hi = 1000.0, 3000.0
    assert _reachable(_by_hand(lo, hi, lo, hi))  # both ends exactly at the range's ends
    assert _reachable(_by_hand(lo * (1 - 1e-12), hi * (1 + 1e-12), lo, hi))  # within rounding of them
    for near, far in ((lo * (1 - 1e-6), hi), (lo, hi * (1 + 1e-6)), (0.5 * lo, hi), (lo, 2 * hi)):
        assert not _reachable(_by_hand(near, far, lo, hi)), (near, far)
    assert _reachable(_by_hand(lo, math.inf, lo, math.inf))  # a projector focusing out to infinity
    from rigcad.optics.focus import _dioptres

    assert _dioptres(math.inf) == 0.0 and _dioptres(250.0) == 1 / 250.0  # focus at infinity: 0 dioptres


def test_a_focus_range_that_starts_at_the_lens_is_refused_naming_the_key(write_profile, table31_text, table31):
    s = table31.lens.distance
    for text in (f"projector:\n  focus_min: {s:g} mm\n", "projector:\n  focus_min: 2 m\n  focus_max: 1 m\n"):
        path = write_profile(table31_text + text)
        p = load_profile(path)
        with pytest.raises(GeometryError) as info:
            focusing_lens(p, derive(p))
        msg = str(info.value)
        assert "projector.focus_min" in msg and "lens.distance" in msg and path.name in msg, msg


@pytest.mark.parametrize("extra, key", [
    ("projector:\n  focus_min: 2 m\n  focus_max: 1 m\n", "focus_min"),  # a range ending before it starts
    ("projector:\n  focus_min: 9 m\n  focus_max: 9.001 m\n", "focus_min"),  # no catalogue lens reaches
    ("lens:\n  focal_length: 100 mm\n", "focal_length"),  # the given lens does not reach
])
def test_each_refusal_points_at_the_line_of_its_key(write_profile, table31_text, extra, key):
    path = write_profile(table31_text + extra)
    line = 1 + max(i for i, t in enumerate(path.read_text().splitlines()) if t.strip().startswith(key + ":"))
    p = load_profile(path)
    with pytest.raises(GeometryError) as info:
        focusing_lens(p, derive(p))
    assert str(info.value).startswith(f"{path}:{line}: "), (str(info.value), line)


def test_no_real_image_is_inf_and_describe_names_every_figure():
    # the projector's image behind the projector (focus - s = -f / 2, or exactly -f): the lens forms no
    # real image (1/u = 1/f + 1/(D - s) <= 0), reported as inf, not a negative distance or an error
    assert math.isinf(image_distance(200.0, 25.0, 25.0 - 100.0)) and math.isinf(image_distance(200.0, 25.0, 25.0 - 200.0))
    from rigcad.optics.focus import FocusingLens

    lens = FocusingLens(200.0, 25.0, 250.0, 270.0, 1500.0, 2500.0, 1000.0, 3000.0, True)
    # a thin lens: the real COP s f / (f + s) before it is seen s before it (the Gaussian inverse), the
    # pixels' angles x (f + s) / f
    assert lens.describe() == {"focal_length_mm": 200.0, "lens_distance_mm": 25.0,
                               "projector_cop_from_lens_mm": pytest.approx(25.0 * 200.0 / 225.0),
                               "paraboloid_from_lens_mm": [250.0, 270.0], "projector_focus_mm": [1500.0, 2500.0],
                               "projector_focus_range_mm": [1000.0, 3000.0], "from_catalogue": True,
                               "cop_shift_mm": pytest.approx(25.0 - 25.0 * 200.0 / 225.0),
                               "pixel_scale": pytest.approx(225 / 200)}


def test_the_tower_places_the_projector_through_the_lens_chosen_even_one_it_cannot_focus_through(
        table31, table31_geometry, write_profile, table31_text):
    """placed_lens is focusing_lens's choice without its verdict: the same lens where the projector can
    focus through it; where it cannot (the COP 30 cm from the vertex: f = 300 mm needs 3.3..43 m) the
    tower is still laid out through it, and focusing_lens (the bill, the optimiser) refuses it."""
    from rigcad.optics.focus import placed_lens

    assert placed_lens(table31, table31_geometry) == focusing_lens(table31, table31_geometry)
    p = load_profile(write_profile(table31_text.replace("27 cm", "30 cm")))
    with pytest.raises(GeometryError, match="no catalogue focusing lens"):
        focusing_lens(p, derive(p))
    assert placed_lens(p, derive(p)).focal_length == 300.0
