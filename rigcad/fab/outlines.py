"""2D cutting outlines of flat parts (the profile templates, thesis 3.4, Figure 3.11) for laser or
water-jet cutting: DXF (ezdxf, $INSUNITS = mm) and SVG (width/height in mm, viewBox in mm),
true scale. The outline is the part's Prism section in the x-z plane, as a closed polyline
within ``chord_error`` mm of the exact curves; the DXF also carries each mirror curve as a
cubic B-spline (control points and knots, interpolating SPLINE_POINTS points of the curve) on its
own layer, for CAM that prefers curves, and its extents ($EXTMIN, $EXTMAX) in the header. Both writers give the same
bytes for the same outline.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from rigcad.parts.recipe import Curve, Part, Prism

#: Points per mirror curve the DXF's spline passes through (the polyline carries the accuracy; the
#: spline is a courtesy for CAM that prefers curves).
SPLINE_POINTS = 200
#: Degree of the DXF's splines: cubic, C2 like the mirror profiles' STEP splines.
SPLINE_DEGREE = 3


@dataclass(frozen=True)
class Outline:
    """A closed outline (n, 2) mm in the section's (x, z) coordinates, the curves' dense points,
    and the plate thickness (mm)."""

    name: str
    polygon: np.ndarray
    curves: tuple[np.ndarray, ...]
    thickness: float

    @property
    def size(self) -> tuple[float, float]:
        return tuple(float(v) for v in np.ptp(self.polygon, axis=0))


def outline(part: Part, chord_error: float) -> Outline:
    """The cutting outline of a flat (Prism) part."""
    if not isinstance(part.solid, Prism):
        raise TypeError(f"{part.name} is not a flat (Prism) part")
    sec = part.solid.section
    curves = tuple(seg.dense(SPLINE_POINTS) for seg in sec.segments if isinstance(seg, Curve))
    return Outline(part.name, sec.polygon(chord_error), curves, part.solid.thickness)


def dxf_bytes(o: Outline) -> bytes:
    """DXF R2010, units mm: layer CUT the closed outline (LWPOLYLINE), layer CURVES the mirror
    curves as cubic B-splines (control points, knots), layer NOTE the name and plate thickness;
    $EXTMIN and $EXTMAX the drawing's extents."""
    import ezdxf
    import ezdxf.bbox

    saved = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True  # fixed dates and GUIDs: same bytes
    try:
        doc = ezdxf.new("R2010", setup=False)
        doc.units = ezdxf.units.MM
        doc.header["$MEASUREMENT"] = 1
        doc.layers.add("CUT", color=1)
        doc.layers.add("CURVES", color=3)
        doc.layers.add("NOTE", color=7)
        msp = doc.modelspace()
        msp.add_lwpolyline([tuple(map(float, p)) for p in o.polygon], close=True, dxfattribs={"layer": "CUT"})
        for c in o.curves:
            # control points and knots, not fit points: a fit-point SPLINE leaves the curve to each
            # reader's own interpolation, and GDAL's OGR refuses one without control points
            msp.add_spline_control_frame([(float(x), float(y), 0.0) for x, y in c], degree=SPLINE_DEGREE,
                                         method="chord", dxfattribs={"layer": "CURVES"})
        lo = o.polygon.min(axis=0)
        msp.add_text(f"{o.name} t={o.thickness:g} mm", height=3.0,
                     dxfattribs={"layer": "NOTE", "insert": (float(lo[0]), float(lo[1]) - 6.0)})
        # the drawing's extents, which readers zoom to ("zoom extents"); ezdxf leaves them at +-1e20.
        # fast: the text's box from its height and character count, no font files (same bytes anywhere)
        box = ezdxf.bbox.extents(msp, fast=True)
        doc.header["$EXTMIN"] = tuple(float(v) for v in box.extmin)
        doc.header["$EXTMAX"] = tuple(float(v) for v in box.extmax)
        msp.dxf.extmin, msp.dxf.extmax = doc.header["$EXTMIN"], doc.header["$EXTMAX"]
        # ezdxf adds a CLASS per entity type in use from a set, whose order follows string hashing
        # (random per process): declaring them first, sorted, fixes the CLASSES section's order
        for dxftype in sorted(doc.entitydb.dxf_types_in_use()):
            doc.classes.add_class(dxftype)
        buf = io.StringIO()
        doc.write(buf)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = saved
    return buf.getvalue().encode()


def svg_bytes(o: Outline, margin: float = 2.0) -> bytes:
    """SVG at true scale: the document is (w + 2 margin) x (h + 2 margin) mm and its viewBox the
    same numbers, so one user unit is one mm; y is flipped (SVG y points down)."""
    lo = o.polygon.min(axis=0) - margin
    hi = o.polygon.max(axis=0) + margin
    w, h = hi - lo
    pts = np.column_stack([o.polygon[:, 0] - lo[0], hi[1] - o.polygon[:, 1]])
    d = "M " + " L ".join(f"{x:.5f},{y:.5f}" for x, y in pts) + " Z"
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w:.5f}mm" height="{h:.5f}mm" '
            f'viewBox="0 0 {w:.5f} {h:.5f}">\n'
            f'  <title>{o.name}: cutting outline, true scale, mm; plate {o.thickness:g} mm</title>\n'
            f'  <path id="{o.name}" d="{d}" fill="none" stroke="#ff0000" stroke-width="0.1"/>\n'
            f'</svg>\n').encode()
