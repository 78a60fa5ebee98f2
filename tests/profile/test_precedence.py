"""Which value wins when a profile extends another and names instrument files: most specific first,
what the profile's own file states > the instrument files it names > what it inherits (``extends:``)
> the schema's defaults. Each level of an ``extends:`` chain is a profile in its own right: the
instruments a base names sit between that base's own keys and what that base extends.
``Profile.set_by``, ``origin`` and ``rigcad profile show`` say the same as the value in force."""

import json
import textwrap
from pathlib import Path
from types import SimpleNamespace

import pytest

from rigcad.profile import derive, load_profile
from rigcad.profile.loader import load_raw

#: The lab technician's profile: the thesis's rig with an Epson EB-W52, a Basler acA2040 and a 16 mm
#: C-mount lens, all shipped files (profiles/instruments/), nothing else changed.
TECHNICIAN = """
extends: achutha2006
description: the thesis's rig with the lab's projector, camera and lens
projector:
  model: epson_eb_w52
  throw_ratio: 1.75   # the lab's own figure: the base's, inherited with the BenQ, is refused
camera:
  model: basler_ace_u_aca2040_55uc
  lens: c_mount_16mm
"""


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.yaml"
    path.write_text(textwrap.dedent(text).lstrip())
    return path


@pytest.fixture
def technician(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # files are named from the lab's folder
    return load_profile(_write(tmp_path, "tech", TECHNICIAN))


def test_a_named_instrument_wins_over_the_figures_the_base_profile_states(technician):
    p = technician
    # achutha2006 states [1024, 768] and [1360, 1024]: its own projector's and camera's, not these
    assert p.projector.resolution == (1280, 800) and p.camera.resolution == (2048, 1536)
    assert p.set_by("projector", "resolution") == "instrument" and p.set_by("camera", "resolution") == "instrument"
    assert p.origin("projector", "resolution") == "profiles/instruments/epson_eb_w52.yaml:4"
    assert p.origin("camera", "resolution") == "profiles/instruments/basler_ace_u_aca2040_55uc.yaml:6"
    assert p.source("camera", "resolution").startswith("https://docs.baslerweb.com/aca2040-55uc/")
    assert p.camera.focal_length == 16.0 and p.origin("camera", "focal_length").endswith("c_mount_16mm.yaml:7")
    # what the lab's profile states wins and is credited to its own line
    assert p.projector.throw_ratio == 1.75 and p.set_by("projector", "throw_ratio") == "profile"
    assert p.origin("projector", "throw_ratio") == "tech.yaml:5"
    assert p.origin("projector", "aperture") == "profiles/achutha2006.yaml:24"  # no instrument figure: inherited
    # the inherited value's mark is gone: an error about it points at the file that set it
    assert p.where("projector", "resolution") == "profiles/instruments/epson_eb_w52.yaml:4"


def test_the_design_and_the_bill_use_the_instruments_figures(technician):
    from rigcad.manual.bom import purchased

    geo = derive(technician)
    assert geo.projector_focal_px == pytest.approx(1280 * 1.75)  # the Epson's 1280 columns, the lab's throw ratio
    rows = {r["item"].split(":")[0]: r for r in purchased(SimpleNamespace(profile=technician))}
    assert rows["projector"]["item"].startswith("projector: Epson EB-W52")
    assert rows["camera"]["item"].startswith("camera: Basler ace U acA2040-55uc")
    assert "body width 29 mm;" in rows["camera"]["spec"]  # Basler's, not the schema's assumed 46 mm


def test_the_profiles_own_value_wins_over_the_instrument_it_names(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = load_profile(_write(tmp_path, "tech", TECHNICIAN + "  resolution: [1920, 1200]\n"))  # camera.resolution
    assert p.camera.resolution == (1920, 1200) and p.set_by("camera", "resolution") == "profile"
    assert p.origin("camera", "resolution") == "tech.yaml:9"
    assert p.camera.pixel_pitch == pytest.approx(3.45e-3)  # the file still gives what the profile does not


def test_a_base_profiles_own_value_wins_over_the_instrument_it_names_itself(tmp_path, monkeypatch):
    """A child that names no instrument changes nothing: the base's statements stand over the base's
    files (achutha2006 names the BenQ and states its resolution itself)."""
    monkeypatch.chdir(tmp_path)
    p = load_profile(_write(tmp_path, "child", "extends: achutha2006\nlayout:\n  cop_to_vertex: 28 cm\n"))
    assert p.projector.resolution == (1024, 768)
    assert p.origin("projector", "resolution") == "profiles/achutha2006.yaml:22"
    assert p.set_by("projector", "resolution") == "profile"


def test_a_chain_of_two_extends(tmp_path, monkeypatch):
    """achutha2006 <- mid (names the Basler, measures its body height) <- child (names a 25 mm lens,
    measures the body width): each file's own keys win over the files it names, which win over what
    it extends."""
    monkeypatch.chdir(tmp_path)
    _write(tmp_path, "mid", """
        extends: achutha2006
        camera:
          model: basler_ace_u_aca2040_55uc
          body_height: 30 mm
          lens_length: 31 mm
    """)
    child = _write(tmp_path, "child", """
        extends: mid
        camera:
          lens: c_mount_25mm
          body_width: 28 mm
    """)
    raw = load_raw(child)
    assert [raw.depth(("camera", k)) for k in ("body_width", "body_height", "resolution", "pixel_pitch")] == [0, 1, 2, None]
    p = load_profile(child)
    # the grandparent's [1360, 1024] loses to the file mid names
    assert p.camera.resolution == (2048, 1536) and p.set_by("camera", "resolution") == "instrument"
    assert p.camera.body_height == 30.0 and p.origin("camera", "body_height") == "mid.yaml:4"  # mid's own, over its file
    assert p.camera.body_width == 28.0 and p.origin("camera", "body_width") == "child.yaml:4"  # the child's own
    assert p.camera.body_depth == 29.3 and p.set_by("camera", "body_depth") == "instrument"  # the file, over the default
    assert p.camera.focal_length == 25.0 and p.origin("camera", "focal_length").endswith("c_mount_25mm.yaml:7")
    assert p.camera.lens_length == 31.0 and p.origin("camera", "lens_length") == "mid.yaml:5"  # the lens file gives none
    assert p.projector.resolution == (1024, 768)  # nothing of the projector changed on the way
    # a lens file named further up the chain than a key a nearer file sets loses to that key
    _write(tmp_path, "child2", "extends: mid\ncamera:\n  lens: c_mount_25mm\n  focal_length: 24.5 mm\n")
    assert load_profile(tmp_path / "child2.yaml").camera.focal_length == 24.5


def test_profile_show_says_where_each_value_in_force_came_from(technician, capsys):
    import argparse

    from rigcad.cli.profile import cmd_show

    assert cmd_show(argparse.Namespace(profile="tech.yaml", json=True)) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["parameters"]["projector"]["resolution"] == [1280, 800]
    assert out["origins"]["projector"]["resolution"] == {
        "set_by": "instrument", "where": "profiles/instruments/epson_eb_w52.yaml:4",
        "source": "WXGA, the format Epson sells it as (product page not found by the stored-page search)"}
    assert out["origins"]["camera"]["resolution"]["where"].endswith("basler_ace_u_aca2040_55uc.yaml:6")
    assert out["origins"]["projector"]["throw_ratio"] == {"set_by": "profile", "where": "tech.yaml:5"}
    assert cmd_show(argparse.Namespace(profile="tech.yaml", json=False)) == 0
    text = capsys.readouterr().out
    rows = text.splitlines()
    row = next(r for r in rows[rows.index("[projector]"):] if r.split()[:1] == ["resolution"])
    assert "[1280, 800]" in row and "profiles/instruments/epson_eb_w52.yaml:4" in row


def test_a_swept_key_is_the_profiles_own_and_the_rest_keeps_its_precedence(tmp_path, monkeypatch):
    """rigcad sweep's --set value is the profile's own (over any file); the other keys keep theirs."""
    from rigcad.tolerance.sweep import parse_set, profile_with

    monkeypatch.chdir(tmp_path)
    _write(tmp_path, "base", "extends: achutha2006\ncamera:\n  body_width: 40 mm\n")
    raw = load_raw(_write(tmp_path, "tech", TECHNICIAN.replace("achutha2006", "base")))
    assert load_profile(tmp_path / "tech.yaml").camera.body_width == 29.0  # the Basler's, over the base's 40 mm
    p = profile_with(raw, parse_set("camera.body_width=20mm..30mm:2"), 20.0)
    assert p.camera.body_width == 20.0 and p.origin("camera", "body_width") == "--set camera.body_width"
    assert p.projector.resolution == (1280, 800)  # still the Epson's, not the base's


def test_a_figure_inherited_with_another_model_is_refused(tmp_path, monkeypatch):
    """A profile that extends the thesis's and names another projector would inherit the BenQ's throw
    ratio (set beside benq_pb6210 in achutha2006.yaml): refused in one line naming the key, the file:line
    it came from, the model it was set with, and the two ways out. Restating the same model is no change
    of projector and is not refused."""
    from rigcad.errors import ProfileError

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ProfileError) as info:
        load_profile(_write(tmp_path, "short", "extends: achutha2006\nprojector:\n  model: benq_mw632st\n"))
    text = str(info.value)
    assert "\n" not in text, text
    for part in ("projector.throw_ratio", "profiles/achutha2006.yaml:23", "'benq_pb6210'", "'benq_mw632st'",
                 "short.yaml:3", "set projector.throw_ratio in this profile", "name a projector file that gives it"):
        assert part in text, (part, text)
    same = load_profile(_write(tmp_path, "same", "extends: achutha2006\nprojector:\n  model: benq_pb6210\n"))
    assert same.projector.throw_ratio == 1.75
