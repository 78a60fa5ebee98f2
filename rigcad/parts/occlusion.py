"""What the mounting hardware hides: the solid angle of incidence directions at the sample point
that the beam, the clamp and the stem block (kernel-free, numpy).

Each direction (theta, phi) at O has one design light path (rotational symmetry): COP -> P on the
paraboloid -> D on the dome -> O, with P and D in the meridional plane at azimuth phi. A direction
is blocked when the segment P -> D or D -> O passes through the beam, or the paraboloid's clamp or
stem (their bounding boxes and cylinder). Directions below the paraboloid's occlusion angle are
outside the measurable zone and not counted.
"""

from __future__ import annotations

import math

import numpy as np

from rigcad.parts.layout import RigLayout
from rigcad.profile.schema import Profile


def _segment_hits_box(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Slab test: does each segment a[i] -> b[i] (n, 3) cross the box [lo, hi]?"""
    d = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - a) / d
        t2 = (hi - a) / d
    t_lo = np.where(d == 0, np.where((a >= lo) & (a <= hi), -np.inf, np.inf), np.minimum(t1, t2))
    t_hi = np.where(d == 0, np.where((a >= lo) & (a <= hi), np.inf, -np.inf), np.maximum(t1, t2))
    enter = np.max(t_lo, axis=1)
    leave = np.min(t_hi, axis=1)
    return (enter <= leave) & (leave > 1e-9) & (enter < 1 - 1e-9)


def blocked_solid_angle(profile: Profile, layout: RigLayout, table: dict[str, np.ndarray],
                        n_theta: int = 400, n_phi: int = 1440) -> dict[str, float]:
    """Solid angle (sr) of the measurable zone's incidence directions blocked by the beam,
    clamp and stem, on a midpoint grid of ``n_theta`` x ``n_phi`` cells (sr weights sin(theta))."""
    theta_deg = table["incidence_theta_deg"]
    order = np.argsort(theta_deg)
    th_tab = np.radians(theta_deg[order])
    th_edges = np.linspace(th_tab[0], th_tab[-1], n_theta + 1)
    th = 0.5 * (th_edges[:-1] + th_edges[1:])
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    rD = np.interp(th, th_tab, table["dome_r_mm"][order])
    zD = np.interp(th, th_tab, table["dome_z_mm"][order])
    rP = np.interp(th, th_tab, table["paraboloid_r_mm"][order])
    zP = np.interp(th, th_tab, table["paraboloid_z_mm"][order])
    T, F = np.meshgrid(np.arange(n_theta), phi, indexing="ij")
    c, s = np.cos(F).ravel(), np.sin(F).ravel()
    i = T.ravel()
    D = np.column_stack([rD[i] * c, rD[i] * s, zD[i]])
    P = np.column_stack([rP[i] * c, rP[i] * s, zP[i]])
    O = np.zeros_like(D)

    mount, beam = profile.paraboloid_mount, profile.beam
    z0, z1 = layout.beam_z
    cl = profile.dome_shell.slot_clearance
    half_out = beam.width / 2 + cl + mount.clamp_wall
    boxes = {
        "beam": (np.array([-layout.beam_half_length, -beam.width / 2, z0]),
                 np.array([layout.beam_half_length, beam.width / 2, z1])),
        "clamp": (np.array([-mount.clamp_length / 2, -half_out, z0]),
                  np.array([mount.clamp_length / 2, half_out, z1 + mount.clamp_wall])),
        "stem": (np.array([-mount.stem_radius, -mount.stem_radius, z1 + mount.clamp_wall]),
                 np.array([mount.stem_radius, mount.stem_radius, layout.paraboloid_back_z])),
    }
    blocked = np.zeros(len(D), dtype=bool)
    by = {}
    for name, (lo, hi) in boxes.items():
        hit = _segment_hits_box(O, D, lo, hi) | _segment_hits_box(P, D, lo, hi)
        by[name] = hit
        blocked |= hit
    weight = (np.sin(th) * np.diff(th_edges))[i] * (2 * math.pi / n_phi)
    zone = float(weight.sum())
    out = {
        "zone_solid_angle_sr": zone,
        "blocked_solid_angle_sr": float(weight[blocked].sum()),
        "blocked_fraction": float(weight[blocked].sum() / zone),
        "grid": f"{n_theta} theta x {n_phi} phi midpoints over the measurable zone",
        "note": "stem as its bounding box: an upper bound on what it hides",
    }
    for name, hit in by.items():
        out[f"{name}_solid_angle_sr"] = float(weight[hit].sum())
    return out
