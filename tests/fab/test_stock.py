"""Sanding stock in the print (issue 14, item 2): every printed mirror surface moved forward, into
the light, by the stock; checked on the printed meshes against the exact profile, by volume, and
the templates that gauge each stage."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from rigcad.errors import ProfileError
from rigcad.fab.printers import load_printer

MK3S = """process: fdm
build_volume: {x: 250 mm, y: 210 mm, z: 210 mm}
layer_height: 0.15 mm
nozzle: 0.4 mm
material_density_g_cm3: 1.24
deposition_rate_mm3_s: 8
"""


def _stl_vertices(path) -> np.ndarray:
    data = path.read_bytes()
    n = struct.unpack_from("<I", data, 80)[0]
    rec = np.frombuffer(data, [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")], n, 84)
    return rec["v"].astype(np.float64)  # (n, 3, 3)


def test_the_printer_key_reads_auto_or_a_length_and_refuses_the_rest(tmp_path):
    assert load_printer("prusa_mk3s").sanding_stock is None  # auto by default
    path = tmp_path / "p.yaml"
    path.write_text(MK3S + "sanding_stock: 4 mil\n")
    assert abs(load_printer(path).sanding_stock - 0.1016) < 1e-12  # 4 mil = 0.1016 mm, exact conversion
    path.write_text(MK3S + "sanding_stock: 0.1\n")
    with pytest.raises(ProfileError, match=r"p.yaml:7.*sanding_stock"):
        load_printer(path)
    path.write_text(MK3S + "sanding_stock: 3 mm\n")
    with pytest.raises(ProfileError, match=r"p.yaml:7.*sanding_stock.*<= 2 mm"):
        load_printer(path)


def test_the_layout_moves_only_the_mirrors(table31_rig):
    lay = table31_rig.layout
    moved = lay.with_sanding_stock(dome=0.09, paraboloid=0.05)
    u = np.linspace(*lay.design_dome.u_range, 50)
    # the moved mirror lies 0.09 mm in front (on the reflecting side) of the sanded surface
    d = moved.printed_dome.distance(moved.as_printed_dome.points(u))
    assert np.allclose(d, 0.09, atol=1e-9)  # parallel curves: exact up to the foot-point solver
    assert moved.dome_outer is lay.dome_outer and moved.paraboloid_back_z == lay.paraboloid_back_z
    assert lay.as_printed_dome is lay.printed_dome  # no stock: the design exports are unchanged


@pytest.mark.e2e  # reads the shared fab run of the dome and small parts (prusa_run): make test-e2e
def test_the_fab_mirrors_lie_the_stock_in_front_of_the_sanded_surface(prusa_run, table31_rig, prusa):
    """Measured on the printed STLs (print position undone) against the exact profiles: the
    vertices on the mirror lie the stock in front of the surface the coating goes on (which the
    coating brings to the design surface); facets depart by at most the chord error."""
    out, res = prusa_run
    rep = json.loads((out / "fab.json").read_text())
    lay = table31_rig.layout
    chord = rep["tolerances"]["stl_chord_error_mm"]
    for part, design in (("dome", lay.design_dome), ("paraboloid", lay.design_paraboloid)):
        e = rep["parts"][part]
        st = e["sanding_stock"]
        stock = st["stock_mm"]
        # auto: the staircase's bound, layer/2 x max|n.D| + chord (between the chord and a layer + chord),
        # the seams' step on the gluing gauge (a split mirror's) and one feeler leaf
        assert chord < st["needed_bound_mm"] <= prusa.layer_height / 2 + chord + 1e-12
        assert stock == pytest.approx(st["needed_bound_mm"] + st["seam_step_mm"] + st["sanding_margin_mm"], abs=1e-12)
        sanded = design.behind(lay.coating)
        area = 0.0
        for pc in e["pieces"]:
            tri = _stl_vertices(out / "stl" / f"{pc['name']}.stl")
            tr = pc["print_transform"]
            rot, shift = np.array(tr["rotation"]), np.array(tr["translation_mm"])
            p = (tri.reshape(-1, 3) - shift) @ rot  # back to the part frame: R^T (p - t)
            d = sanded.distance(np.column_stack([np.hypot(p[:, 0], p[:, 1]), p[:, 2]])).reshape(-1, 3)
            # on the mirror: within the chord error of the stocked surface (the split's cuts put
            # vertices on the facets along the cut edges)
            on = (np.abs(d - stock) < chord).all(axis=1)
            # the mesh's own vertices lie on it: float32 STL coordinates (~2e-5 mm at 300 mm) and the
            # B-spline fit (0.1 um) bound 1e-4 mm; the cut-edge vertices are a small share
            assert np.mean(np.abs(d[on] - stock) < 1e-4) > 0.95, pc["name"]
            t = tri[on]
            cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
            area += 0.5 * np.linalg.norm(cross, axis=1).sum()
            # nothing of the print stands further into the light than the stock and the chord error
            # (the split's cuts put vertices on the facets, which lie in front of a concave mirror)
            assert d.max() <= stock + chord, (pc["name"], d.max(), stock)
            # facet centres: within the chord error of the stocked surface
            c = p.reshape(-1, 3, 3)[on].mean(axis=1)
            dc = sanded.distance(np.column_stack([np.hypot(c[:, 0], c[:, 1]), c[:, 2]]))
            assert np.abs(dc - stock).max() <= chord, (pc["name"], np.abs(dc - stock).max())
        # those faces are the whole mirror: the stocked surface's area of revolution (its meridian's
        # 2 pi r ds), within 0.5 % (the chord error and the cut edges). Not the report's area before
        # the stock: the stock changes it by ~ stock x (k1 + k2), 1.2 % on the paraboloid's convex
        # 16 mm mirror at 0.113 mm (it grows), -0.2 % on the concave dome at 0.159 mm
        pts = sanded.behind(-stock).points(sanded.behind(-stock).sample(20001))
        exact = float(np.sum(np.pi * (pts[1:, 0] + pts[:-1, 0]) * np.hypot(*np.diff(pts, axis=0).T)))
        assert abs(area - exact) < 0.005 * area, (part, area, exact)
        # volumes grow by mirror area x stock within 1 % (the thin shell; curvature is second order)
        assert abs(st["volume_added_over_area_times_stock"] - 1) < 0.01, st
        # the staircase on the stocked slices leaves no valley behind the sanded surface
        assert st["valley_behind_sanded_surface_mm"] == 0.0, st


@pytest.mark.e2e  # reads the shared fab run of the dome and small parts (prusa_run): make test-e2e
def test_the_templates_gauge_every_stage(prusa_run, table31_rig):
    out, _ = prusa_run
    rep = json.loads((out / "fab.json").read_text())
    coating = table31_rig.layout.coating
    for name, mirror in (("dome_template", "dome"), ("paraboloid_template", "paraboloid")):
        stages = rep["parts"][name]["stages"]
        stock = rep["parts"][mirror]["sanding_stock"]["stock_mm"]
        assert stages["sanded"]["depth_behind_design_mm"] == coating
        assert abs(stages["printed"]["depth_behind_design_mm"] - (coating - stock)) < 1e-12
        assert stages["coated"]["depth_behind_design_mm"] < coating  # the clearcoat, under the mirror paint
        blobs = [(out / f).read_bytes() for st in ("printed", "sanded") for f in stages[st]["files"]]
        blobs.append((out / "outlines" / f"{name}.dxf").read_bytes())
        assert len(set(blobs)) == len(blobs)  # three different edges


def test_a_fixed_stock_from_the_printer_file(table31_rig, tmp_path):
    from rigcad.fab.stage import run_fab

    path = tmp_path / "printers" / "p.yaml"
    path.parent.mkdir()
    path.write_text(MK3S + "sanding_stock: 0 mm\n")
    res = run_fab(table31_rig, load_printer(path), tmp_path / "a", parts=["paraboloid", "paraboloid_template"])
    e = res.report["parts"]["paraboloid"]
    assert e["sanding_stock"]["stock_mm"] == 0.0 and abs(e["sanding_stock"]["volume_added_mm3"]) < 1e-6
    exported = table31_rig.mesh("paraboloid").volume
    assert abs(e["volume_mm3"] - exported) < 1e-6 * exported  # no stock: the design part
    assert res.report["parts"]["paraboloid_template"]["stages"]["printed"]["depth_behind_design_mm"] == \
        table31_rig.layout.coating
