"""A part split only because it does not fit the bed, whose glue faces no listed glue fills: the
problem names the profile key that would let it print whole (the beam's overhang) with the largest
value that fits, and that value does fit (the beam then prints whole, no problem) while one step more
does not."""

from __future__ import annotations

import re

import pytest

from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer
from rigcad.fab.stage import SUGGEST_STEP, run_fab

ENDER = "Creality Ender-3 V2 (0.4 mm nozzle)"


@pytest.fixture(scope="module")
def ender():
    if "Creality" not in V.available_bundles():
        pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
    return load_printer(ENDER)


def _beam_with_overhang(tmp_path, overhang: float, ender):
    from rigcad.rig import load

    path = tmp_path / f"beam_{overhang:g}".replace(".", "_") / "beam.yaml"
    path.parent.mkdir()
    path.write_text(f"extends: achutha2006\nbeam:\n  overhang: {overhang:g} mm\n")
    res = run_fab(load(path), ender, path.parent / "fab", parts=["beam"])
    return res.report["parts"]["beam"], [p for p in res.problems if p.startswith("beam:")]


def test_the_beam_split_on_a_small_bed_names_the_overhang_that_fits(table31_rig, ender, tmp_path):
    res = run_fab(table31_rig, ender, tmp_path / "default", parts=["beam"])
    assert res.report["parts"]["beam"]["split"]["pieces"] > 1  # 15 mm overhang: too long for the 220 mm bed
    (msg,) = [p for p in res.problems if p.startswith("beam: its glue faces")]
    m = re.search(r"beam\.overhang at most ([\d.]+) mm \(now 15 mm", msg)
    assert m, msg
    assert "--printer" in msg and "210 x 220 x 250 mm" in msg, msg  # the other way out: a larger printer
    fit = float(m.group(1))
    assert 0 < fit < 15 and fit % SUGGEST_STEP == 0, fit
    whole, problems = _beam_with_overhang(tmp_path, fit, ender)
    assert whole["split"]["pieces"] == 1 and problems == [], (whole["split"], problems)
    longer, _ = _beam_with_overhang(tmp_path, fit + SUGGEST_STEP, ender)  # the largest such value
    assert longer["split"]["pieces"] > 1, longer["split"]
