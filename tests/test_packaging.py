"""The shipped profiles live at the top of the repository (profiles/, where people edit them) and
travel in the wheel as rigcad/profiles/: the package list in pyproject.toml names every package,
and the profiles are found, and named profiles/<name>.yaml, in a checkout and in an installed wheel."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SETUPTOOLS = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


def test_every_package_folder_is_in_the_wheel():
    """The list is explicit (the profiles' mapping needs it): a new folder under rigcad/ with Python
    files must be added to it, or the wheel would ship without it."""
    found = {".".join(d.relative_to(ROOT).parts) for d in (ROOT / "rigcad").rglob("*")
             if d.is_dir() and "__pycache__" not in d.parts and any(d.glob("*.py"))}
    found.add("rigcad")
    listed = set(SETUPTOOLS["packages"])
    assert found == listed - {"rigcad.profiles", "rigcad.profiles.printers", "rigcad.profiles.instruments"}


def test_the_wheel_maps_the_top_profiles_folder_into_the_package():
    assert SETUPTOOLS["package-dir"] == {"rigcad.profiles": "profiles"}
    assert {"rigcad.profiles", "rigcad.profiles.printers", "rigcad.profiles.instruments"} <= set(SETUPTOOLS["packages"])
    for package, patterns in SETUPTOOLS["package-data"].items():
        if package.startswith("rigcad.profiles"):
            folder = ROOT / "profiles" / Path(*package.split(".")[2:])
            assert all(list(folder.glob(p)) for p in patterns), (package, patterns)
    shipped = sorted(p.relative_to(ROOT / "profiles") for p in (ROOT / "profiles").rglob("*.yaml"))
    assert Path("achutha2006.yaml") in shipped and Path("printers/prusa_mk3s.yaml") in shipped
    assert Path("instruments/prosilica_ec1350c.yaml") in shipped
    assert not (ROOT / "rigcad" / "profiles").exists()  # one home: the top folder


def test_a_checkout_reads_the_top_profiles_folder():
    from rigcad.profile.paths import SHIPPED_PROFILES

    assert SHIPPED_PROFILES == ROOT / "profiles"


def _load_from(site: Path, cwd: Path) -> list[str]:
    code = ("from rigcad.profile.loader import load_raw; from rigcad.fab.printers import load_printer; "
            "import rigcad.profile.paths as P; r = load_raw('achutha2006'); "
            "print(P.SHIPPED_PROFILES); print(r.sources[0]); print(r.marks[('layout', 'cop_to_vertex')]); "
            "print(load_printer('vantage_i').source)")
    env = {**os.environ, "PYTHONPATH": str(site)}
    env.pop("RIGCAD_PROFILES", None)
    res = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    return res.stdout.split("\n")


def test_an_installed_wheel_finds_and_names_its_profiles(tmp_path):
    """The wheel's layout (what `pip wheel .` builds: the package with profiles/ inside it, no
    repository beside it), run from an unrelated folder."""
    site = tmp_path / "site-packages"
    shutil.copytree(ROOT / "rigcad", site / "rigcad", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "profiles", site / "rigcad" / "profiles")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    shipped, source, mark, printer = _load_from(site, elsewhere)[:4]
    assert Path(shipped) == site / "rigcad" / "profiles"
    assert source == "profiles/achutha2006.yaml"  # named as the user edits it, not by install folder
    assert mark.startswith("profiles/achutha2006.yaml:")
    assert printer == "profiles/printers/vantage_i.yaml"
