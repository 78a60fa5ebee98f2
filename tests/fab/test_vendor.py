"""PrusaSlicer's vendor presets: the installed PrusaResearch bundle read and flattened as
PrusaSlicer does, the printer file's slicer section validated with file:line, and a real slice
of a small cube whose G-code and 3MF project carry the vendor's settings (read back by regex,
zipfile and PrusaSlicer itself)."""

from __future__ import annotations

import io
import os
import re
import subprocess
import threading
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rigcad.errors import FabricationError, ProfileError
from rigcad.fab import allowlist as A
from rigcad.fab import slicer as S
from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer

from .conftest import ROOT, have_slicer

MK3S = "Original Prusa i3 MK3S & MK3S+"
PRINT = "0.15mm QUALITY @MK3"
PLA = "Prusament PLA"
NO_BUNDLE = ("PrusaSlicer's vendor bundles are not installed (apt-get install prusa-slicer); "
             "the project's CI installs it")


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


# -- brim and skirt ---------------------------------------------------------------------------------

def box(sx: float, sy: float, sz: float) -> bytes:
    from rigcad.export.mesh import stl_bytes

    v = np.array([[x, y, z] for x in (0, sx) for y in (0, sy) for z in (0, sz)], float)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                  [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return stl_bytes(v, f, "box")


def test_footprint_reads_contact_from_the_stl():
    fp = S.footprint(box(30, 10, 50))
    # exact for a box: float32 holds these integers exactly
    assert fp.extents == (30.0, 10.0, 50.0) and fp.contact_area == 300.0 and fp.contact_size == (30.0, 10.0)
    assert fp.slenderness == 5.0


@needs_bundle
def test_the_brim_rule(tmp_path):
    p = load_printer("prusa_mk3s")
    settings, rec = S.placement(p, S.footprint(box(40, 40, 20)))  # 1600 mm2, squat
    assert settings["brim_width"] == "0" and not rec["brim_wanted"] and rec["skirts"] == 1
    settings, rec = S.placement(p, S.footprint(box(30, 30, 80)))  # 900 mm2 but 80 / 30 > 2
    assert settings["brim_width"] == "5" and "height / contact side" in rec["brim_reason"]
    settings, rec = S.placement(p, S.footprint(box(12, 12, 10)))  # 144 mm2 < 400
    assert settings["brim_width"] == "5" and "contact area" in rec["brim_reason"]
    # a bed-filling slender piece: no room for a brim (1 mm margin kept) nor the preset's skirt
    settings, rec = S.placement(p, S.footprint(box(246, 20, 100)))
    assert settings["brim_width"] == "0" and "none printed" in rec["brim_note"]
    assert settings["skirts"] == "0" and "off" in rec["skirt_note"]
    over = load_printer(printer_yaml(tmp_path, slicer_section(overrides="    brim_width: 3\n")))
    settings, rec = S.placement(over, S.footprint(box(12, 12, 10)))
    assert "brim_width" not in settings and rec["brim_width_mm"] == 3.0  # the override wins
    assert "brim_width = 3\n" in S.printer_ini(over, False, settings)


# -- a real slice -----------------------------------------------------------------------------------

def comments(text: str) -> dict[str, str]:
    """'; key = value' lines, as PrusaSlicer writes its configuration into G-code and 3MF."""
    return dict(re.findall(r"^; (\w+) = (.*)$", text, re.M))


def test_without_prusaslicer_the_printer_still_loads_and_gcode_says_why(tmp_path, monkeypatch):
    monkeypatch.setattr(V, "bundle_dirs", lambda: [tmp_path / "nowhere"])
    p = load_printer("prusa_mk3s")
    assert p.slicer_config is None and "apt-get" in p.slicer_unavailable
    assert p.layer_height == 0.15  # the printer file's own figure stands
    job = S.slice_job(p, "x", b"", False, (0.0, 0.0))
    assert job.problem == p.slicer_unavailable
    if have_slicer():
        with pytest.raises(FabricationError, match=r"no G-code was written: .*nowhere.*apt-get"):
            S.slice_all([job])


@needs_slicer
def test_a_cube_sliced_for_the_mk3s_carries_the_vendor_settings(tmp_path):
    p = load_printer("prusa_mk3s")
    job = S.slice_job(p, "cube", box(20, 20, 20), False, (125.0, 105.0))
    (res,), version = S.slice_all([job], workers=1)
    text = res.gcode.decode()
    cfg = comments(text.split("; prusaslicer_config = begin\n")[1].split("; prusaslicer_config = end")[0])
    assert cfg["printer_model"] == "MK3S" and cfg["bed_temperature"] == "60"
    assert cfg["first_layer_bed_temperature"] == "60" and cfg["temperature"] == "215"  # Prusament PLA
    assert cfg["layer_height"] == "0.15" and cfg["perimeters"] == "3" and cfg["fill_density"] == "20%"
    start = text[:text.index(";LAYER_CHANGE")]
    assert 'M862.3 P "MK3S"' in start and "G80 ; mesh bed leveling" in start and "intro line" in start
    assert "M140 S60" in start and "M109 S215" in start
    assert " UTC" not in text.splitlines()[0]  # the date is dropped
    assert res.estimates["print_time_s"] > 0 and res.estimates["filament_g"] > 0  # read from the G-code's tail

    z = zipfile.ZipFile(io.BytesIO(res.project))
    assert all(i.date_time == S.ZIP_EPOCH for i in z.infolist())
    model = z.read("3D/3dmodel.model").decode()
    assert re.search(r'name="CreationDate">\d', model) is None
    inside = comments(z.read(S.PROJECT_CONFIG).decode())
    # the project holds exactly the allow-listed settings that sliced the G-code; the rest are
    # PrusaSlicer's defaults (never handed to it), which it reads back as defaults
    assert inside == {k: v for k, v in cfg.items() if k in A.ALLOWED_KEYS}
    assert {k: cfg[k] for k in set(cfg) - set(inside)} == {
        "post_process": "", "gcode_substitutions": "", "output_filename_format": "[input_filename_base].gcode",
        "threads": cfg["threads"]}

    (again,), _ = S.slice_all([job], workers=1)
    assert again.gcode == res.gcode and again.project == res.project  # deterministic bytes

    # independent reader: PrusaSlicer opens the project alone (no --load) and slices the same G-code
    (tmp_path / "cube.3mf").write_bytes(res.project)
    with S.slicing_pool(1) as pool:  # on one CPU, as rigcad runs it (the slicer's note on determinism)
        proc = pool.submit(subprocess.run, ["prusa-slicer", "--export-gcode", "-o", "again.gcode", "cube.3mf"],
                           cwd=tmp_path, capture_output=True, text=True, timeout=300).result()
    assert proc.returncode == 0, proc.stderr[-500:]
    assert S.normalise((tmp_path / "again.gcode").read_bytes()) == res.gcode


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs Linux's CPU affinity and two CPUs to tell one CPU from all")
def test_each_slicer_starts_on_one_cpu_of_its_own_and_the_caller_keeps_every_cpu():
    """What the slicing threads start runs on one CPU (PrusaSlicer's TBB then runs one thread, its
    tasks in a fixed order: rigcad.fab.slicer's note on determinism); two threads side by side
    take different CPUs; the calling thread keeps its mask."""
    before = os.sched_getaffinity(0)
    both = threading.Barrier(2, timeout=30)

    def allowed(_):
        both.wait()  # each of the two threads runs one task
        out = subprocess.run(["grep", "Cpus_allowed_list", "/proc/self/status"], capture_output=True,
                             text=True, timeout=30, check=True).stdout
        return out.split(":")[1].strip()

    with S.slicing_pool(2) as pool:
        seen = list(pool.map(allowed, range(2)))
    assert all(s.isdigit() for s in seen), seen  # one CPU each, e.g. "1", not "0-1"
    assert len(set(seen)) == 2 and {int(s) for s in seen} <= before
    assert os.sched_getaffinity(0) == before


@needs_slicer
def test_a_slender_piece_is_printed_with_a_brim():
    p = load_printer("prusa_mk3s")
    (res,), _ = S.slice_all([S.slice_job(p, "pin", box(8, 8, 30), False, (125.0, 105.0))], workers=1)
    assert comments(res.gcode.decode())["brim_width"] == "5" and res.placement["brim_width_mm"] == 5.0


@pytest.mark.slow
@needs_slicer
def test_a_rig_part_on_the_mk3s_gets_vendor_gcode_and_a_project(table31_rig, tmp_path):
    """A real piece through the fab stage: G-code with the vendor's start, a 3MF project beside it."""
    from rigcad.fab.stage import run_fab

    p = load_printer("prusa_mk3s")
    res = run_fab(table31_rig, p, tmp_path, parts=["beam"], gcode=True, workers=1)  # printed whatever the profile buys
    assert res.problems == [], res.problems
    for pc in res.report["parts"]["beam"]["pieces"]:
        text = (tmp_path / "gcode" / f"{pc['name']}.gcode").read_text()
        assert 'M862.3 P "MK3S"' in text and "G80 ; mesh bed leveling" in text
        assert comments(text)["bed_temperature"] == "60"
        project = tmp_path / pc["gcode"]["project"]
        with zipfile.ZipFile(project) as z:
            assert comments(z.read(S.PROJECT_CONFIG).decode())["printer_model"] == "MK3S"
        assert "brim_width_mm" in pc["gcode"]["placement"]
    assert "PrusaResearch.ini" in (tmp_path / "printer.ini").read_text().splitlines()[1]
