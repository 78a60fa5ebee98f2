"""Fixtures for the fabrication tests: the Table 3.1 rig's layout and one fab run on the desktop
printer (no G-code) shared by the tests that read its outputs."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rigcad.fab.printers import load_printer

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session", autouse=True)
def _repo_cwd():
    """Printer files are found under profiles/printers relative to the working directory."""
    import os

    old = os.getcwd()
    os.chdir(ROOT)
    yield
    os.chdir(old)


@pytest.fixture(scope="session")
def layout(table31_rig):
    return table31_rig.layout


@pytest.fixture(scope="session")
def prusa():
    return load_printer(ROOT / "profiles" / "printers" / "prusa_mk3s.yaml")


@pytest.fixture(scope="session")
def vantage():
    return load_printer(ROOT / "profiles" / "printers" / "vantage_i.yaml")


@pytest.fixture(scope="session")
def prusa_run(table31_rig, prusa, shared_build):
    """One fab run of the small parts and the dome on the desktop printer, without G-code: run once
    per session for every xdist worker (tests/conftest.py); its readers only read it."""
    from rigcad.fab.stage import run_fab

    def build(folder):
        out = folder / "prusa_mk3s"
        return out, run_fab(table31_rig, prusa, out, parts=["dome", "paraboloid", "beam", "camera_cross_base",
                                                            "camera_cross_hung", "dome_template", "paraboloid_template"])

    return shared_build("prusa_run", build)


def have_slicer() -> bool:
    return shutil.which("prusa-slicer") is not None
