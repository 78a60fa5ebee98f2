"""docs/calibrate.md, the page a lab reads: its pass criterion is the code's, and it stays a page a
lab can read through (under 300 lines; the method and the studies on their own pages)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "calibrate.md"


def _section(text: str, heading: str) -> str:
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return " ".join(text[start:end if end > 0 else None].split())


def test_what_passes_is_the_codes_criterion(table31_rig):
    """"What passes" states rigcad.calibrate.kit.pass_criterion on the Table 3.1 profile: the
    standard errors' margin, each placement's bound, the dome's slope bound."""
    from rigcad.calibrate.kit import pass_criterion

    crit = pass_criterion(table31_rig)
    section = _section(PAGE.read_text(encoding="utf-8"), "## What passes")
    b = crit["placements"]
    want = [f"inside its tolerance by {crit['standard_errors']:g} standard errors",
            f"|value| + {crit['standard_errors']:g} x standard error within the bound",
            f"the paraboloid {b['paraboloid_dx_mm']:g} mm sideways, {b['paraboloid_dz_mm']:g} mm in height, "
            f"{b['paraboloid_tilt_x_deg']:g} deg of tilt",
            f"the camera {b['camera_dx_mm']:g} mm, {b['camera_dz_mm']:g} mm, {b['camera_tilt_x_deg']:g} deg",
            f"at most {crit['residual_slope_p99_mrad']:.3g} mrad"]
    assert b["paraboloid_dx_mm"] == b["paraboloid_dy_mm"] and b["camera_dx_mm"] == b["camera_dy_mm"]
    assert b["paraboloid_tilt_x_deg"] == b["paraboloid_tilt_y_deg"] and b["camera_tilt_x_deg"] == b["camera_tilt_y_deg"]
    missing = [w for w in want if w not in section]
    assert not missing, missing


def test_the_page_stays_readable():
    """Under 300 lines, the procedure first, the method and the studies linked."""
    text = PAGE.read_text(encoding="utf-8")
    assert len(text.splitlines()) < 300, len(text.splitlines())
    assert text.index("## The procedure") < text.index("## What passes") < text.index("## Capture conventions")
    for page in ("calibrate-method.md", "calibrate-notes.md"):
        assert f"]({page})" in text and (ROOT / "docs" / page).is_file(), page


def test_the_seating_table_is_the_benchs():
    """"What seat is enough" shows bench/calibrate.py's rendering of
    bench/results/calibrate_seating_sweep.json (the seating sweep on the current code), every
    seating of bench/calibrate.py's SEATING_VARIANTS with at least two trials."""
    import importlib.util
    import json
    import re

    spec = importlib.util.spec_from_file_location("bench_calibrate", ROOT / "bench" / "calibrate.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    run = json.loads((ROOT / "bench" / "results" / "calibrate_seating_sweep.json").read_text(encoding="utf-8"))
    rows = run["sweep_phase_steps_and_heights"]
    assert set(rows) == set(bench.SEATING_VARIANTS) and min(r["trials"] for r in rows.values()) >= 2, rows.keys()
    text = PAGE.read_text(encoding="utf-8")
    block = re.search(r"<!-- bench/calibrate.py seating -->\n(.*?)<!-- end of bench/calibrate.py seating -->", text, re.S)
    assert block and block.group(1) == bench.seating_table(run)
