"""The seams of a split mirror: the step across each seam, normal to the mirror, against the
sanding stock that must fair it; and the glue each split part's cut faces need.

A split mirror (the dome's sectors) is cut along meridional half-planes, so the mirror's normal lies
in each cut plane and any shift of one piece against the next within the plane is a step in the
mirror. Its pins cannot hold that step below the sanding stock: a pin in its two holes floats by
the holes' clearance, and each hole is off by the printer's position error, so the pins alone
allow ``clearance + 2 x position`` (over half a millimetre on the MK3S, against a stock under
0.2 mm). Sanding to the template then leaves the lower side's surface behind the sanded one: a
groove the coating cannot fill.

So each seam is glued on a gauge, not on its pins: the printed-stage template
(``outlines/<mirror>_template_printed``, whose edge is the surface as printed) stands in the seam's
meridional plane, its datum edge on the base plate; both pieces are pushed against its edge and a
feeler leaf must not pass under it on either side. The pin holes of a mirror part are drawn wider by
twice the position error (:func:`float_pin`) so the pins never hold the pieces off the gauge: they
key the glue, and the glue fills the float. What remains is the gauge's: the thinnest leaf that
can be felt and the edge's squareness across the template's thickness (:func:`seam_steps`).

That step sets one piece's staircase behind the other's, so the sanding stock must cover both: the
staircase's valleys (rigcad.fab.stage.stock_bound) plus the seam's step plus SANDING_MARGIN_MM
(:func:`stock_needed`); a stock below it is a fab problem naming ``sanding_stock``. The pin holes lie
behind the printed surface; sanding takes the stock and may go a leaf deeper, and what is left over
a hole must stay a wall (:func:`pin_cover`).

Glue faces printed oblique to the layers are stepped (``layer x |n . D|``, n the cut face's normal,
D the build direction; faces in a layer plane or across the layers print smooth), each is flat only
to the printer's position error, and two such faces meet ridge on ridge: the glue must fill twice
the sum. :func:`glue_for` picks the first glue of
GLUES whose gap fill covers it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

#: The thinnest leaf of a common feeler-gauge set (0.02-1.00 mm; the manual's tools list one): a
#: step the leaf does not pass under is at most this (mm).
FEELER_LEAF = 0.02
#: How far a cut plate's edge may lean from square across its thickness (deg): a laser-cut 3 mm
#: steel or aluminium plate's edge is square to about half a degree (assumed; a water-jet edge
#: tapers more, so the template is laser cut or its edge filed square against the engineer's
#: square). Both pieces bear on the one edge, each on its side of the seam, so the lean is a step.
EDGE_LEAN_DEG = 0.5
#: Twist drills (DIN 338) are sold in 0.05 mm steps up to 3 mm: a floating pin's clearance is rounded
#: up to it.
DRILL_STEP = 0.05
#: Sanding stock (mm) kept over the staircase's valleys and the seam's step: the knock-down is judged
#: on the template with the thinnest feeler leaf, so the sanded surface may stand a leaf proud of the
#: template where the check passes (a valley that deep would stay) or lie a leaf deeper (what a pin
#: hole's cover loses).
SANDING_MARGIN_MM = FEELER_LEAF
#: The thinnest wall (mm) left over a pin hole after sanding: rigcad.fab.split.MIN_WALL, the thinnest
#: unsupported wall that stands (Formlabs' design guide); thinner, the block breaks through.
PIN_COVER_MIN_MM = 0.6
#: How far either side of a split mirror's seam (the cut plane) its fairing sands (mm): the seam is
#: glued with its faces buttered, and the squeeze-out the gap pushes out onto the mirror is sanded
#: flush with the seam's step down to the template (the manual's gluing step), so whatever the
#: printer left within this band is sanded off with it. Assumed, not measured: a bead of gap-filling
#: epoxy pressed out of a 0.1-0.5 mm gap spreads a millimetre or two; 2 mm is taken. Support the
#: slicer puts on the mirror within it is counted apart (rigcad.fab.support), anywhere else it is a
#: scar on the optics and a fab problem.
SEAM_BAND_MM = 2.0
#: A face counts as lying in a layer plane (printed flat, a top skin or on the bed) when |n . D| is
#: within this of 1: no staircase, whatever its height.
FLAT = 1e-6


@dataclass(frozen=True)
class Glue:
    """A glue for cut faces: what to buy and the widest gap (mm) it fills and still holds, from its
    maker's data sheet class; ``open_min``: its working time (min), the time to set a seam on its
    gauge before it grabs."""

    name: str
    gap_fill: float
    open_min: float
    source: str


#: Glues in order of preference (the thinnest that fills the gap: a thin glue line is the stiffest).
GLUES = (
    Glue("cyanoacrylate glue, medium viscosity (e.g. Loctite 401 class)", 0.10, 0.5,
         "Henkel Loctite 401 technical data sheet: gap fill 0.1 mm"),
    Glue("two-part epoxy, 30 min working time, gap-filling (e.g. Loctite EA 3430 class)", 0.5, 30.0,
         "Henkel Loctite EA 3430 technical data sheet class: structural, gap-filling epoxy; 0.5 mm taken"),
)


def float_pin(pin, position: float):
    """The pin a split mirror's seams take: the printer's, its hole's clearance widened by at least
    twice the position error (``position`` mm), so that whatever the two holes' errors the pieces
    can be brought flush on the gluing gauge (the glue fills the float); rounded up to DRILL_STEP so
    that the hole is a drill one can buy."""
    need = pin.clearance + 2.0 * position
    return replace(pin, clearance=math.ceil(need / DRILL_STEP - 1e-9) * DRILL_STEP)


def cut_normals_of_angles(angles) -> list[np.ndarray]:
    """Unit normals (part frame) of the meridional half-planes at ``angles`` (rad) about the part's axis."""
    return [np.array([-math.sin(a), math.cos(a), 0.0]) for a in angles]


def cut_normals(plan, piece) -> list[np.ndarray]:
    """Unit normals (part frame) of ``piece``'s cut faces under ``plan`` (a sector split's
    half-planes and band cuts; a grid's planes on each axis it is cut along)."""
    from rigcad.fab.split import GridPlan, SplitPlan

    out = []
    if isinstance(plan, SplitPlan):
        if plan.sectors > 1 and piece.sector_range is not None:
            out += cut_normals_of_angles(piece.sector_range)
        if plan.bands > 1:
            out.append(np.array([0.0, 0.0, 1.0]))
    elif isinstance(plan, GridPlan):
        for k, cuts in enumerate((plan.x_cuts, plan.y_cuts, plan.z_cuts)):
            if cuts:
                out.append(np.eye(3)[k])
    return out


def seam_distance(points, normals) -> np.ndarray:
    """Distance (mm) of each point (n, 3) of a piece in its part frame to the nearest of its
    meridional cut planes (``normals``: the unit normals of half-planes through the part's axis, as
    :func:`cut_normals` gives them); inf without one. A band cut (normal along the axis) is no
    meridional seam and is left out."""
    p = np.asarray(points, float).reshape(-1, 3)
    out = np.full(len(p), np.inf)
    for n in normals:
        n = np.asarray(n, float)
        if abs(n[2]) < FLAT:
            out = np.minimum(out, np.abs(p @ n))
    return out


def glue_face_step(layer: float, normals, direction) -> float:
    """The deepest staircase (mm) on a piece's glue faces printed along ``direction``: layer x |n . D|
    over its cut faces, 0 for a face across the layers or in a layer plane."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    steps = [0.0]
    for n in normals:
        c = abs(float(np.dot(n, d)))
        if c < 1.0 - FLAT:
            steps.append(layer * c)
    return max(steps)


def glue_for(gap: float) -> Glue:
    """The first glue of GLUES whose gap fill covers ``gap`` mm (the last, if none: the caller
    compares)."""
    for g in GLUES:
        if g.gap_fill >= gap:
            return g
    return GLUES[-1]


def step_on_gauge(template_thickness: float) -> float:
    """The step (mm) a seam glued on the gauge may leave: the thinnest leaf plus the template edge's
    lean (EDGE_LEAN_DEG) across its ``template_thickness`` (mm)."""
    return FEELER_LEAF + template_thickness * math.tan(math.radians(EDGE_LEAN_DEG))


def stock_needed(staircase: float, step: float) -> float:
    """The sanding stock (mm) a mirror needs: its staircase's bound (``staircase``, the deepest valley
    behind the printed surface), the seam's ``step`` (one piece's surface behind the other's; 0 for a
    whole mirror) and SANDING_MARGIN_MM, so that sanding to the template leaves no valley on either
    side of a seam."""
    return staircase + step + SANDING_MARGIN_MM


def pin_cover(clearance: float | None, stock: float) -> dict:
    """What is left over a split mirror's pin holes after sanding (mm): the holes lie ``clearance``
    behind the printed surface (measured on the pieces), sanding takes the ``stock`` and may go
    SANDING_MARGIN_MM deeper; ``pins_stay_covered``: at least PIN_COVER_MIN_MM is left."""
    if clearance is None:
        return {}
    left = clearance - stock - SANDING_MARGIN_MM
    return {"pin_hole_behind_printed_mm": clearance, "pin_hole_cover_after_sanding_mm": left,
            "pin_cover_min_mm": PIN_COVER_MIN_MM, "pins_stay_covered": left >= PIN_COVER_MIN_MM}


def seam_steps(pin, position: float, stock: float, template_thickness: float, staircase: float = 0.0) -> dict:
    """The step across a split mirror's seams (mm): on its pins alone (``pin`` as drawn: the
    :func:`float_pin`; the holes each off by ``position``) and on the gluing gauge (the leaf and the edge's lean across half the
    template's ``template_thickness`` each side), against the sanding ``stock``; ``fairs``: the stock
    covers the ``staircase`` (its bound, mm), the gauge's step and the margin (:func:`stock_needed`),
    so sanding to the template leaves no groove and no valley."""
    on_pins = pin.clearance + 2.0 * position
    lean = template_thickness * math.tan(math.radians(EDGE_LEAN_DEG))
    on_gauge = step_on_gauge(template_thickness)
    need = stock_needed(staircase, on_gauge)
    return {"step_on_pins_mm": on_pins,
            "step_on_pins_how": f"{pin.diameter:g} mm pins in {pin.diameter + pin.clearance:.2f} mm holes, each hole "
                                f"+-{position:.2f} mm",
            "step_on_gauge_mm": on_gauge,
            "step_on_gauge_how": f"glued on the printed-stage template: a {FEELER_LEAF:g} mm feeler leaf passes under "
                                 f"its edge on neither side; the edge square to {EDGE_LEAN_DEG:g} deg across its "
                                 f"{template_thickness:g} mm ({lean:.3f} mm)",
            "staircase_mm": staircase, "sanding_margin_mm": SANDING_MARGIN_MM, "stock_needed_mm": need,
            "stock_mm": stock, "fairs": need <= stock + 1e-12}


def glue_record(printer, plan, pieces, oriented) -> dict:
    """fab.json's glue for a split part: its glue faces' deepest staircase (``oriented``: each piece's
    chosen orientation, with ``best.direction``), the gap two of them leave (each face's staircase and
    its printed position error: a face is flat to the printer's ``process_errors.position``), the glue
    that fills it."""
    layer = printer.layer_height
    face = max(glue_face_step(layer, cut_normals(plan, pc), o.best.direction) for pc, o in zip(pieces, oriented))
    errors = getattr(printer, "process_errors", None)
    gap = 2.0 * (face + (errors.position if errors is not None else 0.0))
    glue = glue_for(gap)
    return {"glue_face_step_mm": face, "glue_gap_mm": gap, "glue": glue.name, "glue_gap_fill_mm": glue.gap_fill,
            "glue_open_min": glue.open_min, "glue_source": glue.source, "glue_fills": glue.gap_fill >= gap}


def mirror_record(printer, stock: float, template_thickness: float, pin_diameter: float | None = None,
                  staircase: float = 0.0, pin_clearance: float | None = None) -> dict:
    """fab.json's seam steps for a split mirror printed with ``stock`` mm of sanding stock over a
    ``staircase`` mm deep (its bound), its pins ``pin_diameter`` mm (default the printer's; a thin shell
    takes thinner ones), their holes ``pin_clearance`` mm behind the printed surface (:func:`pin_cover`);
    empty when the printer states no process errors: no position error to reckon with."""
    errors = getattr(printer, "process_errors", None)
    if errors is None:
        return {}
    pin = float_pin(printer.alignment_pin, errors.position)
    if pin_diameter:
        pin = replace(pin, diameter=pin_diameter)
    return {**seam_steps(pin, errors.position, stock, template_thickness, staircase), **pin_cover(pin_clearance, stock)}


def problems(part: str, record: dict | None, whole: str = "") -> list[str]:
    """What a fab run must not pass over in a part's seams record: a seam its sanding stock cannot
    fair, or glue faces no listed glue fills (``whole``: what would let the part print whole, with
    no seam to glue: the keys and their values, rigcad.fab.stage.whole_fit_hint)."""
    if not record:
        return []
    out = []
    if record.get("fairs") is False:
        out.append(f"{part}: its {record['stock_mm']:.3f} mm of sanding stock does not cover its staircase "
                   f"({record.get('staircase_mm', 0.0):.3f} mm), its seams' step on the gluing gauge "
                   f"({record['step_on_gauge_mm']:.3f} mm) and the sanding margin "
                   f"({record.get('sanding_margin_mm', 0.0):.3f} mm): sanding would leave valleys; raise the printer "
                   f"file's sanding_stock to at least {record.get('stock_needed_mm', record['step_on_gauge_mm']):.3f} "
                   "mm (or set it to auto)")
    if record.get("pins_stay_covered") is False:
        out.append(f"{part}: its pin holes lie {record['pin_hole_behind_printed_mm']:.2f} mm behind the printed "
                   f"mirror; sanding its {record['stock_mm']:.3f} mm of stock (and a leaf deeper) leaves "
                   f"{record['pin_hole_cover_after_sanding_mm']:.2f} mm over them, under "
                   f"{record['pin_cover_min_mm']:g} mm: set a smaller sanding_stock in the printer file, or print thinner "
                   "layers (its layer_height sets the staircase the auto stock covers)")
    if not record.get("glue_fills", True):
        out.append(f"{part}: its glue faces leave gaps of {record['glue_gap_mm']:.2f} mm, more than any listed glue "
                   f"fills ({GLUES[-1].gap_fill:g} mm): print it with its cut faces across the layers"
                   + (f", or avoid the split: {whole}" if whole else ""))
    return out
