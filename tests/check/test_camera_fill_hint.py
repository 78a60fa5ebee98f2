"""The camera row's hint names the lens that fills the stated fraction of the sensor's short side and
says which way that is from the lens the profile has: shorter when the image is too large, longer when
a short lens leaves it small (a passing row)."""

import pytest

from rigcad.check.tolerances import camera_rows
from rigcad.optics.camera import DEFAULT_FILL


def _cam(fill: float) -> dict:
    """A 2448 x 2048 sensor of 3.45 um pixels behind a 12 mm lens whose paraboloid image fills ``fill``
    of the short side (the image's radius is linear in the focal length)."""
    return {"paraboloid_image_radius_px": fill * 1024, "resolution_px": [2448, 2048], "focal_length_mm": 12.0,
            "focal_length_px": 12.0 / 0.00345, "focal_from": "camera.focal_length",
            "paraboloid_image_fill_of_short_side": fill, "pixel_pitch_mm": 0.00345, "reach_over_room": fill,
            "min_working_distance_mm": None, "working_distance_mm": 300.0}


@pytest.mark.parametrize("fill, word, passes", [(0.38, "longer", True), (1.2, "shorter", False)])
def test_the_hint_says_which_way_the_filling_lens_lies(table31, fill, word, passes):
    (row,) = camera_rows(table31, _cam(fill))
    assert row.ok is passes
    lens = 12.0 * DEFAULT_FILL / fill  # mm: r is linear in f
    assert f"{lens:.3g} mm, a {word} camera.focal_length, fills 90%" in row.hint, row.hint
