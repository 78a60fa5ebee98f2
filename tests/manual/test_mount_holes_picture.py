"""The projector's mounting-hole figure (the manual's measure-first list): drawn to scale with a scale bar,
the holes' spacings dimensioned, and the shelf's slots around them at their size (rigcad.parts.tower's:
the thread's clearance hole plus the tower's travel each way)."""

from __future__ import annotations

import re

import pytest

from rigcad import plots
from rigcad.manual import document as D
from rigcad.profile.instruments import measurements, mount_pattern, sketch


def svg_texts(svg: bytes) -> list[str]:
    return re.findall(r"<text[^>]*>([^<]*)</text>", svg.decode("utf-8"))


@pytest.mark.parametrize("extent, bar", [(410.0, 100.0), (300.0, 50.0), (14.0, 2.0), (4.0, 1.0), (81.0, 20.0)])
def test_the_scale_bar_is_a_round_length_at_most_a_quarter_of_the_drawing(extent, bar):
    assert plots.scale_bar_length(extent) == bar


def _mount_holes(profile):
    (m,) = [m for m in measurements(profile) if m.key == "projector.mount_holes"]
    return sketch(profile, m)


def test_the_figure_dimensions_the_patterns_spacings_and_draws_the_shelfs_slots(table31):
    s = _mount_holes(table31)
    extra, dims, note = D.hole_pattern_marks(table31, s)
    holes = mount_pattern(table31.projector)
    along = max(a for a, _ in holes) - min(a for a, _ in holes)  # 215 - 40
    across = max(c for _, c in holes) - min(c for _, c in holes)  # 112 - -112
    assert (along, across) == (175.0, 224.0)
    assert sorted(label for *_, label in dims) == sorted([f"{along:g} mm", f"{across:g} mm"])
    for (x0, y0), (x1, y1), label in dims:  # each dimension's length is what its label says
        assert abs(((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5 - float(label.split()[0])) < 1e-9, label
    # one slot around each hole: the M4 clearance hole (4.5 mm, ISO 273 medium) + travel_along 2 mm and
    # travel_across 6 mm each way
    assert len(extra) == 4
    for (_, pts), (_, (cx, cy), _) in zip(extra, s.circles):
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]
        assert (max(xs) - min(xs), max(ys) - min(ys)) == pytest.approx((4.5 + 4.0, 4.5 + 12.0), abs=1e-9)
        assert (0.5 * (max(xs) + min(xs)), 0.5 * (max(ys) + min(ys))) == pytest.approx((cx, cy), abs=1e-9)
    assert "8.5 x 16.5 mm" in note and "scale bar" in note
    # the drawing states them: its text read back from the SVG
    texts = svg_texts(plots.measurement_figure(s, "what", extra, dims, fmt="svg"))
    assert "175 mm" in texts and "224 mm" in texts, texts
    bars = [t for t in texts if re.fullmatch(r"\d+ mm", t) and t not in ("175 mm", "224 mm")]
    assert bars and all(re.fullmatch(r"[125]0* mm", t) for t in bars), bars


def test_the_manual_draws_the_marks_and_every_measure_figure_has_a_scale_bar(table31):
    files: dict = {}
    captions = dict(D.measurement_figures(table31, files))
    path = "images/measure/projector_mount_holes.png"
    s = _mount_holes(table31)
    extra, dims, _ = D.hole_pattern_marks(table31, s)
    assert "the shelf's slots dashed blue" in captions[path]
    # planted back: the figure drawn without the marks is not the manual's
    (m,) = [m for m in measurements(table31) if m.key == "projector.mount_holes"]
    words = f"from: {m.between[0]}; to: {m.between[1]}"
    assert files[path] == plots.measurement_figure(s, words, extra, dims)
    assert files[path] != plots.measurement_figure(s, words)
    # every size's figure carries a scale bar (its label read back from the SVG)
    for m in measurements(table31):
        texts = svg_texts(plots.measurement_figure(sketch(table31, m), "w", fmt="svg"))
        assert any(re.fullmatch(r"[125]0* mm|0\.[125]0* mm", t) for t in texts), (m.key, texts)
