"""The rig on an optical breadboard (rigcad.parts.breadboard, ``datum.mount``): the screws land on
the board's grid, the printed holes take the print's and the board's position errors, the assembly
check fits the screws, and the bill lists them."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rigcad
from rigcad.errors import ProfileError
from rigcad.manual import assembly_check as AC
from rigcad.manual import bom, plan
from rigcad.manual.assembly import picture_meshes
from rigcad.parts import breadboard

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

PITCH = {"breadboard_m6_25mm": 25.0, "breadboard_imperial_1in": 25.4}


def _rig(tmp_path, mount: str, extra: str = ""):
    path = tmp_path / f"{mount}.yaml"
    path.write_text(f"extends: achutha2006\ndatum:\n  mount: {mount}\n{extra}", encoding="utf-8")
    return rigcad.load(path)


@pytest.fixture(scope="module")
def rigs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bb")
    return {m: _rig(tmp, m) for m in PITCH}


@pytest.mark.parametrize("mount", list(PITCH))
def test_the_screws_land_on_the_grid_with_the_tower_over_the_paraboloid(rigs, mount):
    """Every screw sits on a grid point (i p, j p) of the board's pitch p (25 mm, 1 in = 25.4 mm),
    O (the paraboloid's axis, under the COP) on a hole; the tongue's screws past the column's foot,
    washers inside the tongue; the disc's inside the dome's flange; each a hole through the plate's
    mesh, with material round it."""
    rig = rigs[mount]
    t, p = rig.layout.tower, PITCH[mount]
    assert rig.geometry.cop_z > 0 and t.cop[:2] == (0.0, 0.0)  # the COP over O, the grid's origin
    pts = breadboard.anchor_points(rig.profile, rig.layout)
    washer = breadboard.board(rig.profile).washer[0] / 2
    for x, y in [q for qs in pts.values() for q in qs]:
        assert x / p == pytest.approx(round(x / p), abs=1e-9) and y / p == pytest.approx(round(y / p), abs=1e-9)
    assert len(pts["tongue"]) == 2 and all(x - washer > t.column_x + t.column_foot_half for x, _ in pts["tongue"])
    assert all(abs(y) + washer <= t.column_foot_half for _, y in pts["tongue"])
    assert all(math.hypot(x, y) + washer < rig.layout.flange_inner_r for x, y in pts["disc"])
    solids = plan.steps(rig, picture_meshes(rig))[1]
    hole = breadboard.fit(rig.profile, rig.layout)["hole_mm"] / 2
    for x, y in [q for qs in pts.values() for q in qs]:
        # the mesh's hole is a polygon inside the true circle: a pin 0.3 mm thinner passes it
        pin = AC.cylinder(np.array([x, y, t.bench_z - 5.0]), np.array([0.0, 0.0, 1.0]), 30.0, hole - 0.3)
        ring = AC.cylinder(np.array([x, y, t.bench_z - 5.0]), np.array([0.0, 0.0, 1.0]), 30.0, hole + 3.0)
        assert AC.penetration(pin, solids["base_plate"]) <= AC.CLEARANCE_MM
        assert AC.penetration(ring, solids["base_plate"]) > 1.0  # the pad or the boss round the hole


def test_the_holes_take_the_print_and_the_board_errors(rigs):
    """hole >= clearance + 2 (print_position + print_scale x span + board error), span the largest
    distance between two screws; the chain's check says so; the screw engages 1 d .. 12 mm."""
    rig = rigs["breadboard_m6_25mm"]
    d = rig.profile.datum
    pts = [q for qs in breadboard.anchor_points(rig.profile, rig.layout).values() for q in qs]
    span = max(math.dist(a, b) for a in pts for b in pts)
    assert span == pytest.approx(math.hypot(250.0 + 100.0, 25.0))  # (250, +-25) to (-100, 0) at achutha2006
    need = 6.6 + 2 * (d.print_position + d.print_scale * span + d.breadboard_hole_position)
    f = breadboard.fit(rig.profile, rig.layout)
    assert need <= f["hole_mm"] < need + 0.1 and f["hole_mm"] < breadboard.board(rig.profile).washer[0] - 2.0
    from rigcad.parts.datum import check_datum_chain, datum_chain

    assert datum_chain(rig.profile, rig.layout).describe()["mount"]["board_hole_position_mm"] == 0.15
    rows = {r["claim"]: r for r in check_datum_chain(rig.profile, rig.layout)}
    assert rows["breadboard_holes_take_the_grid"]["ok"]
    # through the 1.6 mm washer and the tongue, 17 mm deep since the bench lies 2 mm under the
    # sample holder's collar: 30 mm engages 11.4 mm (at most 12), 35 mm would engage 16.4
    assert rig.layout.tower.bench_z == pytest.approx(-17.0)
    L, name, engaged = breadboard.screw_length(rig.profile, rig.layout)
    assert (L, name) == (30.0, "30 mm") and engaged == pytest.approx(30.0 - 1.6 - 17.0)


@pytest.mark.parametrize("mount", list(PITCH))
def test_the_assembly_check_fits_the_screws_and_the_bill_lists_them(rigs, mount):
    """The found order screws the plate down before the dome; the bill and the manual's hardware list
    three screws of the board's thread."""
    rig = rigs[mount]
    a = plan.assembly(rig, picture_meshes(rig))
    screws = a.by_name["base_plate"].fasteners
    assert len(screws) == 3 and all(f.thread_in == "bench" for f in screws)
    order = [s.step.name for s in AC.find_order(a)]
    assert order.index("base_plate") < order.index("dome")
    thread = breadboard.board(rig.profile).thread
    rows = [r for r in bom.fasteners(rig) if r.get("thread") == thread and "breadboard" in r["use"]]
    assert len(rows) == 1 and rows[0]["quantity"] == 3
    hw = [r for r in plan.hardware(a.steps, rig) if "into the breadboard" in r["item"]]
    assert len(hw) == 1 and hw[0]["quantity"] == 3 and hw[0]["item"].startswith(thread)


def test_a_lid_over_a_breadboard_screw_is_refused(rigs):
    """A block over the disc's screw, in the driver's and the L key's way, refuses the base plate's step."""
    rig = rigs["breadboard_m6_25mm"]
    a = plan.assembly(rig, picture_meshes(rig))
    x, y, z = next(f.head for f in a.by_name["base_plate"].fasteners if f.head[0] < 0)
    import manifold3d as m3

    lid = m3.Manifold.cube((20.0, 20.0, 6.0)).translate((x - 10.0, y - 10.0, z + 20.0))
    step = a.by_name["base_plate"]
    import dataclasses

    lidded = dataclasses.replace(step, members=(*step.members, "lid"))
    b = AC.Assembly({**a.solids, "lid": lid}, [lidded if s.name == "base_plate" else s for s in a.steps])
    with pytest.raises(Exception, match=r"base_plate.*M6 x 30 mm socket-head.*blocked by lid"):
        AC.check_order(b, ["sample_holder", "base_plate"])


def test_an_unknown_mount_is_refused_with_the_choices(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("extends: achutha2006\ndatum:\n  mount: breadboard_m4\n", encoding="utf-8")
    with pytest.raises(ProfileError, match=r"datum\.mount.*breadboard_m6_25mm"):
        rigcad.load(path)
