"""The COP tower (thesis 3.1 items 2-7, Figure 3.4): what holds the projector, the camera, the beam
splitter and the focusing lens so that both centres of projection (COP) sit at ``cop_z``.

Layout (mm, rig frame: O at the origin, optical axis +z; every number from the profile):

* the plate beam splitter (``optics.splitter``) at 45 deg on the axis, ``tower.splitter_distance``
  below the COP, its coated front face towards +x and down;
* the projector on its side of the splitter at 90 deg, looking -x: the focusing lens's centre
  ``lens.distance`` from the design COP's image in the splitter's front face, and the real COP
  behind it where the paraboloid, through the lens, sees it at that image (rigcad.optics.focus:
  ``FocusingLens.cop_distance``, 1.14 mm farther back for Table 3.1); it stands on its mounting holes
  (``projector.mount_holes``, rigcad.profile.instruments.mount_pattern), each over a slot in the shelf;
* the camera behind the splitter on the axis, looking down through the plate, its COP moved by the
  plate's compensation (``optics.splitter.camera_cop``: 0.34 mm across and 0.47 mm up for 1 mm of
  N-BK7) so that it sees the rig from the design COP;
* the focusing lens on the projector's axis between its lens and the splitter, in a square pocket;
* a shelf under the projector reaching over the axis (a hole lets the bundle down), on a square
  column that stands on the base plate's datum tongue (two dowels and four bolts at each end of the
  column: the datum chain, ``rigcad.parts.datum``), or a bought extrusion in square pockets;
* the splitter holder on a kinematic seat over the shelf (three push screws on balls in a cone, a
  vee and a flat; two spring bolts): two side walls with 45 deg grooves the plate rests in (it
  slides in through the +y wall; the grooves follow its catalogue thickness), a back wall (a light
  dump for the half of the projector's light the plate transmits), and the camera bracket above,
  with one slot for the camera's two screws (in line along the axis: it cannot pivot);
* adjustment, each way from the nominal placement (``rigcad.parts.adjusters`` states each range and
  resolution against its tolerance): the splitter tips and tilts on its seat; the camera slides in
  its bracket's slot along the axis (``tower.travel_along``) and across it in x
  (``tower.travel_across``), and on slotted shims in y; the projector slides in the shelf's slots
  along its own axis (its virtual COP moves along the optical axis) and across it, and on shims in
  height (its virtual COP moves across, in x), held by screws sized per shim stack.

Instruments are not printed: :func:`instruments` gives them as simple named solids for rig.step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError
from rigcad.optics.focus import focusing_lens, placed_lens
from rigcad.optics.splitter import CameraPlacement, Plate, camera_cop, mirror_point, splitter_plate
from rigcad.parts.joints import LIMITER_SQUEEZE_MM, Bought, Datum, KinematicSeat, SeatContact, datums_of
from rigcad.parts.recipe import (Box, Cylinder, Difference, HexPrism, Line, Part, Prism, Revolve, Section, Translate,
                                 Union_)
from rigcad.profile.instruments import mount_pattern, size_origin
from rigcad.profile.derived import Derived
from rigcad.profile.schema import Profile
from rigcad.standards import (CAMERA_SOCKET_DEPTH, COMPRESSION_LIMITERS, CONICAL_SPRING_WASHERS, CUP_POINT, GAUGE_BLOCK_FACE, INSERTS, THREADS, dowel_diameter_for,
                              longest_screw, screw_lengths, shortest_screw, shortest_set_screw, spring_rate)

#: Gap around the splitter plate in its grooves (mm): a printed groove comes out ~0.1 mm narrow.
GROOVE_GAP = 0.2
#: Depth of the grooves into the holder's side walls (mm): the plate's edge rests on this much.
GROOVE_DEPTH = 2.0
#: Square adjustment shims (mm): side; the U slot takes the screw without removing it.
SHIM_SIDE = 30.0
#: The bench lies this far (mm) under the sample holder's stop collar: the rig stands on three feet (the
#: tongue and two pads under the disc's rim, rigcad.parts.base.feet), never on the collar. 2 mm is 20 times
#: a printed foot's out-of-flat (``datum.foot_flatness``, 0.1 mm by default), so no warp brings it down.
COLLAR_BENCH_GAP_MM = 2.0


def clearance_hole(thread: str) -> float:
    """Clearance hole diameter (mm) for a named mounting thread: ISO 273 medium (ASME B18.2.8 normal
    for an inch thread), from rigcad.standards."""
    return THREADS[thread].clearance


@dataclass(frozen=True)
class TowerLayout:
    """Placements of the tower and its instruments (mm). ``plate``: the splitter; ``camera``: the
    compensated camera placement; ``projector_cop``: the projector's real COP (through the focusing
    lens, its image in the plate's front face is the design COP); ``*_z``: heights of the shelf, the
    bench and the holder; ``projector_feet``: (x, y) of the projector's mounting holes, each over a
    shim stack and a slot in the shelf."""

    plate: Plate
    camera: CameraPlacement
    projector_cop: tuple[float, float, float]
    cop: tuple[float, float, float]
    bench_z: float
    shelf_top_z: float
    shelf_thickness: float
    holder_x: tuple[float, float]  #: back, front of the splitter holder
    holder_top_z: float
    plate_bottom_z: float  #: the splitter plate's lowest point
    wall_y: tuple[float, float]  #: inner, outer |y| of the holder's side walls
    bracket_y: float  #: the camera bracket's face (y), under the camera's shims
    column_x: float  #: the column's centre (x; y = 0)
    column_base_z: float  #: the column foot's underside: the base plate's datum tongue (z = 0)
    column_foot_half: float  #: half the side of the column's square foot and top flange
    projector_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    projector_lens_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    camera_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    camera_lens_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    lens_x: float  #: the focusing lens's centre on the projector's axis
    bundle_radius_at_shelf: float  #: the projector's ray bundle (pinhole cone + aperture) at the shelf
    shims_nominal: int  #: shims under the projector and behind the camera at the nominal placement
    shims_per_stack: int  #: shims printed per stack: the full travel both ways
    projector_feet: tuple[tuple[float, float], ...] = ()  #: the projector's mounting holes (x, y)

    def describe(self) -> dict:
        """Placements for the manifest (mm)."""
        return {
            "cop_mm": list(self.cop), "projector_cop_mm": list(self.projector_cop),
            **self.camera.as_dict(),
            "splitter_center_mm": list(self.plate.center), "splitter_normal": list(self.plate.normal),
            "bench_z_mm": self.bench_z, "shelf_top_z_mm": self.shelf_top_z, "column_x_mm": self.column_x,
            "focusing_lens_x_mm": self.lens_x, "shims_nominal": self.shims_nominal,
            "shims_per_stack": self.shims_per_stack,
        }


def _box(lo, hi) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    return tuple(float(v) for v in lo), tuple(float(v) for v in hi)


#: Bought shim stock (mm): precision shims of stainless steel (AISI 301 shim stock, +-0.005 mm on 0.05-0.2,
#: +-0.01 mm on 0.5 mm, as sold), slotted to SHIM_SIDE like the printed ones, the thicknesses the fine set
#: is made of. The printed shims (``tower.shim_thickness``) give the travel; the bought ones the fine
#: steps between two printed ones, so an adjuster's step is the thinnest bought shim.
SHIM_STOCK = (0.05, 0.1, 0.2, 0.5)
#: The fine set reaches this many printed shims' thickness: 20 % past one, so a printed shim a little
#: thicker than drawn (its layer error) leaves no gap between two settings.
FINE_SET_REACH = 1.2


def fine_shims(profile: Profile) -> tuple[float, ...]:
    """One stack's set of bought shims (mm, thinnest first): each next the thickest of SHIM_STOCK no
    thicker than what the set reaches so far plus the thinnest, so every multiple of the thinnest up
    to the set's sum can be stacked, until it reaches FINE_SET_REACH printed shims."""
    step, out, reach = SHIM_STOCK[0], [], 0.0
    while reach < FINE_SET_REACH * profile.tower.shim_thickness - 1e-9:
        s = max(v for v in SHIM_STOCK if v <= reach + step + 1e-9)
        out.append(s)
        reach += s
    return tuple(out)


def shims_nominal(profile: Profile) -> int:
    """Shims under the projector and behind the camera at the nominal placement: the travel across."""
    tw = profile.tower
    return math.ceil(tw.travel_across / tw.shim_thickness - 1e-9)


def shelf_bottom_z(profile: Profile, cop_z: float) -> float:
    """Height (mm) of the underside of the projector's shelf for a COP at ``cop_z`` mm: the projector's
    real COP lies ``tower.splitter_distance`` below it, its body ``projector.pupil_height`` lower, on its
    nominal shims, on the shelf (2 walls thick). It must clear the dome's top by ``tower.clearance``
    (tower_layout refuses it otherwise; the optimiser holds it as a constraint)."""
    tw = profile.tower
    return (cop_z - tw.splitter_distance - profile.projector.pupil_height
            - shims_nominal(profile) * tw.shim_thickness - 2 * tw.wall)


def _bundle_radius(profile: Profile, geometry: Derived, distance: float) -> float:
    """Radius (mm) of the projector's ray bundle ``distance`` mm from its COP: the pinhole cone to the
    paraboloid's rim plus the thin-lens aperture."""
    return profile.projector.aperture / 2 + distance * math.tan(geometry.rim_angle_at_cop)


def _check_splitter_size(profile: Profile, geometry: Derived) -> None:
    tw, bs = profile.tower, profile.beam_splitter
    r = _bundle_radius(profile, geometry, tw.splitter_distance)
    need = r * math.sqrt(2.0) + tw.clearance
    if bs.length / 2 < need or bs.width / 2 < r + tw.clearance:
        raise GeometryError(
            f"the beam splitter ({bs.width:g} x {bs.length:g} mm) does not cover the ray bundle with "
            f"tower.clearance: at 45 deg it must be at least {2 * need:.1f} mm long and "
            f"{2 * (r + tw.clearance):.1f} mm wide; enlarge beam_splitter.length and width",
            where=profile.where("beam_splitter", "length"))


def _plate_extent(plate: Plate) -> tuple[float, float, float, float]:
    """x0, x1, z0, z1 (mm) of the splitter plate (both faces) in the x-z plane."""
    n = np.asarray(plate.normal)
    corners = np.vstack([plate.corners(), plate.corners() - plate.thickness * n])
    return (float(corners[:, 0].min()), float(corners[:, 0].max()),
            float(corners[:, 2].min()), float(corners[:, 2].max()))


def _camera_boxes(profile: Profile, camera: CameraPlacement, plate_top_z: float, L: float):
    """The camera body's and lens's boxes (looking down; lens front above the plate with clearance)."""
    tw, cm = profile.tower, profile.camera
    cx, cy, cz = camera.cop
    front = cz - cm.pupil_depth
    if front < plate_top_z + tw.clearance:
        raise GeometryError(
            f"the camera's lens front (z = {front:.1f} mm) would be within tower.clearance of the "
            f"splitter's top edge (z = {plate_top_z:.1f} mm): raise tower.splitter_distance (now {L:g} mm) or "
            "shorten camera.pupil_depth", where=profile.where("tower", "splitter_distance"))
    if cm.lens_diameter / 2 > cm.pupil_height:
        raise GeometryError(f"camera.lens_diameter ({cm.lens_diameter:g} mm) reaches past the mounting face "
                            f"(camera.pupil_height {cm.pupil_height:g} mm)", where=profile.where("camera", "lens_diameter"))
    body0 = front + cm.lens_length
    face_y = cy - cm.pupil_height
    body = _box((cx - cm.body_width / 2, face_y, body0), (cx + cm.body_width / 2, face_y + cm.body_height,
                                                           body0 + cm.body_depth))
    lens = _box((cx - cm.lens_diameter / 2, cy - cm.lens_diameter / 2, front),
                (cx + cm.lens_diameter / 2, cy + cm.lens_diameter / 2, body0))
    return body, lens, face_y


def _projector_boxes(profile: Profile, p_cop, plate_x1: float, cop_distance: float):
    """The focusing lens's x (``cop_distance`` before the real COP ``p_cop``) and the projector body's
    and lens's boxes (looking -x at the splitter)."""
    tw, pj, ln = profile.tower, profile.projector, profile.lens
    z_s = p_cop[2]
    front = p_cop[0] - pj.pupil_depth
    lens_x = float(p_cop[0] - cop_distance)
    half = ln.thickness / 2 + tw.wall / 2  # the lens's pocket and its lips
    if lens_x - half < plate_x1 + tw.clearance or lens_x + half > front - tw.clearance:
        raise GeometryError(
            f"the focusing lens's mount (x = {lens_x - half:.1f}..{lens_x + half:.1f} mm) does not "
            f"fit between the splitter (x <= {plate_x1:.1f} mm) and the projector's lens front (x = {front:.1f} mm) "
            f"with tower.clearance: change lens.distance (now {ln.distance:g} mm) or raise tower.splitter_distance",
            where=profile.where("lens", "distance"))
    if pj.lens_diameter / 2 > pj.pupil_height:
        raise GeometryError(f"projector.lens_diameter ({pj.lens_diameter:g} mm) reaches below the body "
                            f"(projector.pupil_height {pj.pupil_height:g} mm)",
                            where=profile.where("projector", "lens_diameter"))
    body0 = front + pj.lens_length
    y0, z0 = -pj.pupil_lateral - pj.body_width / 2, z_s - pj.pupil_height
    body = _box((body0, y0, z0), (body0 + pj.body_depth, y0 + pj.body_width, z0 + pj.body_height))
    lens = _box((front, -pj.lens_diameter / 2, z_s - pj.lens_diameter / 2),
                (body0, pj.lens_diameter / 2, z_s + pj.lens_diameter / 2))
    return lens_x, body, lens


def _shelf_top(profile: Profile, cop_z: float, plate_z0: float, dome_top_z: float) -> float:
    """Height (mm) of the shelf's top; raise when it meets the splitter or comes near the dome."""
    tw = profile.tower
    shelf_t = 2 * tw.wall
    top = shelf_bottom_z(profile, cop_z) + shelf_t
    if top > plate_z0 - tw.clearance:
        raise GeometryError(
            f"the shelf (top z = {top:.1f} mm) would reach the splitter's lower edge (z = {plate_z0:.1f} mm): "
            "raise projector.pupil_height or shorten beam_splitter.length", where=profile.where("projector", "pupil_height"))
    if top - shelf_t < dome_top_z + tw.clearance:
        raise GeometryError(
            f"the shelf under the projector (bottom z = {top - shelf_t:.1f} mm) would be within tower.clearance "
            f"of the dome's top (z = {dome_top_z:.1f} mm): lower tower.splitter_distance (now "
            f"{tw.splitter_distance:g} mm) or projector.pupil_height", where=profile.where("tower", "splitter_distance"))
    return top


def tower_layout(profile: Profile, geometry: Derived, plate_r: float, dome_top_z: float) -> TowerLayout:
    """Place the tower; raise GeometryError naming the parameter when something does not fit."""
    tw, bs, cm = profile.tower, profile.beam_splitter, profile.camera
    if geometry.cop_at_infinity:
        raise GeometryError("the COP tower needs a finite COP (layout.cop_to_vertex is inf)",
                            where=profile.where("layout", "cop_to_vertex"))
    cop_z, L = geometry.cop_z, tw.splitter_distance
    plate = splitter_plate(cop_z, L, bs.width, bs.length, bs.thickness, bs.index)
    camera = camera_cop(plate, cop_z, geometry.rim_angle_at_cop)
    seen = mirror_point(plate, (0.0, 0.0, cop_z))  # = (L, 0, cop_z - L): the COP the paraboloid must see
    focus = placed_lens(profile, geometry)  # whether the projector can focus through it: hardware() judges
    p_cop = np.asarray(seen, float) + (focus.cop_distance - focus.lens_distance, 0.0, 0.0)  # the real COP, behind
    px0, px1, pz0, pz1 = _plate_extent(plate)
    _check_splitter_size(profile, geometry)
    camera_box, camera_lens_box, face_y = _camera_boxes(profile, camera, pz1, L)
    lens_x, projector_box, projector_lens_box = _projector_boxes(profile, p_cop, px1, focus.cop_distance)
    shims = shims_nominal(profile)
    shelf_t = 2 * tw.wall
    shelf_top = _shelf_top(profile, cop_z, pz0, dome_top_z)
    wall_out = bs.width / 2 + GROOVE_GAP + tw.wall
    bracket_y = face_y - shims * tw.shim_thickness
    if bracket_y < -wall_out + tw.wall:
        raise GeometryError(f"the camera bracket would stand outside the splitter holder's wall: camera.pupil_height "
                            f"({cm.pupil_height:g} mm) is larger than the splitter's half width allows",
                            where=profile.where("camera", "pupil_height"))
    foot_half = tw.column_width / 2 + 3 * tw.bolt_diameter
    return TowerLayout(
        plate=plate, camera=camera, projector_cop=tuple(float(v) for v in p_cop), cop=(0.0, 0.0, cop_z),
        bench_z=-(profile.base_plate.thickness + profile.sample_holder.stop_thickness + COLLAR_BENCH_GAP_MM),
        shelf_top_z=shelf_top,
        shelf_thickness=shelf_t, holder_x=(px0 - GROOVE_GAP - 1.0 - tw.wall, px1 + tw.wall), holder_top_z=pz1 + tw.wall,
        plate_bottom_z=pz0,
        wall_y=(bs.width / 2 - GROOVE_DEPTH, wall_out), bracket_y=bracket_y,
        column_x=plate_r + tw.clearance + foot_half, column_base_z=0.0, column_foot_half=foot_half,
        projector_box=projector_box, projector_lens_box=projector_lens_box, camera_box=camera_box,
        camera_lens_box=camera_lens_box, lens_x=lens_x,
        bundle_radius_at_shelf=_bundle_radius(profile, geometry, cop_z - (shelf_top - shelf_t)),
        shims_nominal=shims, shims_per_stack=2 * shims,
        projector_feet=tuple((float(p_cop[0] + a), float(c)) for a, c in mount_pattern(profile.projector)))


# -- the printed parts -----------------------------------------------------------------------------
def _holes(points, diameter: float, z0: float, height: float) -> tuple[Cylinder, ...]:
    return tuple(Cylinder((float(x), float(y), z0 - 1.0), diameter / 2, height + 2.0) for x, y in points)


def _slot(x: float, y: float, half_x: float, half_y: float, z0: float, height: float) -> Box:
    """A rectangular slot (a bolt moves half_x - r each way in x, half_y - r in y) through z0..z0+height."""
    return Box((x - half_x, y - half_y, z0 - 1.0), (x + half_x, y + half_y, z0 + height + 1.0))


def _column_flange_points(t: TowerLayout, profile: Profile):
    h = profile.tower.column_width / 2 + 1.5 * profile.tower.bolt_diameter
    return [(t.column_x + a * h, b * h) for a in (-1, 1) for b in (-1, 1)]


def column_dowel_points(t: TowerLayout, profile: Profile):
    """The two dowel pins of each column joint (x, y; mm): on the x axis either side of the tube,
    between the bolts, as far apart as the foot allows (the joint's angle error is fit / spacing)."""
    h = profile.tower.column_width / 2 + 1.5 * profile.tower.bolt_diameter
    return [(t.column_x - h, 0.0), (t.column_x + h, 0.0)]


#: A printed face lapped flat (mm): rubbed on abrasive paper (P240, wet) laid on float glass until a steel
#: straightedge across it admits no 0.03 mm feeler leaf (a shop step: the tower's hardware rows state it).
#: The printed column's glue faces are lapped so: two faces glued leave the upper piece leaning by at
#: most 2 x this over the tube's side.
LAPPED_FLATNESS = 0.03
#: A bought column: 40 x 40 mm aluminium extrusion (slot 8) whose ends stand in square pockets in the
#: base plate's tongue and under the shelf (POCKET_DEPTH deep, POCKET_GAP wider each side than the
#: extrusion's nominal 40 mm, whose tolerance is about +-0.2 mm: ream or file the pocket to a slide
#: fit), held by an M8 bolt into the extrusion's tapped core at each end.
EXTRUSION = 40.0
#: The bought extrusion's mass per length (kg/m; assumed: makers' catalogues give 1.4-1.9 kg/m for 40 x
#: 40 mm slot-8 profiles, light to heavy; the drawn column is its square envelope, 4.3 kg/m as solid).
EXTRUSION_KG_PER_M = 1.6
POCKET_DEPTH = 1.5
POCKET_GAP = 0.1
CORE_BOLT_HOLE = 9.0  #: M8 clearance (ISO 273 medium)


def column_joint_cuts(t: TowerLayout, profile: Profile, z0: float, height: float, face: str) -> tuple:
    """What a column joint cuts into the plate it stands on (``face`` "top": the base plate's tongue)
    or hangs under ("bottom": the shelf), through z0..z0+height: the printed column's bolt and dowel
    holes, or the bought extrusion's square pocket and core bolt hole."""
    if profile.buy.column == "print":
        return column_joint_holes(t, profile, z0, height)
    h = EXTRUSION / 2 + POCKET_GAP
    zp = z0 + height - POCKET_DEPTH if face == "top" else z0 - 1.0
    pocket = Box((t.column_x - h, -h, zp), (t.column_x + h, h, zp + POCKET_DEPTH + 1.0))
    cuts = (pocket, *_holes([(t.column_x, 0.0)], CORE_BOLT_HOLE, z0, height))
    if face == "bottom":  # the shelf: its top screw's head flush in a 90 deg countersink
        cuts += (Translate(_countersink(), (t.column_x, 0.0, z0 + height)),)
    return cuts


def _countersink() -> Revolve:
    """The 90 deg countersink for the top core screw's head, its rim at z = 0 (mm), 1 mm of air above."""
    r, k = CORE_TOP_SCREW[0] / 2 + 0.2, CORE_TOP_SCREW[1]
    bottom = r - k - 0.2  # 45 deg flanks: the cone's radius at the head's underside depth, and a little play
    return Revolve(Section((Line((0.0, -k - 0.2), (bottom, -k - 0.2)), Line((bottom, -k - 0.2), (r, 0.0)),
                            Line((r, 0.0), (r, 1.0)), Line((r, 1.0), (0.0, 1.0)), Line((0.0, 1.0), (0.0, -k - 0.2)))))


#: Hexagonal nut traps under the tongue (mm): the M4 nut's 7.0 mm across flats and a printed fit's gap
#: (0.2 mm) on each flat; a corner on +x (NUT_TRAP_TURN, rad). The nut (4.04 mm to a corner) cannot turn
#: in it (3.7 mm to a flat). Its depth (:func:`nut_trap_depth`) puts the nut so high that the longest
#: stocked bolt that ends BENCH_CLEAR above the bench stands one thread out of it (every thread of the
#: nut engaged); the tongue then stands on the bench (the assembly check, rigcad.manual.tower_joints,
#: verifies both, the nut drawn as its hexagon).
NUT_TRAP_GAP = 0.2
NUT_TRAP = THREADS["M4"].nut_af + 2 * NUT_TRAP_GAP
NUT_TRAP_TURN = 0.0
#: A bolt that ends in a nut stands out of it by at least this many threads (pitches): the nut's every
#: thread engaged, and the length left for the conical spring washer's free height.
NUT_PROUD_PITCHES = 1
#: The column foot's bolts end at least this far (mm) above the bench: the tongue stands on the bench.
BENCH_CLEAR = 0.5
#: The least printed roof (mm) left over a nut trap in the tongue: the nut's bearing face presses on it
#: (six 0.45 mm perimeters' worth of solid layers: not a skin).
TRAP_ROOF_MIN = 3.0


def spring_washer(thread: str) -> tuple[str, float]:
    """The DIN 6796 conical spring washer under the head of a bolt that locates a datum (creep would relax
    the joint: rigcad.fab.loads marks them): its name and its free height h max (mm), which the grip counts
    (the tower's preloads, under 1.2 kN, leave it near free: DIN 6796 M4 flattens at about 3 kN)."""
    d1, d2, s, h = CONICAL_SPRING_WASHERS[thread]
    return f"{thread} conical spring washer (DIN 6796, {d2:g} mm outside, {h:g} mm free height)", h


def column_foot_bolt(profile: Profile, t: TowerLayout) -> dict:
    """The printed column's foot bolts (mm): down through the conical spring washer and the large washer
    (:func:`spring_washer`, the column's opened hole's washers), the foot and the tongue into a nut in
    its trap: the longest stocked ISO 4762 length that ends BENCH_CLEAR above the bench (the head stands
    on the foot, so the bolt's end depends on its length alone), and the trap deep enough that the bolt
    stands NUT_PROUD_PITCHES threads out of the nut (depth rounded up to 0.1 mm). GeometryError, naming
    ``base_plate.thickness``, when the trap would leave less than TRAP_ROOF_MIN of roof."""
    from rigcad.parts.washers import washers_over

    th = THREADS["M4"]
    stack = washers_over("M4", ("round", column_bolt_hole(t, profile))).thickness + spring_washer("M4")[1]
    # the head's face over the bench: the washers on the compression limiter, the plastic squeezed to it
    head = stack + profile.tower.wall - t.bench_z - LIMITER_SQUEEZE_MM
    length = longest_screw("M4", head - BENCH_CLEAR)
    depth = math.ceil((NUT_PROUD_PITCHES * th.pitch + th.nut_height + head - length) * 10 - 1e-6) / 10
    depth = max(depth, th.nut_height)
    if -t.bench_z - depth < TRAP_ROOF_MIN:
        raise GeometryError(f"the column foot's nut traps ({depth:.1f} mm deep) would leave {-t.bench_z - depth:.1f} mm "
                            f"of the {-t.bench_z:g} mm tongue over the nut (at least {TRAP_ROOF_MIN:g} mm): thicken "
                            "base_plate.thickness", where=profile.where("base_plate", "thickness"))
    grip = head - depth
    return {"length_mm": float(length), "trap_depth_mm": depth, "grip_mm": grip, "washers_mm": stack,
            "proud_mm": length - grip - th.nut_height, "above_bench_mm": head - length,
            "limiter_mm": grip - stack}


def nut_trap_depth(profile: Profile, t: TowerLayout) -> float:
    """The column foot's nut traps' depth (mm) from the bench: :func:`column_foot_bolt`."""
    return column_foot_bolt(profile, t)["trap_depth_mm"]
#: Counterbore under the tongue for the extrusion's M8 socket head (13 mm, 8 mm tall; ISO 4762):
#: diameter, depth (mm). An ISO 7089 M8 washer (16 mm) does not fit it: the head bears on the floor.
CORE_HEAD_BORE = (14.0, 8.5)
#: The top core screw: an M8 countersunk socket screw, ISO 10642 (head 16 mm across, 4.4 mm tall, 5 mm
#: hex key; its length includes the head), flush in a 90 deg countersink in the shelf's top: the
#: projector stands on its shims only ~2 mm above the shelf (a cap screw's 8 mm head would hit it;
#: the assembly check, rigcad.manual.tower_joints, verifies the projector clears the screw).
CORE_TOP_SCREW = (16.0, 4.4, 5.0)
#: The extrusion's ends are tapped M8 this deep (mm); a core bolt's thread stops 1 mm short of it.
CORE_TAP_DEPTH = 20.0


def core_bolt_lengths(profile: Profile, t: TowerLayout) -> dict[str, float]:
    """The bought extrusion's M8 core screws (mm): "foot" (ISO 4762, up from the tongue's counterbore)
    and "top" (ISO 10642 countersunk, down from the shelf's top; its length includes the head), each
    the longest stocked length whose thread stops 1 mm short of the tapped depth."""
    grips = {"foot": -t.bench_z - CORE_HEAD_BORE[1] - POCKET_DEPTH, "top": t.shelf_thickness - POCKET_DEPTH}
    return {k: float(longest_screw("M8", g + CORE_TAP_DEPTH - 1.0)) for k, g in grips.items()}


def tongue_underside_cuts(t: TowerLayout, profile: Profile, z_bottom: float) -> tuple:
    """What the column joint cuts into the tongue's underside (z_bottom: the bench): a hexagonal nut
    trap under each of the printed column's bolts, or a counterbore for the extrusion's M8 head."""
    if profile.buy.column != "print":
        d, depth = CORE_HEAD_BORE
        return (Cylinder((t.column_x, 0.0, z_bottom - 1.0), d / 2, depth + 1.0),)
    depth = nut_trap_depth(profile, t)
    return tuple(HexPrism((x, y, z_bottom - 1.0), NUT_TRAP, depth + 1.0, NUT_TRAP_TURN)
                 for x, y in _column_flange_points(t, profile))


def column_datums(t: TowerLayout, profile: Profile, z0: float, height: float, face: str, where: str) -> tuple[Datum, ...]:
    """The column joint's datum features in the plate it stands on or hangs under (``where`` names
    it): the printed column's two dowel holes, or the bought extrusion's square pocket (a register)."""
    if profile.buy.column == "print":
        return datums_of("dowel", f"{where} dowel hole",
                         _holes(column_dowel_points(t, profile), profile.datum.dowel_diameter, z0, height))
    return (Datum(f"{where} extrusion pocket", "register", column_joint_cuts(t, profile, z0, height, face)[0]),)


def column_register(t: TowerLayout, profile: Profile, z0: float, height: float, end: str):
    """The printed column's dowel register at one ``end`` ("foot" or "top") through its flange at
    z0..z0+height (rigcad.parts.locating.DowelRegister): the pins stand in round reamed holes in the
    tongue (foot) or the shelf (top); the column's flange takes the first in a round hole and the
    second in a slot along the line between them, so the print's scale error over their spacing
    cannot bind the joint (two round holes at each end would)."""
    from rigcad.parts.locating import DowelRegister

    d = profile.datum
    a, b = column_dowel_points(t, profile)
    spacing = math.dist(a, b)
    other = (t.bench_z, t.column_base_z) if end == "foot" else (t.shelf_top_z - t.shelf_thickness, t.shelf_top_z)
    return DowelRegister(f"column {end}", "tower_column", "base_plate" if end == "foot" else "tower_shelf",
                         d.dowel_diameter, (a, b), (z0, z0 + height), other,
                         2 * (2 * d.print_position + d.print_scale * spacing), param="datum.dowel_diameter")


#: The printed column's joints are on the datum chain (the rule: rigcad.parts.joints.LIMITER_SQUEEZE_MM), so
#: each of their M4 bolts runs through a steel compression limiter (rigcad.standards.COMPRESSION_LIMITERS): at
#: the foot, through the foot's flange and the tongue down to the nut in its trap (the nut bears on the
#: sleeve, not on the trap's roof); at the top, through the top flange up to the shelf's insert (a tapped
#: aluminium shelf: its face). Each hole the sleeve passes is wider than the bolt's by the sleeve's walls.
COLUMN_LIMITER = COMPRESSION_LIMITERS["M4"]
LIMITER_WALLS = COLUMN_LIMITER.outer - THREADS["M4"].major


def column_bolt_hole(t: TowerLayout, profile: Profile) -> float:
    """The printed column's bolt holes (mm): opened past the M4 clearance by both parts' print position
    errors and the scale error out to the farthest bolt from the round pin, each side
    (rigcad.parts.locating.bolt_hole), so the dowels locate and the bolts only clamp; and wider by the
    compression limiter's walls (:data:`COLUMN_LIMITER`), which rides on the bolt."""
    from rigcad.parts.locating import bolt_hole

    d = profile.datum
    pin = column_dowel_points(t, profile)[0]
    far = max(math.dist(pin, q) for q in _column_flange_points(t, profile))
    return bolt_hole("M4", far, d.print_position, d.print_scale) + LIMITER_WALLS


def _column_own_holes(t: TowerLayout, profile: Profile, z0: float, height: float, end: str) -> tuple:
    """The printed column's flange at one end: its opened bolt holes and its register's round hole
    and slot (:func:`column_register`)."""
    return (_holes(_column_flange_points(t, profile), column_bolt_hole(t, profile), z0, height)
            + column_register(t, profile, z0, height, end).upper_holes())


def column_joint_holes(t: TowerLayout, profile: Profile, z0: float, height: float) -> tuple[Cylinder, ...]:
    """The bolt holes of a column joint through z0..z0+height (the column's foot on the base plate's
    tongue) and its register's blind dowel holes from the tongue's top (DowelRegister.lower_holes)."""
    return (_holes(_column_flange_points(t, profile), profile.tower.bolt_diameter + LIMITER_WALLS, z0, height)
            + column_register(t, profile, t.column_base_z, profile.tower.wall, "foot").lower_holes())


#: The shelf's joint to the printed column's top flange: bolts up from under the flange into M4
#: heat-set inserts (SHELF_INSERT; a bought aluminium shelf is tapped M4 instead) in blind holes in
#: the shelf's underside, so nothing stands proud of the shelf's top under the projector, which stands
#: on its shims only a few mm above it.


def shelf_joint_cuts(t: TowerLayout, profile: Profile, z0: float) -> tuple:
    """What the column joint cuts into the shelf from its underside (z0): for a printed column, a blind
    insert hole (SHELF_INSERT, 0.5 mm deeper) at each bolt and the register's blind hole at each dowel
    (rigcad.parts.locating.DowelRegister.lower_holes: its floor stops the pin); for a
    bought extrusion, its pocket and core bolt hole (:func:`column_joint_cuts`)."""
    if profile.buy.column != "print":
        return column_joint_cuts(t, profile, z0, t.shelf_thickness, "bottom")
    d, long = SHELF_INSERT.hole, SHELF_INSERT.length
    blind = tuple(Cylinder((x, y, z0 - 1.0), d / 2, long + 1.5) for x, y in _column_flange_points(t, profile))
    top = t.shelf_top_z - t.shelf_thickness  # the column's top flange under the shelf: its register's blind holes
    return blind + column_register(t, profile, top - profile.tower.wall, profile.tower.wall, "top").lower_holes()


def shelf_bolt_length(profile: Profile) -> float:
    """The shelf joint's bolt (mm): the longest stocked ISO 4762 length that stops 0.5 mm short of the
    insert's end, through the column's flange (its compression limiter: the flange squeezed to it), its
    large washer and the conical spring washer (:func:`spring_washer`) under its head."""
    from rigcad.parts.locating import bolt_hole
    from rigcad.parts.washers import washers_over

    # the large washer the column's opened hole takes (column_bolt_hole, before the layout: its largest)
    d = profile.datum
    far = 2 * (profile.tower.column_width / 2 + 1.5 * profile.tower.bolt_diameter)
    hole = bolt_hole("M4", far, d.print_position, d.print_scale) + LIMITER_WALLS
    reach = (shelf_limiter_length(profile) + washers_over("M4", ("round", hole)).thickness + spring_washer("M4")[1]
             + SHELF_INSERT.length - 0.5)
    return float(longest_screw("M4", reach))


def shelf_limiter_length(profile: Profile) -> float:
    """The top joint's compression limiter (mm, as drawn): the column's top flange less the squeeze."""
    return profile.tower.wall - LIMITER_SQUEEZE_MM


def limiter_step(where: str, count: int, length: float, seat: str) -> str:
    """The shop step that fits ``count`` of the column's compression limiters (:data:`COLUMN_LIMITER`)
    ``where``, faced to ``length`` mm as drawn, the sleeve's end on ``seat``."""
    lim = COLUMN_LIMITER
    return (f"part off {count} compression limiters from {lim.outer:g} x {lim.wall:g} mm steel tube ({lim.source}) on "
            f"the lathe and face each to the printed span measured with a micrometer at its hole ({where}) less "
            f"{LIMITER_SQUEEZE_MM:g} mm ({length:.2f} mm as drawn), square and deburred; drop one into each bolt hole, "
            f"its end on {seat}, before the bolt")


def _holder_flange_points(t: TowerLayout, profile: Profile):
    """The two spring bolts that hold the splitter holder down on its seat (x, y; mm; -y first), 8 mm
    inside the holder's back end. The plate slides in along -y over the +y one: where that bolt's top
    (its end over the nut, washers and spring) would stand in the plate's way in (a low projector raises
    the shelf, and the holder on it, up to the plate), it stands behind the plate's lowest edge instead,
    clear by the spring's play on the bolt and GROOVE_GAP; the -y one is never in the way."""
    tw, m4, sp = profile.tower, THREADS["M4"], SEAT_SPRING
    y = t.wall_y[1] + 1.5 * tw.bolt_diameter
    x = t.holder_x[0] + 8.0
    play = (sp["outer_diameter"] - 2 * sp["wire"] - m4.major) / 2  # the spring off-centre on the bolt
    reach = max(m4.washer_od, sp["outer_diameter"], 2 * m4.nut_corner_radius) / 2 + play
    need = _spring_bolt_grip(profile, t) + nut_allowance("M4")
    length = shortest_screw("M4", need) or need  # where it stands only: the bill refuses a length none stocks
    top = t.shelf_top_z - t.shelf_thickness - m4.washer_thickness + length
    if top + GROOVE_GAP <= _plate_floor(t, x - reach):
        return [(x, -y), (x, y)]
    return [(x, -y), (min(x, _plate_extent(t.plate)[0] - reach - GROOVE_GAP), y)]


def _plate_floor(t: TowerLayout, x: float) -> float:
    """The splitter plate's lowest z (mm) at or past ``x`` (toward +x), anywhere along its way in (a
    slide along y): its lowest edge, or its front face at ``x`` (splitter_plate's 45 deg plate faces
    +x and down, so every point of it has z - x >= that of its centre)."""
    cx, _, cz = t.plate.center
    return max(t.plate_bottom_z, x + cz - cx)


def _spring_bolt_grip(profile: Profile, t: TowerLayout) -> float:
    """What a spring bolt passes (mm): the shelf, the seat's gap, the holder's flange, the free spring."""
    return t.shelf_thickness + seat_gap(profile) + profile.tower.wall + SEAT_SPRING["free_length"]


def spring_bolt_length(profile: Profile, t: TowerLayout) -> float:
    """The splitter holder's spring bolts' length (mm): through their grip with two washers and a nut
    past it (GeometryError when no stocked M4 screw is that long)."""
    return _length("M4", _spring_bolt_grip(profile, t), nut_allowance("M4"))


#: The shelf's M4 heat-set inserts (rigcad.standards.INSERTS: the maker's hole and the insert's length).
SHELF_INSERT = INSERTS["M4"]
#: Clearance (mm) of the spring bolts in the holder's flanges: room to tilt by the seat's travel.
SPRING_HOLE = 6.0


#: An adjuster serves a tolerance when its resolution is at most this share of it: a setting must land
#: well inside the tolerance, not merely within one step of its edge (rigcad.fab.stack reads it too).
RESOLUTION_SHARE = 0.25
#: The flat's screw stands this much farther out than the least lever its resolution needs, so that a
#: printed flange a little short still serves (a margin on the lever, not a tolerance).
FLAT_LEVER_MARGIN = 1.1


def flat_lever(profile: Profile) -> float:
    """The least lever (mm) of the seat's flat screw about the cone-vee line: its step (the seat
    thread's pitch x ``adjusters.turn_fraction``) tilts the plate in its plane of incidence, which
    turns the reflected (projector's) axis by twice as much; that turn must be at most
    RESOLUTION_SHARE of ``tolerancing.projector_tilt``."""
    a = profile.adjusters
    step = THREADS[a.seat_thread].pitch * a.turn_fraction
    return 2 * step / (RESOLUTION_SHARE * profile.tolerancing.projector_tilt)


def _flat_reach(t: TowerLayout, profile: Profile) -> float:
    """How far (mm) the flat's screw stands behind the holder's back wall (-x): under the middle of a
    back flange three bolts wide, or farther when its lever would be short of FLAT_LEVER_MARGIN x
    :func:`flat_lever` (the flange then reaches back to it)."""
    tw = profile.tower
    cone_x = t.holder_x[1] - 8.0
    reach = max(1.5 * tw.bolt_diameter, FLAT_LEVER_MARGIN * flat_lever(profile) - (cone_x - t.holder_x[0]))
    if reach > t.holder_x[1] - t.holder_x[0]:
        a = profile.adjusters
        raise GeometryError(f"the splitter seat's flat screw would need a {flat_lever(profile):.0f} mm lever (its "
                            f"{a.seat_thread} pitch x {a.turn_fraction:g} turn, twice on the reflected axis, within "
                            f"{RESOLUTION_SHARE:g} of tolerancing.projector_tilt): a back flange longer than the holder; "
                            "use a finer adjusters.seat_thread or a smaller adjusters.turn_fraction",
                            where=profile.where("adjusters", "seat_thread"))
    return reach


def seat_points(t: TowerLayout, profile: Profile) -> dict[str, tuple[float, float]]:
    """The splitter holder's kinematic seat (x, y; mm): a cone and a vee under the side flanges at its
    +x end, a flat under its back flange (y = 0), as far back as its screw's resolution needs
    (:func:`flat_lever`): each a ball-ended push screw in the holder over its seat in the shelf
    (:func:`splitter_seat`). The vee's pins point at the cone."""
    tw = profile.tower
    y = t.wall_y[1] + 1.5 * tw.bolt_diameter
    x0, x1 = t.holder_x
    return {"cone": (x1 - 8.0, -y), "vee": (x1 - 8.0, y), "flat": (x0 - _flat_reach(t, profile), 0.0)}


#: The seat's push screws: cup-point socket set screws (ISO 4029; ASME B18.3 for a UNC thread) in
#: heat-set inserts in bosses on the holder's flanges, each with a steel ball (``adjusters.seat_ball``,
#: ISO 3290 grade G10) held in its cup by a drop of retaining compound: a hard ball on the screw's end,
#: centred by the cup's rim. The ball must stand clear of the rim by this much of its radius (a ball
#: no larger than the cup would fall into it).
SEAT_BALL_OVER_CUP = 1.2
#: The screws' end stays this far (mm) below the holder's underside at their shortest setting.
SEAT_SCREW_CLEAR = 0.5
#: Floor (mm) under each insert's pocket in its boss: the screw passes it in a clearance hole.
SEAT_BOSS_FLOOR = 1.0
#: Wall (mm) round an insert's knurl in its boss: five 0.4 mm perimeters.
SEAT_BOSS_WALL = 2.0
#: The flat: an ISO 3650 gauge block (hardened steel, lapped flat) of this nominal length (mm), in a
#: pocket its own size, its top flush with the shelf's top.
SEAT_PAD_LENGTH = 2.0
#: The vee's two ISO 8734 dowel pins (mm long) side by side in a channel along the line to the cone.
SEAT_PIN_LENGTH = 10
#: The two preload springs: helical compression springs of patented spring steel wire (EN 10270-1 SH),
#: ends closed and ground, over the M4 spring bolts (inner diameter 6.2 mm), as ordered: wire, outer
#: diameter, free length (mm), active coils; and the length (mm) the nut sets them to, which the manual
#: keeps through the seat's adjustment (each spring measured with the caliper before and after). Sized so
#: that a side pull of rigcad.fab.seat_hold.SIDE_PULL_N at the camera lifts no ball
#: (rigcad.fab.seat_hold.check): 22.3 N/mm, 58 N each at 10.9 mm (0.8 mm wire springs at 14 N each let a
#: 3 N pull lift one); the free length the longest an ISO 4762 M4 bolt (40 mm) carries through the shelf,
#: the gap and the flange. While the screws are turned (+-``adjusters.seat_travel``, before the nuts are
#: reset) they run 25-91 N, clear of solid length and under 0.5 Rm of the wire in shear
#: (:func:`spring_preloads`, :func:`spring_stress`).
SEAT_SPRING = {"wire": 1.4, "outer_diameter": 9.0, "free_length": 13.5, "active_coils": 4, "installed_length": 10.9}
#: The least tensile strength (MPa) of EN 10270-1 SH wire 1.4 mm thick (the standard's table: 1,990-2,230 MPa);
#: EN 13906-1 allows a statically loaded spring 0.5 of it in (Wahl-corrected) shear.
SEAT_SPRING_RM = 1990.0
#: The camera's cable: tied to the column so that its pull and weight bear there, not on the camera on
#: its seat (rigcad.fab.seat_hold.SIDE_PULL_N is what is left: the loop between the tie and the camera).
#: Cable ties (IEC 62275, polyamide 6.6, 4.8 mm wide), two round the column under the shelf, 100 mm apart;
#: the loop from the camera to the upper tie left slack by this much (mm) over the straight run.
CABLE_TIE = {"width": 4.8, "lengths": (100, 140, 200, 300, 370, 450), "count": 2, "slack": 50.0, "cable": 8.0}


def cable_tie_length(profile: Profile) -> int:
    """The shortest stocked cable tie (mm, CABLE_TIE) that goes round the column (its printed side, or
    the bought extrusion's) and the camera's cable with 30 mm for the head and the tail to pull."""
    side = profile.tower.column_width if profile.buy.column == "print" else EXTRUSION
    need = 4 * side + math.pi * CABLE_TIE["cable"] + 30.0
    fits = [n for n in CABLE_TIE["lengths"] if n >= need]
    if not fits:
        raise GeometryError(f"no stocked cable tie ({max(CABLE_TIE['lengths'])} mm the longest) goes round the "
                            f"{side:g} mm column: {need:.0f} mm needed", where=profile.where("tower", "column_width"))
    return fits[0]


@dataclass(frozen=True)
class SeatGeometry:
    """The splitter seat's heights (mm, above the shelf's top ``S``) and sizes, from the profile:
    ``ball`` (the hard balls, on the screws and in the cone), ``pin`` (the vee's dowels), ``cup_rise``
    (a ball's centre under its screw's cup rim), ``centre`` (the screws' balls' centres at the nominal
    setting: on the flat pad, flush with the shelf), ``cone_drop`` and ``vee_drop`` (the cone's balls'
    and the vee's pins' centres under ``centre``), ``gap`` (the holder's underside over the shelf)."""

    ball: float
    pin: float
    cup_rise: float
    centre: float
    cone_drop: float
    vee_drop: float
    gap: float
    travel: float

    @property
    def cone_radius(self) -> float:
        """Radius (mm) of the pocket that holds the cone's three balls touching each other."""
        return self.ball / math.sqrt(3.0) + self.ball / 2

    @property
    def cone_floor(self) -> float:
        return self.centre - self.cone_drop - self.ball / 2

    @property
    def vee_floor(self) -> float:
        return self.centre - self.vee_drop - self.pin / 2


def seat_geometry(profile: Profile) -> SeatGeometry:
    """The seat's geometry (:class:`SeatGeometry`); GeometryError when the ball cannot sit on its
    screw's cup."""
    a = profile.adjusters
    ball, cup = a.seat_ball, CUP_POINT[a.seat_thread]
    if ball < SEAT_BALL_OVER_CUP * cup:
        raise GeometryError(f"adjusters.seat_ball ({ball:g} mm) cannot sit on the {a.seat_thread} cup-point screw's "
                            f"{cup:.2f} mm cup: use a ball of at least {SEAT_BALL_OVER_CUP * cup:.2f} mm",
                            where=profile.where("adjusters", "seat_ball"))
    pin = dowel_diameter_for(ball)
    rise = math.sqrt((ball / 2) ** 2 - (cup / 2) ** 2)
    centre = ball / 2
    cone = math.sqrt(ball ** 2 - ball ** 2 / 3.0)  # a ball on three of its size, touching: sqrt(2/3) d
    vee = math.sqrt(((ball + pin) / 2) ** 2 - (pin / 2) ** 2)
    gap = centre + rise + a.seat_travel + SEAT_SCREW_CLEAR
    return SeatGeometry(ball, pin, rise, centre, cone, vee, gap, a.seat_travel)


def seat_gap(profile: Profile) -> float:
    """Gap (mm) between the shelf's top and the holder's underside with the screws at their nominal
    setting: the balls' centres over the flat pad, their screws' cup rims above, the screws' travel
    and SEAT_SCREW_CLEAR, so the holder never comes down onto the seat."""
    return seat_geometry(profile).gap


#: The seat's pockets in the shelf (the cone's round pocket, the vee's channel, the flat's pocket) are
#: drawn larger than the hard parts they hold by the hole shrink the design allows the printed process
#: (SEAT_POCKET_SHRINK, mm diametral: the largest a shipped printer file's ``process_errors`` states, its
#: horizontal axis's 0.3 mm; the shelf prints flat, its pockets' axes vertical, 0.1-0.2 mm) and a
#: clearance (SEAT_POCKET_CLEARANCE, mm): on every shipped printer each prints a clearance fit the part
#: drops into by hand, and the part is bonded in with gap-filling epoxy (SEAT_BOND), seated under load.
#: Drawn at the hardware's own size they printed 0.1-0.3 mm under it (an interference a printed wall
#: cracks on). :func:`seat_pocket_fits` states each fit on a given process; a process whose shrink exceeds
#: the allowance gets the shop step that opens the pocket to its drawn size.
SEAT_POCKET_SHRINK = 0.3
SEAT_POCKET_CLEARANCE = 0.1
#: The bond: a two-part gap-filling epoxy (Loctite EA 3430 class: its data sheet's gap fill taken at
#: 0.5 mm, the figure rigcad.fab.seams's epoxy carries), the largest printed gap it fills (mm).
SEAT_BOND = ("two-part gap-filling epoxy (Loctite EA 3430 class)", 0.5)


def _pocket_sizes(profile: Profile) -> dict[str, tuple[str, tuple[float, ...]]]:
    """Each seat pocket's hardware, and the sizes (mm, across the pocket) the hardware fills: the cone's
    three balls touching (their circumscribed circle), the vee's two pins side by side (width, length),
    the flat's gauge block (its face)."""
    g = seat_geometry(profile)
    pad_y, pad_x = GAUGE_BLOCK_FACE
    return {"cone": (f"three {g.ball:g} mm balls (ISO 3290-1) touching", (2 * g.cone_radius,)),
            "vee": (f"two {g.pin:g} mm dowel pins (ISO 8734 m6) side by side", (2 * g.pin, float(SEAT_PIN_LENGTH))),
            "flat": (f"a {SEAT_PAD_LENGTH:g} mm gauge block (ISO 3650)", (pad_x, pad_y))}


def seat_pocket_fits(profile: Profile, process=None) -> list[dict]:
    """The seat's pockets as a fit table (mm, diametral): each pocket's hardware and its sizes, the drawn
    sizes (the hardware's + SEAT_POCKET_SHRINK + SEAT_POCKET_CLEARANCE), and, given a printer's
    ``process`` (rigcad.parts.process.ProcessErrors), the sizes as printed (its shrink for a vertical
    axis: the shelf prints flat), the smallest gap and the fit's class ("clearance" within the bond's gap,
    "loose" past it, "interference"), with the shop step that makes it right."""
    allow = SEAT_POCKET_SHRINK + SEAT_POCKET_CLEARANCE
    glue, most = SEAT_BOND
    rows = []
    for pocket, (what, sizes) in _pocket_sizes(profile).items():
        drawn = tuple(v + allow for v in sizes)
        row = {"pocket": pocket, "hardware": what, "hardware_mm": list(sizes), "drawn_mm": list(drawn),
               "allowance_mm": {"shrink": SEAT_POCKET_SHRINK, "clearance": SEAT_POCKET_CLEARANCE},
               "source": "drawn = hardware + the process shrink allowed (the shipped printers' largest, "
                         "process_errors) + a clearance; bonded with " + glue}
        step = (f"bond {what} into the {pocket}'s pocket with {glue}: butter the pocket's walls and floor, press the "
                "part to the floor, and let it cure with the holder standing on its seat (its screws' balls then seat "
                "it where they bear)")
        if process is not None:
            printed = tuple(v - process.shrink(v, "vertical") for v in drawn)
            gap = min(p - h for p, h in zip(printed, sizes))
            cls = "interference" if gap < 0 else ("loose" if gap > most else "clearance")
            if cls == "interference":
                step = (f"open the {pocket}'s pocket to its drawn {' x '.join(f'{v:.2f}' for v in drawn)} mm (it prints "
                        f"{' x '.join(f'{v:.2f}' for v in printed)} mm: a file, or a drill for the round one), then "
                        + step)
            row.update(printed_mm=list(printed), gap_mm=gap, fit=cls)
        row["step"] = step
        rows.append(row)
    return rows


def _seat_cuts(t: TowerLayout, profile: Profile) -> tuple:
    """The shelf's seats (cone, vee, flat): a round pocket that holds three balls touching (the cone:
    a ball on three balls), a channel that holds two dowel pins side by side along the line to the
    cone (the vee), a pocket the gauge block fills flush with the shelf's top (the flat). Each drawn
    SEAT_POCKET_SHRINK + SEAT_POCKET_CLEARANCE over its hardware (:func:`seat_pocket_fits`): a
    clearance fit on every shipped printer, the hardware bonded in."""
    g = seat_geometry(profile)
    top = t.shelf_top_z
    pts = seat_points(t, profile)
    (cx, cy), (vx, vy), (fx, fy) = pts["cone"], pts["vee"], pts["flat"]
    e = (SEAT_POCKET_SHRINK + SEAT_POCKET_CLEARANCE) / 2  # each side
    half = SEAT_PIN_LENGTH / 2 + e
    pad_y, pad_x = GAUGE_BLOCK_FACE  # the block's long side along y, under the back flange
    return (Cylinder((cx, cy, top + g.cone_floor), g.cone_radius + e, -g.cone_floor + 1.0),
            Box((vx - g.pin - e, vy - half, top + g.vee_floor), (vx + g.pin + e, vy + half, top + 1.0)),
            Box((fx - pad_x / 2 - e, fy - pad_y / 2 - e, top - SEAT_PAD_LENGTH),
                (fx + pad_x / 2 + e, fy + pad_y / 2 + e, top + 1.0)))


def _seat_boss(profile: Profile) -> tuple[float, float]:
    """The seat screws' bosses: radius, and height above the holder's flange (mm): the insert's pocket
    (the maker's depth) over SEAT_BOSS_FLOOR."""
    ins = INSERTS[profile.adjusters.seat_thread]
    return ins.outer / 2 + SEAT_BOSS_WALL, max(0.0, ins.pocket_depth + SEAT_BOSS_FLOOR - profile.tower.wall)


def seat_screw_length(profile: Profile) -> int:
    """The seat screws' length (mm, ISO 4029): through the boss and out by the longest setting, so the
    screw's whole length stays in the insert's thread at every setting."""
    a = profile.adjusters
    _, boss = _seat_boss(profile)
    need = profile.tower.wall + boss + 2 * a.seat_travel + SEAT_SCREW_CLEAR
    found = shortest_set_screw(a.seat_thread, need)
    if found is None:
        raise GeometryError(f"no {a.seat_thread} set screw is {need:.1f} mm long: lower adjusters.seat_travel",
                            where=profile.where("adjusters", "seat_travel"))
    return found


def spring_force(k: int = 1) -> dict:
    """The seat's preload springs (SEAT_SPRING): rate (N/mm, EN 13906-1) and the force of ``k`` of them
    at their installed length (N)."""
    sp = SEAT_SPRING
    mean = sp["outer_diameter"] - sp["wire"]
    rate = spring_rate(sp["wire"], mean, sp["active_coils"])
    return {"rate_N_per_mm": rate, "force_N": k * rate * (sp["free_length"] - sp["installed_length"])}


def spring_preloads(profile: Profile) -> dict:
    """One seat spring's preload (N) at the nominal setting and at the ends of the seat's travel
    (``adjusters.seat_travel`` each way: the holder raised compresses it, lowered lets it out)."""
    sp, travel = SEAT_SPRING, profile.adjusters.seat_travel
    rate = spring_force(1)["rate_N_per_mm"]
    defl = sp["free_length"] - sp["installed_length"]
    return {"least_N": rate * (defl - travel), "nominal_N": rate * defl, "most_N": rate * (defl + travel),
            "shortest_mm": sp["installed_length"] - travel}


def spring_stress(force: float) -> float:
    """A seat spring's shear stress (MPa) under ``force`` (N): 8 F D / (pi d^3), Wahl-corrected
    (EN 13906-1), D the mean coil diameter and d the wire (mm)."""
    sp = SEAT_SPRING
    d = sp["wire"]
    mean = sp["outer_diameter"] - d
    c = mean / d
    wahl = (4 * c - 1) / (4 * c - 4) + 0.615 / c
    return wahl * 8 * force * mean / (math.pi * d ** 3)


def splitter_seat(profile: Profile, layout) -> KinematicSeat:
    """The splitter holder's kinematic seat as data (rigcad.parts.joints.KinematicSeat): its three
    contacts, its screws' range and resolution, its springs' preload, and every bought hard part
    (the bill lists them: :attr:`KinematicSeat.bought`)."""
    t, a = layout.tower, profile.adjusters
    g = seat_geometry(profile)
    pts = seat_points(t, profile)
    z = t.shelf_top_z + g.centre
    (cx, cy), (vx, vy) = pts["cone"], pts["vee"]
    n = math.hypot(cx - vx, cy - vy)
    contacts = (SeatContact("cone", *pts["cone"], z), SeatContact("vee", *pts["vee"], z, ((cx - vx) / n, (cy - vy) / n)),
                SeatContact("flat", *pts["flat"], z))
    sp = SEAT_SPRING
    force = spring_force(1)
    springs = _holder_flange_points(t, profile)
    _check_preload_inside(contacts, springs, profile)
    thread = a.seat_thread
    std = "ISO 4029" if thread.startswith("M") else "ASME B18.3"
    bought = (
        Bought(f"{thread} x {seat_screw_length(profile)} mm cup-point socket set screw", std, 3,
               {"length": seat_screw_length(profile), "cup_diameter": CUP_POINT[thread]},
               "the seat's push screws, in the holder's bosses' heat-set inserts, turned from above"),
        Bought(f"{g.ball:g} mm steel ball, grade G10", "ISO 3290-1", 6, {"diameter": g.ball},
               "three in the screws' cups (a drop of retaining compound holds each), three bonded into the "
               "shelf's cone pocket, touching (its drawn size: seat_pocket_fits)"),
        Bought(f"dowel pin {g.pin:g} m6 x {SEAT_PIN_LENGTH} mm", "ISO 8734", 2,
               {"diameter": g.pin, "length": SEAT_PIN_LENGTH}, "the vee: bonded side by side into the shelf's channel"),
        Bought(f"gauge block {SEAT_PAD_LENGTH:g} mm, grade 2, steel", "ISO 3650", 1,
               {"length": SEAT_PAD_LENGTH, "face": list(GAUGE_BLOCK_FACE)},
               "the flat: bonded into its pocket, flush with the shelf's top"),
        Bought(f"compression spring, wire {sp['wire']:g} mm, {sp['outer_diameter']:g} mm outside, "
               f"{sp['free_length']:g} mm free, {sp['active_coils']} active coils, ends closed and ground",
               "EN 13906-1 (wire EN 10270-1)", len(springs),
               {"wire": sp["wire"], "outer_diameter": sp["outer_diameter"], "free_length": sp["free_length"],
                "installed_length": sp["installed_length"]},
               f"preload: on each spring bolt under its nut, set to {sp['installed_length']:g} mm "
               f"({force['force_N']:.1f} N each, {force['rate_N_per_mm']:.2f} N/mm): the seat takes a side pull at the "
               "camera without lifting a ball (rigcad.fab.seat_hold)"),
    )
    return KinematicSeat("splitter seat", "splitter_holder", "tower_shelf", contacts, thread, a.seat_travel,
                         a.turn_fraction, len(springs), force["rate_N_per_mm"],
                         sp["free_length"] - sp["installed_length"], bought)


def _check_preload_inside(contacts, springs, profile: Profile) -> None:
    """The springs' resultant (their mean point: equal springs) must lie inside the three contacts'
    triangle, or the preload would lift one contact off its seat."""
    (ax, ay), (bx, by), (cx, cy) = ((c.x, c.y) for c in contacts)
    px, py = (sum(p[0] for p in springs) / len(springs), sum(p[1] for p in springs) / len(springs))

    def side(x0, y0, x1, y1):
        return (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)

    s = (side(ax, ay, bx, by), side(bx, by, cx, cy), side(cx, cy, ax, ay))
    if not (all(v > 0 for v in s) or all(v < 0 for v in s)):
        raise GeometryError(f"the splitter seat's springs pull at ({px:.1f}, {py:.1f}) mm, outside its three contacts: "
                            "the preload would lift one off its seat", where=profile.where("tower", "bolt_diameter"))


def _lens_foot(t: TowerLayout, profile: Profile):
    """(x0, x1, half_y, bolt points) of the lens mount's foot."""
    ln, tw = profile.lens, profile.tower
    half_y = ln.diameter / 2 + GROOVE_GAP + tw.wall + 3 * tw.bolt_diameter
    half_x = max(ln.thickness / 2 + tw.wall / 2, tw.bolt_diameter / 2 + tw.travel_along + tw.wall)
    y = half_y - 1.5 * tw.bolt_diameter
    return t.lens_x - half_x, t.lens_x + half_x, half_y, [(t.lens_x, y), (t.lens_x, -y)]


def _projector_feet(t: TowerLayout):
    """(x, y) of the projector's mounting holes (rigcad.parts.projector_mount checks the shelf carries them)."""
    return list(t.projector_feet)


def _shelf_extent(t: TowerLayout, profile: Profile):
    tw = profile.tower
    (bx0, by0, _), (bx1, by1, _) = t.projector_box
    hy = t.wall_y[1] + 3 * tw.bolt_diameter
    _, _, lens_hy, _ = _lens_foot(t, profile)
    flange = tw.column_width / 2 + 3 * tw.bolt_diameter
    x0 = t.holder_x[0] - _flat_reach(t, profile) - 1.5 * tw.bolt_diameter - tw.wall  # under the holder's back flange
    x1 = max(bx1 + tw.wall, t.column_x + flange)
    y0 = min(by0 - tw.wall, -hy - tw.wall, -lens_hy - tw.wall, -flange)
    y1 = max(by1 + tw.wall, hy + tw.wall, lens_hy + tw.wall, flange)
    return x0, x1, y0, y1


def tower_column(profile: Profile, layout) -> Part:
    """Square hollow column on the base plate's datum tongue, under the projector's shelf: a foot and
    a top flange, each with four bolt holes and two dowel holes (the datum chain, rigcad.parts.datum)."""
    t, tw = layout.tower, profile.tower
    if profile.buy.column != "print":
        return _extrusion_column(profile, t)
    w = tw.column_width / 2
    top = t.shelf_top_z - t.shelf_thickness
    xc, z0 = t.column_x, t.column_base_z
    foot_h = t.column_foot_half
    foot = Box((xc - foot_h, -foot_h, z0), (xc + foot_h, foot_h, z0 + tw.wall))
    # the bore runs through the foot and the flange: a closed bore would be a sealed void (a second shell
    # in the STEP, an inward-facing box in the STL, a second part to the slicer)
    bore = Box((xc - w + tw.wall, -w + tw.wall, z0 - 1.0), (xc + w - tw.wall, w - tw.wall, top + 1.0))
    tube = Box((xc - w, -w, z0), (xc + w, w, top))
    flange = Box((xc - foot_h, -foot_h, top - tw.wall), (xc + foot_h, foot_h, top))
    holes = (*_column_own_holes(t, profile, z0, tw.wall, "foot"), *_column_own_holes(t, profile, top - tw.wall, tw.wall, "top"))
    datums = tuple(Datum(f"{where} dowel {kind}", "dowel", shape) for z, end, where in
                   ((z0, "foot", "foot"), (top - tw.wall, "top", "top flange"))
                   for kind, shape in (("hole", column_register(t, profile, z, tw.wall, end).upper_holes()[0]),
                                       ("slot", Union_(column_register(t, profile, z, tw.wall, end).upper_holes()[1:]))))
    return Part("tower_column", Difference(Union_((foot, tube, flange)), (bore, *holes)), (0.55, 0.57, 0.6),
                f"COP tower: hollow {tw.column_width:g} mm column on the base plate's datum tongue, under the "
                f"projector's shelf; two {profile.datum.dowel_diameter:g} mm dowels (a round hole and a slot in its flange) and "
                f"four bolts in {column_bolt_hole(t, profile):.1f} mm holes at each end",
                datums=datums)


def _extrusion_column(profile: Profile, t: TowerLayout) -> Part:
    """The bought column: the extrusion from the tongue's pocket to the shelf's."""
    h = EXTRUSION / 2
    z0, z1 = t.column_base_z - POCKET_DEPTH, t.shelf_top_z - t.shelf_thickness + POCKET_DEPTH
    return Part("tower_column", Box((t.column_x - h, -h, z0), (t.column_x + h, h, z1)), (0.75, 0.77, 0.8),
                f"COP tower: bought {EXTRUSION:g} x {EXTRUSION:g} mm aluminium extrusion column, standing in square "
                "pockets in the base plate's tongue and under the shelf, an M8 bolt into its core at each end",
                bought=f"aluminium extrusion {EXTRUSION:g} x {EXTRUSION:g} mm, slot 8, cut to {z1 - z0:.1f} mm, "
                       "ends sawn square (0.1 mm across 40 mm), core tapped M8 x 20 mm at both ends",
                mass_kg=EXTRUSION_KG_PER_M * (z1 - z0) / 1000.0)


def tower_shelf(profile: Profile, layout) -> Part:
    """The plate the projector stands on (on its shims), reaching over the optical axis, where the
    splitter holder and the lens mount stand; a hole lets the ray bundle down to the paraboloid."""
    t, tw, pj = layout.tower, profile.tower, profile.projector
    x0, x1, y0, y1 = _shelf_extent(t, profile)
    z0 = t.shelf_top_z - t.shelf_thickness
    plate = Box((x0, y0, z0), (x1, y1, t.shelf_top_z))
    hole = Cylinder((0.0, 0.0, z0 - 1.0), t.bundle_radius_at_shelf + tw.clearance, t.shelf_thickness + 2.0)
    d = clearance_hole(pj.mount_thread)
    slots = tuple(_slot(x, y, d / 2 + tw.travel_along, d / 2 + tw.travel_across, z0, t.shelf_thickness)
                  for x, y in _projector_feet(t))
    _, _, _, lens_pts = _lens_foot(t, profile)
    seat = _seat_cuts(t, profile)
    joint = shelf_joint_cuts(t, profile, z0)
    holes = joint + _holes(_holder_flange_points(t, profile) + lens_pts, tw.bolt_diameter, z0, t.shelf_thickness) + seat
    inserts = joint[:4] if profile.buy.column == "print" else ()
    datums = (*column_datums(t, profile, z0, t.shelf_thickness, "bottom", "shelf"),
              *datums_of("insert", "shelf insert pocket", inserts),
              *(Datum(f"splitter seat {kind}", "seat", cut) for kind, cut in zip(("cone", "vee", "flat"), seat)))
    bought = "" if profile.buy.shelf == "print" else (
        f"aluminium plate EN AW-5083, {t.shelf_thickness:g} mm, cut to {x1 - x0:.1f} x {y1 - y0:.1f} mm; drill and "
        "mill its holes, slots and the seat's cone, vee and flat as drawn (print the shelf at 0.2 mm layers as a "
        "drilling template)")
    return Part("tower_shelf", Difference(plate, (hole, *slots, *holes)), (0.55, 0.57, 0.6),
                f"COP tower: shelf under the projector; {pj.mount_thread} screws through its four slots "
                f"(+-{tw.travel_along:g} mm along the projector's axis, +-{tw.travel_across:g} mm across) hold it "
                "on its shim stacks; a hole passes the ray bundle", bought=bought, datums=datums)


def _groove(t: TowerLayout, y1: float) -> Translate:
    """The plate's slab in x-z with GROOVE_GAP around it: blind in the -y wall (GROOVE_DEPTH), through
    the +y wall (to ``y1``, mm), so the plate slides in along -y and rests on the groove's lower 45 deg
    faces."""
    p = t.plate
    n = np.array([p.normal[0], p.normal[2]])
    l_ = np.array([p.length_dir[0], p.length_dir[2]])
    c = np.array([p.center[0], p.center[2]])
    a = p.half_length + GROOVE_GAP
    front = c + GROOVE_GAP * n
    back = c - (p.thickness + GROOVE_GAP) * n
    pts = [front - a * l_, front + a * l_, back + a * l_, back - a * l_]
    pts = [(float(q[0]), float(q[1])) for q in pts]
    y0 = -(p.half_width + GROOVE_GAP)
    slab = Prism(Section(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4))), y1 - y0)
    return Translate(slab, (0.0, 0.5 * (y0 + y1), 0.0))


#: The splitter plate's retainer. The plate lies in its grooves on its coated face (the face that
#: reflects the projector's light), on the grooves' lower flanks: the datum flank. The grooves are
#: GROOVE_GAP wider than the plate each side, so, left loose, only gravity seats it and it can turn
#: across that play (:func:`plate_play`), its reflected axis twice as far. Dots of a neutral-cure
#: silicone RTV in the gap over its back face, near each end of each groove, dispensed with the holder
#: standing upright on the bench (the plate then lies on its datum flanks under its own weight, pressed
#: on with a finger at each edge) and cured there, fill the play: the plate cannot leave its datum flank,
#: and what remains is the flanks' printed position. Neutral (alkoxy) cure, not acetoxy: acetoxy RTV gives
#: off acetic acid, which attacks a dielectric or metal coating. The dots sit on the uncoated back face
#: inside the grooves, outside the clear aperture; a blade takes them off to change the plate.
PLATE_RETAINER = {"item": "silicone RTV, one-part, neutral (alkoxy) cure, non-corrosive (DOWSIL 3145 class)",
                  "standard": "MIL-A-46146 (non-corrosive RTV silicone)", "dots_per_groove": 2, "cure_h": 24}


def plate_play(profile: Profile, layout) -> tuple[float, float]:
    """The splitter plate's play in its grooves (mm): the grooves' width across the plate less its
    thickness (2 GROOVE_GAP, as :func:`_groove` cuts them), and the length of groove it turns over (its
    own plus GROOVE_GAP at each end)."""
    p = layout.tower.plate
    return 2 * GROOVE_GAP, 2 * (p.half_length + GROOVE_GAP)


def plate_float_tilt(profile: Profile, layout) -> float:
    """How far (rad) the plate turns in its grooves when nothing holds it on its datum flank: its play
    across the grooves over their length (:func:`plate_play`), in the plane of incidence."""
    play, length = plate_play(profile, layout)
    return math.atan2(play, length)


def plate_retainer_step(profile: Profile) -> str:
    """The shop step that holds the plate on its datum flank (PLATE_RETAINER), with its figures."""
    r = PLATE_RETAINER
    return (f"with the holder upright on the bench and the plate lying on the grooves' lower flanks (its coated face "
            f"down on them: the datum flank), press each edge onto its flank with a finger and put {r['dots_per_groove']} "
            f"dots of {r['item']} into each groove's gap over the plate's back face, one near each end (in the grooves, "
            f"outside the clear aperture); leave the holder upright {r['cure_h']} h while they cure. The cured dots fill "
            f"the grooves' {2 * GROOVE_GAP:g} mm of play, so the plate cannot turn off its datum flank; cut them with a "
            "blade to change the plate")


def _camera_bracket(t: TowerLayout, profile: Profile) -> tuple[tuple[Box, Box], Box]:
    """The camera bracket on the holder's -y wall (a ledge into the wall's top and an upright) and its
    slot: both camera screws slide in it by travel_along along the axis and travel_across across."""
    tw, cm = profile.tower, profile.camera
    x0, x1 = t.holder_x
    yi, yo = t.wall_y
    z1 = t.holder_top_z
    (cx0, _, _), (cx1, _, cz1) = t.camera_box
    (cx, s0), (_, s1) = camera_screws(t, profile)
    d = clearance_hole(cm.mount_thread)
    if s1 + d / 2 > cz1 or s0 - d / 2 < t.camera_box[0][2]:
        raise GeometryError(f"the camera's screws ({cm.mount_spacing:g} mm apart) do not fit its body "
                            f"({cm.body_depth:g} mm deep along its axis): check camera.mount_spacing",
                            where=profile.where("camera", "mount_spacing"))
    from rigcad.parts.washers import washers_over

    # the bracket carries the washer that bears over the slot wherever the screws are set in it
    (_, q0), (_, q1) = camera_screws(t, profile)
    bearing = washers_over(cm.mount_thread, ("slot", d + 2 * tw.travel_across, q1 - q0 + d + 2 * tw.travel_along))
    half_w = max((cx1 - cx0) / 2, d / 2 + tw.travel_across + tw.wall, tw.travel_across + bearing.bearing.outer / 2 + 1.0)
    bx0, bx1 = max(cx - half_w, x0), min(cx + half_w, x1)
    ledge = Box((bx0, -yo, z1 - tw.wall), (bx1, -yi, z1))  # sits into the -y wall's top
    upright = Box((bx0, -yo, z1 - tw.wall), (bx1, t.bracket_y, cz1))
    slot = Box((cx - d / 2 - tw.travel_across, -yo - 1.0, s0 - d / 2 - tw.travel_along),
               (cx + d / 2 + tw.travel_across, t.bracket_y + 1.0, s1 + d / 2 + tw.travel_along))
    return (ledge, upright), slot


def splitter_holder(profile: Profile, layout) -> Part:
    """The beam splitter's holder: side walls with 45 deg grooves (the plate slides in through the +y
    wall and rests on their lower faces), a back wall, and flanges on a kinematic seat over the shelf
    (three push screws in heat-set inserts, on balls in the shelf's cone, vee and flat; two spring
    bolts hold it down): tip and tilt. Above, the camera bracket with its slot for two screws."""
    t, tw, cm, a = layout.tower, profile.tower, profile.camera, profile.adjusters
    x0, x1 = t.holder_x
    yi, yo = t.wall_y
    z0, z1 = t.shelf_top_z + seat_gap(profile), t.holder_top_z
    if z0 > t.plate_bottom_z - GROOVE_GAP:
        raise GeometryError(f"the splitter holder, raised {seat_gap(profile):.1f} mm on its seat, would start above "
                            f"the plate's lower edge (z = {t.plate_bottom_z:.1f} mm): lower adjusters.seat_travel "
                            "or adjusters.seat_ball", where=profile.where("adjusters", "seat_travel"))
    walls = [Box((x0, s0, z0), (x1, s1, z1)) for s0, s1 in ((-yo, -yi), (yi, yo))]
    back = Box((x0, -yo, z0), (x0 + tw.wall, yo, z1))
    fl = 3 * tw.bolt_diameter
    springs = _holder_flange_points(t, profile)
    fx0 = min(x0, springs[1][0] - 1.5 * tw.bolt_diameter)  # the +y flange reaches back under its spring bolt
    flanges = [Box((x0, -yo - fl, z0), (x1, -yo, z0 + tw.wall)), Box((fx0, yo, z0), (x1, yo + fl, z0 + tw.wall)),
               Box((x0 - _flat_reach(t, profile) - 1.5 * tw.bolt_diameter, -yo, z0), (x0, yo, z0 + tw.wall))]
    bracket, slot = _camera_bracket(t, profile)
    ins = INSERTS[a.seat_thread]
    boss_r, boss_h = _seat_boss(profile)
    top = z0 + tw.wall + boss_h
    pts = tuple(seat_points(t, profile).values())
    bosses = tuple(Cylinder((x, y, z0), boss_r, tw.wall + boss_h) for x, y in pts)
    # each insert's pocket at its maker's hole and depth from the boss's top; the screw on through the floor
    pockets = tuple(Cylinder((x, y, top - ins.pocket_depth), ins.hole / 2, ins.pocket_depth + 1.0) for x, y in pts)
    holes = (_holes(pts, THREADS[a.seat_thread].clearance, z0, tw.wall + boss_h) + pockets
             + _holes(springs, SPRING_HOLE, z0, tw.wall))
    # the plate slides in over the +y flange: where the flange's top reaches its way in, the groove runs on through it
    low = z0 + tw.wall > t.plate_bottom_z - GROOVE_GAP - tw.clearance
    groove = _groove(t, yo + fl + 1.0 if low else t.wall_y[1] + 1.0)
    datums = (*datums_of("insert", "seat screw insert pocket", pockets), Datum("splitter grooves", "seat", groove))
    solid = Difference(Union_((*walls, back, *flanges, *bosses, *bracket)), (groove, slot, *holes))
    return Part("splitter_holder", solid, (0.3, 0.5, 0.75),
                f"COP tower: holds the {profile.beam_splitter.thickness:g} mm plate beam splitter at 45 deg in its "
                f"grooves (slide it in through the +y wall) on a kinematic seat (three {a.seat_thread} cup-point push "
                f"screws in heat-set inserts in bosses, a {a.seat_ball:g} mm ball in each cup, on a cone of three balls, "
                "a vee of two dowel pins and a gauge block in the shelf; two spring bolts), and the camera on its "
                f"bracket above (two {cm.mount_thread} screws in the slot; shims between camera and bracket)",
                datums=datums)


def lens_mount(profile: Profile, layout) -> Part:
    """The focusing lens's mount on the shelf: a square pocket the round lens drops into (it touches
    the four sides) with lips both sides, on a post with a slotted foot (focus +-travel_along)."""
    t, tw, ln = layout.tower, profile.tower, profile.lens
    zc = t.cop[2] - profile.tower.splitter_distance
    half = ln.diameter / 2 + GROOVE_GAP
    outer = half + tw.wall
    lx0, lx1 = t.lens_x - ln.thickness / 2 - tw.wall / 2, t.lens_x + ln.thickness / 2 + tw.wall / 2
    frame = Box((lx0, -outer, t.shelf_top_z), (lx1, outer, zc + outer))
    pocket = Box((t.lens_x - ln.thickness / 2 - GROOVE_GAP / 2, -half, zc - half),
                 (t.lens_x + ln.thickness / 2 + GROOVE_GAP / 2, half, zc + outer + 1.0))
    window = Box((lx0 - 1.0, -(ln.diameter / 2 - ln.rim), zc - (ln.diameter / 2 - ln.rim)),
                 (lx1 + 1.0, ln.diameter / 2 - ln.rim, zc + outer + 1.0))
    fx0, fx1, fhy, pts = _lens_foot(t, profile)
    foot = Box((fx0, -fhy, t.shelf_top_z), (fx1, fhy, t.shelf_top_z + tw.wall))
    slots = tuple(_slot(x, y, tw.bolt_diameter / 2 + tw.travel_along, tw.bolt_diameter / 2, t.shelf_top_z, tw.wall)
                  for x, y in pts)
    return Part("lens_mount", Difference(Union_((frame, foot)), (pocket, window, *slots)), (0.3, 0.5, 0.75),
                f"COP tower: the {ln.diameter:g} mm focusing lens drops into its square pocket on the projector's "
                f"axis, {ln.distance:g} mm in front of the projector's COP; slotted foot (+-{tw.travel_along:g} mm)")


def tower_shim(profile: Profile, layout) -> Part:
    """One slotted adjustment shim (square, U slot to the edge: it slides in around the screw)."""
    t, tw = layout.tower, profile.tower
    d = max(clearance_hole(profile.projector.mount_thread), clearance_hole(profile.camera.mount_thread))
    h = SHIM_SIDE / 2
    body = Box((-h, -h, 0.0), (h, h, tw.shim_thickness))
    slot = Box((-d / 2, -1.0 - h, -1.0), (d / 2, 0.0, tw.shim_thickness + 1.0))
    end = Cylinder((0.0, 0.0, -1.0), d / 2, tw.shim_thickness + 2.0)
    stacks = 5  # four under the projector's feet, one behind the camera
    return Part("tower_shim", Difference(body, (slot, end)), (0.9, 0.8, 0.3),
                f"COP tower: {tw.shim_thickness:g} mm adjustment shim (print {stacks * t.shims_per_stack}: "
                f"{t.shims_per_stack} per stack, {t.shims_nominal} in each stack at the nominal placement; four "
                "stacks under the projector, one behind the camera)", quantity=stacks * t.shims_per_stack,
                in_rig=False)


TOWER_PARTS = ("tower_column", "tower_shelf", "splitter_holder", "lens_mount", "tower_shim")

#: Screwed into an instrument, a screw engages its socket this far (mm; assumed: 5 mm).
SOCKET_ENGAGEMENT = 5.0


def _length(thread: str | None, grip: float, extra: float) -> float:
    """The shortest preferred length (mm, rigcad.standards) of a screw of ``thread`` through ``grip``
    mm that needs ``extra`` mm past it (a nut and washers, or a socket's engagement)."""
    need = grip + extra
    length = shortest_screw(thread, need)
    if length is None:
        raise GeometryError(f"no {thread or ''} screw of the preferred lengths is {need:.1f} mm long: "
                            "the joint's parts are too thick", param="tower.wall")
    return float(length)


def nut_allowance(thread: str, washers: int = 2) -> float:
    """What a through bolt needs past its grip (mm): ``washers`` washers (under its head and under
    its nut; one when the nut sits in a printed trap), the nut, and two pitches proud (rigcad.standards)."""
    th = THREADS[thread]
    return washers * th.washer_thickness + th.nut_height + 2 * th.pitch


def _column_hardware(profile: Profile, t: TowerLayout, nut: float) -> list[dict]:
    """The column's joints to the base plate's tongue and to the shelf: four bolts and two dowels at
    each end of a printed column; one M8 bolt into the core at each end of a bought extrusion."""
    tw, tongue = profile.tower, -t.bench_z  # the tongue reaches down to the bench
    if profile.buy.column != "print":
        length = core_bolt_lengths(profile, t)
        return [{"item": "bolt, ISO 4762 (no washer: the head bears on its counterbore's floor)", "thread": "M8",
                 "length_mm": length["foot"], "quantity": 1,
                 "steps": ('tower_column',), "joins": "up through the base plate's tongue (its head in the counterbore underneath) into the "
                          f"extrusion's core, tapped {CORE_TAP_DEPTH:g} mm deep"},
                {"item": "countersunk socket screw, ISO 10642 (length with the head)", "thread": "M8",
                 "length_mm": length["top"], "quantity": 1,
                 "steps": ('tower_shelf',), "joins": "down through the shelf (its head flush in the countersink on top) into the extrusion's core, "
                          f"tapped {CORE_TAP_DEPTH:g} mm deep"}]
    from rigcad.parts.locating import PRESS_IN_COMPOUND, SLOT_FIT_MM
    from rigcad.parts.washers import washers_over

    hole = column_bolt_hole(t, profile)
    reg = column_register(t, profile, t.column_base_z, tw.wall, "foot")  # the fits and tools of both ends' registers
    top_reg = column_register(t, profile, t.shelf_top_z - t.shelf_thickness - tw.wall, tw.wall, "top")
    big = washers_over("M4", ("round", hole))
    cone, cone_h = spring_washer("M4")
    foot = column_foot_bolt(profile, t)
    top_step = limiter_step("the column's top flange", 4, shelf_limiter_length(profile),
                            "the shelf's insert, pressed flush with its underside" if profile.buy.shelf == "print"
                            else "the shelf's underside")
    foot_step = limiter_step("the column's foot and the tongue, from the foot's top face to the trap's roof", 4,
                             foot["limiter_mm"], "the nut in its trap")
    lap = (f"lap the column's foot-side and flange-side glue faces flat before they are glued: wet P240 paper on "
           f"float glass, figure-of-eight strokes, until a steel straightedge laid across each face in four directions "
           f"admits no {LAPPED_FLATNESS:g} mm feeler leaf")
    return [
        {"item": "bolt, conical washer (DIN 6796) and large washer (ISO 7093-1) on a compression limiter", "thread": "M4",
         "length_mm": shelf_bolt_length(profile), "quantity": 4, "washer_mm": big.thickness + cone_h,
         "washers": [w.name() for w in big.washers], "spring_washer": cone, "nuts": 0, "plain_washers": 0,
         "limiter": COLUMN_LIMITER.name(), "limiter_mm": shelf_limiter_length(profile),
         "steps": ('tower_shelf',), "joins": "the column's top flange to the shelf: up from under the flange into "
                  + ("heat-set inserts pressed into the shelf's underside" if profile.buy.shelf == "print" else
                     "M4 threads tapped in the shelf's underside (8 mm deep)")
                  + f" ({cone} on {big.describe()}, through a steel compression limiter "
                    f"{shelf_limiter_length(profile):.2f} mm long: the dowels locate, the bolts only clamp); " + top_step,
         "shop_steps": [top_step]},
        {"item": "bolt, conical washer (DIN 6796), large washer (ISO 7093-1), compression limiter and nut",
         "thread": "M4", "length_mm": foot["length_mm"], "quantity": 4, "washer_mm": foot["washers_mm"],
         "washers": [w.name() for w in big.washers], "spring_washer": cone, "nuts": 1, "plain_washers": 0,
         "limiter": COLUMN_LIMITER.name(), "limiter_mm": foot["limiter_mm"],
         "steps": ('tower_column',), "joins": "the column's foot to the base plate's datum tongue (the nuts in the hexagonal traps "
                  f"under the tongue, {foot['trap_depth_mm']:g} mm deep, put in before it stands on the bench: the bolt stands "
                  f"{foot['proud_mm']:.1f} mm out of its nut and ends {foot['above_bench_mm']:.1f} mm above the bench; "
                  f"{cone} on {big.describe()}, through a steel compression limiter {foot['limiter_mm']:.2f} mm long "
                  "down through the foot and the tongue to the nut, which bears on it, not on the trap's roof); " + foot_step,
         "shop_steps": [foot_step]},
        *([{"item": "heat-set insert", "thread": "M4", "length_mm": None, "quantity": 4, "hole_mm": SHELF_INSERT.hole,
            "steps": ('tower_shelf',), "joins": "pressed into the shelf's four blind holes from below (the column joint's bolts)"}]
          if profile.buy.shelf == "print" else []),
        *({"item": "dowel pin, ISO 8734 m6", "thread": None, "diameter_mm": profile.datum.dowel_diameter,
         "length_mm": float(length), "quantity": count, "steps": steps,
         "joins": f"{which}: "
                  f"pressed into the tongue's and the shelf's blind holes (printed at {reg.drill:g} mm: drill them "
                  f"{reg.drill:g} mm, ream {reg.diameter:g} {reg.press.hole}: {reg.press.describe()}), "
                  f"{PRESS_IN_COMPOUND}; at each end the "
                  f"column's flange takes the first pin in its round hole (drilled {reg.drill:g} mm, reamed "
                  f"{reg.diameter:g} {reg.slip.hole}: {reg.slip.describe()}) and the second in its slot (file it until "
                  f"the pin slides, {SLOT_FIT_MM:g} mm across); {lap}",
         "shop_steps": [f"drill the tongue's and the shelf's blind dowel holes {reg.drill:g} mm and ream them "
                        f"{reg.diameter:g} {reg.press.hole} (the press end)",
                        f"drill the column's round dowel holes {reg.drill:g} mm and ream them {reg.diameter:g} "
                        f"{reg.slip.hole} (the slip end)",
                        f"file the column's dowel slots until the pin slides ({SLOT_FIT_MM:g} mm)", lap]}
          for length, count, which, steps in _dowel_rows(reg, top_reg)),
    ]


def _dowel_rows(foot, top) -> list[tuple[int, int, str, tuple[str, ...]]]:
    """The column's dowel pins by length (mm, count, which they locate, the steps that press them in):
    each end's register (rigcad.parts.locating.DowelRegister.length) sets its own pins' length; one
    row when both agree, its pins shared between the column's and the shelf's steps."""
    foot_use = "two locate the column's foot on the base plate's tongue"
    if foot.length == top.length:
        return [(foot.length, 4, f"{foot_use}, two its top flange under the shelf", ('tower_column', 'tower_shelf'))]
    return [(foot.length, 2, foot_use, ('tower_column',)),
            (top.length, 2, "two locate the column's top flange under the shelf", ('tower_shelf',))]


def _seat_hardware(profile: Profile, t: TowerLayout) -> list[dict]:
    """The splitter seat's push screws, inserts and spring bolts (threaded: the bill's fasteners), then
    its balls, dowel pins, gauge block and springs (the seat's bought hard parts, :func:`splitter_seat`)."""
    a = profile.adjusters
    spring = SEAT_SPRING
    g = seat_geometry(profile)
    std = "ISO 4029" if a.seat_thread.startswith("M") else "ASME B18.3"
    force = spring_force(1)
    fits = {f["pocket"]: f for f in seat_pocket_fits(profile)}
    return [
        {"item": f"set screw, {std} (cup point), a {g.ball:g} mm ball held in its cup", "thread": a.seat_thread,
         "length_mm": seat_screw_length(profile), "quantity": 3,
         "steps": ('splitter_holder',), "joins": "the splitter holder's seat: a ball-ended push screw on the shelf's cone, vee or flat, turned from "
                  "above (tip/tilt and height). In the alignment the flat's screw sets the camera's tilt first (it turns "
                  "the holder, with the camera's bracket, in the bracket's plane: rigcad.parts.adjusters.camera_tilt), "
                  "then the camera's slot its place; the projector's own tilt (its feet's shims) then takes back what "
                  "the turn did to its reflected axis, and the vee's screw the tilt across the plane of incidence"},
        {"item": "heat-set insert", "thread": a.seat_thread, "length_mm": None, "quantity": 3,
         "hole_mm": INSERTS[a.seat_thread].hole, "steps": ('splitter_holder',), "joins": "pressed into the holder's three seat bosses from above"},
        {"item": "steel ball, ISO 3290-1 grade G10", "thread": None, "length_mm": None, "quantity": 6,
         "diameter_mm": g.ball,
         "steps": ('seat_cone_ball', 'seat_ball'), "joins": "three in the seat screws' cups (a drop of retaining compound), three bonded into the shelf's cone "
                  "pocket, touching: " + fits["cone"]["step"], "fit_mm": fits["cone"]},
        {"item": "dowel pin, ISO 8734 m6", "thread": None, "diameter_mm": g.pin, "length_mm": float(SEAT_PIN_LENGTH),
         "quantity": 2, "steps": ('seat_vee_pin',), "joins": "the seat's vee: bonded side by side into the shelf's channel: " + fits["vee"]["step"],
         "fit_mm": fits["vee"]},
        {"item": f"gauge block, ISO 3650 grade 2, {SEAT_PAD_LENGTH:g} mm", "thread": None, "length_mm": None,
         "quantity": 1, "size_mm": [*GAUGE_BLOCK_FACE, SEAT_PAD_LENGTH],
         "steps": ('seat_flat_pad',), "joins": "the seat's flat: bonded into its pocket in the shelf, flush with its top: " + fits["flat"]["step"],
         "fit_mm": fits["flat"]},
        {"item": "bolt, two washers, nut and compression spring", "thread": "M4",
         "length_mm": spring_bolt_length(profile, t), "quantity": 2,
         "spring_mm": {"inner_diameter": spring["outer_diameter"] - 2 * spring["wire"], "wire": spring["wire"],
                       "outer_diameter": spring["outer_diameter"], "free_length": spring["free_length"],
                       "installed_length": spring["installed_length"], "active_coils": spring["active_coils"]},
         "spring_rate_N_per_mm": force["rate_N_per_mm"], "preload_N": force["force_N"], "nuts": 1, "plain_washers": 2,
         "steps": ('splitter_holder',), "joins": "from under the shelf up through the holder's flange; the spring under the nut holds the holder "
                  f"on its three contacts (nut set to {spring['installed_length']:g} mm of spring: "
                  f"{force['force_N']:.1f} N each, EN 13906-1)"},
    ]


#: Washers (ISO 7089 for the projector's thread: rigcad.standards) a screw may carry under its head to reach
#: the right depth: more and the joint loses stiffness.
MAX_EXTRA_WASHERS = 3
#: ... or as many thin washers as make this much (mm): a shallow socket (an M3 camera's 2.5 mm) takes a
#: screw only within half a millimetre, and the stocked lengths step by up to 5 mm.
MAX_EXTRA_WASHER_MM = 5.0


#: A camera's mounting socket's thread depth by its thread: rigcad.standards.CAMERA_SOCKET_DEPTH.


def slot_openings(profile: Profile, layout) -> dict[str, tuple]:
    """The openings under the tower's bolts (rigcad.parts.washers): ("slot", width x, width y) for the
    projector's slots in the shelf (along its axis, across), the camera's slot in its bracket (across,
    along the axis) and the lens mount's foot; ("round", d) for the printed column's opened holes."""
    t, tw = layout.tower, profile.tower
    d_pj = clearance_hole(profile.projector.mount_thread)
    d_cm = clearance_hole(profile.camera.mount_thread)
    (_, s0), (_, s1) = camera_screws(t, profile)
    return {"projector": ("slot", d_pj + 2 * tw.travel_along, d_pj + 2 * tw.travel_across),
            "camera": ("slot", d_cm + 2 * tw.travel_across, s1 - s0 + d_cm + 2 * tw.travel_along),
            "lens": ("slot", tw.bolt_diameter + 2 * tw.travel_along, tw.bolt_diameter),
            "column": ("round", column_bolt_hole(t, profile))}


def joint_washers(profile: Profile, layout) -> dict:
    """The washers under each of the tower's bolts over a slot or an opened hole
    (rigcad.parts.washers.washers_over): keys as :func:`slot_openings`."""
    from rigcad.parts.washers import washers_over

    threads = {"projector": profile.projector.mount_thread, "camera": profile.camera.mount_thread, "lens": "M4",
               "column": "M4"}
    return {k: washers_over(threads[k], op) for k, op in slot_openings(profile, layout).items()}


def _stack_screws(thread: str, fixed: float, shim: float, stacks: int, fine: float, washer: float,
                  depth: float, shallow: bool = False) -> list[dict]:
    """Screws into an instrument's socket through ``fixed`` mm (washers under the head, the printed part),
    a stack of n printed ``shim`` mm shims (n = 0..stacks) and the whole bought set (``fine`` mm: the
    bought shims not in the stack go under the head's washers, so the reach does not change with the
    fine setting): the shortest stocked length, with the fewest extra ``washer`` mm washers (at most
    MAX_EXTRA_WASHERS, or MAX_EXTRA_WASHER_MM of thin ones), that engages the socket by
    SOCKET_ENGAGEMENT, or, with ``shallow`` (a light instrument whose maker's socket is shorter), by the
    socket's depth less one washer (the step the extra washers set), and never passes ``depth`` (a
    screw that bottoms out does not clamp)."""
    least = min(SOCKET_ENGAGEMENT, depth - washer) if shallow else SOCKET_ENGAGEMENT
    rows = []
    for n in range(stacks + 1):
        grip = fixed + n * shim + fine
        most = max(MAX_EXTRA_WASHERS, math.floor(MAX_EXTRA_WASHER_MM / washer + 1e-9))
        fits = [(L, w, L - grip - w * washer) for L in screw_lengths(thread) for w in range(most + 1)
                if least - 1e-9 <= L - grip - w * washer <= depth + 1e-9]
        length, washers, reach = fits[0] if fits else (None, None, None)
        rows.append({"shims": n, "grip_mm": grip, "length_mm": length, "extra_washers": washers,
                     "engagement_mm": reach, "least_engagement_mm": least, "ok": bool(fits)})
    return rows


def projector_screws(profile, layout) -> list[dict]:
    """The projector's screws for each shim stack (0..shims_per_stack printed shims and the bought set,
    :func:`fine_shims`; mm): through the washers over the shelf's slot (:func:`joint_washers`), the
    shelf and the stack, engaging the projector's thread by SOCKET_ENGAGEMENT to
    ``projector.mount_depth`` (:func:`_stack_screws`). ``ok`` False: no stocked length fits that stack."""
    t, tw, pj = layout.tower, profile.tower, profile.projector
    fixed = joint_washers(profile, layout)["projector"].thickness + t.shelf_thickness
    return _stack_screws(pj.mount_thread, fixed, tw.shim_thickness, t.shims_per_stack, sum(fine_shims(profile)),
                         THREADS[pj.mount_thread].washer_thickness, pj.mount_depth)


def camera_socket_depth(profile: Profile) -> float:
    """The camera's mounting socket's thread depth (mm): CAMERA_SOCKET_DEPTH for its thread."""
    return CAMERA_SOCKET_DEPTH[profile.camera.mount_thread]


def camera_screws(t: TowerLayout, profile: Profile) -> list[tuple[float, float]]:
    """The camera's two screws (x, z; mm) at the nominal placement: in line along the optical axis,
    ``camera.mount_spacing`` apart, about the body's middle (two points: the camera cannot pivot)."""
    (cx0, _, cz0), (cx1, _, cz1) = t.camera_box
    cx, cz, s = 0.5 * (cx0 + cx1), 0.5 * (cz0 + cz1), profile.camera.mount_spacing
    return [(cx, cz - s / 2), (cx, cz + s / 2)]


def camera_stack_screws(profile: Profile, layout) -> list[dict]:
    """The camera's two screws for each shim stack behind it, as :func:`projector_screws`: through the
    washers over the bracket's slot, the bracket and the stack, into the camera's socket no deeper than
    :func:`camera_socket_depth` (a screw that bottoms out would not clamp)."""
    t, tw, cm = layout.tower, profile.tower, profile.camera
    fixed = joint_washers(profile, layout)["camera"].thickness + (t.bracket_y + t.wall_y[1])
    return _stack_screws(cm.mount_thread, fixed, tw.shim_thickness, t.shims_per_stack, sum(fine_shims(profile)),
                         THREADS[cm.mount_thread].washer_thickness, camera_socket_depth(profile), shallow=True)


def _screw_rows(rows: list[dict], thread: str, count: int, step: str, what: str, param: tuple[str, str],
                profile: Profile, washers, key: str = "for_stacks_of_shims") -> list[dict]:
    """One hardware row per screw length ``rows`` (:func:`_stack_screws`) needs; ``key`` names the stacks
    each length serves (the projector's ``for_stacks_of_shims``; the camera's its own key)."""
    bad = [r["shims"] for r in rows if not r["ok"]]
    if bad:
        raise GeometryError(f"no stocked {thread} screw suits {what} on a stack of {bad[0]} shims (with the bought "
                            f"set) without bottoming in its socket: check {param[0]}.{param[1]}",
                            where=profile.where(*param))
    stacks: dict[float, list[int]] = {}
    for r in rows:
        stacks.setdefault(r["length_mm"], []).append(r["shims"])
    names = " on ".join(f"{w.size} {w.standard}" for w in washers.washers)
    std = "ISO 4762" if thread.startswith("M") else "ASME B18.3"
    return [{"item": f"socket-head screw ({std}) with {names} washers", "thread": thread, "length_mm": float(L),
             "quantity": count,
             key: ns, "washers": [w.name() for w in washers.washers],
             "steps": (step,), "joins": f"{what}, through {washers.describe()}, the slot and a stack of {ns[0]}..{ns[-1]} "
                      "printed shims and the bought ones (extra washers per stack: rigcad.parts.tower, "
                      f"{'projector_screws' if step == 'projector_body' else 'camera_stack_screws'})"}
            for L, ns in stacks.items()]


def _refuse_projector_screws(profile: Profile, layout, rows: list[dict]) -> None:
    """Why no stocked screw holds the projector on some stack of ``rows`` (:func:`projector_screws`),
    with the value that passes: a socket too shallow for every length that reaches it (a deeper
    ``projector.mount_depth``, as measured), or a stack thicker than the longest stocked screw of the
    projector's thread reaches through (less ``tower.travel_across``, so fewer shims per stack)."""
    from dataclasses import replace

    pj, tw = profile.projector, profile.tower
    n = next(r["shims"] for r in rows if not r["ok"])

    def passes(depth: float) -> bool:
        return all(r["ok"] for r in projector_screws(replace(profile, projector=replace(pj, mount_depth=depth)), layout))

    if passes(1e3):  # the shallowest socket, in 0.1 mm steps, that every stack's screw fits
        need = next(d / 10 for d in range(math.ceil(pj.mount_depth * 10), 10 ** 4) if passes(d / 10))
        raise GeometryError(f"no stocked {pj.mount_thread} screw suits the projector's mounting holes on a stack of {n} "
                            f"shims without bottoming in its {pj.mount_depth:g} mm deep socket; valid: "
                            f"projector.mount_depth at least {need:g} mm (measure the holes' thread depth)",
                            where=profile.where("projector", "mount_depth"), param="projector.mount_depth")
    longest, grip = max(screw_lengths(pj.mount_thread)), rows[n]["grip_mm"]
    fits = max((k for k in range(len(rows)) if rows[k]["grip_mm"] + SOCKET_ENGAGEMENT <= longest + 1e-9), default=0)
    raise GeometryError(f"the longest stocked {pj.mount_thread} screw ({longest} mm) cannot hold the projector on a "
                        f"stack of {n} shims ({grip:.2f} mm through, {SOCKET_ENGAGEMENT:g} mm in its socket); valid: "
                        f"tower.travel_across at most {fits // 2 * tw.shim_thickness:g} mm ({fits // 2 * 2} shims a "
                        "stack), or a coarser thread in the projector's holes (projector.mount_thread)",
                        where=profile.where("tower", "travel_across"), param="tower.travel_across")


def _projector_screw_rows(profile: Profile, layout) -> list[dict]:
    """The projector's screws: one row per length the shim stacks need (:func:`projector_screws`)."""
    rows = projector_screws(profile, layout)
    if not all(r["ok"] for r in rows):
        _refuse_projector_screws(profile, layout, rows)
    return _screw_rows(rows, profile.projector.mount_thread,
                       len(_projector_feet(layout.tower)), "projector_body", "the projector's mounting holes",
                       ("projector", "mount_depth"), profile, joint_washers(profile, layout)["projector"])


def _fine_shim_rows(profile: Profile) -> list[dict]:
    """The bought shims: one set per stack (four under the projector, one behind the camera), a row per
    thickness, with the shop step that makes them."""
    counts: dict[float, int] = {}
    for v in fine_shims(profile):
        counts[v] = counts.get(v, 0) + 1
    stacks = 5
    return [{"item": f"precision shim, stainless steel (AISI 301 shim stock), {v:g} mm", "thread": None,
             "length_mm": None, "quantity": stacks * n, "thickness_mm": v, "size_mm": [SHIM_SIDE, SHIM_SIDE, v],
             "steps": ("projector_body", "camera_body"),
             "joins": f"{n} with each of the five shim stacks (four under the projector's feet, one behind the camera): "
                      f"in the stack, between the printed {profile.tower.shim_thickness:g} mm shims, the fine steps of the "
                      "alignment (the projector's near feet's stacks against its far feet's tilt it in the plane of "
                      "incidence: rigcad.parts.adjusters.projector_tilt); the rest under the screw's washers, so its reach "
                      "stays the same "
                      f"(cut {SHIM_SIDE:g} x {SHIM_SIDE:g} mm from the sheet with tin snips, the printed shim as the "
                      "template for its U slot; deburr with a file)"}
            for v, n in sorted(counts.items())]


def hardware(profile: Profile, layout) -> list[dict]:
    """The tower's bought hardware, computed from the parts (mm; units in keys): each item's name,
    quantity, thread and length (grip plus nut or socket engagement, the shortest preferred length), a
    bolt's ``washers`` (its washer stack's, by name), ``plain_washers`` and ``nuts`` (ISO 7089, ISO 4032:
    per bolt; the bill counts its lines from them), and
    what it joins: the datum chain's dowels and bolts, the splitter seat's parts, the projector's
    screws per shim stack, the camera's two screws, the splitter and the focusing lens (bought to
    the catalogue specification: ``splitter_spec``, ``rigcad.optics.focus``). ``steps``: the assembly
    steps (named by their part) that fit the item, as data: the manual places each row there."""
    t, tw, cm, bs, ln = layout.tower, profile.tower, profile.camera, profile.beam_splitter, profile.lens
    m4 = "M4"
    nut = nut_allowance(m4)
    washers = joint_washers(profile, layout)
    # the lens mount's foot on the shelf: its washers over the foot's slot, the nut's under the shelf
    through = _length(m4, tw.wall + t.shelf_thickness + washers["lens"].thickness - THREADS[m4].washer_thickness, nut)
    _, _, _, lens_pts = _lens_foot(t, profile)
    focus = focusing_lens(profile, layout.geometry)
    return [
        *_column_hardware(profile, t, nut),
        *_seat_hardware(profile, t),
        {"item": "bolt, large washer (ISO 7093-1) over its slot, washer and nut", "thread": m4, "length_mm": through,
         "quantity": len(lens_pts), "washers": [w.name() for w in washers["lens"].washers],
         "nuts": 1, "plain_washers": 1,
         "steps": ('lens_mount',), "joins": f"the lens mount's slotted foot to the shelf ({washers['lens'].describe()})"},
        *_projector_screw_rows(profile, layout),
        *_screw_rows(camera_stack_screws(profile, layout), cm.mount_thread, 2, "camera_body",
                     f"the camera's two mounting holes ({cm.mount_spacing:g} mm apart along its axis; "
                     f"{camera_socket_depth(profile):g} mm deep, rigcad.standards.CAMERA_SOCKET_DEPTH)",
                     ("camera", "mount_thread"), profile, washers["camera"], "for_camera_stacks_of_shims"),
        *_fine_shim_rows(profile),
        {"item": "plate beam splitter", "thread": None, "length_mm": None, "quantity": 1,
         "size_mm": [bs.width, bs.length, bs.thickness], "index": bs.index, "spec": splitter_spec(profile),
         "steps": ('beam_splitter',), "joins": "slides into the splitter holder's grooves through its +y wall, coated face towards the projector"},
        {"item": f"cable tie, IEC 62275, polyamide 6.6, {CABLE_TIE['width']:g} x {cable_tie_length(profile)} mm",
         "thread": None, "length_mm": None, "quantity": CABLE_TIE["count"], "standard": "IEC 62275",
         "steps": ('camera_body',),
         "joins": f"the camera's cable to the column: {CABLE_TIE['count']} ties round the column and the cable, the "
                  "upper just under the shelf, the lower 100 mm below it, pulled tight; leave the cable from the camera "
                  f"to the upper tie {CABLE_TIE['slack']:g} mm longer than the straight run (a slack loop), so that its "
                  "pull and weight bear on the column, not on the camera on the splitter's seat"},
        {"item": PLATE_RETAINER["item"], "thread": None, "length_mm": None, "quantity": 1,
         "standard": PLATE_RETAINER["standard"], "steps": ('beam_splitter',),
         "joins": "holds the beam splitter on its datum flank: " + plate_retainer_step(profile)},
        {"item": "focusing lens", "thread": None, "length_mm": None, "quantity": 1,
         "size_mm": [ln.diameter, ln.thickness], "focal_length_mm": focus.focal_length,
         "spec": f"plano-convex singlet, {ln.diameter:g} mm diameter, f = {focus.focal_length:g} mm, N-BK7, "
                 "AR coated 400-700 nm; its curved side towards the projector (the nearly collimated beam: the "
                 "least spherical aberration)",
         "steps": ('focusing_lens',), "joins": "drops into the lens mount's pocket"},
    ]


def screw_engagements(profile: Profile, layout) -> list[dict]:
    """Every screw joint of the tower with how its thread is engaged (mm): a bolt into a nut stands at
    least NUT_PROUD_PITCHES threads out of it (``proud_mm`` against ``least_mm``: the nut's every thread
    engaged, the conical spring washer at its free height counted in the grip); a bolt into an insert or a
    tapped core engages at least one diameter and ends short of the insert's (or the tapping's) end; a
    screw into an instrument engages it as :func:`_stack_screws` asks (``ok`` per shim stack). ``ok``: the
    joint keeps to it."""
    t, tw = layout.tower, profile.tower
    th = THREADS["M4"]
    rows = []

    def nut(joint, length, grip, extra=""):
        proud = length - grip - th.nut_height
        least = NUT_PROUD_PITCHES * th.pitch
        rows.append({"joint": joint, "thread": "M4", "length_mm": length, "grip_mm": grip, "into": "nut",
                     "proud_mm": proud, "least_mm": least, "ok": proud >= least - 1e-9, "note": extra})

    def threaded(joint, thread, length, grip, depth, into):
        engaged = length - grip
        least = THREADS[thread].major
        rows.append({"joint": joint, "thread": thread, "length_mm": length, "grip_mm": grip, "into": into,
                     "engaged_mm": engaged, "least_mm": least, "most_mm": depth,
                     "ok": least - 1e-9 <= engaged <= depth + 1e-9})

    hw = hardware(profile, layout)
    if profile.buy.column == "print":
        foot = column_foot_bolt(profile, t)
        nut("column foot on the tongue", foot["length_mm"], foot["grip_mm"],
            f"ends {foot['above_bench_mm']:.1f} mm above the bench")
        rows[-1]["ok"] = rows[-1]["ok"] and foot["above_bench_mm"] >= BENCH_CLEAR - 1e-9
        top = next(h for h in hw if h["joins"].startswith("the column's top flange to the shelf"))
        threaded("column top under the shelf", "M4", top["length_mm"], tw.wall + top["washer_mm"],
                 SHELF_INSERT.length - 0.5 if profile.buy.shelf == "print" else t.shelf_thickness - 2.0,
                 "heat-set insert" if profile.buy.shelf == "print" else "tapped thread")
    else:
        core = core_bolt_lengths(profile, t)
        threaded("extrusion's foot core screw", "M8", core["foot"], -t.bench_z - CORE_HEAD_BORE[1] - POCKET_DEPTH,
                 CORE_TAP_DEPTH - 1.0, "tapped core")
        threaded("extrusion's top core screw", "M8", core["top"], t.shelf_thickness - POCKET_DEPTH, CORE_TAP_DEPTH - 1.0,
                 "tapped core")
    washers = joint_washers(profile, layout)
    lens = next(h for h in hw if h["joins"].startswith("the lens mount's slotted foot"))
    nut("lens mount's foot on the shelf", lens["length_mm"],
        tw.wall + t.shelf_thickness + washers["lens"].thickness + th.washer_thickness)
    spring = next(h for h in hw if h["joins"].startswith("from under the shelf up through the holder's flange"))
    nut("splitter holder's spring bolts (spring free)", spring["length_mm"],
        2 * th.washer_thickness + t.shelf_thickness + seat_gap(profile) + tw.wall + SEAT_SPRING["free_length"])
    for joint, screws in (("projector on its shims", projector_screws(profile, layout)),
                          ("camera on its shims", camera_stack_screws(profile, layout))):
        for r in screws:
            rows.append({"joint": f"{joint} ({r['shims']} printed shims)", "thread": None, "length_mm": r["length_mm"],
                         "grip_mm": r["grip_mm"], "into": "the instrument's socket", "engaged_mm": r["engagement_mm"],
                         "least_mm": r["least_engagement_mm"], "ok": r["ok"]})
    return rows


def splitter_spec(profile: Profile) -> str:
    """The beam splitter as a catalogue would list it (size, ratio at 45 deg, coating, thickness)."""
    bs = profile.beam_splitter
    r = round(100 * bs.reflectance)
    return (f"plate beam splitter, {bs.width:g} x {bs.length:g} mm, {bs.thickness:g} mm thick, {r}R/{100 - r}T at "
            f"45 deg (400-700 nm), {bs.coating} coating on the front face, AR-coated back; the holder's grooves are "
            f"cut for {bs.thickness:g} mm + {2 * GROOVE_GAP:g} mm")


# -- the instruments and markers in rig.step -------------------------------------------------------
#: Side of the centre-of-projection markers (mm): visible in a viewer, small against every body.
MARKER = 2.0


def _marker(name: str, p, color) -> Part:
    h = MARKER / 2
    return Part(name, Box((p[0] - h, p[1] - h, p[2] - h), (p[0] + h, p[1] + h, p[2] + h)), color,
                f"marker: {name.replace('_', ' ')} at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) mm")


def _sphere(centre, r: float, n: int = 16) -> Translate:
    """A ball drawn as the polygon of ``n`` sides inscribed in its meridian, revolved (inside the ball:
    a drawing never reaches past the true surface)."""
    pts = [(r * math.sin(math.pi * k / n), -r * math.cos(math.pi * k / n)) for k in range(n + 1)]
    pts[0], pts[-1] = (0.0, -r), (0.0, r)
    segs = tuple(Line(pts[k], pts[k + 1]) for k in range(n)) + (Line((0.0, r), (0.0, -r)),)
    return Translate(Revolve(Section(segs)), tuple(float(v) for v in centre))


def _pin_along_y(centre, r: float, length: float, n: int = 16) -> Translate:
    """A dowel pin along y drawn as the inscribed polygon of ``n`` sides, extruded."""
    pts = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)]
    return Translate(Prism(Section(tuple(Line(pts[k], pts[(k + 1) % n]) for k in range(n))), length),
                     tuple(float(v) for v in centre))


#: The seat's balls and pins are drawn this much (mm) under their radius: the screws' balls touch the
#: cone's balls, the vee's pins and the gauge block, and a mesh's facets would otherwise show them
#: pressing into each other.
DRAWN_UNDER = 0.1


def _seat_balls(profile: Profile, t: TowerLayout) -> tuple[Part, ...]:
    """The splitter seat's bought hard parts in place: the three balls in the push screws' cups (on the
    cone, the vee and the flat), the cone's three balls, the vee's two dowel pins and the flat's gauge
    block (:func:`splitter_seat`); balls and pins DRAWN_UNDER their size."""
    g = seat_geometry(profile)
    S = t.shelf_top_z
    pts = seat_points(t, profile)
    steel = (0.8, 0.8, 0.85)
    out = [Part(f"seat_ball_{i + 1}", _sphere((x, y, S + g.centre), g.ball / 2 - DRAWN_UNDER), steel,
                f"{g.ball:g} mm steel ball (ISO 3290) in the {kind}'s push screw's cup, on the shelf's {kind}")
           for i, (kind, (x, y)) in enumerate(pts.items())]
    (cx, cy), (vx, vy), (fx, fy) = pts["cone"], pts["vee"], pts["flat"]
    rc = g.ball / math.sqrt(3.0)
    for k in range(3):
        ang = math.pi / 2 + 2 * math.pi * k / 3
        out.append(Part(f"seat_cone_ball_{k + 1}", _sphere((cx + rc * math.cos(ang), cy + rc * math.sin(ang),
                                                            S + g.centre - g.cone_drop), g.ball / 2 - DRAWN_UNDER),
                        steel, f"{g.ball:g} mm steel ball (ISO 3290) bonded into the shelf's cone pocket: one of the "
                        "three the seat's cone is made of"))
    for k, side in enumerate((-1, 1)):
        out.append(Part(f"seat_vee_pin_{k + 1}", _pin_along_y((vx + side * g.pin / 2, vy, S + g.centre - g.vee_drop),
                                                              g.pin / 2 - DRAWN_UNDER, SEAT_PIN_LENGTH),
                        steel, f"{g.pin:g} mm dowel pin (ISO 8734) in the shelf's channel: one side of the seat's vee"))
    py, px = GAUGE_BLOCK_FACE
    out.append(Part("seat_flat_pad", Box((fx - px / 2, fy - py / 2, S - SEAT_PAD_LENGTH), (fx + px / 2, fy + py / 2, S)),
                    steel, f"{SEAT_PAD_LENGTH:g} mm gauge block (ISO 3650) in the shelf's pocket: the seat's flat"))
    return tuple(out)


def instruments(profile: Profile, layout) -> tuple[Part, ...]:
    """The bought items as simple named solids in their working positions (not printed): projector
    and camera bodies and lenses, the beam splitter plate, the focusing lens, the nominal shim
    stacks, the splitter seat's balls; and markers at the design COP and at the projector's and camera's real COPs."""
    t = layout.tower
    tw, ln = profile.tower, profile.lens
    p = t.plate
    nx, nz = p.normal[0], p.normal[2]
    lx, lz = p.length_dir[0], p.length_dir[2]
    cx, cz = p.center[0], p.center[2]
    a = p.half_length
    pts = [(cx - a * lx, cz - a * lz), (cx + a * lx, cz + a * lz),
           (cx + a * lx - p.thickness * nx, cz + a * lz - p.thickness * nz),
           (cx - a * lx - p.thickness * nx, cz - a * lz - p.thickness * nz)]
    plate = Prism(Section(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4))), 2 * p.half_width)
    zc = t.cop[2] - tw.splitter_distance
    r = ln.diameter / 2
    stack = t.shims_nominal * tw.shim_thickness
    h = SHIM_SIDE / 2
    z_body = t.projector_box[0][2]
    shims = tuple(Part(f"projector_shims_{i + 1}", Box((x - h, y - h, z_body - stack), (x + h, y + h, z_body)),
                       (0.9, 0.8, 0.3), f"{t.shims_nominal} shims under projector foot {i + 1}")
                  for i, (x, y) in enumerate(_projector_feet(t)))
    (cx0, _, cz0), (cx1, _, cz1) = t.camera_box
    ccx, ccz = 0.5 * (cx0 + cx1), 0.5 * (cz0 + cz1)
    cam_shims = Box((ccx - h, t.bracket_y, ccz - h), (ccx + h, t.bracket_y + stack, ccz + h))
    glass = (0.6, 0.8, 0.9)
    dark = (0.15, 0.15, 0.17)
    return (
        Part("projector_body", Box(*t.projector_box), dark, f"projector body ({profile.projector.body_width:g} x "
             f"{profile.projector.body_depth:g} x {profile.projector.body_height:g} mm, "
             f"{size_origin(profile, 'projector', ('body_width', 'body_depth', 'body_height'))})"),
        Part("projector_lens", Box(*t.projector_lens_box), dark,
             f"projector lens barrel ({size_origin(profile, 'projector', ('lens_diameter', 'lens_length'))})"),
        Part("camera_body", Box(*t.camera_box), dark,
             f"camera body ({size_origin(profile, 'camera', ('body_width', 'body_height', 'body_depth'))})"),
        Part("camera_lens", Box(*t.camera_lens_box), dark,
             f"camera lens ({size_origin(profile, 'camera', ('lens_diameter', 'lens_length'))})"),
        Part("beam_splitter", plate, glass, f"plate beam splitter {profile.beam_splitter.width:g} x "
             f"{profile.beam_splitter.length:g} x {profile.beam_splitter.thickness:g} mm at 45 deg"),
        Part("focusing_lens", Box((t.lens_x - ln.thickness / 2, -r, zc - r), (t.lens_x + ln.thickness / 2, r, zc + r)),
             glass, f"focusing lens {ln.diameter:g} mm (its square bounding box)"),
        *shims,
        *_seat_balls(profile, t),
        Part("camera_shims", cam_shims, (0.9, 0.8, 0.3), f"{t.shims_nominal} shims behind the camera"),
        _marker("cop_marker", t.cop, (1.0, 0.1, 0.1)),
        _marker("projector_cop_marker", t.projector_cop, (1.0, 0.6, 0.1)),
        _marker("camera_cop_marker", t.camera.cop, (0.1, 0.8, 0.2)),
    )


__all__ = ["TOWER_PARTS", "TowerLayout", "hardware", "instruments", "lens_mount", "splitter_holder", "tower_column",
           "tower_layout", "tower_shelf", "tower_shim"]
