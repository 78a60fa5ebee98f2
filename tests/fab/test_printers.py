"""Printer profiles: the three shipped ones load with their units; mistakes name file:line."""

from __future__ import annotations

import pytest

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab.printers import available_printers, load_printer


def test_shipped_printers_load_in_mm():
    assert {"vantage_i", "prusa_mk3s", "form3"} <= set(available_printers())
    v = load_printer("vantage_i")
    # thesis 3.4: 0.007 in layers; exact unit conversion, so float rounding only
    assert abs(v.layer_height - 0.1778) < 1e-12
    assert abs(v.build_volume.x - 406.4) < 1e-9  # 16 in
    p = load_printer("prusa_mk3s")
    assert (p.build_volume.x, p.build_volume.y, p.build_volume.z) == (250.0, 210.0, 210.0)
    assert p.nozzle == 0.4 and p.slicer == "prusa-slicer"
    f = load_printer("form3")
    assert f.process == "sla" and abs(f.pixel - 0.085) < 1e-12


def test_bad_unit_names_file_line_key_and_valid_units(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("process: fdm\nbuild_volume: {x: 200 mm, y: 200 mm, z: 200 mm}\nlayer_height: 0.2\n"
                    "nozzle: 0.4 mm\nmaterial_density_g_cm3: 1.2\ndeposition_rate_mm3_s: 5\n")
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert "bad.yaml:3" in msg and "layer_height" in msg and "mm" in msg


def test_unknown_key_is_refused_with_a_suggestion(tmp_path):
    path = tmp_path / "typo.yaml"
    path.write_text("process: fdm\nbuild_volume: {x: 200 mm, y: 200 mm, z: 200 mm}\nlayer_hieght: 0.2 mm\n")
    with pytest.raises(ProfileError, match=r"typo.yaml:3.*layer_height"):
        load_printer(path)


def test_unknown_printer_lists_the_known_ones():
    with pytest.raises(ProfileError, match="prusa_mk3s"):
        load_printer("no_such_printer")


def test_the_generic_prusa_slicer_printer_still_loads(tmp_path):
    """`slicer: prusa-slicer` (no presets) keeps rigcad's generic configuration."""
    from rigcad.fab.slicer import printer_ini

    path = tmp_path / "generic.yaml"
    path.write_text("process: fdm\nbuild_volume: {x: 200 mm, y: 200 mm, z: 180 mm}\nlayer_height: 0.2 mm\n"
                    "nozzle: 0.4 mm\nfilament_diameter: 1.75 mm\nmaterial_density_g_cm3: 1.24\nslicer: prusa-slicer\n")
    p = load_printer(path)
    assert p.slicer == "prusa-slicer" and p.slicer_config is None and p.slicer_unavailable is None
    ini = printer_ini(p, support=True)
    assert "bed_shape = 0x0,200x0,200x200,0x200\n" in ini and "support_material = 1\n" in ini
    assert "start_gcode" not in ini  # PrusaSlicer's default start G-code: no presets, no vendor G-code
