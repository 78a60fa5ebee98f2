"""PrusaSlicer's vendor presets: the installed PrusaResearch bundle read and flattened as
PrusaSlicer does, with file:line errors and "did you mean" for a wrong name."""

from __future__ import annotations

import re

import pytest

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab import vendor as V

MK3S = "Original Prusa i3 MK3S & MK3S+"
PRINT = "0.15mm QUALITY @MK3"
PLA = "Prusament PLA"
NO_BUNDLE = "PrusaSlicer's vendor bundles are not installed (apt-get install prusa-slicer); the project's CI installs it"


def have_bundle() -> bool:
    return "PrusaResearch" in V.available_bundles()


needs_bundle = pytest.mark.skipif(not have_bundle(), reason=NO_BUNDLE)


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
