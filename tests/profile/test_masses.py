"""The instruments' masses are profile keys with units (``projector.mass``, ``camera.mass``; kg inside):
assumed 3 kg and 0.3 kg by default, read in kg, g, lb or oz, refused bare or not positive, and what the loads
read (rigcad.fab.loads: the same shelf figure as the masses passed by hand); section 0 of the manual asks to
weigh the ones the profile only assumes."""

from __future__ import annotations

import pytest

from rigcad.errors import ProfileError
from rigcad.fab import loads
from rigcad.fab.printers import load_printer
from rigcad.manual import document as D
from rigcad.rig import load


def _profile(tmp_path, body: str):
    path = tmp_path / "m.yaml"
    path.write_text("extends: achutha2006\n" + body)
    return path


def test_the_defaults_are_the_assumed_masses(table31_rig):
    p = table31_rig.profile
    assert (p.projector.mass, p.camera.mass) == (3.0, 0.3)
    assert p.set_by("projector", "mass") == p.set_by("camera", "mass") == "default"


def test_a_stated_mass_is_read_in_kg_and_loads_the_shelf(table31_rig, tmp_path):
    rig = load(_profile(tmp_path, "projector:\n  mass: 6.6 kg\ncamera:\n  mass: 350 g\n"))
    assert rig.profile.projector.mass == 6.6 and rig.profile.camera.mass == pytest.approx(0.35, rel=1e-12)
    mk3s = load_printer("prusa_mk3s")
    stated = {d.part: d.share for d in loads.deflections(rig.profile, rig.layout, mk3s)}
    by_hand = {d.part: d.share for d in loads.deflections(table31_rig.profile, table31_rig.layout, mk3s,
                                                            masses={"projector": 6.6, "camera": 0.35})}
    default = {d.part: d.share for d in loads.deflections(table31_rig.profile, table31_rig.layout, mk3s)}
    assert stated == pytest.approx(by_hand, rel=1e-12) and stated["shelf"] > default["shelf"]
    assert load(_profile(tmp_path, "projector:\n  mass: 2 lb\n")).profile.projector.mass == pytest.approx(0.90718474)


@pytest.mark.parametrize("value, words", [("6.6", r"projector\.mass: a mass needs a unit, e\.g\. '6\.6 kg'"),
                                          ("0 kg", r"projector\.mass: .*valid: > 0 kg"),
                                          ("6.6 mm", r"projector\.mass")])
def test_a_mass_without_a_unit_or_not_positive_is_refused_naming_the_key(tmp_path, value, words):
    with pytest.raises(ProfileError, match=words):
        load(_profile(tmp_path, f"projector:\n  mass: {value}\n"))


def test_section_0_asks_to_weigh_only_the_assumed_masses(table31_rig, tmp_path):
    class Notes:
        def __init__(self):
            self.text = []

        def p(self, text):
            self.text.append(text)

    notes = Notes()
    D._weigh_first(notes, table31_rig.profile)
    (line,) = notes.text
    assert "`projector.mass`, assumed 3 kg" in line and "`camera.mass`, assumed 0.3 kg" in line
    notes = Notes()
    D._weigh_first(notes, load(_profile(tmp_path, "projector:\n  mass: 6.6 kg\n")).profile)
    (line,) = notes.text
    assert "projector.mass" not in line and "`camera.mass`, assumed 0.3 kg" in line
