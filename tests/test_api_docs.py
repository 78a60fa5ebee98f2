"""docs/api.md is executable: every ```python block runs, in order, in one namespace, in an empty
folder (so profiles come from the package's search path, not the repository)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)


def test_the_page_has_examples():
    assert len(blocks()) >= 6  # an empty page would make the test below vacuous


def test_every_example_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("RIGCAD_PROFILES", raising=False)
    namespace: dict = {}
    for i, code in enumerate(blocks()):
        try:
            exec(compile(code, f"{DOC.name}[block {i}]", "exec"), namespace)
        except Exception as err:  # noqa: BLE001 - report which block failed, with its text
            pytest.fail(f"docs/api.md block {i} failed: {type(err).__name__}: {err}\n{code}")
    out = capsys.readouterr().out
    assert "achutha2006" in out and "10.66 x 9.05 in" in out  # the thesis rig's ~11 x 9 in dome
    assert (tmp_path / "exports" / "achutha2006" / "step" / "beam.step").is_file()
