"""Section 6's calibration steps as rigcad.manual.calibration writes them: the measured circle is
recorded where ``rigcad basis`` and ``rigcad calibrate --gray-card-kit`` read it, in the format they
read; the gray card's placement is one physically consistent procedure; the instruments are focused
and locked."""

from __future__ import annotations

import json
import re

import pytest

from rigcad.manual import calibration as C


def test_the_recorded_circle_is_in_the_format_and_place_basis_reads(table31_rig, tmp_path):
    from rigcad.basis.measured import CIRCLE_JSON, load_measured

    _, info = C.circle_image(table31_rig)
    text = C.record_circle(table31_rig, info)
    assert f"`exports/achutha2006/{CIRCLE_JSON}`" in text
    assert "`rigcad basis achutha2006`" in text and "`rigcad calibrate achutha2006 --gray-card-kit`" in text
    template = re.search(r"`(\{.*?\})`", text).group(1)
    path = tmp_path / "achutha2006" / CIRCLE_JSON
    path.parent.mkdir(parents=True)
    path.write_text(template.replace("CX", "515").replace("CY", "380").replace("R", "109"))
    circle = load_measured(table31_rig, tmp_path).circle  # what rigcad basis reads, found beside
    assert (circle.centre_px, circle.radius_px) == ((515.0, 380.0), 109.0)
    assert json.loads(path.read_text())["resolution_px"] == list(table31_rig.profile.projector.resolution)


def test_the_gray_card_is_checked_flush_only_while_the_plate_top_is_bare(table31_rig):
    from rigcad.manual.document import gray_card_seat

    text = C.gray_card_placement(table31_rig, gray_card_seat(table31_rig))
    lift, check = text.index("lift it off its register pins"), text.index("steel straightedge across the bore")
    back, below = text.index("Set the dome back on its pins"), text.index("out of the bore")
    # the straightedge lies on the plate's top: only between the dome coming off and going back on
    assert lift < check < back, text
    # from below (through the bore) only once the card's height is checked and the dome is back on
    assert back < below and "from below" not in text[:back] and "dome on" in text[back:], text
    assert f"{len(table31_rig.layout.bolt_angles)} flange screws" in text
    rows = {r["item"]: r for r in C.access(table31_rig)}
    assert "the dome the first time" in rows["gray card and its foil"]["out_of_the_way"]


def test_the_checkerboard_is_judged_where_the_camera_sees_it_with_the_bills_lens_too(table31_rig):
    from rigcad.manual.camera_lens import camera_lens

    g, lay = table31_rig.geometry, table31_rig.layout
    corr = C.camera_correspondence(table31_rig)
    inner, outer = corr["direct_ring_mm"]
    # the ring's outer edge: the line from the COP to it grazes the dome's top opening
    dome = lay.printed_dome
    top_r, top_z = dome.points(__import__("numpy").array([dome.u_range[1]]))[0]
    assert outer * (1 - top_z / g.cop_z) == pytest.approx(top_r, rel=1e-9)
    # the inner edge: the paraboloid's shadow, outside the bore's hole the disc is cut with
    assert inner == pytest.approx(C.film_shadows(table31_rig)["paraboloid_shadow_radius_mm"], rel=1e-12)
    assert C.checkerboard(table31_rig)["hole_diameter_mm"] / 2 < inner < outer
    model, bought = corr["lenses"]
    assert model["image_radius_px"] == pytest.approx(corr["image_radius_px"], rel=1e-12)
    assert model["ring_px"][0] == pytest.approx(model["image_radius_px"], rel=1e-12)  # the disc's edge is the ring's
    lens = camera_lens(table31_rig)  # the bill's line: its own figure of the paraboloid's image
    assert bought["image_radius_px"] == pytest.approx(lens["image_radius_px"], rel=1e-12)
    assert round(bought["image_radius_px"]) == 143 and round(model["image_radius_px"]) == 134
    text = C.checker_text(corr)
    assert "seen in it through the mirrors" not in text and "unbroken" not in text
    for lens_ in corr["lenses"]:
        assert f"the design's radius **{lens_['image_radius_px']:.1f} px**" in text
        assert f"within **{lens_['centre_tolerance_px']:.1f} px**" in text
    assert f"{inner:.1f} mm (the paraboloid's shadow) to {outer:.1f} mm from O" in text
