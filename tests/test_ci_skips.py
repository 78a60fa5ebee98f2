"""In CI (CI=true) a test that would skip for a missing tool fails instead; elsewhere it skips."""

from __future__ import annotations

from pathlib import Path

pytest_plugins = ["pytester"]

CONFTEST = Path(__file__).with_name("conftest.py")

MISSING_TOOL = """
import pytest

@pytest.mark.skipif(True, reason="prusa-slicer is not installed")
def test_marked():
    pass

def test_imported():
    pytest.importorskip("no_such_module_rigcad_ci")

def test_runs():
    pass
"""


def test_a_missing_tool_skips_on_a_desk_and_fails_in_ci(pytester, monkeypatch):
    pytester.makeconftest(CONFTEST.read_text())
    pytester.makepyfile(test_tools=MISSING_TOOL)
    monkeypatch.delenv("CI", raising=False)
    pytester.runpytest_inprocess("-p", "no:cacheprovider").assert_outcomes(passed=1, skipped=2)
    monkeypatch.setenv("CI", "true")
    res = pytester.runpytest_inprocess("-p", "no:cacheprovider", "-rE")
    res.assert_outcomes(passed=1, errors=1, failed=1)  # skipif skips in setup (an error), importorskip in the call
    res.stdout.fnmatch_lines(["*skipped in CI (CI=true)*prusa-slicer is not installed*"])
