"""Walls round the split pins (rigcad.fab.split.pin_wall): every pin hole keeps three of the printer's
perimeter lines or 1.5 mm, whichever is more, on an FDM printer (the hole is drilled to size after
printing; a hand drill can take one line off one side and two must remain), measured on the real
pieces of the default rig for every shipped printer."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.export import mesh as M
from rigcad.fab import choice, orientation, seams, stage
from rigcad.fab import split as SP
from rigcad.errors import FabricationError
from rigcad.fab.printers import load_printer

#: Every shipped printer. The Form 3's default base plate (a 4 x 3 grid) was refused at the face x cut 137.5 mm,
#: y slab 1 (near the disc's rim the face's outline narrows along the pin, which ran out of it); its pins now
#: come from the section along the pin's length (split._swept_section) there.
SHIPPED = ("prusa_mk3s", "vantage_i", "form3")


def test_the_wall_is_three_perimeters_or_one_and_a_half_millimetres():
    mk3s, vantage = load_printer("prusa_mk3s"), load_printer("vantage_i")
    # MK3S: 3 x its preset's 0.45 mm perimeters = 1.35 mm, under the 1.5 mm floor
    assert SP.pin_wall(mk3s) == pytest.approx(1.5)
    # Vantage i: 3 x 1.125 x its 0.016 in nozzle = 1.37 mm: the floor again
    assert SP.pin_wall(vantage) == pytest.approx(1.5) and 3 * 1.125 * 0.016 * 25.4 < 1.5
    # a 0.8 mm nozzle with automatic widths: 3 x 0.9 = 2.7 mm, three perimeters rule
    wide = SimpleNamespace(process="fdm", nozzle=0.8, slicer_config=None)
    assert SP.pin_wall(wide) == pytest.approx(3 * 1.125 * 0.8)
    # resin: no perimeters; the thinnest unsupported wall
    assert SP.pin_wall(SimpleNamespace(process="sla", nozzle=None)) == SP.MIN_WALL


def _pieces_and_pins(rig, printer):
    """Each part the printer splits, as fab splits it (rigcad.fab.stage._fab_part's steps): its pieces'
    union (what the pieces reassemble to), its pins, and the hole radius and depth of the pin it took."""
    chord = rig.profile.tessellation.chord_error
    for name, part in rig.recipes.items():
        if part.bought:
            continue
        man = M.build(part.solid, chord)
        mirror = stage._mirror(part, rig.layout)
        v, _ = M.mesh_arrays(man)
        plate = None if mirror else orientation.plate_axis(v)
        plan = choice.split_plan(man, v, mirror is not None, plate, printer, SP.keepouts(part.datums))
        if plan.count == 1:
            continue
        pin = printer.alignment_pin
        if mirror is not None and printer.process_errors is not None:
            pin = seams.float_pin(pin, printer.process_errors.position)
        pieces, pins, _ = SP.split_part(man, name, plan, pin, mirror, [], wall=SP.pin_wall(printer))
        whole = pieces[0].manifold
        for p in pieces[1:]:
            whole = whole + p.manifold
        yield name, whole, pins, pin.depth


@pytest.mark.e2e  # a whole-rig split per printer: a minute or two each on 2 cores
@pytest.mark.parametrize("printer_name", SHIPPED)
def test_every_pin_hole_keeps_its_wall_on_the_real_pieces(table31_rig, printer_name):
    printer = load_printer(printer_name)
    wall = SP.pin_wall(printer)
    measured = 0
    for name, whole, pins, depth in _pieces_and_pins(table31_rig, printer):
        for p in pins:
            axis, centre, r = np.array(p.axis), np.array(p.centre), p.hole_diameter / 2
            # the hole widened by the wall (less 0.01 mm: the 24-gon's flats and round-off), less the hole
            # itself (0.01 mm wider), lies wholly inside the pieces: at least the wall all round and past its end
            probe = SP._cylinder(axis, centre, r + wall - 0.01, depth + wall - 0.01)
            hole = SP._cylinder(axis, centre, r + 0.01, depth + 0.01)
            ring = probe - hole
            outside = (ring - whole).volume()
            assert outside < 1e-6 * ring.volume(), (printer_name, name, p.face, outside)
            measured += 1
    if printer_name == "vantage_i":
        assert measured == 0  # its bed takes every part whole: no pins
    else:
        assert measured >= 8, (printer_name, measured)  # the base plate alone has two on each of four faces


MINI = "Original Prusa MINI & MINI+"


@pytest.fixture(scope="module")
def mini_run(table31_rig, tmp_path_factory):
    """The default rig's dome and beam on the Prusa MINI (180 mm cube: both split), no G-code."""
    from rigcad.fab import vendor as V
    from rigcad.fab.stage import run_fab

    if "PrusaResearch" not in V.available_bundles():
        pytest.skip("PrusaSlicer's PrusaResearch bundle is not installed (apt-get install prusa-slicer)")
    return run_fab(table31_rig, load_printer(MINI), tmp_path_factory.mktemp("mini") / "fab", parts=["dome", "beam"])


@pytest.mark.e2e  # the dome's fab on a small bed: two to three minutes on 2 shared cores
def test_the_mini_splits_and_pins_the_dome_its_thin_band_glued_without_pins(mini_run):
    dome = mini_run.report["parts"]["dome"]
    assert "error" not in dome and dome["split"]["sectors"] == 4 and dome["split"]["bands"] == 2, dome.get("error")
    # the flange band's faces take two pins each; the 4.4 mm shell above has no room for any pin with its
    # 1.5 mm walls and 1 mm behind the mirror: its four faces are glued on the template without pins
    faces = {p["face"] for p in dome["pins"]}
    assert len(dome["pins"]) == 8 and all(f.endswith("band 1") for f in faces), faces
    skipped = dome["pinless_seams"]
    assert sorted(s["face"] for s in skipped) == sorted(f.replace("band 1", "band 2") for f in faces), skipped
    assert all("printed-stage template" in s["held_by"] for s in skipped)
    assert [p for p in mini_run.problems if p.startswith("dome:")] == [], mini_run.problems
    # each piece as made (with its tongue) fits the bed
    assert all(pc["candidates"] and any(c["fits"] for c in pc["candidates"]) for pc in dome["pieces"])


@pytest.mark.e2e
def test_the_mini_splits_the_beam_with_pins_across_its_section(mini_run):
    beam = mini_run.report["parts"]["beam"]
    assert beam["split"]["pieces"] == 2 and len(beam["pins"]) == 2, beam.get("error")
    assert not [p for p in mini_run.problems if p.startswith("beam:") and "pin" in p], mini_run.problems


@pytest.mark.e2e
@pytest.mark.xfail(strict=True, reason="open: the beam's cut plane lies 1.25 deg off square (choose_phase's middle of "
                   "the run at 88.75 deg), its glue faces print near the layer plane with 0.15 mm steps, and the gap "
                   "(0.503 mm) passes the epoxy's 0.5 mm by 0.003 mm; strict, so the fix shows")
def test_the_mini_beam_has_no_fab_problem(mini_run):
    assert [p for p in mini_run.problems if p.startswith("beam:")] == []
