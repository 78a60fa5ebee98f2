"""The hexagonal prism recipe node (a nut trap): both back ends give the closed-form solid."""

from __future__ import annotations

import math

import pytest

from rigcad.parts.recipe import HexPrism

TRAP = HexPrism((3.0, -2.0, -1.0), 7.4, 6.6, 0.3)


def _area(across_flats: float) -> float:
    return math.sqrt(3.0) / 2 * across_flats ** 2  # a regular hexagon: 6 triangles of side AF / sqrt 3


def test_the_corners_are_the_regular_hexagon_turned():
    c = TRAP.corners()
    r = 7.4 / math.sqrt(3.0)
    assert c[0] == pytest.approx((3.0 + r * math.cos(0.3), -2.0 + r * math.sin(0.3)), abs=1e-12)
    for a, b in zip(c, c[1:] + c[:1]):
        assert math.dist(a, b) == pytest.approx(r, rel=1e-12)  # each side equals the circumradius


def test_the_mesh_and_the_kernel_give_the_closed_form_volume_and_place():
    from rigcad.export.mesh import build as mesh_build
    from rigcad.parts import _kernel

    want = _area(7.4) * 6.6
    man = mesh_build(TRAP, 0.01)
    assert man.volume() == pytest.approx(want, rel=1e-9)
    lo = man.bounding_box()[:3]
    assert lo[2] == pytest.approx(-1.0, abs=1e-9)
    shape = _kernel.build(TRAP, 0.01, _kernel.FitReport())
    assert _kernel.volume(shape) == pytest.approx(want, rel=1e-9)
