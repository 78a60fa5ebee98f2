"""The projector's entrance pupil, measured as a projector allows (rigcad.profile.instruments.projector_pupil):
the projected image's width at two walls, the lines through its edges crossing at the pupil. Checked on a
synthetic pinhole projector, against a finite-difference uncertainty, and in the measure-first table."""

from __future__ import annotations

import math

from rigcad.profile import instruments as I


def test_the_two_walls_recover_a_pinholes_pupil_and_its_stated_uncertainty(table31):
    t, p = 1.75, 37.0  # a pinhole projector: image width (d + p) / t at distance d from the barrel's front
    walls = I.PUPIL_WALLS_MM
    widths = [(d + p) / t for d in walls]
    assert abs(I.pupil_from_widths(walls, widths) - p) < 1e-9  # exact in exact arithmetic: rounding only
    m = I.projector_pupil(t, p)
    assert m["widths_mm"] == widths
    # each reading off by the read error, one at a time, by finite differences: their root sum of squares
    e = m["read_mm"]
    shifts = []
    for k in range(2):
        w = list(widths)
        w[k] += e
        shifts.append(I.pupil_from_widths(walls, w) - p)
        d = list(walls)
        d[k] += e
        shifts.append(I.pupil_from_widths(d, widths) - p)
    rss = math.sqrt(sum(s * s for s in shifts))
    # linear in the widths and nearly so in the distances (second order: e / (d2 - d1) = 1e-3 relative)
    assert abs(m["uncertainty_mm"] - rss) < 2e-3 * rss, (m["uncertainty_mm"], rss)


def test_the_projector_is_not_told_to_find_a_no_parallax_point(table31):
    rows = {m.key: m for m in I.measurements(table31)}
    proj, cam = rows["projector.pupil_depth"].between[1], rows["camera.pupil_depth"].between[1]
    assert "no-parallax" not in proj and "no-parallax" in cam  # sighting through: the camera's method only
    m = I.projector_pupil(table31.projector.throw_ratio, table31.projector.pupil_depth)
    assert f"±{m['uncertainty_mm']:.1f} mm" in proj and "(w1 d2 - w2 d1) / (w2 - w1)" in proj
    # the Table 3.1 projector: 4.5 mm, wider than its 1 mm height tolerance, and the text says so
    assert m["uncertainty_mm"] > table31.tolerancing.projector_height and "projector_height" in proj
