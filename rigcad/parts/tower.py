"""The COP tower (thesis 3.1 items 2-7, Figure 3.4): what holds the projector, the camera, the beam
splitter and the focusing lens so that both centres of projection (COP) sit at ``cop_z``.

Layout (mm, rig frame: O at the origin, optical axis +z; every number from the profile):

* the plate beam splitter (``optics.splitter``) at 45 deg on the axis, ``tower.splitter_distance``
  below the COP, its coated front face towards +x and down;
* the projector on its side of the splitter at 90 deg: its COP on the x axis as far from the axis as
  the splitter is below the COP (its image in the front face is the design COP), looking -x;
* the camera behind the splitter on the axis, looking down through the plate, its COP moved by the
  plate's compensation (``optics.splitter.camera_cop``: 0.34 mm across and 0.47 mm up for 1 mm of
  N-BK7) so that it sees the rig from the design COP;
* the focusing lens on the projector's axis between its lens and the splitter, in a square pocket;
* a shelf under the projector reaching over the axis (a hole lets the bundle down), on a square
  column that stands on the bench beside the base plate (the bench is level with the rig's lowest
  point, the sample holder's stop collar);
* the splitter holder on the shelf: two side walls with 45 deg grooves the plate rests in (it slides
  in through the +y wall), a back
  wall (a light dump for the half of the projector's light the plate transmits), and the camera
  bracket above, with a slot for the camera's tripod screw;
* adjustment, each way from the nominal placement: the camera slides in its bracket's slot along the
  axis (``tower.travel_along``) and across it in x (``tower.travel_across``), and on slotted shims
  in y; the projector slides in the shelf's slots along its own axis (its virtual COP moves along
  the optical axis) and across it, and on shims in height (its virtual COP moves across, in x).

Instruments are not printed: :func:`instruments` gives them as simple named solids for rig.step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.errors import GeometryError
from rigcad.optics.splitter import CameraPlacement, Plate, camera_cop, mirror_point, splitter_plate
from rigcad.parts.recipe import Box, Cylinder, Difference, Line, Part, Prism, Section, Translate, Union_
from rigcad.profile.derived import Derived
from rigcad.profile.schema import MOUNT_THREADS, Profile

#: Clearance hole over a thread's major diameter (mm): ISO 273 medium for M4 is 4.5 mm.
THREAD_CLEARANCE = 0.5
#: Gap around the splitter plate in its grooves (mm): a printed groove comes out ~0.1 mm narrow.
GROOVE_GAP = 0.2
#: Depth of the grooves into the holder's side walls (mm): the plate's edge rests on this much.
GROOVE_DEPTH = 2.0
#: Square adjustment shims (mm): side; the U slot takes the screw without removing it.
SHIM_SIDE = 30.0
#: Inset of the projector's shim stacks (and the shelf's slots under them) from its body's corners (mm).
FOOT_INSET = 30.0


def clearance_hole(thread: str) -> float:
    """Clearance hole diameter (mm) for a named mounting thread."""
    return MOUNT_THREADS[thread] + THREAD_CLEARANCE


@dataclass(frozen=True)
class TowerLayout:
    """Placements of the tower and its instruments (mm). ``plate``: the splitter; ``camera``: the
    compensated camera placement; ``projector_cop``: the projector's real COP (its image in the
    plate's front face is the design COP); ``*_z``: heights of the shelf, the bench and the holder."""

    plate: Plate
    camera: CameraPlacement
    projector_cop: tuple[float, float, float]
    cop: tuple[float, float, float]
    bench_z: float
    shelf_top_z: float
    shelf_thickness: float
    holder_x: tuple[float, float]  #: back, front of the splitter holder
    holder_top_z: float
    wall_y: tuple[float, float]  #: inner, outer |y| of the holder's side walls
    bracket_y: float  #: the camera bracket's face (y), under the camera's shims
    column_x: float  #: the column's centre (x; y = 0)
    projector_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    projector_lens_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    camera_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    camera_lens_box: tuple[tuple[float, float, float], tuple[float, float, float]]
    lens_x: float  #: the focusing lens's centre on the projector's axis
    bundle_radius_at_shelf: float  #: the projector's ray bundle (pinhole cone + aperture) at the shelf
    shims_nominal: int  #: shims under the projector and behind the camera at the nominal placement
    shims_per_stack: int  #: shims printed per stack: the full travel both ways

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


def _projector_boxes(profile: Profile, p_cop, plate_x1: float):
    """The focusing lens's x and the projector body's and lens's boxes (looking -x at the splitter)."""
    tw, pj, ln = profile.tower, profile.projector, profile.lens
    z_s = p_cop[2]
    front = p_cop[0] - pj.pupil_depth
    lens_x = float(p_cop[0] - ln.distance)
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
    p_cop = mirror_point(plate, (0.0, 0.0, cop_z))  # = (L, 0, cop_z - L): the projector's real COP
    px0, px1, pz0, pz1 = _plate_extent(plate)
    _check_splitter_size(profile, geometry)
    camera_box, camera_lens_box, face_y = _camera_boxes(profile, camera, pz1, L)
    lens_x, projector_box, projector_lens_box = _projector_boxes(profile, p_cop, px1)
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
        bench_z=-(profile.base_plate.thickness + profile.sample_holder.stop_thickness), shelf_top_z=shelf_top,
        shelf_thickness=shelf_t, holder_x=(px0 - GROOVE_GAP - 1.0 - tw.wall, px1 + tw.wall), holder_top_z=pz1 + tw.wall,
        wall_y=(bs.width / 2 - GROOVE_DEPTH, wall_out), bracket_y=bracket_y,
        column_x=plate_r + tw.clearance + foot_half,
        projector_box=projector_box, projector_lens_box=projector_lens_box, camera_box=camera_box,
        camera_lens_box=camera_lens_box, lens_x=lens_x,
        bundle_radius_at_shelf=_bundle_radius(profile, geometry, cop_z - (shelf_top - shelf_t)),
        shims_nominal=shims, shims_per_stack=2 * shims)


# -- the printed parts -----------------------------------------------------------------------------
def _holes(points, diameter: float, z0: float, height: float) -> tuple[Cylinder, ...]:
    return tuple(Cylinder((float(x), float(y), z0 - 1.0), diameter / 2, height + 2.0) for x, y in points)


def _slot(x: float, y: float, half_x: float, half_y: float, z0: float, height: float) -> Box:
    """A rectangular slot (a bolt moves half_x - r each way in x, half_y - r in y) through z0..z0+height."""
    return Box((x - half_x, y - half_y, z0 - 1.0), (x + half_x, y + half_y, z0 + height + 1.0))


def _column_flange_points(t: TowerLayout, profile: Profile):
    h = profile.tower.column_width / 2 + 1.5 * profile.tower.bolt_diameter
    return [(t.column_x + a * h, b * h) for a in (-1, 1) for b in (-1, 1)]


def _holder_flange_points(t: TowerLayout, profile: Profile):
    y = t.wall_y[1] + 1.5 * profile.tower.bolt_diameter
    x0, x1 = t.holder_x
    return [(x, s * y) for x in (x0 + 8.0, x1 - 8.0) for s in (-1, 1)]


def _lens_foot(t: TowerLayout, profile: Profile):
    """(x0, x1, half_y, bolt points) of the lens mount's foot."""
    ln, tw = profile.lens, profile.tower
    half_y = ln.diameter / 2 + GROOVE_GAP + tw.wall + 3 * tw.bolt_diameter
    half_x = max(ln.thickness / 2 + tw.wall / 2, tw.bolt_diameter / 2 + tw.travel_along + tw.wall)
    y = half_y - 1.5 * tw.bolt_diameter
    return t.lens_x - half_x, t.lens_x + half_x, half_y, [(t.lens_x, y), (t.lens_x, -y)]


def _projector_feet(t: TowerLayout):
    (x0, y0, _), (x1, y1, _) = t.projector_box
    return [(x, y) for x in (x0 + FOOT_INSET, x1 - FOOT_INSET) for y in (y0 + FOOT_INSET, y1 - FOOT_INSET)]


def _shelf_extent(t: TowerLayout, profile: Profile):
    tw = profile.tower
    (bx0, by0, _), (bx1, by1, _) = t.projector_box
    hy = t.wall_y[1] + 3 * tw.bolt_diameter
    _, _, lens_hy, _ = _lens_foot(t, profile)
    flange = tw.column_width / 2 + 3 * tw.bolt_diameter
    x0 = t.holder_x[0] - tw.wall
    x1 = max(bx1 + tw.wall, t.column_x + flange)
    y0 = min(by0 - tw.wall, -hy - tw.wall, -lens_hy - tw.wall, -flange)
    y1 = max(by1 + tw.wall, hy + tw.wall, lens_hy + tw.wall, flange)
    return x0, x1, y0, y1


def tower_column(profile: Profile, layout) -> Part:
    """Square hollow column on the bench beside the base plate, under the projector's shelf: a foot
    with four bolt holes (to the bench), a top flange with four (to the shelf)."""
    t, tw = layout.tower, profile.tower
    w = tw.column_width / 2
    top = t.shelf_top_z - t.shelf_thickness
    xc = t.column_x
    foot_h = w + 3 * tw.bolt_diameter
    foot = Box((xc - foot_h, -foot_h, t.bench_z), (xc + foot_h, foot_h, t.bench_z + tw.wall))
    tube = Difference(Box((xc - w, -w, t.bench_z), (xc + w, w, top)),
                      (Box((xc - w + tw.wall, -w + tw.wall, t.bench_z + tw.wall), (xc + w - tw.wall, w - tw.wall,
                                                                                    top - tw.wall)),))
    flange = Box((xc - foot_h, -foot_h, top - tw.wall), (xc + foot_h, foot_h, top))
    h = w + 1.5 * tw.bolt_diameter
    feet_holes = [(xc + a * h, b * h) for a in (-1, 1) for b in (-1, 1)]
    holes = _holes(feet_holes, tw.bolt_diameter, t.bench_z, tw.wall) + \
        _holes(_column_flange_points(t, profile), tw.bolt_diameter, top - tw.wall, tw.wall)
    return Part("tower_column", Difference(Union_((foot, tube, flange)), holes), (0.55, 0.57, 0.6),
                f"COP tower: hollow {tw.column_width:g} mm column on the bench beside the base plate, "
                "under the projector's shelf; bolts to the bench and to the shelf")


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
    holes = _holes(_column_flange_points(t, profile) + _holder_flange_points(t, profile) + lens_pts,
                   tw.bolt_diameter, z0, t.shelf_thickness)
    return Part("tower_shelf", Difference(plate, (hole, *slots, *holes)), (0.55, 0.57, 0.6),
                f"COP tower: shelf under the projector; {pj.mount_thread} screws through its four slots "
                f"(+-{tw.travel_along:g} mm along the projector's axis, +-{tw.travel_across:g} mm across) hold it "
                "on its shim stacks; a hole passes the ray bundle")


def _groove(t: TowerLayout) -> Translate:
    """The plate's slab in x-z with GROOVE_GAP around it: blind in the -y wall (GROOVE_DEPTH), through
    the +y wall, so the plate slides in along -y and rests on the groove's lower 45 deg faces."""
    p = t.plate
    n = np.array([p.normal[0], p.normal[2]])
    l_ = np.array([p.length_dir[0], p.length_dir[2]])
    c = np.array([p.center[0], p.center[2]])
    a = p.half_length + GROOVE_GAP
    front = c + GROOVE_GAP * n
    back = c - (p.thickness + GROOVE_GAP) * n
    pts = [front - a * l_, front + a * l_, back + a * l_, back - a * l_]
    pts = [(float(q[0]), float(q[1])) for q in pts]
    y0, y1 = -(p.half_width + GROOVE_GAP), t.wall_y[1] + 1.0
    slab = Prism(Section(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4))), y1 - y0)
    return Translate(slab, (0.0, 0.5 * (y0 + y1), 0.0))


def splitter_holder(profile: Profile, layout) -> Part:
    """The beam splitter's holder on the shelf: side walls with 45 deg grooves (the plate slides in
    through the +y wall and rests on their lower faces), a back wall, bolt flanges, and the camera bracket above with a slot for the
    camera's tripod screw (+-travel_along along the axis, +-travel_across across)."""
    t, tw, cm = layout.tower, profile.tower, profile.camera
    x0, x1 = t.holder_x
    yi, yo = t.wall_y
    z0, z1 = t.shelf_top_z, t.holder_top_z
    walls = [Box((x0, s0, z0), (x1, s1, z1)) for s0, s1 in ((-yo, -yi), (yi, yo))]
    back = Box((x0, -yo, z0), (x0 + tw.wall, yo, z1))
    fl = 3 * tw.bolt_diameter
    flanges = [Box((x0, -yo - fl, z0), (x1, -yo, z0 + tw.wall)), Box((x0, yo, z0), (x1, yo + fl, z0 + tw.wall))]
    (cx0, _, cz0), (cx1, _, cz1) = t.camera_box
    cx = 0.5 * (cx0 + cx1)
    d = clearance_hole(cm.mount_thread)
    half_w = max((cx1 - cx0) / 2, d / 2 + tw.travel_across + tw.wall)
    bx0, bx1 = max(cx - half_w, x0), min(cx + half_w, x1)
    bracket = Box((bx0, -yo, z1 - tw.wall), (bx1, -yi, z1))  # sits into the -y wall's top
    upright = Box((bx0, -yo, z1 - tw.wall), (bx1, t.bracket_y, cz1))
    screw_z = 0.5 * (cz0 + cz1)
    slot = Box((cx - d / 2 - tw.travel_across, -yo - 1.0, screw_z - d / 2 - tw.travel_along),
               (cx + d / 2 + tw.travel_across, t.bracket_y + 1.0, screw_z + d / 2 + tw.travel_along))
    holes = _holes(_holder_flange_points(t, profile), tw.bolt_diameter, z0, tw.wall)
    solid = Difference(Union_((*walls, back, *flanges, bracket, upright)), (_groove(t), slot, *holes))
    return Part("splitter_holder", solid, (0.3, 0.5, 0.75),
                f"COP tower: holds the {profile.beam_splitter.thickness:g} mm plate beam splitter at 45 deg in its "
                f"grooves (slide it in through the +y wall) and the camera on its bracket above "
                f"({cm.mount_thread} screw in the slot; shims between camera and bracket)")


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

#: What a bolt needs past its grip (mm): a washer and a nut (0.8 d) for a through bolt, and two
#: threads proud; or, screwed into an instrument, the thread engaged in its socket (assumed 5 mm).
NUT_FACTOR = 0.8
WASHER = 1.0
SOCKET_ENGAGEMENT = 5.0
#: Bolt lengths are rounded up to this step (mm): ISO 4762 lengths run in 5 mm steps from 10 to 50.
LENGTH_STEP = 5.0


def _length(grip: float, extra: float) -> float:
    return LENGTH_STEP * math.ceil((grip + extra) / LENGTH_STEP - 1e-9)


def hardware(profile: Profile, layout) -> list[dict]:
    """The tower's bought hardware, computed from the parts (mm; units in keys): each item's name,
    quantity, thread and length (grip plus nut or socket engagement, rounded up to LENGTH_STEP), and
    what it joins. The bench bolts are the user's (their length depends on the bench)."""
    t, tw, pj, cm, bs, ln = layout.tower, profile.tower, profile.projector, profile.camera, \
        profile.beam_splitter, profile.lens
    m4 = "M4"
    nut = NUT_FACTOR * MOUNT_THREADS[m4] + WASHER + 1.0  # + two threads of 0.7 mm pitch, rounded
    through = _length(tw.wall + t.shelf_thickness, nut)
    shim_max = t.shims_per_stack * tw.shim_thickness
    bracket = t.bracket_y + t.wall_y[1]  # the camera bracket's thickness (y)
    _, _, _, lens_pts = _lens_foot(t, profile)
    return [
        {"item": "bolt, washer and nut", "thread": m4, "length_mm": through, "quantity": 4,
         "joins": "the column's top flange to the shelf"},
        {"item": "bolt, washer and nut", "thread": m4, "length_mm": through, "quantity": len(_holder_flange_points(t, profile)),
         "joins": "the splitter holder's flanges to the shelf"},
        {"item": "bolt, washer and nut", "thread": m4, "length_mm": through, "quantity": len(lens_pts),
         "joins": "the lens mount's slotted foot to the shelf"},
        {"item": "bench bolt or screw", "thread": f"{tw.bolt_diameter:g} mm clearance holes", "length_mm": None,
         "quantity": 4, "joins": "the column's foot to the bench (length: the bench's)"},
        {"item": "screw and washer", "thread": pj.mount_thread,
         "length_mm": _length(t.shelf_thickness + shim_max, SOCKET_ENGAGEMENT), "quantity": len(_projector_feet(t)),
         "joins": "the projector's mounting holes, through the shelf's slots and its shim stacks"},
        {"item": "screw and washer", "thread": cm.mount_thread,
         "length_mm": _length(bracket + shim_max, SOCKET_ENGAGEMENT), "quantity": 1,
         "joins": "the camera's tripod socket, through the bracket's slot and its shim stack"},
        {"item": "plate beam splitter", "thread": None, "length_mm": None, "quantity": 1,
         "size_mm": [bs.width, bs.length, bs.thickness], "index": bs.index,
         "joins": "slides into the splitter holder's grooves through its +y wall, coated face towards the projector"},
        {"item": "focusing lens", "thread": None, "length_mm": None, "quantity": 1,
         "size_mm": [ln.diameter, ln.thickness], "joins": "drops into the lens mount's pocket"},
    ]


# -- the instruments and markers in rig.step -------------------------------------------------------
#: Side of the centre-of-projection markers (mm): visible in a viewer, small against every body.
MARKER = 2.0


def _marker(name: str, p, color) -> Part:
    h = MARKER / 2
    return Part(name, Box((p[0] - h, p[1] - h, p[2] - h), (p[0] + h, p[1] + h, p[2] + h)), color,
                f"marker: {name.replace('_', ' ')} at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) mm")


def instruments(profile: Profile, layout) -> tuple[Part, ...]:
    """The bought items as simple named solids in their working positions (not printed): projector
    and camera bodies and lenses, the beam splitter plate, the focusing lens, the nominal shim
    stacks; and markers at the design COP and at the projector's and camera's real COPs."""
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
             f"{profile.projector.body_depth:g} x {profile.projector.body_height:g} mm, assumed)"),
        Part("projector_lens", Box(*t.projector_lens_box), dark, "projector lens barrel (assumed size)"),
        Part("camera_body", Box(*t.camera_box), dark, "camera body (assumed size)"),
        Part("camera_lens", Box(*t.camera_lens_box), dark, "camera lens (assumed size)"),
        Part("beam_splitter", plate, glass, f"plate beam splitter {profile.beam_splitter.width:g} x "
             f"{profile.beam_splitter.length:g} x {profile.beam_splitter.thickness:g} mm at 45 deg"),
        Part("focusing_lens", Box((t.lens_x - ln.thickness / 2, -r, zc - r), (t.lens_x + ln.thickness / 2, r, zc + r)),
             glass, f"focusing lens {ln.diameter:g} mm (its square bounding box)"),
        *shims,
        Part("camera_shims", cam_shims, (0.9, 0.8, 0.3), f"{t.shims_nominal} shims behind the camera"),
        _marker("cop_marker", t.cop, (1.0, 0.1, 0.1)),
        _marker("projector_cop_marker", t.projector_cop, (1.0, 0.6, 0.1)),
        _marker("camera_cop_marker", t.camera.cop, (0.1, 0.8, 0.2)),
    )


__all__ = ["TOWER_PARTS", "TowerLayout", "hardware", "instruments", "lens_mount", "splitter_holder", "tower_column",
           "tower_layout", "tower_shelf", "tower_shim"]
