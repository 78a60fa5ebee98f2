"""A newcomer's printer file: every problem reported at once (each with its file:line, in the file's
order), a printer the installed PrusaSlicer has no presets for named as such with the nearest ones it
has and what to do, and another printer's presets refused unless the file says they stand in."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from rigcad.errors import ProfileError
from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer, model_matches

from .test_vendor import needs_bundle

#: A newer printer than the installed bundle knows (PrusaSlicer 2.5's PrusaResearch 1.5.1 has no MK4),
#: with two slips of its own: a misspelt key and a bare layer height.
MK4 = """\
description: Original Prusa MK4, PLA
process: fdm
build_volume: {x: 250 mm, y: 210 mm, z: 220 mm}
layer_hieght: 0.15 mm
layer_height: 0.15
nozzle: 0.4 mm
filament_diameter: 1.75 mm
slicer:
  vendor_bundle: PrusaResearch
  printer_preset: Original Prusa MK4
  print_preset: 0.15mm QUALITY @MK4
  filament_preset: Prusament PLA
"""


@needs_bundle
def test_every_problem_of_a_printer_file_is_reported_at_once(tmp_path):
    path = tmp_path / "mk4.yaml"
    path.write_text(MK4)
    with pytest.raises(V.Problems) as err:
        load_printer(path)
    problems = err.value.problems
    lines = [int(str(p).split(":")[1]) for p in problems]
    # the misspelt key (4), the bare number (5), the printer preset (10), the print preset (11)
    assert lines == [4, 5, 10, 11], [str(p) for p in problems]
    assert lines == sorted(lines)  # in the file's order
    text = str(err.value)
    assert text.startswith(f"printer file {path}: 4 problems") or "4 problems" in text.split(":", 2)[1], text
    assert "did you mean 'layer_height'" in text and "printer_preset 'Original Prusa MK4'" in text


@needs_bundle
def test_a_printer_the_installed_slicer_lacks_is_named_with_the_nearest_and_what_to_do(tmp_path):
    path = tmp_path / "mk4.yaml"
    path.write_text(MK4.replace("layer_hieght: 0.15 mm\n", "").replace("layer_height: 0.15\n", "")
                    .replace("0.15mm QUALITY @MK4", "0.15mm QUALITY @MK3"))
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert "is not in the installed PrusaSlicer's bundle" in msg and "no presets for that printer" in msg, msg
    near = re.search(r"the nearest it has: (.*?) \(all:", msg).group(1)
    assert "'Original Prusa i3 MK3'" in near and "SL1" not in near, near  # FFF printers only: no resin printer
    assert "Export Config" in msg and "slicer.vendor_bundle" in msg and "stand_in" in msg


def _mk3s_as(tmp_path, extra: str):
    from rigcad.profile.paths import search_path

    shipped = next(d / "printers" / "prusa_mk3s.yaml" for d in search_path()
                   if (d / "printers" / "prusa_mk3s.yaml").is_file())
    text = re.sub(r"(?m)^model: .*\n", "", shipped.read_text())
    path = tmp_path / "mk4_as_mk3s.yaml"
    path.write_text(text + extra)
    return path


@needs_bundle
def test_another_printers_presets_are_refused_unless_the_file_says_they_stand_in(tmp_path):
    path = _mk3s_as(tmp_path, "model: Original Prusa MK4\n")
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert f"{path.name}:{len(path.read_text().splitlines())}" in msg, msg  # the model line
    assert "printer_model MK3S" in msg and "stand_in" in msg
    path = _mk3s_as(tmp_path, "model: Original Prusa MK4\nstand_in: the MK4 runs MK3S G-code in its MK3 mode\n")
    printer = load_printer(path)
    assert printer.model == "Original Prusa MK4" and printer.stand_in.startswith("the MK4")
    assert printer.describe()["stand_in"] == printer.stand_in  # fab.json says so
    assert load_printer("prusa_mk3s").model == "Original Prusa i3 MK3S+"  # the shipped file states its own


@pytest.mark.parametrize("model, model_id, name, same", [
    ("Original Prusa i3 MK3S+", "MK3S", "Original Prusa i3 MK3S && MK3S+", True),
    ("Original Prusa MK4", "MK3S", "Original Prusa i3 MK3S && MK3S+", False),
    ("Creality Ender-3 V2", "ENDER3V2", "Creality Ender-3 V2", True),
    ("Creality Ender-3", "ENDER3V2", "Creality Ender-3 V2", True),  # every word of the model in the name
    ("Creality Ender-3 S1", "ENDER3V2", "Creality Ender-3 V2", False),
    ("Original Prusa MINI+", "MINI", "Original Prusa MINI && MINI+", True),
    ("Bambu Lab X1 Carbon", "MK3S", "Original Prusa i3 MK3S && MK3S+", False),
])
def test_a_model_matches_its_presets_printer_model(model, model_id, name, same):
    assert model_matches(model, model_id, name) is same


def test_fab_refuses_the_printer_file_in_one_line_before_any_rig(tmp_path, monkeypatch):
    from rigcad.cli import main
    from rigcad.rig import Rig

    def no_rig(*args, **kwargs):
        raise AssertionError("a rig was built")

    monkeypatch.setattr(Rig, "from_profile", no_rig)
    path = tmp_path / "mk4.yaml"
    path.write_text(MK4)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["fab", "achutha2006", "--printer", str(path), "--exports", str(tmp_path / "x")])
    lines = err.getvalue().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("rigcad: error:"), lines
    assert "mk4.yaml:4" in lines[0] and "mk4.yaml:5" in lines[0]


def test_a_printer_named_without_its_nozzle_is_shown_its_presets():
    """Creality's presets are per nozzle: 'Creality Ender-3 V2' is no preset, but four start with it."""
    if "Creality" not in V.available_bundles():
        pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
    b = V.load_bundle(V.find_bundle("Creality"))
    with pytest.raises(ProfileError) as err:
        b.flatten("printer", "Creality Ender-3 V2")
    msg = str(err.value)
    assert "'Creality Ender-3 V2 (0.4 mm nozzle)'" in msg and "name the one for your nozzle" in msg, msg
    assert "no presets for that printer" not in msg  # it has them


def test_a_printer_preset_by_its_name_is_a_printer(monkeypatch):
    """`--printer "Creality Ender-3 V2 (0.4 mm nozzle)"`: the bundle's printer preset with its default
    print and filament presets; the bed and height from its bed_shape (5x0,215x0,215x220,5x220) and
    max_print_height (250), the layer, nozzle and material from the presets."""
    if "Creality" not in V.available_bundles():
        pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
    printer = load_printer("Creality Ender-3 V2 (0.4 mm nozzle)")
    assert printer.name == "creality_ender_3_v2_0_4_mm_nozzle"  # its fab folder's name
    assert printer.model == "Creality Ender-3 V2" and printer.slicer == "prusa-slicer"
    v = printer.build_volume
    assert (v.x, v.y, v.z) == (210.0, 220.0, 250.0)
    cfg = printer.slicer_config
    assert cfg.print_preset == "0.16 mm OPTIMAL (0.4 mm nozzle) @CREALITY" and cfg.filament_preset == "Generic PLA @CREALITY"
    assert printer.layer_height == 0.16 and printer.nozzle == 0.4 and "layer_height" in printer.from_preset
    assert cfg.effective()["printer_model"] == "ENDER3V2"

    def no_bundles(*args, **kwargs):
        raise AssertionError("a bundle was read for a printer file's name")

    monkeypatch.setattr(V, "available_bundles", no_bundles)
    assert load_printer("vantage_i").name == "vantage_i"  # a name without a space reads no bundle
    with pytest.raises(ProfileError, match="no printer 'nosuch'"):
        load_printer("nosuch")


GENERIC = ("process: fdm\nbuild_volume: {x: 256 mm, y: 256 mm, z: 256 mm}\nlayer_height: 0.2 mm\nnozzle: 0.4 mm\n"
           "filament_diameter: 1.75 mm\nmaterial_density_g_cm3: 1.24\nslicer: prusa-slicer\n")


def test_no_gcode_without_start_gcode_and_temperatures(tmp_path, monkeypatch):
    """A printer with no presets (an X1C written as `slicer: prusa-slicer`) would get G-code with a cold
    bed and no start code: `fab --gcode` refuses it in one line before any rig, and the slicing job
    carries the same refusal for a caller of the fab stage."""
    from rigcad.cli import main
    from rigcad.fab import slicer as S
    from rigcad.rig import Rig

    path = tmp_path / "x1c.yaml"
    path.write_text(GENERIC)

    def no_rig(*args, **kwargs):
        raise AssertionError("a rig was built")

    monkeypatch.setattr(Rig, "from_profile", no_rig)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["fab", "achutha2006", "--printer", str(path), "--gcode", "--exports", str(tmp_path / "x")])
    lines = err.getvalue().splitlines()
    assert code != 0 and len(lines) == 1 and "no start G-code" in lines[0] and "bed at 0 C" in lines[0], lines
    job = S.slice_job(load_printer(path), "cube", b"", False, (128.0, 128.0))
    assert job.problem and "no G-code is made" in job.problem
