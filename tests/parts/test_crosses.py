"""The projector crosses define the axis the projector is aligned TO: their plate registers on what
stays fixed on the shelf when the splitter holder is lifted off (the splitter seat's cone, vee and
flat), never on the focusing lens's mount, which slides in its slots. Held here on the exact solids
(OpenCascade): the plate's three balls touch the seat's six constraint surfaces at the holder's own
ball positions, the plate touches nothing that stays (the lens mount at either end of its slots
included), the crosses' centres are on the projector's design axis, and the fixture's weight acts
inside the seat's triangle."""

import math
from pathlib import Path

import pytest

from rigcad.errors import GeometryError
from rigcad.parts import _kernel as K
from rigcad.parts.crosses import GAP, TIP_MARGIN, centre_of_mass_x, cross_fixture
from rigcad.parts.recipe import Translate
from rigcad.parts.tower import DRAWN_UNDER, SEAT_PIN_LENGTH, _sphere, instruments, seat_geometry
from rigcad.profile import load_profile
from rigcad.rig import Rig

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rig():
    return Rig.from_profile(load_profile(ROOT / "profiles/achutha2006.yaml"))


def _solid(recipe):
    return K.single_solid(K.build(recipe, 1e-4, K.FitReport()))


def _common(a, b) -> float:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    return K.volume(BRepAlgoAPI_Common(a, b).Shape())


def _mass(shape):
    """Volume (mm^3) and centre (x, y, z; mm) of a solid: OpenCascade's own, not the fixture's sum."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    c = props.CentreOfMass()
    return props.Mass(), (c.X(), c.Y(), c.Z())


def test_the_plates_balls_sit_on_the_seats_cone_vee_and_flat(rig):
    """Each ball pressed into the plate touches exactly the seat surfaces of its contact, measured from
    the seat's own drawn hard parts: the cone's three balls (centre distance = one ball diameter), the
    vee's two pins (axis distance = (ball + pin) / 2), the flat's block (its top one radius below).
    So the plate stands where the holder stood, on the shelf's fixed hard points, whatever the lens
    mount's slot position."""
    f = cross_fixture(rig.profile, rig.layout)
    g = seat_geometry(rig.profile)
    parts = {part.name: part for part in instruments(rig.profile, rig.layout)}  # the seat's hard parts, drawn
    cone = [parts[f"seat_cone_ball_{k}"].solid.offset for k in (1, 2, 3)]
    pins = [parts[f"seat_vee_pin_{k}"].solid.offset for k in (1, 2)]  # each pin's end centre; its axis along y
    pad_top = parts["seat_flat_pad"].solid.hi[2]
    by = {kind: (x, y, f.ball_centre_z) for kind, x, y in f.balls}
    for c in cone:
        assert math.dist(by["cone"], c) == pytest.approx(g.ball, abs=1e-9)  # touching: centres a diameter apart
    for p in pins:
        d = math.hypot(by["vee"][0] - p[0], by["vee"][2] - p[2])  # distance to the pin's axis (along y)
        assert d == pytest.approx((g.ball + g.pin) / 2, abs=1e-9)
        assert abs(by["vee"][1] - p[1]) < SEAT_PIN_LENGTH / 2  # within the pin's length (drawn symmetric about p)
    assert by["flat"][2] - g.ball / 2 == pytest.approx(pad_top, abs=1e-9)  # resting on the gauge block
    # the plate's underside clears the seat's hard parts at their true size (drawn DRAWN_UNDER it) by GAP
    tops = [c[2] + g.ball / 2 for c in cone] + [q[2] + g.pin / 2 for q in pins] + [pad_top]
    assert f.underside_z - max(tops) >= GAP - 1e-9, (f.underside_z, tops)
    # and they are where the splitter holder's own balls sit: the plate takes the holder's place
    held = {n: parts[n].solid.offset for n in ("seat_ball_1", "seat_ball_2", "seat_ball_3")}
    assert sorted(tuple(round(v, 9) for v in b) for b in by.values()) == sorted(tuple(round(v, 9) for v in b)
                                                                               for b in held.values())


def test_the_plate_touches_nothing_that_stays_and_its_crosses_are_on_the_design_axis(rig):
    """The plate with its balls pressed in (drawn DRAWN_UNDER their size, like the seat's) is clear of
    the shelf, the seat's cone balls, vee pins and flat block, and of the lens mount at both ends of
    its slots (it is never pushed against it); the crosses (one moved to the far fence) and the
    backplate stand clear of it in their fences; both crosses' centres lie on the projector's design
    axis (the tower's projector COP height, y = 0)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    p, t = rig.profile, rig.layout.tower
    f = cross_fixture(p, rig.layout)
    plate = _solid(rig.recipe("projector_mounting_plate").solid)
    r = f.ball_diameter / 2 - DRAWN_UNDER
    balls = [_solid(_sphere((x, y, f.ball_centre_z), r)) for _, x, y in f.balls]
    travel = p.tower.travel_along
    stays = [_solid(rig.recipe("tower_shelf").solid)]
    stays += [_solid(part.solid) for part in instruments(p, rig.layout)
              if part.name.startswith(("seat_cone_ball", "seat_vee_pin", "seat_flat_pad"))]
    stays += [_solid(Translate(rig.recipe("lens_mount").solid, (dx, 0.0, 0.0))) for dx in (-travel, 0.0, travel)]
    assert len(stays) == 1 + 3 + 2 + 1 + 3
    for other in stays:
        assert _common(plate, other) < 1e-6  # mm^3: shared faces only, no overlap
        for ball in balls:
            assert _common(ball, other) < 1e-6
    for ball in balls:
        assert _common(ball, plate) < 1e-6  # each ball fits its pocket
    cross = rig.recipe("projector_cross").solid
    crosses = [_solid(cross), _solid(Translate(cross, (-f.spacing, 0.0, 0.0)))]
    for other in crosses + [_solid(rig.recipe("projector_backplate").solid)]:
        assert _common(plate, other) < 1e-6
    box = Bnd_Box()
    BRepBndLib.Add_s(plate, box)
    x0, _, z0, x1, _, _ = box.Get()
    assert z0 == pytest.approx(f.underside_z, abs=1e-6) and z0 > t.shelf_top_z  # it stands on its balls, not the shelf
    cop = t.projector_cop
    for solid in crosses:
        box = Bnd_Box()
        BRepBndLib.Add_s(solid, box)
        cx0, cy0, _, cx1, cy1, zmax = box.Get()
        # the cross's centre (top of the vertical bar minus the arm) on the axis: its height and y = 0
        assert zmax - p.crosses.arm_length == pytest.approx(cop[2], abs=1e-6)
        assert (cy0 + cy1) / 2 == pytest.approx(cop[1], abs=1e-6)
        assert x0 < cx0 and cx1 < x1


def test_the_fixtures_weight_holds_it_on_all_three_contacts(rig):
    """The fixture's centre of mass from the exact solids (plate, two crosses, backplate; uniform
    density) agrees with the fixture's own box sum and lies TIP_MARGIN inside the seat's triangle."""
    f = cross_fixture(rig.profile, rig.layout)
    cross = rig.recipe("projector_cross").solid
    solids = [_solid(rig.recipe("projector_mounting_plate").solid), _solid(cross),
              _solid(Translate(cross, (-f.spacing, 0.0, 0.0))), _solid(rig.recipe("projector_backplate").solid)]
    masses = [_mass(s) for s in solids]
    total = sum(m for m, _ in masses)
    x = sum(m * c[0] for m, c in masses) / total
    y = sum(m * c[1] for m, c in masses) / total
    # 2 mm: the box sum leaves out the fences (~1.5 mm walls) and counts the crosses' bar crossing twice
    assert centre_of_mass_x(f, rig.profile) == pytest.approx(x, abs=2.0)
    assert abs(y) < 1e-6  # symmetric about the axis' plane
    pts = [(bx, by) for _, bx, by in f.balls]
    dist = [((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / math.dist(a, b)
            for a, b in zip(pts, pts[1:] + pts[:1])]
    assert all(d > TIP_MARGIN for d in dist) or all(d < -TIP_MARGIN for d in dist), dist


def test_a_fixture_that_would_tip_off_the_seat_is_refused(rig):
    """A seat whose flat stood nearer the fixture's centre of mass (towards the cone and vee) would
    leave its weight on or outside the triangle's edge: refused within TIP_MARGIN, naming the key.
    (Longer arms do not do it: the backplate and the plate widen together.)"""
    from dataclasses import replace

    from rigcad.parts.crosses import _check_standing

    p = rig.profile
    f = cross_fixture(p, rig.layout)
    x = centre_of_mass_x(f, p)
    (cx, cy), = {(bx, abs(by)) for k, bx, by in f.balls if k != "flat"}

    def inside(flat_x):  # the weight's distance (mm) inside the flat-vee side, by similar triangles
        return (x - flat_x) * cy / math.hypot(cx - flat_x, cy)

    def flat_at(distance):  # the flat's x that puts the weight ``distance`` inside (bisection; inside() is monotonic)
        lo, hi = cx - 1000.0, x
        for _ in range(100):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if inside(mid) > distance else (lo, mid)
        return lo

    assert inside(dict((k, bx) for k, bx, _ in f.balls)["flat"]) > 2 * TIP_MARGIN  # the default: well inside
    for flat_x, refused in ((flat_at(1.2 * TIP_MARGIN), False), (flat_at(0.8 * TIP_MARGIN), True), (x + 1.0, True)):
        moved = replace(f, balls=tuple((k, flat_x if k == "flat" else bx, by) for k, bx, by in f.balls))
        if not refused:
            _check_standing(moved, p)
            continue
        with pytest.raises(GeometryError) as info:
            _check_standing(moved, p)
        assert "would tip off one" in str(info.value) and "crosses.arm_length" in str(info.value)


def test_the_plate_lists_its_balls_to_buy(rig):
    f = cross_fixture(rig.profile, rig.layout)
    (ball,) = f.bought
    assert ball.quantity == 3 and ball.standard == "ISO 3290-1"
    assert ball.size_mm == {"diameter": rig.profile.adjusters.seat_ball}  # the seat's own balls' size


def test_the_calibration_kit_lists_the_plates_balls(rig):
    """The manual's calibration kit (rigcad.manual.calibration.kit_items) carries the plate's balls,
    for the crosses' step, by the words that step names them with."""
    from rigcad.manual import calibration as C

    f = cross_fixture(rig.profile, rig.layout)
    (item,) = [k for k in C.kit_items(rig) if "steel balls" in k.words]
    assert item.quantity == str(len(f.balls)) == "3" and item.steps == (C.STEP_CROSSES,)
    assert f"{rig.profile.adjusters.seat_ball:g} mm" in item.item and "ISO 3290-1" in item.item
