"""PrusaSlicer's vendor presets: the installed PrusaResearch bundle read and flattened as
PrusaSlicer does, and the printer file's slicer section validated with file:line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer

from .conftest import ROOT, have_slicer

MK3S = "Original Prusa i3 MK3S & MK3S+"
PRINT = "0.15mm QUALITY @MK3"
PLA = "Prusament PLA"
NO_BUNDLE = "PrusaSlicer's vendor bundles are not installed (apt-get install prusa-slicer); the project's CI installs it"


def have_bundle() -> bool:
    return "PrusaResearch" in V.available_bundles()


needs_bundle = pytest.mark.skipif(not have_bundle(), reason=NO_BUNDLE)
needs_slicer = pytest.mark.skipif(not (have_slicer() and have_bundle()), reason=NO_BUNDLE)


def printer_yaml(tmp_path: Path, slicer: str, drop: tuple[str, ...] = (), edit: dict[str, str] | None = None) -> Path:
    """The shipped MK3S printer file with its slicer section replaced (and keys dropped or edited)."""
    text = (ROOT / "profiles" / "printers" / "prusa_mk3s.yaml").read_text()
    head, _, tail = text.partition("slicer:\n")
    tail = tail[tail.index("alignment_pin:"):]
    lines = [ln for ln in head.splitlines() if not any(ln.startswith(k + ":") for k in drop)]
    for key, value in (edit or {}).items():
        lines = [f"{key}: {value}" if ln.startswith(key + ":") else ln for ln in lines]
    path = tmp_path / "mk3s.yaml"
    path.write_text("\n".join(lines) + "\n" + slicer + tail)
    return path


def slicer_section(printer=MK3S, print_=PRINT, filament=PLA, overrides: str = "") -> str:
    return (f"slicer:\n  vendor_bundle: PrusaResearch\n  printer_preset: {printer}\n  print_preset: {print_}\n"
            f"  filament_preset: {filament}\n" + (f"  overrides:\n{overrides}" if overrides else ""))


def line_of(path: Path, needle: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if needle in ln)


# -- the bundle ------------------------------------------------------------------------------------

@needs_bundle
def test_the_installed_bundle_flattens_the_mk3s_chain():
    path = V.find_bundle("PrusaResearch")
    b = V.load_bundle(path)
    assert b.vendor["name"] == "Prusa Research" and "MK3S" in b.printer_models()
    # MK3S & MK3S+ -> Original Prusa i3 MK3 -> *common*: each level contributes a key
    raw = V.read_ini(path).sections
    assert raw[f"printer:{MK3S}"]["inherits"] == "Original Prusa i3 MK3"
    printer = b.flatten("printer", MK3S)
    assert printer["printer_model"] == "MK3S"  # the preset's own key
    assert printer["max_print_height"] == "210"  # MK3's, overriding *common*'s 200
    assert raw["printer:*common*"]["max_print_height"] == "200"
    assert printer["printer_technology"] == "FFF" and printer["bed_shape"] == "0x0,250x0,250x210,0x210"  # *common*
    assert "inherits" not in printer
    start = printer["start_gcode"]
    # the vendor's start G-code: model check, mesh bed levelling (G80 on Prusa firmware), purge line
    assert 'M862.3 P \\"[printer_model]\\"' in start and "G80 ; mesh bed leveling" in start and "intro line" in start
    pla = b.flatten("filament", PLA)
    # from *PLA*; 0 would switch the bed heater off (the G-code had 0)
    assert int(pla["bed_temperature"]) > 0 and int(pla["first_layer_bed_temperature"]) > 0
    assert pla["temperature"] == "215" and pla["filament_density"] == "1.24"  # the preset's own keys
    assert pla["filament_type"] == "PLA"
    assert b.flatten("print", PRINT)["layer_height"] == "0.15"
    # abstract presets are building blocks, not choices
    assert "*common*" not in b.presets("printer") and "*common*" in b.presets("printer", abstract=True)


@needs_bundle
def test_a_bundle_is_parsed_once_per_process():
    path = V.find_bundle("PrusaResearch")
    assert V.load_bundle(path) is V.load_bundle(path)
    assert V.load_bundle(path).flatten("printer", MK3S) is not V.load_bundle(path).flatten("printer", MK3S)  # copies


def test_parents_apply_left_to_right_and_own_keys_win(tmp_path):
    ini = tmp_path / "Mini.ini"
    ini.write_text("[vendor]\nname = Mini\n\n[print:*a*]\nx = 1\ny = 1\n# a comment\n[print:*b;c*]\ny = 2\nz = 2\n"
                   "[print:child]\ninherits = *a*; \"*b;c*\"\nz = 3\n[print:grandchild]\ninherits = child\nw = 4\n")
    b = V.load_bundle(ini)
    assert b.flatten("print", "child") == {"x": "1", "y": "2", "z": "3"}  # *b;c* after *a*, own z last
    assert b.flatten("print", "grandchild") == {"x": "1", "y": "2", "z": "3", "w": "4"}
    assert V.split_inherits('a; "b; c" ;d') == ["a", "b; c", "d"]


def test_broken_inheritance_names_the_file_and_line(tmp_path):
    ini = tmp_path / "Loop.ini"
    ini.write_text("[print:a]\ninherits = b\n[print:b]\ninherits = a\n[print:c]\ninherits = nowhere\n")
    b = V.load_bundle(ini)
    with pytest.raises(FabricationError, match=r"Loop.ini:\d+.*inherits itself"):
        b.flatten("print", "a")
    with pytest.raises(FabricationError, match=r"Loop.ini:6.*unknown preset 'nowhere'"):
        b.flatten("print", "c")
    dup = tmp_path / "Dup.ini"
    dup.write_text("[print:a]\nx = 1\nx = 2\n")
    with pytest.raises(FabricationError, match=r"Dup.ini:3.*'x' is given twice"):
        V.read_ini(dup)


@needs_bundle
def test_a_misspelt_preset_gets_a_did_you_mean():
    b = V.load_bundle(V.find_bundle("PrusaResearch"))
    with pytest.raises(ProfileError, match=re.escape(f"did you mean {MK3S!r}")):
        b.flatten("printer", "Original Prusa i3 MK3S & MK3S", where="x.yaml:9")
    with pytest.raises(ProfileError, match=r"x.yaml:9.*'Prusament PLA'"):
        b.flatten("filament", "Prusament PLAA", where="x.yaml:9")
    with pytest.raises(ProfileError, match=re.escape(f"was renamed to {MK3S!r}")):
        b.flatten("printer", "Original Prusa i3 MK3S")
    with pytest.raises(ProfileError, match="abstract"):
        b.flatten("printer", "*common*")


def test_a_missing_bundle_says_where_rigcad_looked_and_how_to_install(tmp_path):
    with pytest.raises(FabricationError) as err:
        V.find_bundle("PrusaResearch", dirs=[tmp_path / "none", tmp_path])
    assert str(tmp_path) in str(err.value) and "apt-get" in str(err.value) and "prusa-slicer" in str(err.value)
    (tmp_path / "Other.ini").write_text("[vendor]\nname = Other\n")
    with pytest.raises(ProfileError, match=r"no bundle 'Othr' \(did you mean 'Other'\?\)"):
        V.find_bundle("Othr", dirs=[tmp_path])


@needs_bundle
def test_the_command_line_lists_presets(capsys):
    assert V.main(["PrusaResearch", "printer"]) == 0
    assert MK3S in capsys.readouterr().out.splitlines()
    assert V.main(["PrusaResearch", "print", PRINT]) == 0
    assert "layer_height = 0.15" in capsys.readouterr().out.splitlines()
    assert V.main(["PrusaResearch", "print", "0.15mm QUALTY @MK3"]) == ProfileError.exit_code
    assert "did you mean" in capsys.readouterr().err


def test_yaml_values_become_prusaslicer_text():
    assert V.ini_value(True) == "1" and V.ini_value(5) == "5" and V.ini_value(0.15) == "0.15"
    assert V.ini_value("20%") == "20%" and V.ini_value("G28\nG80") == "G28\\nG80"
    assert V.ini_value([215, 210]) == "215,210" and V.ini_value(["a", "b"]) == '"a";"b"'
    with pytest.raises(ProfileError, match="brim_width"):
        V.ini_value({"no": 1}, "brim_width")


# -- the printer file's slicer section --------------------------------------------------------------

@needs_bundle
def test_the_shipped_mk3s_resolves_its_presets():
    p = load_printer("prusa_mk3s")
    cfg = p.slicer_config
    assert cfg is not None and p.slicer == "prusa-slicer" and p.slicer_unavailable is None
    assert (cfg.printer_preset, cfg.print_preset, cfg.filament_preset) == (MK3S, PRINT, PLA)
    eff = cfg.effective()
    assert eff["printer_model"] == "MK3S" and eff["print_settings_id"] == PRINT
    assert eff["perimeters"] == "3" and eff["fill_density"] == "20%"  # the printer file's overrides
    assert "inherits" not in eff and "compatible_printers_condition" not in eff
    # rigcad's figures agree with the preset (checked at load): the staircase maths uses the layers PrusaSlicer prints
    assert p.layer_height == float(eff["layer_height"]) and p.nozzle == float(eff["nozzle_diameter"])
    assert p.describe()["slicer_presets"]["print_preset"] == PRINT


@needs_bundle
def test_figures_left_out_come_from_the_preset(tmp_path):
    drop = ("layer_height", "first_layer_height", "nozzle", "filament_diameter", "material", "material_density_g_cm3")
    p = load_printer(printer_yaml(tmp_path, slicer_section(print_="0.20mm QUALITY @MK3"), drop=drop))
    assert set(p.from_preset) == set(drop)
    assert (p.layer_height, p.first_layer_height, p.nozzle, p.filament_diameter) == (0.2, 0.2, 0.4, 1.75)
    assert p.material == "PLA" and p.material_density_g_cm3 == 1.24


@needs_bundle
def test_a_figure_that_disagrees_with_the_preset_is_refused(tmp_path):
    path = printer_yaml(tmp_path, slicer_section(), edit={"layer_height": "0.2 mm"})
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert f"mk3s.yaml:{line_of(path, 'layer_height: 0.2')}" in msg
    assert "layer_height" in msg and "0.2" in msg and "'0.15'" in msg and PRINT in msg
    path = printer_yaml(tmp_path, slicer_section(), edit={"  x": "240 mm"})
    with pytest.raises(ProfileError, match=r"mk3s.yaml:\d+: build_volume.x: 240 mm disagrees.*bed_shape"):
        load_printer(path)


@needs_bundle
def test_a_misspelt_preset_in_the_printer_file_names_its_line(tmp_path):
    path = printer_yaml(tmp_path, slicer_section(print_="0.15mm QUALTY @MK3"))
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    assert f"mk3s.yaml:{line_of(path, 'print_preset:')}" in str(err.value)
    assert f"did you mean {PRINT!r}" in str(err.value)


@needs_bundle
def test_an_unknown_override_names_the_key_its_line_and_a_suggestion(tmp_path):
    path = printer_yaml(tmp_path, slicer_section(overrides="    perimeters: 3\n    brim_widht: 5\n"))
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert f"mk3s.yaml:{line_of(path, 'brim_widht')}" in msg
    assert "'brim_widht'" in msg and "did you mean 'brim_width'" in msg
    path = printer_yaml(tmp_path, slicer_section(overrides="    inherits: x\n"))
    with pytest.raises(ProfileError, match="slicer.overrides.inherits: a bundle's bookkeeping key"):
        load_printer(path)


@needs_slicer
def test_an_override_value_prusaslicer_refuses_names_its_line(tmp_path):
    path = printer_yaml(tmp_path, slicer_section(overrides="    perimeters: 3\n    gcode_flavor: klipperish\n"))
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    msg = str(err.value)
    assert f"mk3s.yaml:{line_of(path, 'gcode_flavor')}" in msg and "klipperish" in msg
    assert "valid: (" in msg and "marlin2" in msg  # PrusaSlicer's own list of flavours


@needs_bundle
def test_a_users_flat_config_replaces_the_bundle(tmp_path):
    eff = load_printer("prusa_mk3s").slicer_config.effective()
    (tmp_path / "my_mk3s.ini").write_text("# generated by PrusaSlicer 2.5.0\n" + "".join(
        f"{k} = {v}\n" for k, v in sorted(eff.items())))
    p = load_printer(printer_yaml(tmp_path, "slicer:\n  vendor_bundle: my_mk3s.ini\n"))
    assert p.slicer_config.kind == "config" and p.slicer_config.effective() == eff
    path = printer_yaml(tmp_path, "slicer:\n  vendor_bundle: my_mk3s.ini\n  print_preset: x\n")
    with pytest.raises(ProfileError, match=rf"mk3s.yaml:{line_of(path, 'print_preset')}: .*flat PrusaSlicer"):
        load_printer(path)
