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
    assert lens.focal_length in CATALOGUE_FOCAL_LENGTHS
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
