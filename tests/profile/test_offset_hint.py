"""A projector whose lens axis lies on or outside its image (lens_offset >= 100 %) holds no disc about
it whatever its throw: the refusal names the lens shift that would pass and no throw ratio; an axis
inside the image keeps the throw-ratio hint (a wider zoom shrinks the disc)."""

import pytest

from rigcad.errors import GeometryError
from rigcad.profile import derive, load_profile


def _profile(write_profile, projector: str, name: str = "p"):
    return load_profile(write_profile(f"extends: achutha2006\nprojector: {{{projector}}}\n", name))


def _refusal(write_profile, projector: str, name: str) -> str:
    with pytest.raises(GeometryError) as err:
        derive(_profile(write_profile, projector, name))
    return str(err.value)


def test_an_axis_outside_the_image_gets_no_throw_hint(write_profile):
    msg = _refusal(write_profile, "lens_offset: 110 %", "out")
    assert "row 806 of 768" in msg, msg  # 768 / 2 x 2.1: below the bottom edge
    assert "throw_ratio can help" in msg and "lower projector.throw_ratio" not in msg, msg
    best = float(msg.split("at most ")[1].split("%")[0]) / 100
    derive(_profile(write_profile, f"lens_offset: {best - 0.005}", "ok"))  # the shift it names passes


def test_an_axis_inside_the_image_keeps_the_throw_hint(write_profile):
    radius = derive(_profile(write_profile, "lens_offset: 0", "c")).pixels_vertex_to_rim
    inside = 1 - radius / 384 + 0.1  # the disc no longer fits, the axis still 0.1 half heights inside the image
    assert inside < 1
    msg = _refusal(write_profile, f"lens_offset: {inside}", "in")
    assert "lower projector.throw_ratio (zoom wider)" in msg and "can help" not in msg, msg
