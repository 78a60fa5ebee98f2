"""The estimate model (issue 14, item 4): the fit recovers known coefficients, the model reads
the slicer's settings, and the shipped coefficients reproduce PrusaSlicer's figures on this rig
(the per-piece check against a live slice is tests/fab/test_fab_run.py, slow)."""

from __future__ import annotations

import dataclasses

import numpy as np

from rigcad.fab import estimate as E


def _features(rng, n):
    return [E.Features(volume_mm3=float(rng.uniform(1e3, 3e5)), surface_mm2=float(rng.uniform(1e3, 1e5)),
                       layers=int(rng.integers(40, 900)), support_envelope_mm3=float(rng.uniform(0, 9e5)),
                       overhang_mm2=float(rng.uniform(0, 4e4)), shell_mm=1.35) for _ in range(n)]


def test_the_fit_recovers_known_coefficients(prusa):
    """Figures made by the model from known coefficients: NNLS gives them back (exact data, so
    to rounding: 1e-6 relative)."""
    rng = np.random.default_rng(7)
    truth = dataclasses.replace(E.FIT, source="truth")
    feats = _features(rng, 30)
    rows = [(f, E.estimate(f, prusa, truth)["print_time_s"], E.estimate(f, prusa, truth)["material_g"]) for f in feats]
    got = E.fit(rows, prusa.material_density_g_cm3, "test")
    for name in ("m_shell", "m_core", "m_support", "m_piece", "t_shell", "t_core", "t_support", "t_overhang",
                 "t_layer", "t_piece"):
        want = getattr(truth, name)
        assert abs(getattr(got, name) - want) <= 1e-6 * max(abs(want), 1.0), (name, getattr(got, name), want)


def test_the_shell_is_the_slicers_perimeters(prusa, vantage):
    assert abs(E.shell_thickness(prusa) - 3 * 0.45) < 1e-12  # the printer file's perimeters: 3, the preset's 0.45 mm
    assert abs(E.shell_thickness(vantage) - 3 * 1.125 * vantage.nozzle) < 1e-12  # no slicer: PrusaSlicer's default width


def test_the_time_scales_with_a_slower_printer(prusa):
    f = _features(np.random.default_rng(1), 1)[0]
    slow = dataclasses.replace(prusa, deposition_rate_mm3_s=4.0, slicer_config=None)
    a, b = E.estimate(f, prusa), E.estimate(f, slow)
    fixed = f.layers * E.FIT.t_layer + E.FIT.t_piece
    assert abs((b["print_time_s"] - fixed) / (a["print_time_s"] - fixed) - 2.0) < 1e-12  # half the rate
    assert a["material_g"] == b["material_g"]
