"""The seams of a split mirror against its sanding stock, and the glue its cut faces need
(rigcad.fab.seams), checked against closed forms and the printed STLs."""

import math

import numpy as np
import pytest

from rigcad.fab import seams as S
from rigcad.fab.printers import AlignmentPin
from rigcad.fab import split as SP
from rigcad.fab.split import GridPlan, Piece, SplitPlan


def test_a_glue_face_oblique_to_the_layers_steps_by_the_layer_times_its_normal_along_the_build():
    """A sector cut at 30 deg printed with its build direction tilted 50 deg from z in the x-z
    plane: the half-plane's normal (-sin 30, cos 30, 0) . D = -sin 30 sin 50 (closed form)."""
    plan = SplitPlan(4, 1, math.radians(30), (0.0, 100.0))
    piece = Piece("p", 0, 0, plan.sector_range(0), None)
    d = np.array([math.sin(math.radians(50)), 0.0, math.cos(math.radians(50))])
    n0 = abs(math.sin(math.radians(30)) * math.sin(math.radians(50)))
    n1 = abs(math.sin(math.radians(120)) * math.sin(math.radians(50)))
    assert S.glue_face_step(0.15, S.cut_normals(plan, piece), d) == pytest.approx(0.15 * max(n0, n1), abs=1e-12)


def test_glue_faces_across_the_layers_or_in_a_layer_plane_print_smooth():
    """A flat plate's grid cuts printed flat (+z): x and y cut faces stand across the layers, a z cut
    lies in a layer plane: no staircase."""
    plan = GridPlan((10.0,), (20.0,), (5.0,))
    assert S.glue_face_step(0.2, S.cut_normals(plan, None), (0, 0, 1)) == 0.0
    assert S.glue_face_step(0.2, S.cut_normals(plan, None), (0, 0, -1)) == 0.0


def test_the_thinnest_glue_that_fills_the_gap_is_chosen():
    assert S.glue_for(0.0) is S.GLUES[0]
    assert S.glue_for(S.GLUES[0].gap_fill + 1e-6) is S.GLUES[1]
    assert [g.gap_fill for g in S.GLUES] == sorted(g.gap_fill for g in S.GLUES)


def test_a_floating_pin_lets_the_pieces_reach_the_gauge_whatever_the_holes_errors():
    """Two holes each off by p (2p apart at worst): the pin must take a relative shift of 2p in its
    two holes, so its clearance grows by 2p (rounded up to a drill); on its own it then allows
    that clearance + 2p."""
    pin = AlignmentPin(1.75, 0.15, 6.0)
    f = S.float_pin(pin, 0.1)
    assert f.clearance == pytest.approx(0.35) and f.diameter == pin.diameter and f.depth == pin.depth
    g = S.float_pin(pin, 0.1016)  # 0.004 in: 0.3532 mm needed, a 0.40 mm drill step
    assert g.clearance == pytest.approx(0.40)
    rec = S.seam_steps(f, 0.1, 0.093, 3.0)
    assert rec["step_on_pins_mm"] == pytest.approx(0.55)
    assert rec["step_on_gauge_mm"] == pytest.approx(S.FEELER_LEAF + 3.0 * math.tan(math.radians(S.EDGE_LEAN_DEG)))
    assert rec["fairs"] is True
    assert S.seam_steps(f, 0.1, 0.04, 3.0)["fairs"] is False


def test_a_seam_the_stock_cannot_fair_is_a_fab_problem_naming_the_key():
    rec = S.seam_steps(AlignmentPin(1.75, 0.35, 6.0), 0.1, 0.03, 3.0)
    rec.update({"glue_fills": True})
    (msg,) = S.problems("dome", rec)
    assert "sanding_stock" in msg and "dome" in msg
    assert S.problems("dome", {**rec, "fairs": True}) == []
    assert "cut faces" in S.problems("x", {"glue_fills": False, "glue_gap_mm": 0.9})[0]


@pytest.mark.e2e  # reads the shared fab run of the dome and small parts (prusa_run): make test-e2e
def test_the_dome_seams_fair_and_its_glue_fills_read_from_the_printed_pieces(prusa_run, prusa):
    """On the printed STLs (print position): the dome's cut faces' normals against the build
    direction (z) give the glue face's staircase (layer x |n_z|) the record states; its pin holes are
    drawn wider by twice the position error; the gauge's step lies within the stock."""
    import trimesh

    out, res = prusa_run
    e = res.report["parts"]["dome"]
    rec = e["seams"]
    assert rec["fairs"] and rec["glue_fills"] and rec["step_on_gauge_mm"] < rec["stock_mm"]
    assert rec["step_on_pins_mm"] > rec["stock_mm"]  # why the gauge: the pins alone would not do
    # the auto stock covers the staircase's bound, the gauge's step and a leaf (to rounding)
    st = e["sanding_stock"]
    assert st["stock_mm"] == pytest.approx(st["needed_bound_mm"] + rec["step_on_gauge_mm"] + S.FEELER_LEAF, abs=1e-12)
    assert rec["staircase_mm"] == st["needed_bound_mm"] and rec["stock_needed_mm"] <= rec["stock_mm"] + 1e-12
    # the pin holes' walls keep split.MIRROR_CLEARANCE (1 mm) behind the printed surface, as placed (1.49 mm
    # measured on 25 x 36 points of each wall; the placement checked 7 x 12: 0.05 mm allows what lies between);
    # sanding the stock and a leaf deeper leaves at least 0.6 mm over them
    assert rec["pin_hole_behind_printed_mm"] >= SP.MIRROR_CLEARANCE - 0.05 and rec["pins_stay_covered"]
    assert rec["pin_hole_cover_after_sanding_mm"] == pytest.approx(
        rec["pin_hole_behind_printed_mm"] - rec["stock_mm"] - S.FEELER_LEAF, abs=1e-12)
    pin = prusa.alignment_pin
    float_clearance = e["pin_fit"]["hole_drawn_mm"] - e["pin_fit"]["pin_diameter_mm"]
    need = pin.clearance + 2 * prusa.process_errors.position
    assert need <= float_clearance < need + S.DRILL_STEP
    assert round(e["pin_fit"]["hole_drawn_mm"] / S.DRILL_STEP, 6) % 1 == 0  # a drill one can buy
    planes = [math.radians(a) for a in e["split"]["sector_planes_deg"]]
    cut_normals = [np.array([-math.sin(a), math.cos(a), 0.0]) for a in planes]
    worst = 0.0
    for pc in e["pieces"]:
        m = trimesh.load(out / "stl" / f"{pc['name']}.stl")
        rot = np.array(pc["print_transform"]["rotation"])
        in_part = m.face_normals @ rot  # print = rot @ part: a normal back in the part frame
        on_cut = np.zeros(len(m.faces), bool)
        for n in cut_normals:
            on_cut |= np.abs(np.abs(in_part @ n) - 1.0) < 1e-4
        assert m.area_faces[on_cut].sum() > 1000.0  # the two cut faces, found on the mesh
        worst = max(worst, float(prusa.layer_height * np.abs(m.face_normals[on_cut, 2]).max()))
    assert rec["glue_face_step_mm"] == pytest.approx(worst, abs=1e-4)


def test_the_stock_covers_the_staircase_the_seam_step_and_a_leaf():
    """A seam glued on the gauge leaves one piece's surface up to the gauge's step behind the other's,
    and its staircase's valleys reach the staircase's bound behind that: sanding to the template leaves
    no valley only if the stock covers the bound + the step + one leaf (the template's check). The
    MK3S's figures: a 0.093 mm bound, the 3 mm template's 0.046 mm step."""
    step = S.step_on_gauge(3.0)
    assert step == pytest.approx(0.02 + 3.0 * math.tan(math.radians(0.5)), abs=1e-12)  # leaf + lean, closed form
    need = S.stock_needed(0.093, step)
    assert need == pytest.approx(0.093 + step + S.FEELER_LEAF, abs=1e-12)
    pin = S.float_pin(AlignmentPin(1.5, 0.15, 6.0), 0.1)
    assert S.seam_steps(pin, 0.1, need, 3.0, staircase=0.093)["fairs"] is True
    # planted: the stock equal to the staircase's bound (the old rule), and the bound + step without the
    # leaf, are refused, and the refusal names the key and the stock that would do
    for short in (0.093, 0.093 + step, need - 1e-4):
        rec = S.seam_steps(pin, 0.1, short, 3.0, staircase=0.093)
        assert rec["fairs"] is False, short
        (msg,) = S.problems("dome", {**rec, "glue_fills": True})
        assert "dome" in msg and "sanding_stock" in msg and f"{need:.3f}" in msg and "\n" not in msg, msg


def test_sanding_cannot_open_the_pin_holes():
    """Holes 1.03 mm behind the printed surface (the machinist's measure), a 0.159 mm stock and a leaf
    deeper: 0.851 mm of cover left, over the 0.6 mm floor; holes 0.7 mm behind are refused."""
    rec = S.pin_cover(1.03, 0.159)
    assert rec["pin_hole_cover_after_sanding_mm"] == pytest.approx(1.03 - 0.159 - S.FEELER_LEAF, abs=1e-12)
    assert rec["pins_stay_covered"] is True
    thin = S.pin_cover(0.7, 0.159)  # 0.521 mm left
    assert thin["pins_stay_covered"] is False
    (msg,) = S.problems("dome", {**thin, "fairs": True, "glue_fills": True, "stock_mm": 0.159})
    assert "pin holes" in msg and "sanding_stock" in msg, msg
    assert S.pin_cover(None, 0.159) == {}  # no pins: nothing to cover
