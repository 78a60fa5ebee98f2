"""A design the search calls feasible builds on the certified path on every CPU: each geometric
constraint keeps GEOMETRY_RESERVE mm short of the refusal it mirrors, and the chosen design is put
through the certified layout before it is written. Checked at the tower's boundary, where the search
put a shelf 5.0 mm (tower.clearance, met to the last bits) over the dome's top."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from rigcad.errors import GeometryError
from rigcad.optimize.problem import GEOMETRY_RESERVE, evaluate
from rigcad.optimize.run import certify, load_problem

KEY = "design.tower_above_dome"


@pytest.fixture(scope="module")
def problem():
    return load_problem("achutha2006_optimize")


def _at(problem, cop_to_vertex):
    x = problem.base_x.copy()
    x[problem.names.index("layout.cop_to_vertex")] = cop_to_vertex
    row = evaluate(problem, x)
    row["index"] = 0
    return row


def test_the_tower_constraint_holds_its_reserve_and_certify_refuses_what_build_refuses(problem):
    # the COP height at which the shelf sits exactly tower.clearance over the dome's top (the refusal),
    # found on the fast path's value without the reserve: brentq to 1e-12 mm in cop_to_vertex
    def room(c):
        return _at(problem, c)["constraints"][KEY] - GEOMETRY_RESERVE

    edge = brentq(room, 200.0, 450.0, xtol=1e-12)
    on_edge = _at(problem, edge)
    # at the refusal the search sees a violation of the reserve (g = +1e-3 mm, up to the root's 1e-12)
    assert abs(on_edge["constraints"][KEY] - GEOMETRY_RESERVE) < 1e-9 and not on_edge["feasible"]
    # 1e-6 mm below the refusal: the certified layout refuses (GeometryError, naming the tower), so the
    # run tries the next design instead of writing one `rigcad build` refuses
    below = _at(problem, edge - 1e-6)
    with pytest.raises(GeometryError, match="tower.clearance"):
        certify(problem, below)
    # where the constraint is met with its reserve (g = 0), the certified layout accepts it and keeps
    # the reserve: the fast and certified dome tops agree to ~4e-11 mm, far inside 1e-3 mm
    met = brentq(lambda c: _at(problem, c)["constraints"][KEY], 200.0, 450.0, xtol=1e-12)
    rep = certify(problem, _at(problem, met))
    assert rep["tower_room_mm"] == pytest.approx(GEOMETRY_RESERVE, abs=1e-8)
    assert np.isfinite(rep["certified"]["theta_min_deg"])
