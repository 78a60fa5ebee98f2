"""After a failed calibration the calibration page (rigcad.calibrate.kit.manual_page, section 6 of the manual)
says what to do per failing line: for each placement the adjuster that moves it, how far one step of it
moves the part, its range and resolution, read from the adjusters' and stops' own declarations
(rigcad.calibrate.kit.remedies); for the dome's slopes the finishing recipe from the sanding on, with the
slope test before the mirror coat again."""

from __future__ import annotations

import math

import pytest

from rigcad.calibrate import kit
from rigcad.manual.finishing import recipe
from rigcad.parts import adjusters as A
from rigcad.parts.paraboloid import foil_step


def _section(rig, refinish=None) -> str:
    page = kit.manual_page(rig, refinish)
    return page.split("## When it fails", 1)[1].split("\n## ", 1)[0]


def test_every_placement_has_an_adjuster_that_can_bring_it_back(table31_rig):
    rig = table31_rig
    crit = kit.pass_criterion(rig)
    rem = kit.remedies(rig)
    assert set(rem) == set(crit["placements"])
    for name, r in rem.items():
        bound = crit["placements"][name]
        # it can move the part back from past its bound (its range covers the tolerance) and set it within it
        assert r["range"] >= bound and 0 < r["resolution"] <= bound, (name, r, bound)
        assert r["unit"] == ("deg" if name.endswith("_deg") else "mm")
    # the figures are the declarations' own: the foil's thinnest step, the seat's flat screw, the camera's slots
    assert rem["paraboloid_dx_mm"]["per_step"] == foil_step()
    assert rem["paraboloid_dz_mm"]["per_step"] == pytest.approx(foil_step() / 2)
    flat = A.camera_tilt(rig.profile, rig.layout)
    assert rem["camera_tilt_y_deg"]["per_step"] == pytest.approx(math.degrees(flat.resolution), rel=1e-12)
    slot = next(a for a in A.slot_adjusters(rig.profile, rig.layout) if a.name == "camera along the axis")
    assert rem["camera_dz_mm"]["range"] == slot.range and rem["camera_dz_mm"]["resolution"] == slot.resolution
    # the vee screw turns the camera about x by the cone-flat line's share along x: less than the flat
    # screw's whole turn about y (their levers are within 1 mm), more than half of it
    ratio = rem["camera_tilt_x_deg"]["per_step"] / rem["camera_tilt_y_deg"]["per_step"]
    assert 0.5 < ratio < 1.0, ratio


def test_the_page_says_per_failure_what_to_turn_and_how_to_refinish(table31_rig):
    rig = table31_rig
    stages = [row[0] for row in recipe(rig.profile)]  # as the manual and --kit pass them (rigcad.calibrate sits below)
    section = _section(rig, stages)
    for name, r in kit.remedies(rig).items():
        assert f"- `{name}` out: {r['adjuster']}" in section, name
        assert f"moves it {r['per_step']:.3g} {r['unit']}" in section, name
    assert "exits 1 on FAIL" in section and "unresolved" in section
    # the dome's slopes: every stage of the recipe after the sanding, the slope test before the mirror coat
    slope = section.split("`residual_slope_p99_mrad` over", 1)[1]
    at = [slope.index(st) for st in stages]
    assert at == sorted(at), "the recipe's stages in their order"
    test = next(k for k, st in enumerate(stages) if "Slope test" in st)
    assert test == len(stages) - 2, "the slope test comes right before the mirror coat"
    assert f"{kit.dome_slope_tolerance(rig):.3g} mrad" in slope and "sand" in slope
    # without the stages (the page on its own) it still sends the slopes to the recipe, not a bare sentence
    alone = _section(rig).split("`residual_slope_p99_mrad` over", 1)[1]
    assert "'Finishing recipe, stage by stage'" in alone and "each of its stages after the first" in alone
