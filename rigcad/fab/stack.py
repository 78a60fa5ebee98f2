"""The tolerance stack of the printed rig: how far each optical element can sit from its design
placement through every printed link, seam, pin, clearance and joint, on a given printer's
process (kernel-free; mm and rad).

For each optical element (the paraboloid, the dome, the projector's virtual COP, the splitter and
the camera) the chain from the sample point O (the base plate's bore) to the element is a tuple of
:class:`Link` values, each with its worst-case lateral (x-y) and vertical (z) error (mm) and tilt
(rad), and how many times it occurs (``count``: the seams of a split part). Per axis the stack's
worst case is the sum, its likely value the root sum of squares (independent links), against the
profile's ``tolerancing`` figure for that element and axis:

* within the tolerance: **held** (the element's adjusters, if any, only refine);
* beyond it, an adjuster on that axis whose range (each way) covers the worst case and whose
  resolution is at most a quarter of the tolerance (:data:`RESOLUTION_SHARE`): **adjusted**;
* otherwise **refused**: :func:`refuse` raises a FabricationError naming the element, the axis,
  the links that dominate and the ``buy:`` option (a bought part or a purchase) that removes each.

Adjusters and locating features are inputs (:class:`AdjusterSpec`, :class:`Locator`), so a new one
(a paraboloid adjuster, a dome register, a kinematic splitter seat) enters as data:
:func:`default_adjusters` reads the tower's adjusters (rigcad.parts.adjusters); a :class:`Locator`
replaces the links it makes irrelevant by one of its own.

The process figures are the printer's (rigcad.fab.printers ``process_errors``,
rigcad.parts.process): a printed length ``position + scale * span``; a height half a layer step and
the scale; a hole shrinks by its diameter and its axis as printed, and a hole that shrinks below
what goes through it is drilled to its drawn size (its float is then the drawn clearance). Seams:
the seams a chain crosses in a split part, each alignment pins in printed holes: the pin's float
in its two holes and each hole's position error, along the cut (the pieces are glued face to
face). The seams are given (:func:`seams_from_pieces` of a fab run's split plans: a conservative
n - 1 for n pieces) or estimated from the part's extent against the build volume
(:func:`estimate_seams`). The dome's sectors are each bolted to the base plate: their seams make
steps in the mirror (a finishing matter), not placement errors.

A feature of revolution about the bore (the dome's bolt circle, the two beam slots) is centred to
the position error alone: the scale moves its points out alike, not its centre.

Frame: O at the origin, +z up along the optical axis. Tilts of the splitter's plate count twice
(a plate turned by delta turns the reflected axis by 2 delta); a tilt of the whole tower once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from rigcad.errors import FabricationError, GeometryError
from rigcad.fab import seat_hold
from rigcad.fab.printers import Printer
from rigcad.fab.split import PIN_SPACING
from rigcad.parts import adjusters as A
from rigcad.parts.datum import DOWEL_FIT, datum_chain
from rigcad.parts.dome import flange_joint
from rigcad.parts.process import ProcessErrors
from rigcad.parts.tower import (LAPPED_FLATNESS, PLATE_RETAINER, _projector_feet, _shelf_extent, plate_float_tilt,
                                 plate_play, seat_pocket_fits, splitter_seat)
from rigcad.standards import THREADS

#: The optical elements, in the order the tables list them.
ELEMENTS = ("paraboloid", "dome", "cop", "splitter", "camera")
#: What each element is, for the tables.
ELEMENT_NAMES = {"paraboloid": "paraboloid", "dome": "dome", "cop": "projector's (virtual) COP",
                 "splitter": "splitter", "camera": "camera"}
#: The axes of a stack: "tilt" is an element's tilt of its axis; the paraboloid's is along its beam
#: (in the x-z plane, which its seats' packs set one against the other) and it has a second, "roll",
#: about the beam's axis (x: in the y-z plane, which the roll bars' packs under the beam set).
AXES = ("lateral", "vertical", "tilt")
#: Each element's axes, in the tables' order.
ELEMENT_AXES = {e: AXES for e in ("dome", "cop", "splitter", "camera")} | {"paraboloid": (*AXES, "roll")}
#: The angular axes (rad inside, deg in tables).
ANGLES = ("tilt", "roll")
#: The tolerancing key each element's axes are held to (``tolerancing.<key>``): the splitter's
#: placement moves the virtual COP, so it serves the projector's.
TOLERANCE_KEYS = {
    "paraboloid": ("paraboloid_offset", "paraboloid_height", "paraboloid_tilt", "paraboloid_tilt"),
    "dome": ("dome_offset", "dome_height", "dome_tilt"),
    "cop": ("projector_offset", "projector_height", "projector_tilt"),
    "splitter": ("projector_offset", "projector_height", "projector_tilt"),
    "camera": ("camera_offset", "camera_height", "camera_tilt"),
}
#: An adjuster serves a tolerance when its resolution is at most this share of it: a setting must
#: land well inside the tolerance, not merely within one step of its edge.
RESOLUTION_SHARE = 0.25
#: The split parts whose seams may lie on an element's chain (the beam, the paraboloid and its clamp
#: print whole on every shipped printer).
CHAIN_PARTS = ("base_plate", "dome", "tower_column", "tower_shelf", "splitter_holder")
#: How far a kinematic seat of hard balls on a cone, a vee and a flat returns to its place after a
#: lift-off (mm): "ordinary quality kinematic hardware" repeats "in the micrometer range" (Bal-tec,
#: The Kinematic Encyclopedia, precisionballs.com); 5 um taken for balls pressed into printed pockets
#: (assumed).
KINEMATIC_REPEAT = 0.005
#: The links a locating feature replaces, by what it locates: the paraboloid's (its shim stops: the
#: beam pressed onto its seats, the clamp onto the beam's pin, replace the beam's and the clamp's
#: floats), the dome's (a register
#: replaces the bolts' float) and the splitter seat's (a kinematic seat, on the COP's, the splitter's
#: and the camera's chains). A Locator's ``replaces`` names these.
PARABOLOID_FLOATS = ("beam across its slots", "beam along its slots", "clamp on the beam", "clamp along the beam")
DOME_FLOATS = ("dome's bolts in their holes",)
SEAT_FLOATS = ("splitter seat",)
#: The splitter plate's play in its grooves (rigcad.parts.tower.plate_play): a float (kind "float": it moves
#: after any setting, so no adjuster takes it out), on the splitter's and the COP's chains until a retainer
#: holds the plate on its datum flank (rigcad.parts.tower.PLATE_RETAINER: :func:`declared_locators`).
PLATE_FLOATS = ("splitter plate in its grooves",)
#: Dominating links named in a refusal: the fewest largest links making this share of the stack, at most MAX_NAMED.
DOMINANT_SHARE = 0.5
MAX_NAMED = 3


def _roll_buy(profile) -> str:
    """What would remove the paraboloid's printed roll links (each a printed face's error across the beam's
    narrow width or the roll bars' lever)."""
    return "a bought tip-tilt mount under the stem (two fine screws, the paraboloid's roll and its tilt along the beam)"


@dataclass(frozen=True)
class Link:
    """One link of a chain. ``lateral``, ``vertical``: worst-case error each way (mm; ``math.inf``
    when nothing holds the element along that axis); ``tilt``: worst-case tilt (rad); ``count``:
    how many such links the chain holds (each independent); ``kind``: printed, seam, joint,
    clearance, free, bought or float (a play that moves after any setting: no adjuster takes it out, so
    the floats on an axis alone must be within its tolerance); ``buy``: the purchase (or ``buy:`` key) that would remove it; ``roll``:
    worst-case tilt about the paraboloid's beam (rad; its ``tilt`` is then along the beam)."""

    name: str
    kind: str
    source: str
    lateral: float = 0.0
    vertical: float = 0.0
    tilt: float = 0.0
    count: int = 1
    buy: str = ""
    roll: float = 0.0

    def worst(self, axis: str) -> float:
        """This link's share of the worst case on ``axis`` (mm or rad): count times its error."""
        v = getattr(self, axis)
        return 0.0 if v == 0 else self.count * v

    def square(self, axis: str) -> float:
        """Its share of the sum of squares (count independent links)."""
        return self.count * getattr(self, axis) ** 2

    def describe(self) -> dict:
        return {"name": self.name, "kind": self.kind, "source": self.source, "count": self.count,
                "lateral_mm": _finite(self.lateral), "vertical_mm": _finite(self.vertical),
                "tilt_deg": _finite(math.degrees(self.tilt)), "roll_deg": _finite(math.degrees(self.roll)),
                "buy": self.buy}


@dataclass(frozen=True)
class AdjusterSpec:
    """An adjuster as the stack reads it: the element it moves, the axis ("lateral": x and y;
    "x" or "y" alone; "vertical"; "tilt"; "roll": about the paraboloid's beam), its range each way and its resolution (mm, or rad for
    a tilt; a tilt of the splitter's reflected axis for the splitter and the COP)."""

    name: str
    element: str
    axis: str
    range: float
    resolution: float
    how: str = ""
    range_key: str = ""  #: the profile key whose value (mm) is this range each way ("": none sets it)


@dataclass(frozen=True)
class Locator:
    """A locating feature (a register, a kinematic seat, a stop): on ``element``'s chain it
    replaces the links named in ``replaces`` by ``link``."""

    name: str
    element: str
    replaces: tuple[str, ...]
    link: Link


@dataclass(frozen=True)
class AxisVerdict:
    """One element's stack on one axis: ``worst`` and ``rss`` (mm, or rad for ``tilt``) against
    ``tolerance`` (``tolerancing.<tolerance_key>``, same unit); ``status``: held, adjusted or
    refused; ``adjuster``: the adjuster that serves it (None: none); ``dominating``: the links that
    dominate it (names); ``buy``: what would remove them; ``reason``: why it is refused (or "");
    ``cure``: the profile settings that would pass it as it stands (``key >= value unit``)."""

    element: str
    axis: str
    tolerance_key: str
    tolerance: float
    worst: float
    rss: float
    status: str
    adjuster: AdjusterSpec | None
    dominating: tuple[str, ...]
    buy: tuple[str, ...]
    reason: str = ""
    cure: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.status != "refused"

    def describe(self) -> dict:
        unit = "deg" if self.axis in ANGLES else "mm"
        f = math.degrees if self.axis in ANGLES else float
        adj = self.adjuster
        return {"element": self.element, "axis": self.axis, "tolerance_key": f"tolerancing.{self.tolerance_key}",
                f"tolerance_{unit}": f(self.tolerance), f"worst_{unit}": _finite(f(self.worst)),
                f"rss_{unit}": _finite(f(self.rss)), "status": self.status,
                "adjuster": None if adj is None else {
                    "name": adj.name, f"range_each_way_{unit}": _finite(f(adj.range)),
                    f"resolution_{unit}": f(adj.resolution)},
                "dominating": list(self.dominating), "buy": list(self.buy), "reason": self.reason,
                "cure": list(self.cure)}


@dataclass(frozen=True)
class ElementStack:
    """One optical element: its chain's links and its three axes' verdicts."""

    element: str
    links: tuple[Link, ...]
    axes: tuple[AxisVerdict, ...]


@dataclass(frozen=True)
class StackReport:
    """The stack of every element on one printer: its process figures, the seams per chain part
    (and whether they were estimated) and the elements."""

    printer: str
    process: ProcessErrors
    seams: tuple[tuple[str, int], ...]
    seams_estimated: bool
    elements: tuple[ElementStack, ...]
    locators: tuple[str, ...] = field(default=())

    @property
    def refused(self) -> tuple[AxisVerdict, ...]:
        return tuple(v for e in self.elements for v in e.axes if not v.ok)

    @property
    def ok(self) -> bool:
        return not self.refused

    def element(self, name: str) -> ElementStack:
        return next(e for e in self.elements if e.element == name)


def _finite(v: float) -> float | None:
    """A figure for JSON: None for an unbounded one (nothing holds the element)."""
    return None if math.isinf(v) else float(v)


# ----------------------------------------------------------------------------------------- seams

def _extents(profile, layout) -> dict[str, tuple[float, float, float]]:
    """Each chain part's (CHAIN_PARTS) bounding box (mm), from the layout (no kernel)."""
    t, tw = layout.tower, profile.tower
    x0, x1, y0, y1 = _shelf_extent(t, profile)
    foot = 2 * t.column_foot_half
    r = layout.plate_r
    return {
        "base_plate": (t.column_x + t.column_foot_half + r, 2 * r, profile.base_plate.thickness),
        "dome": (2 * layout.flange_outer_r, 2 * layout.flange_outer_r, layout.dome_top_z),
        "tower_column": (foot, foot, t.shelf_top_z - t.shelf_thickness - t.column_base_z),
        "tower_shelf": (x1 - x0, y1 - y0, t.shelf_thickness),
        "splitter_holder": (t.holder_x[1] - t.holder_x[0] + 2 * tw.wall, 2 * t.wall_y[1],
                            t.holder_top_z - t.shelf_top_z),
    }


def estimate_seams(profile, layout, printer: Printer) -> dict[str, int]:
    """Seams a chain crosses in each chain part when no fab run's split plans are at hand: the part
    cut as a grid of its bounding box, the largest side against the printer's largest usable side
    (ceil of each ratio), a straight chain crossing each cut plane once: the cuts summed over the
    three axes. It ignores diagonal placement, so it may count more cuts than the split planner
    makes. The dome's sectors are each bolted to the base plate, so only its cuts across its height
    (bands: the upper piece located through the seam) lie on a chain. A bought part has none."""
    usable = sorted(printer.usable, reverse=True)
    out = {}
    for name, ext in _extents(profile, layout).items():
        if (name == "tower_column" and profile.buy.column != "print") or (
                name == "tower_shelf" and profile.buy.shelf != "print"):
            out[name] = 0
        elif name == "dome":
            out[name] = max(0, math.ceil(ext[2] / usable[0] - 1e-9) - 1)
        else:
            out[name] = sum(math.ceil(e / u - 1e-9) - 1 for e, u in zip(sorted(ext, reverse=True), usable))
    return out


def seams_from_pieces(pieces: dict[str, int]) -> dict[str, int]:
    """Seams on a chain from a fab run's pieces per part, conservatively: a part of n pieces, n - 1
    (a chain crosses each seam at most once); the dome's sectors, each bolted down, none (a fab
    run's band cuts: pass the dome's seams yourself)."""
    return {k: (0 if k == "dome" else max(0, n - 1)) for k, n in pieces.items()}


def seams_from_fab(parts: dict[str, dict]) -> dict[str, int]:
    """Seams on a chain from a fab run's record of its parts (fab.json's ``parts``): a part's
    ``datum_seams`` (rigcad.fab.split.datum_seams: the seams between two of its datum features), the
    most any two of them cross; a split part that declares no datum features, its pieces less one
    (:func:`seams_from_pieces`); a whole part, none; the dome, its band cuts (as :func:`estimate_seams`
    counts them: its sectors are each screwed to the plate and glued on a gauge, rigcad.fab.seams)."""
    out = {}
    for name, entry in parts.items():
        if name == "dome":  # its sectors are each screwed down and glued on the gauge: its band cuts only
            out[name] = max(0, int((entry.get("split") or {}).get("bands", 1)) - 1)
        elif entry.get("datum_seams"):
            out[name] = max(int(s.get("count", 0)) for s in entry["datum_seams"])
        else:
            pieces = int((entry.get("split") or {}).get("pieces", 1))
            out[name] = seams_from_pieces({name: pieces})[name]
    return out


# ----------------------------------------------------------------------------------------- links

def _drilled(hole: float, inner: float, process: ProcessErrors, axis: str) -> tuple[float, str]:
    """The float (mm, diametral) of ``inner`` mm in a printed ``hole`` mm: the shrunk hole's, or,
    when it shrinks below ``inner``, the drawn hole's (drilled to size)."""
    printed = hole - process.shrink(hole, axis)
    if printed >= inner:
        return printed - inner, f"printed {printed:.2f} mm"
    return hole - inner, f"prints {printed:.2f} mm, drilled to {hole:g} mm"


def seam_link(part: str, seams: int, printer: Printer, process: ProcessErrors, dowels: bool = False) -> Link | None:
    """The ``seams`` seams of ``part`` on a chain (None for none): each lets the pieces shift along
    the cut by the pin's float in its two holes and each hole's position error. The pieces are
    glued face to face (flat parts on a flat table), so a seam adds no step across the cut and no
    tilt (a part cut across its height adds its glue faces' lean: :func:`_column_glue`). With
    ``dowels``, the ``buy`` option: ISO 8734 m6 steel dowels pressed N7 in one piece, sliding F7 in the
    other (the shop step), whose fit (DOWEL_FIT) replaces the pin's float; the holes' printed positions stay."""
    if seams <= 0:
        return None
    buy = SEAM_BUY.get(part, f"a printer whose bed takes the {part.replace('_', ' ')} whole (rigcad fab --printer)")
    if dowels:
        e = DOWEL_FIT + 2 * process.position
        return Link(f"{part.replace('_', ' ')} seams", "seam",
                    f"{seams} seam(s): ISO 8734 m6 dowels pressed N7, sliding F7 ({DOWEL_FIT:g} mm), each hole "
                    f"+-{process.position:.2f} mm", e, 0.0, 0.0, seams, buy)
    pin = printer.alignment_pin
    hole = pin.diameter + pin.clearance
    play, how = _drilled(hole, pin.diameter, process, "unknown")
    e = play + 2 * process.position
    return Link(f"{part.replace('_', ' ')} seams", "seam",
                f"{seams} seam(s): {pin.diameter:g} mm pins in {hole:g} mm holes ({how}), each hole "
                f"+-{process.position:.2f} mm", e, 0.0, 0.0, seams, buy)


def _paraboloid_links(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    """O to the paraboloid's vertex: the base plate, the dome on it, the beam in the dome's slots,
    the clamp on the beam, the stem."""
    from rigcad.parts.dome import ROLL_BAR, roll_lever

    pm, shell = profile.paraboloid_mount, profile.dome_shell
    z0, z1 = layout.beam_z
    lever = roll_lever()
    vertex_z = layout.tower.cop[2] - profile.layout.cop_to_vertex
    clear = 2 * shell.slot_clearance
    slot_play, slot_how = _drilled(profile.beam.width + clear, profile.beam.width, process, "unknown")
    return (*_dome_seat(profile, layout, process, seams),
            Link("dome: flange to the beam's slots", "printed",
                 f"printed: the beam's seats (or slots) {z0:.0f} mm above the flange, {2 * layout.slot_r:.0f} mm apart, "
                 "centred on the axis (the scale moves both alike), their floors each within half a layer",
                 process.position, process.height_error(z0), process.layer_step / (2 * layout.slot_r)),
            Link("seats' floors under the roll bars' ends", "printed",
                 f"printed: each floor flat to {process.position:.2f} mm across the {lever:g} mm between the roll "
                 "bar's foil packs", roll=process.position / lever, buy=_roll_buy(profile)),
            Link("roll bars", "bought", f"{ROLL_BAR.name}: its ends' thickness within {ROLL_BAR.thickness_tolerance:g} mm "
                 f"over its {lever:g} mm lever", roll=ROLL_BAR.thickness_tolerance / lever),
            Link("beam's underside across its roll bars", "printed",
                 f"printed: the beam's underside flat to {process.position:.2f} mm across its {profile.beam.width:g} mm "
                 "width (it rolls on the bars)", roll=process.position / profile.beam.width, buy=_roll_buy(profile)),
            *seams("dome"),
            Link("beam across its slots", "clearance",
                 f"the slots' {shell.slot_clearance:g} mm clearance each side ({slot_how})", slot_play / 2),
            Link("beam along its slots", "free", "nothing stops the beam sliding along x in its slots", math.inf,
                 buy="a locating feature: a stop or screw along the beam, or an adjuster in x"),
            Link("beam", "printed", f"printed: {profile.beam.height:g} mm high", 0.0,
                 process.height_error(profile.beam.height)),
            Link("clamp on the beam", "clearance",
                 f"the {pm.clamp_length:g} mm clamp's channel: {shell.slot_clearance:g} mm each side ({slot_how}); "
                 f"its roof flat to {process.position:.2f} mm over its length", slot_play / 2, 0.0,
                 process.position / pm.clamp_length,
                 buy="a locating feature with an adjuster in x, y and height (screws or a printed flexure)"),
            Link("clamp along the beam", "free", "no screw and no stop hold the clamp along the beam", math.inf,
                 buy="a locating feature with an adjuster in x, y and height (screws or a printed flexure)"),
            Link("clamp's roof across the beam's top", "printed",
                 f"printed: the roof and the beam's top each flat to {process.position:.2f} mm across the beam's "
                 f"{profile.beam.width:g} mm width (the clamp rolls on it)", roll=process.position / profile.beam.width,
                 buy=_roll_buy(profile)),
            Link("stem and back", "printed", f"printed: {vertex_z - z1:.0f} mm from the beam's top to the vertex",
                 0.0, process.height_error(vertex_z - z1)))


def sample_link(profile, process: ProcessErrors | None = None) -> Link:
    """The sample point O on its holder in the base plate's bore (the first link of every chain): the
    holder turned and the bore bored to their ISO 286 sliding fit (rigcad.parts.locating.holder_fit), the
    holder anywhere within the fit's largest clearance: half of it each way. Machined, so the same on
    every printer; with ``process``, the source states the stock the printer's hole shrink leaves the
    boring (the bore is drawn at its finished size)."""
    from rigcad.parts.locating import holder_fit

    fit = holder_fit(2 * profile.sample_holder.radius, where=profile.where("sample_holder", "radius"))
    stock = "" if process is None else (f"; the bore prints {process.shrink(fit.size, 'vertical'):.2f} mm under its "
                                        f"{fit.size:g} mm (the printer's hole shrink): the boring's stock")
    return Link("sample holder in its bore", "clearance",
                f"the holder turned and the bore bored to {fit.describe()}: half the largest clearance each way"
                + stock, fit.clearance[1] / 2, buy="a three-point register in the bore (two contacts and a spring plunger)")


def _dome_seat(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    """O to the dome's flange: the sample holder in its bore, the base plate from its bore to the bolt
    circle, its seams, the bolts' float."""
    flat, r = profile.datum.foot_flatness, layout.bolt_circle_r
    hole = profile.dome_shell.bolt_diameter
    major = THREADS[flange_joint(profile, layout).thread].major
    play, how = _drilled(hole, major, process, "vertical")
    return (sample_link(profile, process),
            Link("base plate: bore to the dome's bolt circle", "printed",
                 f"printed: a pattern {r:.0f} mm round the bore (the scale moves its holes out alike, not its centre); "
                 f"out of flat {flat:g} mm (datum.foot_flatness) across the flange", process.position, flat,
                 flat / (2 * layout.flange_outer_r), roll=flat / (2 * layout.flange_outer_r)),
            *seams("base_plate"),
            Link("dome's bolts in their holes", "clearance",
                 f"{profile.dome_shell.bolts} bolts ({major:g} mm) in {hole:g} mm holes ({how}): nothing else centres "
                 "the dome", play / 2, buy="a register: a spigot or two ISO 8734 dowels between flange and plate"))


def _dome_links(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    return (*_dome_seat(profile, layout, process, seams), *seams("dome"),
            Link("dome: flange to the mirror", "printed", "printed; the mirror sanded to the templates, which stand "
                 "on the flange: half a layer", 0.0, process.height_error(0.0)))


def _column_glue(profile, layout, link: Link, point) -> Link:
    """The printed column's seams (cut across its height) with their glue faces: each face lapped
    flat to LAPPED_FLATNESS (a shop step the column's hardware row states) leaves the upper piece
    leaning by up to 2 x LAPPED_FLATNESS over the tube's side; that lean, taken about the column's
    foot (the lowest a seam can be), moves ``point`` (x, z; mm) across by the lean x its height and
    along the axis by the lean x its reach from the column, on top of the pins' float."""
    t, tw = layout.tower, profile.tower
    lean = 2 * LAPPED_FLATNESS / tw.column_width
    x, z = point
    return replace(link, source=link.source + f"; its glue faces lapped flat to {LAPPED_FLATNESS:g} mm lean the upper "
                   f"piece {math.degrees(lean):.3f} deg over the {tw.column_width:g} mm tube, up to "
                   f"{z - t.column_base_z:.0f} mm below the element", lateral=link.lateral + lean * (z - t.column_base_z),
                   vertical=lean * abs(t.column_x - x), tilt=lean)


def _tower_links(profile, layout, process: ProcessErrors, seams, holder: bool = True, mirror: float = 1.0,
                 point=None) -> tuple[Link, ...]:
    """O to the splitter holder's seat (and, with ``holder``, through it), with the datum chain's
    links (rigcad.parts.datum at the process's figures), their tilts and the seams of their parts.
    ``mirror``: how many times a tilt of the shelf under the seat turns the element's axis (2 for the
    projector's reflected axis: the splitter turns on the shelf, the projector's feet elsewhere; 1
    for the camera on the holder); ``point``: the element's (x, z) mm, for the column's glue faces."""
    t, flat = layout.tower, profile.datum.foot_flatness
    chain = {k.name: k for k in datum_chain(profile, layout, process).links}
    span = t.column_x - t.holder_x[1]
    point = point or (0.0, t.plate.center[2])
    printed_column, printed_shelf = profile.buy.column == "print", profile.buy.shelf == "print"
    out = [sample_link(profile, process), _link(chain["base plate"], "printed", 0.0), *seams("base_plate")]
    for name in chain:
        if name.endswith("tongue to column") or name.endswith("column to shelf"):
            out.append(_link(chain[name], "joint", 0.0))  # a turn about the column's axis tilts no axis
            if name.endswith("tongue to column"):
                c = chain["column"]
                out.append(_link(c, "printed" if printed_column else "bought", flat / (2 * t.column_foot_half)
                                 if printed_column else c.lateral / (t.shelf_top_z - t.column_base_z),
                                 "" if not printed_column else "buy.column: extrusion_40x40"))
                out.extend(_column_glue(profile, layout, k, point) for k in seams("tower_column"))
    shelf = _link(chain["shelf"], "printed" if printed_shelf else "bought",
                  mirror * flat / span if printed_shelf else 0.0, "buy.shelf: aluminium_plate" if printed_shelf else "")
    if mirror != 1.0 and printed_shelf:
        shelf = replace(shelf, source=shelf.source + f"; its tilt under the seat ({flat:g} mm over {span:.0f} mm) "
                        f"turns the reflected axis {mirror:g} x")
    out.append(shelf)
    out.extend(seams("tower_shelf"))
    if holder:
        seat = splitter_seat(profile, layout)
        kinds = [c.kind for c in seat.contacts]
        kinds = f"{', a '.join(kinds[:-1])} and a {kinds[-1]}"
        cone = next(f for f in seat_pocket_fits(profile, process) if f["pocket"] == "cone")
        hold = seat_hold.check(profile, layout)  # refused when the design's side pull at the camera lifts a ball
        out.append(Link("splitter seat", "joint",
                        f"kinematic: ball-ended screws on a {kinds} (sprung, {seat.preload:.0f} N: "
                        f"{hold.lift_pull_n:.1f} N at the camera lifts a ball, {seat_hold.SIDE_PULL_N:g} N designed "
                        "for): it repeats on "
                        f"lift-off to {KINEMATIC_REPEAT * 1000:g} um (assumed); the cone's balls bonded in a pocket "
                        f"printed {cone['gap_mm']:.2f} mm over them (half of it each way)",
                        KINEMATIC_REPEAT + max(cone["gap_mm"], 0.0) / 2, buy="a bought kinematic mount"))
    return tuple(out)


def _link(k, kind: str, tilt: float, buy: str = "") -> Link:
    """A datum-chain link (rigcad.parts.datum.Link) as a stack link."""
    return Link(k.name, kind, k.source, k.lateral, k.vertical, tilt, buy=buy)


def _splitter_links(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    holder = {k.name: k for k in datum_chain(profile, layout, process).links}["splitter holder"]
    groove = 2 * process.position / profile.beam_splitter.length
    play, length = plate_play(profile, layout)
    return (*_tower_links(profile, layout, process, seams, mirror=2.0), *seams("splitter_holder"),
            Link(holder.name, "printed", holder.source + f"; the grooves' faces +-{process.position:.2f} mm over "
                 f"the {profile.beam_splitter.length:g} mm plate (the reflected axis turns twice)",
                 holder.lateral, holder.vertical, 2 * groove),
            Link(PLATE_FLOATS[0], "float", f"the grooves {play:g} mm wider than the plate over {length:.1f} mm: "
                 f"loose, it turns {math.degrees(plate_float_tilt(profile, layout)):.2f} deg in them (the reflected axis "
                 "twice), and moves after any setting", 0.0, 0.0, 2 * plate_float_tilt(profile, layout),
                 buy="a retainer holding the plate on its datum flank (RTV dots, a spring tab or a nylon-tipped set "
                     "screw)"))


def _cop_links(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    """The splitter's chain, then the projector on the shelf: the shelf from the seat to the
    projector's feet, and the printed shims under them (their thickness moves its COP across)."""
    t, tw = layout.tower, profile.tower
    feet = max(abs(x - t.column_x) for x, _ in _projector_feet(t))
    n = t.shims_nominal
    links = _splitter_links(profile, layout, process, seams)
    shims = (Link("projector's shims", "printed", f"{n} printed {tw.shim_thickness:g} mm shims under each foot "
                  f"(each {process.height_error(tw.shim_thickness):.3f} mm)", process.height_error(tw.shim_thickness),
                  count=n, buy="bought shim stock (steel or brass)"),) if n else ()
    return (*links, Link("shelf: column joint to the projector's feet", "printed" if profile.buy.shelf == "print"
                         else "bought", f"printed: {feet:.0f} mm from its column joint to the farthest foot",
                         process.length_error(feet) if profile.buy.shelf == "print" else 0.0, 0.0, 0.0,
                         buy="buy.shelf: aluminium_plate" if profile.buy.shelf == "print" else ""), *shims)


def _camera_links(profile, layout, process: ProcessErrors, seams) -> tuple[Link, ...]:
    """The tower to the holder's seat, the holder to the camera bracket, the camera's two screws."""
    cm, a = profile.camera, profile.adjusters
    holder = {k.name: k for k in datum_chain(profile, layout, process).links}["splitter holder"]
    cam = layout.tower.camera.cop
    return (*_tower_links(profile, layout, process, seams, point=(cam[0], cam[2])), *seams("splitter_holder"),
            Link(holder.name + " to the camera bracket", "printed", holder.source, holder.lateral, holder.vertical),
            Link("camera on its two screws", "joint", f"two screws {cm.mount_spacing:g} mm apart in one slot, each set "
                 f"to {a.hand_slide:g} mm", 0.0, 0.0, a.hand_slide / cm.mount_spacing,
                 buy="a camera mount with a pin or a keyed plate"))


#: What removes a chain part's seams besides a larger bed: the ``buy:`` key that buys it whole.
SEAM_BUY = {"tower_column": "buy.column: extrusion_40x40", "tower_shelf": "buy.shelf: aluminium_plate"}

CHAINS = {"paraboloid": _paraboloid_links, "dome": _dome_links, "cop": _cop_links, "splitter": _splitter_links,
          "camera": _camera_links}


# ------------------------------------------------------------------------------------- adjusters

def default_adjusters(profile, layout) -> tuple[AdjusterSpec, ...]:
    """The tower's adjusters (rigcad.parts.adjusters) as the stack reads them: the camera's and
    projector's slots and shims, the splitter seat's screws (serving the splitter and the COP,
    whose slots also take up the splitter's placement), the camera's tilt (the seat's flat screw
    turning the holder and its bracket) and the projector's own tilt (its feet's shims, serving the
    COP). The paraboloid and the dome have none."""
    out = []
    for adj in A.slot_adjusters(profile, layout):
        element = "camera" if adj.tolerance_key.startswith("tolerancing.camera") else "cop"
        axis = ("vertical" if adj.tolerance_key.endswith("_height") else
                "y" if "(y)" in adj.name or adj.name.startswith("projector across") else "x")
        key = "tower.travel_along" if axis == "vertical" else "tower.travel_across"  # slots' and shims' range
        out.append(AdjusterSpec(adj.name, element, axis, adj.range, adj.resolution, adj.how, key))
        if element == "cop":
            out.append(AdjusterSpec(adj.name, "splitter", axis, adj.range, adj.resolution, adj.how, key))
    for adj in A.splitter_adjusters(profile, layout):
        for element in ("splitter", "cop"):
            out.append(AdjusterSpec(adj.name, element, "tilt", adj.range, adj.resolution, adj.how))
    cam, pj = A.camera_tilt(profile, layout), A.projector_tilt(profile, layout)
    out.append(AdjusterSpec(cam.name, "camera", "tilt", cam.range, cam.resolution, cam.how))
    out.append(AdjusterSpec(pj.name, "cop", "tilt", pj.range, pj.resolution, pj.how))
    return tuple(out)


def _candidates(adjusters, element: str, axis: str) -> list[AdjusterSpec]:
    """The ways ``element``'s ``axis`` can be adjusted: an adjuster on that axis; for "lateral",
    also one in x with one in y (the smaller range, the coarser resolution); for "tilt", both of
    two tilt screws together likewise (each turns about its own line)."""
    own = [a for a in adjusters if a.element == element and a.axis == axis]
    if axis == "lateral":
        xs = [a for a in adjusters if a.element == element and a.axis == "x"]
        ys = [a for a in adjusters if a.element == element and a.axis == "y"]
        own += [AdjusterSpec(f"{x.name}; {y.name}", element, axis, min(x.range, y.range),
                             max(x.resolution, y.resolution),
                             range_key=x.range_key if x.range_key == y.range_key else "") for x in xs for y in ys]
    if axis == "tilt" and len(own) > 1:
        own = [AdjusterSpec("; ".join(a.name for a in own), element, axis, min(a.range for a in own),
                            max(a.resolution for a in own))]
    return own


# --------------------------------------------------------------------------------------- verdicts

def _dominating(links: tuple[Link, ...], axis: str) -> tuple[Link, ...]:
    """The fewest largest links (at most MAX_NAMED) making DOMINANT_SHARE of the axis's worst case;
    every unbounded link when there is one."""
    free = tuple(k for k in links if math.isinf(k.worst(axis)))
    if free:
        return free
    ranked = sorted((k for k in links if k.worst(axis) > 0), key=lambda k: -k.worst(axis))
    total, out, acc = sum(k.worst(axis) for k in ranked), [], 0.0
    for k in ranked[:MAX_NAMED]:
        out.append(k)
        acc += k.worst(axis)
        if acc >= DOMINANT_SHARE * total:
            break
    return tuple(out)


def _verdict(element: str, axis: str, links: tuple[Link, ...], key: str, tol: float, adjusters) -> AxisVerdict:
    worst = sum(k.worst(axis) for k in links)
    rss = math.sqrt(sum(k.square(axis) for k in links)) if math.isfinite(worst) else math.inf
    dom = _dominating(links, axis)
    names, buys = tuple(k.name for k in dom), tuple(dict.fromkeys(k.buy for k in dom if k.buy))
    cands = _candidates(adjusters, element, axis)
    fine = tol * RESOLUTION_SHARE

    def serves(a: AdjusterSpec) -> bool:
        return a.range >= worst and a.resolution <= fine

    best = next((a for a in cands if serves(a)), None)
    floats = tuple(k for k in links if k.kind == "float" and k.worst(axis) > 0)
    drift = sum(k.worst(axis) for k in floats)
    if drift > tol:  # it moves after any setting: no adjuster holds it
        unit, f = ("deg", math.degrees) if axis in ANGLES else ("mm", float)
        return AxisVerdict(element, axis, key, tol, worst, rss, "refused", cands[0] if cands else None,
                           tuple(k.name for k in floats), tuple(dict.fromkeys(k.buy for k in floats if k.buy)),
                           f"{', '.join(k.name for k in floats)} float {f(drift):.3g} {unit} after any setting, past the "
                           f"{f(tol):.3g} {unit} tolerance: an adjuster cannot hold what moves after it is set")
    if worst <= tol:
        return AxisVerdict(element, axis, key, tol, worst, rss, "held", best or (cands[0] if cands else None), names,
                           buys)
    if best is not None:
        return AxisVerdict(element, axis, key, tol, worst, rss, "adjusted", best, names, buys)
    unit, f = ("deg", math.degrees) if axis in ANGLES else ("mm", float)
    if math.isinf(worst):
        reason = "nothing holds it"
    elif not cands:
        reason = f"no adjuster, and the stack {f(worst):.3g} {unit} exceeds the {f(tol):.3g} {unit} tolerance"
    else:
        a = max(cands, key=lambda c: (c.range >= worst, -c.resolution))
        why = []
        if a.range < worst:
            why.append(f"its range {f(a.range):.3g} {unit} is short of the stack {f(worst):.3g} {unit}")
        if a.resolution > fine:
            why.append(f"its resolution {f(a.resolution):.3g} {unit} exceeds a quarter of the {f(tol):.3g} {unit} "
                       "tolerance")
        reason = f"{a.name}: " + " and ".join(why)
        if a.range < worst and a.range_key and a.resolution <= fine:  # its range's key may pass it: stack() solves
            return AxisVerdict(element, axis, key, tol, worst, rss, "refused", a, names, buys, reason, (a.range_key,))
    return AxisVerdict(element, axis, key, tol, worst, rss, "refused", cands[0] if cands else None, names, buys,
                       reason)


def declared_locators(profile, layout, process: ProcessErrors) -> tuple[Locator, ...]:
    """The locating features the parts declare (rigcad.parts.locating), as the stack reads them: the
    dome's register (rigcad.parts.dome.register) replaces the bolts' float by its pins' fit (or, when it
    is printed in place rather than drilled in place, that and the printed position of the flange's
    round hole about the dome's axis); the paraboloid's shim stops (rigcad.parts.paraboloid.stops, the
    beam's seats: rigcad.parts.dome.beam_seats) replace the beam's and the clamp's floats by what holds
    them: :func:`_paraboloid_held`."""
    from rigcad.parts.dome import register

    reg = register(profile, layout)
    lateral, turn = reg.repeatability
    printed = 0.0 if reg.drilled else process.position
    how = ("drilled and reamed in the plate through the flange's round hole and slot once the dome is indicated in"
           if reg.drilled else f"the flange's round hole printed about the dome's axis ({process.position:g} mm)")
    pins = Link("dome register: pins in the plate, a reamed hole and a slot in the flange", "joint",
                f"two {reg.diameter:g} mm ISO 8734 m6 pins: {lateral * 1e3:.0f} um of fit; {how}", lateral + printed, 0.0,
                turn)
    # the paraboloid rides on the dome: its chain passes the same register
    play, _ = plate_play(profile, layout)
    seated = Link("splitter plate on its datum flank", "joint",
                  f"held on the grooves' lower flanks by {PLATE_RETAINER['item']} dots cured in the {play:g} mm of play "
                  "over its back face (rigcad.parts.tower.PLATE_RETAINER): the play is taken out; the flanks' printed "
                  "position stays, in the splitter holder's link")
    return (Locator("dome register", "dome", DOME_FLOATS, pins),
            Locator("dome register", "paraboloid", DOME_FLOATS, pins),
            Locator("paraboloid on its stops", "paraboloid", PARABOLOID_FLOATS,
                    _paraboloid_held(profile, layout, process)),
            *(Locator("splitter plate retainer", e, PLATE_FLOATS, seated) for e in ("splitter", "cop")))


def _paraboloid_held(profile, layout, process: ProcessErrors) -> Link:
    """What holds the paraboloid once its stops replace the floats (one link): the beam pressed onto its
    seats' floors and -y walls by their set screws, set along x by hand (its overhangs equal to
    ``adjusters.hand_slide``); the stop pin's hole printed in the beam and the clamp's end face and -y
    wall printed about its stem; the clamp's roof flat on the beam's top to the print's position error
    over its length (a tilt the seats' packs take out)."""
    from rigcad.parts.paraboloid import mount

    m, a = mount(profile, layout), profile.adjusters
    pin_x = abs(m.pin.base[0])
    length = m.clamp.hi[0] - m.clamp.lo[0]
    lateral = a.hand_slide + process.length_error(pin_x) + process.length_error(length / 2)
    return Link("paraboloid on its stops: the beam on its seats, the clamp on the beam's pin", "joint",
                f"the beam pressed onto its seats by set screws, centred by hand to {a.hand_slide:g} mm "
                f"(adjusters.hand_slide); the pin's hole {pin_x:.1f} mm from the beam's middle and the clamp's end "
                f"{length / 2:g} mm from its stem, printed; the clamp's roof flat to {process.position:.2f} mm over "
                f"its {length:g} mm", lateral, 0.0, process.position / length,
                buy="a bought miniature XY stage under the stem")


def located_adjusters(profile, layout, process: ProcessErrors | None = None) -> tuple[AdjusterSpec, ...]:
    """The paraboloid's and the dome's adjusters the parts declare (rigcad.parts.locating.ShimStop): the
    clamp's x and y shim stops (rigcad.parts.paraboloid.stops), the beam's seats' height and tilt
    (rigcad.parts.dome.beam_seats) and the dome's indicating in from the bore (rigcad.parts.dome.indicating,
    its travel less the flange's bolt holes' shrink on ``process``)."""
    from rigcad.parts.dome import beam_seats, flange_bolt_hole, indicate_travel, indicating
    from rigcad.parts.paraboloid import stops as clamp_stops

    stops = (*clamp_stops(profile, layout), *beam_seats(profile, layout).stops())
    ind = indicating(profile, layout)
    if process is not None:
        hole = flange_bolt_hole(profile, layout)
        ind = replace(ind, range=indicate_travel(profile, layout, process.shrink(hole, "vertical")))
    return tuple(AdjusterSpec(s.name, s.element, s.axis, s.range, s.resolution, s.how) for s in (*stops, ind))


def stack(profile, layout, printer: Printer, *, seams: dict[str, int] | None = None,
          adjusters: tuple[AdjusterSpec, ...] | None = None, locators: tuple[Locator, ...] | None = None,
          process: ProcessErrors | None = None, cures: bool = True) -> StackReport:
    """Every optical element's stack on ``printer`` (its ``process_errors``, or ``process``): the
    seams on each chain part from ``seams`` (part -> seams a chain crosses: :func:`seams_from_pieces`
    of a fab run; default :func:`estimate_seams`), against ``tolerancing``, with ``adjusters``
    (default :func:`default_adjusters`) and the ``locators`` (each replaces links on its element's
    chain; default: the ones the parts declare, :func:`declared_locators`). The default adjusters
    add the paraboloid's and the dome's (:func:`located_adjusters`). With ``cures`` (and the default
    adjusters), a refused axis whose adjuster's range a profile key sets names that key and the value that
    passes it on the tower re-laid with it (:func:`_cured`)."""
    proc = process or printer.process_errors
    if proc is None:
        raise FabricationError(f"printer {printer.name}: no process_errors, so no tolerance stack")
    estimated = seams is None
    counts = dict(estimate_seams(profile, layout, printer) if estimated else seams)
    adj = (*default_adjusters(profile, layout), *located_adjusters(profile, layout, proc)) if adjusters is None \
        else tuple(adjusters)
    locators = declared_locators(profile, layout, proc) if locators is None else tuple(locators)

    def on_chain(part: str) -> tuple[Link, ...]:
        k = seam_link(part, counts.get(part, 0), printer, proc)
        return () if k is None else (k,)

    tol = profile.tolerancing
    elements = []
    for element in ELEMENTS:
        links = CHAINS[element](profile, layout, proc, on_chain)
        for loc in (x for x in locators if x.element == element):
            unknown = set(loc.replaces) - {k.name for k in links}
            if unknown:
                raise FabricationError(f"locator {loc.name}: no link {', '.join(sorted(unknown))} on the {element}'s "
                                       f"chain; its links: {', '.join(k.name for k in links)}")
            links = tuple(k for k in links if k.name not in loc.replaces) + (loc.link,)
        axes = tuple(_verdict(element, axis, links, key, getattr(tol, key), adj)
                     for axis, key in zip(ELEMENT_AXES[element], TOLERANCE_KEYS[element]))
        elements.append(ElementStack(element, links, axes))
    if cures and adjusters is None:
        elements = [replace(e, axes=tuple(_cured(profile, layout, printer, counts, locators, proc, v) for v in e.axes))
                    for e in elements]
    else:
        elements = [replace(e, axes=tuple(replace(v, cure=()) for v in e.axes)) for e in elements]
    return StackReport(printer.name, proc, tuple(sorted(counts.items())), estimated, tuple(elements),
                       tuple(x.name for x in locators))


#: Rounds of re-laying the tower when solving a range key's value (the stack grows a little with the travel).
CURE_ROUNDS = 8


def _cured(profile, layout, printer, counts, locators, proc, v: AxisVerdict) -> AxisVerdict:
    """``v`` with its cure as ``key >= value mm``: the least travel (to 0.1 mm) whose re-laid tower's stack
    (the same seams, locators and process) its adjuster covers, found by raising the key to the stack until
    the range covers it; no cure when it does not converge within CURE_ROUNDS, the adjuster's resolution
    fails, or the tower cannot be laid out with that travel (GeometryError)."""
    from rigcad.parts.tower import tower_layout

    if not v.cure:
        return v
    key = v.cure[0]
    section, name = key.split(".")
    value = getattr(getattr(profile, section), name)
    worst = v.worst
    for _ in range(CURE_ROUNDS):
        value = max(value, math.ceil(worst * 10 - 1e-9) / 10)
        p2 = replace(profile, **{section: replace(getattr(profile, section), **{name: value})})
        try:
            lay2 = replace(layout, tower=tower_layout(p2, layout.geometry, layout.plate_r, layout.dome_top_z))
        except GeometryError:  # the tower cannot take that travel: the key alone is no cure
            break
        again = stack(p2, lay2, printer, seams=counts, locators=locators, process=proc, cures=False)
        w = next(x for e in again.elements for x in e.axes if (x.element, x.axis) == (v.element, v.axis))
        if w.ok:
            return replace(v, cure=(f"{key} >= {value:g} mm",))
        if w.adjuster is None or w.adjuster.resolution > w.tolerance * RESOLUTION_SHARE or math.isinf(w.worst):
            break
        worst = w.worst
    return replace(v, cure=())


def refuse(report: StackReport) -> None:
    """Raise FabricationError when an element's stack is refused: one line naming each refused
    element and axis, the links that dominate it, the setting that would pass it (its adjuster's range
    key and the value, when one sets the range) and the ``buy:`` options that would remove the links."""
    bad = report.refused
    if not bad:
        return
    parts = []
    for v in bad:
        cure = f"; set {' or '.join(v.cure)}" if v.cure else ""
        buy = f"; {'or ' if v.cure else ''}buy: {' / '.join(v.buy)}" if v.buy else ""
        parts.append(f"{ELEMENT_NAMES[v.element]} {v.axis} (tolerancing.{v.tolerance_key}): {v.reason}; dominated by "
                     f"{', '.join(v.dominating)}{cure}{buy}")
    raise FabricationError(f"on {report.printer}, {len(bad)} placement(s) the printed rig cannot hold or adjust: "
                           + " | ".join(parts))


def check(profile, layout, printer: Printer, **options) -> StackReport:
    """:func:`stack` then :func:`refuse`: the report when every element is held or adjusted, else
    FabricationError (what ``rigcad fab`` would call with the run's seams: ``seams_from_pieces``)."""
    report = stack(profile, layout, printer, **options)
    refuse(report)
    return report


# -------------------------------------------------------------------------------------- rendering

def _fmt(v: float, axis: str) -> str:
    if math.isinf(v):
        return "free"
    return f"{math.degrees(v):.2f} deg" if axis in ANGLES else f"{v:.2f} mm"


def table_lines(report: StackReport) -> list[str]:
    """The stack as Markdown lines (for the manual and docs/rig-mechanics.md): one row per element
    and axis: worst case, RSS, tolerance, the adjuster that serves it (range each way / resolution),
    the verdict and the dominating links."""
    lines = ["| element | axis | worst case | RSS | tolerance | adjuster (range / resolution) | verdict | "
             "dominated by |", "|---|---|---|---|---|---|---|---|"]
    for e in report.elements:
        for v in e.axes:
            a = v.adjuster
            adj = "-" if a is None else f"{a.name} ({_fmt(a.range, v.axis)} / {_fmt(a.resolution, v.axis)})"
            lines.append(f"| {ELEMENT_NAMES[e.element]} | {v.axis} | {_fmt(v.worst, v.axis)} | {_fmt(v.rss, v.axis)} "
                         f"| {_fmt(v.tolerance, v.axis)} | {adj} | {v.status} | {', '.join(v.dominating) or '-'} |")
    return lines


def record(report: StackReport) -> dict:
    """The stack as a JSON-able record (units in the keys; an unbounded figure is null)."""
    return {"printer": report.printer, "process_errors": report.process.describe(),
            "seams": dict(report.seams), "seams_estimated": report.seams_estimated,
            "locators": list(report.locators), "ok": report.ok,
            "elements": [{"element": e.element, "links": [k.describe() for k in e.links],
                          "axes": [v.describe() for v in e.axes]} for e in report.elements]}


def with_process(printer: Printer, **figures) -> Printer:
    """``printer`` with some process figures replaced (``scale=0.003``, ``hole_shrink_vertical=0.3``...):
    what-if runs of the stack."""
    return replace(printer, process_errors=replace(printer.process_errors, **figures))


__all__ = ["ANGLES", "AXES", "ELEMENT_AXES", "AdjusterSpec", "AxisVerdict", "ELEMENTS", "ElementStack", "Link", "Locator", "RESOLUTION_SHARE",
           "DOME_FLOATS", "PARABOLOID_FLOATS", "PLATE_FLOATS", "declared_locators", "sample_link", "located_adjusters", "SEAT_FLOATS", "StackReport", "check", "default_adjusters", "estimate_seams", "record", "refuse", "seam_link", "seams_from_fab", "seams_from_pieces", "stack",
           "table_lines", "with_process"]
