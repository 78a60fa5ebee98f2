"""Shop drawings of the parts that are machined, not printed: the sample holder, turned from bar.

The figures are read from the part's own recipe (its two cylinders: the body and the stop collar,
rigcad.parts.base.holder_body) and its fit (rigcad.parts.locating.holder_fit, ISO 286's zones in
rigcad.standards), never typed here; rigcad.plots.turned_part_drawing draws them. The manual writes
each drawing as SVG (its text kept as text, so a reader or a test reads the dimensions back) and PNG
(shown in the manual), under ``drawings/``. mm.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The general tolerance class of a dimension the drawing gives no tolerance of (ISO 2768-1, fine: +-0.1 mm
#: over 6-30 mm): the turned lengths, which set the sample's face against O, kept to half of
#: ``tolerancing.paraboloid_height``'s 0.2 mm on the thesis's rig; a lathe holds it without special care.
GENERAL_TOLERANCE = "ISO 2768-f"


@dataclass(frozen=True)
class Dimension:
    """One dimension as the drawing states it: ``label`` (what is written), the nominal ``value`` (mm),
    its deviations (``lower``, ``upper``, mm; None: the general tolerance) and the zone's name."""

    name: str
    value: float
    diameter: bool = False
    zone: str = ""
    lower: float | None = None
    upper: float | None = None

    @property
    def label(self) -> str:
        size = ("Ø" if self.diameter else "") + f"{self.value:g}"
        if self.lower is None:
            return size
        return f"{size} {self.zone} ({self.upper:+.3f}/{self.lower:+.3f})"


@dataclass(frozen=True)
class TurnedDrawing:
    """A part turned from bar: its steps from the bottom up as (diameter, length) mm, its dimensions,
    the notes under it (stock, the fit it makes, the faces) and its title."""

    part: str
    title: str
    steps: tuple[tuple[float, float], ...]
    dimensions: tuple[Dimension, ...]
    notes: tuple[str, ...]


def sample_holder(rig) -> TurnedDrawing:
    """The sample holder's drawing from its recipe: the collar (bottom) and the body (top), the body
    to the fit's shaft zone, the lengths to :data:`GENERAL_TOLERANCE`."""
    from rigcad.parts.base import holder_stock
    from rigcad.parts.locating import holder_fit
    from rigcad.standards import tolerance_zone

    p = rig.profile
    cylinders = sorted(rig.recipes["sample_holder"].solid.items, key=lambda c: c.base[2])  # bottom first
    collar, body = cylinders
    fit = holder_fit(2 * body.radius, where=p.where("sample_holder", "radius"))
    lo, hi = tolerance_zone(fit.size, fit.shaft)
    least, most = fit.clearance
    dims = (Dimension("body_diameter", 2 * body.radius, True, fit.shaft, lo, hi),
            Dimension("collar_diameter", 2 * collar.radius, True),
            Dimension("body_length", body.height), Dimension("collar_thickness", collar.height),
            Dimension("overall_length", body.height + collar.height))
    notes = (f"Stock: {holder_stock(p)}.",
             f"Body {fit.size:g} {fit.shaft} slides in the base plate's bore, bored {fit.size:g} {fit.hole}: "
             f"{fit.describe()}; measure it with an outside micrometer.",
             f"Top face: the sample's seat ({p.sample_holder.sample_thickness:g} mm sample, its face at O), "
             "faced square to the body in the chucking that turns the body; the collar's top face stops "
             "against the plate's underside.",
             f"Lengths and the collar: general tolerances {GENERAL_TOLERANCE}. mm.")
    return TurnedDrawing("sample_holder", f"sample_holder: turned from bar, {fit.size:g} {fit.shaft} (1 off)",
                         ((2 * collar.radius, collar.height), (2 * body.radius, body.height)), dims, notes)


def drawings(rig) -> dict[str, bytes]:
    """The manual's drawing files (relative path -> bytes): ``drawings/<part>.svg`` and ``.png`` for each
    machined part the rig has."""
    from rigcad import plots

    if "sample_holder" not in rig.recipes:
        return {}
    d = sample_holder(rig)
    return {f"drawings/{d.part}.svg": plots.turned_part_drawing(d, "svg"),
            f"drawings/{d.part}.png": plots.turned_part_drawing(d, "png")}


__all__ = ["GENERAL_TOLERANCE", "Dimension", "TurnedDrawing", "drawings", "sample_holder"]
