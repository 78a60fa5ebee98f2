"""Every function in rigcad/manual is at most 80 lines (the project's limit: a function longer than
a screen hides its steps), counted from its `def` line to its last line, decorators and docstring
included."""

from __future__ import annotations

import ast
from pathlib import Path

import rigcad.manual

LIMIT = 80  # lines: the project's standard (STYLE, "Functions at most 80 lines")


def test_every_function_in_the_manual_package_is_at_most_80_lines():
    long = []
    for path in sorted(Path(rigcad.manual.__file__).parent.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > LIMIT:
                    long.append(f"{path.name}:{node.lineno} {node.name}: {n} lines")
    assert not long, long
