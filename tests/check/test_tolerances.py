"""rigcad.check.tolerances on a hand-made report (no tracing; milliseconds): each row's key, reading,
limit, relation, unit, file:line and hint, the rows that appear only with a mesh reading, a tower or
a Monte Carlo, a row's verdict at its edges, and the one CheckError naming every failed row. The
rows on real reports of every shipped profile are tested in test_raycheck.py."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from rigcad.check.tolerances import Row, evaluate, raise_if_failed
from rigcad.errors import CheckError
from rigcad.units import DEG

WHERE = {("raycheck", "max_spot_radius"): "p.yaml:10", ("raycheck", "max_angle_error"): "p.yaml:11",
         ("raycheck", "max_facet_spot_radius"): "p.yaml:12", ("raycheck", "max_mesh_angle_error"): "p.yaml:13",
         ("raycheck", "theta_coverage_tolerance"): "p.yaml:14", ("raycheck", "min_px_per_deg"): "p.yaml:15",
         ("raycheck", "max_lost_fraction"): "p.yaml:16", ("tessellation", "mirror_normal_error"): "p.yaml:20",
         ("beam_splitter", "thickness"): "p.yaml:30", ("tower", "clearance"): "p.yaml:31",
         ("tolerancing", "min_yield"): "p.yaml:40"}


def _profile(mode="analytic", where=WHERE):
    rc = SimpleNamespace(mode=mode, max_spot_radius=0.05, max_angle_error=0.2 * DEG, max_facet_spot_radius=0.5,
                         max_mesh_angle_error=0.1 * DEG, theta_coverage_tolerance=1.5 * DEG, min_px_per_deg=2.0,
                         max_lost_fraction=0.25)
    return SimpleNamespace(raycheck=rc, targets=SimpleNamespace(theta_min=10 * DEG, theta_max=80 * DEG),
                           tolerancing=SimpleNamespace(min_yield=0.9),
                           tessellation=SimpleNamespace(mirror_chord_error=0.01, mirror_normal_error=0.002),
                           where=lambda *key: where.get(key))


def _reading(spot=0.01, angle=0.1 * DEG, lo=11.0, hi=79.0, lost=0.1, mesh=None):
    r = {"max_spot_radius_mm": spot, "max_angle_error_rad": angle, "theta_min_deg": lo, "theta_max_deg": hi,
         "lost_fraction": lost}
    if mesh is not None:
        r["mesh_minus_exact_angle_rad"] = {"max": mesh}
    return r


def _report(mode="analytic", px=3.0, **kw):
    return {"readings": {mode: _reading(**kw)}, "pixels_per_degree": {"px_per_deg_min": px}}


def test_the_analytic_rows_name_their_keys_readings_and_limits():
    rows = evaluate(_profile(), _report())
    assert [r.as_dict() for r in rows] == [
        {"check": "spot radius (pinhole, max)", "profile_key": "raycheck.max_spot_radius", "measured": 0.01,
         "limit": 0.05, "relation": "<=", "unit": "mm", "where": "p.yaml:10", "ok": True},
        {"check": "angle error vs design (pinhole, max)", "profile_key": "raycheck.max_angle_error",
         "measured": pytest.approx(0.1), "limit": pytest.approx(0.2), "relation": "<=", "unit": "deg",
         "where": "p.yaml:11", "ok": True},
        {"check": "smallest theta traced (targets.theta_min 10 + 1.5)", "profile_key": "raycheck.theta_coverage_tolerance",
         "measured": 11.0, "limit": pytest.approx(11.5), "relation": "<=", "unit": "deg", "where": "p.yaml:14",
         "ok": True},
        {"check": "largest theta traced (targets.theta_max 80 - 1.5)", "profile_key": "raycheck.theta_coverage_tolerance",
         "measured": 79.0, "limit": pytest.approx(78.5), "relation": ">=", "unit": "deg", "where": "p.yaml:14",
         "ok": True},
        {"check": "pixels per degree (min along theta)", "profile_key": "raycheck.min_px_per_deg", "measured": 3.0,
         "limit": 2.0, "relation": ">=", "unit": "px/deg", "where": "p.yaml:15", "ok": True},
        {"check": "rays lost (occluded, escaped)", "profile_key": "raycheck.max_lost_fraction", "measured": 0.1,
         "limit": 0.25, "relation": "<=", "unit": "", "where": "p.yaml:16", "ok": True},
    ]


def test_the_designs_theta_range_is_held_to_the_targets_themselves():
    """The newcomer's case: the design reaches theta 10.3 deg against targets.theta_min 10 deg, while
    the traced rays' coverage row lets it through (11.0 within 10 + 1.5): the design's own range is
    exact, so its rows take no coverage tolerance and fail it, naming the targets' keys and lines."""
    where = {**WHERE, ("targets", "theta_min"): "p.yaml:50", ("targets", "theta_max"): "p.yaml:51"}
    report = {**_report(), "design_range": {"theta_min_deg": 10.3, "theta_max_deg": 80.0}}
    rows = {r.key: r for r in evaluate(_profile(where=where), report)}
    cov = [r for r in evaluate(_profile(where=where), report) if r.key == "raycheck.theta_coverage_tolerance"]
    assert all(r.ok for r in cov)  # the traced rows alone would pass it
    lo, hi = rows["targets.theta_min"], rows["targets.theta_max"]
    assert not lo.ok and lo.measured == 10.3 and lo.where == "p.yaml:50", lo
    assert "targets.theta_min >= 10.3 deg would pass" in lo.hint and "layout.sample_to_rim" in lo.hint, lo.hint
    assert hi.ok and hi.where == "p.yaml:51"  # 80 reaches 80: only float rounding is allowed for
    report["design_range"] = {"theta_min_deg": 10.0 + 1e-6, "theta_max_deg": 80.0 - 1e-6}
    rows = {r.key: r for r in evaluate(_profile(where=where), report)}
    # a micro-degree short is short: the slack is float rounding (1e-9 rad = 5.7e-8 deg), no tolerance
    assert not rows["targets.theta_min"].ok and not rows["targets.theta_max"].ok
    with pytest.raises(CheckError, match=r"targets\.theta_min \(p\.yaml:50\)"):
        raise_if_failed(list(rows.values()), "p")


def test_each_failed_rows_hint():
    rows = evaluate(_profile(), _report(spot=0.06, angle=0.3 * DEG, lo=12.0, hi=78.0, lost=0.3, px=1.0))
    assert not any(r.ok for r in rows)
    assert [r.as_dict()["hint"] for r in rows] == [
        "reading analytic; the design itself", "reading analytic",
        "traced theta from 12.00 deg; targets.theta_min 10 deg",
        "traced theta up to 78.00 deg; targets.theta_max 80 deg",
        "projector.throw_ratio (a longer throw), projector.resolution or the paraboloid's size set it; "
        "raycheck.min_px_per_deg <= 1 would pass",
        "see readings.<mode>.losses for where; the beam's width sets most of it"]
    assert "hint" not in Row("a", "k", 1.0, 0.0, ">=", "", None, "why").as_dict()  # hints only on failure
    assert "hint" not in Row("a", "k", 1.0, 2.0, ">=", "", None).as_dict()  # and only when there is one


def test_a_rows_verdict_at_its_edges():
    assert Row("a", "k", 1.0, 1.0, "<=", "", None).ok and Row("a", "k", 1.0, 1.0, ">=", "", None).ok
    assert not Row("a", "k", math.nextafter(1.0, 2), 1.0, "<=", "", None).ok
    assert not Row("a", "k", math.nextafter(1.0, 0), 1.0, ">=", "", None).ok
    for bad in (math.nan, math.inf, -math.inf):
        assert not Row("a", "k", bad, 1.0, "<=", "", None).ok and not Row("a", "k", bad, 1.0, ">=", "", None).ok


def test_a_mesh_mode_adds_the_facet_and_mesh_minus_exact_rows():
    for mode in ("mesh", "smooth"):
        rep = _report(mode, mesh=0.05 * DEG)
        rep["readings"].setdefault("mesh", _reading())["max_spot_radius_mm"] = 0.7
        rep["readings"][f"{mode}_paraboloid_mesh_only"] = {"mesh_minus_exact_angle_rad": {"max": 0.02 * DEG}}
        rep["readings"][f"{mode}_dome_mesh_only"] = {"mesh_minus_exact_angle_rad": {"max": 0.04 * DEG}}
        rows = evaluate(_profile(mode), rep)
        tess = "mirror meshes at tessellation.mirror_chord_error 0.01 mm / mirror_normal_error 0.002 rad (p.yaml:20)"
        assert rows[0].hint == f"reading {mode}; {tess}: tighten them"
        facet, mesh = rows[2], rows[3]
        assert (facet.name, facet.key, facet.measured, facet.limit, facet.relation, facet.unit, facet.where,
                facet.hint, facet.ok) == (
            "spot radius, flat facets (STL-literal, max)", "raycheck.max_facet_spot_radius", 0.7, 0.5, "<=", "mm",
            "p.yaml:12", f"{tess}: tighten mirror_normal_error", False)
        assert (mesh.name, mesh.key, mesh.relation, mesh.unit, mesh.where, mesh.ok) == (
            "mesh minus exact angle error (max)", "raycheck.max_mesh_angle_error", "<=", "deg", "p.yaml:13", True)
        assert (mesh.measured, mesh.limit) == pytest.approx((0.05, 0.1), rel=1e-12)
        assert mesh.hint == (f"{tess}; the dome mesh alone gives 0.04 deg: tighten "
                             "tessellation.mirror_normal_error and mirror_chord_error")
        assert len(rows) == 8
    # the paraboloid's mesh the worse: it is the one named
    rep["readings"]["smooth_paraboloid_mesh_only"]["mesh_minus_exact_angle_rad"]["max"] = 0.06 * DEG
    assert "the paraboloid mesh alone gives 0.06 deg" in evaluate(_profile("smooth"), rep)[3].hint
    # a mesh reading in analytic mode adds the facet row only; no tessellation key set: "default"
    rep = _report()
    rep["readings"]["mesh"] = {"max_spot_radius_mm": 0.1}
    where = {k: v for k, v in WHERE.items() if k[0] != "tessellation"}
    rows = evaluate(_profile(where=where), rep)
    assert len(rows) == 7 and rows[2].key == "raycheck.max_facet_spot_radius" and rows[2].ok
    assert rows[2].hint == ("mirror meshes at tessellation.mirror_chord_error 0.01 mm / mirror_normal_error "
                            "0.002 rad (default): tighten mirror_normal_error")
    both = {**WHERE, ("tessellation", "mirror_chord_error"): "p.yaml:19"}
    assert "rad (p.yaml:19, p.yaml:20)" in evaluate(_profile(where=both), rep)[2].hint


def test_the_tower_and_monte_carlo_rows():
    rep = _report()
    rep["tower"] = {
        "camera_through_splitter": {"max_spot_radius_mm": 0.04, "max_mirror_angle_error_rad": 0.25 * DEG,
                                    "max_angle_error_rad": 1.5 * DEG},
        "bundle_clearance": {"projector": {"blocked": 2, "blocked_by": ["shelf"]},
                             "projector_widened": {"blocked": 3, "blocked_by": ["shelf", "column"]},
                             "camera": {"blocked": 0, "blocked_by": []}}}
    rep["monte_carlo"] = {"yield": 0.85, "max_spot_radius_mm": {"p90": 0.0123456},
                          "max_mirror_angle_error_rad": {"p90": 0.5 * DEG}}
    rows = evaluate(_profile(), rep)
    cam_spot, cam_angle, tower, mc = rows[6:]
    assert (cam_spot.name, cam_spot.key, cam_spot.measured, cam_spot.limit, cam_spot.relation, cam_spot.unit,
            cam_spot.where, cam_spot.ok) == (
        "camera via splitter: spot radius (max)", "raycheck.max_spot_radius", 0.04, 0.05, "<=", "mm", "p.yaml:10", True)
    assert cam_spot.hint == "the plate's astigmatism (beam_splitter.thickness, p.yaml:30): a thinner plate"
    assert (cam_angle.name, cam_angle.key, cam_angle.unit, cam_angle.where, cam_angle.ok) == (
        "camera via splitter: angle error, calibrated (max)", "raycheck.max_angle_error", "deg", "p.yaml:11", False)
    assert (cam_angle.measured, cam_angle.limit) == pytest.approx((0.25, 0.2), rel=1e-12)
    assert cam_angle.hint == ("against the paraboloid point each camera ray meets (thesis 4.1.1); uncalibrated "
                              "1.5 deg; a thinner beam_splitter.thickness")
    assert (tower.name, tower.key, tower.measured, tower.limit, tower.relation, tower.unit, tower.where, tower.ok) == (
        "tower parts in the ray bundles (rays)", "tower.clearance", 5.0, 0.0, "<=", "", "p.yaml:31", False)
    assert tower.hint == "blocked by column, shelf: move them or raise tower.splitter_distance"
    assert (mc.name, mc.key, mc.measured, mc.limit, mc.relation, mc.unit, mc.where, mc.ok) == (
        "Monte Carlo yield (spot and mirror angle targets)", "tolerancing.min_yield", 0.85, 0.9, ">=", "",
        "p.yaml:40", False)
    assert mc.hint == "p90 spot 0.0123 mm, p90 angle 0.5 deg: tighten the tolerancing.* placements"
    rep["tower"]["bundle_clearance"]["camera"] = {"blocked": 1, "blocked_by": ["lens"]}
    assert evaluate(_profile(), rep)[8].measured == 6.0
    where = {k: v for k, v in WHERE.items() if k[0] != "beam_splitter"}
    assert "(beam_splitter.thickness, default)" in evaluate(_profile(where=where), rep)[6].hint


def test_every_failed_row_is_named_in_one_check_error():
    rows = [Row("spot", "raycheck.max_spot_radius", 0.06, 0.05, "<=", "mm", "p.yaml:10", "tighten"),
            Row("fine", "raycheck.x", 1.0, 2.0, "<=", "mm", None, "never shown"),
            Row("px", "raycheck.min_px_per_deg", 1.0, 2.0, ">=", "px/deg", None, "bigger")]
    with pytest.raises(CheckError) as e:
        raise_if_failed(rows, "rig")
    assert str(e.value) == ("rig: 2 ray-check tolerance(s) not met: raycheck.max_spot_radius (p.yaml:10): spot 0.06 mm "
                            "not <= 0.05 mm; tighten | raycheck.min_px_per_deg (default): px 1 px/deg not >= 2 "
                            "px/deg; bigger")
    assert raise_if_failed(rows[1:2], "rig") is None
