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


def test_pass_limit_is_twice_the_slope_tolerance_in_camera_pixels(table31_rig):
    acc = F.slope_acceptance(table31_rig)
    p = table31_rig.profile
    f_px = min(p.camera.resolution) / 2 / math.tan(table31_rig.incidence.alpha_max)
    assert acc["pass_limit_px"] == pytest.approx(2 * p.tolerancing.max_angle_error / 4 * f_px, rel=1e-12)
