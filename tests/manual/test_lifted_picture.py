"""A step done with the dome lifted off (the paraboloid put in through the dome's open base) is drawn so: the
dome upside down, its open base on top, carrying the beam, the base plate not in the picture. The paraboloid's U
clamp opens at the bottom in the working position, so upside down it belongs under the beam, its open side
towards the open base: it comes up onto the beam from below (drawn under its place, never lowered straight
through the beam), and the step's words say so and say what holds it while the dome is upside down."""

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
    working = np.array([0.0, 0.0, -1.0])  # the clamp lowered onto the beam, dome on the plate (the gate's order)
    way = D.lifted_way(working)
    offsets = D._approach(shown, kept, new, way)
    para, beam = shown[new[0]], shown[index["beam"]]
    # upside down the paraboloid hangs under the beam (its centre below the beam's) and is
    # drawn further under its place, moving up onto the beam: never above it, lowered through the 6 mm beam
    assert float(para.lo[2] + para.hi[2]) < float(beam.lo[2] + beam.hi[2]), (para.lo, para.hi, beam.lo, beam.hi)
    assert np.allclose(way, [0.0, 0.0, 1.0]) and float(offsets[new[0]][2]) < 0.0, (way, offsets[new[0]])
    # drawn inside the upturned dome, clear of its closed top (now the bottom)
    assert float(para.lo[2] + offsets[new[0]][2]) > float(dome.lo[2]), (para.lo, offsets[new[0]], dome.lo)
    # a part slid in level keeps its way, turned with the dome (the beam along -x)
    assert np.allclose(D.lifted_way([-1.0, 0.0, 0.0]), [-1.0, 0.0, 0.0])


def test_the_words_take_the_paraboloid_beside_the_beam_and_up_onto_it():
    words = D.into_upturned("dome", "beam", [0.0, 0.0, -1.0])
    assert "beside the beam" in words and "push it up onto the beam from below" in words, words
    assert "nothing else holds it" in words and "set screw" in words, words  # what holds it upside down
    # planted: the words the lab technician read ("put the part in through the dome's open base onto the beam")
    assert "onto the beam from below" not in "put the part in through the dome's open base onto the beam."
    # a part pushed up in the working position is lowered onto its carrier in the upturned dome
    assert "lower it onto the beam" in D.into_upturned("dome", "beam", [0.0, 0.0, 1.0])
