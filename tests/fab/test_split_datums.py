"""Datums off the seams: the split planner keeps its cut planes off every datum feature the parts
declare (dowel holes, the sample bore, the splitter seat, insert pockets), on every printer shipped;
the seams left between two datum features are listed; pin holes keep two perimeters of wall; every
insert pocket is its maker's hole and depth. The plans are made on the parts' meshes (about a second
a printer); whether a feature is cut is judged on the feature's own mesh, cell by cell, not by the
planner's boxes."""

from __future__ import annotations

import math
from pathlib import Path
from dataclasses import replace
from types import SimpleNamespace

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.export import mesh as M
from rigcad.fab import choice, orientation
from rigcad.fab import split as SP
from rigcad.fab.printers import load_printer
from rigcad.parts.joints import Datum
from rigcad.parts.recipe import Box, Cylinder
from rigcad.standards import INSERTS

ROOT = Path(__file__).resolve().parents[2]
PRINTERS = sorted(p.stem for p in (ROOT / "profiles" / "printers").glob("*.yaml"))


def _man(solid, chord):
    return M.build(solid, chord)


def _plan(rig, part, printer, keep=True):
    man = _man(part.solid, rig.profile.tessellation.chord_error)
    v, _ = M.mesh_arrays(man)
    ko = SP.keepouts(part.datums) if keep else ()
    return man, choice.split_plan(man, v, False, orientation.plate_axis(v), printer, ko)


def _cells(plan):
    if isinstance(plan, SP.GridPlan):
        return [lambda m, c=c: SP.grid_cell(m, plan, *c) for c in plan.cells()]
    return [lambda m, i=i, j=j: SP.cell(m, plan, i, j) for i in range(plan.sectors) for j in range(plan.bands)]


def _pieces_holding(feature: m3d.Manifold, plan) -> int:
    """How many of the plan's cells hold a part of ``feature`` (more than 1e-6 of its volume)."""
    v = feature.volume()
    return sum(cut(feature).volume() > 1e-6 * v for cut in _cells(plan))


@pytest.mark.parametrize("printer_name", PRINTERS)
def test_no_split_crosses_a_datum_feature_on_any_printer(table31_rig, printer_name):
    printer = load_printer(ROOT / "profiles" / "printers" / f"{printer_name}.yaml")
    chord = table31_rig.profile.tessellation.chord_error
    checked = 0
    for name, part in table31_rig.recipes.items():
        if not part.datums or part.bought:
            continue
        _, plan = _plan(table31_rig, part, printer)
        for d in part.datums:
            # the feature's own solid lies in one piece: no cut plane runs through it
            assert _pieces_holding(_man(d.shape, chord), plan) == 1, (printer_name, name, d.name, plan.describe())
            checked += 1
        assert SP.crossed(part.datums, plan) == [], (printer_name, name)
    assert checked == 13 + 9 + 4 + 4 + 2  # base plate, shelf, column, holder, the dome's two beam seats: every one judged


def test_equal_slabs_would_cut_the_sample_bore_and_the_dowels(table31_rig, prusa):
    """What the keep-outs change: on the MK3S the base plate's equal-slab grid cuts y = 0 through the
    sample bore and both tongue dowel holes (and the shelf's through its dowels); with them, it does not."""
    chord = table31_rig.profile.tessellation.chord_error
    for name, cut in (("base_plate", {"sample bore", "tongue dowel hole 1", "tongue dowel hole 2"}),
                      ("tower_shelf", {"shelf dowel hole 1", "shelf dowel hole 2"})):
        part = table31_rig.recipes[name]
        _, bare = _plan(table31_rig, part, prusa, keep=False)
        assert cut <= set(SP.crossed(part.datums, bare)), (name, bare.describe())
        d = next(d for d in part.datums if d.name in cut)
        assert _pieces_holding(_man(d.shape, chord), bare) == 2
        _, kept = _plan(table31_rig, part, prusa)
        assert kept.count == bare.count  # the same number of pieces: the cut moved, nothing was added


def test_a_grid_cut_moves_to_the_nearer_edge_of_a_keep_out():
    # a cut at 0 inside (-5, 3) moves to 3 (nearer), then -5; one outside every keep-out stays
    assert SP.clear_cuts((0.0,), -100.0, 100.0, [(-5.0, 3.0)]) == [(3.0,), (-5.0,)]
    assert SP.clear_cuts((10.0,), -100.0, 100.0, [(-5.0, 3.0)]) == [(10.0,)]
    # a move that would leave the part or put two cuts out of order is not offered
    assert SP.clear_cuts((0.0, 2.0), -100.0, 100.0, [(-5.0, 3.0)]) == [(-5.0, 3.0)]
    assert SP.clear_cuts((98.0,), -100.0, 99.0, [(95.0, 120.0)]) == [(95.0,)]
    boxes = SP.keepouts([Datum("d", "dowel", Cylinder((1.0, 0.0, 0.0), 2.0, 5.0))])
    # a cylinder of radius 2 at x = 1 grown by the margin on each side
    assert SP._blocked(boxes, 0) == [(-1.0 - SP.DATUM_MARGIN, 3.0 + SP.DATUM_MARGIN)]


def test_the_sector_phase_keeps_off_a_keep_out():
    tube = m3d.Manifold.cylinder(30.0, 50.0, 50.0, 96) - m3d.Manifold.cylinder(32.0, 35.0, 35.0, 96).translate((0, 0, -1))
    free = SP.choose_phase(tube, 4)
    feature = Datum("hole", "dowel", Cylinder((42.5 * math.cos(free), 42.5 * math.sin(free), -1.0), 2.0, 32.0))
    boxes = SP.keepouts([feature])
    phase = SP.choose_phase(tube, 4, keep_out=boxes)
    assert phase is not None and not any(SP._half_plane_crosses(phase + k * math.pi / 2, boxes) for k in range(4))
    assert SP._half_plane_crosses(free, boxes)  # the phase without it runs through the feature
    # a keep-out round the axis itself meets every half-plane: no sector split keeps off it
    assert SP.choose_phase(tube, 4, keep_out=SP.keepouts([Datum("bore", "bore", Cylinder((0, 0, -1), 5.0, 32.0))])) is None


def test_datum_seams_name_the_cuts_between_two_features():
    a = Datum("a", "dowel", Cylinder((-20.0, 0.0, 0.0), 1.0, 5.0))
    b = Datum("b", "bore", Cylinder((30.0, 25.0, 0.0), 5.0, 5.0))
    c = Datum("c", "seat", Box((-30.0, -2.0, 0.0), (-25.0, 2.0, 3.0)))
    plan = SP.GridPlan((0.0, 20.0), (10.0,))
    seams = SP.datum_seams([a, b, c], plan)
    assert seams == [
        {"between": ["a", "b"], "kinds": ["dowel", "bore"], "seams": ["x cut 0.0 mm", "x cut 20.0 mm", "y cut 10.0 mm"],
         "count": 3},
        {"between": ["b", "c"], "kinds": ["bore", "seat"], "seams": ["x cut 0.0 mm", "x cut 20.0 mm", "y cut 10.0 mm"],
         "count": 3}]  # a and c share a piece: no seam between them
    sectors = SP.SplitPlan(4, 1, math.radians(45.0), (0.0, 10.0))
    d = Datum("d", "dowel", Cylinder((40.0, 0.0, 0.0), 1.0, 5.0))  # in the sector 315..45 deg
    e = Datum("e", "dowel", Cylinder((0.0, -40.0, 0.0), 1.0, 5.0))  # in 225..315 deg: one plane between
    assert SP.datum_seams([d, e], sectors)[0]["seams"] == ["sector plane 315.0 deg"]


def test_pin_walls_are_two_perimeters_of_the_printers_line(prusa, vantage):
    assert SP.pin_wall(prusa) == pytest.approx(0.9)  # MK3S QUALITY preset's 0.45 mm perimeters, or 1.125 x 0.4
    assert SP.pin_wall(vantage) == pytest.approx(2 * 1.125 * 0.016 * 25.4)
    sla = SimpleNamespace(process="sla", nozzle=None)
    assert SP.pin_wall(sla) == SP.MIN_WALL


def test_the_base_plates_pins_keep_two_perimeters_and_state_their_fit(table31_rig, prusa):
    part = table31_rig.recipes["base_plate"]
    man, plan = _plan(table31_rig, part, prusa)
    pieces, pins, _ = SP.split_part(man, "base_plate", plan, prusa.alignment_pin, None, wall=SP.pin_wall(prusa))
    wall = 2 * 0.45  # two of the MK3S's 0.45 mm perimeters (0.60-0.90 mm walls before: drilling broke out)
    assert len(pins) >= 2 * 4  # two pins at least on each of the 2 x 2 grid's four faces
    for p in pins:
        r = p.hole_diameter / 2 + wall - 1e-3  # the hole widened by the wall, less rounding
        probe = SP._cylinder(np.array(p.axis), np.array(p.centre), r, prusa.alignment_pin.depth + wall - 1e-3)
        # all of it in the part: the material round the hole is at least the wall everywhere
        assert (probe - man).volume() < 1e-6 * probe.volume(), p
    fit = SP.pin_fit(prusa, pins)
    assert fit["class_after_drilling"] == "clearance" and fit["hole_drawn_mm"] == pytest.approx(1.9)
    floating = SP.pin_fit(prusa, pins, replace(prusa.alignment_pin, clearance=0.4))
    assert floating["class_after_drilling"] == "float (the glue fills it)" and floating["hole_drawn_mm"] == pytest.approx(2.15)
    assert fit["hole_as_printed_mm"] == pytest.approx(1.9 - fit["hole_shrink_mm"])
    assert "drill every pin hole 1.9 mm" in fit["step"]


def _ring(r0, r1, z0, z1, x, y):
    outer = m3d.Manifold.cylinder(z1 - z0, r1, r1, 96).translate((x, y, z0))
    return outer - m3d.Manifold.cylinder(z1 - z0 + 2, r0, r0, 96).translate((x, y, z0 - 1)) if r0 > 0 else outer


def test_every_insert_pocket_is_its_makers_hole_and_depth(table31_rig):
    """Probed on each part's mesh: inside the maker's hole (less 0.05 mm) no material down to the maker's
    depth (less 0.05), all material round it (0.05 to 0.6 mm out) over that depth, and a floor under it
    (a blind pocket: its insert cannot stand proud or sink past it)."""
    chord = table31_rig.profile.tessellation.chord_error
    found = 0
    for name, part in table31_rig.recipes.items():
        pockets = [d for d in part.datums if d.kind == "insert"]
        if not pockets:
            continue
        man = _man(part.solid, chord)
        for d in pockets:
            assert isinstance(d.shape, Cylinder)
            makers = [i for i in INSERTS.values() if math.isclose(2 * d.shape.radius, i.hole, abs_tol=1e-9)]
            assert makers, (name, d.name, 2 * d.shape.radius)
            ins = makers[0]
            x, y, zb = d.shape.base
            zt = zb + d.shape.height
            # the open end: no material round the shape's end there (it runs 1 mm past the face)
            top_open = (_ring(ins.hole / 2 + 0.05, ins.hole / 2 + 0.6, zt - 0.5, zt, x, y) ^ man).volume() < 1e-6
            face = zt - 1.0 if top_open else zb + 1.0
            sign = -1.0 if top_open else 1.0
            lo, hi = sorted((face, face + sign * (ins.pocket_depth - 0.05)))
            core = m3d.Manifold.cylinder(hi - lo, ins.hole / 2 - 0.05, ins.hole / 2 - 0.05, 96).translate((x, y, lo))
            assert (core ^ man).volume() < 1e-6, (name, d.name, "material in the pocket")
            wall = _ring(ins.hole / 2 + 0.05, ins.hole / 2 + 0.6, lo, hi, x, y)
            assert (wall - man).volume() < 1e-6 * wall.volume(), (name, d.name, "the pocket is wider or shallower")
            f0, f1 = sorted((face + sign * (ins.pocket_depth + 0.05), face + sign * (ins.pocket_depth + 0.3)))
            floor = _ring(1.75, ins.hole / 2 - 0.05, f0, f1, x, y)  # outside an M3 screw's 3.4 mm clearance hole
            assert (floor - man).volume() < 1e-6 * floor.volume(), (name, d.name, "no floor at the maker's depth")
            found += 1
    assert found >= 8 + 4 + 3  # the base plate's flange inserts, the shelf's, the splitter holder's
