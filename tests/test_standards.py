"""rigcad.standards, the one home of the standards' figures: a few rows against the standards'
printed tables (ISO 273, ISO 4032, ISO 7089, ISO 4762, ASME B18.2.8), the look-ups at their edges,
and a scan of the package that finds no second table of these figures anywhere else."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rigcad import standards as S

ROOT = Path(__file__).resolve().parents[1] / "rigcad"


def test_rows_read_as_the_standards_print_them():
    m4, m6 = S.THREADS["M4"], S.THREADS["M6"]
    # ISO 273 medium: M4 4.5, M6 6.6 mm (a rule of 'major + 0.5' gives 6.5: the disagreement this fixes)
    assert (m4.clearance, m6.clearance) == (4.5, 6.6)
    # ISO 7089: M4 washer 0.8 mm thick; ISO 4032: M4 nut 7 mm across flats, 3.2 mm high
    assert (m4.washer_thickness, m4.nut_af, m4.nut_height) == (0.8, 7.0, 3.2)
    # ISO 4762: M4 head 7 mm across, 4 mm high, 3 mm key
    assert (m4.head_diameter, m4.head_height, m4.hex_key) == (7.0, 4.0, 3.0)
    # ASME B18.2.8 normal fit for 1/4 in: 0.281 in; 20 threads per inch
    quarter = S.THREADS["1/4-20 UNC"]
    assert quarter.clearance == pytest.approx(7.1374, abs=1e-9) and quarter.pitch == pytest.approx(1.27, abs=1e-12)
    # every metric thread's clearance series is ordered: fine < medium, and both above the thread
    for name in S.METRIC_THREADS:
        t = S.THREADS[name]
        assert t.major < t.clearance_fine < t.clearance_medium, name
        assert t.head_diameter > t.clearance_medium and t.nut_af > t.major, name


def test_thread_for_hole_takes_the_largest_medium_clearance_that_fits_at_each_edge():
    names = S.METRIC_THREADS
    for k, name in enumerate(names):
        hole = S.THREADS[name].clearance_medium
        assert S.thread_for_hole(hole).name == name
        assert S.thread_for_hole(hole - 5e-10).name == name  # within the 1e-9 mm of round-off
        if k:
            assert S.thread_for_hole(hole - 1e-6).name == names[k - 1]
    assert S.thread_for_hole(100.0).name == "M12"
    with pytest.raises(ValueError, match="2.399 mm hole takes no ISO metric bolt"):
        S.thread_for_hole(2.399)


def test_screw_lengths_keep_to_what_iso_4762_sells():
    assert S.screw_lengths("M4") == (6, 8, 10, 12, 16, 20, 25, 30, 35, 40)
    assert S.shortest_screw("M4", 12.0) == 12 and S.shortest_screw("M4", 12.0 + 1e-6) == 16
    assert S.shortest_screw("M4", 40.5) is None
    assert S.longest_screw("M4", 15.9) == 12 and S.longest_screw("M4", 5.9) is None
    assert S.longest_dowel(12.0) == 12 and S.longest_dowel(11.9) == 10
    with pytest.raises(ValueError, match="ISO 8734"):
        S.longest_dowel(2.0)


def test_insert_holes_are_the_makers_never_the_inserts_outside():
    for name, ins in S.INSERTS.items():
        # the knurl must bite: the hole is under the insert's outside, and over the thread's clearance
        assert ins.hole < ins.outer, name
        assert ins.hole > S.THREADS[name].clearance_medium, name
        assert ins.pocket_depth == pytest.approx(ins.length + 0.5)


#: Shapes a second table of the standards' figures would take in a module: a dict or tuple row keyed
#: by a thread's name and holding a number ("M4": 7.0, ("M4", 4.5, ...)), or the preferred lengths.
SECOND_TABLE = (re.compile(r"""["']M\d+(?:\.\d+)?["']\s*:\s*\(?\s*\d"""),
                re.compile(r"""\(\s*["']M\d+(?:\.\d+)?["']\s*,\s*\d"""),
                re.compile(r"\b8, 10, 12, 16, 20, 25\b"),
                re.compile(r"\b\d(?:\.\d+)? x \d+(?:\.\d+)? mm\)?; the one home"))


def second_tables(text: str) -> list[str]:
    return [m.group(0) for pat in SECOND_TABLE for m in pat.finditer(text)]


def test_no_module_but_standards_states_a_standards_table():
    found = {}
    for path in sorted(ROOT.rglob("*.py")):
        if path.name == "standards.py" and path.parent == ROOT:
            continue
        hits = second_tables(path.read_text(encoding="utf-8"))
        if hits:
            found[str(path.relative_to(ROOT))] = hits
    assert not found, f"standards' figures outside rigcad/standards.py: {found}"


def test_the_scan_sees_a_planted_second_table():
    # the scan itself, broken on purpose: each shape a second table takes is found
    assert second_tables('NUT_AF = {"M2": 4.0, "M4": 7.0}')
    assert second_tables('METRIC = (("M2", 2.4, 0.4),)')
    assert second_tables("LENGTHS = (6, 8, 10, 12, 16, 20, 25, 30)")
    assert not second_tables('thread = "M4"; key = THREADS["M4"].nut_af')
