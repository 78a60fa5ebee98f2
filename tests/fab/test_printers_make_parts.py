"""Every shipped printer makes every printed part of the default profile: whole, or cut into
pieces that each fit the printer in one of their orientations (the fit-or-split plan of
rigcad.fab.choice; no slicing). A tall part (the tower's column, the splitter holder: taller
than the Form 3's build height and longer than its bed's diagonal) is cut across its height."""

from __future__ import annotations

import pytest

from rigcad.export import mesh
from rigcad.export.build import select_parts
from rigcad.fab import choice, orientation, split
from rigcad.fab.printers import available_printers, load_printer
from rigcad.fab.stage import CUT_PARTS, _mirror


def _plan_and_pieces(rig, name, printer):
    """The part's plan on ``printer`` and its cut pieces, each with whether it fits."""
    part = rig.recipe(name)
    man = mesh.build(part.solid, rig.profile.tessellation.chord_error)
    v, _ = mesh.mesh_arrays(man)
    mirror = _mirror(part, rig.layout)
    plate = None if mirror else orientation.plate_axis(v)
    plan = choice.split_plan(man, v, mirror is not None, plate, printer)
    pieces, pins, _ = split.split_part(man, name, plan, printer.alignment_pin, mirror)
    out = []
    for pc in pieces:
        pv, _ = mesh.mesh_arrays(pc.manifold)
        sector = pc.sector_range if isinstance(plan, split.SplitPlan) else None
        out.append((pc.name, choice.fits(pv, choice.candidates(mirror is not None, plate, sector), printer)))
    return plan, out, pins


@pytest.mark.parametrize("name", ["tower_column", "splitter_holder"])
def test_form3_makes_the_tall_tower_parts(table31_rig, name):
    form3 = load_printer("form3")
    plan, pieces, pins = _plan_and_pieces(table31_rig, name, form3)
    # too tall for the Form 3 whole: cut across the height, not lengthwise into slabs
    assert isinstance(plan, split.GridPlan) and plan.count == 2 and plan.nz == 2, plan.describe()
    assert all(ok for _, ok in pieces), pieces
    assert len(pins) >= 2 and all(abs(abs(p.axis[2]) - 1) < 1e-9 for p in pins)


def test_grid_prefers_cuts_across_the_longest_side():
    import numpy as np

    assert split._grid_options(np.array([77.0, 77.0, 290.0]))[1] == (1, 1, 2)
    assert split._grid_options(np.array([297.0, 150.0, 6.0]))[1] == (2, 1, 1)
    assert split._grid_options(np.array([100.0, 100.0, 100.0]))[1] == (2, 1, 1)  # a tie: x first


@pytest.mark.slow
@pytest.mark.parametrize("printer_name", available_printers())
def test_every_printer_makes_every_printed_part(table31_rig, printer_name):
    printer = load_printer(printer_name)
    for name in select_parts(None):
        if table31_rig.recipe(name).bought or name in CUT_PARTS:
            continue
        plan, pieces, _ = _plan_and_pieces(table31_rig, name, printer)
        assert pieces and all(ok for _, ok in pieces), (printer_name, name, pieces)
