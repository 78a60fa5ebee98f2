"""`rigcad fab`'s total line: the slicer's time wherever it ran, rigcad's estimate (scaled by the
printer's deposition rate) only for pieces no slicer ran on, and labelled so (rigcad.cli.fab.total_line)."""

from __future__ import annotations

from types import SimpleNamespace

from rigcad.cli.fab import total_line

HOUR = 3600.0


def _piece(est_h: float, slicer_h: float | None = None) -> dict:
    pc = {"estimate": {"print_time_s": est_h * HOUR, "material_g": 10.0}}
    if slicer_h is not None:
        pc["gcode"] = {"estimates": {"print_time_s": slicer_h * HOUR, "filament_g": 12.0}}
    return pc


def _report(pieces: list[dict], requested: bool) -> dict:
    return {"parts": {"dome": {"quantity": 2, "pieces": pieces}, "dome_template": {"quantity": 1}},
            "gcode": {"requested": requested}}


MK4 = SimpleNamespace(name="mk4", slicer="prusa-slicer", process="fdm", deposition_rate_mm3_s=15.0)


def test_the_slicers_time_alone_when_it_sliced_every_piece():
    # the estimate (100 h a piece) would say 400 h; PrusaSlicer says 30 + 20 h per dome, twice
    line = total_line(_report([_piece(100, 30), _piece(100, 20)], True), MK4)
    assert line == "  total (prusa-slicer, with quantities): 100h00m, 48 g filament", line


def test_the_estimate_only_where_no_slicer_ran_and_labelled_so():
    line = total_line(_report([_piece(100), _piece(50)], False), MK4)
    assert line.startswith("  total (rigcad's estimate (no slicer ran: --gcode for PrusaSlicer's own time, its "
                           "volume terms at deposition_rate_mm3_s 15); with quantities): 300h00m"), line
    part = total_line(_report([_piece(100, 30), _piece(50)], True), MK4)
    assert part.startswith("  total (prusa-slicer, with quantities): 60h00m, 24 g filament for 2 of 4 pieces; "
                           "the other 2 by rigcad's estimate (not sliced: see the problems"), part
    assert part.endswith(": 100h00m, 20 g"), part


def test_a_printer_without_a_rate_says_whose_rate_the_estimate_takes():
    """A printer named by its PrusaSlicer preset states no deposition rate: the estimate runs at the
    MK3S fit's (rigcad.fab.estimate.CALIBRATION), and the label says so."""
    preset = SimpleNamespace(name="ender", slicer="prusa-slicer", process="fdm", deposition_rate_mm3_s=0.0)
    line = total_line(_report([_piece(10)], False), preset)
    assert "at the prusa_mk3s fit's 8 mm3/s: the printer states no deposition_rate_mm3_s" in line, line
