"""Loads on the printed rig (rigcad.fab.loads): the closed forms against an independent finite-element
computation (Euler-Bernoulli beam elements, numpy/scipy), the bolt figures against their definitions,
and the default rig's figures within the tolerances they eat."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg

from rigcad.errors import FabricationError
from rigcad.fab import loads as L
from rigcad.fab.printers import load_printer


def _fe_beam(length: float, n: int, EI: float, rho_a: float, support: str):
    """Stiffness and consistent mass matrices (N/mm, kg) of a beam of ``n`` Hermite elements (dofs:
    deflection, slope per node), with its supports' dofs removed; returns (K, M, free dof indices)."""
    le = length / n
    k = EI / le ** 3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le ** 2, -6 * le, 2 * le ** 2],
                                 [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le ** 2, -6 * le, 4 * le ** 2]])
    m = rho_a * le / 420 * np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le ** 2, 13 * le, -3 * le ** 2],
                                     [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le ** 2, -22 * le, 4 * le ** 2]])
    K = np.zeros((2 * n + 2, 2 * n + 2))
    M = np.zeros_like(K)
    for e in range(n):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
    fixed = {0, 2 * n} if support == "simple" else {0, 1}
    free = [i for i in range(2 * n + 2) if i not in fixed]
    return K, M, free


def test_simply_supported_sag_and_first_mode_match_a_finite_element_model():
    L_, EI, P, q, m_point, rho_a = 268.0, 2539.0 * 500.0, 0.11, 7.3e-4, 0.011, 7.44e-5  # mm, N mm2, N, N/mm, kg, kg/mm
    n = 40
    K, M, free = _fe_beam(L_, n, EI, rho_a, "simple")
    F = np.zeros(2 * n + 2)
    le = L_ / n
    for e in range(n):  # consistent load of the uniform weight
        F[2 * e: 2 * e + 4] += q * le * np.array([0.5, le / 12, 0.5, -le / 12])
    F[n] += P  # the mid node's deflection dof
    u = np.zeros_like(F)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], F[free])
    M[n, n] += m_point
    w2 = scipy.linalg.eigh(K[np.ix_(free, free)] * 1000.0, M[np.ix_(free, free)], eigvals_only=True)[0]
    sag, f = L.simply_supported(P, q, L_, EI, m_point, rho_a * L_)
    assert sag == pytest.approx(u[n], rel=1e-9)  # Hermite elements are exact at the nodes
    assert f == pytest.approx(math.sqrt(w2) / (2 * math.pi), rel=0.01)  # Rayleigh: within 1 %


def test_cantilever_deflection_and_slope_match_a_finite_element_model():
    length, EI, q = 200.0, 2539.0 * 2.4e4, 3.6e-2
    loads = [(3.9, 142.0), (7.4, 47.0)]
    n = 200  # nodes every 1 mm: the loads and the seat at nodes
    K, _, free = _fe_beam(length, n, EI, 1.0, "cantilever")
    F = np.zeros(2 * n + 2)
    le = length / n
    for e in range(n):
        F[2 * e: 2 * e + 4] += q * le * np.array([0.5, le / 12, 0.5, -le / 12])
    for P, a in loads:
        F[2 * round(a / le)] += P
    u = np.zeros_like(F)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], F[free])
    for x in (142.0, 100.0, 200.0):
        y, th = L.cantilever(loads, q, length, x, EI)
        i = round(x / le)
        assert y == pytest.approx(u[2 * i], rel=1e-6) and th == pytest.approx(u[2 * i + 1], rel=1e-6)  # round-off of 400 dofs


def test_printed_sections_lie_between_their_core_and_solid():
    assert L.printed_inertia(6, 10, infill=1.0) == pytest.approx(6 * 10 ** 3 / 12)
    assert L.printed_inertia(6, 10, skin=5.0, infill=0.0) == pytest.approx(6 * 10 ** 3 / 12)  # all skin
    assert L.printed_inertia(294, 10) == pytest.approx((294 * 1000 - 0.8 * 291.3 * 7.3 ** 3) / 12)
    solid = (50 ** 4 - 40 ** 4) / 12
    assert L.printed_tube_inertia(50, 5, infill=1.0) == pytest.approx(solid)
    assert 0.5 * solid < L.printed_tube_inertia(50, 5) < solid


def test_bolt_torque_is_the_short_form_equation_on_the_bearing_ring(table31_rig):
    mk3s = load_printer("prusa_mk3s")
    rows = {b.joint: b for b in L.bolt_loads(table31_rig.profile, table31_rig.layout, mk3s)}
    b = rows["dome flange on the base plate"]
    from rigcad.parts.dome import flange_bolt_hole

    hole = flange_bolt_hole(table31_rig.profile, table31_rig.layout)  # opened past 4.5 mm: a large washer
    area = math.pi / 4 * (12.0 ** 2 - hole ** 2)  # ISO 7093-1 M4 washer (12 mm) on the opened hole
    assert hole > 4.5 and b.area_mm2 == pytest.approx(area) and "ISO 7093-1" in b.bearing
    assert b.pressure_mpa == pytest.approx(L.BEARING_SHARE * 26.0)
    assert b.torque_nm == pytest.approx(0.2 * b.preload_n * 4.0 / 1000)
    # a hand-tight 1 N m: 1.25 kN on an M4
    assert b.hand_tight_mpa == pytest.approx(1250.0 / area)
    foot = rows["column foot on the tongue"]
    # the foot's nuts bear on the bolts' compression limiters (steel), so its face on plastic is the washer
    assert foot.bearing.startswith("large washer") and "nut" not in foot.bearing and foot.spring_washer
    assert not rows["projector on the shelf's slots"].spring_washer


def test_the_default_rig_holds_its_loads_and_the_record_is_json(table31_rig):
    r = L.loads(table31_rig.profile, table31_rig.layout, load_printer("prusa_mk3s"))
    d = {x.part: x for x in r.deflections}
    assert all(x.holds for x in r.deflections)
    assert 0 < d["beam"].sag_mm < table31_rig.profile.tolerancing.paraboloid_height
    assert d["beam"].first_mode_hz > 20 and d["column"].first_mode_hz > 10
    rec = json.loads(json.dumps(r.record()))
    assert rec["deflections"][1]["first_mode_hz"] > 20  # the shelf's mode, by Rayleigh
    assert rec["deflections"][3]["first_mode_hz"] is None  # a temperature swing has no mode
    assert len(r.table_lines()) == (2 + len(r.bolts) + 3 + len(r.deflections) + 3 + len(r.flanges)
                                    + 3 + len(r.shelf_options))


def test_a_softer_material_eats_more_and_an_unknown_one_is_refused(table31_rig):
    from dataclasses import replace

    mk3s = load_printer("prusa_mk3s")
    pla = L.deflections(table31_rig.profile, table31_rig.layout, mk3s)
    abs_ = L.deflections(table31_rig.profile, table31_rig.layout, replace(mk3s, material="ABS"))
    assert abs_[1].sag_mm > pla[1].sag_mm  # ABS's low modulus is below PLA's
    with pytest.raises(FabricationError, match="no published strength.*'standard resin'.*known: PLA, ABS"):
        L.loads(table31_rig.profile, table31_rig.layout, load_printer("form3"))


def test_heavier_instruments_sag_the_shelf_in_proportion(table31_rig):
    mk3s = load_printer("prusa_mk3s")
    light = L.deflections(table31_rig.profile, table31_rig.layout, mk3s, {"camera": 0.3, "holder": 0.2})[1]
    heavy = L.deflections(table31_rig.profile, table31_rig.layout, mk3s, {"camera": 0.8, "holder": 0.2})[1]
    assert heavy.sag_mm > light.sag_mm


def test_a_part_that_bends_past_its_tolerance_is_refused_with_its_buy_option(table31_rig):
    mk3s = load_printer("prusa_mk3s")
    ok = L.loads(table31_rig.profile, table31_rig.layout, mk3s)
    L.refuse(ok)  # the default rig holds
    heavy = L.loads(table31_rig.profile, table31_rig.layout, mk3s, {"camera": 6.0})
    with pytest.raises(FabricationError, match=r"shelf \(\d+ % of tolerancing.projector_height, projector_tilt\); "
                                               r"buy: buy.shelf: aluminium_plate"):
        L.refuse(heavy)


def test_a_breadboard_adds_its_screws_on_large_washers(write_profile, table31_text):
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    rig = Rig.from_profile(load_profile(write_profile(table31_text + "datum:\n  mount: breadboard_m6_25mm\n")))
    rows = {b.joint: b for b in L.bolt_loads(rig.profile, rig.layout, load_printer("prusa_mk3s"))}
    b = rows["the rig on the breadboard"]
    assert (b.thread, b.count, b.bearing, b.spring_washer) == ("M6", 3, "large washer", True)
    assert b.area_mm2 == pytest.approx(math.pi / 4 * (18.0 ** 2 - 8.6 ** 2))  # ISO 7093 M6 on the 8.6 mm hole
    plain = Rig.from_profile(load_profile(write_profile(table31_text)))
    assert "the rig on the breadboard" not in {x.joint for x in L.bolt_loads(plain.profile, plain.layout,
                                                                              load_printer("prusa_mk3s"))}


@pytest.mark.parametrize("option", ["print", "aluminium_plate"])
def test_the_shelfs_first_mode_matches_a_finite_element_model(table31_rig, option):
    """Rayleigh's quotient on the shelf's static curve (rigcad.fab.loads._shelf_model) against the first
    eigenvalue of the same cantilever in Hermite beam elements with consistent mass and the point
    masses at their nodes: an upper bound, within 2 % (the static curve is close to the first mode's)."""
    mk3s = load_printer("prusa_mk3s")
    m = L._shelf_model(table31_rig.profile, table31_rig.layout, mk3s, L.material(mk3s), None, option)
    n = 400
    K, M, free = _fe_beam(m["overhang"], n, m["EI_nmm2"], m["mass_per_mm_kg"], "cantilever")
    le = m["overhang"] / n
    for mass, a in m["point_masses"]:
        M[2 * round(a / le), 2 * round(a / le)] += mass
    w2 = scipy.linalg.eigh(K[np.ix_(free, free)] * 1000.0, M[np.ix_(free, free)], eigvals_only=True)[0]
    fe = math.sqrt(w2) / (2 * math.pi)
    assert fe <= m["first_mode_hz"] * (1 + 1e-6)  # Rayleigh bounds the first mode from above
    assert m["first_mode_hz"] == pytest.approx(fe, rel=0.02)  # and the static curve is near its shape


def test_the_column_flanges_hold_the_overturning_moment(table31_rig, other_rig):
    """The shelf's overturning moment on the column's foot and top: the most loaded bolt's extra tension
    from the bolt group's rigid-flange model, re-derived here, far under the preload; the pressure under
    the nut with it added under the yield."""
    from rigcad.parts.tower import _column_flange_points

    mk3s = load_printer("prusa_mk3s")
    for rig in (table31_rig, other_rig):
        t = rig.layout.tower
        joints = L.flange_joints(rig.profile, rig.layout, mk3s)
        assert [j.joint for j in joints] == ["column foot on the tongue", "column top under the shelf"]
        moment = L.deflections(rig.profile, rig.layout, mk3s)[2].model.split("moment ")[1].split(" N m")[0]
        assert joints[0].moment_nmm / 1000 == pytest.approx(float(moment), abs=0.005)
        edge = t.column_x - t.column_foot_half
        d = sorted(x - edge for x, _ in _column_flange_points(t, rig.profile))
        # two rows of two bolts, at d[0] and d[2] from the edge it turns about
        assert joints[0].bolt_force_n == pytest.approx(joints[0].moment_nmm * d[-1] / (2 * d[0] ** 2 + 2 * d[-1] ** 2))
        for j in joints:
            assert j.holds and j.margin > 10  # the preload is over ten times the moment's pull: the joint stays shut
            assert j.pressure_mpa < j.yield_mpa
    # planted: 100 kg at the seat (over three hundred times the camera) pulls the foot's bolts past their
    # preload (943 N on the washer over the compression limiter's hole; 30 kg pulls 383 N): refused
    heavy = L.loads(table31_rig.profile, table31_rig.layout, mk3s, {"camera": 100.0})
    assert not heavy.flanges[0].holds
    with pytest.raises(FabricationError, match="column foot on the tongue.*buy: buy.column: extrusion_40x40"):
        L.refuse(heavy)


def test_a_lab_swing_of_three_kelvin_moves_the_cop_by_alpha_dt_times_its_height(table31_rig):
    """A uniform +-3 K on a printed rig: the COP along the axis against the vertex by PLA's 102e-6 /K
    (Stratasys's data sheet) x 3 K x cop_to_vertex; across nothing when base plate and shelf are both PLA,
    the PLA-aluminium difference over the column-to-seat span with the bought shelf."""
    from rigcad.parts.tower import seat_points

    mk3s = load_printer("prusa_mk3s")
    p, t = table31_rig.profile, table31_rig.layout.tower
    th = L.thermal(p, table31_rig.layout, mk3s)
    assert th.sag_mm == pytest.approx(102e-6 * 3 * p.layout.cop_to_vertex) and th.tilt_rad == 0
    assert th.holds and th.share < 0.2  # under a fifth of projector_height: the machinist's 'fine'
    opts = {o["option"]: o for o in L.shelf_options(p, table31_rig.layout, mk3s)}
    assert opts["print"]["thermal_across_mm"] == pytest.approx(0.0, abs=1e-12)
    span = t.column_x - seat_points(t, p)["cone"][0]
    assert opts["aluminium_plate"]["thermal_across_mm"] == pytest.approx((102e-6 - 24.2e-6) * 3 * span)
    assert opts["aluminium_plate"]["share"] < 0.05 < opts["print"]["share"]
