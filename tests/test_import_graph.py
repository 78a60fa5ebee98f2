"""Start-up imports only what a command uses: `import rigcad` and building the `rigcad` argument
parser (what `rigcad --help` and every command do before any work) load no integrator, CAD kernel,
compiler or plotting library. Each case runs in a fresh interpreter, so what earlier tests imported
does not hide an eager import."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Imported by whichever command needs them, never at start-up (the integrator alone was 1.6 s of a
#: cold 2.1 s `import rigcad`).
HEAVY = ("scipy.integrate", "OCP", "numba", "matplotlib", "build123d")
#: Not needed to print help or to parse arguments either: numpy, the rest of scipy, the meshers.
LIGHT_START = ("numpy", "scipy", "trimesh", "pyarrow", "optuna", "joblib", "PIL", "tqdm")


def _modules_after(code: str) -> set[str]:
    """The top-level and dotted module names in sys.modules after ``code`` runs in a new interpreter
    that imports this checkout's rigcad."""
    script = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)}
    res = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return set(json.loads(res.stdout.splitlines()[-1]))


def _loaded(modules: set[str], names: tuple[str, ...]) -> list[str]:
    return [n for n in names if n in modules or any(m.startswith(n + ".") for m in modules)]


def test_import_rigcad_loads_nothing_heavy():
    modules = _modules_after("import rigcad")
    assert "rigcad" in modules  # the probe ran this checkout's package
    assert not _loaded(modules, HEAVY + LIGHT_START)


def test_cli_parser_loads_nothing_heavy():
    modules = _modules_after("import rigcad.cli\nrigcad.cli.build_parser()")
    assert "rigcad.cli" in modules and "rigcad.cli.fab" in modules  # every sub-command registered
    assert not _loaded(modules, HEAVY + LIGHT_START)


def test_the_rig_module_loads_no_scipy():
    """`rigcad.Rig` and `rigcad.load` are light: the dome's integrator, root finder and spline are
    imported when a dome is built, not with the model."""
    modules = _modules_after("from rigcad import Rig, load")
    assert "rigcad.rig" in modules and "rigcad.optics.dome" in modules
    assert not _loaded(modules, HEAVY + ("scipy",))


def test_an_up_to_date_stl_loads_nothing_heavy():
    """What an up-to-date `rigcad stl` does before it returns (read and validate the profile, hash
    it and the code, compare the manifest) needs YAML, not numpy, the integrator, kernel or plots."""
    modules = _modules_after("from rigcad.profile import load_profile\nfrom rigcad.export.manifest import inputs_key\n"
                             "inputs_key(load_profile('achutha2006'))\nimport rigcad.export.atomic")
    assert "rigcad.profile.schema" in modules and "yaml" in modules
    assert not _loaded(modules, HEAVY + LIGHT_START)


@pytest.mark.parametrize("name", ["Rig", "load", "__version__"])
def test_public_names_still_work(name):
    import rigcad

    assert name in rigcad.__all__ and name in dir(rigcad)
    assert getattr(rigcad, name) is not None
    if name != "__version__":
        from rigcad import rig

        assert getattr(rigcad, name) is getattr(rig, name)


def test_an_unknown_attribute_is_an_attribute_error():
    import rigcad

    with pytest.raises(AttributeError, match="no_such_name"):
        rigcad.no_such_name  # noqa: B018
