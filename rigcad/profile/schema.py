"""Validated, frozen profile parameters (millimetres, radians).

Each section of a profile is a frozen dataclass; each field carries a :class:`Spec` saying its
kind, unit, default, valid range and meaning. :func:`validate` turns a :class:`RawProfile` into a
:class:`Profile` or raises :class:`ProfileError` naming the key, the file:line, the value and what
would be valid. Nothing after this module reads YAML.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from rigcad.errors import ProfileError
from rigcad.standards import MOUNT_THREADS
from rigcad.profile import instruments as instrument_files
from rigcad.profile.loader import Key, RawProfile
from rigcad.units import DEG, UnitError, parse_quantity

REQUIRED = object()

#: Largest finite length a profile may give (mm): rigcad designs bench-top rigs; past this a value
#: is a typo (a unit slip) and, far past it, float64 loses the micrometres the dome is built to.
MAX_LENGTH_MM = 10_000.0
#: Largest seed (numpy's SeedSequence takes any int; this keeps seeds portable as int64).
MAX_SEED = 2**63 - 1
#: Largest projector or camera side (pixels): 16K, past any projector (8K UHD is 7680 x 4320) or
#: machine-vision camera (150 MP: 14204 x 10652) of the rig's kind; the calibration image has a
#: byte per projector pixel (268 MB at 16384 x 16384, 10 GB at the 100,000 once allowed).
MAX_PIXELS = 16_384
#: Thickest coating layer (mm): paint films are 0.01..0.1 mm; a millimetre is a unit slip.
MAX_COATING_LAYER_MM = 1.0
#: What the rig may stand on (``datum.mount``): its base plate on a bench, or an optical breadboard
#: (rigcad.parts.breadboard holds each grid's pitch and thread).
MOUNTS = ("base_plate", "breadboard_m6_25mm", "breadboard_imperial_1in")

_POS = {"lo": 0, "lo_open": True}
#: Most holes a ``holes`` key lists: an instrument's mounting pattern has 2 to 6.
MAX_HOLES = 16


@dataclass(frozen=True)
class Spec:
    """How one profile key is read and checked.

    ``kind`` is ``length`` (mm), ``angle`` (rad), ``int``, ``float``, ``choice``, ``pixels``
    (a ``[width, height]`` pair of positive integers), ``layers`` (a list of named thicknesses),
    ``lengths`` (a list of lengths, mm, each within the bounds), ``ints`` (a list of whole numbers,
    each within the bounds), ``name`` (an instrument file's name, rigcad.profile.instruments),
    ``point`` (an ``[x, y]`` pair of pixel coordinates, each 0..MAX_PIXELS) or ``holes`` (a list of
    ``[along, across]`` pairs of lengths, mm, at most MAX_HOLES).
    Bounds are in internal units.
    """

    kind: str
    doc: str
    default: Any = REQUIRED
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    allow_inf: bool = False
    choices: tuple[str, ...] = ()

    def describe_range(self) -> str:
        unit, scale = {"length": ("mm", 1.0), "angle": ("deg", DEG), "mass": ("kg", 1.0)}.get(self.kind, ("", 1.0))
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "name":
            return "the name of a file under instruments/, without .yaml"
        if self.kind == "point":
            return f"[x, y] in pixels, each 0..{MAX_PIXELS}"
        if self.kind == "holes":
            return f"a list of 1..{MAX_HOLES} [along, across] pairs of lengths"
        if self.kind == "fraction":
            return f"{self.lo * 100:g} % to {self.hi * 100:g} % (or {self.lo:g} to {self.hi:g})"
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {self.lo / scale:g} {unit}".rstrip())
        if self.hi is not None:
            parts.append(f"{'<' if self.hi_open else '<='} {self.hi / scale:g} {unit}".rstrip())
        return " and ".join(parts) if parts else "any value"


def spec(kind: str, doc: str, default: Any = REQUIRED, **kw: Any) -> Any:
    """A dataclass field whose metadata is a :class:`Spec`."""
    s = Spec(kind=kind, doc=doc, default=default, **kw)
    if default is REQUIRED:
        return field(metadata={"spec": s})
    return field(default=None, metadata={"spec": s})


# ---------------------------------------------------------------------------------------------
# Sections. Geometry frame: meridional plane, sample point O at the origin, optical axis +z.


@dataclass(frozen=True)
class ParaboloidParams:
    """The convex paraboloid mirror, vertex up towards the centre of projection (COP).

    Give either (``vertical_extent``, ``tangent_angle``) as in the thesis's Table 3.1, or
    (``focal_length``, ``rim_radius``).
    """

    vertical_extent: float | None = spec(
        "length", "d_p: axial distance from the vertex down to the plane of the rim", None, lo=0, lo_open=True)
    tangent_angle: float | None = spec(
        "angle", "tau: angle between the rim's meridional tangent and the optical axis", None,
        lo=0, hi=90 * DEG, lo_open=True, hi_open=True)
    focal_length: float | None = spec("length", "f: vertex to focus", None, lo=0, lo_open=True)
    rim_radius: float | None = spec("length", "radius of the rim circle", None, lo=0, lo_open=True)


@dataclass(frozen=True)
class LayoutParams:
    """Where the paraboloid sits between the COP and the sample point."""

    cop_to_vertex: float = spec(
        "length", "d_cp: COP down to the paraboloid's vertex (its nearest point to the COP); 'inf' for parallel rays",
        lo=0, lo_open=True, allow_inf=True)
    sample_to_rim: float = spec(
        "length", "d_o: sample point up to the plane of the paraboloid's rim (its nearest point to the sample)",
        lo=0, lo_open=True)


@dataclass(frozen=True)
class ProjectorParams:
    """The projector at the COP, looking down the optical axis. ``model`` names a projector file
    (``instruments/<model>.yaml``, rigcad.profile.instruments): its figures replace the defaults
    below but for the keys the profile sets; the sizes neither gives stay ASSUMED
    (``rigcad.profile.instruments.measurements`` lists them)."""

    model: str = spec("name", "projector file under instruments/ (rigcad.profile.instruments)", "benq_pb6210")
    resolution: tuple[int, int] = spec("pixels", "[width, height] in pixels", [1024, 768])
    throw_ratio: float = spec("float", "throw distance / image width (sets the field of view)", 1.75,
                              lo=0, lo_open=True, hi=100)
    lens_offset: float = spec(
        "fraction", "the image's centre above its lens axis, in half image heights, as the datasheet's offset "
        "(100 % or 1: the image's bottom edge on the axis; 0: centred, or a lens shift set to the centre; "
        "assumed 0); the paraboloid's image is a disc about the axis's pixel (rigcad.profile.derived)", 0.0, lo=0, hi=2)
    native_resolution: tuple[int, int] | None = spec(
        "pixels", "[width, height] of the mirror array or panel itself, when the projector shifts it to show more "
        "(4K XPR, e-shift); default: none given (projector.resolution is native)", None)
    aperture: float = spec("length", "thin-lens aperture diameter (thesis 3.2.2)", "0.5 cm", lo=0)
    # The body as the COP tower holds it (rigcad.parts.tower). The thesis names the BenQ PB6210 and
    # its resolution only; these sizes are ASSUMED (a 2006 XGA DLP of its class), no datasheet at hand.
    body_width: float = spec("length", "body width across its optical axis (assumed)", "284 mm", **_POS)
    body_height: float = spec("length", "body height (assumed)", "109 mm", **_POS)
    body_depth: float = spec("length", "body depth along its optical axis, lens excluded (assumed)", "235 mm", **_POS)
    lens_diameter: float = spec("length", "diameter of the lens barrel (assumed)", "50 mm", **_POS)
    lens_length: float = spec("length", "lens barrel's protrusion from the body's front face (assumed)", "20 mm",
                              lo=0)
    pupil_depth: float = spec("length", "entrance pupil (the COP) behind the lens barrel's front, along the axis "
                              "(assumed)", "10 mm", lo=0)
    pupil_height: float = spec("length", "optical axis above the body's bottom face (assumed)", "55 mm", **_POS)
    mass: float = spec("mass", "mass with its lens, on the shelf (assumed: a desktop projector of the PB6210's class; "
                       "weigh it)", "3 kg", lo=0.0, lo_open=True)
    pupil_lateral: float = spec("length", "optical axis's offset from the body's centre line, across (assumed)",
                                "0 mm")
    mount_thread: str = spec("choice", "thread of the body's mounting holes (ceiling mount; assumed)", "M4",
                             choices=tuple(MOUNT_THREADS))
    mount_depth: float = spec("length", "depth of thread in the body's mounting holes (assumed: 8 mm, a ceiling "
                              "mount's brass insert)", "8 mm", **_POS)
    mount_holes: tuple[tuple[float, float], ...] | None = spec(
        "holes", "the body's mounting holes in its bottom face, each [along, across]: along the optical axis back "
        "from the COP (the entrance pupil), across it to the right seen from behind (looking where the projector "
        "projects); default: four, 30 mm in from the bottom face's corners (assumed)", None)
    focus_min: float = spec("length", "nearest distance the projector's own lens focuses, from its COP (assumed: "
                            "1 m, a business projector's)", "1 m", **_POS)
    focus_max: float = spec("length", "farthest distance it focuses, from its COP (assumed: 10 m)", "10 m", **_POS,
                            allow_inf=True)


@dataclass(frozen=True)
class CameraParams:
    """The camera, sharing the COP through the beam splitter: behind it on the optical axis, looking
    down through the plate (thesis Figure 3.4, right). ``model``: a camera file, as for the
    projector; ``lens``: a lens file (its focal length, sizes and closest focus fill the lens keys).
    Without a lens file or ``focal_length`` the lens is the one that frames the paraboloid as the
    projector does (rigcad.optics.camera, reported as derived)."""

    model: str = spec("name", "camera file under instruments/ (rigcad.profile.instruments)", "prosilica_ec1350c")
    resolution: tuple[int, int] = spec("pixels", "[width, height] in pixels", [1360, 1024])
    pixel_pitch: float | None = spec("length", "the sensor's pixel pitch (e.g. 3.45 um); default: unknown, the "
                                     "lens then known in pixels only", None, lo=0, lo_open=True, hi=0.1)
    lens: str | None = spec("name", "lens file under instruments/ (its focal length, sizes, closest focus); "
                            "default: none, the lens that frames the paraboloid as the projector does (derived)",
                            None)
    focal_length: float | None = spec("length", "the lens's focal length (needs pixel_pitch); default: the lens "
                                      "file's, else derived (rigcad.optics.camera)", None, lo=0, lo_open=True,
                                      hi=2000.0)
    principal_point: tuple[float, float] | None = spec(
        "point", "[x, y] px from the image's top-left corner where the optical axis meets the sensor; "
        "default: the centre, [width / 2, height / 2]", None)
    min_working_distance: float | None = spec("length", "the lens's closest focus, from its front (the "
                                              "datasheet's MOD); default: unknown, not checked", None, lo=0)
    # The Prosilica EC 1350C of thesis 3.1: resolution from the thesis; the sizes are ASSUMED
    # (a C-mount FireWire machine-vision camera of its class), no datasheet at hand.
    body_width: float = spec("length", "body width across its optical axis (assumed)", "46 mm", **_POS)
    body_height: float = spec("length", "body height, mounting face to top (assumed)", "33 mm", **_POS)
    body_depth: float = spec("length", "body depth along its optical axis, lens excluded (assumed)", "59 mm",
                             **_POS)
    lens_diameter: float = spec("length", "diameter of the C-mount lens (assumed)", "30 mm", **_POS)
    lens_length: float = spec("length", "lens protrusion from the body's front face (assumed)", "40 mm", lo=0)
    pupil_depth: float = spec("length", "entrance pupil (the COP) behind the lens's front, along the axis "
                              "(assumed)", "15 mm", lo=0)
    pupil_height: float = spec("length", "optical axis above the body's mounting (tripod) face (assumed: centred)",
                               "16.5 mm", **_POS)
    mass: float = spec("mass", "mass with its lens, on its bracket (assumed: a machine-vision camera with a C-mount "
                       "lens; weigh it)", "0.3 kg", lo=0.0, lo_open=True)
    mount_thread: str = spec("choice", "thread of the tripod hole in the mounting face (assumed)", "1/4-20 UNC",
                             choices=tuple(MOUNT_THREADS))
    mount_spacing: float = spec("length", "between the two screws that hold the camera (its mounting holes, or a "
                                "two-hole tripod adapter), along its optical axis (assumed)", "20 mm", **_POS)


@dataclass(frozen=True)
class LensParams:
    """The lens that focuses the projector on the paraboloid (thesis 3.1, item 6), on the projector's
    axis between its lens and the beam splitter. Sizes ASSUMED (a 50 mm close-up lens)."""

    diameter: float = spec("length", "lens diameter (assumed)", "50 mm", **_POS)
    thickness: float = spec("length", "edge thickness held by the mount (assumed)", "6 mm", **_POS)
    distance: float = spec("length", "from the projector's COP to the lens's centre, along the projector's axis",
                           "25 mm", **_POS)
    focal_length: float | None = spec("length", "the lens's focal length; default: computed from the projector's "
                                      "focus range and the path to the paraboloid, rounded to a catalogue value "
                                      "(rigcad.optics.focus)", None, **_POS)
    rim: float = spec("length", "radial seat of the mount under the lens's edge (the clear aperture is the "
                      "diameter less twice this)", "2 mm", **_POS)


@dataclass(frozen=True)
class BeamSplitterParams:
    """The plate beam splitter at 45 deg on the optical axis (thesis 3.1, item 4; Figure 3.4): its
    coated front face reflects the projector down onto the paraboloid; the camera looks through the
    plate, whose thickness shifts the transmitted axis sideways (rigcad.optics.splitter). ``model``
    names a splitter file (its figures replace the defaults below but for the keys the profile sets)."""

    model: str | None = spec("name", "splitter file under instruments/ (rigcad.profile.instruments); default: "
                             "none, the sizes below", None)
    width: float = spec("length", "plate width across the plane of incidence (assumed)", "50 mm", **_POS)
    length: float = spec("length", "plate length along the 45 deg slope (assumed)", "50 mm", **_POS)
    thickness: float = spec("length", "plate thickness (catalogue plate beam splitters are 1.1 mm soda-lime or "
                            "B270 float glass, or 1 / 3 mm N-BK7)", "1.1 mm", **_POS)
    reflectance: float = spec("float", "fraction of the light the coated face reflects (to the projector's side); "
                              "the camera gets the rest: 0.5 for a 50R/50T splitter", 0.5, lo=0, hi=1, lo_open=True,
                              hi_open=True)
    coating: str = spec("choice", "the front face's coating: dielectric (low absorption) or metallic (inconel, "
                        "~ 20 % absorbed, little polarisation); the back face is anti-reflection coated",
                        "dielectric", choices=("dielectric", "metallic"))
    index: float = spec("float", "refractive index of the plate (N-BK7 at 587.6 nm, 1.5168; the glass is assumed)",
                        1.5168, lo=1.0, hi=4.0)


@dataclass(frozen=True)
class TowerParams:
    """The COP tower (rigcad.parts.tower): a column on the base plate's datum tongue, a shelf for the
    projector at 90 deg that reaches over the optical axis, where the splitter holder (with the camera
    bracket above the splitter) and the lens mount stand. Adjustment travel is each way from the
    nominal position."""

    splitter_distance: float = spec("length", "from the COP down to the splitter's centre, along the optical axis "
                                    "(the projector's COP is as far from the axis)", "70 mm", **_POS)
    travel_along: float = spec("length", "adjustment each way along the optical axis (camera: its bracket's slot; "
                               "projector: its shelf's slots along its own axis); at least tolerancing's "
                               "camera_height and projector_height, and the vertical stack (rigcad.fab.stack)",
                               "2 mm", lo=0)
    travel_across: float = spec("length", "adjustment each way across the optical axis (camera: its bracket's "
                                "slot and shims; projector: its shelf's slots and shims); at least tolerancing's "
                                "camera_offset and projector_offset, and the lateral stack, seams and all "
                                "(rigcad.fab.stack)", "6 mm", lo=0)
    shim_thickness: float = spec("length", "thickness of one printed adjustment shim (the range; bought stainless "
                                 "shims, rigcad.parts.tower.fine_shims, set the fine steps)", "1 mm", **_POS)
    column_width: float = spec("length", "side of the square column", "50 mm", **_POS)
    wall: float = spec("length", "wall of the column, the splitter holder and the lens mount (the shelf is "
                       "twice as thick)", "5 mm", **_POS)
    clearance: float = spec("length", "least gap between the tower and the rig's parts, and between the tower "
                            "and the ray bundle", "5 mm", **_POS)
    bolt_diameter: float = spec("length", "clearance hole of the bolts joining the tower's parts (M4)", "4.5 mm",
                                **_POS)


@dataclass(frozen=True)
class DatumParams:
    """The rig's one reference (rigcad.parts.datum): the base plate. The tower's column stands on the
    base plate's datum tongue, located by two dowel pins in reamed printed holes and held by bolts;
    the shelf sits on the column the same way. The assumed print accuracy sets the error the chain
    can hold (``rigcad.parts.datum.datum_chain``)."""

    dowel_diameter: float = spec("length", "dowel pins locating each joint of the chain (ISO 8734, m6; the printed "
                                 "holes are reamed to H7)", "4 mm", **_POS)
    print_position: float = spec("length", "a printed feature's position error, fixed part (assumed: a calibrated "
                                 "FDM printer, about half a 0.4 mm nozzle's width)", "0.1 mm", lo=0)
    print_scale: float = spec("float", "a printed length's relative error (shrinkage, steps per mm; assumed 0.2 %)",
                              0.002, lo=0, hi=0.05)
    foot_flatness: float = spec("length", "out-of-flat of a printed foot or flange across its width (warp; "
                                "assumed)", "0.1 mm", lo=0)
    mount: str = spec("choice", "what the rig stands on: its own base plate on a bench, or screwed down to an "
                      "optical breadboard's grid (M6 on 25 mm, or 1/4-20 UNC on 1 in; rigcad.parts.breadboard)",
                      "base_plate", choices=MOUNTS)
    breadboard_hole_position: float = spec(
        "length", "a breadboard's tapped hole's position error, each way (assumed: 0.15 mm, the order of the "
        "makers' figures for machined breadboards; no maker's specification was found to cite)", "0.15 mm", lo=0)


@dataclass(frozen=True)
class AdjusterParams:
    """The adjusters (rigcad.parts.adjusters): what a hand can set, and the splitter's kinematic seat
    (three screws on three balls in a cone, a vee and a flat, two springs holding it down)."""

    turn_fraction: float = spec("float", "finest fraction of a turn a hand sets on a screw with a hex key "
                                "(assumed: 1/8 turn, 45 deg)", 0.125, lo=0, hi=1, lo_open=True)
    hand_slide: float = spec("length", "finest a hand sets a slide in a slot, against a caliper or a feeler gauge "
                             "(assumed)", "0.1 mm", **_POS)
    seat_thread: str = spec("choice", "thread of the splitter seat's push screws (set screws in heat-set inserts "
                            "in the holder's flanges)", "M3", choices=tuple(MOUNT_THREADS))
    seat_travel: float = spec("length", "travel of each seat screw, each way from its nominal setting", "1.5 mm",
                              **_POS)
    seat_ball: float = spec("length", "steel balls (DIN 5401) under the seat screws' tips", "3 mm", **_POS)


@dataclass(frozen=True)
class BuyParams:
    """Print or buy each structural part (rigcad.parts.stock): a bought part is standard stock cut to
    length; it is drawn in the rig, listed in the bill with its stock, and not printed."""

    column: str = spec("choice", "the tower's column: print it, or buy a 40 x 40 mm aluminium extrusion (slot 8, "
                       "M8 core tapped at both ends) with printed end plates", "print",
                       choices=("print", "extrusion_40x40"))
    shelf: str = spec("choice", "the tower's shelf: print it, or cut and drill it from aluminium plate (EN AW-5083) "
                      "as thick as the printed one, with the same outline, holes and seats", "print",
                      choices=("print", "aluminium_plate"))


@dataclass(frozen=True)
class TargetParams:
    """What the design must achieve; the design stage checks and reports these."""

    theta_min: float = spec("angle", "smallest incidence angle the design must reach", "9 deg",
                            lo=0, hi=90 * DEG)
    theta_max: float = spec("angle", "largest incidence angle the design must reach", "90 deg",
                            lo=0, hi=90 * DEG)


@dataclass(frozen=True)
class DomeParams:
    """How the dome profile is integrated (thesis 3.2)."""

    method: str = spec("choice", "integrator: dop853/rk45 (adaptive, scipy), euler (thesis polyline), "
                       "equal_path (closed form)", "dop853", choices=("dop853", "rk45", "euler", "equal_path"))
    tolerance: float | None = spec(
        "length", "adaptive integrators: certified global error in the distance along each reflected ray "
        "(default: 1e-11 of the optical path)", None, lo=1e-10, hi=1e-3)  # float64 resolves ~1e-13 mm on a path of
    # 100..1000 mm; below 1e-10 mm the error estimate is rounding (the integrator refuses, after long work)
    euler_steps: int = spec("int", "euler: rays evenly spaced in radius from the rim to the vertex; the polyline "
                            "stops before the first one whose return to O is occluded",
                            2000, lo=2, hi=2_000_000)
    # <= 2 M: the polyline's error falls as 1/steps (1000x the default is far past any print), and
    # it costs ~600 bytes a step (peak RSS 1.27 GB at 2 M, measured; 50 M would need ~30 GB)
    table_rows: int = spec("int", "rows of the profile table (CSV) and points of the smooth curve (at least: doubled "
                           "until the curve returns every chief ray to O within 1e-9 of the optical path)", 2001,
                           lo=11, hi=1_000_000)


@dataclass(frozen=True)
class MisalignmentParams:
    """2D misalignments (meridional plane); the design reports the convergence error of each."""

    camera_dx: float = spec("length", "camera horizontal offset", "0 mm")
    camera_dz: float = spec("length", "camera vertical offset", "0 mm")
    projector_dx: float = spec("length", "projector horizontal offset", "0 mm")
    projector_dz: float = spec("length", "projector vertical offset", "0 mm")
    paraboloid_dx: float = spec("length", "paraboloid horizontal offset", "0 mm")
    dome_dx: float = spec("length", "dome horizontal offset", "0 mm")
    probe: float = spec("length", "offset used for the per-component sensitivity table", "1 mm",
                        lo=0, lo_open=True, hi=50.0)
    camera_tilt: float = spec("angle", "3D ray check: camera tilt about +y (in the x-z plane), pivot at the COP",
                              "0 deg", lo=-10 * DEG, hi=10 * DEG)
    projector_tilt: float = spec("angle", "3D ray check: projector tilt about +y, pivot at the COP", "0 deg",
                                 lo=-10 * DEG, hi=10 * DEG)
    paraboloid_tilt: float = spec("angle", "3D ray check: paraboloid tilt about +y, pivot at its vertex", "0 deg",
                                  lo=-10 * DEG, hi=10 * DEG)
    dome_tilt: float = spec("angle", "3D ray check: dome tilt about +y, pivot at the sample point O", "0 deg",
                            lo=-10 * DEG, hi=10 * DEG)
    probe_tilt: float = spec("angle", "tilt used for the 3D ray check's sensitivity table", "1 mrad",
                             lo=0, lo_open=True, hi=10 * DEG)
    rays: int = spec("int", "rays traced across the paraboloid for each misalignment case", 401, lo=5, hi=100_000)



DEFAULT_COATING = [
    {"name": "black base paint", "thickness": "1.5 mil"},
    {"name": "polyurethane primer", "thickness": "1.5 mil"},
    {"name": "polyurethane clearcoat", "thickness": "1.5 mil"},
    {"name": "MirraChrome", "thickness": "1 mil"},
]


@dataclass(frozen=True)
class CoatingParams:
    """Paint stack on both mirrors (thesis 3.4: 5-6 mil in all). Printed mirror surfaces sit this
    far behind the design surfaces (dome outward, paraboloid inward)."""

    layers: tuple[tuple[str, float], ...] = spec(
        "layers", "layers bottom (on the print) to top (the mirror): [{name, thickness}]; total 5.5 mil",
        DEFAULT_COATING)
    margin: float = spec("float", "paint to have at hand per layer, as a multiple of the film's volume on the "
                         "mirrors (rigcad manual): spray guns land about half of what they spray (HVLP transfer "
                         "efficiency ~50-65 %), plus a test panel", 2.5, lo=1, hi=100)
    reflectance: float = spec("float", "fraction of visible light the top layer (the mirror) reflects, the same on "
                              "both mirrors; assumed 0.6: MirraChrome gives 95 % of chrome plating's reflectivity "
                              "(thesis 3.4), and polished chrome reflects ~0.6-0.65 of visible light. A ray seen "
                              "through the rig meets both mirrors, so it keeps its square", 0.6, lo=0, hi=1,
                              lo_open=True)


@dataclass(frozen=True)
class DomeShellParams:
    """The printed dome: a wall behind the mirror, a base flange, beam slots (thesis 3.1)."""

    wall: float = spec("length", "wall thickness behind the printed mirror surface, along its normal", "4 mm", **_POS)
    flange_width: float = spec("length", "base flange: radial width beyond the wall", "22 mm", **_POS)
    flange_thickness: float = spec("length", "base flange thickness", "6 mm", **_POS)
    bolts: int = spec("int", "bolts through the flange into the base plate", 8, lo=3, hi=64)
    bolt_diameter: float = spec("length", "bolt hole diameter (M4 clearance)", "4.5 mm", **_POS)
    slot_clearance: float = spec("length", "clearance around the beam in its wall slots (sides and top; it "
                                 "rests on the slot's floor)", "0.3 mm", lo=0)


@dataclass(frozen=True)
class ParaboloidMountParams:
    """The paraboloid mirror's body under the mirror surface, its stem and beam clamp."""

    back_thickness: float = spec("length", "solid back below the rim plane", "3 mm", **_POS)
    stem_radius: float = spec("length", "radius of the stem from the back down to the beam clamp", "4 mm", **_POS)
    stem_length: float = spec("length", "stem length from the back to the top of the beam", "8 mm", **_POS)
    clamp_wall: float = spec("length", "wall of the U clamp around the beam", "3 mm", **_POS)
    clamp_length: float = spec("length", "clamp length along the beam", "14 mm", **_POS)


@dataclass(frozen=True)
class BeamParams:
    """The narrow mounting beam spanning the dome (thesis Figure 3.3)."""

    width: float = spec("length", "beam width (across; it occludes a strip of directions)", "6 mm", **_POS)
    height: float = spec("length", "beam height", "10 mm", **_POS)
    overhang: float = spec("length", "length beyond the dome's outer wall at each end", "15 mm", lo=0)


@dataclass(frozen=True)
class BasePlateParams:
    """The plate under the dome: bolted to the flange, bored for the sample holder."""

    thickness: float = spec("length", "plate thickness (its top is the sample plane z = 0)", "10 mm", **_POS)
    margin: float = spec("length", "plate radius beyond the dome flange", "5 mm", lo=0)


@dataclass(frozen=True)
class SampleHolderParams:
    """The cylinder that slides into the base plate; the sample's top lands on z = 0."""

    radius: float = spec("length", "holder radius", "20 mm", **_POS)
    clearance: float = spec("length", "radial clearance in the base plate's bore", "0.15 mm", lo=0)
    sample_thickness: float = spec("length", "thickness of the material sample on the holder", "1 mm", lo=0)
    stop_radius: float = spec("length", "radius of the stop collar under the plate", "28 mm", **_POS)
    stop_thickness: float = spec("length", "thickness of the stop collar", "5 mm", **_POS)


@dataclass(frozen=True)
class CrossesParams:
    """Calibration crosses (thesis 4.1.1)."""

    arm_length: float = spec("length", "half-length of each cross arm from the centre", "15 mm", **_POS)
    bar_width: float = spec("length", "width of the cross bars", "2 mm", **_POS)
    thickness: float = spec("length", "thickness of the cross plate", "2 mm", **_POS)


@dataclass(frozen=True)
class TemplateParams:
    """Profile templates (thesis Figure 3.11): flat gauges with the negative of a mirror profile."""

    gauged_layer: str = spec("str", "the coating layer whose top surface the templates gauge (the polishing "
                             "stage is before the mirror paint); 'design' for the finished mirror", "polyurethane clearcoat")
    thickness: float = spec("length", "template plate thickness", "3 mm", **_POS)
    band: float = spec("length", "width of the template behind its gauging edge", "15 mm", **_POS)


@dataclass(frozen=True)
class TessellationParams:
    """Meshes: printed parts and the mirror meshes for the ray checker."""

    chord_error: float = spec("length", "printed parts (STL): max distance from the exact surface; default a "
                              "tenth of the thesis printer's 0.007 in layer (above 0.03 mm the small parts' STL "
                              "volumes drift past the 0.5 % STL/STEP check)", "0.018 mm", lo=0.002, hi=0.03)  # >= 2 um: a fifth of the
    # finest printer layer (0.01 mm); triangles grow as 1/chord error (9x the default's at the bound)
    mirror_chord_error: float = spec("length", "mirror meshes for the ray checker: max distance from the "
                                     "exact surface", "0.001 mm", lo=1e-4)  # >= 0.1 um: triangles grow as
    # 1/chord error: 0.8 M on the dome at the default, 7.9 M at the bound (export.mirror_mesh._plan)
    mirror_normal_error: float = spec("angle", "mirror meshes: max facet-normal error (the flat-facet reading; "
                                      "smooth traces use the exact vertex normals)", "0.01 rad", lo=1e-3)
    # >= 1 mrad: triangles grow as 1/error^2: 12 M on the dome at the bound (export.mirror_mesh._plan)
    fit_tolerance: float = spec("length", "B-spline fit of the mirror profiles in the STEP solids (<= 1 um)",
                                "0.1 um", lo=1e-6, hi=0.001)  # >= 1 nm: ten times OpenCascade's
    # Precision::Confusion (1e-7 mm), below which the kernel takes two points for one


@dataclass(frozen=True)
class RayCheckParams:
    """3D ray check (rigcad check): how rays are traced and the tolerances it enforces. Spots are the
    distance from the sample point O to each returning ray (mm); angles between a ray's arrival
    direction and the design's for its projector pixel (rad)."""

    mode: str = spec("choice", "surfaces traced: mesh (flat facets of the mirror meshes, what an STL says), "
                     "smooth (mirror meshes with interpolated vertex normals), analytic (exact surfaces)",
                     "smooth", choices=("mesh", "smooth", "analytic"))
    rays: int = spec("int", "pinhole rays aimed across the paraboloid's useful annulus (seeded)", 100_000,
                     lo=100, hi=50_000_000)
    seed: int = spec("int", "seed of the ray sampling", 2006, lo=0, hi=MAX_SEED)
    lens_azimuths: int = spec("int", "thin lens: aperture-edge rays per chief ray (thesis 3.2.2 traced 2 in 2D)",
                              8, lo=2, hi=64)
    max_spot_radius: float = spec("length", "largest distance from O to a returning pinhole ray, in `mode`",
                                  "0.01 mm", **_POS)
    max_facet_spot_radius: float = spec("length", "the same for the flat-facet (STL-literal) reading",
                                        "3 mm", **_POS)
    max_angle_error: float = spec("angle", "largest arrival-direction error against the design, per pixel, "
                                  "in `mode`", "0.01 deg", **_POS)
    max_mesh_angle_error: float = spec("angle", "largest arrival-direction difference mesh minus exact "
                                       "surfaces, in `mode` (mesh or smooth)", "0.01 deg",
                                       **_POS)
    theta_coverage_tolerance: float = spec("angle", "the traced theta range must reach each end of "
                                           "targets.theta_min..theta_max within this", "1.5 deg", lo=0)
    min_px_per_deg: float = spec("float", "fewest projector pixels per degree of theta (thesis 3.2.1: about 1)",
                                 0.9, lo=0)
    max_lost_fraction: float = spec("float", "largest fraction of rays aimed at the useful annulus that are "
                                    "occluded or escape", 0.08, lo=0, hi=1)


@dataclass(frozen=True)
class TolerancingParams:
    """Seeded Monte Carlo of the 3D ray check over fabrication and alignment tolerances: each build
    moves every component by an offset uniform in a disc of radius ``*_offset`` (x-y), uniform in
    +-``*_height`` (z), and tilts it by an angle uniform in 0..``*_tilt`` about a random horizontal
    axis (pivots: COP for camera and projector, vertex for the paraboloid, O for the dome)."""

    builds: int = spec("int", "random builds", 200, lo=1, hi=100_000)
    seed: int = spec("int", "seed of the builds", 2006, lo=0, hi=MAX_SEED)
    rays: int = spec("int", "pinhole rays per build", 4000, lo=100, hi=10_000_000)
    projector_offset: float = spec("length", "projector: lateral placement tolerance", "0.5 mm", lo=0)
    projector_height: float = spec("length", "projector: height tolerance", "1 mm", lo=0)
    projector_tilt: float = spec("angle", "projector: tilt tolerance", "0.5 deg", lo=0, hi=10 * DEG)
    camera_offset: float = spec("length", "camera: lateral placement tolerance", "0.5 mm", lo=0)
    camera_height: float = spec("length", "camera: height tolerance", "1 mm", lo=0)
    camera_tilt: float = spec("angle", "camera: tilt tolerance", "0.5 deg", lo=0, hi=10 * DEG)
    paraboloid_offset: float = spec("length", "paraboloid: lateral placement tolerance", "0.1 mm", lo=0)
    paraboloid_height: float = spec("length", "paraboloid: height tolerance", "0.2 mm", lo=0)
    paraboloid_tilt: float = spec("angle", "paraboloid: tilt tolerance", "0.2 deg", lo=0, hi=10 * DEG)
    dome_offset: float = spec("length", "dome: lateral placement tolerance", "0.3 mm", lo=0)
    dome_height: float = spec("length", "dome: height tolerance", "0.3 mm", lo=0)
    dome_tilt: float = spec("angle", "dome: tilt tolerance", "0.1 deg", lo=0, hi=10 * DEG)
    max_spot_radius: float = spec("length", "a build meets the target when its largest spot radius is at most this",
                                  "3 mm", **_POS)
    max_angle_error: float = spec("angle", "... and its largest arrival-direction error at most this", "1 deg",
                                  **_POS)
    min_yield: float = spec("float", "fewest builds (fraction) that must meet both targets", 0.9, lo=0, hi=1)


@dataclass(frozen=True)
class CalibrationParams:
    """Deflectometric calibration of the as-built rig (rigcad calibrate): a flat screen at the
    sample, shown phase-shifted sinusoids and Gray codes, seen by the camera through the mirrors at
    two or more heights. The screen's emitting surface stands at z = spacer + screen_thickness -
    sample_holder.sample_thickness (the spacer on the holder's seat). The ``sim_*`` keys shape the
    simulated capture (``--simulate``): the planted dome error and the camera's noise."""

    # the default: an 8.3-inch tablet (e.g. Apple's iPad mini, 6th generation: 2266 x 1488 px at 326 ppi): its
    # 176.5 x 115.9 mm display lies inside the dome's 234.7 mm at the sample plane; a 10-inch 16:10
    # tablet's corners (a 256.6 mm diagonal) would not (rigcad.calibrate.kit.check_screen_fits)
    screen_pitch: float = spec("length", "screen pixel pitch (a tablet: 0.05-0.1 mm)", "0.0779 mm",
                               lo=0.005, hi=2.0)
    screen_resolution: tuple[int, int] = spec("pixels", "screen [width, height] in pixels; the display must lie "
                                              "inside the dome at the spacers' heights", [2266, 1488])
    screen_thickness: float = spec("length", "screen: from its back (on the spacer) to its emitting surface",
                                   "6 mm", lo=0, hi=100.0)
    spacer_heights: tuple[float, ...] = spec("lengths", "printed spacers under the screen, one capture per "
                                             "spacer (two or more, distinct)", ["1 mm", "20 mm"], lo=0, hi=200.0)
    screen_tilt: float = spec("angle", "how far the screen laid on a spacer may tilt from the holder's seat (the "
                              "sample plane), the wedge of the spacer's faces and the screen's back: no image "
                              "shows that plane (the fit's prior; the simulation plants wedges within it)",
                              "0.2 deg", lo=0, lo_open=True, hi=5 * DEG)
    half_turn: str = spec("choice", "'every': each spacer is captured again with the spacer and the screen on it "
                          "turned a half turn together, so their wedge (screen_tilt) cancels between the two "
                          "captures and the sample plane's tilt is known to screen_seating; 'highest': the highest "
                          "spacer only; 'none': the map's frame rests on screen_tilt", "every",
                          choices=("every", "highest", "none"))
    screen_seating: float = spec("angle", "how the same screen on the same spacer repeats its tilt when laid again "
                                 "(dust, the print's texture): with half_turn, the map's frame's tolerance",
                                 "0.02 deg", lo=0, lo_open=True, hi=5 * DEG)
    upright_turns: int = spec("int", "captures of a second, small display stood on edge in the holder's bore, its face "
                              "towards the dome (rigcad.calibrate.upright): one at each of this many equal turns about "
                              "the axis (0: none; 3 or more cover every azimuth). It sees the rays near grazing, which "
                              "pass under the flat screen", 4, lo=0, hi=24)
    upright_offset: float = spec("length", "upright display: its face's distance from the axis (its module must stand in "
                                 "the holder's bore: rigcad.calibrate.kit.check_upright_fits)", "7 mm", lo=0, hi=100.0)
    upright_pitch: float = spec("length", "upright display: pixel pitch (a 2-inch 240 x 320 module: 0.1275 mm)",
                                "0.1275 mm", lo=0.005, hi=2.0)
    upright_resolution: tuple[int, int] = spec("pixels", "upright display: [width, height] in pixels, width along "
                                               "the sample plane", [240, 320])
    upright_depth: float = spec("length", "upright display: how far below the sample plane its active area starts "
                                "(its stand sinks it into the holder's bore, so the last rays before grazing meet it)",
                                "1 mm", lo=0, hi=20.0)
    upright_border: float = spec("length", "upright display: its module's frame beyond the active area, at the sides "
                                 "and below (the stand's ledge and the bore's room)", "2 mm", lo=0, hi=20.0)
    upright_thickness: float = spec("length", "upright display: the module's thickness (its stand's slot)", "4 mm",
                                    lo=0, lo_open=True, hi=30.0)
    upright_tilt: float = spec("angle", "upright display: how far it may lean in its stand or the stand turn from its "
                               "mark (the fit's prior; the simulation plants within it)", "2 deg", lo=0, lo_open=True,
                               hi=10 * DEG)
    phase_steps: int = spec("int", "phase shifts per sinusoid period (>= 3)", 4, lo=3, hi=64)
    periods: tuple[int, ...] = spec("ints", "sinusoid periods in screen pixels, coarse to fine unwrapping "
                                    "(the coarsest is unwrapped by the Gray code)", [128, 16], lo=4, hi=MAX_PIXELS)
    gray_bits: int = spec("int", "Gray-code bits per axis; the finest stripe is half the coarsest period",
                          6, lo=1, hi=16)
    min_modulation: float = spec("float", "least fringe modulation (amplitude / mean) a camera pixel must show to "
                                 "be decoded", 0.1, lo=0, hi=1, lo_open=True)
    fit_stride: int = spec("int", "camera pixels used by the misalignment fit: every n-th row and column", 2,
                           lo=1, hi=64)
    sim_bump_amplitude: float = spec("length", "simulation: the dome's low-order bump, peak height", "20 um",
                                     lo=0, hi=1.0)
    sim_bump_width: float = spec("length", "simulation: the bump's Gaussian width (sigma) along the dome", "25 mm",
                                 lo=0, lo_open=True, hi=1000.0)
    sim_ripple_amplitude: float = spec("length", "simulation: the sanding ripple across the print layers, "
                                       "amplitude", "2 um", lo=0, hi=1.0)
    sim_ripple_period: float = spec("length", "simulation: the ripple's period along the print's z", "12 mm",
                                    lo=0, lo_open=True, hi=1000.0)
    sim_supersample: int = spec("int", "simulation: sub-pixel rays per camera pixel side", 3, lo=1, hi=16)
    sim_blur: float = spec("float", "defocus blur, Gaussian sigma in camera pixels: the simulation's, and the lens's "
                           "that the decoding's bias correction assumes", 0.5, lo=0, hi=20)
    sim_full_well: float = spec("float", "simulation: electrons at a white screen pixel's full exposure", 10000.0,
                                lo=1, hi=1e7)
    sim_read_noise: float = spec("float", "simulation: read noise, electrons RMS", 10.0, lo=0, hi=1e5)


SECTIONS: dict[str, type] = {
    "paraboloid": ParaboloidParams,
    "layout": LayoutParams,
    "projector": ProjectorParams,
    "camera": CameraParams,
    "lens": LensParams,
    "beam_splitter": BeamSplitterParams,
    "tower": TowerParams,
    "datum": DatumParams,
    "adjusters": AdjusterParams,
    "buy": BuyParams,
    "targets": TargetParams,
    "dome": DomeParams,
    "misalignment": MisalignmentParams,
    "coating": CoatingParams,
    "dome_shell": DomeShellParams,
    "paraboloid_mount": ParaboloidMountParams,
    "beam": BeamParams,
    "base_plate": BasePlateParams,
    "sample_holder": SampleHolderParams,
    "crosses": CrossesParams,
    "templates": TemplateParams,
    "tessellation": TessellationParams,
    "raycheck": RayCheckParams,
    "tolerancing": TolerancingParams,
    "calibration": CalibrationParams,
}
#: ``optimize`` is read and validated by rigcad.optimize.spec (rigcad optimize), ignored by the other stages.
TOP_LEVEL = {"description", "optimize"}


@dataclass(frozen=True)
class Profile:
    """A validated profile. ``marks`` maps key paths to ``file:line`` for later error messages."""

    name: str
    description: str
    paraboloid: ParaboloidParams
    layout: LayoutParams
    projector: ProjectorParams
    camera: CameraParams
    lens: LensParams
    beam_splitter: BeamSplitterParams
    tower: TowerParams
    datum: DatumParams
    adjusters: AdjusterParams
    buy: BuyParams
    targets: TargetParams
    dome: DomeParams
    misalignment: MisalignmentParams
    coating: CoatingParams
    dome_shell: DomeShellParams
    paraboloid_mount: ParaboloidMountParams
    beam: BeamParams
    base_plate: BasePlateParams
    sample_holder: SampleHolderParams
    crosses: CrossesParams
    templates: TemplateParams
    tessellation: TessellationParams
    raycheck: RayCheckParams
    tolerancing: TolerancingParams
    calibration: CalibrationParams
    sources: tuple[str, ...]
    marks: dict[Key, str] = field(compare=False, repr=False)
    #: The instrument files the profile names, by the key that names each ("camera.model", "camera.lens").
    instruments: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)
    #: file:line of each key an instrument file set (the profile did not).
    instrument_marks: dict[Key, str] = field(default_factory=dict, compare=False, repr=False)

    def where(self, section: str, key: str) -> str | None:
        """file:line of a parameter, when it came from a file (the profile's, else an instrument file's)."""
        return (self.marks.get((section, key)) or self.instrument_marks.get((section, key))
                or self.marks.get((section,)))

    def set_by(self, section: str, key: str) -> str:
        """Who set ``section.key``: "profile", "instrument" (a file the profile names) or "default"."""
        if (section, key) in self.marks:
            return "profile"
        return "instrument" if (section, key) in self.instrument_marks else "default"

    def origin(self, section: str, key: str) -> str:
        """Where ``section.key`` came from, as ``rigcad profile show`` says it: the profile's file:line,
        the instrument file's file:line, or "default"."""
        return self.marks.get((section, key)) or self.instrument_marks.get((section, key)) or "default"

    def apart_from_model(self, section: str, key: str) -> str | None:
        """The file:line of ``section.key`` when a profile file set it other than the file that chose the
        section's instrument (``section.model``): a base profile's figure for its own instrument that a
        profile extending it inherits with another model (the thesis's throw ratio under another
        projector); None otherwise."""
        here, model = self.marks.get((section, key)), self.marks.get((section, "model"))
        if key == "model" or here is None or model is None:
            return None
        return None if here.rsplit(":", 1)[0] == model.rsplit(":", 1)[0] else here

    def source(self, section: str, key: str) -> str | None:
        """Where the instrument file that set ``section.key`` read it (a datasheet), if it says."""
        mark = self.instrument_marks.get((section, key))
        for inst in self.instruments.values():
            if mark is not None and inst.section == section and inst.marks.get(key) == mark:
                return inst.sources.get(key)
        return None

    @property
    def instrument_files(self) -> tuple[Path, ...]:
        """The instrument files the profile names, absolute: what a watcher of the profile watches too."""
        return tuple(Path(i.path) for i in self.instruments.values())

    def instrument(self, section: str, key: str = "model"):
        """The instrument file named by ``section.key`` (rigcad.profile.instruments.Instrument), or None."""
        return self.instruments.get(f"{section}.{key}")

    def as_dict(self) -> dict[str, dict[str, Any]]:
        """Resolved parameters in internal units, keys suffixed with their unit."""
        out: dict[str, dict[str, Any]] = {}
        for section in SECTIONS:
            obj = getattr(self, section)
            out[section] = {}
            for f in fields(obj):
                s: Spec = f.metadata["spec"]
                value = getattr(obj, f.name)
                suffix = {"length": "_mm", "lengths": "_mm", "holes": "_mm", "angle": "_rad"}.get(s.kind, "")
                if isinstance(value, float) and math.isinf(value):
                    value = "inf"
                if s.kind == "layers":
                    value = [{"name": n, "thickness_mm": t} for n, t in value]
                out[section][f.name + suffix] = list(value) if isinstance(value, tuple) else value
        return out


def _r(value: Any, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters: an error quotes what was given, not a whole document."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 4] + " ..."


#: What an unknown key may look like for an error to quote it: a setting's name, maybe mistyped.
#: Anything else (a line of a file that is not a profile, such as a password or key file given by
#: path) is never echoed: the error says where it is, not what it says.
_KEY_LIKE = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,39}")


def unknown_key(key: Any) -> str:
    """An unknown key as an error shows it: quoted when it looks like a setting's name, else not shown."""
    return repr(key) if isinstance(key, str) and _KEY_LIKE.fullmatch(key) else "(not a setting's name; not shown)"


def suggest(name: str, valid: list[str]) -> str:
    close = difflib.get_close_matches(name, valid, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def convert_value(s: Spec, value: Any, key: str, where: str | None) -> Any:
    def fail(msg: str) -> ProfileError:
        return ProfileError(f"{key}: {msg}", where=where)

    if value is None:
        raise fail(f"has no value; expected {s.doc} ({s.describe_range()})")
    if s.kind in ("str", "name", "point", "pixels"):  # text, an instrument file's name, pixels: no range after
        return _text_or_point(s, value, fail)
    if s.kind in ("length", "angle", "mass"):
        try:
            out = parse_quantity(value, s.kind)
        except UnitError as err:
            raise fail(str(err)) from err
        if math.isnan(out):
            raise fail("is NaN")
        if math.isinf(out) and not s.allow_inf:
            raise fail(f"must be finite ({s.describe_range()})")
        if s.kind == "length" and math.isfinite(out) and abs(out) > MAX_LENGTH_MM:
            raise fail(f"{_r(value)} is longer than {MAX_LENGTH_MM / 1000:g} m, the largest length rigcad accepts "
                       "(a bench-top rig; check the unit)")
    elif s.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise fail(f"expected a whole number, got {_r(value)} ({s.describe_range()})")
        out = value
    elif s.kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise fail(f"expected a plain number, got {_r(value)} ({s.describe_range()})")
        try:
            out = float(value)
        except OverflowError:
            out = math.inf
        if not math.isfinite(out):
            raise fail(f"must be finite, got {_r(value)} ({s.describe_range()})")
    elif s.kind == "fraction":
        out = _fraction(s, value, fail)
    elif s.kind == "choice":
        if value not in s.choices:
            raise fail(f"{_r(value)} is not valid; {s.describe_range()}{suggest(str(value), list(s.choices))}")
        return value
    elif s.kind == "layers":
        if not isinstance(value, list) or not value:
            raise fail("expected a list of layers, bottom (on the print) to top (the mirror), each "
                       "{name: ..., thickness: '1.5 mil'}")
        layers = []
        for i, layer in enumerate(value):
            if not isinstance(layer, dict) or set(layer) != {"name", "thickness"} or not isinstance(layer["name"], str):
                raise fail(f"layer {i + 1}: expected {{name: text, thickness: length}}, got {_r(layer)}")
            try:
                t = parse_quantity(layer["thickness"], "length")
            except UnitError as err:
                raise fail(f"layer {i + 1} ({layer['name']}): {err}") from err
            if not (math.isfinite(t) and 0 <= t <= MAX_COATING_LAYER_MM):
                raise fail(f"layer {i + 1} ({layer['name']}): thickness must be 0..{MAX_COATING_LAYER_MM:g} mm (a paint "
                           f"film), got {_r(layer['thickness'])}")
            layers.append((layer["name"], t))
        names = [n for n, _ in layers]
        if len(set(names)) != len(names):
            raise fail(f"layer names must be distinct, got {names}")
        return tuple(layers)
    elif s.kind in ("lengths", "ints"):
        one = Spec("length" if s.kind == "lengths" else "int", s.doc, lo=s.lo, hi=s.hi, lo_open=s.lo_open,
                   hi_open=s.hi_open)
        if not isinstance(value, list) or not value:
            raise fail(f"expected a list of {'lengths' if s.kind == 'lengths' else 'whole numbers'} "
                       f"({one.describe_range()}), got {_r(value)}")
        return tuple(convert_value(one, v, f"{key}[{i}]", where) for i, v in enumerate(value))
    elif s.kind == "holes":
        return _holes(s, value, key, where, fail)
    else:  # pragma: no cover - a programming error in a Spec
        raise AssertionError(s.kind)
    too_low = s.lo is not None and (out < s.lo or (s.lo_open and out == s.lo))
    too_high = s.hi is not None and (out > s.hi or (s.hi_open and out == s.hi))
    if too_low or too_high:
        raise fail(f"{_r(value)} is out of range; valid: {s.describe_range()}")
    return out


def _fraction(s: Spec, value: Any, fail) -> float:
    """``value`` read as a fraction (kind ``fraction``): a plain number, or a percentage as datasheets
    write it ("100 %")."""
    text = value.strip() if isinstance(value, str) else None
    try:
        out = (float(text[:-1]) / 100 if text and text.endswith("%") else None if text is not None
               else float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None)
    except (ValueError, OverflowError):
        out = None
    if out is None or not math.isfinite(out):
        raise fail(f"expected a fraction such as 0.5 or 50 %, got {_r(value)} ({s.describe_range()})")
    return out


def _holes(s: Spec, value: Any, key: str, where: str | None, fail) -> tuple[tuple[float, float], ...]:
    """``value`` read as a list of ``[along, across]`` pairs of lengths (kind ``holes``)."""
    pair = Spec("length", s.doc)
    if not isinstance(value, list) or not 1 <= len(value) <= MAX_HOLES or not all(
            isinstance(v, list) and len(v) == 2 for v in value):
        raise fail(f"expected {s.describe_range()} (e.g. [[40 mm, -112 mm], [40 mm, 112 mm], [215 mm, 0 mm]]), "
                   f"got {_r(value)}")
    return tuple(tuple(convert_value(pair, v, f"{key}[{i}][{j}]", where) for j, v in enumerate(hole))
                 for i, hole in enumerate(value))


def _text_or_point(s: Spec, value: Any, fail) -> Any:
    """``value`` read as text (kind ``str``), an instrument file's name (``name``), an ``[x, y]``
    pixel point (``point``) or a ``[width, height]`` in whole pixels (``pixels``); ``fail(message)``
    makes the error naming the key."""
    if s.kind == "str":
        if not isinstance(value, str) or not value:
            raise fail(f"expected text, got {_r(value)}")
        return value
    if s.kind == "name":
        if not isinstance(value, str) or not instrument_files.INSTRUMENT_NAME.fullmatch(value):
            raise fail(f"{_r(value)} is not an instrument's name; {s.describe_range()} (letters, digits, '_', '.', "
                       "'+', '-')")
        return value
    if s.kind == "pixels":
        ok = (isinstance(value, list) and len(value) == 2
              and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= MAX_PIXELS for v in value))
        if not ok:
            raise fail(f"expected [width, height] in whole pixels, each 1..{MAX_PIXELS}, got {_r(value)}")
        return (value[0], value[1])
    ok = (isinstance(value, list) and len(value) == 2
          and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                  and 0 <= v <= MAX_PIXELS for v in value))
    if not ok:
        raise fail(f"expected [x, y] in pixels, each 0..{MAX_PIXELS}, got {_r(value)}")
    return (float(value[0]), float(value[1]))


def bound(section: str, key: str) -> float | None:
    """The upper bound of profile key ``section.key`` (internal units), or None."""
    return next(f.metadata["spec"] for f in fields(SECTIONS[section]) if f.name == key).hi


def check_override(section: str, key: str, value: Any, flag: str) -> Any:
    """A command-line value that replaces profile key ``section.key`` (``--rays`` for raycheck.rays),
    checked against that key's Spec: the same range as in a profile, the message naming ``flag``."""
    s = next(f.metadata["spec"] for f in fields(SECTIONS[section]) if f.name == key)
    try:
        return convert_value(s, value, f"{flag} (as {section}.{key})", None)
    except ProfileError as err:
        raise ProfileError(err.message, param=flag) from None


def read_section(raw: RawProfile, name: str, cls: type) -> Any:
    """Validate section ``name`` of ``raw`` into the frozen dataclass ``cls`` (whose fields carry
    Specs): unknown keys, missing values, bad units and out-of-range values are refused with
    file:line. Also used for sections of other YAML files (printers)."""
    data = raw.data.get(name, {})
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ProfileError(f"section {name!r} must be a mapping of keys, got {_r(data)}", where=raw.where((name,)))
    valid = [f.name for f in fields(cls)]
    for key in data:
        if key not in valid:
            raise ProfileError(
                f"unknown key {name}.{key if _KEY_LIKE.fullmatch(str(key)) else unknown_key(key)}"
                f"{suggest(str(key), valid)}; valid keys in {name}: {', '.join(valid)}",
                where=raw.where((name, key)))
    values = {}
    for f in fields(cls):
        s: Spec = f.metadata["spec"]
        if f.name in data:
            values[f.name] = convert_value(s, data[f.name], f"{name}.{f.name}", raw.where((name, f.name)))
        elif s.default is REQUIRED:
            raise ProfileError(f"missing required key {name}.{f.name}: {s.doc} ({s.describe_range()})",
                               where=raw.where((name,)) or (str(raw.sources[0]) if raw.sources else None))
        elif s.default is None:
            values[f.name] = None
        else:
            values[f.name] = convert_value(s, s.default, f"{name}.{f.name} (default)", None)
    return cls(**values)


def _with_instruments(raw: RawProfile, sections: dict[str, Any]) -> tuple[dict[str, Any], dict[Key, str]]:
    """The instrument files the profile names (``projector.model``, ``camera.model``, ``camera.lens``,
    ``beam_splitter.model``), read and checked (rigcad.profile.instruments), their figures converted
    with each key's own Spec into ``sections`` where they win (:func:`_instrument_wins`). Returns the
    files by naming key and the file:line of each key a file set."""
    from dataclasses import replace

    from rigcad.profile.paths import INSTRUMENTS_SUBDIR

    near = raw.files[0].parent / INSTRUMENTS_SUBDIR if raw.files else None
    chosen: dict[str, Any] = {}
    for kind, (section, key) in instrument_files.NAMED_BY.items():
        name = getattr(sections[section], key)
        if name is None:
            continue
        where = raw.marks.get((section, key))
        chosen[f"{section}.{key}"] = instrument_files.read(instrument_files.find(name, kind, where, near), kind, where)
    winners: dict[Key, tuple[tuple, Any]] = {}  # each key a file sets -> (its rank, the file)
    for naming, inst in chosen.items():
        rank = _instrument_rank(raw, naming, inst.kind)
        for key in inst.figures:
            k = (inst.section, key)
            if _instrument_wins(raw, k, rank) and (k not in winners or rank < winners[k][0]):
                winners[k] = (rank, inst)
    marks: dict[Key, str] = {}
    for section in dict.fromkeys(k[0] for k in winners):
        specs = {f.name: f.metadata["spec"] for f in fields(SECTIONS[section])}
        updates = {}
        for (sec, key), (_, inst) in winners.items():
            if sec == section:
                updates[key] = convert_value(specs[key], inst.figures[key], f"{section}.{key}", inst.marks[key])
                marks[(section, key)] = inst.marks[key]
        sections[section] = replace(sections[section], **updates)
    return chosen, marks


def _instrument_rank(raw: RawProfile, naming: str, kind: str) -> tuple[float, int]:
    """How specific an instrument file is, smaller first: the depth in the ``extends:`` chain of the
    file that names it (RawProfile.depth; a model no file names, the schema's default, after every
    file), then a lens file before the camera's (the lens keys describe the lens mounted)."""
    depth = raw.depth(tuple(naming.split(".")))
    return (math.inf if depth is None else depth, 0 if kind == "lens" else 1)


def _instrument_wins(raw: RawProfile, key: Key, rank: tuple[float, int]) -> bool:
    """True when an instrument file of ``rank`` sets ``key`` over the profile. Most specific first:
    what a profile file states > the instrument files it names > what it extends > the schema's
    defaults. So a key the profile itself sets is the lab's measurement and wins over any file, and
    an instrument the profile names wins over the figures it inherits from the profile it extends
    (a base profile's resolution is its own projector's, not the one named here)."""
    depth = raw.depth(key)
    return depth is None or depth > rank[0]


def _profile_marks(marks: dict[Key, str], instrument_marks: dict[Key, str]) -> dict[Key, str]:
    """The profile files' marks but for the keys an instrument file set over them (and their items):
    a value's mark is where the value in force came from."""
    return {k: v for k, v in marks.items() if not any(k[:len(i)] == i for i in instrument_marks)}


def _check_camera(cam: CameraParams, where) -> None:
    """The camera keys that depend on each other: a focal length in mm needs the pixel pitch; the
    principal point lies on the sensor."""
    if cam.focal_length is not None and cam.pixel_pitch is None:
        raise ProfileError(f"camera.focal_length {cam.focal_length:g} mm needs camera.pixel_pitch (the sensor's pixel "
                           "size, e.g. 3.45 um) to place the lens in pixels: set it, or name a camera file that gives "
                           "it", where=where("focal_length"))
    if cam.principal_point is not None:
        (x, y), (w, h) = cam.principal_point, cam.resolution
        if not (0 < x < w and 0 < y < h):
            raise ProfileError(f"camera.principal_point [{x:g}, {y:g}] px is not on the {w} x {h} px sensor "
                               f"(camera.resolution): need 0 < x < {w} and 0 < y < {h}; the centre is "
                               f"[{w / 2:g}, {h / 2:g}]", where=where("principal_point"))


#: Addressable resolutions that projectors mostly make by shifting a smaller array within a frame
#: (pixel shifting), with the native arrays behind them: TI's 4K UHD DMDs (DLP471TP, 0.47 inch: 1920 x
#: 1080 mirrors shifted four ways; DLP660TE, 0.66 inch: 2716 x 1528, two ways) and e-shift panels.
PIXEL_SHIFTED = {(3840, 2160): "1920 x 1080 mirrors on a 0.47-inch DMD shifted four ways, or 2716 x 1528 on a "
                               "0.66-inch one shifted two ways"}


def _check_projector(pj: ProjectorParams, where) -> None:
    """The projector's resolution is its native array's: the distinct directions a pixel-shifting
    projector lights are its mirrors' (or panel pixels'), however many it addresses."""
    (w, h), native = pj.resolution, pj.native_resolution
    if native is not None and tuple(native) != (w, h):
        raise ProfileError(f"projector.resolution {w} x {h} px is not the {native[0]} x {native[1]} px array that "
                           "projector.native_resolution gives: a pixel-shifting projector lights the sample from as "
                           "many directions as its mirrors (or panel pixels), not its addressed pixels; enter "
                           f"projector.resolution: [{native[0]}, {native[1]}] with the datasheet's throw ratio",
                           where=where("resolution"))
    if native is None and (w, h) in PIXEL_SHIFTED:
        raise ProfileError(f"projector.resolution {w} x {h} px is a pixel-shifted figure for most projectors that "
                           f"state it ({PIXEL_SHIFTED[w, h]}): enter the native array the projector's or chip's "
                           "datasheet gives, e.g. projector.resolution: [1920, 1080] for a 0.47-inch DMD; a projector "
                           f"whose own panel has {w} x {h} pixels says so with projector.native_resolution: [{w}, {h}]",
                           where=where("resolution"))


def _check_inherited_figures(raw: RawProfile, sections: dict, instrument_marks: dict[Key, str]) -> None:
    """A projector's or camera's figure (its throw ratio, lens offset, pixel pitch, sizes) that a profile
    inherits from a file which set it for another model is refused: the figure describes that file's
    instrument, not the one this profile names. The profile itself may set it (the lab's measurement),
    and a figure the named instrument file gives wins over the inherited one anyway."""
    if not raw.layers:
        return
    for section in ("projector", "camera"):
        model_now = getattr(sections[section], "model")
        default = next(f.metadata["spec"].default for f in fields(SECTIONS[section]) if f.name == "model")
        for key in instrument_files.FIGURE_KEYS[section]:
            depth = raw.depth((section, key))
            if not depth or (section, key) in instrument_marks:
                continue
            model_then = next((layer[section]["model"] for layer in raw.layers[depth:]
                               if isinstance(layer.get(section), dict) and "model" in layer[section]), default)
            if str(model_then) == str(model_now):
                continue
            model_mark = raw.marks.get((section, "model"))
            raise ProfileError(
                f"{section}.{key} {_r(raw.data[section][key], 30)} is inherited from {raw.marks[(section, key)]}, "
                f"where it was set with {section}.model {_r(str(model_then), 40)}, but this profile's {section} is "
                f"{_r(str(model_now), 40)}" + (f" (set in {model_mark})" if model_mark else "")
                + f": set {section}.{key} in this profile (your {section}'s own figure, from its datasheet or "
                f"measured), or name a {section} file that gives it",
                where=str(raw.sources[0]) if raw.sources else None)


def validate(raw: RawProfile) -> Profile:
    """Check every key of ``raw`` and return the frozen :class:`Profile`."""
    valid_top = sorted(set(SECTIONS) | TOP_LEVEL)
    for key in raw.data:
        if key not in valid_top:
            raise ProfileError(f"unknown section {unknown_key(key)}{suggest(str(key), valid_top)}; valid: "
                               f"{', '.join(valid_top)}",
                               where=raw.where((key,)))
    sections = {name: read_section(raw, name, cls) for name, cls in SECTIONS.items()}
    chosen, instrument_marks = _with_instruments(raw, sections)
    marks = _profile_marks(raw.marks, instrument_marks)
    _check_inherited_figures(raw, sections, instrument_marks)
    _check_camera(sections["camera"], lambda key: marks.get(("camera", key)) or instrument_marks.get(("camera", key))
                  or raw.where(("camera",)))
    _check_projector(sections["projector"], lambda key: marks.get(("projector", key))
                     or instrument_marks.get(("projector", key)) or raw.where(("projector",)))
    par: ParaboloidParams = sections["paraboloid"]
    pair_a = (par.vertical_extent, par.tangent_angle)
    pair_b = (par.focal_length, par.rim_radius)
    given_a = [v is not None for v in pair_a]
    given_b = [v is not None for v in pair_b]
    if not ((all(given_a) and not any(given_b)) or (all(given_b) and not any(given_a))):
        raise ProfileError(
            "paraboloid: give either vertical_extent and tangent_angle (thesis Table 3.1), "
            "or focal_length and rim_radius, and not a mix",
            where=raw.where(("paraboloid",)) or (str(raw.sources[0]) if raw.sources else None))
    tgt: TargetParams = sections["targets"]
    if tgt.theta_min >= tgt.theta_max:
        raise ProfileError(
            f"targets.theta_min ({tgt.theta_min / DEG:g} deg) must be below targets.theta_max "
            f"({tgt.theta_max / DEG:g} deg)", where=raw.where(("targets", "theta_min")))
    layer_names = [n for n, _ in sections["coating"].layers]
    gauged = sections["templates"].gauged_layer
    if gauged != "design" and gauged not in layer_names:
        raise ProfileError(f"templates.gauged_layer {_r(gauged)} is not a coating layer; valid: design, "
                           + ", ".join(layer_names), where=raw.where(("templates", "gauged_layer")))
    tower: TowerParams = sections["tower"]
    tol: TolerancingParams = sections["tolerancing"]
    for key, need in (("travel_along", ("camera_height", "projector_height")),
                      ("travel_across", ("camera_offset", "projector_offset"))):
        worst = max(need, key=lambda k: getattr(tol, k))
        if getattr(tower, key) < getattr(tol, worst):
            raise ProfileError(
                f"tower.{key} ({getattr(tower, key):g} mm) does not cover tolerancing.{worst} "
                f"({getattr(tol, worst):g} mm): the adjustment must reach every placement the tolerances allow; "
                f"raise tower.{key} to at least {getattr(tol, worst):g} mm", where=raw.where(("tower", key)))
    _check_calibration(sections["calibration"], raw)
    description = raw.data.get("description", "")
    if not isinstance(description, str):
        raise ProfileError("description must be text", where=raw.where(("description",)))
    return Profile(name=raw.name, description=description, sources=tuple(str(p) for p in raw.sources),
                   marks=marks, instruments=chosen, instrument_marks=instrument_marks, **sections)


def _check_calibration(cal: CalibrationParams, raw: RawProfile) -> None:
    """The calibration keys that depend on each other: two or more distinct spacers, periods from
    coarse to fine, and Gray codes that number every coarsest half-period across the screen."""
    heights = sorted(cal.spacer_heights)
    if len(heights) < 2 or min(b - a for a, b in zip(heights, heights[1:])) <= 0:
        raise ProfileError(f"calibration.spacer_heights {[f'{h:g} mm' for h in cal.spacer_heights]}: a ray needs "
                           "two or more distinct heights", where=raw.where(("calibration", "spacer_heights")))
    if any(b >= a for a, b in zip(cal.periods, cal.periods[1:])):
        raise ProfileError(f"calibration.periods {list(cal.periods)}: list them coarse to fine, each shorter than "
                           "the one before", where=raw.where(("calibration", "periods")))
    stripes = 2 ** cal.gray_bits
    need = max(cal.screen_resolution)
    if stripes * (cal.periods[0] / 2) < need:
        bits = math.ceil(math.log2(need / (cal.periods[0] / 2)))
        raise ProfileError(f"calibration.gray_bits {cal.gray_bits}: {stripes} stripes of {cal.periods[0] / 2:g} px "
                           f"(half the coarsest period) do not span the screen's {need} px; need >= {bits}",
                           where=raw.where(("calibration", "gray_bits")))


def load_profile(spec_or_path: Any) -> Profile:
    """Read, merge and validate a profile by name or path."""
    from rigcad.profile.loader import load_raw

    return validate(load_raw(spec_or_path))
