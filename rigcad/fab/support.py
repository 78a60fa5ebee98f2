"""Support contact from the slicer's own G-code: where PrusaSlicer's support extrusions touch a
piece, on its mirror and on its other faces (mm2).

PrusaSlicer marks each extrusion's role in a comment (``;TYPE:Support material``, ``;TYPE:Support
material interface``) and its bead (``;HEIGHT:``, ``;WIDTH:``); the moves between are absolute
``G1 X Y Z`` with an extrusion ``E`` (relative or absolute, ``M83``/``M82``). Every support bead is
sampled along its centre line (at most SAMPLE_SPACING apart, at the middle of its height). The
piece's surface (in print position: the STL sliced, whose coordinates the G-code keeps) is
sampled evenly by area; a surface sample touches support when a bead's centre line passes within
the contact reach: the slicer's gap between support and part (``support_material_contact_distance``
over a face, ``support_material_xy_spacing`` beside one) plus half a bead, plus half the sampling
step. The contact area is the touched samples' share of the surface area. A support column that
runs alongside a wall, the slicer's xy gap away, counts as touching it: on a mirror that is a
scar risk too, so the figure errs on the side of the optics. Independent of the model's estimate
(rigcad.fab.orientation.support_contact): this is what the printer will print. A dome quarter's
67 MB G-code (2.3 million moves) reads in one regex pass and numpy: 28 s on the shared 2 cores at
a load of 7.7 (its slicing took 95-140 s); beads are cut into COARSE pieces and only those near
the surface are sampled finely.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

#: Support beads are sampled at most this far apart along their centre lines (mm): under a bead
#: width (0.35 mm), so a touched face is not missed between samples.
SAMPLE_SPACING = 0.25
#: Surface samples per mm2 of the piece's surface: one every 0.1 mm2 (a 0.32 mm grid, under the
#: support interface's 0.2 mm line spacing plus a bead, so each interface line touches samples).
SURFACE_DENSITY = 10.0
#: Seed of the surface sampling: the same piece gives the same figure.
SEED = 20061
SUPPORT_TYPES = ("Support material", "Support material interface")



@dataclass(frozen=True)
class SupportBeads:
    """Support extrusions of one G-code: ``segments`` (n, 5) = x0, y0, x1, y1 (mm) and the bead's
    mid-height z (mm) of each straight bead, the extruded length (mm), the number of support layers."""

    segments: np.ndarray
    length_mm: float
    layers: int

    def sample(self, spacing: float = SAMPLE_SPACING, which: np.ndarray | None = None) -> np.ndarray:
        """Points (m, 3) mm along the beads' centre lines, at most ``spacing`` apart (the segments
        ``which`` only, when given)."""
        s = self.segments if which is None else self.segments[which]
        if len(s) == 0:
            return np.zeros((0, 3))
        a, b = s[:, 0:2], s[:, 2:4]
        n = np.maximum(np.ceil(np.linalg.norm(b - a, axis=1) / spacing).astype(int), 1)
        seg = np.repeat(np.arange(len(s)), n)
        start = np.repeat(np.cumsum(n) - n, n)
        t = (np.arange(len(seg)) - start + 0.5) / n[seg]
        return np.column_stack([a[seg] + t[:, None] * (b - a)[seg], s[seg, 4]])

    @property
    def points(self) -> np.ndarray:
        return self.sample()


#: The G-code lines the reader needs, one regex pass: XY moves (with E when extruding), Z moves,
#: extrusion roles, bead heights, the extrusion mode (PrusaSlicer writes X and Y on every XY move).
_LINES = re.compile(rb"^(?:G1 X([-.\d]+) Y([-.\d]+)(?: E([-.\d]+))?|G1 Z([-.\d]+)|;TYPE:([^\n]*)|;HEIGHT:([-.\d]+)"
                    rb"|(M8[23]))", re.M)


def _last(mask: np.ndarray) -> np.ndarray:
    """For every row, the index of the last row at or before it where ``mask`` holds (-1: none)."""
    return np.maximum.accumulate(np.where(mask, np.arange(len(mask)), -1))


def support_beads(gcode: bytes) -> SupportBeads:
    """The support beads of a PrusaSlicer G-code (see the module docstring); vectorised over the
    matched lines."""
    rows = _LINES.findall(gcode)
    if not rows:
        return SupportBeads(np.zeros((0, 5)), 0.0, 0)
    cols = [np.array(c) for c in zip(*rows)]  # x, y, e, z, type, height, mode: one bytes array each
    xy, has_e, zrow, trow, hrow, mrow = (cols[i] != b"" for i in (0, 2, 3, 4, 5, 6))

    def num(col, mask):
        out = np.zeros(len(rows))
        out[mask] = cols[col][mask].astype(float)
        return out

    x, y, e, z, h = num(0, xy), num(1, xy), num(2, has_e), num(3, zrow), num(5, hrow)
    last_t, last_z, last_h, last_m = _last(trow), _last(zrow), _last(hrow), _last(mrow)
    names = {k.encode() for k in SUPPORT_TYPES}
    is_support_type = np.zeros(len(rows), bool)
    t_idx = np.nonzero(trow)[0]
    is_support_type[t_idx] = [cols[4][i].strip() in names for i in t_idx]  # a few thousand role changes
    support = (last_t >= 0) & is_support_type[np.maximum(last_t, 0)]
    zc = np.where(last_z >= 0, z[np.maximum(last_z, 0)], 0.0) - 0.5 * np.where(last_h >= 0, h[np.maximum(last_h, 0)], 0.0)
    relative = (last_m < 0) | (cols[6][np.maximum(last_m, 0)] == b"M83")
    prev_e = np.concatenate([[-1], _last(has_e)[:-1]])
    de = np.where(relative, e, e - np.where(prev_e >= 0, e[np.maximum(prev_e, 0)], 0.0))
    prev_xy = np.concatenate([[-1], _last(xy)[:-1]])
    bead = xy & has_e & (de > 0) & support & (prev_xy >= 0)
    i, p = np.nonzero(bead)[0], prev_xy[bead]
    seg = np.column_stack([x[p], y[p], x[i], y[i], zc[i]])
    seg = seg[(seg[:, 0] != seg[:, 2]) | (seg[:, 1] != seg[:, 3])]
    length = float(np.linalg.norm(seg[:, 2:4] - seg[:, 0:2], axis=1).sum())
    return SupportBeads(seg, length, int(len(np.unique(np.round(seg[:, 4], 4)))))


#: Length (mm) of the coarse pieces the beads are first cut into (:func:`contact_areas`).
COARSE = 4.0


def _chunks(seg: np.ndarray, length: float) -> np.ndarray:
    """Segments (n, 5) cut into pieces of at most ``length`` mm (same z)."""
    a, b = seg[:, 0:2], seg[:, 2:4]
    n = np.maximum(np.ceil(np.linalg.norm(b - a, axis=1) / length).astype(int), 1)
    k = np.repeat(np.arange(len(seg)), n)
    start = np.repeat(np.cumsum(n) - n, n)
    j = np.arange(len(k)) - start
    t0, t1 = j / n[k], (j + 1) / n[k]
    d = (b - a)[k]
    return np.column_stack([a[k] + t0[:, None] * d, a[k] + t1[:, None] * d, seg[k, 4]])


def contact_reach(settings: dict[str, str], layer_height: float) -> float:
    """How near (mm) a support bead's centre line comes to a face it touches: the larger of the
    slicer's vertical gap (contact distance + half a layer) and its horizontal gap (xy spacing,
    a share of the extrusion width, + half a bead), plus half the sampling step."""
    def num(key, default):
        try:
            return float(str(settings.get(key, default)).split(",")[0].rstrip("%"))
        except ValueError:
            return float(default)

    width = num("support_material_extrusion_width", 0.35) or 0.35
    ext = num("extrusion_width", 0.45) or 0.45
    contact = num("support_material_contact_distance", 0.2)
    xy = str(settings.get("support_material_xy_spacing", "60%"))
    xy_mm = ext * float(xy[:-1]) / 100 if xy.endswith("%") else float(xy or 0)
    return max(contact + 0.5 * layer_height, xy_mm + 0.5 * width) + 0.5 * max(SAMPLE_SPACING, 1 / np.sqrt(SURFACE_DENSITY))


def contact_areas(vertices: np.ndarray, faces: np.ndarray, mirror_index: np.ndarray, beads: SupportBeads,
                  reach: float, band: tuple | None = None) -> dict:
    """Support contact (mm2) on the mirror faces (``mirror_index``) and the other faces of a mesh
    in print position (vertices (n, 3) mm, faces (m, 3)), and the touched surface samples for a
    picture. ``band``: (the same vertices in another frame (n, 3), a function of points (k, 3) in
    that frame giving a distance (mm), the band's width (mm)): the mirror's contact is also split
    into ``mirror_in_band_mm2`` (samples within the width: a split mirror's seams, which their
    fairing sands, rigcad.fab.seams.SEAM_BAND_MM) and ``mirror_off_band_mm2`` (the rest)."""
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    total = float(area.sum())
    count = max(int(total * SURFACE_DENSITY), 1)
    rng = np.random.default_rng(SEED)
    face = rng.choice(len(faces), size=count, p=area / total)
    r1, r2 = rng.random(count), rng.random(count)
    flip = r1 + r2 > 1
    r1[flip], r2[flip] = 1 - r1[flip], 1 - r2[flip]
    t = tri[face]
    pts = t[:, 0] + r1[:, None] * (t[:, 1] - t[:, 0]) + r2[:, None] * (t[:, 2] - t[:, 0])
    is_mirror = np.zeros(len(faces), bool)
    is_mirror[np.asarray(mirror_index, dtype=int)] = True
    on_m = is_mirror[face]
    touched = np.zeros(count, bool)
    if len(beads.segments):
        # coarse to fine: the beads cut into COARSE pieces, only pieces that come near the surface
        # are sampled at SAMPLE_SPACING (support far inside its columns touches nothing)
        surface = cKDTree(pts)
        coarse = SupportBeads(_chunks(beads.segments, COARSE), beads.length_mm, beads.layers)
        mid = coarse.sample(spacing=2 * COARSE)  # one point per chunk: its middle
        d, _ = surface.query(mid, distance_upper_bound=reach + 0.5 * COARSE)
        near = coarse.sample(which=np.isfinite(d))
        if len(near):
            d, _ = cKDTree(near).query(pts, distance_upper_bound=reach)
            touched = np.isfinite(d)
    per = total / count
    split = {}
    if band is not None:
        frame_vertices, distance, width = band
        ft = np.asarray(frame_vertices, float)[faces][face]
        in_band = on_m & (distance(ft[:, 0] + r1[:, None] * (ft[:, 1] - ft[:, 0])
                                   + r2[:, None] * (ft[:, 2] - ft[:, 0])) <= width)
        split = {"mirror_in_band_mm2": float((touched & in_band).sum() * per),
                 "mirror_off_band_mm2": float((touched & on_m & ~in_band).sum() * per), "band_mm": float(width)}
    return {**split, "mirror_mm2": float((touched & on_m).sum() * per), "other_mm2": float((touched & ~on_m).sum() * per),
            "mirror_area_mm2": float(area[is_mirror].sum()), "surface_samples": count, "reach_mm": reach,
            "support_extruded_length_mm": beads.length_mm, "support_layers": beads.layers,
            "_points": pts, "_touched": touched, "_mirror": on_m}


def mirror_problems(piece: str, contact: dict, model_mm2: float, printer_source: str) -> list[str]:
    """A fab problem when the slicer's support (``contact``: :func:`contact_areas`' record of the
    piece's G-code) touches its mirror outside its seams' faired band (the whole mirror for a piece
    without seams): naming the piece, the area, what rigcad's orientation model predicted
    (``model_mm2``) and what to change. Support inside the band is stated in fab.md, not refused:
    the seam's fairing sands it off (rigcad.fab.seams.SEAM_BAND_MM)."""
    off = contact.get("mirror_off_band_mm2", contact.get("mirror_mm2", 0.0))
    if off <= 0.0:
        return []
    where = (f" outside the {contact['band_mm']:g} mm band its seams' fairing sands "
             f"({contact['mirror_in_band_mm2']:.1f} mm2 more inside it)" if "band_mm" in contact else "")
    return [f"{piece}: the slicer's support touches {off:.1f} mm2 of its mirror{where}, measured on its G-code "
            f"(rigcad.fab.support; picture {contact.get('png', 'support/' + piece + '.png')}), where rigcad's "
            f"orientation model predicted {model_mm2:.1f} mm2: a scar on the optics. Change the printer's support "
            f"settings (slicer.overrides in {printer_source}: support_material_threshold, "
            f"support_material_buildplate_only, support_material_contact_distance) or print it in another "
            f"orientation; the model that chose this one disagreed with the slicer"]
