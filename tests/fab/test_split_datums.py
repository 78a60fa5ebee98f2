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


ENDER = "Creality Ender-3 V2 (0.4 mm nozzle)"
#: The precision machinist's review: a glue seam at least 10 mm from the sample bore, which is bored
#: to its H7 fit after the pieces are glued (a figure from outside the code under test).
BORE_SEAM_FLOOR_MM = 10.0


def _printer(name):
    if name == ENDER:  # a printer by its PrusaSlicer preset name, when the slicer's bundle is installed
        from rigcad.fab import vendor

        if "Creality" not in vendor.available_bundles():
            pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
        return load_printer(ENDER)
    return load_printer(ROOT / "profiles" / "printers" / f"{name}.yaml")


def _cut_planes(plan):
    """The plan's cut planes as (unit normal, offset, radial or None): points p on one have n . p =
    offset (and, for a sector's half-plane, p . radial >= 0), mm."""
    out = []
    if isinstance(plan, SP.GridPlan):
        for a in range(3):
            out += [(np.eye(3)[a], float(c), None) for c in plan.cuts(a)]
        return out
    if plan.sectors > 1:
        for i in range(plan.sectors):
            a = plan.sector_range(i)[0]
            out.append((np.array([-math.sin(a), math.cos(a), 0.0]), 0.0, np.array([math.cos(a), math.sin(a), 0.0])))
    out += [(np.array([0.0, 0.0, 1.0]), float(z), None) for z in plan.band_z[1:-1]]
    return out


def _seam_faces(pieces, plan) -> np.ndarray:
    """The triangles (n, 3, 3) of the pieces' meshes that lie on a cut plane (to 1e-5 mm): the glue
    faces as cut, read off the pieces, not off the plan."""
    tris = []
    for pc in pieces:
        v, f = M.mesh_arrays(pc)
        t = np.asarray(v, float)[np.asarray(f)]
        for n, off, radial in _cut_planes(plan):
            on = np.all(np.abs(t @ n - off) < 1e-5, axis=1)
            if radial is not None:
                on &= np.all(t @ radial > -1e-5, axis=1)
            tris.append(t[on])
    return np.concatenate(tris) if tris else np.zeros((0, 3, 3))


def _point_triangle(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Least distance (mm) from each point p (n, 3) to the triangles t (m, 3, 3): to the plane where
    the foot lies inside a triangle, else to its nearest edge (closed forms, by hand: the only
    library that does this, trimesh's proximity, needs rtree, which the venv does not have)."""
    out = np.full(len(p), np.inf)
    a, b, c = t[:, 0], t[:, 1], t[:, 2]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    keep = area2 > 1e-12
    a, b, c, n, area2 = a[keep], b[keep], c[keep], n[keep] / area2[keep, None], area2[keep]

    def seg(q, u, w):  # q (k, 1, 3) to the segments u-w (1, m, 3)
        d = w - u
        s = np.clip(np.einsum("kmj,kmj->km", q - u, np.broadcast_to(d, (q.shape[0], *d.shape[1:])))
                    / np.maximum(np.einsum("mj,mj->m", d[0], d[0]), 1e-300), 0.0, 1.0)
        return np.linalg.norm(q - (u + s[..., None] * d), axis=2)

    for k in range(0, len(p), 64):
        q = p[k:k + 64, None, :]
        h = np.einsum("kmj,mj->km", q - a, n)
        foot = q - h[..., None] * n
        # the foot inside the triangle: each sub-triangle's normal points along n
        inside = np.ones(h.shape, bool)
        for u, w in ((a, b), (b, c), (c, a)):
            inside &= np.einsum("kmj,mj->km", np.cross(w - u, foot - u), n) >= 0.0
        d = np.where(inside, np.abs(h), np.inf)
        d = np.minimum(d, np.minimum(seg(q, a[None], b[None]), np.minimum(seg(q, b[None], c[None]), seg(q, c[None], a[None]))))
        out[k:k + 64] = d.min(axis=1)
    return out


def _distance(feature: m3d.Manifold, seams: np.ndarray) -> float:
    """The least distance (mm) between a feature's mesh and the seam faces: from each of the feature's
    vertices to the faces and from each face vertex to the feature's facets. The feature's vertices lie
    on the true feature, so this is at most its true distance plus the chord error of its facets."""
    v, f = M.mesh_arrays(feature)
    v = np.asarray(v, float)
    a = _point_triangle(v, seams).min()
    b = _point_triangle(np.unique(seams.reshape(-1, 3), axis=0), v[np.asarray(f)]).min()
    return float(min(a, b))


@pytest.mark.parametrize("printer_name", [*PRINTERS, ENDER])
def test_every_seam_keeps_its_margin_off_every_datum_feature_on_any_printer(table31_rig, printer_name):
    """On every printer shipped (and the Ender-3 V2 by preset name): each part with datum features is
    cut into its pieces; the glue faces found on the pieces' meshes keep at least the feature's
    split.datum_margin from each feature's own mesh, the sample bore at least the machinist's 10 mm,
    and each feature lies in one piece."""
    printer = _printer(printer_name)
    chord = table31_rig.profile.tessellation.chord_error
    checked, split_parts, nearest_bore = 0, 0, math.inf
    for name, part in table31_rig.recipes.items():
        if not part.datums or part.bought:
            continue
        man, plan = _plan(table31_rig, part, printer)
        assert SP.crossed(part.datums, plan) == [], (printer_name, name)
        if plan.count == 1:
            checked += len(part.datums)  # whole: no seam at all
            continue
        split_parts += 1
        cells = [cut(man) for cut in _cells(plan)]
        seams = _seam_faces([c for c in cells if not c.is_empty()], plan)
        area = 0.5 * np.linalg.norm(np.cross(seams[:, 1] - seams[:, 0], seams[:, 2] - seams[:, 0]), axis=1).sum()
        assert area > 100.0, (printer_name, name)  # the cut faces were found on the pieces (mm^2)
        for d in part.datums:
            feature = _man(d.shape, chord)
            # the feature's own solid lies in one piece: no cut plane runs through it
            assert _pieces_holding(feature, plan) == 1, (printer_name, name, d.name, plan.describe())
            gap = _distance(feature, seams)
            # its margin, less 1e-6 mm of rounding (the measured distance may exceed the true one by
            # the chord error, 0.018 mm, where a cut stands exactly at the margin: see _distance)
            assert gap >= SP.datum_margin(d) - 1e-6, (printer_name, name, d.name, gap, SP.datum_margin(d))
            if d.kind == "bore":
                assert gap >= BORE_SEAM_FLOOR_MM, (printer_name, name, d.name, gap)
                nearest_bore = min(nearest_bore, gap)
            checked += 1
    assert checked == 13 + 9 + 4 + 4 + 2  # base plate, shelf, column, holder, the dome's two beam seats: every one judged
    if printer_name in ("prusa_mk3s", ENDER):
        assert split_parts >= 2  # the base plate and the shelf are cut on the small beds: the measurement ran
        # the base plate's y cut at the 20 mm hub + 1 mm of glue off the bore; measured from the bore's
        # polygon, whose vertices may miss its extreme point by the polygon's sagitta (0.03 mm here)
        assert 21.0 - 1e-6 <= nearest_bore < 21.0 + 0.05, nearest_bore


def test_the_keep_out_round_a_hole_that_takes_a_fit_is_its_hub():
    """datum_margin: a hub twice the hole's diameter (a wall of half the diameter) plus the glue's
    1 mm round a bore, a dowel or a register pin's hole; the feature's 1 mm wall plus the glue's 1 mm
    round anything else, and never less than that."""
    bore = Datum("sample bore", "bore", Cylinder((0.0, 0.0, -10.0), 20.0, 12.0))
    assert SP.datum_margin(bore) == pytest.approx(20.0 + 1.0)  # 40 mm bore: 20 mm of hub wall, 1 mm of glue
    assert SP.datum_margin(bore) >= BORE_SEAM_FLOOR_MM
    assert SP.datum_margin(Datum("d", "dowel", Cylinder((0.0, 0.0, 0.0), 3.0, 5.0))) == pytest.approx(3.0 + 1.0)
    assert SP.datum_margin(Datum("d", "dowel", Cylinder((0.0, 0.0, 0.0), 0.5, 5.0))) == pytest.approx(2.0)
    assert SP.datum_margin(Datum("i", "insert", Cylinder((0.0, 0.0, 0.0), 2.5, 5.0))) == pytest.approx(2.0)
    assert SP.datum_margin(Datum("s", "seat", Box((0.0, 0.0, 0.0), (9.0, 9.0, 3.0)))) == pytest.approx(2.0)


def test_a_part_no_cut_can_keep_off_is_refused_naming_the_printer_and_the_key(prusa):
    """A 400 mm plate (larger than the MK3S's bed) whose 300 mm bore's keep-out covers all of it: no
    grid keeps off it, and the refusal names the printer, its build_volume key and the datum rule."""
    from rigcad.errors import FabricationError

    plate = m3d.Manifold.cube((400.0, 400.0, 5.0), True)
    v, _ = M.mesh_arrays(plate)
    bore = Datum("sample bore", "bore", Cylinder((0.0, 0.0, -3.5), 150.0, 7.0))
    free = choice.split_plan(plate, v, False, orientation.plate_axis(v), prusa)
    assert free.count > 1  # without the keep-out it splits
    with pytest.raises(FabricationError) as e:
        choice.split_plan(plate, v, False, orientation.plate_axis(v), prusa, SP.keepouts([bore]))
    msg = str(e.value)
    assert "prusa_mk3s" in msg and "build_volume" in msg and "datum_margin" in msg and "\n" not in msg, msg


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
    # a dowel hole of radius 2 at x = 1 grown by its hub's 2 mm wall and the glue's 1 mm on each side
    assert SP._blocked(boxes, 0) == [(-1.0 - 3.0, 3.0 + 3.0)]


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


def test_pin_walls_are_three_perimeters_of_the_printers_line_or_1_5_mm(prusa, vantage):
    # MK3S QUALITY preset's 0.45 mm perimeters x 3 = 1.35 mm; the Vantage's 3 x 1.125 x its 0.016 in nozzle = 1.37 mm:
    # both under the 1.5 mm floor (tests/fab/test_pin_walls.py measures them on the pieces)
    assert SP.pin_wall(prusa) == pytest.approx(1.5) and 3 * 0.45 < 1.5
    assert SP.pin_wall(vantage) == pytest.approx(1.5) and 3 * 1.125 * 0.016 * 25.4 < 1.5
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
