"""The calibration screen lies inside the dome, on a spacer at the sample: its display's corners must
clear the dome's inside at the heights each spacer puts it (rigcad.calibrate.kit.screen_room), or
the command refuses the profile before any work, naming the screen's key and its line."""

import math

import numpy as np
import pytest

from rigcad.calibrate.kit import check_screen_fits, screen_room
from rigcad.cli import main
from rigcad.errors import ProfileError
from rigcad.profile.schema import load_profile
from rigcad.rig import Rig


def _rig(tmp_path, pitch_mm: float, resolution=(2560, 1600), spacers="[1 mm, 20 mm]"):
    path = tmp_path / "p.yaml"
    path.write_text(f"extends: achutha2006\ncalibration:\n  screen_pitch: {pitch_mm!r} mm\n"
                    f"  screen_resolution: [{resolution[0]}, {resolution[1]}]\n  spacer_heights: {spacers}\n")
    return path, Rig.from_profile(load_profile(path))


def test_the_default_tablet_lies_inside_the_dome_where_it_starts(table31_rig):
    room = check_screen_fits(table31_rig)
    # 2266 x 1488 px at 0.0779 mm: an 8.3-inch display, its half diagonal by hand
    assert room["display_mm"] == pytest.approx([176.5214, 115.9152], abs=1e-9)
    assert room["half_diagonal_mm"] == pytest.approx(math.hypot(176.5214, 115.9152) / 2, rel=1e-12)
    # the lower spacer (1 mm) under a 1 mm sample's seat puts the screen's back on the sample plane,
    # where the dome starts (its first row, z = 0) and is narrowest
    r0, z0 = table31_rig.dome.points[0]
    assert z0 == 0.0 and room["tightest"] == {"spacer": 0, "z_mm": 0.0, "dome_radius_mm": pytest.approx(r0, abs=1e-12)}
    assert room["body_diameter_mm"] == pytest.approx(2 * r0, abs=1e-12) and room["fits"]


def test_a_ten_inch_tablet_is_refused_naming_the_screen_and_its_line(tmp_path):
    path, rig = _rig(tmp_path, 0.085)
    with pytest.raises(ProfileError) as e:
        check_screen_fits(rig)
    r0 = float(rig.dome.points[0][0])
    assert e.value.message == (
        "calibration.screen_resolution 2560 x 1600 px at calibration.screen_pitch 0.085 mm is a 217.6 x 136.0 mm "
        f"display whose corners lie {math.hypot(217.6, 136.0) / 2:.1f} mm from the axis, but the dome's inside is "
        f"{r0:.1f} mm from the axis at z = 0.0 mm, where spacer 0 (1 mm) puts the screen: choose a screen whose "
        f"display diagonal (and body) is under {2 * r0:.0f} mm")
    assert e.value.where.endswith("p.yaml:4")  # calibration.screen_resolution's line


def test_the_bound_is_the_dome_radius_to_a_micrometre(tmp_path):
    """A display whose corners reach the dome's radius less or more 1 um: in, then out."""
    r0 = float(Rig.from_profile(load_profile("achutha2006")).dome.points[0][0])
    for delta, fits in ((-1e-3, True), (1e-3, False)):
        pitch = 2 * (r0 + delta) / math.hypot(2560, 1600)
        assert screen_room(_rig(tmp_path, pitch)[1])["fits"] is fits


def test_a_screen_higher_up_meets_the_dome_where_it_is_wider(tmp_path):
    """Spacers of 20 and 40 mm: the lower screen spans z = 19..25 mm (6 mm thick, on a 1 mm sample's
    seat); the dome widens upward there, so its narrowest is at the screen's back, z = 19 mm."""
    _, rig = _rig(tmp_path, 0.0779, (2266, 1488), "[20 mm, 40 mm]")
    room = screen_room(rig)
    pts = rig.dome.points
    i = np.searchsorted(pts[:, 1], 19.0)  # the rows on either side of z = 19 mm, interpolated by hand
    (ra, za), (rb, zb) = pts[i - 1], pts[i]
    assert room["tightest"]["spacer"] == 0 and room["tightest"]["z_mm"] == pytest.approx(19.0, abs=1e-12)
    assert room["tightest"]["dome_radius_mm"] == pytest.approx(ra + (rb - ra) * (19.0 - za) / (zb - za), abs=1e-9)
    assert room["tightest"]["dome_radius_mm"] > float(pts[0][0])  # wider than at the sample plane


def test_the_command_refuses_it_in_one_line_and_writes_nothing(tmp_path, capsys):
    path, _ = _rig(tmp_path, 0.085)
    out = tmp_path / "exports"
    assert main(["calibrate", str(path), "--kit", "--exports", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "p.yaml:4" in err and "calibration.screen_resolution" in err
    assert not (out / "p").exists()


def test_the_manual_page_gives_the_circle_the_screen_must_fit(table31_rig):
    from rigcad.calibrate.kit import manual_page

    room = screen_room(table31_rig)
    page = manual_page(table31_rig)
    assert f"must fit in a\n  {room['body_diameter_mm']:.0f} mm circle" in page
