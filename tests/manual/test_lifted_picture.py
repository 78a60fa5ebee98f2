"""A step done with the dome lifted off (the paraboloid put in through the dome's open base) is drawn so: the
dome upside down, its open base on top, carrying the beam, the base plate not in the picture, and the part
coming down into the open base; the picture's way in is the text's."""

from __future__ import annotations

import numpy as np

import rigcad
from rigcad.manual import document as D
from rigcad.manual.assembly import lifted_view, picture_meshes


def test_the_paraboloid_goes_in_through_the_upturned_domes_open_base():
    meshes = picture_meshes(rigcad.load("achutha2006"))
    index = {m.name: i for i, m in enumerate(meshes)}
    done = [index[n] for n in ("base_plate", "dome", "beam")]
    new = [index["paraboloid"]]
    shown, kept, way = lifted_view(meshes, done, "dome")
    assert {shown[i].name for i in kept} == {"dome", "beam"}  # the beam rides with the dome; the plate stays down
    dome = shown[index["dome"]]
    # the dome's base (its face on the plate, z = 0) is now its top: the open side faces up
    assert abs(float(dome.hi[2])) < 1.0 and float(dome.lo[2]) < -100.0, (dome.lo, dome.hi)
    offsets = D._approach(shown, kept, new, way)
    para = shown[new[0]]
    # drawn before it goes in: moved back towards the open base (up, the side it comes in from), never towards
    # the dome's closed top (down): the picture's way in is the text's "through the dome's open base"
    assert float(offsets[new[0]][2]) > 0.0 and float(para.hi[2]) < float(dome.hi[2]), (para.hi, offsets[new[0]])
    assert np.allclose(way, [0.0, 0.0, -1.0])
