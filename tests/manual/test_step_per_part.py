"""A step that puts in several parts named alike but for a number (the projector's four shim stacks, one per
foot) states each part's own figure for each part: the shims under every foot, not foot 1's for all four."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

import rigcad
from rigcad.manual import document as D
from rigcad.manual.assembly import group_description, picture_meshes


@pytest.fixture(scope="module")
def shims():
    rig = rigcad.load("achutha2006")
    meshes = {m.name: m for m in picture_meshes(rig)}
    names = sorted(n for n in meshes if n.startswith("projector_shims_"))
    return rig, meshes, names


def test_the_shim_step_names_every_foot(shims):
    rig, meshes, names = shims
    assert len(names) == 4  # four feet, four stacks
    step = SimpleNamespace(members=tuple(reversed(names)), name=names[0], bought=False, fasteners=(),
                           needs=("tower_shelf",))
    text = D.step_text(SimpleNamespace(step=step, direction=np.array([0.0, 0.0, -1.0])), meshes, {},
                       D._shim_mm(rig))
    feet = [int(k) for k in re.findall(r"shims under projector foot (\d+)", text)]
    assert feet == [1, 2, 3, 4], text  # each foot once, in order
    each = D.shim_stacks(step, meshes, D._shim_mm(rig))[1]
    assert text.count(f"{each} shims under projector foot") == 4, text  # the count is per foot


def test_one_part_and_like_descriptions_are_said_once(shims):
    _, meshes, names = shims
    assert group_description((names[0],), names[0], meshes) == meshes[names[0]].description
    same = {n: SimpleNamespace(description="a washer") for n in ("washer_1", "washer_2")}
    assert group_description(tuple(same), "washer_1", same) == "a washer"
