"""The calibration circle is the paraboloid's disc with the focusing lens in place, a few pixels larger than the
disc `design` judges without it (107.9 against 100.3 px on the default rig): a lens offset that holds the one and
not the other is refused by the manual with design's own rule and remedy (rigcad.profile.derived.check_disc,
naming projector.lens_offset and the largest offset that fits), not with a throw-ratio line."""

from __future__ import annotations

import re

import pytest

from rigcad.errors import GeometryError
from rigcad.manual import calibration as C
from rigcad.profile import derive, load_profile
from rigcad.rig import load


def test_an_offset_that_holds_the_bare_disc_but_not_the_lensed_one_names_the_offset(table31_rig, tmp_path):
    _, info = C.circle_image(table31_rig)
    h = table31_rig.profile.projector.resolution[1]
    lensed, bare = info["radius_px"], info["radius_without_lens_px"]
    assert bare < lensed  # the focusing lens widens the disc
    # an offset whose room below the axis, h/2 x (1 - offset), lies between the two radii
    offset = 1.0 - (bare + lensed) / h
    path = tmp_path / "offset.yaml"
    path.write_text(f"extends: achutha2006\nprojector:\n  lens_offset: {100 * offset:.2f} %\n")
    derive(load_profile(path))  # design's bare disc fits
    with pytest.raises(GeometryError, match=r"projector\.lens_offset") as err:
        C.circle_image(load(path))
    best = float(re.search(r"at most (\d+)%", str(err.value)).group(1))
    assert best == round(100 * (1.0 - 2.0 * lensed / h))  # the largest offset that holds the lensed disc
