"""Support off the mirrors (issue 14, item 3): the model's support contact against closed forms,
the G-code reader against synthetic G-code with known beads, thin plates printed flat, and the
slicer's own support on the rig's mirror pieces."""

from __future__ import annotations

import math

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.export import mesh as M
from rigcad.fab import orientation as O
from rigcad.fab import support as SU

from .conftest import have_slicer


def _table(top=(40.0, 30.0, 4.0), leg=(10.0, 10.0, 20.0), step: float | None = None):
    """A slab on a centred post (an overhang of known area at a known height); with ``step``, a
    block of that height under one half of the slab, on which the support then stands."""
    post = m3d.Manifold.cube(leg).translate((-leg[0] / 2, -leg[1] / 2, 0.0))
    slab = m3d.Manifold.cube(top).translate((-top[0] / 2, -top[1] / 2, leg[2]))
    solid = post + slab
    if step is not None:
        solid = solid + m3d.Manifold.cube((top[0] / 2 - leg[0] / 2 - 2.0, top[1], step)).translate(
            (leg[0] / 2 + 2.0, -top[1] / 2, 0.0))
    return M.mesh_arrays(solid)


def test_the_model_puts_support_under_an_overhang_and_on_what_it_stands_on():
    v, f = _table()
    c = O.support_contact(v, f, (0, 0, 1))
    under = 40 * 30 - 10 * 10  # the slab's underside beyond the post (mm2)
    assert abs(c["other_under_mm2"] - under) < 1e-6 and c["other_on_mm2"] == 0.0  # on the bed
    assert abs(c["support_envelope_mm3"] - under * 20.0) < 1e-6  # columns 20 mm tall
    # mark the slab's underside as a "mirror": support is then under the mirror
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    under_slab = (n[:, 2] < 0) & (np.abs(tri[:, :, 2] - 20.0) < 1e-9).all(axis=1)
    c = O.support_contact(v, f, (0, 0, 1), under_slab)
    assert abs(c["mirror_under_mm2"] - under) < 1e-6

    v, f = _table(step=5.0)
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    step_top = (n[:, 2] > 0) & (np.abs(tri[:, :, 2] - 5.0) < 1e-9).all(axis=1)
    c = O.support_contact(v, f, (0, 0, 1), step_top)
    # the step (13 x 30 mm: the slab's half beyond the post less a 2 mm gap) takes the support over
    # it; the columns are cut on a ~2 mm grid, so the step's 30 mm edge is resolved to one cell
    edge = 30 * math.sqrt(O.SUPPORT_CELL_MM2)
    assert abs(c["mirror_on_mm2"] - 13 * 30) < edge, c
    assert abs(c["support_envelope_mm3"] - ((under - 13 * 30) * 20.0 + 13 * 30 * 15.0)) < edge * 5.0  # 5 mm step


def test_thin_plates_print_flat(table31_rig, prusa, tmp_path):
    from rigcad.fab.stage import run_fab

    res = run_fab(table31_rig, prusa, tmp_path, parts=["tower_shim"])
    e = res.report["parts"]["tower_shim"]
    assert res.problems == []
    assert len(e["pieces"]) == 1  # 0.5 mm thick, 30 mm across: flat, never a fin on edge
    for pc in e["pieces"]:
        thickness = table31_rig.profile.tower.shim_thickness
        assert pc["orientation"].startswith("flat") and abs(pc["extents_mm"]["z_mm"] - thickness) < 1e-9
    assert O.plate_axis(np.array([[0, 0, 0], [300, 144, 7.5]])) == 2
    assert O.plate_axis(np.array([[0, 0, 0], [301.6, 6.0, 10.0]])) is None  # the beam is a bar, not a plate


def _gcode(lines: list[str]) -> bytes:
    return ("\n".join(["M83", "G1 Z0.350 F720", ";TYPE:Perimeter", ";HEIGHT:0.15", "G1 X0 Y0",
                       "G1 X5 Y0 E1.0"] + lines) + "\n").encode()


def test_the_gcode_reader_finds_the_support_beads():
    lines = [";TYPE:Support material", ";WIDTH:0.35", "G1 X0 Y1", "G1 X10 Y1 E0.5", "G1 X10 Y3 F9000",
             ";TYPE:Support material interface", "G1 X0 Y3 E0.5", "G1 X0 Y4 E-0.8", ";TYPE:External perimeter",
             "G1 X10 Y4 E0.5"]
    beads = SU.support_beads(_gcode(lines))
    assert abs(beads.length_mm - 20.0) < 1e-12  # two 10 mm extrusions; travel and retraction are not beads
    assert beads.layers == 1
    assert np.allclose(beads.points[:, 2], 0.35 - 0.075)  # the bead's middle: Z minus half its height
    assert set(np.round(beads.points[:, 1], 9)) == {1.0, 3.0}
    assert np.diff(np.sort(beads.points[beads.points[:, 1] == 1.0][:, 0])).max() <= SU.SAMPLE_SPACING + 1e-12


def test_contact_area_of_beads_over_a_plate_is_the_dilated_patch():
    """Beads 0.2 mm apart over a 10 x 10 mm patch, h above a plate's top: each touched point of
    the plate lies within the reach r of a bead, so the touched area is the patch dilated by
    a = sqrt(r^2 - h^2) (rounded corners: (10 + 2a)^2 - (4 - pi) a^2), to the sampling's noise."""
    v, f = M.mesh_arrays(m3d.Manifold.cube((40.0, 40.0, 2.0)).translate((-20.0, -20.0, 0.0)))
    h, reach = 0.3, 0.6
    seg = np.array([(-5.0, y, 5.0, y, 2.0 + h) for y in np.arange(-5.0, 5.0 + 1e-9, 0.2)])
    beads = SU.SupportBeads(seg, 10.0 * len(seg), 1)
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    top = np.nonzero(n[:, 2] > 0)[0]
    c = SU.contact_areas(v, f, top, beads, reach)
    a = math.sqrt(reach ** 2 - h ** 2)
    expected = (10 + 2 * a) ** 2 - (4 - math.pi) * a * a
    # 10 samples per mm2: the touched count's relative noise is ~1/sqrt(1300) = 3 %
    assert abs(c["mirror_mm2"] - expected) < 0.06 * expected, (c["mirror_mm2"], expected)
    assert c["other_mm2"] == 0.0


@pytest.mark.skipif(not have_slicer(), reason="prusa-slicer is not installed")
def test_the_gcode_reader_sees_support_on_a_mirror_where_there_is_some(table31_rig, prusa):
    """A positive control: the paraboloid upside down (its mirror's rim band overhangs) through
    PrusaSlicer with support. The G-code's support touches the mirror, and its area agrees with
    the model's independent estimate (rays from the overhangs) within a factor 2 (measured: 233 mm2
    from the G-code, 145 mm2 from the model, a ratio of 1.61; 158 mm2, 1.09, before the paraboloid's
    clamp took its shim stops, set screw and stop pin: the mirror is the same, the slicer's support
    under it is not, and the cause is not isolated; the slicer's threshold, 50 deg, is not the
    model's 45 deg, and its interface spreads past the overhang's edge)."""
    from rigcad.fab import slicer as S
    from rigcad.fab.mirror import mirror_faces
    from rigcad.fab.stage import _mirror

    part = table31_rig.recipe("paraboloid")
    v, f = M.mesh_arrays(M.build(part.solid, 0.018))
    mf = mirror_faces(v, f, _mirror(part, table31_rig.layout), 0.02)
    o = O.Orientation("upside_down", (0.0, 0.0, -1.0))
    placed = O.place(v, o, (125.0, 105.0))
    (res,), _ = S.slice_all([S.slice_job(prusa, "upside_down", M.stl_bytes(placed, f, "x"), True, (125.0, 105.0))],
                            workers=1)
    c = SU.contact_areas(placed, f, mf.index, SU.support_beads(res.gcode),
                         SU.contact_reach(prusa.slicer_config.effective(), prusa.layer_height))
    model = O.support_contact(v, f, o.direction, np.isin(np.arange(len(f)), mf.index))
    assert model["mirror_mm2"] > 100  # the control has support on its mirror
    assert model["mirror_mm2"] / 2 < c["mirror_mm2"] < model["mirror_mm2"] * 2, (c["mirror_mm2"], model)
