"""The command line as a user runs it: outputs, determinism, one-line errors, nothing half-written."""

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rigcad.cli import main

ROOT = Path(__file__).resolve().parents[1]


def run(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "rigcad", *args], cwd=cwd, capture_output=True, text=True)


def test_design_writes_report_table_and_figures(tmp_path, capsys):
    assert main(["design", str(ROOT / "profiles/achutha2006.yaml"), "--exports", str(tmp_path)]) == 0
    out = tmp_path / "achutha2006"
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "dome_profile.csv", "incidence.png", "rays.png"]
    report = json.loads((out / "design.json").read_text())
    for key in ("focal_length_mm", "rim_radius_mm", "vertex_z_mm", "rim_z_mm", "cop_z_mm"):
        assert isinstance(report["paraboloid"][key], float), key
    rows = list(csv.DictReader((out / "dome_profile.csv").open()))
    assert len(rows) == 2001
    assert float(rows[0]["incidence_theta_deg"]) == pytest.approx(90.0)
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in out.glob("*.png"))
    assert "10.66 x 9.05 in" in capsys.readouterr().out


def test_design_is_byte_for_byte_deterministic(tmp_path):
    for name in ("a", "b"):
        assert main(["design", "achutha2006", "--exports", str(tmp_path / name)]) == 0
    for path in (tmp_path / "a" / "achutha2006").iterdir():
        twin = tmp_path / "b" / "achutha2006" / path.name
        assert path.read_bytes() == twin.read_bytes(), path.name


def test_bad_profile_is_one_line_with_file_and_line_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("paraboloid:\n  vertical_extent: 2.25 cm\n  tangent_angle: 95 deg\n"
                   "layout: {cop_to_vertex: 27 cm, sample_to_rim: 13.5 cm}\n")
    res = run("design", str(bad), "--exports", str(tmp_path / "exports"))
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr
    assert "bad.yaml:3" in lines[0] and "paraboloid.tangent_angle" in lines[0] and "< 90 deg" in lines[0]
    assert not (tmp_path / "exports").exists()


def test_impossible_geometry_keeps_previous_exports_intact(tmp_path):
    good = tmp_path / "rig.yaml"
    good.write_text((ROOT / "profiles/achutha2006.yaml").read_text())
    exports = tmp_path / "exports"
    assert main(["design", str(good), "--exports", str(exports)]) == 0
    before = {p.name: p.read_bytes() for p in (exports / "rig").iterdir()}
    good.write_text(good.read_text().replace("tangent_angle: 20 deg", "tangent_angle: 60 deg"))
    res = run("design", str(good), "--exports", str(exports))
    assert res.returncode == 2 and "tangent_angle" in res.stderr
    after = {p.name: p.read_bytes() for p in (exports / "rig").iterdir()}
    assert after == before  # no partial overwrite, no temporary files left


def test_profile_show_lists_sources_and_derived_values():
    res = run("profile", "show", "achutha2006")
    assert res.returncode == 0, res.stderr
    assert "profiles/achutha2006.yaml:14" in res.stdout  # where tangent_angle was set
    assert "focal_length" in res.stdout and "2.98067 mm" in res.stdout


def test_profile_show_json():
    res = run("profile", "show", "achutha2006", "--json")
    data = json.loads(res.stdout)
    assert data["derived"]["rim_radius_mm"] == pytest.approx(16.3787, abs=1e-4)


def test_help_explains_subcommands():
    res = run("--help")
    assert res.returncode == 0
    assert "design" in res.stdout and "profile" in res.stdout


def test_unknown_profile_names_the_known_ones():
    res = run("design", "no_such_profile")
    assert res.returncode == 2 and "achutha2006" in res.stderr


def test_readme_ray_diagram_is_current(tmp_path):
    # docs/rays.png is shown in docs/design.md; `make docs` regenerates it
    assert main(["design", "achutha2006", "--exports", str(tmp_path)]) == 0
    assert (tmp_path / "achutha2006" / "rays.png").read_bytes() == (ROOT / "docs" / "rays.png").read_bytes()


def test_build_help_lists_every_part():
    from rigcad.parts import PARTS

    res = run("build", "--help")
    assert all(name in res.stdout for name in PARTS)  # the epilog is written out to keep --help light


def test_stl_returns_at_once_when_nothing_changed_and_repairs_a_damaged_file(exports_copy):
    exports = exports_copy  # a copy of the session's `rigcad stl achutha2006` (its first, full run)
    again = run("stl", "achutha2006", "--exports", str(exports))
    assert "up to date" in again.stdout
    stl = exports / "achutha2006" / "stl" / "beam.stl"
    good = stl.read_bytes()
    stl.write_bytes(b"damaged")
    repaired = run("stl", "achutha2006", "--exports", str(exports))
    assert "up to date" not in repaired.stdout and "1 part(s) built" in repaired.stdout
    assert stl.read_bytes() == good


@pytest.mark.parametrize("given, advised", [(None, False), ("1", True), ("0", False)])
def test_rigcad_starts_numpy_without_huge_page_advice_unless_told(given, advised, tmp_path):
    # numpy reads NUMPY_MADVISE_HUGEPAGE once, when imported: a fresh process runs rigcad's main (a
    # command that imports numpy), then asks numpy what it does. A value the user set wins.
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if given is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = given
    code = ("import sys; from rigcad.cli.main import main; assert 'numpy' not in sys.modules\n"
            f"assert main(['design', 'achutha2006', '--exports', {str(tmp_path)!r}]) == 0; assert 'numpy' in sys.modules\n"
            "from numpy._core.multiarray import _get_madvise_hugepage; print('advised', _get_madvise_hugepage())")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == f"advised {advised}"


def test_design_refuses_what_check_and_stl_refuse_all_at_once(tmp_path, capsys):
    """The newcomer's rig passed `design` at 0.75 px/deg and failed `check` at 0.9: design now refuses
    it as stl would (rigcad.check.criteria), every failed criterion at once, each naming its key and
    file:line; the default rig (1.1 px/deg at the fewest, theta from 6.92 deg) passes."""
    assert main(["design", "achutha2006", "--exports", str(tmp_path / "a")]) == 0
    assert "refus" not in capsys.readouterr().err
    strict = tmp_path / "strict.yaml"
    strict.write_text("extends: achutha2006\nraycheck:\n  min_px_per_deg: 5\ntargets:\n  theta_min: 5 deg\n")
    assert main(["design", str(strict), "--exports", str(tmp_path / "b")]) == 1
    err = capsys.readouterr().err
    assert "2 refusal(s)" in err and (tmp_path / "b" / "strict" / "design.json").is_file()
    assert "raycheck.min_px_per_deg (" in err and "strict.yaml:3" in err
    assert "targets.theta_min (" in err and "strict.yaml:5" in err and "targets.theta_min >= 6.92 deg would pass" in err
