"""The projector stands on the shelf by its own mounting holes (projector.mount_holes): the shelf's
slots follow the pattern over their travel, and a pattern the shelf cannot carry is refused in one
line naming the key, its file:line and what would be valid (rigcad.parts.projector_mount)."""

import textwrap

import numpy as np
import pytest

from rigcad.errors import GeometryError, ProfileError
from rigcad.parts.recipe import Box, Difference
from rigcad.parts.tower import clearance_hole, tower_shelf
from rigcad.profile import load_profile
from rigcad.profile.instruments import measurements, mount_pattern
from rigcad.rig import Rig


def _rig(write_profile, table31_text, holes: str, name: str = "p"):
    return Rig.from_profile(load_profile(write_profile(table31_text + f"projector:\n  mount_holes: {holes}\n", name)))


def _slots(rig):
    """The shelf's cuts that are the projector's slots: boxes as wide as its clearance hole plus the travel."""
    p, t = rig.profile, rig.layout.tower
    d = clearance_hole(p.projector.mount_thread)
    w = (d + 2 * p.tower.travel_along, d + 2 * p.tower.travel_across)
    shape = tower_shelf(p, rig.layout).solid
    assert isinstance(shape, Difference)
    return [((c.lo[0] + c.hi[0]) / 2, (c.lo[1] + c.hi[1]) / 2) for c in shape.cuts if isinstance(c, Box)
            and (c.hi[0] - c.lo[0], c.hi[1] - c.lo[1]) == pytest.approx(w)]


def test_the_shelf_slots_follow_the_projectors_holes(write_profile, table31_text):
    """Three holes given with their units (one in inches) put three slots under them, each centred on
    its hole (so the hole moves +-travel_along and +-travel_across inside it); the assumed pattern puts
    four where the 30 mm inset put them."""
    rig = _rig(write_profile, table31_text, "[[60 mm, -100 mm], [60 mm, 100 mm], [9 in, 0 mm]]")
    t = rig.layout.tower
    x_cop = t.projector_cop[0]
    want = [(x_cop + 60.0, -100.0), (x_cop + 60.0, 100.0), (x_cop + 228.6, 0.0)]
    assert np.allclose(t.projector_feet, want, atol=1e-9)
    assert np.allclose(sorted(_slots(rig)), sorted(want), atol=1e-9)
    assert "projector.mount_holes" not in [m.key for m in measurements(rig.profile)]  # measured: not assumed


def test_the_assumed_pattern_is_listed_to_measure_and_gives_the_old_slots(table31_rig):
    t, pj = table31_rig.layout.tower, table31_rig.profile.projector
    (x0, y0, _), (x1, y1, _) = t.projector_box
    old = [(x, y) for x in (x0 + 30.0, x1 - 30.0) for y in (y0 + 30.0, y1 - 30.0)]  # the former FOOT_INSET
    assert np.allclose(sorted(_slots(table31_rig)), sorted(old), atol=1e-9)
    (m,) = [m for m in measurements(table31_rig.profile) if m.key == "projector.mount_holes"]
    assert m.unit == "mm" and m.assumed == "[" + ", ".join(f"[{a:g}, {c:g}]" for a, c in mount_pattern(pj)) + "]"


@pytest.mark.parametrize("holes, words", [
    ("[[60 mm, -100 mm], [200 mm, 100 mm]]", "2 holes; the projector stands on a shim stack at each hole"),
    ("[[60 mm, 0 mm], [120 mm, 1 mm], [200 mm, 0 mm]]", "of one line"),
    ("[[60 mm, -100 mm], [60 mm, 100 mm], [400 mm, 0 mm]]", "hole 3 at [400, 0] mm is not on the body's bottom face; "
                                                            "valid: along 12.2..242.8 mm"),
    ("[[60 mm, -100 mm], [60 mm, 100 mm], [200 mm, 0 mm], [220 mm, 10 mm]]", "holes 3 and 4 are closer than a shim's"),
    ("[[60 mm, -100 mm], [60 mm, 100 mm], [125 mm, 0 mm]]", "hole 3 at [125, 0] mm: its screw's head and washers under "
                                                            "the shelf (15 mm across, +-2 mm along) would meet the "
                                                            "column's top flange"),
])
def test_a_pattern_the_shelf_cannot_carry_is_refused_naming_the_key_and_line(write_profile, table31_text, holes, words):
    with pytest.raises(GeometryError) as info:
        _ = _rig(write_profile, table31_text, holes).layout
    msg = str(info.value)
    assert "/p.yaml:8: projector.mount_holes: " in msg, msg  # the key's own line
    assert words in msg, msg
    assert "\n" not in msg


def test_the_assumed_pattern_refused_says_to_measure_it(write_profile, table31_text):
    """A body too narrow for the assumed pattern's stacks: the refusal says the pattern is assumed."""
    p = load_profile(write_profile(table31_text + "projector:\n  body_width: 80 mm\n", "narrow"))
    with pytest.raises(GeometryError) as info:
        _ = Rig.from_profile(p).layout
    assert "(the assumed pattern: measure yours and set projector.mount_holes)" in str(info.value)


@pytest.mark.parametrize("holes, words", [
    ("[[60, -100], [60, 100], [200, 0]]", "needs a unit"),
    ("[60 mm, 100 mm]", "a list of 1..16 [along, across] pairs of lengths"),
    ("[[60 mm, -100 mm, 3 mm]]", "a list of 1..16 [along, across] pairs of lengths"),
    ("[]", "a list of 1..16"),
])
def test_a_malformed_pattern_is_refused_by_the_profile(write_profile, table31_text, holes, words):
    with pytest.raises(ProfileError) as info:
        load_profile(write_profile(table31_text + f"projector:\n  mount_holes: {holes}\n"))
    assert "projector.mount_holes" in str(info.value) and words in str(info.value), str(info.value)


def test_an_instrument_file_gives_the_pattern_with_its_source(tmp_path, write_profile, table31_text):
    folder = tmp_path / "instruments"
    folder.mkdir()
    (folder / "lab_projector.yaml").write_text(textwrap.dedent("""
        kind: projector
        title: a lab's projector
        mount_holes: [[50 mm, -90 mm], [50 mm, 90 mm], [200 mm, 0 mm]]
        sources:
          mount_holes: measured on our unit, 2026-12-07
    """).lstrip())
    path = write_profile(table31_text + "projector:\n  model: lab_projector\n", "lab")
    (path.parent / "instruments").mkdir(exist_ok=True)
    (path.parent / "instruments" / "lab_projector.yaml").write_text((folder / "lab_projector.yaml").read_text())
    p = load_profile(path)
    assert p.projector.mount_holes == ((50.0, -90.0), (50.0, 90.0), (200.0, 0.0))
    assert p.set_by("projector", "mount_holes") == "instrument"
    assert "projector.mount_holes" not in [m.key for m in measurements(p)]
