"""The COP tower: valid solids, no interference with the rig or the instruments, adjustment travel
that covers the tolerances (probed with bolts in the slots), and errors that name the parameter."""

import itertools
import math

import manifold3d as m3d
import numpy as np
import pytest

from rigcad.errors import GeometryError
from rigcad.export import mesh as M
from rigcad.parts import _kernel as K
from rigcad.parts.recipe import Cylinder, Part
from rigcad.parts.tower import TOWER_PARTS, clearance_hole
from rigcad.profile import load_profile
from rigcad.rig import Rig

RIG = ["dome", "paraboloid", "beam", "base_plate", "sample_holder"]
IN_RIG_TOWER = ["tower_column", "tower_shelf", "splitter_holder", "lens_mount"]
#: Intended contacts (the shelf on the column, the holder and lens mount on the shelf, the projector
#: on its shims, the camera on its shims) share faces only: zero volume; 1e-6 mm^3 is far below any
#: real overlap (a 0.01 mm overlap over the smallest contact, 30 x 30 mm, is 9 mm^3).
CONTACT_MM3 = 1e-6


def _solid(part):
    return K.part_solid(part, 1e-4, K.FitReport())


@pytest.fixture(scope="module")
def rig(table31_rig):
    return table31_rig


@pytest.fixture(scope="module")
def shapes(rig):
    out = {n: _solid(rig.recipe(n)) for n in RIG + IN_RIG_TOWER}
    out.update({p.name: _solid(p) for p in rig.instruments})
    return out


def _common(a, b) -> float:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    return K.volume(BRepAlgoAPI_Common(a, b).Shape())


@pytest.mark.parametrize("name", TOWER_PARTS)
def test_tower_parts_are_valid_solids_and_watertight_meshes(rig, name):
    part = rig.recipe(name)
    shape = _solid(part)  # one valid solid (BRepCheck) or a KernelError
    man = M.build(part.solid, rig.profile.tessellation.chord_error)
    assert man.status() == m3d.Error.NoError
    v, f = M.mesh_arrays(man)
    # boxes, z cylinders and flat prisms: the mesh is exact but for the cylinders' chords
    assert M.mesh_volume(v, f) == pytest.approx(K.volume(shape), rel=1e-3)


def test_no_tower_part_cuts_into_the_rig_the_instruments_or_another_tower_part(rig, shapes):
    others = RIG + [p.name for p in rig.instruments if not p.name.endswith("_marker")]
    pairs = [(a, b) for a in IN_RIG_TOWER for b in others] + list(itertools.combinations(IN_RIG_TOWER, 2))
    bad = {(a, b): v for a, b in pairs if (v := _common(shapes[a], shapes[b])) > CONTACT_MM3}
    assert not bad, bad


def test_instruments_do_not_cut_into_each_other_or_the_rig(rig, shapes):
    names = [p.name for p in rig.instruments if not p.name.endswith("_marker")]
    bad = {}
    for a, b in itertools.combinations(names, 2):
        if {a, b} in ({"projector_body", "projector_lens"}, {"camera_body", "camera_lens"}):
            continue  # a lens is screwed to its body: they share a face
        if (v := _common(shapes[a], shapes[b])) > CONTACT_MM3:
            bad[(a, b)] = v
    for a in names:
        for b in RIG:
            if (v := _common(shapes[a], shapes[b])) > CONTACT_MM3:
                bad[(a, b)] = v
    assert not bad, bad


def test_both_centres_of_projection_sit_at_cop_z(rig):
    from rigcad.optics.splitter import mirror_point, transmit, virtual_source, cone_dirs

    t = rig.layout.tower
    cop = np.array([0.0, 0.0, rig.geometry.cop_z])
    # the projector: its real COP stands behind the COP the paraboloid sees through the focusing lens
    # (rigcad.optics.focus.FocusingLens.cop_distance; tests/parts/test_projector_mount.py traces it), whose
    # image in the plate's front face is the design COP: the real COP's image is that far above it
    from rigcad.optics.focus import focusing_lens

    lens = focusing_lens(rig.profile, rig.geometry)
    behind = lens.cop_distance - lens.lens_distance
    assert np.allclose(mirror_point(t.plate, t.projector_cop), cop + (0.0, 0.0, behind), atol=1e-9)
    # the camera: its rays through the plate meet (least squares) at the design COP
    dirs = cone_dirs(rig.geometry.rim_angle_at_cop)
    p, d, inside = transmit(t.plate, np.tile(t.camera.cop, (len(dirs), 1)), dirs)
    assert inside.all()
    assert np.linalg.norm(virtual_source(p, d) - cop) < 1e-9  # exact up to round-off: the plate is uniform
    # the instruments' boxes put each entrance pupil at its COP
    cam, prof = rig.profile.camera, rig.profile.projector
    assert t.camera_lens_box[0][2] == pytest.approx(t.camera.cop[2] - cam.pupil_depth)
    assert t.projector_lens_box[0][0] == pytest.approx(t.projector_cop[0] - prof.pupil_depth)


def _bolt_fits(shape, x, y, z0, height, diameter) -> bool:
    bolt = _solid(Part("bolt", Cylinder((x, y, z0), diameter / 2 - 0.05, height), (0, 0, 0), ""))
    return _common(shape, bolt) < CONTACT_MM3


def test_projector_slots_travel_covers_the_tolerances(rig, shapes):
    # a bolt of the projector's thread moves in each shelf slot by tower.travel_along along x and
    # travel_across along y, which cover tolerancing.projector_height / projector_offset; one
    # 0.3 mm further it meets the shelf
    t, tw, tol = rig.layout.tower, rig.profile.tower, rig.profile.tolerancing
    assert tw.travel_along >= tol.projector_height and tw.travel_across >= tol.projector_offset
    d = clearance_hole(rig.profile.projector.mount_thread) - 0.5  # the thread itself
    (x0, y0, _), (x1, y1, _) = t.projector_box
    z0 = t.shelf_top_z - t.shelf_thickness - 1.0
    shelf = shapes["tower_shelf"]
    x, y = t.projector_feet[0]  # a foot (the assumed pattern: 30 mm in from the body's corners)
    assert (x, y) == pytest.approx((x0 + 30.0, y0 + 30.0))
    for dx, dy in ((tw.travel_along, 0), (-tw.travel_along, 0), (0, tw.travel_across), (0, -tw.travel_across)):
        assert _bolt_fits(shelf, x + dx, y + dy, z0, t.shelf_thickness + 2, d), (dx, dy)
    assert not _bolt_fits(shelf, x + tw.travel_along + 0.3 + 0.25, y, z0, t.shelf_thickness + 2, d)


def test_camera_slot_travel_covers_the_tolerances(rig, shapes):
    # both camera screws (two points, camera.mount_spacing apart along the axis) move in the bracket's
    # slot by travel_along (z) and travel_across (x); 0.55 mm further along, the upper one meets it
    from rigcad.parts.recipe import Box
    from rigcad.parts.tower import camera_screws

    t, tw, tol = rig.layout.tower, rig.profile.tower, rig.profile.tolerancing
    assert tw.travel_along >= tol.camera_height and tw.travel_across >= tol.camera_offset
    d = clearance_hole(rig.profile.camera.mount_thread) - 0.5
    holder = shapes["splitter_holder"]
    yo = t.wall_y[1]
    screws = camera_screws(t, rig.profile)
    assert screws[1][1] - screws[0][1] == pytest.approx(rig.profile.camera.mount_spacing)

    def fits(x, z):  # a square screw of side d along y through the bracket
        screw = _solid(Part("screw", Box((x - d / 2 + 0.05, -yo - 2, z - d / 2 + 0.05),
                                         (x + d / 2 - 0.05, t.bracket_y + 0.5, z + d / 2 - 0.05)), (0, 0, 0), ""))
        return _common(holder, screw) < CONTACT_MM3

    for cx, cz in screws:
        for dx, dz in ((tw.travel_across, 0), (-tw.travel_across, 0), (0, tw.travel_along), (0, -tw.travel_along)):
            assert fits(cx + dx, cz + dz), (dx, dz)
    assert not fits(screws[1][0], screws[1][1] + tw.travel_along + 0.55)
    # shims across y: travel_across each way from the nominal stack
    assert t.shims_nominal * tw.shim_thickness >= tw.travel_across
    assert t.shims_per_stack * tw.shim_thickness >= 2 * tw.travel_across


def _rig_of(write_profile, table31_text, extra):
    return Rig.from_profile(load_profile(write_profile(table31_text + extra)))


def test_a_splitter_too_close_to_the_cop_names_the_key(write_profile, table31_text):
    with pytest.raises(GeometryError) as info:
        _rig_of(write_profile, table31_text, "tower:\n  splitter_distance: 30 mm\n").layout
    msg = str(info.value)
    assert "tower.splitter_distance" in msg and "p.yaml:8" in msg


def test_a_lens_that_does_not_fit_names_the_key(write_profile, table31_text):
    with pytest.raises(GeometryError) as info:
        _rig_of(write_profile, table31_text, "lens:\n  distance: 65 mm\n").layout
    assert "lens.distance" in str(info.value) and "p.yaml:8" in str(info.value)


def test_a_too_small_splitter_names_the_key(write_profile, table31_text):
    with pytest.raises(GeometryError) as info:
        _rig_of(write_profile, table31_text, "beam_splitter:\n  length: 12 mm\n  width: 12 mm\n").layout
    assert "beam_splitter.length" in str(info.value)


def test_hardware_is_computed_from_the_parts(rig, write_profile, table31_text):
    from rigcad.parts.tower import fine_shims, hardware

    items = hardware(rig.profile, rig.layout)
    m4 = {i["joins"].split(" (")[0]: i for i in items if i["thread"] == "M4" and " nut" in i["item"]
          and "spring" not in i["item"]}
    assert sorted(i["quantity"] for i in m4.values()) == [2, 4]  # lens foot, column foot on the tongue
    # lens foot: 5 mm foot + 10 mm shelf + a large washer over the foot's slot (1.0, ISO 7093-1) and one under
    # the nut (0.8, ISO 7089), nut (3.2, ISO 4032), 2 pitches (1.4) = 21.4 mm; column foot: 5 mm foot + the
    # tongue above its nut traps (15 - 5.6 mm) + a large washer over its opened hole (the nut sits in its
    # trap), nut, pitches = 20.0 mm (the bolt ends above the bench)
    assert m4["the lens mount's slotted foot to the shelf"]["length_mm"] == 25.0
    foot = m4["the column's foot to the base plate's datum tongue"]["length_mm"]
    assert foot == 20.0 and foot <= rig.profile.tower.wall + 1.0 - rig.layout.tower.bench_z
    # the shelf on the column's flange: up into inserts, 12 mm (5 mm flange + large washer + 6 mm of the 8.1 mm insert)
    shelf = next(i for i in items if i["joins"].startswith("the column's top flange to the shelf"))
    assert shelf["quantity"] == 4 and shelf["length_mm"] == 12.0 and "ISO 7093-1" in shelf["item"]
    springs = next(i for i in items if "spring" in i["item"])
    assert springs["quantity"] == 2
    screws = [i for i in items if "for_stacks_of_shims" in i]
    # every stack from 0 to shims_per_stack has its screw, four of each length (one per foot)
    assert sorted(n for i in screws for n in i["for_stacks_of_shims"]) == list(range(rig.layout.tower.shims_per_stack + 1))
    assert all(i["quantity"] == 4 and i["thread"] == rig.profile.projector.mount_thread for i in screws)
    # the camera's likewise, two of each length
    cam = [i for i in items if "for_camera_stacks_of_shims" in i]
    assert sorted(n for i in cam for n in i["for_camera_stacks_of_shims"]) == list(range(rig.layout.tower.shims_per_stack + 1))
    # the bought shims: one fine set per stack (four under the projector, one behind the camera)
    fine = [i for i in items if i["item"].startswith("precision shim")]
    assert sum(i["quantity"] for i in fine) == 5 * len(fine_shims(rig.profile))
    # less travel: fewer shims in each stack, shorter screws through the thickest
    less = Rig.from_profile(load_profile(write_profile(table31_text + "tower:\n  travel_across: 3 mm\n")))
    screws2 = [i for i in hardware(less.profile, less.layout) if "for_stacks_of_shims" in i]
    assert max(i["length_mm"] for i in screws2) < max(i["length_mm"] for i in screws)
    assert less.recipe("tower_shim").quantity == 5 * 6  # 6 mm of 1 mm shims per stack
