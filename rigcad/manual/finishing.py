"""Finishing the printed mirrors so that thesis 4.4's failure (surfaces right in form, wrong in
slope) does not repeat: the sanding blocks sized from each mirror's curvature, the template gaps as
feeler-gauge leaves, and an optical acceptance test with a pass limit computed from the angle
target.

- Curvature: each mirror's design meridian (``Part.mirrors``) gives its principal radii along the
  meridian (meridional, from the plane curve's curvature) and across it (sagittal: r / |n_r|, the
  distance along the normal to the axis). A flat block of length L on a curve of radius R stands
  off by the sagitta L^2 / (8 R): the longest block that keeps it under BLOCK_SAG_MM is
  sqrt(8 R BLOCK_SAG_MM); a longer block must be curved to R (convex for a concave mirror).
- Slope: every ray of a right rig lands on O (the sample point); a mirror tilted by e turns a
  reflected ray by 2 e, and it lands off O. The acceptance test looks at that directly: a white disc
  of radius ``tolerancing.max_spot_radius`` on black at O, seen by the camera through the rig, is
  white over the paraboloid's whole image when every ray lands inside it (slope_acceptance).

Units: mm and rad inside; the figures carry their unit in their keys.
"""

from __future__ import annotations

import math

import numpy as np

#: Largest stand-off (mm) of a flat sanding block from the design curve: 1 mil (0.0254 mm), the
#: thinnest coat: a sanding error a coat cannot fill must stay under it.
BLOCK_SAG_MM = 0.0254
#: Kerf (mm, the width the cut removes) by cutting process, for the templates' outline offset: the
#: cutter's path runs half a kerf outside the outline. Typical figures from the processes' practice:
#: CO2 / fibre laser in 1-3 mm sheet, abrasive waterjet, a 3 mm end mill on a CNC router.
KERF_MM = {"laser": 0.2, "waterjet": 0.9, "router": 3.0}


def principal_radii(meridian, samples: int = 4001) -> dict:
    """Smallest meridional and sagittal radii of curvature (mm) of the surface of revolution of
    ``meridian`` (r, z), from finite differences on ``samples`` points (second order)."""
    p = meridian.points(meridian.sample(samples))
    r, z = p[:, 0], p[:, 1]
    dr, dz = np.gradient(r), np.gradient(z)
    ddr, ddz = np.gradient(dr), np.gradient(dz)
    speed = np.hypot(dr, dz)
    kappa = np.abs(dr * ddz - dz * ddr) / speed ** 3
    n_r = np.abs(dz) / speed  # the normal's radial component
    inner = slice(2, -2)  # one-sided differences at the ends are first order: left out
    meridional = 1.0 / np.max(kappa[inner])
    with np.errstate(divide="ignore"):
        sagittal = np.where(n_r > 1e-9, np.abs(r) / np.maximum(n_r, 1e-300), np.inf)
    return {"meridional_mm": float(meridional), "sagittal_mm": float(np.min(sagittal[inner]))}


def sanding_blocks(rig) -> list[dict]:
    """Per mirror: its smallest radii, the smaller one, and the longest flat block (mm) it takes."""
    rows = []
    for part_name, part in rig.recipes.items():
        for mirror, design in part.mirrors:
            radii = principal_radii(design)
            r_min = min(radii.values())
            rows.append({"mirror": mirror, "part": part_name, **radii, "smallest_radius_mm": r_min,
                         "flat_block_max_mm": math.sqrt(8.0 * r_min * BLOCK_SAG_MM),
                         "concave": mirror != "paraboloid"})
    return rows


def slope_acceptance(rig) -> dict:
    """The optical acceptance test's figures: every camera pixel's ray lands on the sample plane within
    ``tolerancing.max_spot_radius`` of O when the mirrors are right, so a white disc of that radius on
    black, centred on O, fills the paraboloid's whole image white; a pixel that sees black marks a
    mirror area whose slope is off. The dome's slope tolerance that this test holds: a slope error e
    turns the ray by 2 e, which lands 2 e D off O, D the dome's farthest point from O (mm)."""
    p = rig.profile
    pts = rig.layout.design_dome.points(rig.layout.design_dome.sample(2001))
    far = float(np.max(np.hypot(pts[:, 0], pts[:, 1])))
    limit = p.tolerancing.max_spot_radius
    return {"disc_radius_mm": limit, "dome_farthest_from_o_mm": far,
            "dome_slope_tolerance_mrad": 1e3 * limit / (2.0 * far), "pass_fraction": p.tolerancing.min_yield}


#: The finishing recipe, stage by stage: (stage, what, how, cure / wait, check). A 2K (isocyanate)
#: primer or clear needs a supplied-air or A2/P3 respirator; 1K products are given as the safer choice.
RECIPE = (
    ("1. Knock down the layer lines", "wet-or-dry SiC paper P120 then P240 (ISO 6344) on the sanding block "
     "below", "wet sanding, water with a drop of soap; strokes along the meridian, then across", "-",
     "guide coat (black dry powder, e.g. 3M 05861) wiped on: sand until it is gone everywhere"),
    ("2. Filler primer", "1K high-build filler primer (aerosol, e.g. acrylic), or 2K epoxy/polyurethane primer "
     "with its hardener", "3 thin coats, 10 min flash-off between; 20-25 cm from the surface", "1K: 24 h; 2K: "
     "per data sheet (typically 12 h at 20 C)", "-"),
    ("3. Block the primer", "P400 then P600 wet", "guide coat again; block until it is gone", "-",
     "template: the primer's gap (table in section 4); feeler gauge"),
    ("4. Base coat", "the profile's base paint (coating.layers)", "spray: HVLP gun 1.3-1.4 mm nozzle at "
     "~2 bar, or aerosol; 2-3 wet coats", "per data sheet (1K: 24 h before sanding)", "template gap"),
    ("5. Level the base", "P800 then P1000 wet", "light pressure, guide coat", "-", "template gap; no orange peel"),
    ("6. Clear coat", "the profile's clear (coating.layers)", "HVLP 1.3 mm, 2 coats, 10-15 min flash", "2K clear: "
     "24 h at 20 C before sanding; a week before polishing hard", "template gap"),
    ("7. Cut and polish", "P1500, P2000, P3000 wet; then cutting compound (e.g. 3M 06085 equivalent) and a finishing "
     "polish on a foam pad", "by hand or a 75 mm DA polisher at low speed; keep the block for P1500-P2000", "-",
     "the optical acceptance test below"),
)


__all__ = ["BLOCK_SAG_MM", "KERF_MM", "RECIPE", "principal_radii", "sanding_blocks", "slope_acceptance"]
