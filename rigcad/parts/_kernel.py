"""The one place (with rigcad.export.step) that touches OpenCascade: recipe -> exact B-rep.

Mirror curves become C2 cubic B-splines fitted to the exact meridian (GeomAPI_PointsToBSpline,
chord-length parameters) and each fit is measured against the exact curve. No Geom_OffsetCurve
ever enters the topology: offsets are taken on the exact meridian before fitting, because OCCT's
STEP writer drops faces of revolution built on offset curves (build123d #939, #1353).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from OCP.Approx import Approx_ChordLength
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon,
                                BRepBuilderAPI_MakeWire, BRepBuilderAPI_Transform)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.BRepPrimAPI import (BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakePrism,
                             BRepPrimAPI_MakeRevol)
from OCP.GeomAbs import GeomAbs_C2
from OCP.GeomAPI import GeomAPI_PointsToBSpline, GeomAPI_ProjectPointOnCurve
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.GProp import GProp_GProps
from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
from OCP.TColgp import TColgp_Array1OfPnt
from OCP.TopAbs import TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Shape
from OCP.TopTools import TopTools_ListOfShape

from rigcad.errors import GeometryError, KernelError
from rigcad.parts.recipe import (Box, Curve, Cylinder, Difference, HexPrism, Line, Part, Prism, Revolve, Section, Solid,
                                 Translate, Union_)

#: Points of the exact curve given to each B-spline fit, and (more) used to measure it.
FIT_POINTS = 1001
CHECK_POINTS = 4001


@dataclass
class FitReport:
    """B-spline fits made while building one part: max distance (mm) from the exact curve."""

    fits: list[dict] = field(default_factory=list)

    @property
    def max_error(self) -> float:
        return max((f["max_error_mm"] for f in self.fits), default=0.0)


def _xz(p) -> gp_Pnt:
    return gp_Pnt(float(p[0]), 0.0, float(p[1]))


def fit_curve(curve: Curve, tol: float, report: FitReport):
    """C2 cubic B-spline through the exact curve within ``tol`` mm, end points exact; measured."""
    pts = curve.dense(FIT_POINTS)
    arr = TColgp_Array1OfPnt(1, len(pts))
    for i, p in enumerate(pts, 1):
        arr.SetValue(i, _xz(p))
    fit = GeomAPI_PointsToBSpline(arr, Approx_ChordLength, 3, 3, GeomAbs_C2, tol)
    if not fit.IsDone():
        raise GeometryError(f"B-spline fit of the {curve.meridian.kind} profile failed at tolerance {tol:g} mm")
    spline = fit.Curve()
    check = curve.dense(CHECK_POINTS)
    proj = GeomAPI_ProjectPointOnCurve()
    worst = 0.0
    for p in check:
        proj.Init(_xz(p), spline)
        worst = max(worst, proj.LowerDistance() if proj.NbPoints() else math.inf)
    ends = max(spline.StartPoint().Distance(_xz(pts[0])), spline.EndPoint().Distance(_xz(pts[-1])))
    report.fits.append({"curve": curve.meridian.kind, "offset_mm": curve.meridian.offset, "poles": spline.NbPoles(),
                        "max_error_mm": worst, "end_gap_mm": ends, "checked_points": len(check)})
    return spline


def _face(section: Section, tol: float, report: FitReport):
    wire = BRepBuilderAPI_MakeWire()
    for seg in section.segments:
        if isinstance(seg, Line):
            edge = BRepBuilderAPI_MakeEdge(_xz(seg.p0), _xz(seg.p1)).Edge()
        else:
            edge = BRepBuilderAPI_MakeEdge(fit_curve(seg, tol, report)).Edge()
        wire.Add(edge)
    if not wire.IsDone():
        raise GeometryError("a part's cross-section does not close into a wire (kernel)")
    face = BRepBuilderAPI_MakeFace(wire.Wire(), True)
    if not face.IsDone():
        raise GeometryError("a part's cross-section is not a planar face (kernel)")
    return face.Face()


def _list(shapes) -> TopTools_ListOfShape:
    out = TopTools_ListOfShape()
    for s in shapes:
        out.Append(s)
    return out


def _boolean(op, base: TopoDS_Shape, tools: list[TopoDS_Shape]) -> TopoDS_Shape:
    b = op()
    b.SetArguments(_list([base]))
    b.SetTools(_list(tools))
    b.Build()
    if not b.IsDone():
        raise GeometryError(f"boolean {op.__name__} failed in the kernel")
    unify = ShapeUpgrade_UnifySameDomain(b.Shape(), True, True, False)
    unify.Build()
    return unify.Shape()


def build(solid: Solid, tol: float, report: FitReport) -> TopoDS_Shape:
    """The exact B-rep of a recipe tree (mm)."""
    if isinstance(solid, Revolve):
        face = _face(solid.section, tol, report)
        return BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2 * math.pi, False).Shape()
    if isinstance(solid, Prism):
        face = _face(solid.section, tol, report)
        t = gp_Trsf()
        t.SetTranslation(gp_Vec(0, -solid.thickness / 2, 0))
        moved = BRepBuilderAPI_Transform(face, t, True).Shape()
        return BRepPrimAPI_MakePrism(moved, gp_Vec(0, solid.thickness, 0)).Shape()
    if isinstance(solid, Box):
        return BRepPrimAPI_MakeBox(gp_Pnt(*solid.lo), gp_Pnt(*solid.hi)).Shape()
    if isinstance(solid, Cylinder):
        ax = gp_Ax2(gp_Pnt(*solid.base), gp_Dir(0, 0, 1))
        return BRepPrimAPI_MakeCylinder(ax, solid.radius, solid.height).Shape()
    if isinstance(solid, HexPrism):
        poly = BRepBuilderAPI_MakePolygon()
        for x, y in solid.corners():
            poly.Add(gp_Pnt(x, y, solid.base[2]))
        poly.Close()
        face = BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
        return BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, solid.height)).Shape()
    if isinstance(solid, Union_):
        shapes = [build(s, tol, report) for s in solid.items]
        return shapes[0] if len(shapes) == 1 else _boolean(BRepAlgoAPI_Fuse, shapes[0], shapes[1:])
    if isinstance(solid, Difference):
        return _boolean(BRepAlgoAPI_Cut, build(solid.base, tol, report), [build(s, tol, report) for s in solid.cuts])
    if isinstance(solid, Translate):
        t = gp_Trsf()
        t.SetTranslation(gp_Vec(*solid.offset))
        return BRepBuilderAPI_Transform(build(solid.solid, tol, report), t, True).Shape()
    raise TypeError(f"unknown recipe node {type(solid).__name__}")


def volume(shape: TopoDS_Shape) -> float:
    """Volume (mm^3) by adaptive Gauss integration; OCCT's default fixed-order rule can be off by
    percent on B-spline faces, so a relative precision is always given."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    return props.Mass()


def solids(shape: TopoDS_Shape) -> int:
    """Number of solids in a shape."""
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    n = 0
    while exp.More():
        n += 1
        exp.Next()
    return n


def single_solid(shape: TopoDS_Shape) -> TopoDS_Shape:
    """The one solid inside ``shape`` (booleans return compounds); raises if there is not exactly one."""
    from OCP.TopoDS import TopoDS

    found = []
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    while exp.More():
        found.append(TopoDS.Solid_s(exp.Current()))
        exp.Next()
    if len(found) != 1:
        raise GeometryError(f"expected one solid, the kernel produced {len(found)}")
    return found[0]


def is_valid(shape: TopoDS_Shape) -> bool:
    """OCCT's BRepCheck verdict."""
    return BRepCheck_Analyzer(shape).IsValid()


def part_solid(part: Part, tol: float, report: FitReport, profile=None) -> TopoDS_Shape:
    """The one valid solid of ``part``'s recipe (B-spline fits at ``tol`` mm, recorded in ``report``).
    Any kernel failure (OCCT's Standard_Failure family, such as StdFail_NotDone or
    Standard_DomainError; a boolean that
    fails; a result that is not exactly one solid, or not valid) becomes a KernelError naming the
    part, the profile keys that shaped it (with the first one's file:line when ``profile`` is
    given) and what to try."""
    try:
        shape = single_solid(build(part.solid, tol, report))
    except GeometryError as err:
        raise kernel_error(part, err.message, profile) from err
    except Exception as err:
        # OCP raises OCCT's Standard_Failure family (StdFail_NotDone, Standard_DomainError, ...) as
        # classes of its own that all derive from Exception alone: recognised by their module
        if not type(err).__module__.startswith("OCP"):
            raise
        raise kernel_error(part, f"{type(err).__name__}: {str(err).strip() or 'no message'}", profile) from err
    if not is_valid(shape):
        raise kernel_error(part, "the solid it produced is not valid (BRepCheck)", profile)
    return shape


def kernel_error(part: Part, what: str, profile=None) -> KernelError:
    keys = list(part.shaped_by)
    where = None
    if profile is not None:
        marked = [k for k in keys if tuple(k.split(".")) in profile.marks]
        if marked:  # a key the user set is the likeliest cause: name it first
            keys = marked + [k for k in keys if k not in marked]
            where = profile.marks[tuple(marked[0].split("."))]
    shaped = ", ".join(keys[:6]) + (", ..." if len(keys) > 6 else "") if keys else "the layout"
    return KernelError(f"part {part.name!r}: OpenCascade could not build it ({what}). It is shaped by {shaped} "
                       "(and the mirrors' layout): look for a size near zero, a clearance or offset that cuts it "
                       f"apart, or features that no longer overlap; change {keys[0] if keys else 'the profile'} "
                       "and build again", where=where, param=keys[0] if keys else None)


def polylines(lines) -> TopoDS_Shape:
    """Polylines (k, m, 3) mm (k rays of m points each) as one compound of k wires of straight edges,
    for a viewer that shows B-rep shapes (an OCP CAD Viewer); consecutive equal points are skipped."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon
    from OCP.TopoDS import TopoDS_Compound

    builder = BRep_Builder()
    compound = TopoDS_Compound()
    builder.MakeCompound(compound)
    for line in lines:
        polygon = BRepBuilderAPI_MakePolygon()
        for x, y, z in line:
            polygon.Add(gp_Pnt(float(x), float(y), float(z)))
        if polygon.IsDone():
            builder.Add(compound, polygon.Wire())
    return compound
