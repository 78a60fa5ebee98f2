"""The projector's lens offset and pixel shifting: the paraboloid's image is a disc about the pixel
on the projector's lens axis (below the image's centre by ``projector.lens_offset`` half heights), and
a projector whose image cannot hold that disc is refused in one line naming the key and the offset
that would pass; a 4K figure that is mostly a pixel-shifted one is refused with the native figure."""

import pytest

from rigcad.errors import GeometryError, ProfileError
from rigcad.profile import derive, load_profile
from rigcad.profile.derived import projector_disc_room, projector_principal_point


def _profile(write_profile, projector: str, name: str = "p"):
    return load_profile(write_profile(f"extends: achutha2006\nprojector: {{{projector}}}\n", name))


def test_principal_point_moves_down_by_the_offset_in_half_heights(write_profile):
    centred = _profile(write_profile, "lens_offset: 0").projector
    assert projector_principal_point(centred) == (512.0, 384.0)  # the 1024 x 768 image's centre
    full = _profile(write_profile, "lens_offset: 100 %", "full").projector  # percent as datasheets write it
    assert full.lens_offset == 1.0
    assert projector_principal_point(full) == (512.0, 768.0)  # the bottom edge: the datasheet's 100 %
    assert projector_disc_room(full) == 0.0
    part = _profile(write_profile, "lens_offset: 0.5", "part").projector
    assert projector_principal_point(part) == (512.0, 576.0)  # 384 + 0.5 x 384
    assert projector_disc_room(part) == 192.0  # 768 - 576 below it, the nearest edge


def test_full_offset_is_refused_naming_the_key_and_the_offset_that_fits(write_profile):
    with pytest.raises(GeometryError) as err:
        derive(_profile(write_profile, "lens_offset: 100 %"))
    msg = str(err.value)
    assert "projector.lens_offset" in msg and "row 768 of 768" in msg and "\n" not in msg, msg
    assert "p.yaml:2" in msg, msg  # the file:line that set the offset
    # the offset it names as the largest that fits holds the disc, and 1 % more does not
    best = float(msg.split("at most ")[1].split("%")[0]) / 100
    radius = derive(_profile(write_profile, "lens_offset: 0", "c")).pixels_vertex_to_rim
    assert radius == pytest.approx(768 / 2 * (1 - best), abs=768 / 2 * 0.005)  # rounded to 1 % in the message
    derive(_profile(write_profile, f"lens_offset: {best - 0.005}", "ok"))
    with pytest.raises(GeometryError):
        derive(_profile(write_profile, f"lens_offset: {best + 0.01}", "over"))


def test_an_offset_the_image_holds_keeps_the_design(write_profile):
    """The offset moves which pixels light the paraboloid, not how many: the same focal length in
    pixels and the same disc, so the same pixels per degree."""
    a = derive(_profile(write_profile, "lens_offset: 0", "a"))
    b = derive(_profile(write_profile, "lens_offset: 30 %", "b"))
    assert (a.projector_focal_px, a.pixels_vertex_to_rim) == (b.projector_focal_px, b.pixels_vertex_to_rim)


def test_an_offset_image_too_small_for_the_disc_names_another_way(write_profile):
    # throw 7: f = 7168 px, the disc ~400 px in radius, more than the 384 px half height: no offset holds it
    with pytest.raises(GeometryError, match=r"projector.lens_offset 10%.*lens shift set to the centre"):
        derive(_profile(write_profile, "throw_ratio: 7, lens_offset: 0.1"))


def test_lens_offset_that_is_not_a_fraction_is_refused(write_profile):
    with pytest.raises(ProfileError, match=r"projector.lens_offset: expected a fraction such as 0.5 or 50 %"):
        _profile(write_profile, "lens_offset: half")
    with pytest.raises(ProfileError, match=r"projector.lens_offset: .* out of range; valid: 0 % to 200 %"):
        _profile(write_profile, "lens_offset: 250 %", "hi")


def test_a_4k_uhd_figure_is_refused_with_the_native_array(write_profile):
    with pytest.raises(ProfileError) as err:
        _profile(write_profile, "resolution: [3840, 2160], throw_ratio: 1.5")
    msg = str(err.value)
    assert "projector.resolution: [1920, 1080]" in msg and "projector.native_resolution" in msg, msg
    assert "p.yaml:2" in msg, msg
    # a true 4K panel says so, and is taken as it is
    p = _profile(write_profile, "resolution: [3840, 2160], native_resolution: [3840, 2160], throw_ratio: 1.5", "true")
    assert p.projector.resolution == (3840, 2160)
    # the native array named, the addressed figure entered: refused with the native figure to enter
    with pytest.raises(ProfileError, match=r"enter projector.resolution: \[1920, 1080\]"):
        _profile(write_profile, "resolution: [3840, 2160], native_resolution: [1920, 1080]", "xpr")
    assert _profile(write_profile, "resolution: [1920, 1080], native_resolution: [1920, 1080], throw_ratio: 1.5",
                    "native").projector.resolution == (1920, 1080)


def test_the_instruments_page_states_the_default_rigs_figures(write_profile):
    """docs/instruments.md's offset figures on the default rig come from the code: the disc's radius
    and the largest offset whose image holds it."""
    from pathlib import Path

    text = " ".join((Path(__file__).resolve().parents[2] / "docs" / "instruments.md").read_text().split())
    p = _profile(write_profile, "lens_offset: 0")
    radius, (w, h) = derive(p).pixels_vertex_to_rim, p.projector.resolution
    best = 1 - 2 * radius / h
    assert f"a disc {radius:.0f} px in radius on a {w} x {h} image) that is {best * 100:.0f} %" in text


def test_profile_show_states_the_axis_pixel_and_the_room(write_profile, capsys):
    from rigcad.cli import main

    path = write_profile("extends: achutha2006\nprojector: {lens_offset: 50 %}\n", "shown")
    assert main(["profile", "show", str(path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "projector_axis_pixel" in x)
    assert "[512, 576] px of 1024 x 768 (lens_offset 50%); room for a disc 192 px in radius" in line, line
