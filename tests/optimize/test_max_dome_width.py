"""A hard limit on the dome's size (optimize.constraints.max_dome_width), distinct from the
objectives: read with its unit and file:line, and a design whose dome part (flange included) is
wider is infeasible by exactly the excess."""

from __future__ import annotations

import pytest

from rigcad.errors import ProfileError
from rigcad.optimize.problem import CONSTRAINT_KEYS, CONSTRAINT_UNITS, evaluate
from rigcad.optimize.run import load_problem

SECTION = """
optimize:
  parameters:
    layout.cop_to_vertex: [20 cm, 45 cm]
  objectives:
    theta_min: minimize
  constraints:
    max_dome_width: {width}
"""


def test_the_limit_reads_with_its_unit(write_profile):
    pb = load_problem(write_profile("w", SECTION.format(width="30 cm")))
    assert pb.spec.constraints.max_dome_width == 300.0
    assert pb.spec.describe()["constraints"]["max_dome_width_mm"] == 300.0
    assert "max_dome_width" in CONSTRAINT_KEYS and CONSTRAINT_UNITS["max_dome_width"] == "mm"


@pytest.mark.parametrize("width, match", [
    ("300", r"w.yaml:9: optimize.constraints.max_dome_width: .*unit"),
    ("-3 cm", r"w.yaml:9: optimize.constraints.max_dome_width"),
    ("wide", r"w.yaml:9: optimize.constraints.max_dome_width"),
])
def test_a_bad_limit_is_refused_naming_key_and_line(write_profile, width, match):
    with pytest.raises(ProfileError, match=match):
        load_problem(write_profile("w", SECTION.format(width=width)))


def test_a_wider_dome_is_infeasible_by_its_excess(write_profile):
    """Table 3.1's dome part is 294.1 mm wide (flange included): 300 mm holds it, 280 mm does not,
    by the same 14.1 mm the figure says."""
    roomy = load_problem(write_profile("w", SECTION.format(width="300 mm")))
    row = evaluate(roomy, roomy.base_x)
    width = row["figures"]["dome_outer_width_mm"]
    assert 290 < width < 300 and row["constraints"]["max_dome_width"] == pytest.approx(width - 300.0)
    tight = load_problem(write_profile("w", SECTION.format(width="280 mm")))
    row = evaluate(tight, tight.base_x)
    assert row["constraints"]["max_dome_width"] == pytest.approx(width - 280.0) and not row["feasible"]
