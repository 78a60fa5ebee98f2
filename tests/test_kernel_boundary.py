"""The optics and profile stages never touch the CAD kernel (CadQuery's rule, checked)."""

import ast
from pathlib import Path

import rigcad

PKG = Path(rigcad.__file__).parent
KERNEL = ("build123d", "OCP", "cadquery", "manifold3d", "trimesh", "pymeshlab", "embreex")


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_profile_and_optics_do_not_import_the_kernel():
    files = sorted((PKG / "profile").rglob("*.py")) + sorted((PKG / "optics").rglob("*.py"))
    assert len(files) >= 8  # the stages exist: an empty glob would make this test vacuous
    offenders = {str(f.relative_to(PKG)): sorted(_imports(f) & set(KERNEL)) for f in files}
    offenders = {k: v for k, v in offenders.items() if v}
    assert not offenders, f"kernel imports outside parts/export: {offenders}"


def test_only_the_loader_reads_yaml():
    readers = [str(f.relative_to(PKG)) for f in PKG.rglob("*.py") if "yaml" in _imports(f)]
    assert readers == ["profile/loader.py"], readers
