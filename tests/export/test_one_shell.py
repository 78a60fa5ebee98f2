"""A part meant to be one solid is one closed shell: one connected body in its mesh (manifold3d's
components, the STL's triangles) and one shell in its B-rep (OCCT's shells, what the STEP holds).
A sealed cavity inside a part is a second body: an inward-facing box in the STL, a second shell in
the STEP, and PrusaSlicer reports two parts."""

from __future__ import annotations

import pytest

from rigcad.parts import PARTS

@pytest.fixture(scope="module")
def rig():
    from rigcad.rig import load

    return load("achutha2006")


@pytest.mark.parametrize("name", list(PARTS))
def test_every_part_meshes_to_one_body(rig, name):
    from rigcad.export import mesh

    man = mesh.build(PARTS[name](rig.profile, rig.layout).solid, mesh.PICTURE_CHORD_ERROR)
    assert len(man.decompose()) == 1, name


def test_a_sealed_cavity_is_a_second_body():
    """The check sees a cavity: a cube with a smaller cube cut out of its inside is two bodies."""
    from rigcad.export import mesh
    from rigcad.parts.recipe import Box, Difference

    hollow = Difference(Box((0.0, 0.0, 0.0), (10.0, 10.0, 10.0)), (Box((2.0, 2.0, 2.0), (8.0, 8.0, 8.0)),))
    assert len(mesh.build(hollow, 0.1).decompose()) == 2
    vented = Difference(Box((0.0, 0.0, 0.0), (10.0, 10.0, 10.0)), (Box((2.0, 2.0, 2.0), (8.0, 8.0, 11.0)),))
    assert len(mesh.build(vented, 0.1).decompose()) == 1


def _shells(shape) -> int:
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer

    explorer, n = TopExp_Explorer(shape, TopAbs_SHELL), 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


@pytest.mark.e2e
@pytest.mark.parametrize("name", list(PARTS))
def test_every_part_is_one_shell_in_its_step(rig, name, tmp_path):
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    from rigcad.export.step import step_writer
    from rigcad.parts import _kernel as K

    part = PARTS[name](rig.profile, rig.layout)
    shape = K.part_solid(part, rig.profile.tessellation.fit_tolerance, K.FitReport(), rig.profile)
    path = tmp_path / f"{name}.step"
    step_writer([(name, shape, part.color)], name)(path)
    reader = STEPControl_Reader()  # the shells as the STEP file holds them, read back
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    assert _shells(reader.OneShape()) == 1, name
