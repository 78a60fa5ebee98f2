"""`rigcad fab` reckons the tolerance stack with the seams its own split plans leave
(rigcad.fab.stage.tolerance_stack): the default rig's stack holds on the shipped desktop printer,
and a worse process is a fab problem naming the placements, their dominating links and the buy
option."""

import pytest

from rigcad.fab import stack as ST
from rigcad.fab.stage import tolerance_stack


def test_the_default_rig_holds_on_the_desktop_printer_and_says_where_its_seams_come_from(table31_rig, prusa):
    rec, problems = tolerance_stack(table31_rig, prusa, {})
    assert problems == [] and rec["ok"]
    assert set(rec["seams_from"].values()) == {"estimated"}  # no chain part in this run
    assert rec["table_md"][0].startswith("| element | axis |")
    assert len(rec["table_md"]) == 2 + sum(len(ST.ELEMENT_AXES[e]) for e in ST.ELEMENTS)  # with the paraboloid's roll


def test_a_chain_part_the_run_split_counts_its_datum_seams_from_the_plan(table31_rig, prusa):
    """A fab entry's datum_seams (the split planner's) replace the estimate for that part only."""
    made = {"base_plate": {"split": {"pieces": 4}, "datum_seams": [{"count": 1}, {"count": 0}]}}
    rec, _ = tolerance_stack(table31_rig, prusa, made)
    assert rec["seams"]["base_plate"] == 1 and rec["seams_from"]["base_plate"] == "this run's split plans"
    assert rec["seams_from"]["tower_shelf"] == "estimated"
    dome = {"dome": {"split": {"pieces": 4, "sectors": 4, "bands": 1}, "datum_seams": [{"count": 2}]}}
    rec, _ = tolerance_stack(table31_rig, prusa, dome)
    assert rec["seams"]["dome"] == 0  # sectors screwed down, glued on the gauge: no band cut, no chain seam


@pytest.mark.parametrize("figures", [{"position": 0.3}, {"scale": 0.01}])
def test_a_worse_process_is_a_fab_problem_naming_the_links_and_what_to_buy(table31_rig, prusa, figures):
    """Three times the MK3S's position error, or five times its scale error: the adjusters no longer
    cover the stack and fab says which placements, which links dominate and what to buy."""
    rec, problems = tolerance_stack(table31_rig, ST.with_process(prusa, **figures), {})
    assert not rec["ok"]
    (msg,) = problems
    assert msg.startswith("tolerance stack: on prusa_mk3s") and "dominated by" in msg and "buy:" in msg
    assert "tolerancing." in msg


def test_a_printer_without_process_errors_has_no_stack_and_no_problem(table31_rig, prusa):
    from dataclasses import replace

    assert tolerance_stack(table31_rig, replace(prusa, process_errors=None), {}) == (None, [])
