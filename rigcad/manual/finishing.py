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


#: Specular reflectance of a polished clear coat over a black base at normal incidence: Fresnel's
#: ((n - 1) / (n + 1))^2 for a clear of index n = 1.5 (polyurethane 1.49-1.52): 0.04.
CLEAR_REFLECTANCE = 0.04

#: How each coat of the shipped profiles' ``coating.layers`` goes on, by the layer's name as the profile
#: gives it: (what, how, cure / wait). A layer not named here is applied as its maker's data sheet says.
#: A 2K (isocyanate) coat needs a supplied-air or A2/P3 respirator; 1K products are the safer choice.
LAYER_METHODS = {
    "black base paint": ("gloss black base (1K acrylic or 2K polyurethane), the ground the mirror coat needs",
                         "HVLP gun, 1.3-1.4 mm nozzle at ~2 bar (or aerosol), 2-3 thin wet coats, 10 min flash-off "
                         "between, 20-25 cm from the surface", "1K: 24 h; 2K: per data sheet (about 12 h at 20 C)"),
    "polyurethane primer": ("2K polyurethane primer-surfacer with its hardener: it fills what sanding left",
                            "HVLP 1.4 mm, 2 coats, 10 min flash; then block it wet P600-P800 on the sanding blocks "
                            "with a guide coat until the guide coat is gone", "per data sheet (about 12 h at 20 C) "
                            "before sanding"),
    "polyurethane clearcoat": ("2K polyurethane clear with its hardener", "HVLP 1.3 mm, 2 coats, 10-15 min flash; "
                               "after the cure wet-sand P1500, P2000, P3000 on the blocks, then cutting compound "
                               "(e.g. 3M 06085 class) and a finishing polish on a 75 mm foam pad, by hand or a DA "
                               "polisher at low speed", "24 h at 20 C before sanding; a week before polishing hard"),
    "MirraChrome": ("MirraChrome (Alsa Corp.) spray chrome, over the polished gloss coat",
                    "its own low-pressure spray system (an airbrush or a 0.8-1.0 mm HVLP at ~1 bar), mist coats "
                    "until the surface turns mirror, no more; dust-free room, 20-25 C, gloves: never touch it",
                    "per its data sheet (dust-dry in minutes; handle after 24 h); no clear on top unless the data "
                    "sheet allows it"),
}


def recipe(profile, stock_mm: dict[str, float] | None = None) -> list[tuple[str, str, str, str, str]]:
    """The finishing recipe, stage by stage, from print to mirror: (stage, what, how, cure / wait, check).

    One recipe for the profile's ``coating.layers`` in their order, nothing else sprayed: knock the
    staircase down to the template (the print stands forward by its sanding stock, ``stock_mm`` by
    mirror), then each coat, with the template's check after each up to the gauged layer, and the slope
    test on the polished coat before the last (the mirror) coat goes on."""
    from rigcad.parts.templates import gauged_depth

    layers = list(profile.coating.layers)
    total = float(sum(t for _, t in layers))
    gap = total - gauged_depth(profile)
    stock = "" if not stock_mm else " (" + ", ".join(f"{k} {v:.3f} mm" for k, v in stock_mm.items()) + " of stock)"
    rows = [("1. Knock down the layer lines", "wet-or-dry SiC paper P120, P240, P400 (ISO 6344) on the sanding blocks "
             "below", "wet, a drop of soap in the water; strokes along the meridian, then across", "-",
             f"guide coat (dry black powder, e.g. 3M 05861) gone everywhere; the template's gap {gap:.3f} mm "
             f"({gap / 0.0254:.1f} mil) all along it: the print's staircase is gone{stock}")]
    for k, (name, t) in enumerate(layers):
        gap -= t
        what, how, cure = LAYER_METHODS.get(name, (name, "as its maker's data sheet says", "per data sheet"))
        if k == len(layers) - 1 and len(layers) > 1:
            rows.append((f"{k + 2}. Slope test before the mirror coat", "the optical acceptance test below, on the "
                         "polished coat", "the rig assembled as for the test; the polished coat reflects about "
                         f"{100 * CLEAR_REFLECTANCE:g} % where the mirror coat will reflect "
                         f"{100 * profile.coating.reflectance:.0f} % (`coating.reflectance`): light the disc brighter "
                         f"or expose {(profile.coating.reflectance / CLEAR_REFLECTANCE) ** 2:.0f} times longer (two "
                         "reflections)", "-", "pass as below; a black patch: block and polish that area again, never "
                         "under the mirror coat"))
            k += 1
        check = ("template flush along its whole edge" if abs(gap) < 1e-9 else
                 f"template gap {gap:.3f} mm ({gap / 0.0254:.1f} mil)" if gap > 0 else
                 "past the gauged layer: do not force the template")
        rows.append((f"{k + 2}. {name} ({t / 0.0254:g} mil)", what, how, cure, check))
    return rows


__all__ = ["BLOCK_SAG_MM", "CLEAR_REFLECTANCE", "KERF_MM", "LAYER_METHODS", "principal_radii", "recipe",
           "sanding_blocks", "slope_acceptance"]
