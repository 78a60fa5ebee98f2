"""rigcad.basis keeps its mathematical core pure: the modules that do the maths work on plain arrays
and never reach into the rig's geometry, parts, exports or checks; the modules that wire the core to
a Rig (projector images, simulated acquisition on the rig) are named here, and the pure
ones may not import them either."""

import ast
from pathlib import Path

import rigcad

PKG = Path(rigcad.__file__).parent
#: The mathematical core: numpy/scipy and each other only.
PURE = {"__init__.py", "zonal.py", "gram.py", "brdf.py", "merl.py", "sh.py", "simulate.py"}
#: The wiring to the rig: may import the Rig's stages (optics, check, parts, export, plots).
WIRED = {"projector.py", "acquire.py", "card_light.py", "measured.py"}
#: What the pure modules must not import: the rig's stages, the wiring, and CAD kernels.
FORBIDDEN = ("rigcad.check", "rigcad.parts", "rigcad.export", "rigcad.fab", "rigcad.profile", "rigcad.optics",
             "rigcad.cli", "rigcad.plots", "rigcad.rig", "rigcad.basis.projector", "rigcad.basis.acquire", "rigcad.basis.measured",
             "build123d", "OCP", "cadquery", "manifold3d", "trimesh")


def _imports(path: Path) -> list[str]:
    """Every module ``path`` imports, at any depth (function-level imports included), absolute names."""
    names = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from .projector import x -> rigcad.basis.projector
                base = "rigcad.basis" + (f".{base}" if base else "")
                names += [base] if node.module else [f"{base}.{a.name}" for a in node.names]
            else:
                names.append(base)
    return names


def test_every_basis_module_is_classified():
    files = {f.name for f in (PKG / "basis").glob("*.py")}
    # a new module must be declared pure or wired on purpose; PURE and WIRED must name real files
    assert files == PURE | WIRED, f"unclassified: {sorted(files - PURE - WIRED)}, missing: {sorted(PURE | WIRED - files)}"


def test_pure_modules_import_only_numpy_scipy_and_each_other():
    offenders = {}
    for name in sorted(PURE):
        bad = [n for n in _imports(PKG / "basis" / name) if any(n == p or n.startswith(p + ".") for p in FORBIDDEN)]
        if bad:
            offenders[name] = bad
    assert not offenders, offenders


def test_the_checker_sees_a_forbidden_import():
    # the test above would pass vacuously if _imports missed function-level or relative imports
    wired = set(_imports(PKG / "basis" / "projector.py"))
    assert "rigcad.check.trace3d" in wired and "rigcad.basis.gram" in wired, sorted(wired)
