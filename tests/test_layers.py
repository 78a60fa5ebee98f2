"""The import floors hold: `lint-imports` (import-linter) keeps the contracts in pyproject.toml's
[tool.importlinter]: imports run downwards only, no cycles between sibling modules, no CAD kernel
under profile/ or optics/. import-linter reads the source, it imports nothing of rigcad. A second
test plants one offence per contract in a copy of the package and watches each contract break, so
the first cannot pass because the contracts check nothing."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONTRACTS = ("floors: imports run downwards only", "no import cycles between sibling modules",
             "the design has no CAD kernel")


def _lint(root: Path) -> subprocess.CompletedProcess:
    """`lint-imports` on the package under ``root`` with ``root``'s pyproject.toml, in a fresh
    interpreter (import-linter finds the package through sys.path; no cache)."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    code = "from importlinter.cli import lint_imports_command; lint_imports_command()"
    return subprocess.run([sys.executable, "-c", code, "--no-cache", "--config", str(root / "pyproject.toml")],
                          cwd=root, env=env, capture_output=True, text=True, timeout=300)


def test_the_floors_hold():
    res = _lint(ROOT)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out
    for name in CONTRACTS:
        assert name in out and "BROKEN" not in out, out


def test_each_contract_breaks_on_an_offence(tmp_path):
    shutil.copytree(ROOT / "rigcad", tmp_path / "rigcad", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    plant = {"optics/paraboloid.py": "from rigcad.fab import split  # noqa: E402,F401  (an upward import)\n",
             "check/result.py": "from rigcad.check import trace3d  # noqa: E402,F401  (a cycle)\n",
             "profile/derived.py": "import build123d  # noqa: E402,F401  (the CAD kernel in the design)\n"}
    for path, line in plant.items():
        with open(tmp_path / "rigcad" / path, "a") as f:
            f.write(line)
    res = _lint(tmp_path)
    out = res.stdout + res.stderr
    assert res.returncode != 0, out
    assert "Contracts: 0 kept, 3 broken." in out, out
    assert "rigcad.optics.paraboloid -> rigcad.fab.split" in out, out
    assert "rigcad.profile.derived -> build123d" in out, out
