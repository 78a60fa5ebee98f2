"""A printed section's solid skin from the printer's resolved slicer settings (rigcad.fab.loads.skin), and the
flat-printed shelf's section with a top and a bottom skin of their own (rigcad.fab.loads.printed_plate)."""

from __future__ import annotations

import dataclasses

import pytest

import rigcad
from rigcad.fab import loads as L
from rigcad.fab.printers import load_printer


@pytest.fixture(scope="module")
def mk3s():
    p = load_printer("prusa_mk3s")
    if p.slicer_config is None:
        pytest.skip(f"the MK3S's presets are not resolved here: {p.slicer_unavailable}")
    return p


def test_the_mk3s_skin_is_its_presets(mk3s):
    """3 perimeters of 0.45 mm each side; on top 8 solid layers of 0.15 mm (1.2 mm, over the preset's 0.7 mm
    least); underneath a 0.2 mm first layer and 4 of 0.15 mm (0.8 mm, over its 0.5 mm least); 20 % infill."""
    s = L.skin(mk3s)
    assert (s.side, s.top, s.bottom, s.infill) == pytest.approx((1.35, 1.2, 0.8, 0.2), abs=1e-9)  # float sums
    assert "resolved slicer settings" in s.source


def test_an_override_and_the_least_thickness_set_the_skin(mk3s):
    """Fewer top layers than the preset's least thickness: the least thickness holds (3 x 0.15 < 0.7 mm)."""
    cfg = dataclasses.replace(mk3s.slicer_config, overrides=(("top_solid_layers", "3"), ("perimeters", "2")))
    s = L.skin(dataclasses.replace(mk3s, slicer_config=cfg))
    assert s.top == pytest.approx(0.7) and s.side == pytest.approx(0.9) and s.bottom == pytest.approx(0.8)


def test_no_slicer_settings_keep_the_assumed_skin(mk3s):
    s = L.skin(dataclasses.replace(mk3s, slicer_config=None))
    assert (s.side, s.top, s.bottom, s.infill) == (L.SKIN_MM, L.SKIN_MM, L.SKIN_MM, L.INFILL)


def test_the_plate_section_against_closed_forms():
    """Equal skins: the symmetric section's I (printed_inertia) and its half height. A thinner top than
    bottom moves the neutral axis down (the top face farthest) and, with less skin, lowers I. Solid infill:
    the solid rectangle's b h^3 / 12 whatever the skin."""
    even = L.Skin(1.35, 1.35, 1.35, 0.2, "")
    inertia, c = L.printed_plate(294.0, 10.0, even)
    assert inertia == pytest.approx(L.printed_inertia(294.0, 10.0), rel=1e-12) and c == pytest.approx(5.0)
    uneven, c2 = L.printed_plate(294.0, 10.0, L.Skin(1.35, 1.2, 0.8, 0.2, ""))
    assert uneven < inertia and c2 > 5.0
    solid, _ = L.printed_plate(294.0, 10.0, L.Skin(1.35, 1.2, 0.8, 1.0, ""))
    assert solid == pytest.approx(294.0 * 10.0 ** 3 / 12, rel=1e-12)


def test_the_shelf_bends_on_the_slicers_skin(mk3s):
    """The printed shelf's EI is the material's low modulus times the plate section on the MK3S's skin."""
    rig = rigcad.load("achutha2006")
    model = L._shelf_model(rig.profile, rig.layout, mk3s, L.material(mk3s), None, "print")
    inertia, c = L.printed_plate(model["width"], model["thickness"], L.skin(mk3s))
    assert model["EI_nmm2"] == pytest.approx(L.material(mk3s).modulus_low * inertia, rel=1e-12)
    assert model["stress_mpa"] == pytest.approx(model["root_moment_nmm"] * c / inertia, rel=1e-12)


def test_the_mechanics_page_states_the_mk3s_skin(mk3s):
    from pathlib import Path

    page = " ".join((Path(__file__).resolve().parents[2] / "docs" / "rig-mechanics.md").read_text(encoding="utf-8").split())
    s = L.skin(mk3s)
    assert f"on the MK3S {s.top:g} mm on top" in page and f"{s.bottom:g} mm underneath" in page
