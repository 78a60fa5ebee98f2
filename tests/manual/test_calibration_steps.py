"""Section 6's calibration steps as rigcad.manual.calibration writes them: the measured circle is
recorded where ``rigcad basis`` and ``rigcad calibrate --gray-card-kit`` read it, in the format they
read; the gray card's placement is one physically consistent procedure; the instruments are focused
and locked."""

from __future__ import annotations

import json
import math
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
    assert round(bought["image_radius_px"]) == 297 and round(model["image_radius_px"]) == 134
    text = C.checker_text(corr)
    assert "seen in it through the mirrors" not in text and "unbroken" not in text
    for lens_ in corr["lenses"]:
        assert f"the design's radius **{lens_['image_radius_px']:.1f} px**" in text
        assert f"within **{lens_['centre_tolerance_px']:.1f} px**" in text
    assert f"{inner:.1f} mm (the paraboloid's shadow) to {outer:.1f} mm from O" in text


def test_the_projector_is_focused_at_the_distance_the_lens_images_onto_the_paraboloid(table31_rig):
    from rigcad.optics.focus import focusing_lens

    g, s = table31_rig.geometry, table31_rig.profile.lens.distance
    f = C.projector_focus(table31_rig)
    lens = focusing_lens(table31_rig.profile, g)
    # thin lens (1/u = 1/f + 1/(D - s)): the card's distance D lands between the vertex and the rim
    u = 1.0 / (1.0 / lens.focal_length + 1.0 / (f["focus_mm"] - s))
    vertex, rim = g.cop_z - g.vertex_z - s, math.hypot(g.rim_radius, g.cop_z - g.rim_z) - s
    assert vertex < u < rim, (vertex, u, rim)
    # midway in dioptres: the vertex and the rim equally out of focus
    assert 1 / f["focus_near_mm"] - 1 / f["focus_mm"] == pytest.approx(1 / f["focus_mm"] - 1 / f["focus_far_mm"])
    assert (round(f["focus_near_mm"] / 1e3, 2), round(f["focus_far_mm"] / 1e3, 2)) == (1.36, 2.53)  # rig-mechanics.md
    text = C.projector_focus_text(table31_rig)
    assert f"**{f['from_front_mm'] / 1e3:.2f} m** from the lens barrel's front" in text and "focusing lens out" in text


def test_the_instruments_are_locked_to_the_torque_tables_torque_and_the_camera_focused_once(table31_rig):
    from rigcad.fab.loads import bolt_loads
    from rigcad.fab.printers import load_printer

    printer = load_printer("prusa_mk3s")
    rows = {b.joint: b for b in bolt_loads(table31_rig.profile, table31_rig.layout, printer)}
    lock = C.projector_lock(table31_rig, printer)
    cam = C.camera_focus_and_lock(table31_rig, printer)
    pj, cm = rows["projector on the shelf's slots"], rows["camera on its bracket's slot"]
    assert f"its {pj.count} {pj.thread} screws" in lock and f"**{pj.torque_nm:.2f} N m**" in lock
    assert f"its {cm.count} {cm.thread} screws" in cam and f"**{cm.torque_nm:.2f} N m**" in cam
    assert "still coincide" in lock and "still overlap" in cam  # the alignment checked after tightening
    # one camera focus rule: the hung cross, kept; the deflectometry page no longer refocuses it
    assert "on the hung cross" in cam and "tape the focus ring" in cam
    from rigcad.calibrate.kit import manual_page

    page = manual_page(table31_rig)
    assert "Focus between" not in page and "section 6 set it, on the hung cross" in page


def test_the_cop_heights_effect_on_the_circle_by_finite_differences(table31_rig):
    _, info = C.circle_image(table31_rig)
    assert C.circle_radius_px(table31_rig) == pytest.approx(info["radius_px"], rel=1e-12)  # the design's circle
    h = C.cop_height_check(table31_rig)
    step = 0.01  # mm: central difference of the function the closed form differentiates
    fd = (C.circle_radius_px(table31_rig, step) - C.circle_radius_px(table31_rig, -step)) / (2 * step)
    assert h["radius_px_per_mm"] == pytest.approx(fd, rel=1e-4), (h["radius_px_per_mm"], fd)
    # the lens nearly cancels it: far under the pixel the page reads, so the text says the circle cannot check it
    assert abs(h["tolerance_px"]) < 0.1 * C.EDGE_READ_PX
    text = C.shared_cop_text(table31_rig, __import__("rigcad.fab.printers", fromlist=["x"]).load_printer("prusa_mk3s"))
    assert "the circle cannot check" in text and f"{h['mm_per_px_read']:.0f} mm" in text


def test_the_projector_is_referenced_to_the_dome_axis_through_the_cameras_cop(table31_rig):
    g, t = table31_rig.geometry, table31_rig.profile.tolerancing
    c = C.shared_cop(table31_rig)
    # ray geometry: a COP d across the axis at height Z, through the hung cross's centre (0, z_h), to z = 0
    d, Z, zh = 0.37, g.cop_z, g.vertex_z
    x0 = d + (0.0 - d) * Z / (Z - zh)  # where the shadow of the hung cross's centre lands
    assert abs(x0) == pytest.approx(c["shadow_mm_per_mm"] * d, rel=1e-12)
    # the camera at the design COP (on the axis) sees that point at atan(|x0| / Z) from the hung cross's centre
    assert c["camera_px_per_mm"] * d == pytest.approx(c["camera_focal_px"] * abs(x0) / Z, rel=1e-12)
    assert c["tolerance_px"] == pytest.approx(max(c["camera_px_per_mm"] * t.projector_offset, C.EDGE_READ_PX))
    from rigcad.fab.printers import load_printer

    text = C.shared_cop_text(table31_rig, load_printer("prusa_mk3s"))
    assert f"within **{c['tolerance_px']:.1f} px**" in text and "dome's axis" in text


def test_the_calibration_circle_is_drawn_about_the_lens_axis_pixel(write_profile):
    import io

    import numpy as np
    from PIL import Image

    from rigcad.profile import load_profile
    from rigcad.profile.derived import projector_principal_point
    from rigcad.rig import Rig

    rig = Rig.from_profile(load_profile(write_profile("extends: achutha2006\nprojector: {lens_offset: 30 %}\n", "o")))
    png, info = C.circle_image(rig)
    cx, cy = projector_principal_point(rig.profile.projector)
    assert (cx, cy) == pytest.approx((512.0, 384 * 1.3)) and info["centre_px_from_top_left"] == [cx, cy]
    rows, cols = np.nonzero(np.asarray(Image.open(io.BytesIO(png))))
    assert cols.mean() + 0.5 == pytest.approx(cx, abs=0.05) and rows.mean() + 0.5 == pytest.approx(cy, abs=0.05)
    assert f'"cy": {json.dumps(cy)}'.encode() in C.circle_page(rig, info)  # the page's design circle, its 0 key, the same


@pytest.mark.e2e
def test_section_6_of_the_written_manual_carries_each_step_in_order(table31_rig, tmp_path):
    """The manual as written (section 6 of manual.md) holds each of these paragraphs, in the order a lab
    does them: a paragraph dropped from rigcad.manual.document fails here."""
    from rigcad.fab.printers import load_printer
    from rigcad.manual.document import gray_card_seat, write_manual

    printer = load_printer("prusa_mk3s")
    fab = table31_rig.fab("prusa_mk3s", tmp_path / "fab", parts=["base_plate"]).report
    write_manual(table31_rig, printer, fab, tmp_path / "manual")
    md = (tmp_path / "manual" / "manual.md").read_text(encoding="utf-8")
    _, info = C.circle_image(table31_rig)
    paragraphs = [C.projector_lock(table31_rig, printer), C.projector_focus_text(table31_rig),
                  C.record_circle(table31_rig, info), C.camera_focus_and_lock(table31_rig, printer),
                  C.shared_cop_text(table31_rig, printer), C.checker_text(C.camera_correspondence(table31_rig)),
                  C.gray_card_placement(table31_rig, gray_card_seat(table31_rig))]
    at = [md.find(p[:120]) for p in paragraphs]
    assert all(i >= 0 for i in at), [p[:60] for p, i in zip(paragraphs, at) if i < 0]
    assert at == sorted(at), at
