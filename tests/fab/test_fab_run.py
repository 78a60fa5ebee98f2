"""One fab run on the desktop printer: every piece fits, the report says what it should, the
outputs are deterministic, and PrusaSlicer accepts every STL."""

from __future__ import annotations

import json
import re
import subprocess

import pytest

from rigcad.errors import FabricationError
from rigcad.fab import slicer as S

from .conftest import have_slicer

NO_SLICER = "prusa-slicer is not installed (apt-get install prusa-slicer); the project's CI installs it"


@pytest.mark.e2e  # reads the shared fab run of the dome and small parts (prusa_run): make test-e2e
def test_report_describes_every_part(prusa_run, prusa):
    out, res = prusa_run
    rep = json.loads((out / "fab.json").read_text())
    assert rep["problems"] == []
    dome = rep["parts"]["dome"]
    assert dome["split"]["pieces"] == 4 and dome["split"]["sectors"] == 4  # the fewest that fit 250 x 210 x 210
    for pc in dome["pieces"]:
        ext = pc["extents_mm"]
        assert ext["x_mm"] <= prusa.usable[0] and ext["y_mm"] <= prusa.usable[1] and ext["z_mm"] <= prusa.usable[2]
        names = {c["orientation"] for c in pc["candidates"]}
        assert {"upright", "upside_down", "axis_horizontal"} <= names  # the three, at least
        s = pc["staircase_from_slices"]
        # slices and closed form agree on the real dome too (5 %, as on the sphere)
        assert abs(s["slices_vs_closed_form_mean_rel_diff"]) < 0.05
        # no cusp exceeds a layer (t |cos| <= t), up to the mesh's chord error
        assert s["cusp_from_slices_max_mm"] <= prusa.layer_height + 0.02
    assert (out / "staircase" / "dome.png").is_file() and (out / "fab.md").is_file()
    for name in ("dome_template", "paraboloid_template"):
        assert (out / "outlines" / f"{name}.dxf").is_file() and (out / "outlines" / f"{name}.svg").is_file()
    # the ranking: the chosen orientation has the least support contact on the mirror of those that
    # fit (none here), then the least closed-form mean cusp among those
    for pc in dome["pieces"] + rep["parts"]["paraboloid"]["pieces"]:
        fit = [c for c in pc["candidates"] if c["fits"]]
        chosen = next(c for c in pc["candidates"] if c["orientation"] == pc["orientation"])
        assert chosen["support_model"]["mirror_mm2"] < 1.0  # MIRROR_SUPPORT_TIE_MM2
        clean = [c for c in fit if c["support_model"]["mirror_mm2"] < 1.0]
        best = min(c["staircase_closed_form"]["cusp_mean_mm"] for c in clean)
        assert chosen["staircase_closed_form"]["cusp_mean_mm"] <= best * (1 + 1e-3)  # CUSP_TIE_RTOL
    # the dome's quarters: lying on their cut face gives less staircase but puts support on
    # ~18,000 mm2 of mirror (the figure); they lie on their backs instead, mirror up
    for pc in dome["pieces"]:
        cand = {c["orientation"]: c for c in pc["candidates"]}
        assert pc["orientation"] == "axis_horizontal"
        assert cand["on_cut_face"]["support_model"]["mirror_mm2"] > 15000


def test_fab_outputs_are_deterministic(table31_rig, prusa, tmp_path):
    from rigcad.fab.stage import run_fab

    parts = ["paraboloid", "beam", "paraboloid_template"]
    a, b = tmp_path / "a", tmp_path / "b"
    run_fab(table31_rig, prusa, a, parts=parts)
    run_fab(table31_rig, prusa, b, parts=parts)
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert files and files == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel


@pytest.mark.e2e  # reads the shared fab run of the dome and small parts (prusa_run): make test-e2e
@pytest.mark.skipif(not have_slicer(), reason=NO_SLICER)
def test_prusaslicer_reads_every_stl_as_a_clean_mesh(prusa_run):
    out, _ = prusa_run
    stls = sorted((out / "stl").glob("*.stl"))
    assert len(stls) >= 8
    for stl in stls:
        proc = subprocess.run(["prusa-slicer", "--info", str(stl)], capture_output=True, text=True, timeout=120)
        info = dict(re.findall(r"^(\w+) = (.*)$", proc.stdout, re.M))
        assert proc.returncode == 0 and info.get("manifold") == "yes", (stl.name, proc.stdout[-500:])
        for key in ("open_edges", "degenerate_facets", "facets_reversed", "backwards_edges", "edges_fixed"):
            assert int(float(info.get(key, 0))) == 0, (stl.name, key, info.get(key))


@pytest.mark.skipif(not have_slicer(), reason=NO_SLICER)
def test_prusaslicer_slices_the_small_parts_deterministically_and_caches(table31_rig, prusa, tmp_path):
    from rigcad.fab.stage import run_fab

    parts = ["paraboloid", "beam", "camera_cross_base", "camera_cross_hung"]  # the sample holder is turned from bar
    res = run_fab(table31_rig, prusa, tmp_path, parts=parts, gcode=True, workers=2)
    assert res.problems == [], res.problems  # no slicer error or warning
    rep = res.report
    first = {p: (tmp_path / "gcode" / f"{p}.gcode").read_bytes() for p in parts}
    for p in parts:
        est = rep["parts"][p]["pieces"][0]["gcode"]["estimates"]
        assert est["print_time_s"] > 0 and est["filament_g"] > 0  # filament_density is in the .ini
        assert not first[p].startswith(b"; generated by PrusaSlicer 2") or b" UTC" not in first[p].split(b"\n")[0]
    # the slicer's own support (read from its G-code) stays off the paraboloid's mirror: printed
    # upright, it has support under its back and in its clamp only
    sc = rep["parts"]["paraboloid"]["pieces"][0]["gcode"]["support_contact"]
    assert sc["support_extruded_length_mm"] > 0 and sc["other_mm2"] > 0
    assert sc["mirror_mm2"] == 0.0, sc
    assert (tmp_path / sc["png"]).is_file()
    again = run_fab(table31_rig, prusa, tmp_path, parts=parts, gcode=True, workers=2)
    assert all(s == 0.0 for s in again.slicer_s.values()), again.slicer_s  # nothing re-sliced
    for p in parts:
        assert (tmp_path / "gcode" / f"{p}.gcode").read_bytes() == first[p]


@pytest.mark.slow
@pytest.mark.skipif(not have_slicer(), reason=NO_SLICER)
def test_prusaslicer_slices_every_piece_of_every_part(table31_rig, prusa, tmp_path):
    """The whole rig on the desktop printer (the dome's quarters take 1-2 min each): every piece
    sliced cleanly; the slicer's own support extrusions touch no mirror outside the band its seams'
    fairing sands (rigcad.fab.seams.SEAM_BAND_MM; the dome's quarters have 0.7-2.4 mm2 of it where
    a seam meets the mirror, next to a pin hole), which run_fab would report as a problem; rigcad's
    estimate within 25 % of PrusaSlicer on every piece."""
    from rigcad.fab import estimate as E
    from rigcad.fab.stage import run_fab

    res = run_fab(table31_rig, prusa, tmp_path, gcode=True)
    assert res.problems == [], res.problems
    for entry in res.report["parts"].values():
        for pc in entry.get("pieces", []):
            g = pc["gcode"]
            assert g["estimates"]["print_time_s"] > 0 and not g["slicer_warnings"]
            if entry["mirror"]:
                sc = g["support_contact"]
                assert sc.get("mirror_off_band_mm2", sc["mirror_mm2"]) == 0.0, (pc["name"], sc)
                # measured 0.7-2.4 mm2 per quarter; support along a whole seam would be hundreds
                assert sc.get("mirror_in_band_mm2", 0.0) < 10.0, (pc["name"], sc)
            t, m = g["estimates"]["print_time_s"], g["estimates"]["filament_g"]
            assert abs(pc["estimate"]["print_time_s"] / t - 1) < E.MAX_REL_ERROR, (pc["name"], pc["estimate"], t)
            assert abs(pc["estimate"]["material_g"] / m - 1) < E.MAX_REL_ERROR, (pc["name"], pc["estimate"], m)


def test_missing_slicer_says_how_to_install_and_the_rest_is_written(table31_rig, prusa, tmp_path, monkeypatch):
    from rigcad.fab.stage import run_fab

    monkeypatch.setattr(S, "find_slicer", lambda: None)
    with pytest.raises(FabricationError, match="apt-get install prusa-slicer"):
        S.slice_all([S.SliceJob("x", b"", "", (0.0, 0.0))])
    res = run_fab(table31_rig, prusa, tmp_path, parts=["beam"], gcode=True)
    assert any("apt-get install prusa-slicer" in p for p in res.problems)
    assert (tmp_path / "stl" / "beam.stl").is_file() and (tmp_path / "fab.json").is_file()
