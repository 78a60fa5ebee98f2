"""Small optimize profiles written to tmp_path (they extend the shipped Table 3.1 profile)."""

from __future__ import annotations

import textwrap

import pytest


@pytest.fixture()
def write_profile(tmp_path):
    def write(name: str, text: str):
        path = tmp_path / f"{name}.yaml"
        path.write_text("extends: achutha2006\n" + textwrap.dedent(text))
        return path

    return write
