"""The design profile optimize writes names its base by ``extends: <name>``; it is written where
that name resolves from any folder: beside the base's file unless the base is shipped with rigcad,
so a lab folder moved elsewhere (or read from another working directory, or without
$RIGCAD_PROFILES) still reads its designs."""

import shutil

from rigcad.optimize.run import _design_home
from rigcad.profile import load_profile


def test_a_design_of_a_lab_profile_moves_with_its_folder(tmp_path, monkeypatch):
    lab = tmp_path / "lab"
    (lab / "profiles").mkdir(parents=True)
    (lab / "profiles" / "bench.yaml").write_text("extends: achutha2006\nbeam:\n  width: 7 mm\n")
    monkeypatch.chdir(lab)  # ./profiles: the base is found by name from here only
    out = lab / "exports" / "bench" / "optimize"
    home = _design_home("bench", "bench", out)
    assert home == lab / "profiles"
    (home / "bench_design.yaml").write_text("extends: bench\nbeam:\n  height: 5 mm\n")
    moved = tmp_path / "elsewhere" / "lab"
    shutil.move(str(lab), str(moved))
    monkeypatch.chdir(tmp_path)  # another working directory: ./profiles is not the lab's
    design = load_profile(moved / "profiles" / "bench_design.yaml")
    assert design.beam.width == 7.0 and design.beam.height == 5.0  # the base read beside it


def test_a_design_of_a_shipped_profile_stays_in_the_exports(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "exports" / "achutha2006_optimize" / "optimize"
    assert _design_home("achutha2006_optimize", "achutha2006_optimize", out) == out
