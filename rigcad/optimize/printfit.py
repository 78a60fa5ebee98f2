"""Does the dome print on a printer in at most N pieces? The fabrication stage's own rules
(``fab.split.plan_split``: N sectors x M bands, fewest pieces first; ``fab.orientation``: the
mirror part's candidate orientations, and the spin that fits the bed, over the same SPINS) applied
to the fast path's printed outline instead of the part's mesh, so that one answer costs about a
millisecond and comes with a continuous margin (mm) the optimiser can follow.

A cell (sector i, band j) of a solid of revolution is the section cut to the band and revolved
over the sector's angles [a0, a1]. Its extent along any direction e is exact in closed form: a
section point (r, z) sweeps the arc r (cos a, sin a) at height z, whose projection on e is
r rho cos(a - beta) + z e_z (rho, beta: e's horizontal length and azimuth), largest at a = beta when
beta lies in the sector, else at the nearer end. So no mesh, hull or angular sampling: the widths
over every spin are one array operation on the section's points. The beam slots and bolt holes
only remove material and are ignored. tests/optimize compares the answer with ``rigcad fab``'s
split and with ``fab.orientation.fit_margin`` on a densely revolved point cloud.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from rigcad.fab.orientation import SPINS, mirror_candidates, tilt_to_z
from rigcad.fab.split import BAND_COUNTS, SECTOR_COUNTS, band_cuts
from rigcad.optimize.fast import Outline

_COS, _SIN = np.cos(SPINS), np.sin(SPINS)


def _polylines(outline: Outline) -> tuple[np.ndarray, np.ndarray]:
    """The section's polylines (outer wall, mirror, flange ring, the seats' edge) as one array of (r, z) rows and
    the mask of the segments that join consecutive rows of the same polyline."""
    fl = outline.flange
    lines = [outline.outer, outline.inner, np.concatenate([fl, fl[:1]])]
    if len(outline.seats):
        lines.append(outline.seats)
    pts = np.concatenate(lines)
    joined = np.ones(len(pts) - 1, bool)
    ends = np.cumsum([len(x) for x in lines])[:-1]
    joined[ends - 1] = False
    return pts, joined


def _section_in_band(pts: np.ndarray, joined: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """The polylines' points with z0 <= z <= z1, plus their crossings of the two planes."""
    z = pts[:, 1]
    keep = [pts[(z >= z0) & (z <= z1)]]
    for level in (z0, z1):
        d = z - level
        i = np.nonzero((d[:-1] * d[1:] < 0) & joined)[0]
        f = d[i] / (d[i] - d[i + 1])
        keep.append(pts[i] + f[:, None] * (pts[i + 1] - pts[i]))
    return np.concatenate(keep)


@lru_cache(maxsize=32)
def _sweep(a0: float, a1: float, directions: tuple) -> tuple[np.ndarray, np.ndarray]:
    """For the unit directions e of every build direction in ``directions`` x (the spins' x and y,
    the height): the coefficients of a section point's largest and smallest projection on e over
    the arc a0..a1, r * hi + z * e_z and r * lo + z * e_z (see the module docstring), as (k, 2)
    matrices [hi, e_z] and [lo, e_z] to multiply the (2, n) section by."""
    dirs = []
    for d in directions:
        T = tilt_to_z(np.asarray(d, dtype=float))
        # printer-frame x after the spin is (c, -s, 0), y is (s, c, 0), height z; in the part frame T^T v
        dirs += [np.stack([_COS, -_SIN, np.zeros_like(_COS)], axis=-1) @ T,
                 np.stack([_SIN, _COS, np.zeros_like(_COS)], axis=-1) @ T, T[2][None, :]]
    e = np.concatenate(dirs)
    rho = np.hypot(e[:, 0], e[:, 1])
    beta = np.arctan2(e[:, 1], e[:, 0])
    span = a1 - a0
    c0, c1 = np.cos(a0 - beta), np.cos(a1 - beta)
    inside = np.mod(beta - a0, 2 * math.pi) <= span + 1e-12
    opposite = np.mod(beta + math.pi - a0, 2 * math.pi) <= span + 1e-12
    hi = rho * np.where(inside, 1.0, np.maximum(c0, c1))
    lo = rho * np.where(opposite, -1.0, np.minimum(c0, c1))
    return np.column_stack([hi, e[:, 2]]), np.column_stack([lo, e[:, 2]])


def revolved_fit_margins(section: np.ndarray, a0: float, a1: float, directions) -> np.ndarray:
    """Extents of the section (n, 2) of (r, z) rows revolved about z from angle a0 to a1 (rad), for
    each build direction: (len(directions), 2 * len(SPINS) + 1) mm, the widths along the printer's x
    and y at every spin of SPINS, then the height (exact: module docstring)."""
    hi, lo = _sweep(float(a0), float(a1), tuple(tuple(float(v) for v in d) for d in directions))
    pts = np.ascontiguousarray(section.T)  # (2, n)
    ext = (hi @ pts).max(axis=1) - (lo @ pts).min(axis=1)
    return ext.reshape(len(directions), -1)


def revolved_fit_margin(section: np.ndarray, a0: float, a1: float, direction, usable) -> float:
    """``fab.orientation.fit_margin`` of the revolved section, for one build direction."""
    return float(_margins(revolved_fit_margins(section, a0, a1, [direction]), usable)[0])


def _margins(ext: np.ndarray, usable) -> np.ndarray:
    k = len(SPINS)
    wx, hy, height = ext[:, :k], ext[:, k:2 * k], ext[:, -1]
    return np.minimum(usable[2] - height, np.minimum(usable[0] - wx, usable[1] - hy).max(axis=1))


@lru_cache(maxsize=32)
def _candidates(sectors: int) -> tuple:
    width = 2 * math.pi / sectors
    cands = mirror_candidates(None if sectors == 1 else (0.0, width))
    # upright and upside down have the same extents: one of them is enough
    return tuple(o.direction for o in cands if o.name != "upside_down")


def _hull(section: np.ndarray) -> np.ndarray:
    """The section's 2D convex hull vertices: each extent is linear in (r, z), so they give them all."""
    try:
        return section[ConvexHull(section).vertices]
    except (QhullError, ValueError):  # an empty or degenerate sliver of band: its points will do
        return section


def _cell_margin(section: np.ndarray, sectors: int, usable) -> float:
    """Best margin (mm) of one cell: the band's section revolved over one sector, in its candidate
    orientations (every sector of a plan is the same solid: the slots and holes are ignored)."""
    if len(section) < 2:
        return math.inf  # an empty cell fits anywhere
    ext = revolved_fit_margins(section, 0.0, 2 * math.pi / sectors, _candidates(sectors))
    return float(_margins(ext, usable).max())


def plans(max_pieces: int) -> list[tuple[int, int]]:
    """(sectors, bands) with at most ``max_pieces`` pieces, in ``plan_split``'s order."""
    options = sorted(((s, b) for s in SECTOR_COUNTS for b in BAND_COUNTS), key=lambda sb: (sb[0] * sb[1], sb[1]))
    return [(s, b) for s, b in options if s * b <= max_pieces]


#: Where a two-band plan is cut (fractions of the dome's height; ``plan_split`` tries 0.2..0.8 in
#: steps of 0.05: fewer here, so the model may miss a fit the fabrication stage finds, never the reverse).
TWO_BAND_FRACTIONS = (0.3, 0.5, 0.7)


def _cuts(z0: float, z1: float, bands: int):
    if bands == 2:
        return [(z0, z0 + f * (z1 - z0), z1) for f in TWO_BAND_FRACTIONS]
    return list(band_cuts(z0, z1, bands))


def dome_fit(outline: Outline, usable: tuple[float, float, float], max_pieces: int) -> dict:
    """The fewest pieces (sectors x bands, up to ``max_pieces``, in ``plan_split``'s order) in which
    the dome of ``outline`` fits the ``usable`` box (x, y, z mm; ``Printer.usable``), and a margin
    (mm): the first fitting plan's smallest room left (>= 0), or when no plan of at most
    ``max_pieces`` fits, minus how much too large the best of them is (< 0)."""
    pts, joined = _polylines(outline)
    z_lo, z_hi = float(pts[:, 1].min()), float(pts[:, 1].max())
    sections: dict[tuple[float, float], np.ndarray] = {}
    best = -math.inf
    for s, b in plans(max_pieces):
        for cuts in _cuts(z_lo, z_hi, b):
            m = math.inf
            for j in range(b):
                band = (float(cuts[j]), float(cuts[j + 1]))
                if band not in sections:
                    sections[band] = _hull(_section_in_band(pts, joined, *band))
                m = min(m, _cell_margin(sections[band], s, usable))
                if m < best:  # this cut cannot beat the best so far
                    break
            if m >= 0:
                return {"pieces": s * b, "sectors": s, "bands": b, "margin_mm": float(m)}
            best = max(best, m)
    return {"pieces": None, "sectors": None, "bands": None, "margin_mm": float(best)}
