"""rigcad.basis is the mathematical core: it must not reach into the rig's geometry, parts or exports."""

import ast
from pathlib import Path

import rigcad

PKG = Path(rigcad.__file__).parent
#: Stages basis must not depend on (the projector-pixel map will be wired in from outside), and CAD kernels.
FORBIDDEN = ("rigcad.check", "rigcad.parts", "rigcad.export", "rigcad.fab", "rigcad.profile", "rigcad.optics",
             "rigcad.cli", "rigcad.plots", "build123d", "OCP", "cadquery", "manifold3d", "trimesh")


def test_basis_imports_only_numpy_scipy_and_itself():
    files = sorted((PKG / "basis").glob("*.py"))
    assert len(files) >= 7  # the package exists: an empty glob would make this test vacuous
    offenders = {}
    for f in files:
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
            bad = [n for n in names if any(n == p or n.startswith(p + ".") for p in FORBIDDEN)]
            if bad:
                offenders.setdefault(f.name, []).extend(bad)
    assert not offenders, offenders
