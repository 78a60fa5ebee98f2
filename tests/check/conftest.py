"""Shared, session-scoped rig geometry and meshes for the ray-check tests (BVHs are the cost)."""

from __future__ import annotations

import pytest

from rigcad.check.scene import analytic_optics, mesh_optics, mirror_meshes

#: A coarse tessellation for fast tests: 66k + 121k triangles, built in ~0.5 s.
COARSE = (0.01, 0.01)
#: A finer one where a test needs mesh error well below its bound: 0.73M + 1.3M triangles, ~2 s.
FINE = (0.003, 0.003)


@pytest.fixture(scope="session")
def rig(table31_rig):
    return table31_rig


@pytest.fixture(scope="session")
def design_map(rig):
    return rig.incidence


@pytest.fixture(scope="session")
def analytic(rig):
    return analytic_optics(rig)


@pytest.fixture(scope="session")
def coarse_meshes(rig):
    return mirror_meshes(rig, None, *COARSE)


@pytest.fixture(scope="session")
def coarse(coarse_meshes):
    return mesh_optics(coarse_meshes, "smooth")


@pytest.fixture(scope="session")
def fine(rig):
    return mesh_optics(mirror_meshes(rig, None, *FINE), "smooth")


@pytest.fixture(scope="session")
def optics_cache():
    """run_raycheck's cache of meshes and BVHs, shared by the tests of a session."""
    return {}
