"""The printer files' process errors: parsed with their units and sources, mistakes named by
file:line, and the calibration print's measurements turned into the figures."""

from __future__ import annotations

import pytest

from rigcad.errors import ProfileError
from rigcad.fab.printers import DEFAULT_PROCESS, load_printer
from rigcad.parts.process import from_measurements

BASE = ("process: fdm\nbuild_volume: {x: 200 mm, y: 200 mm, z: 200 mm}\nlayer_height: 0.2 mm\nnozzle: 0.4 mm\n"
        "material: PLA\nmaterial_density_g_cm3: 1.24\ndeposition_rate_mm3_s: 5\n")


def _printer(tmp_path, text: str, name: str = "p"):
    path = tmp_path / f"{name}.yaml"
    path.write_text(BASE + text)
    return load_printer(path)


def test_shipped_printers_state_their_process_with_a_source():
    mk3s = load_printer("prusa_mk3s").process_errors
    assert (mk3s.scale, mk3s.position) == (pytest.approx(0.002), pytest.approx(0.1016))  # 0.2 %, 0.004 in
    assert (mk3s.hole_shrink_vertical, mk3s.hole_shrink_horizontal) == (0.2, 0.3)
    assert mk3s.layer_step == 0.15 and "Xometry" in mk3s.source
    assert load_printer("vantage_i").process_errors.layer_step == pytest.approx(0.1778)  # 0.007 in
    assert load_printer("form3").process_errors.layer_step == 0.05  # the layer height, unstated


def test_a_file_without_the_section_gets_its_process_defaults(tmp_path):
    p = _printer(tmp_path, "").process_errors
    d = DEFAULT_PROCESS["fdm"]
    assert (p.scale, p.position, p.hole_shrink_vertical, p.hole_shrink_horizontal) == (
        d["scale"], d["position"], d["vertical"], d["horizontal"])
    assert p.layer_step == 0.2 and p.source == d["source"]


def test_stated_figures_are_read_with_their_units(tmp_path):
    p = _printer(tmp_path, "process_errors:\n  scale: 0.3 %\n  position: 4 mil\n  hole_shrink:\n"
                           "    vertical: 0.25 mm\n    per_mm: 1 %\n  source: our measurements\n  layer_step: 4 mil\n").process_errors
    assert p.scale == pytest.approx(0.003) and p.position == pytest.approx(0.1016)
    assert p.hole_shrink_vertical == 0.25 and p.hole_shrink_per_mm == pytest.approx(0.01)
    assert p.hole_shrink_horizontal == DEFAULT_PROCESS["fdm"]["horizontal"]
    assert p.shrink(10.0, "vertical") == pytest.approx(0.35) and p.source == "our measurements"
    assert p.layer_step == pytest.approx(0.1016) and p.height_error(100.0) == pytest.approx(0.0508 + 0.3)


@pytest.mark.parametrize("text, line, words", [
    ("process_errors:\n  scale: 0.3\n", 9, "percentage"),  # a bare number: 0.3 % or 30 %?
    ("process_errors:\n  scale: 30 %\n", 9, "outside"),
    ("process_errors:\n  position: 0.1\n", 9, "position"),
    ("process_errors:\n  hole_shrink:\n    vertcal: 0.2 mm\n", 10, "vertical"),
    ("process_errors:\n  scael: 0.2 %\n", 9, "scale"),
    ("process_errors:\n  measured:\n    lengths: [[100 mm, 99.8 mm]]\n    holes_vertical: [[3 mm, 2.8 mm]]\n"
     "    holes_horizontal: [[3 mm, 2.7 mm]]\n", 9, "two bars"),
    ("process_errors:\n  measured:\n    lengths: [[20 mm, 19.9 mm], [100 mm, 99.8 mm]]\n"
     "    holes_vertical: [[3 mm, 2.8 mm]]\n", 9, "holes_horizontal"),
    ("process_errors:\n  measured:\n    lengths: [[20 mm, 2 mm], [100 mm, 99.8 mm]]\n    holes_vertical: [[3 mm, "
     "2.8 mm]]\n    holes_horizontal: [[3 mm, 2.7 mm]]\n", 9, "20 %"),
])
def test_mistakes_name_the_file_line_and_what_is_valid(tmp_path, text, line, words):
    with pytest.raises(ProfileError) as err:
        _printer(tmp_path, text, "bad")
    assert f"bad.yaml:{line}" in str(err.value) and words in str(err.value)
    assert "\n" not in str(err.value)


def test_the_calibration_print_gives_back_the_process_it_was_printed_with():
    # bars and holes "printed" by a known process: scale 0.25 %, a 0.04 mm offset of each end, holes
    # shrinking 0.18 mm (vertical) and 0.31 mm (horizontal) plus 0.5 % of their diameter
    scale, end, per_mm = -0.0025, 0.04, 0.005
    lengths = [(n, n * (1 + scale) + 2 * end) for n in (20.0, 50.0, 100.0)]
    holes_v = [(d, d - 0.18 - per_mm * d) for d in (2.0, 4.0, 8.0)]
    holes_h = [(d, d - 0.31 - per_mm * d) for d in (2.0, 4.0, 8.0)]
    p = from_measurements(lengths, holes_v, holes_h, layer_step=0.15)
    assert p.scale == pytest.approx(0.0025, abs=1e-12)
    assert p.position == pytest.approx(end, abs=1e-12)  # half the intercept: each end; no scatter
    assert p.hole_shrink_per_mm == pytest.approx(per_mm, abs=1e-12)
    assert p.hole_shrink_vertical == pytest.approx(0.18, abs=1e-12)
    assert p.hole_shrink_horizontal == pytest.approx(0.31, abs=1e-12)
    # every measured hole is covered by the fitted worst case, also with scatter
    holes_v[1] = (4.0, 4.0 - 0.25 - per_mm * 4.0)
    q = from_measurements(lengths, holes_v, holes_h, layer_step=0.15)
    assert all(n - m <= q.shrink(n, "vertical") + 1e-12 for n, m in holes_v)


def test_a_measured_section_replaces_the_stated_figures(tmp_path):
    p = _printer(tmp_path, "process_errors:\n  measured:\n    lengths: [[20 mm, 19.95 mm], [100 mm, 99.75 mm]]\n"
                           "    holes_vertical: [[3 mm, 2.8 mm]]\n    holes_horizontal: [[3 mm, 2.6 mm]]\n")
    pe = p.process_errors
    assert pe.scale == pytest.approx(0.0025) and pe.position == pytest.approx(0.0, abs=1e-12)
    assert (pe.hole_shrink_vertical, pe.hole_shrink_horizontal) == (pytest.approx(0.2), pytest.approx(0.4))
    assert "calibration print" in pe.source


@pytest.mark.parametrize("text", [
    "process_errors: 5\n", "process_errors: [1, 2]\n", "process_errors:\n  scale: '\uff11 %'\n",
    "process_errors:\n  scale: 1e400 %\n", "process_errors:\n  scale: nan %\n", "process_errors:\n  scale: [1]\n",
    "process_errors:\n  scale: -0.2 %\n", "process_errors:\n  scale: true\n", "process_errors:\n  position: inf mm\n",
    "process_errors:\n  position: .nan\n", "process_errors:\n  position: 3 mm\n", "process_errors:\n  hole_shrink: 0.2 mm\n",
    "process_errors:\n  hole_shrink:\n    per_mm: 0.01\n", "process_errors:\n  source: ''\n",
    "process_errors:\n  source: [a]\n", "process_errors:\n  layer_step: -1 mm\n",
    "process_errors:\n  measured: yes\n", "process_errors:\n  measured:\n    lengths: x\n",
    "process_errors:\n  measured:\n    lengths: [[1 mm]]\n", "process_errors:\n  measured:\n    lengths: [[1 mm, 2 mm, 3 mm]]\n",
    "process_errors:\n  measured:\n    lengths: [[a, b]]\n", "process_errors:\n  measured:\n    lengths: [[0 mm, 1 mm]]\n",
    "process_errors:\n  measured:\n    lengths: [[20 mm, 20 mm], [20 mm, 20.1 mm]]\n    holes_vertical: [[3 mm, 2.8 mm]]\n"
    "    holes_horizontal: [[3 mm, 2.7 mm]]\n",
    "process_errors:\n  measured:\n    lenghts: []\n",
])
def test_hostile_process_errors_are_refused_in_one_line(tmp_path, text):
    with pytest.raises(ProfileError) as err:
        _printer(tmp_path, text, "hostile")
    msg = str(err.value)
    assert "hostile.yaml" in msg and "\n" not in msg and "Traceback" not in msg


def test_the_calibration_prints_nominal_sizes_fit_back(tmp_path):
    from rigcad.parts.process import CalibrationPrint

    cal = CalibrationPrint()
    assert len(set(cal.bars)) >= 2 and cal.holes  # enough to tell scale from position
    # fill the manual's template as a lab would, from a process with 0.3 % scale and 0.25 / 0.35 mm shrink
    text = cal.yaml_template()
    for b in cal.bars:
        text = text.replace(f"[{b:g} mm, ]", f"[{b:g} mm, {b * 0.997:.4f} mm]", 1)
    wall = text.index("holes_horizontal")
    head, tail = text[:wall], text[wall:]
    for h in cal.holes:
        head = head.replace(f"[{h:g} mm, ]", f"[{h:g} mm, {h - 0.25:.4f} mm]", 1)
        tail = tail.replace(f"[{h:g} mm, ]", f"[{h:g} mm, {h - 0.35:.4f} mm]", 1)
    p = _printer(tmp_path, head + tail).process_errors
    assert p.scale == pytest.approx(0.003, abs=1e-6) and p.position == pytest.approx(0.0, abs=1e-4)
    assert (p.hole_shrink_vertical, p.hole_shrink_horizontal) == (pytest.approx(0.25), pytest.approx(0.35))
    assert len(cal.steps()) == 4 and all("\n" not in s for s in cal.steps())
