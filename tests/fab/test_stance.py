"""The rig's stance on the bench (rigcad.fab.stance), measured on the parts' meshes: three supports (the
base plate's tongue and its two feet under the rim), the sample holder's collar clear of the bench, and the
centre of mass inside the support polygon with a margin."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rigcad
from rigcad.fab.printers import load_printer
from rigcad.fab.stance import stance
from rigcad.parts import base
from rigcad.parts.tower import COLLAR_BENCH_GAP_MM

#: The least tip angle (rad) the default rig must keep: 5 deg, a bench out of level by far more than
#: any lab's, or a push at the shelf, before the centre of mass crosses an edge of the support polygon
#: (measured: 12.8 deg, margin 66.7 mm, with printed parts weighed as their shells and infill).
MIN_TIP_ANGLE = math.radians(5.0)


@pytest.fixture(scope="module")
def rig():
    return rigcad.load("achutha2006")


@pytest.fixture(scope="module")
def measured(rig):
    return stance(rig, load_printer("prusa_mk3s"))


def test_the_rig_stands_on_the_tongue_and_two_feet(rig, measured):
    """Exactly three patches touch the bench, all on the base plate: the tongue's underside (out past the
    disc's rim, under the column) and the two feet, each centred where rigcad.parts.base.feet puts it."""
    s, t = measured, rig.layout.tower
    assert s.bench_z == pytest.approx(t.bench_z, abs=1e-9)  # the lowest point is the tongue's level
    assert [p.part for p in s.patches] == ["base_plate"] * 3, [(p.part, p.centroid) for p in s.patches]
    tongue = [p for p in s.patches if p.centroid[0] > rig.layout.plate_r]
    assert len(tongue) == 1 and np.ptp(tongue[0].outline[:, 0]) > 50.0  # the tongue's 88 mm run along x
    feet = sorted((c.base[0], c.base[1]) for c in base.feet(rig.profile, rig.layout))
    got = sorted(p.centroid for p in s.patches if p is not tongue[0])
    for (fx, fy), (gx, gy) in zip(feet, got, strict=True):
        # a foot's patch is its whole disc (no hole in it): its centroid is the foot's axis to mesh rounding
        assert math.hypot(gx - fx, gy - fy) < 0.05, (fx, fy, gx, gy)


def test_the_holder_collar_stands_clear_of_the_bench(rig, measured):
    """The sample holder's collar, its lowest point, stands COLLAR_BENCH_GAP_MM over the bench, at least ten
    times a printed foot's out-of-flat (so no warp of a foot brings it down); no part but the base plate
    comes down to it."""
    gap = measured.clearance_mm["sample_holder"]
    assert gap == pytest.approx(COLLAR_BENCH_GAP_MM, abs=1e-6)  # flat faces: exact in the mesh
    assert gap >= 10 * rig.profile.datum.foot_flatness  # 1 mm with the default 0.1 mm warp
    assert min(v for k, v in measured.clearance_mm.items() if k != "base_plate") >= COLLAR_BENCH_GAP_MM - 1e-6


def test_the_centre_of_mass_lies_inside_the_three_supports(measured):
    """The centre of mass (parts' volumes x density, the instruments' masses) lies inside the polygon the
    three patches span, at least MIN_TIP_ANGLE from tipping over its nearest edge."""
    s = measured
    assert s.mass_kg > 4.0  # the projector's 3 kg, the camera's 0.3 kg and the printed parts
    assert s.margin_mm > 0.0, f"centre of mass {s.centre_of_mass} outside the supports {s.polygon.tolist()}"
    assert s.tip_angle >= MIN_TIP_ANGLE, f"tips at {math.degrees(s.tip_angle):.1f} deg, margin {s.margin_mm:.1f} mm"


def test_the_manual_says_which_stance(rig):
    """The base plate's step (its recipe's description, which the manual's step quotes) says the rig stands
    on the tongue and two feet with the collar clear by the gap."""
    text = rig.recipes["base_plate"].description
    assert "three feet" in text and f"collar {COLLAR_BENCH_GAP_MM:g} mm clear of the bench" in text, text


def test_the_mechanics_page_states_the_measured_stance(measured):
    """docs/rig-mechanics.md's stance figures are the measurement's."""
    from pathlib import Path

    page = " ".join((Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md").read_text(encoding="utf-8").split())
    s = measured
    for words in (f"{COLLAR_BENCH_GAP_MM:g} mm clear of the bench", f"{2 * base.FOOT_RADIUS_MM:g} mm across",
                  f"{s.margin_mm:.1f} mm inside the nearest edge",
                  f"{s.centre_of_mass[2] - s.bench_z:.0f} mm above the bench", f"tilt {math.degrees(s.tip_angle):.1f} deg"):
        assert words in page, words


def test_a_printed_part_weighs_its_shell_solid_and_its_core_at_the_infill_share():
    """A 100 mm cube printed on the MK3S: its mass is the closed form of its shell (area x the preset's side
    skin) solid and the rest at its infill share, far under the solid cube's; a cube thinner than two skins is
    solid; a bought part states its mass or is aluminium through."""
    import trimesh

    from rigcad.fab import loads
    from rigcad.fab.stance import part_mass
    from rigcad.parts.recipe import Part

    printer = load_printer("prusa_mk3s")
    skin, rho = loads.skin(printer), printer.material_density_g_cm3 * 1e-6
    cube = trimesh.creation.box((100.0, 100.0, 100.0))
    shell = 6 * 100.0**2 * skin.side
    printed = Part("cube", None, (0, 0, 0), "a printed cube")
    assert part_mass(printed, cube, printer) == pytest.approx(rho * (shell + skin.infill * (1e6 - shell)), rel=1e-9)
    assert part_mass(printed, cube, printer) < 0.5 * rho * 1e6
    thin = trimesh.creation.box((100.0, 100.0, skin.side))  # every point within a skin of a face: solid
    assert part_mass(printed, thin, printer) == pytest.approx(rho * 100.0 * 100.0 * skin.side, rel=1e-9)
    bought = Part("bar", None, (0, 0, 0), "a bar", bought="aluminium bar")
    assert part_mass(bought, cube, printer) == pytest.approx(loads.ALUMINIUM_DENSITY * 1e6, rel=1e-9)
    stated = Part("extrusion", None, (0, 0, 0), "an extrusion", bought="extrusion", mass_kg=0.8)
    assert part_mass(stated, cube, printer) == 0.8


def test_the_bought_extrusion_weighs_its_mass_per_metre(tmp_path):
    """The 40 x 40 extrusion column is drawn as its square envelope; it weighs EXTRUSION_KG_PER_M over its
    cut length, not the solid envelope's 4.3 kg/m."""
    from rigcad.parts import tower
    from rigcad.rig import load

    path = tmp_path / "extrusion.yaml"
    path.write_text("extends: achutha2006\nbuy:\n  column: extrusion_40x40\n")
    col = load(path).recipes["tower_column"]
    (lo, hi) = col.solid.lo, col.solid.hi
    assert col.mass_kg == pytest.approx(tower.EXTRUSION_KG_PER_M * (hi[2] - lo[2]) / 1000.0, rel=1e-12)
    assert col.mass_kg < 0.5 * 2.66e-6 * (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2])
