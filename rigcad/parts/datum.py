"""The rig's one datum chain: how far the tower's optics can sit from the design COP before any
adjustment, and whether the adjusters can take that up (kernel-free; mm).

The reference is the base plate: its bore holds the sample holder (the sample point O on the
optical axis). The chain runs, link by link, to the splitter (whose front face makes the
projector's virtual COP and whose plate the camera looks through):

1. the base plate's datum tongue: the bore to the tongue's dowel holes (a printed length);
2. dowel pins, tongue to column foot (ISO 8734 m6 pins in printed holes reamed H7), or, for a
   bought extrusion, the square pocket it stands in;
3. the column: foot to top flange, and its lean (the foot's out-of-flat over its width, times the
   column's height), or, bought, the extrusion's saw-cut end squareness;
4. dowel pins (or the pocket), column to shelf;
5. the shelf: its dowel holes to the splitter seat's cone (a printed, or a cut and drilled, length);
6. the splitter holder: the seat's balls to the grooves the plate rests on (printed).

The print accuracy is the profile's ``datum`` figures (assumed), or, given a printer's
``process`` (rigcad.parts.process.ProcessErrors: what the tolerance stack, rigcad.fab.stack, uses),
its figures: a length as ``position + scale * span``, a height as half a layer step plus the scale.

Each link's error is its worst case; the chain's worst case is their sum and its likely value
their root sum of squares (independent links). Links 1-5 move the whole tower (projector, camera
and splitter together): the COPs move as much. Link 6 moves the splitter alone: its virtual image
of the projector's COP moves by twice the plate's shift along its normal, whose lateral part, at
45 deg, equals the shift (2 cos^2 45 deg = 1); so every link counts once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from rigcad.parts import breadboard
from rigcad.parts.process import ProcessErrors
from rigcad.parts.tower import EXTRUSION, POCKET_GAP

def dowel_fit(diameter: float) -> float:
    """How far (mm, each way) a joint on ISO 8734 m6 dowels of ``diameter`` mm may shift: the pins pressed
    into one part (rigcad.parts.locating.press_fit: no play), the other sliding on them (slip_fit): half
    the slip fit's largest clearance (4 mm pins, F7/m6: 0.018 mm, so 0.009 mm)."""
    from rigcad.parts.locating import slip_fit

    return slip_fit(diameter).clearance[1] / 2


#: :func:`dowel_fit` of the default 4 mm dowels (``datum.dowel_diameter``): the what-if of steel dowels
#: across a seam (rigcad.fab.stack.seam_link) takes it.
DOWEL_FIT = dowel_fit(4.0)
#: A 40 x 40 mm extrusion cut on a saw with a stop (assumed): its ends square to 0.1 mm across 40 mm,
#: and its length to 0.1 mm.
EXTRUSION_END_SQUARENESS = 0.1
#: Holes in a cut-and-drilled aluminium plate (assumed: drilled through a printed template, 0.05 mm).
PLATE_HOLE_POSITION = 0.05


@dataclass(frozen=True)
class Link:
    """One link of the chain: its name, what the error comes from, its lateral (x-y) and vertical
    (z) worst-case error (mm)."""

    name: str
    source: str
    lateral: float
    vertical: float


@dataclass(frozen=True)
class DatumChain:
    """The chain's links and totals (mm)."""

    links: tuple[Link, ...]
    #: The rig on a breadboard (rigcad.parts.breadboard.fit): no link of the chain (the rig is one
    #: rigid piece), but what its screws' holes must take up; None on the base plate alone.
    mount: dict | None = None

    @property
    def lateral_worst(self) -> float:
        return sum(k.lateral for k in self.links)

    @property
    def lateral_rss(self) -> float:
        return math.sqrt(sum(k.lateral ** 2 for k in self.links))

    @property
    def vertical_worst(self) -> float:
        return sum(k.vertical for k in self.links)

    def describe(self) -> dict:
        return {"links": [{"name": k.name, "source": k.source, "lateral_mm": k.lateral, "vertical_mm": k.vertical}
                          for k in self.links],
                "lateral_worst_mm": self.lateral_worst, "lateral_rss_mm": self.lateral_rss,
                "vertical_worst_mm": self.vertical_worst, "mount": self.mount}


def _printed(profile, span: float, process: ProcessErrors | None = None) -> float:
    """Position error (mm) of a printed feature ``span`` mm from the part's datum feature."""
    if process is not None:
        return process.length_error(span)
    d = profile.datum
    return d.print_position + d.print_scale * abs(span)


def _height(profile, span: float, process: ProcessErrors | None = None) -> float:
    """Error (mm) of a printed height ``span`` mm: as a position (the profile's figures), or half a
    layer step and the scale (a printer's process)."""
    return _printed(profile, span) if process is None else process.height_error(span)


def _column_links(profile, t, process: ProcessErrors | None = None) -> tuple[Link, Link, Link]:
    """The column and its two joints: a printed column on dowels, or a bought extrusion in pockets."""
    d = profile.datum
    height = t.shelf_top_z - t.shelf_thickness - t.column_base_z
    if profile.buy.column == "print":
        from rigcad.parts.locating import SLOT_FIT_MM
        from rigcad.parts.tower import column_dowel_points

        foot = 2 * t.column_foot_half
        a, b = column_dowel_points(t, profile)
        yaw = SLOT_FIT_MM / math.dist(a, b)
        fit = dowel_fit(d.dowel_diameter)
        dowels = Link("dowels", f"ISO 8734 m6 pressed N7, the column sliding on them F7: {fit:g} mm; the second pin "
                      f"in a slot filed to {SLOT_FIT_MM:g} mm turns the column {yaw * 1e3:.2f} mrad, which swings the "
                      f"axis {t.column_x:.0f} mm away by {yaw * t.column_x:.2f} mm", fit + yaw * t.column_x, 0.0)
        pattern = _printed(profile, 0, process)
        return (dowels, Link("column", f"printed: dowel pattern {pattern:.2f} mm; lean: the foot's "
                             f"{d.foot_flatness:g} mm out-of-flat over {foot:.0f} mm, times {height:.0f} mm",
                             pattern + d.foot_flatness / foot * height, _height(profile, height, process)), dowels)
    pocket = Link("pocket", f"square pocket, a slide fit: {POCKET_GAP:g} mm each side", POCKET_GAP, 0.0)
    return (pocket, Link("column", f"extrusion: saw-cut ends square to {EXTRUSION_END_SQUARENESS:g} mm over "
                         f"{EXTRUSION:g} mm, times {height:.0f} mm; cut length to {EXTRUSION_END_SQUARENESS:g} mm",
                         EXTRUSION_END_SQUARENESS / EXTRUSION * height, EXTRUSION_END_SQUARENESS), pocket)


def datum_chain(profile, layout, process: ProcessErrors | None = None) -> DatumChain:
    """The chain from the base plate's bore to the splitter for ``profile`` and ``layout`` (RigLayout),
    at the profile's assumed print accuracy or, given, a printer's ``process`` figures."""
    t = layout.tower
    low, column, high = _column_links(profile, t, process)
    span = t.column_x - t.holder_x[1]
    shelf = (Link("shelf", f"printed: {span:.0f} mm from its column joint to the seat", _printed(profile, span, process),
                  _height(profile, t.shelf_thickness, process)) if profile.buy.shelf == "print" else
             Link("shelf", f"aluminium plate drilled through a printed template ({PLATE_HOLE_POSITION:g} mm)",
                  PLATE_HOLE_POSITION, 0.0))
    holder_span = t.holder_top_z - t.shelf_top_z
    return DatumChain((
        Link("base plate", f"printed: {t.column_x:.0f} mm from its bore to the tongue's column joint",
             _printed(profile, t.column_x, process), _height(profile, profile.base_plate.thickness, process)),
        replace(low, name=f"{low.name}, tongue to column"),
        column,
        replace(high, name=f"{high.name}, column to shelf"),
        shelf,
        Link("splitter holder", f"printed: {holder_span:.0f} mm from its seat to the grooves",
             _printed(profile, holder_span, process), _height(profile, holder_span, process)),
    ), breadboard.fit(profile, layout) if breadboard.board(profile) else None)


def check_datum_chain(profile, layout) -> list[dict]:
    """The chain against the tolerances and the adjusters (mm): one row per claim, with ``ok``.

    * ``needs_adjustment``: whether the chain alone holds ``tolerancing.projector_offset`` (then the
      adjusters only refine) or not (then the calibration must use them);
    * ``lateral_within_travel``: the chain's worst lateral error is within the adjusters' travel
      across (``tower.travel_across``): the adjusters can always bring the COP back;
    * ``vertical_within_travel``: the same along the axis (``tower.travel_along``);
    * on a breadboard, ``breadboard_holes_take_the_grid``: the screws' holes take the printed and the
      board's position errors (rigcad.parts.breadboard.fit)."""
    chain = datum_chain(profile, layout)
    tol, tw = profile.tolerancing, profile.tower
    board = [] if chain.mount is None else [
        {"claim": "breadboard_holes_take_the_grid", "value_mm": chain.mount["hole_needed_mm"],
         "limit_mm": chain.mount["hole_mm"], "ok": chain.mount["hole_needed_mm"] <= chain.mount["hole_mm"]}]
    return board + [
        {"claim": "needs_adjustment", "value_mm": chain.lateral_worst, "limit_mm": tol.projector_offset,
         "ok": True, "adjust": chain.lateral_worst > tol.projector_offset},
        {"claim": "lateral_within_travel", "value_mm": chain.lateral_worst, "limit_mm": tw.travel_across,
         "ok": chain.lateral_worst <= tw.travel_across},
        {"claim": "vertical_within_travel", "value_mm": chain.vertical_worst, "limit_mm": tw.travel_along,
         "ok": chain.vertical_worst <= tw.travel_along},
    ]
