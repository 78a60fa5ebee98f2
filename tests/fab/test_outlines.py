"""Template outlines: DXF and SVG re-read at true scale, deterministic."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import ezdxf
import numpy as np
import pytest

from rigcad.fab.outlines import dxf_bytes, outline, svg_bytes
from rigcad.parts import PARTS


def _depth_of_gauged_surface(profile) -> float:
    """mm behind the design surface: the coating layers above the gauged one (the schema's
    definition, restated here rather than read from rigcad.parts.templates)."""
    names = [n for n, _ in profile.coating.layers]
    above = profile.coating.layers[names.index(profile.templates.gauged_layer) + 1:]
    return float(sum(t for _, t in above))


def _paraboloid_offset(geometry, depth: float, count: int) -> np.ndarray:
    """The closed form: z = z_v - r^2 / (4 f) (thesis 3.2), moved ``depth`` mm behind along its unit
    normal (r / 2f, 1) / |.|, for signed r across the whole template (both halves)."""
    f, zv, rim = geometry.focal_length, geometry.vertex_z, geometry.rim_radius
    r = np.linspace(-rim, rim, count)
    n = np.column_stack([r / (2 * f), np.ones_like(r)])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return np.column_stack([r, zv - r * r / (4 * f)]) - depth * n


def _distance_to_polyline(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Distance (mm) from each point to a dense reference polyline: to the two segments beside
    the nearest reference vertex (exact while the reference is much denser than the distances
    looked for are long)."""
    from scipy.spatial import cKDTree

    _, i = cKDTree(ref).query(points)
    best = np.full(len(points), np.inf)
    for a, b in ((np.maximum(i - 1, 0), i), (i, np.minimum(i + 1, len(ref) - 1))):
        pa, ab = ref[a], ref[b] - ref[a]
        t = np.clip(np.sum((points - pa) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0, 1)
        best = np.minimum(best, np.linalg.norm(points - (pa + t[:, None] * ab), axis=1))
    return best


# Reference curves are sampled this densely: 200,001 points over <= 400 mm are <= 2e-3 mm apart, and
# on radii of curvature >= 5.9 mm (the mirrors' smallest) the dense polyline is within
# (2e-3)^2 / (8 * 5.9) = 1e-7 mm of the curve. So "on the curve" below is 1e-6 mm.
REF_SAMPLES = 200_001
ON_CURVE_MM = 1e-6
#: The DXF's splines interpolate 200 points of each curve (outlines.SPLINE_POINTS): a cubic's error
#: between them goes as h^4 (h ~ 1 mm); measured 2.4e-7 mm at most; a tenth of the chord error
#: leaves room while still catching a spline that is not the curve.
SPLINE_ON_CURVE_MM = 0.0018


def _reference_curves(name, table31, layout, geometry) -> list[np.ndarray]:
    depth = _depth_of_gauged_surface(table31)
    if name == "paraboloid_template":
        return [_paraboloid_offset(geometry, depth, REF_SAMPLES)]
    # the dome has no closed form: its meridian (rigcad.optics, tested against the thesis's
    # construction in tests/optics) is the reference; the gauged surface and the template's
    # front edge, band mm in front of it, both from where the gauged surface meets the sample plane
    # (z = 0) to the dome's top
    from rigcad.parts.layout import u_at_height

    g = layout.design_dome.behind(depth)
    front = g.behind(-table31.templates.band)
    u = np.linspace(u_at_height(g, 0.0), g.u_range[1], REF_SAMPLES)
    return [m.points(u) for m in (g, front)]


def test_dxf_rereads_at_true_scale(table31, table31_rig, layout, tmp_path):
    chord = table31.tessellation.chord_error
    for name in ("dome_template", "paraboloid_template"):
        part = PARTS[name](table31, layout)
        o = outline(part, chord)
        path = tmp_path / f"{name}.dxf"
        path.write_bytes(dxf_bytes(o))
        doc = ezdxf.readfile(path)  # ezdxf's reader, not the writer's objects
        assert doc.units == ezdxf.units.MM
        cut = [e for e in doc.modelspace() if e.dxftype() == "LWPOLYLINE" and e.dxf.layer == "CUT"]
        assert len(cut) == 1 and cut[0].closed
        pts = np.array([(x, y) for x, y, *_ in cut[0].get_points()])
        # the same numbers as the section (DXF stores 16 significant digits)
        assert np.allclose(pts, o.polygon, atol=1e-9), name
        # and the part's own size (manifest), from the recipe's polygon: width and height in mm
        sec = part.solid.section.polygon(chord)
        assert np.allclose(np.ptp(pts, axis=0), np.ptp(sec, axis=0), atol=1e-9)

        refs = _reference_curves(name, table31, layout, table31_rig.geometry)
        # the mirror curves as cubic B-splines given by control points and knots (no fit points:
        # GDAL reads no other kind), evaluated by ezdxf from the file's numbers, within
        # SPLINE_ON_CURVE_MM of the curves all along, from one end of each curve to the other
        splines = [e for e in doc.modelspace() if e.dxftype() == "SPLINE" and e.dxf.layer == "CURVES"]
        assert len(splines) == 2, (name, len(splines))  # two curves in each template
        ends = []
        for sp in splines:
            assert sp.dxf.degree == 3 and len(sp.fit_points) == 0 and len(sp.control_points) > 3, name
            assert len(sp.knots) == len(sp.control_points) + 4, name  # clamped cubic: n + degree + 1 knots
            along = np.array(list(sp.construction_tool().points(np.linspace(0.0, 1.0, 4001))))
            assert np.all(along[:, 2] == 0.0)  # a 2D drawing
            d = np.min([_distance_to_polyline(along[:, :2], ref) for ref in refs], axis=0)
            assert d.max() < SPLINE_ON_CURVE_MM, (name, d.max())
            ends.append(along[[0, -1], :2])
        ends = np.vstack(ends)
        for ref in refs:
            # each reference curve's two ends are spline ends (within rounding): no piece is missing
            assert np.min(np.linalg.norm(ends[:, None] - ref[[0, -1]][None], axis=2), axis=0).max() < ON_CURVE_MM

        # The cut outline: its curved part is a polyline whose vertices are exact curve points and
        # which stays within the chord error (0.018 mm, tessellation.chord_error: the claim of
        # rigcad.fab.outlines) of the curve. Edges are checked at 9 interior points each.
        on = [(_distance_to_polyline(pts, ref) < ON_CURVE_MM) for ref in refs]
        nxt = np.roll(np.arange(len(pts)), -1)
        worst, covered = 0.0, 0.0
        for ref, is_on in zip(refs, on):
            edge = is_on & is_on[nxt]
            assert edge.sum() > 20, (name, edge.sum())  # a curve, not a few stray vertices
            t = np.linspace(0.1, 0.9, 9)
            a, b = pts[edge], pts[nxt][edge]
            inner = (a[:, None] + t[None, :, None] * (b - a)[:, None]).reshape(-1, 2)
            worst = max(worst, _distance_to_polyline(inner, ref).max())
            # the on-curve edges run the curve's whole length (an inscribed polyline is shorter
            # by ~ (8/3) sag^2 / h per chord: < 0.1 % here)
            length = np.sum(np.linalg.norm(np.diff(ref, axis=0), axis=1))
            covered = np.sum(np.linalg.norm(b - a, axis=1)) / length
            assert 0.999 < covered <= 1.0 + 1e-9, (name, covered)
        assert worst <= chord, (name, worst, chord)


def test_dxf_layers_units_and_note(table31, layout, tmp_path):
    """What the DXF's docstring promises besides the geometry: R2010, millimetres (metric), the
    three layers with their entities, the note naming the part and plate thickness below the
    outline, flat (z = 0) splines."""
    part = PARTS["paraboloid_template"](table31, layout)
    o = outline(part, table31.tessellation.chord_error)
    assert o.name == part.name and o.thickness == part.solid.thickness
    path = tmp_path / "t.dxf"
    before = ezdxf.options.write_fixed_meta_data_for_testing
    path.write_bytes(dxf_bytes(o))
    # the writer fixes ezdxf's dates and GUIDs for its own call only: the global option is restored
    assert ezdxf.options.write_fixed_meta_data_for_testing == before
    doc = ezdxf.readfile(path)
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.header["$MEASUREMENT"] == 1 and doc.header["$INSUNITS"] == 4  # metric, mm
    # CAM reads the layer table: CUT red (1), CURVES green (3), NOTE white (7), ezdxf's ACI numbers
    assert {la.dxf.name: la.dxf.color for la in doc.layers if la.dxf.name in ("CUT", "CURVES", "NOTE")} == \
        {"CUT": 1, "CURVES": 3, "NOTE": 7}
    msp = doc.modelspace()
    assert sorted(e.dxf.layer for e in msp) == ["CURVES", "CURVES", "CUT", "NOTE"]
    [text] = [e for e in msp if e.dxftype() == "TEXT"]
    assert text.dxf.layer == "NOTE" and text.dxf.text == f"paraboloid_template t={o.thickness:g} mm"
    lo = o.polygon.min(axis=0)
    # the note sits under the outline's lower-left corner, clear of the cut (6 mm below, 3 mm high)
    assert tuple(text.dxf.insert)[:2] == pytest.approx((lo[0], lo[1] - 6.0), abs=1e-9)
    assert text.dxf.height == 3.0
    for sp in (e for e in msp if e.dxftype() == "SPLINE"):
        assert np.all(np.array(sp.control_points)[:, 2] == 0.0)  # a 2D drawing
    # the header's extents hold every entity (readers zoom to them); ezdxf's default is +-1e20
    lo3, hi3 = np.array(doc.header["$EXTMIN"]), np.array(doc.header["$EXTMAX"])
    pts = np.vstack([o.polygon, [tuple(text.dxf.insert)[:2]]])
    assert np.all(lo3[:2] <= pts.min(axis=0)) and np.all(pts.max(axis=0) <= hi3[:2])
    # and no more than the text's height (3 mm) and the splines' overshoot beyond the outline's box
    assert np.all(np.abs(lo3[:2] - pts.min(axis=0)) < 3.1) and np.all(np.abs(hi3[:2] - o.polygon.max(axis=0)) < 0.1)


def test_outline_refuses_a_part_that_is_not_flat(table31, layout):
    part = PARTS["beam"](table31, layout)
    with pytest.raises(TypeError, match="beam is not a flat"):
        outline(part, 0.018)


def test_svg_is_true_scale_in_mm(table31, layout):
    part = PARTS["dome_template"](table31, layout)
    o = outline(part, table31.tessellation.chord_error)
    root = ET.fromstring(svg_bytes(o))
    w, h = (float(root.get(k).removesuffix("mm")) for k in ("width", "height"))
    vb = [float(v) for v in root.get("viewBox").split()]
    assert vb[:2] == [0.0, 0.0] and vb[2:] == [w, h]  # one user unit = one mm
    # the document is the outline plus the 2 mm margin on each side (5 decimals: 1e-5 mm)
    assert np.allclose([w, h], np.ptp(o.polygon, axis=0) + 4.0, atol=2e-5)
    path = root.find("{http://www.w3.org/2000/svg}path")
    d = path.get("d")
    # absolute commands: one moveto, a lineto per further vertex, closed
    assert d.startswith("M ") and d.endswith(" Z") and d.count(" L ") == len(o.polygon) - 1
    assert not re.search(r"[a-z]", d)  # no relative (lower-case) command
    assert re.fullmatch(r"M [-\d.]+,[-\d.]+( L [-\d.]+,[-\d.]+)* Z", d), d[:80]  # nothing else in the path
    xy = np.array([[float(a), float(b)] for a, b in re.findall(r"([-\d.]+),([-\d.]+)", d)])
    # each vertex where the drawing puts it: x from the left margin, y flipped from the top margin
    lo, hi = o.polygon.min(axis=0), o.polygon.max(axis=0)
    expect = np.column_stack([o.polygon[:, 0] - lo[0] + 2.0, hi[1] + 2.0 - o.polygon[:, 1]])
    assert np.allclose(xy, expect, atol=2e-5)


def test_dxf_is_the_same_in_every_process():
    """Python salts string hashes per process; the DXF must not depend on it (ezdxf collects its
    CLASS entries in a set). Two interpreters with different PYTHONHASHSEED write the same bytes,
    DXF and SVG (two processes, not two calls in one: a call cannot be its own reference)."""
    import hashlib
    import os
    import subprocess
    import sys

    code = ("import hashlib, rigcad; from rigcad.fab.outlines import dxf_bytes, outline, svg_bytes; "
            "rig = rigcad.load('achutha2006'); "
            "o = outline(rig.recipe('paraboloid_template'), 0.018); "
            "print(hashlib.sha256(dxf_bytes(o) + b'|' + svg_bytes(o)).hexdigest())")
    # this process's bytes too (so mutation testing sees this test call the writers)
    o = outline(PARTS["paraboloid_template"](*_table31_and_layout()), 0.018)
    digests = {hashlib.sha256(dxf_bytes(o) + b"|" + svg_bytes(o)).hexdigest()}
    for seed in ("0", "4"):  # two seeds known to order the classes differently without the fix
        env = {**os.environ, "PYTHONHASHSEED": seed}
        res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        digests.add(res.stdout.strip())
    assert len(digests) == 1, digests
    assert len(next(iter(digests))) == 64  # a sha256 hex digest, not an empty line


def _table31_and_layout():
    import rigcad

    rig = rigcad.load("achutha2006")
    return rig.profile, rig.layout
