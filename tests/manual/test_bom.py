"""The bill of materials' arithmetic on hand-built inputs (no rig, no CAD; seconds): the ISO tables'
look-ups at their edges, bolt lengths summed by hand, areas of revolution against closed forms, the
coating stack's mid-surfaces, bolts found in recipes built here, the pins, the printed rows and the
purchased rows, each field and each line of text written out. The whole rig's bill (the fab stage's
report, the manual's files) is tested in test_manual.py."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.manual import bom as B
from rigcad.standards import THREADS
from rigcad.parts.recipe import Box, Cylinder, Difference, Part, Translate, Union_


# -- the ISO tables (their figures: rigcad.standards; tests/test_standards.py) ----------------------
def test_thread_for_hole_refuses_a_hole_under_m2_naming_the_profile_key():
    with pytest.raises(GeometryError) as e:
        B.thread_for_hole(2.4 - 1e-6)
    assert e.value.param == "dome_shell.bolt_diameter"
    assert str(e.value) == "a 2.4 mm hole takes no ISO metric bolt from M2 (2.4 mm clearance, ISO 273 medium) up"


def test_bolt_length_is_the_shortest_preferred_length_over_the_sum():
    m4 = THREADS["M4"]
    # grip + 2 washers (ISO 7089 M4: 0.8 mm) + nut (ISO 4032 M4: 3.2 mm) + 2 pitches (0.7 mm), by hand
    assert B.bolt_length(16.0, m4) == (25, pytest.approx(16 + 1.6 + 3.2 + 1.4, abs=1e-12))
    assert B.bolt_length(20.0 - 6.2, m4)[0] == 20  # need exactly 20
    assert B.bolt_length(20.0 - 6.2 + 1e-6, m4)[0] == 25
    assert B.bolt_length(0.0, m4)[0] == 8  # need 6.2: the shortest M4 that ISO 4762 sells of 6.2 mm or more
    with pytest.raises(GeometryError) as e:
        B.bolt_length(40.0, m4)  # 46.2 mm: past ISO 4762's longest M4 (40 mm)
    assert e.value.param == "base_plate.thickness"
    assert str(e.value) == ("M4 bolts of 46.2 mm are longer than the longest ISO 4762 length (40 mm): "
                            "the flange and plate are too thick")


# -- areas and the coating stack ------------------------------------------------------------------
class Segment:
    """A meridian (r, z) that is a straight segment, moved ``offset`` mm outward in r by behind()."""

    def __init__(self, a, b, offset=0.0):
        self.a, self.b, self.offset = np.asarray(a, float), np.asarray(b, float), offset
        self.calls = []

    def sample(self, count):
        self.calls.append(count)
        return np.linspace(0.0, 1.0, count)

    def points(self, u):
        p = self.a + np.outer(u, self.b - self.a)
        return p + np.array([self.offset, 0.0])

    def behind(self, distance):
        return Segment(self.a, self.b, self.offset + distance)


class Arc:
    """A quarter circle of radius R about the origin in (r, z): revolved, a hemisphere, 2 pi R^2."""

    def __init__(self, R):
        self.R = R

    def sample(self, count):
        return np.linspace(0.0, math.pi / 2, count)

    def points(self, u):
        return self.R * np.stack([np.cos(u), np.sin(u)], axis=1)


def test_revolved_area_of_a_frustum_and_a_hemisphere():
    # frustum r 3 -> 7 over a slant of 5 (dz = 3): pi (r1 + r2) L = 50 pi; the midpoint rule is exact on it
    m = Segment((3.0, 0.0), (7.0, 3.0))
    assert B.revolved_area(m) == pytest.approx(50 * math.pi, rel=1e-12)
    assert m.calls == [20001]
    # the mirror image (r < 0) sweeps the same surface
    assert B.revolved_area(Segment((-3.0, 0.0), (-7.0, 3.0)), samples=11) == pytest.approx(50 * math.pi, rel=1e-12)
    assert B.revolved_area(Segment((0.0, 0.0), (4.0, 3.0)), samples=2) == pytest.approx(20 * math.pi, rel=1e-12)
    exact = 2 * math.pi * 10.0 ** 2
    assert abs(B.revolved_area(Arc(10.0)) - exact) / exact < 1e-8  # second order: ~1e-9 at 20001 points
    coarse = abs(B.revolved_area(Arc(10.0), samples=101) - exact) / exact
    assert 1e-6 < coarse < 1e-4  # ~ (pi/2 / 100)^2 / 24: second order, not better


def _rig(layers, margin, recipes, tower=None):
    # no breadboard (datum.mount names none of parts.breadboard's): the rig stands on its own plate
    profile = SimpleNamespace(coating=SimpleNamespace(layers=layers, margin=margin),
                              datum=SimpleNamespace(mount="own base plate"), buy=SimpleNamespace(column="bought"))
    return SimpleNamespace(profile=profile, recipes=recipes, layout=SimpleNamespace(tower=tower))


def _part(name, solid=None, mirrors=(), in_rig=True):
    return Part(name, solid if solid is not None else Box((0, 0, 0), (1, 1, 1)), (0.5, 0.5, 0.5), name,
                in_rig=in_rig, mirrors=mirrors)


def test_each_coating_layer_is_measured_on_its_own_mid_surface():
    # a cylinder of radius 10 and height 20 whose parallel curves move outward: area 2 pi (10 + d) 20
    H = 20.0
    layers = [("base", 0.1), ("clear", 0.2), ("top", 0.05)]
    rig = _rig(layers, 1.5, {"cup": _part("cup", mirrors=(("inner", Segment((10.0, 0.0), (10.0, H))),
                                                          ("outer", Segment((30.0, 0.0), (30.0, H)))))})
    rows = B.coating_rows(rig)
    assert [(r.mirror, r.layer) for r in rows] == [(m, n) for m in ("inner", "outer") for n, _ in layers]
    tops = {"base": 0.25, "clear": 0.05, "top": 0.0}  # the layers above each, bottom to top
    for r in rows:
        t = dict(layers)[r.layer]
        R = (10.0 if r.mirror == "inner" else 30.0) + tops[r.layer] + t / 2
        area = 2 * math.pi * R * H
        assert r.part == "cup" and r.thickness_mm == t
        assert r.top_behind_design_mm == pytest.approx(tops[r.layer], abs=1e-15)
        assert r.area_mm2 == pytest.approx(area, rel=1e-12)
        assert r.film_cm3 == pytest.approx(area * t / 1000, rel=1e-12)
        assert r.to_buy_cm3 == pytest.approx(area * t / 1000 * 1.5, rel=1e-12)


# -- bolts found in recipes -----------------------------------------------------------------------
def _plate_and_flange():
    """A plate (z 0..6) and a flange above it (z 6..16, placed by a Translate), a 4 mm hole through
    both at (10, 20) (each hole 1 mm past the faces it crosses)."""
    plate = Difference(Box((0, 0, 0), (50, 50, 6)), (Cylinder((10.0, 20.0, -1.0), 2.0, 8.0),))
    flange = Translate(Difference(Box((0, 0, 0), (50, 50, 10)), (Cylinder((10.01 - 1, 20.0, -1.0), 2.0, 12.0),)),
                       (1.0, 0.0, 6.0))
    return plate, flange


def test_a_hole_through_two_parts_is_one_bolt_through_both():
    plate, flange = _plate_and_flange()
    rig = _rig([], 1.0, {"plate": _part("plate", plate), "flange": _part("flange", flange)})
    (b,) = B.bolt_axes(rig)
    assert b == {"parts": ("flange", "plate"), "upper": "flange",
                 "spans": {"flange": (6.0, 16.0), "plate": (0.0, 6.0)},
                 "x": 10.0, "y": 20.0, "top_z": 16.0, "bottom_z": 0.0, "grip_mm": 16.0, "hole_mm": 4.0}
    assert list(B._holes(plate)) == [(10.0, 20.0, -1.0, 7.0, 4.0, True)]
    assert list(B._holes(plate.base)) == []  # the plate's own body is no hole


def test_what_counts_as_a_bolt_hole():
    def holes(cut):
        return list(B._holes(Difference(Box((0, 0, 0), (90, 90, 9)), (cut,))))

    assert holes(Cylinder((0, 0, 0), 8.0, 5.0)) == [(0.0, 0.0, 0.0, 5.0, 16.0, True)]  # 16 mm: still a hole
    assert holes(Cylinder((0, 0, 0), 8.0 + 1e-9, 5.0)) == []
    assert holes(Box((0, 0, 0), (16, 4, 9))) == [(8.0, 2.0, 0.0, 9.0, 4.0, False)]  # a slot, its narrow width
    assert holes(Box((0, 0, 0), (4, 16, 9))) == [(2.0, 8.0, 0.0, 9.0, 4.0, False)]
    assert holes(Box((0, 0, 0), (16.5, 4, 9))) == [] and holes(Box((0, 0, 0), (4, 16.5, 9))) == []
    assert holes(Box((0, 0, 0), (4, 2, 16))) == []  # as deep as 4x its width: a channel, no bolt
    assert holes(Box((0, 0, 0), (4, 2, 15.9))) == [(2.0, 1.0, 0.0, 15.9, 2.0, False)]
    # a cut inside a union inside a translate, and a translate of the cut itself
    nested = Translate(Difference(Union_((Box((0, 0, 0), (9, 9, 9)), Cylinder((0, 0, 0), 1.0, 9.0))),
                                  (Union_((Translate(Cylinder((1, 2, 3), 1.5, 4.0), (10, 20, 30)),)),)),
                       (100, 200, 300))
    assert list(B._holes(nested)) == [(111.0, 222.0, 333.0, 337.0, 3.0, True)]
    # holes of a difference's base (a plate drilled, then cut again), moved with it; a cut whose own
    # base is a hole (a hole with a key left in it) is a hole; a slot moved off the origin
    drilled = Translate(Difference(Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((1, 2, 0), 1.0, 9.0),)),
                                   (Difference(Cylinder((5, 6, 0), 2.0, 9.0), (Box((5, 6, 0), (5.5, 6.5, 9)),)),
                                    Box((1, 2, 0), (4, 10, 9)))), (10, 20, 30))
    assert list(B._holes(drilled)) == [(11.0, 22.0, 30.0, 39.0, 2.0, True), (15.0, 26.0, 30.0, 39.0, 4.0, True),
                                       (12.5, 26.0, 30.0, 39.0, 3.0, False)]


def test_bolt_axes_split_a_stack_where_its_holes_stop_touching_and_skip_lone_slots():
    touching = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 0), 1.0, 5.0),
                                                      Cylinder((0, 0, 5.0 + 1e-7), 1.0, 5.0)))
    apart = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 0), 1.0, 5.0),
                                                   Cylinder((0, 0, 5.0 + 1e-5), 1.0, 5.0)))
    slot = Difference(Box((0, 0, 0), (9, 9, 9)), (Box((30, 30, 0), (34, 31, 9)),))
    assert [b["grip_mm"] for b in B.bolt_axes(_rig([], 1, {"a": _part("a", touching)}))] == \
        [pytest.approx(10 + 1e-7 - 2)]
    runs = B.bolt_axes(_rig([], 1, {"a": _part("a", apart)}))
    assert [(b["bottom_z"], b["top_z"]) for b in runs] == [(1.0, 4.0), (pytest.approx(6 + 1e-5), pytest.approx(9 + 1e-5))]
    assert B.bolt_axes(_rig([], 1, {"s": _part("s", slot)})) == []  # a slot of one part alone: no bolt
    # a slot in one part under a round hole in another is a bolt through both
    over = Difference(Box((0, 0, 9), (40, 40, 12)), (Cylinder((32, 30.5, 8), 0.5, 5.0),))
    (b,) = B.bolt_axes(_rig([], 1, {"s": _part("s", slot), "o": _part("o", over)}))
    assert b["parts"] == ("o", "s") and b["hole_mm"] == 1.0 and b["upper"] == "o"
    assert (b["x"], b["y"]) == (32.0, 30.5)  # the lowest hole's axis
    # parts left out of the rig, and the tower's unless asked for
    plate, flange = _plate_and_flange()
    rig = _rig([], 1, {"plate": _part("plate", plate), "tower_column": _part("tower_column", flange),
                       "jig": _part("jig", flange, in_rig=False)})
    assert [b["parts"] for b in B.bolt_axes(rig)] == [("plate",)]
    assert [b["parts"] for b in B.bolt_axes(rig, tower=True)] == [("plate", "tower_column")]


def test_holes_on_axes_0_5_mm_apart_are_separate_bolts_and_a_stack_is_ordered_by_its_bottoms():
    def hole(x, y, z0, z1, r=1.0):
        return Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((x, y, z0), r, z1 - z0),))

    rig = _rig([], 1, {"a": _part("a", hole(0, 0, 0, 5)), "b": _part("b", hole(0, 0.5, 0, 5)),
                       "c": _part("c", hole(0.5, 0, 0, 5))})
    assert sorted((b["x"], b["y"], b["parts"]) for b in B.bolt_axes(rig)) == [
        (0.0, 0.0, ("a",)), (0.0, 0.5, ("b",)), (0.5, 0.0, ("c",))]
    # a long hole (0..10) holding two short ones (2..3, 5..6): one run, whatever order their tops come in
    long_ = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 0), 1.0, 10.0), Cylinder((0, 0, 2), 1.0, 1.0)))
    rig = _rig([], 1, {"p": _part("p", long_), "q": _part("q", hole(0, 0, 5, 6))})
    (b,) = B.bolt_axes(rig)
    assert b["parts"] == ("p", "q") and (b["bottom_z"], b["top_z"]) == (1.0, 9.0)
    # the same bottom: the first by name gives the axis
    rig = _rig([], 1, {"b": _part("b", hole(10.0, 0, 0, 5)), "a": _part("a", hole(10.01, 0, 0, 6))})
    (b,) = B.bolt_axes(rig)
    assert (b["x"], b["upper"]) == (10.01, "a")
    # a hole starting exactly at the margin above the last top still joins it
    edge = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 0), 1.0, 5.0),
                                                  Cylinder((0, 0, 5.0 + 1e-6), 1.0, 5.0)))
    assert len(B.bolt_axes(_rig([], 1, {"e": _part("e", edge)}))) == 1
    # a lone slot under a separate round hole on its axis: the slot is skipped, the hole still a bolt
    slot_then_hole = Difference(Box((0, 0, 0), (9, 9, 30)), (Box((0, 0, 0), (4, 2, 9)),
                                                             Cylinder((2, 1, 20), 1.0, 5.0)))
    (b,) = B.bolt_axes(_rig([], 1, {"s": _part("s", slot_then_hole)}))
    assert (b["parts"], b["bottom_z"], b["top_z"]) == (("s",), 21.0, 24.0)


def test_bolts_are_grouped_by_grip_to_the_micrometre_and_by_hole():
    def pair(x, top, r=2.0):
        lower = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((x, 0, -1), r, 8.0),))
        upper = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((x, 0, 5), r, top - 4),))
        return lower, upper

    parts = {}
    for k, (x, top, r) in enumerate([(0, 17.0, 2.0), (20, 17.0004, 2.0), (40, 17.4, 2.0), (60, 17.0, 2.25),
                                     (80, 17.0, 2.0002)]):
        lo, up = pair(x, top, r)
        parts[f"lo{k}"], parts[f"up{k}"] = lo, up
    lower = Difference(Box((0, 0, 0), (99, 9, 9)), tuple(c for k in range(5) for c in parts[f"lo{k}"].cuts))
    upper = Difference(Box((0, 0, 0), (99, 9, 9)), tuple(c for k in range(5) for c in parts[f"up{k}"].cuts))
    rows = B.bolt_joints(_rig([], 1, {"lower": _part("lower", lower), "upper": _part("upper", upper)}))
    assert [(r["count"], r["thread"], round(r["grip_mm"], 4)) for r in rows] == [
        (3, "M3", 17.0), (1, "M4", 17.0), (1, "M3", 17.4)]  # holes the same to the micrometre: one joint


def test_the_upper_part_is_the_one_whose_hole_reaches_highest_the_name_breaking_ties():
    a = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 0), 1.0, 5.0),))
    b = Difference(Box((0, 0, 0), (9, 9, 9)), (Cylinder((0, 0, 4), 1.0, 1.0),))  # same top, higher bottom
    (bolt,) = B.bolt_axes(_rig([], 1, {"b": _part("b", b), "a": _part("a", a)}))
    assert bolt["upper"] == "b" and bolt["spans"] == {"a": (1.0, 4.0), "b": (5.0, 4.0)}
    assert bolt["bottom_z"] == 1.0 and bolt["top_z"] == 4.0


def _joints_rig():
    """Two through bolts of 16 mm grip (4 mm holes: M3) and one of 10 mm between plate and flange,
    and a lone 5.5 mm hole (M5) of the plate into the bench."""
    plate = Difference(Box((0, 0, 0), (90, 90, 6)), (Cylinder((50, 50, -1), 2.75, 8.0),
                                                     Cylinder((0, 0, -1), 2.0, 8.0), Cylinder((20, 0, -1), 2.0, 8.0),
                                                     Cylinder((40, 0, -1), 2.0, 8.0)))
    flange = Difference(Box((0, 0, 6), (90, 90, 16)), (Cylinder((0, 0, 5), 2.0, 12.0), Cylinder((20, 0, 5), 2.0, 12.0),
                                                       Cylinder((40, 0, 5), 2.0, 6.0)))
    return _rig([], 1, {"plate": _part("plate", plate), "flange": _part("flange", flange)})


def test_bolt_joints_group_and_size_each_bolt():
    rows = B.bolt_joints(_joints_rig())
    assert [(r["parts"], r["grip_mm"], r["count"]) for r in rows] == \
        [(("flange", "plate"), 10.0, 1), (("flange", "plate"), 16.0, 2), (("plate",), 6.0, 1)]
    short, long_, alone = rows
    # M3 (4 mm hole, 3.4 mm clearance): 16 + 2 x 0.5 + 2.4 + 2 x 0.5 = 20.4 -> 25; 10 + 4.4 = 14.4 -> 16
    assert long_ == {"parts": ("flange", "plate"), "grip_mm": 16.0, "hole_mm": 4.0, "count": 2, "thread": "M3",
                     "joins": "flange + plate", "item": "M3 x 25 mm socket-head bolt (ISO 4762)",
                     "short": "M3 x 25 mm bolts", "length_mm": 25, "nuts": 2, "washers": 4,
                     "note": "needs 20.4 mm: 16 mm grip + 2 washers + nut 2.4 mm + 2 pitches"}
    assert short["length_mm"] == 16 and short["item"] == "M3 x 16 mm socket-head bolt (ISO 4762)"
    assert alone == {"parts": ("plate",), "grip_mm": 6.0, "hole_mm": 5.5, "count": 1, "thread": "M5",
                     "joins": "plate to what it stands on",
                     "item": "M5 bolt, length to suit (passes 6 mm of plate)", "short": "M5 bolts",
                     "length_mm": None, "nuts": 0, "washers": 1,
                     "note": "into the bench (or what the part stands on): choose its length on site"}


def test_fasteners_add_nuts_and_washers_per_thread_and_the_towers_own(monkeypatch):
    rig = _joints_rig()
    rows = B.fasteners(rig)
    assert rows == [
        {"item": "M3 x 16 mm socket-head bolt (ISO 4762)", "short": "M3 x 16 mm bolts", "quantity": 1,
         "use": "flange + plate", "length_mm": 16, "thread": "M3",
         "note": "needs 14.4 mm: 10 mm grip + 2 washers + nut 2.4 mm + 2 pitches"},
        {"item": "M3 x 25 mm socket-head bolt (ISO 4762)", "short": "M3 x 25 mm bolts", "quantity": 2,
         "use": "flange + plate", "length_mm": 25, "thread": "M3",
         "note": "needs 20.4 mm: 16 mm grip + 2 washers + nut 2.4 mm + 2 pitches"},
        {"item": "M5 bolt, length to suit (passes 6 mm of plate)", "short": "M5 bolts", "quantity": 1,
         "use": "plate to what it stands on", "length_mm": None, "thread": "M5",
         "note": "into the bench (or what the part stands on): choose its length on site"},
        {"item": "M3 hex nut (ISO 4032)", "short": "M3 nuts", "quantity": 3, "use": "one per through bolt",
         "length_mm": None, "note": "2.4 mm high"},
        {"item": "M3 washer (ISO 7089)", "short": "M3 washers", "quantity": 6, "use": "under each bolt head and nut",
         "length_mm": None, "note": "0.5 mm thick"},
        {"item": "M5 washer (ISO 7089)", "short": "M5 washers", "quantity": 1, "use": "under each bolt head and nut",
         "length_mm": None, "note": "1 mm thick"},
    ]
    assert B.tower_hardware(rig) == []  # no tower in this layout
    assert B.tower_hardware(SimpleNamespace(layout=SimpleNamespace())) == []  # a layout that knows no tower
    import rigcad.parts.tower as T

    seen = []

    def hardware(profile, layout):
        seen.append((profile, layout))
        return [{"thread": "M4", "length_mm": 12.0, "item": "button-head screw", "quantity": 3, "joins": "shelf + column"},
                {"thread": "1/4-20", "item": "camera screw", "quantity": 1, "joins": "camera"},
                {"thread": None, "item": "dowel pin", "diameter_mm": 4.0, "length_mm": 12.0, "quantity": 4,
                 "joins": "shelf", "steps": ("tower_shelf",)},
                {"thread": None, "item": "focusing lens", "spec": "f = 200 mm", "quantity": 1, "joins": "lens"}]

    monkeypatch.setattr(T, "hardware", hardware)
    rig.layout.tower = SimpleNamespace(column_x=500.0)  # a bought column: its core screw's axis, far off
    # every row but the optics (the purchased table's), the thread-less ones too
    assert [h["item"] for h in B.tower_hardware(rig)] == ["button-head screw", "camera screw", "dowel pin"]
    assert seen == [(rig.profile, rig.layout)]
    tower = B.fasteners(rig)[-3:]
    assert tower == [
        {"item": "M4 x 12 mm button-head screw", "short": "M4 x 12 mm button-head screw", "quantity": 3,
         "use": "shelf + column", "length_mm": 12.0, "note": "COP tower (parts.tower.hardware)", "thread": "M4",
         "tower": True, "steps": []},
        {"item": "camera screw (1/4-20)", "short": "camera screw (1/4-20)", "quantity": 1, "use": "camera",
         "length_mm": None, "note": "COP tower (parts.tower.hardware)", "thread": "1/4-20", "tower": True, "steps": []},
        {"item": "dowel pin, 4 x 12 mm", "short": "dowel pin, 4 x 12 mm", "quantity": 4, "use": "shelf",
         "length_mm": 12.0, "note": "COP tower (parts.tower.hardware)", "thread": None, "tower": True,
         "steps": ["tower_shelf"]}]


# -- pins, printed pieces, purchased items ----------------------------------------------------------
def _printer(filament=None, **kw):
    p = SimpleNamespace(alignment_pin=SimpleNamespace(diameter=1.75, depth=6.0, clearance=0.15),
                        source="printers/x.yaml", **kw)
    if filament is not None:
        p.filament_diameter = filament
    return p


def test_dowel_pins_count_per_part_times_its_quantity():
    report = {"parts": {"plate": {"pins": [1, 2, 3], "quantity": 2, "pin_fit": {"hole_drawn_mm": 1.9}},
                        "dome": {"pins": [1], "pin_fit": {"hole_drawn_mm": 2.1}},
                        "tool": {"pins": []}, "arm": {}}}
    pins = B.dowel_pins(report, _printer())
    note = ("holes 1.9 mm (plate), 2.1 mm (dome) x 6 mm deep into each piece (alignment_pin in printers/x.yaml; a "
            "split mirror's wider: its seams are glued on a gauge)")
    assert pins == {"item": "dowel pin 1.75 mm x 11.5 mm", "quantity": 7, "diameter_mm": 1.75, "length_mm": 11.5,
                    "per_part": {"plate": 6, "dome": 1}, "use": "plate: 6, dome: 1", "note": note,
                    "by_diameter_mm": {"1.75": 7}}
    assert B.dowel_pins(report, _printer(filament=1.75))["note"] == note + "; cut from the printer's own filament"
    assert B.dowel_pins(report, _printer(filament=2.85))["note"] == pins["note"]
    assert B.dowel_pins(report, _printer(filament=0.0))["note"] == pins["note"]  # no filament diameter
    none = _printer()
    none.filament_diameter = None
    assert B.dowel_pins(report, none)["note"] == pins["note"]
    assert B.dowel_pins({"parts": {"a": {"pins": []}, "b": {}}}, _printer()) is None
    thin = {"parts": {"plate": {"pins": [{"diameter_mm": 1.75}] * 3, "quantity": 2},
                      "dome": {"pins": [{"diameter_mm": 1.5}] * 4}}}  # a thin shell takes thinner pins
    two = B.dowel_pins(thin, _printer())
    assert two["by_diameter_mm"] == {"1.75": 6, "1.5": 4} and two["quantity"] == 10
    assert two["item"] == "dowel pins 11.5 mm long: 6 x 1.75 mm and 4 x 1.5 mm"
    assert B.dowel_pins(thin, _printer(filament=1.75))["note"].endswith(
        "the 1.75 mm ones cut from the printer's own filament, the others bought")
    assert B.dowel_drills(report) == ("HSS twist drills (DIN 338) for the pin holes: 1.9 mm (plate), 2.1 mm (dome)",
                                      "1 each")
    # with the rig, the COP tower's dowels' reamer at datum.dowel_diameter (it said 4 mm whatever the profile)
    from types import SimpleNamespace

    rig = SimpleNamespace(profile=SimpleNamespace(datum=SimpleNamespace(dowel_diameter=5.0)),
                          layout=SimpleNamespace(tower=object()))
    from rigcad.parts.locating import reamers

    assert B.dowel_drills(report, rig)[0].endswith(f"; for the column's dowel holes {reamers(5.0)}")
    assert "5 mm" in reamers(5.0)
    assert "reamer" not in B.dowel_drills(report, SimpleNamespace(profile=rig.profile, layout=SimpleNamespace(tower=None)))[0]


def test_each_glue_the_seams_need_is_listed_once_with_its_parts():
    report = {"parts": {"plate": {"seams": {"glue": "cyanoacrylate glue, thin"}}, "shelf": {"seams": {"glue": "cyanoacrylate glue, thin"}},
                        "dome": {"seams": {"glue": "two-part epoxy (e.g. Loctite EA 3430)"}}, "arm": {}}}
    assert B.glue_rows(report) == [("Cyanoacrylate glue, thin, for the cut faces and pins of plate, shelf", "1"),
                                   ("Two-part epoxy (e.g. Loctite EA 3430), for the cut faces and pins of dome", "1")]


def _piece(t, g, orientation, gcode=None):
    pc = {"estimate": {"print_time_s": t, "material_g": g}, "orientation": orientation}
    if gcode is not None:
        pc["gcode"] = {"estimates": gcode}
    return pc


def test_printed_rows_take_the_slicers_figures_only_when_every_piece_has_them():
    recipes = {"plate": _part("plate"), "jig": _part("jig", in_rig=False)}
    rig = _rig([], 1, recipes)
    report = {"parts": {
        "plate": {"quantity": 2, "process": "FDM", "pieces": [
            _piece(100.0, 5.0, "flat", {"print_time_s": 1000.0, "filament_g": 50.0}),
            _piece(200.0, 7.0, "upright", {"print_time_s": 3000.0, "filament_g": None})]},
        "jig": {"quantity": 1, "process": "FDM", "pieces": [
            _piece(100.0, 5.0, "flat", {"print_time_s": 1000.0, "filament_g": 50.0}), _piece(200.0, 7.0, "flat")]},
        "extra": {"quantity": 3, "process": "laser", "plate_thickness_mm": 3.0, "outline_size_mm": (120.04, 80.26)},
        "broken": {"error": "too big"}}}
    report["parts"]["plain"] = {"quantity": 1, "process": "FDM", "pieces": [{**_piece(5.0, 1.0, "flat"), "gcode": {}}]}
    first = {"parts": {"broken": report["parts"]["broken"], "plate": report["parts"]["plate"]}}
    assert [r["part"] for r in B.printed(rig, first)] == ["broken", "plate"]  # an error row, then the others
    plate, jig, extra, broken, plain = B.printed(rig, report)
    assert plain["source"] == "rigcad estimate" and plain["time_s"] == 5.0  # G-code without estimates
    # sliced: the slicer's times and grams (the estimate's grams where the slicer gave none), times quantity
    assert plate == {"part": "plate", "use": "rig", "quantity": 2, "process": "FDM", "pieces": 2,
                     "time_s": 8000.0, "material_g": 114.0, "source": "slicer", "note": "flat, upright"}
    # one piece without G-code: every figure is rigcad's estimate
    assert jig == {"part": "jig", "use": "tool", "quantity": 1, "process": "FDM", "pieces": 2,
                   "time_s": 300.0, "material_g": 12.0, "source": "rigcad estimate", "note": "flat"}
    assert extra == {"part": "extra", "use": "tool", "quantity": 3, "process": "laser", "pieces": 0, "time_s": None,
                     "material_g": None, "source": None,
                     "note": "3 mm plate, outline 120.0 x 80.3 mm (fab outlines/extra.dxf, .svg)"}
    assert broken == {"part": "broken", "use": "tool", "quantity": None, "process": "not printable", "note": "too big"}
    report["parts"]["plate"]["pieces"][1]["gcode"]["estimates"]["print_time_s"] = 0.0  # no time: not sliced
    assert B.printed(rig, report)[0]["source"] == "rigcad estimate"
    assert B.printed(rig, report)[0]["time_s"] == 600.0


@dataclass(frozen=True)
class Camera:
    focal: float = field(default=12.5, metadata={"spec": SimpleNamespace(kind="length", doc="lens focal length")})
    fov: float = field(default=0.5, metadata={"spec": SimpleNamespace(kind="angle", doc="Assumed field of view")})
    resolution: tuple = field(default=(1920, 1080), metadata={"spec": SimpleNamespace(kind="pixels", doc=None)})
    name: str | None = field(default=None, metadata={"spec": SimpleNamespace(kind="text", doc="")})
    bands: tuple = field(default=(1, 2), metadata={})
    model: str = "X-1"
    mount_thread: str = "M6"


def test_purchased_rows_describe_every_field_with_its_unit():
    asked = []

    def where(section, key):
        asked.append((section, key))
        return "p.yaml:3" if section == "camera" else None

    profile = SimpleNamespace(camera=Camera(), lens=Camera(focal=1234.5678, name="L"), projector=None, where=where)
    rows = B.purchased(SimpleNamespace(profile=profile))
    fov = f"fov {0.5 * 180 / math.pi:.4g} deg (assumed)"
    assert fov == "fov 28.65 deg (assumed)"
    assert rows == [
        {"item": "camera", "quantity": 1, "source": "p.yaml:3",
         "spec": f"focal 12.5 mm; {fov}; resolution 1920 x 1080 px; bands [1, 2]; model X-1; mount thread M6"},
        {"item": "focusing lens", "quantity": 1, "source": "default",
         "spec": f"focal 1235 mm; {fov}; resolution 1920 x 1080 px; name L; bands [1, 2]; model X-1; mount thread M6"}]
    assert asked == [("camera", "focal"), ("lens", "focal")]
    profile.beam_splitter = profile.splitter = profile.projector = Camera()
    rows = B.purchased(SimpleNamespace(profile=profile))
    assert [r["item"] for r in rows] == ["projector", "camera", "plate beam splitter", "splitter", "focusing lens"]



def test_the_bill_sums_the_coating_by_layer_and_measures_each_mirror():
    layers = [("base", 0.1), ("top", 0.05)]
    a, b = Segment((10.0, 0.0), (10.0, 20.0)), Segment((5.0, 0.0), (5.0, 4.0))
    rig = _rig(layers, 2.0, {"cup": _part("cup", mirrors=(("inner", a),)), "lid": _part("lid", mirrors=(("top", b),))})
    rig.profile.where = lambda *k: None
    report = {"parts": {"cup": {"quantity": 1, "process": "FDM", "pieces": [_piece(10.0, 1.0, "flat")]}},
              "totals": {"time_s": 10.0}}
    pinned = {"parts": {"cup": {**report["parts"]["cup"], "pins": [1, 2]}}}
    assert B.bill(rig, pinned, _printer())["pins"] == B.dowel_pins(pinned, _printer()) != None  # noqa: E711
    doc = B.bill(rig, report, _printer())
    coats = B.coating_rows(rig)
    assert doc["coating_by_mirror"] == [c.__dict__ for c in coats]
    for name, t in layers:
        mine = [c for c in coats if c.layer == name]
        assert doc["coating"][[r["layer"] for r in doc["coating"]].index(name)] == {
            "layer": name, "thickness_mm": t, "film_cm3": pytest.approx(sum(c.film_cm3 for c in mine), rel=1e-12),
            "to_buy_cm3": pytest.approx(sum(c.to_buy_cm3 for c in mine), rel=1e-12),
            "area_mm2": pytest.approx(sum(c.area_mm2 for c in mine), rel=1e-12)}
    assert [r["layer"] for r in doc["coating"]] == ["base", "top"]
    assert doc["mirrors"] == [{"mirror": "inner", "part": "cup", "design_area_mm2": pytest.approx(400 * math.pi)},
                              {"mirror": "top", "part": "lid", "design_area_mm2": pytest.approx(40 * math.pi)}]
    assert doc["coating_margin"] == 2.0 and doc["totals"] == {"time_s": 10.0} and doc["pins"] is None
    assert doc["printed"] == B.printed(rig, report) and doc["fasteners"] == [] and doc["purchased"] == []
    assert B.bill(rig, {"parts": {}}, _printer())["totals"] == {}


def test_feeler_gauge_names_the_leaves_the_gaps_need():
    assert B.feeler_gauge([0.0449, 0.02, 0.0151, 0.046, 0.3, 0.3001]) == (
        "Feeler gauge set 0.02-1.00 mm in 0.01 mm steps (DIN 2275); leaves used: 0.02, 0.04, 0.05, 0.30 mm", "1")
    assert B.feeler_gauge([0.031, 0.032]) == (  # one 0.03 leaf for both
        "Feeler gauge set 0.02-1.00 mm in 0.01 mm steps (DIN 2275); leaves used: 0.03 mm", "1")
    assert B.feeler_gauge([0.019999]) == (
        "Feeler gauge set 0.02-1.00 mm in 0.01 mm steps (DIN 2275); leaves used: none (check against the light)", "1")


def test_the_bill_names_the_focusing_lens_by_its_focal_length(table31_rig):
    from rigcad.optics.focus import focusing_lens

    (row,) = [r for r in B.purchased(table31_rig) if r["item"] == "focusing lens"]
    f = focusing_lens(table31_rig.profile, table31_rig.geometry)
    # the lens re-images the projector focused at its nearest into the paraboloid's span (thin lens, eq. 1)
    s = table31_rig.profile.lens.distance
    u = 1.0 / (1.0 / f.focal_length + 1.0 / (f.focus_near - s))
    assert u == pytest.approx(f.image_near, rel=1e-9)
    assert f"f = {f.focal_length:g} mm" in row["spec"] and "plano-convex" in row["spec"]
    assert "curved side towards the projector" in row["spec"]
    (row,) = [r for r in B.purchased(table31_rig) if r["item"].startswith("plate beam splitter")]
    assert "coated face towards the projector" in row["spec"]


def test_the_bill_has_a_conical_spring_washer_for_every_screw_the_torque_table_marks(table31_rig):
    """Section 5's torque table puts a spring washer under the joints that locate a datum; the bill
    lists one per screw of those joints, per thread (the machinist found none in the bill)."""
    from pathlib import Path

    from rigcad.fab import loads as L
    from rigcad.fab.printers import load_printer
    from rigcad.manual.document import _spring_washers

    prusa = load_printer(Path(__file__).resolve().parents[2] / "profiles" / "printers" / "prusa_mk3s.yaml")
    rows = _spring_washers(table31_rig, prusa)
    marked = [b for b in L.loads(table31_rig.profile, table31_rig.layout, prusa).bolts if b.spring_washer]
    assert marked and sum(r["quantity"] for r in rows) == sum(b.count for b in marked)
    assert all("DIN 6796" in r["item"] for r in rows)
    assert {r["item"].split(" ")[0] for r in rows} == {b.thread for b in marked}


def test_the_print_section_asks_for_the_printed_stage_template_the_seams_are_glued_on():
    """The dome's seams are glued on its printed-stage template (rigcad.fab.seams): the print section's
    cut list names its outline when the fab run wrote one, and not when it did not."""
    from rigcad.manual.document import _cut_line

    e = {"plate_thickness_mm": 3.0, "stages": {"printed": {"files": {"outlines/dome_template_printed.dxf": "x",
                                                                     "outlines/dome_template_printed.svg": "y"}}}}
    assert "`outlines/dome_template_printed.dxf`" in _cut_line("dome_template", e)
    assert "printed stage" not in _cut_line("dome_template", {"plate_thickness_mm": 3.0, "stages": {"printed": {"note": "n"}}})


def test_the_bills_washers_and_nuts_are_the_sum_of_every_bolt_rows_stack(table31_rig):
    """The machinist counted 18 M4 large washers in the bill's own rows against 16 ordered, 8 M4 nuts
    against 6, and no M5/M10 large washer under the projector's and camera's screws though the torque
    table assumes them. The bill's lines are summed here from the rows themselves: the dome's declared
    joint, every tower row's washers/nuts per bolt, one washer stack per instrument foot."""
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes
    from rigcad.parts import tower
    from rigcad.parts.joints import ScrewJoint
    from rigcad.parts.washers import large, plain

    rig = table31_rig
    steps = plan.steps(rig, picture_meshes(rig))[0]
    rows = plan.bill_hardware(rig, steps, {"fasteners": B.fasteners(rig), "pins": None})
    line = {r["item"]: r["quantity"] for r in rows if r["steps"] == ["with the bolts above"]}
    hw = [h for h in tower.hardware(rig.profile, rig.layout) if h.get("thread")]
    joints = [j for p in rig.recipes.values() for j in p.joints if isinstance(j, ScrewJoint)]
    feet = {k: [h for h in hw if k in h] for k in ("for_stacks_of_shims", "for_camera_stacks_of_shims")}
    fixed = [h for h in hw if not any(k in h for k in feet)]

    def n_large(size: str) -> int:
        name = large(size).name()
        n = sum(j.count for j in joints if name in j.washer_spec)
        n += sum(h["quantity"] * h.get("washers", []).count(name) for h in fixed)
        return n + sum(max(h["quantity"] for h in hs) * hs[0]["washers"].count(name) for hs in feet.values() if hs)

    for size in ("M4", "M5", "M6", "M10"):
        bill_line = f"{size} large washer (ISO 7093-1, {large(size).outer:g} mm outside, {large(size).thickness:g} mm)"
        assert line.get(bill_line, 0) == n_large(size) > 0, (size, line)
    # the review's own count: 8 dome + 4 column top + 4 foot + 2 lens mount + 4 projector feet
    assert line["M4 large washer (ISO 7093-1, 12 mm outside, 1 mm)"] == 22
    nuts = sum(h.get("nuts", 0) * h["quantity"] for h in fixed) + sum(j.count for j in joints if j.into == "nut")
    assert line["M4 hex nut (ISO 4032)"] == nuts == 8  # 4 traps, 2 lens mount, 2 spring bolts
    # every plain washer: the spring bolts' two, the lens mount's nut's one, the instruments' extra ones
    m4 = f"M4 washer (ISO 7089, {plain('M4').outer:g} mm outside, {plain('M4').thickness:g} mm)"
    assert line[m4] == sum(h.get("plain_washers", 0) * h["quantity"] for h in fixed) + 4 * max(
        r["extra_washers"] or 0 for r in tower.projector_screws(rig.profile, rig.layout))
    assert not any(k.endswith("washer (ISO 7089)") or "large washer (ISO 7093)" == k[3:] for k in line)  # old words
    # the steps fit the screws with the stack the torque table assumes, not "a washer" that drops through
    fitted = {st.name: {f.item for f in st.fasteners} for st in steps}
    for step, big in (("projector_body", "M5"), ("camera_body", "M10")):
        assert fitted[step] and all(f"on {large(big).name()}" in item for item in fitted[step]), fitted[step]


def test_the_stop_pin_is_a_slip_fit_in_retaining_compound_over_a_floor(table31_rig):
    """The beam's stop pin: pressed N7/m6 into a 6 mm beam's 1.5 mm walls it loaded the plastic to ~58 % of
    yield, and its blind hole ended 0.5 mm over the underside (the drill broke through). Now: a slip fit
    (at most the m6/F7 tables' 2 um of interference) set in retaining compound, a floor of at least
    PIN_FLOOR_MM under the hole as the beam is cut, and the compound and the slip reamer in the bill."""
    from rigcad.parts.paraboloid import PIN_FLOOR_MM, hardware, mount
    from rigcad.parts.recipe import bounds

    rig = table31_rig
    m = mount(rig.profile, rig.layout)
    lo, _ = bounds(m.pin_hole)
    floor = lo[2] - rig.layout.beam_z[0]  # the hole's bottom over the beam's underside
    assert floor >= PIN_FLOOR_MM - 1e-9 and PIN_FLOOR_MM >= 1.0, floor
    assert floor == pytest.approx(m.pin_floor, abs=1e-9)
    (row,) = [h for h in hardware(rig.profile, rig.layout) if h["item"].startswith("dowel pin")]
    assert "slip fit" in row["item"] and "retaining compound" in row["joins"] and "press" not in row["joins"]
    assert f"its floor, {m.pin_floor:g} mm" in row["joins"]
    d = 2 * m.pin.radius
    from rigcad.parts.locating import slip_fit

    assert slip_fit(d).clearance[0] >= -0.002 - 1e-12  # ISO 286 F7/m6 at 3 mm: -0.002..+0.014 mm
    assert any(c[0].startswith("Retaining compound") and "stop pin" in c[0] for c in B.CONSUMABLES)
    assert f"{d:g} mm {slip_fit(d).hole} hand reamer" in B.dowel_drills({"parts": {}}, rig)[0]


def test_the_tools_and_consumables_the_shop_steps_name_have_bill_lines(table31_rig):
    """The lab review found steps naming a lathe, a boring bar, a micrometer, an airbrush, cyanoacrylate in
    the nut traps and packing tape under the seams with no bill line. Each word the step texts use
    (read from where they are made) is a TOOL_WORDS word with a tools line, or a consumables line."""
    import re

    from rigcad.manual.finishing import LAYER_METHODS
    from rigcad.parts.base import turning_text

    texts = turning_text(table31_rig.profile)
    for word in ("lathe", "boring bar", "micrometer"):
        assert re.search(rf"\b{word}", texts), word
        assert word in B.TOOL_WORDS and any(word in line.lower() for line, _ in B.TOOLS), word
    assert "airbrush" in LAYER_METHODS["MirraChrome"][1]
    assert "airbrush" in B.TOOL_WORDS and any("airbrush" in line.lower() and "0.8-1.0 mm" in line for line, _ in B.TOOLS)
    consumables = " ".join(line.lower() for line, _ in B.CONSUMABLES)
    for what in ("cyanoacrylate", "packing tape", "retaining compound"):
        assert what in consumables, what
