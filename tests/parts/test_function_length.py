"""Functions at most 80 lines in rigcad/parts (the project's standard; tower_layout was 107)."""

import ast
from pathlib import Path

import rigcad.parts

#: The standard's limit (STYLE: "Functions at most 80 lines").
MAX_LINES = 80


def test_every_parts_function_is_at_most_80_lines():
    long = {}
    for path in sorted(Path(rigcad.parts.__file__).parent.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_LINES:
                    long[f"{path.name}:{node.name}"] = lines
    assert not long, long
