"""What the mounting hardware hides: the solid angle of incidence directions at the sample point
that the beam, the clamp, the stem and the clamp's stop pin and set screw block (kernel-free, numpy).

Each direction (theta, phi) at O has one design light path (rotational symmetry): COP -> P on the
paraboloid -> D on the dome -> O, with P and D in the meridional plane at azimuth phi. A direction
is blocked when the segment P -> D or D -> O passes through the beam, or the paraboloid's clamp or
stem: the occluders their part recipes declare (``Part.occluders``), boxes as they are and the
stem by its bounding box. Directions below the paraboloid's occlusion angle are
outside the measurable zone and not counted.
"""

from __future__ import annotations

import math

import numpy as np

from rigcad.optics.solids import segments_hit_box
from rigcad.parts.recipe import Box, Cylinder

#: The occluders counted, by the names their recipes give them (the paraboloid's back lies inside
#: the occlusion cone of its rim and is not counted; the beam's seats stand outside the dome).
COUNTED = ("beam", "clamp", "stem", "pin", "set screw")


def bounds(solid: Box | Cylinder) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box (lo, hi) (3,) mm of an occluder."""
    if isinstance(solid, Box):
        return np.array(solid.lo, float), np.array(solid.hi, float)
    x, y, z = solid.base
    r = solid.radius
    return np.array([x - r, y - r, z]), np.array([x + r, y + r, z + solid.height])


def design_path(table: dict[str, np.ndarray], theta: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The design light path of incidence directions (theta, phi) (n,) rad at O: the paraboloid point
    P and the dome point D (n, 3) mm, in the meridional plane at azimuth phi, by linear interpolation
    in theta between the rows of the design's profile table (``optics.design.profile_table``)."""
    order = np.argsort(table["incidence_theta_deg"])
    th_tab = np.radians(table["incidence_theta_deg"][order])
    rD, zD, rP, zP = (np.interp(theta, th_tab, table[k][order])
                      for k in ("dome_r_mm", "dome_z_mm", "paraboloid_r_mm", "paraboloid_z_mm"))
    c, s = np.cos(phi), np.sin(phi)
    return np.column_stack([rP * c, rP * s, zP]), np.column_stack([rD * c, rD * s, zD])


def blocked_solid_angle(occluders: dict[str, tuple], table: dict[str, np.ndarray],
                        n_theta: int = 400, n_phi: int = 1440) -> dict[str, float]:
    """Solid angle (sr) of the measurable zone's incidence directions blocked by the beam,
    clamp, stem, stop pin and set screw (``occluders``: part name -> ((name, Box or Cylinder), ...), as
    ``Rig.occluders``), on a midpoint grid of ``n_theta`` x ``n_phi`` cells (sr weights sin(theta)).
    ``table``: the design's profile table (``optics.design.profile_table``)."""
    th_tab = np.radians(np.sort(table["incidence_theta_deg"]))
    th_edges = np.linspace(th_tab[0], th_tab[-1], n_theta + 1)
    th = 0.5 * (th_edges[:-1] + th_edges[1:])
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    T, F = np.meshgrid(np.arange(n_theta), phi, indexing="ij")
    i = T.ravel()
    P, D = design_path(table, th[i], F.ravel())
    O = np.zeros_like(D)

    solids = {name: solid for group in occluders.values() for name, solid in group}
    missing = [n for n in COUNTED if n not in solids]
    if missing:
        raise ValueError(f"the part recipes declare no occluder named {', '.join(missing)}")
    boxes = {name: bounds(solids[name]) for name in COUNTED}
    blocked = np.zeros(len(D), dtype=bool)
    by = {}
    for name, (lo, hi) in boxes.items():
        hit = segments_hit_box(O, D, lo, hi) | segments_hit_box(P, D, lo, hi)
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
