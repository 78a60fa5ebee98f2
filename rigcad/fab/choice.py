"""How a part is cut and laid on the bed, chosen: the orientations a piece may be printed in (a
mirror's, a plate's flat ones, or the generic six: rigcad.fab.orientation), each evaluated on the
piece (fit in the printer with the best spin about the build direction, overhang, the staircase
on its mirror in closed form, the support the model expects) and the best one chosen; and the
fit-or-split plan (rigcad.fab.split), which asks whether each cell of a candidate split fits in one
of those orientations. Frame: the part's working position, mm; directions are unit vectors in it.
"""

from __future__ import annotations

import math

import numpy as np

from rigcad.errors import FabricationError
from rigcad.fab import orientation, split, staircase
from rigcad.fab.printers import Printer

#: Two orientations whose mean cusp differs by less than this fraction tie (upright and upside
#: down give the same |n . D| everywhere); the tie goes to less support on the mirror.
CUSP_TIE_RTOL = 1e-3
#: Support contact on a mirror (mm2, the model's estimate) below this counts as none: a few
#: facets at a sector's edge, far under one support line's footprint.
MIRROR_SUPPORT_TIE_MM2 = 1.0


def candidates(has_mirror: bool, plate, sector=None) -> list[orientation.Orientation]:
    """The orientations a piece may be printed in: a mirror's (within ``sector``, its angular range,
    when the part is split in sectors), a plate's flat ones (``plate``: its thin axis, or None), or
    the generic six."""
    if has_mirror:
        return orientation.mirror_candidates(sector)
    return orientation.flat_candidates(plate) if plate is not None else orientation.generic_candidates()


def fits(vertices, cands: list[orientation.Orientation], printer: Printer) -> bool:
    """Whether the mesh fits the printer's usable volume in one of ``cands`` (with some spin)."""
    return any(orientation.fit_spin(vertices, o.direction, printer.usable)[0] is not None for o in cands)


def split_plan(man, vertices, has_mirror: bool, plate, printer: Printer, keep_out=()):
    """The fewest pieces the part ``man`` (its mesh ``vertices``) prints in: whole when it fits in one
    of its orientations; else sectors and bands about the axis (rigcad.fab.split.plan_split), or a
    grid in its own bounding box for a flat or off-axis part (or when no sector split fits); no cut
    crosses a ``keep_out`` box (its datum features: rigcad.fab.split.keepouts). A band above a cut is
    judged with the tongue it carries below the cut (every band cut has one: rigcad.fab.split.make_tongues,
    within the cut face and at most the printer's pin depth deep: the cell's vertices on the cut, moved
    down by that depth, join its own), so the piece as made fits, not only its cell."""
    from rigcad.export import mesh

    if fits(vertices, candidates(has_mirror, plate), printer):
        return split.SplitPlan(1, 1, 0.0, (float(vertices[:, 2].min()), float(vertices[:, 2].max())))

    reach = printer.alignment_pin.depth  # a band's pieces carry their tongue this far under its cut (at most)

    def cell_fits(cell, plan, i, j):
        if cell.is_empty():
            return True
        cell_vertices, _ = mesh.mesh_arrays(cell)
        if isinstance(plan, split.SplitPlan) and j > 0:  # with the tongue split.make_tongues gives it: inside its
            cut = cell_vertices[np.abs(cell_vertices[:, 2] - plan.band_z[j]) < 1e-6]  # cut face, at most reach deep
            cell_vertices = np.vstack([cell_vertices, cut - np.array([0.0, 0.0, reach])])
        sector = plan.sector_range(i) if plan.sectors > 1 else None
        return fits(cell_vertices, candidates(has_mirror, plate, sector if isinstance(plan, split.SplitPlan) else None),
                    printer)

    try:
        if split.is_off_axis(man):
            return split.plan_grid(man, cell_fits, keep_out)
        try:
            return split.plan_split(man, cell_fits, keep_out)
        except FabricationError:
            return split.plan_grid(man, cell_fits, keep_out)
    except FabricationError as err:
        v = printer.build_volume
        raise FabricationError(f"{err} on printer '{printer.name}' ({v.x:g} x {v.y:g} x {v.z:g} mm): choose a printer "
                               "with a larger build volume (--printer; the printer file's build_volume), or buy the "
                               "part where the profile's buy section offers it") from err


def evaluate(vertices, faces, orient: orientation.Orientation, printer: Printer, mirror_f) -> dict:
    """One candidate orientation of one piece: fit, staircase (closed form), supports."""
    spin, extents = orientation.fit_spin(vertices, orient.direction, printer.usable)
    row = {"orientation": orient.name, "build_direction": [round(float(v), 12) for v in orient.direction],
           "fits": spin is not None, "spin_deg": None if spin is None else math.degrees(spin),
           "extents_mm": extents, "overhang_area_mm2": orientation.overhang_area(vertices, faces, orient.direction)}
    mask = None
    if mirror_f is not None and len(mirror_f.index):
        mask = np.zeros(len(faces), bool)
        mask[mirror_f.index] = True
        row["mirror_overhang_area_mm2"] = orientation.overhang_area(vertices, faces, orient.direction, mask)
        row["staircase_closed_form"] = staircase.surface_staircase(mirror_f, orient.direction, printer.layer_height)
    if spin is not None:
        row["support_model"] = orientation.support_contact(vertices, faces, orient.direction, mask)
    return row


def choose(rows: list[dict]) -> int:
    """Index of the best candidate: among those that fit, the least support contact on the mirror
    (the model's estimate; below MIRROR_SUPPORT_TIE_MM2 counts as none), then the least mean cusp
    on the mirror (ties within CUSP_TIE_RTOL), then the least overhang, then the lowest height;
    without a mirror, the least overhang, then the lowest height."""
    ok = [i for i, r in enumerate(rows) if r["fits"]]
    if not ok:
        return 0
    if all("staircase_closed_form" in rows[i] for i in ok):
        def on_mirror(i):
            a = rows[i]["support_model"]["mirror_mm2"]
            return 0.0 if a < MIRROR_SUPPORT_TIE_MM2 else round(a, 0)

        least = min(on_mirror(i) for i in ok)
        ok = [i for i in ok if on_mirror(i) == least]
        best = min(rows[i]["staircase_closed_form"]["cusp_mean_mm"] for i in ok)
        ok = [i for i in ok if rows[i]["staircase_closed_form"]["cusp_mean_mm"] <= best * (1 + CUSP_TIE_RTOL)]
        return min(ok, key=lambda i: (round(rows[i]["overhang_area_mm2"], 3), rows[i]["extents_mm"]["z_mm"], i))
    return min(ok, key=lambda i: (round(rows[i]["overhang_area_mm2"], 3), rows[i]["extents_mm"]["z_mm"], i))


def best_orientation(vertices, faces, mirror_f, cands: list[orientation.Orientation], printer: Printer,
                     piece: str) -> tuple[orientation.Orientation, list[dict], dict]:
    """The piece's print orientation among ``cands`` (:func:`choose`), with its spin; every
    candidate's row (:func:`evaluate`) and the chosen one. A piece that fits in none is refused."""
    rows = [evaluate(vertices, faces, o, printer, mirror_f) for o in cands]
    k = choose(rows)
    if not rows[k]["fits"]:
        raise FabricationError(f"piece {piece} fits the printer in no orientation")
    best = orientation.Orientation(cands[k].name, cands[k].direction, math.radians(rows[k]["spin_deg"]))
    return best, rows, rows[k]
