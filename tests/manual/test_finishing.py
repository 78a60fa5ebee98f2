"""The finishing figures against closed forms: the paraboloid's principal radii, the block length
from the sagitta, and the acceptance test's pass limit from the angle target."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rigcad.manual import finishing as F


def test_paraboloid_radii_match_the_closed_form(table31_rig):
    """z = z_v - r^2 / (4 f): meridional radius 2 f (1 + r^2 / 4 f^2)^(3/2), sagittal 2 f (1 + r^2 / 4 f^2)^(1/2),
    both smallest at the smallest r of the mirror's annulus."""
    g = table31_rig.geometry
    f = g.focal_length
    design = table31_rig.layout.design_paraboloid
    r = np.abs(design.points(design.sample(4001))[2:-2, 0])
    q = 1 + r * r / (4 * f * f)
    exact_m, exact_s = float(np.min(2 * f * q ** 1.5)), float(np.min(2 * f * q ** 0.5))
    got = F.principal_radii(design)
    # second-order differences on 4001 points of a smooth curve: ~1e-6 relative; 1e-4 leaves room
    assert got["meridional_mm"] == pytest.approx(exact_m, rel=1e-4)
    assert got["sagittal_mm"] == pytest.approx(exact_s, rel=1e-4)


def test_flat_block_length_keeps_the_sagitta(table31_rig):
    for b in F.sanding_blocks(table31_rig):
        L, R = b["flat_block_max_mm"], b["smallest_radius_mm"]
        assert L * L / (8 * R) == pytest.approx(F.BLOCK_SAG_MM, rel=1e-12)


def test_the_dome_slope_held_by_the_disc_test(table31_rig):
    """A ray turned by 2 e at the dome's farthest point (distance D from O) lands 2 e D off O: the disc's
    radius over 2 D; D checked against the dome's rim point (r, z) from the layout directly."""
    acc = F.slope_acceptance(table31_rig)
    p = table31_rig.profile
    rim = table31_rig.layout.design_dome.points(np.array(table31_rig.layout.design_dome.u_range))
    assert acc["dome_farthest_from_o_mm"] >= float(np.max(np.hypot(rim[:, 0], rim[:, 1]))) - 1e-9
    e = acc["dome_slope_tolerance_mrad"] / 1e3
    assert 2 * e * acc["dome_farthest_from_o_mm"] == pytest.approx(p.tolerancing.max_spot_radius, rel=1e-12)


def test_the_recipe_sprays_the_profiles_coats_only_and_tests_slope_before_the_mirror(table31, tmp_path):
    """Every coat of ``coating.layers`` is a stage, in order, and nothing else is sprayed; the slope test
    stands right before the last (mirror) coat; the template checks follow the coats' thicknesses."""
    import dataclasses

    other = (("gloss black", 0.05), ("clear", 0.04), ("silver", 0.001))
    for layers, gauged in ((table31.coating.layers, table31.templates.gauged_layer), (other, "clear")):
        p = dataclasses.replace(table31, coating=dataclasses.replace(table31.coating, layers=tuple(layers)),
                                templates=dataclasses.replace(table31.templates, gauged_layer=gauged))
        rows = F.recipe(p, {"dome": 0.093})
        names = [name for name, _ in layers]
        coats = [r for r in rows if any(r[0].split(". ", 1)[1].startswith(n + " (") for n in names)]
        assert [r[0].split(". ", 1)[1].split(" (")[0] for r in coats] == names
        assert not any("filler" in " ".join(r).lower() for r in rows)
        slope = [i for i, r in enumerate(rows) if "Slope test" in r[0]]
        assert slope == [len(rows) - 2]  # right before the mirror coat
        assert [int(r[0].split(".")[0]) for r in rows] == list(range(1, len(rows) + 1))
        assert "0.093 mm of stock" in rows[0][4]
    # the shipped profile: the template fits flush after the gauged layer (the clear coat)
    rows = F.recipe(table31)
    (flush,) = [r for r in rows if r[4].startswith("template flush")]
    assert table31.templates.gauged_layer in flush[0]


def test_the_slope_test_sees_the_paraboloids_placement_within_its_disc(table31_rig):
    """The paraboloid is indicated in before the slope test: what its placement tolerance alone adds to the
    spot stays well inside the disc, where its unadjusted lateral stack (0.62 mm RSS) would not."""
    from rigcad.manual import finishing as F

    acc = F.slope_acceptance(table31_rig)
    t = table31_rig.profile.tolerancing
    assert acc["placement_offset_mm"] == t.paraboloid_offset
    assert F.placement_spot(table31_rig, 0.0) < 1e-3  # the design's chief rays meet O (its integration error)
    # small offsets act linearly: twice the offset, twice the spot, to 5 % (the trace's second order)
    one, two = F.placement_spot(table31_rig, 0.05), F.placement_spot(table31_rig, 0.1)
    assert abs(two / one - 2.0) < 0.1, (one, two)
    # placed to its 0.1 mm tolerance: under a tenth of the 3 mm disc, the rest left to the slopes
    assert acc["placement_spot_mm"] < 0.1 * acc["disc_radius_mm"], acc["placement_spot_mm"]
    assert abs(acc["slope_room_mm"] - (acc["disc_radius_mm"] - acc["placement_spot_mm"])) < 1e-12
    # unplaced, the stack's 0.62 mm RSS alone takes half the disc or more: why the placement comes first
    assert F.placement_spot(table31_rig, 0.62) > 0.5 * acc["disc_radius_mm"]


def test_the_acceptance_step_places_the_paraboloid_first_and_bills_the_turntable(table31_rig):
    from rigcad.manual import calibration as C
    from rigcad.manual import finishing as F
    from rigcad.manual.document import Doc, _section_acceptance

    class _Ctx:
        rig = table31_rig
        finishing = {"acceptance": F.slope_acceptance(table31_rig)}

    d = Doc()
    _section_acceptance(d, _Ctx())
    text = " ".join(b[-1] if isinstance(b[-1], str) else " ".join(b[-1]) for b in d.blocks)
    acc = _Ctx.finishing["acceptance"]
    assert f"**{acc['placement_spot_mm']:.2f} mm**" in text and f"**{acc['slope_room_mm']:.2f} mm**" in text
    assert text.index("Place the paraboloid first") < text.index("The test lights a disc")
    assert "turntable" in text
    items = [it for it in C.kit_items(table31_rig) if C.STEP_ACCEPTANCE in it.steps]
    assert not [m for m in C.kit_misses({C.STEP_ACCEPTANCE: text}, items) if "turntable" in m]  # its bill line
