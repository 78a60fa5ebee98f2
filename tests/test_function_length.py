"""No function in rigcad/ runs over 80 lines (from its ``def`` to its last line, docstring and
comments included): a longer one is split by meaning. Numba kernels are exempt (a function decorated
with numba's ``njit``/``jit``: the compiler sees one function, and splitting a kernel costs calls in
its inner loop). The scan reads the source (ast), it imports nothing."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 80
#: Functions still over the limit, by (file under rigcad/, name): none (the manual's build_manual, the
#: last one, is split into one function per section); nothing may join this list.
ALLOWED: set[tuple[str, str]] = set()


def _is_numba_kernel(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    for dec in fn.decorator_list:
        target = dec.func if isinstance(dec, ast.Call) else dec
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit"):
            return True
    return False


def long_functions(package: Path) -> dict[tuple[str, str], int]:
    """(file relative to ``package``, function name) -> lines, for every function or method over
    MAX_LINES lines that is not a numba kernel."""
    found = {}
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not _is_numba_kernel(node):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_LINES:
                    found[(path.relative_to(package).as_posix(), node.name)] = lines
    return found


def test_no_function_runs_over_80_lines():
    assert len(list((ROOT / "rigcad").rglob("*.py"))) > 40  # the package is there: an empty scan would pass
    over = {k: v for k, v in long_functions(ROOT / "rigcad").items() if k not in ALLOWED}
    assert not over, f"functions over {MAX_LINES} lines (split them by meaning): {over}"


def test_the_scan_finds_a_long_function_and_exempts_only_kernels(tmp_path):
    body = "".join(f"    x{i} = {i}\n" for i in range(MAX_LINES))  # def line + 80 = 81 lines
    (tmp_path / "mod.py").write_text(
        "import numba as nb\n\n\n"
        f"def long_one():\n{body}\n\n"
        f"def short_one():\n{body[:-(len(f'    x{MAX_LINES - 1} = {MAX_LINES - 1}') + 1)]}\n\n"
        f"class Holder:\n    def long_method(self):\n{''.join('    ' + line for line in body.splitlines(True))}\n\n"
        f"@nb.njit(cache=True)\ndef kernel():\n{body}\n")
    assert long_functions(tmp_path) == {("mod.py", "long_one"): 81, ("mod.py", "long_method"): 81}
