"""The hostile suite's fixtures: every module a command imports is imported once before the first
case is forked (so a case's clock measures its command, not imports), and each case gets a fresh
sandbox (harness.Sandbox)."""

from __future__ import annotations

import pytest

from .harness import Sandbox, warm_imports


@pytest.fixture(scope="session", autouse=True)
def _warm():
    warm_imports()


@pytest.fixture
def sandbox(tmp_path) -> Sandbox:
    return Sandbox(tmp_path)
