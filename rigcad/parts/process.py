"""A printer's dimensional errors: what the printed process does to a length, a hole and a height
(kernel-free; mm, and fractions for relative errors).

A printer file states them (``process_errors:``, rigcad.fab.printers) with their source: defaults
from published figures, cited in the file, or the lab's own calibration print (the manual tells the
lab to print it and measure it; :func:`from_measurements` turns the measured lengths and holes into
these figures). The datum chain (rigcad.parts.datum) and the tolerance stack (rigcad.fab.stack)
read them.

The model, each figure a worst case (each way):

* a printed length L is off by ``position + scale * L`` (a feature's position: a fixed part, about
  half a nozzle's width, and a part proportional to its distance from the part's datum feature);
* a printed hole of diameter d comes out smaller by ``shrink(d, axis) = hole_shrink_<axis> +
  hole_shrink_per_mm * d`` (diametral; the axis as printed: ``vertical``, the hole's axis along the
  printer's z, or ``horizontal``, where the hole's top droops); a slot's width shrinks the same;
* a printed height is a whole number of layers: a face is off by up to half of ``layer_step``.
"""

from __future__ import annotations

from dataclasses import dataclass

from rigcad.errors import ProfileError

#: The axes a printed hole may have, as printed.
HOLE_AXES = ("vertical", "horizontal")


@dataclass(frozen=True)
class ProcessErrors:
    """A printer's dimensional errors (see the module doc). ``scale``: a printed length's relative
    error (a fraction: 0.002 is 0.2 %); ``position`` (mm): a feature's fixed position error;
    ``hole_shrink_vertical``, ``hole_shrink_horizontal`` (mm): the diametral undersize of a hole
    whose axis is vertical or horizontal as printed; ``hole_shrink_per_mm``: the undersize's part
    proportional to the diameter (a fraction, mm per mm); ``layer_step`` (mm): the step heights come
    in; ``source``: where the figures come from (published figures cited, or the calibration print)."""

    scale: float
    position: float
    hole_shrink_vertical: float
    hole_shrink_horizontal: float
    hole_shrink_per_mm: float
    layer_step: float
    source: str

    def length_error(self, span: float) -> float:
        """Worst-case error (mm) of a printed length, or of a feature's position ``span`` mm from its datum."""
        return self.position + self.scale * abs(span)

    def height_error(self, span: float) -> float:
        """Worst-case error (mm) of a printed height ``span`` mm: half a layer step and the scale."""
        return self.layer_step / 2 + self.scale * abs(span)

    def shrink(self, diameter: float, axis: str) -> float:
        """Diametral undersize (mm) of a printed hole (or slot width) of ``diameter`` mm whose axis is
        ``axis`` ("vertical", "horizontal") as printed; "unknown" takes the larger of the two."""
        if axis == "unknown":
            base = max(self.hole_shrink_vertical, self.hole_shrink_horizontal)
        elif axis in HOLE_AXES:
            base = self.hole_shrink_vertical if axis == "vertical" else self.hole_shrink_horizontal
        else:
            raise ValueError(f"a hole's axis is one of {HOLE_AXES} or 'unknown', not {axis!r}")
        return base + self.hole_shrink_per_mm * diameter

    def describe(self) -> dict:
        """The figures with their units in the keys (for fab.json and the manual)."""
        return {"scale_percent": 100 * self.scale, "position_mm": self.position,
                "hole_shrink_vertical_mm": self.hole_shrink_vertical,
                "hole_shrink_horizontal_mm": self.hole_shrink_horizontal,
                "hole_shrink_per_mm": self.hole_shrink_per_mm, "layer_step_mm": self.layer_step,
                "source": self.source}


def _fit_line(x: list[float], y: list[float]) -> tuple[float, float]:
    """Least-squares slope and intercept of y on x (x not all equal)."""
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    slope = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sxx
    return slope, my - slope * mx


def _pairs(what: str, rows, where: str | None) -> list[tuple[float, float]]:
    out = []
    for nominal, measured in rows:
        if not (nominal > 0 and measured > 0):
            raise ProfileError(f"process_errors.measured.{what}: nominal and measured sizes must be > 0 mm, got "
                               f"{nominal:g} and {measured:g} mm", where=where)
        if abs(measured / nominal - 1) > 0.2:
            raise ProfileError(f"process_errors.measured.{what}: {measured:g} mm measured for {nominal:g} mm is off by "
                               f"more than 20 %: a slip of unit or of row (each row is [nominal, measured])",
                               where=where)
        out.append((float(nominal), float(measured)))
    return out


def from_measurements(lengths, holes_vertical=(), holes_horizontal=(), *, layer_step: float,
                      source: str = "the calibration print, measured", where: str | None = None) -> ProcessErrors:
    """Process figures from a calibration print's measurements: ``lengths``, ``holes_vertical`` and
    ``holes_horizontal`` are sequences of (nominal, measured) sizes in mm (bars' lengths; holes'
    diameters, by their axis as printed).

    * scale: the slope of measured on nominal length (least squares), less one, as a magnitude;
    * position: the largest residual of a length off that line, plus half the line's intercept
      (an offset of each of the length's two ends), so every measured bar is covered;
    * hole shrink, per axis: nominal less measured diameter; its part per mm of diameter is the
      least-squares slope on the diameter when two or more diameters were measured (else 0), and
      the fixed part the largest shrink left over, so every measured hole is covered; the per-mm part
      is the larger of the two axes' slopes (one figure for both).

    At least two lengths of different nominal sizes are needed (one cannot tell scale from
    position) and at least one hole per axis; ProfileError names what is missing."""
    bars = _pairs("lengths", lengths, where)
    if len({n for n, _ in bars}) < 2:
        raise ProfileError("process_errors.measured.lengths: measure at least two bars of different nominal lengths "
                           "(e.g. [[20 mm, 19.96 mm], [100 mm, 99.81 mm]]): one length cannot tell scale from position",
                           where=where)
    slope, icept = _fit_line([n for n, _ in bars], [m for _, m in bars])
    scale = abs(slope - 1)
    position = max(abs(m - (slope * n + icept)) for n, m in bars) + abs(icept) / 2
    slopes, fixed = [], {}
    for axis, rows in (("vertical", holes_vertical), ("horizontal", holes_horizontal)):
        holes = _pairs(f"holes_{axis}", rows, where)
        if not holes:
            raise ProfileError(f"process_errors.measured.holes_{axis}: measure at least one hole printed with its axis "
                               f"{axis} (rows of [nominal, measured] diameters)", where=where)
        d = [n for n, _ in holes]
        slopes.append(max(_fit_line(d, [n - m for n, m in holes])[0], 0.0) if len(set(d)) >= 2 else 0.0)
        fixed[axis] = holes
    per_mm = max(slopes)
    # with the common per-mm part, each axis's fixed part covers its worst hole
    fixed = {axis: max(0.0, max((n - m) - per_mm * n for n, m in holes)) for axis, holes in fixed.items()}
    return ProcessErrors(scale=scale, position=position, hole_shrink_vertical=fixed["vertical"],
                         hole_shrink_horizontal=fixed["horizontal"], hole_shrink_per_mm=per_mm,
                         layer_step=layer_step, source=source)


@dataclass(frozen=True)
class CalibrationPrint:
    """What the lab prints and measures to state its printer's process (the manual's step): bars
    of ``bars`` nominal lengths (mm), measured end to end; holes of ``holes`` nominal diameters (mm),
    once through a flat plate (their axes vertical as printed) and once through an upright wall
    (their axes horizontal); each measured with a caliper (bars) and gauge pins or drill shanks
    (holes: the largest that enters), after the part has cooled a day."""

    bars: tuple[float, ...] = (20.0, 50.0, 100.0)
    holes: tuple[float, ...] = (2.0, 3.0, 4.0, 6.0, 8.0)

    def steps(self) -> list[str]:
        """The manual's instructions, one line each."""
        bars = ", ".join(f"{b:g}" for b in self.bars)
        holes = ", ".join(f"{h:g}" for h in self.holes)
        return [f"Print three bars {bars} mm long, and a plate and an upright wall each with holes of {holes} mm, "
                "with the settings the rig's parts print with; let them cool for a day.",
                "Measure each bar end to end with a caliper, and each hole with gauge pins (or drill shanks): the "
                "largest that enters.",
                "Write the pairs under process_errors.measured in the printer file: lengths: [[nominal, measured], "
                "...], holes_vertical: (the plate's), holes_horizontal: (the wall's).",
                "Run the command again: rigcad fits the printer's scale, position and hole shrink from them "
                "(rigcad.parts.process.from_measurements)."]

    def yaml_template(self) -> str:
        """The ``measured`` section to fill in, the nominal sizes written, the measured ones blank."""
        bars = ", ".join(f"[{b:g} mm, ]" for b in self.bars)
        holes = ", ".join(f"[{h:g} mm, ]" for h in self.holes)
        return (f"process_errors:\n  measured:\n    lengths: [{bars}]\n    holes_vertical: [{holes}]\n"
                f"    holes_horizontal: [{holes}]\n")


__all__ = ["CalibrationPrint", "HOLE_AXES", "ProcessErrors", "from_measurements"]
