"""Layers, the staircase they leave on a mirror surface, and what it does to the light.

A layered process builds a surface as steps of height t (the layer) along the build direction D.
The cusp height -- the largest distance of the stepped surface from the true one -- is, for a
locally flat surface whose normal n makes the angle theta with D (Dolenc & Makela 1994),

    c = t |cos theta| = t |n . D|                                               (closed form)

Here it is also measured from the actual slices: each layer is the part's contour at the layer's
mid-plane (as PrusaSlicer slices), extruded by t. Between a contour point of layer k and the
nearest point of layer k+1's contour the step is a right triangle with legs t (vertical) and
Delta (horizontal), and the cusp is its height over the hypotenuse, t Delta / sqrt(t^2 + Delta^2);
this uses the slices only, no surface model. The stepped surface's corners (contour point
+- t/2 D) measured against the exact mirror give its peaks and valleys: the polishing allowance.

Optical effect of the as-printed (unpolished) stepped surface, modelled as ideal steps: treads
with normal +-D (normal error theta, area fraction cos theta per unit of true surface) and risers
with horizontal normal (error 90 deg - theta, fraction sin theta). A reflected ray turns by twice
the normal error (law of reflection), and for the dome, whose reflected rays go straight to the
sample point O at distance L, it misses O by L tan(2 delta).

Frames: part frame (working position) unless said; mm, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d as m3d
import numpy as np
from scipy.spatial import cKDTree

from rigcad.fab.mirror import MirrorFaces, MirrorSurface


def closed_form_cusp(normals: np.ndarray, direction, layer: float) -> np.ndarray:
    """t |n . D| (n,) mm for unit normals (n, 3) and build direction D (part frame)."""
    d = np.asarray(direction, dtype=float)
    return layer * np.abs(normals @ (d / np.linalg.norm(d)))


@dataclass(frozen=True)
class Layers:
    """The slices of a part in print position: ``heights`` (k,) mid-plane z (mm, printer frame,
    bed at z = 0) and ``contours`` a list per layer of closed polygons (m, 2) in printer x, y."""

    layer: float
    heights: np.ndarray
    contours: list[list[np.ndarray]]

    @property
    def count(self) -> int:
        return len(self.heights)


def slice_layers(man: m3d.Manifold, rotation: np.ndarray, layer: float, first_layer: float | None = None) -> tuple[Layers, np.ndarray]:
    """Slice ``man`` (part frame) printed with ``rotation`` (part -> printer) at each layer's
    mid-plane. Returns the layers and the shift (3,) added after the rotation to put the part
    on the bed (printer = rotation @ part + shift)."""
    mat = np.hstack([rotation, np.zeros((3, 1))])
    turned = man.transform(mat.tolist())
    lo, _ = turned.bounding_box()[:3], None
    bb = np.asarray(turned.bounding_box(), dtype=float)
    lo, hi = bb[:3], bb[3:]
    shift = np.array([0.0, 0.0, -lo[2]])
    height = hi[2] - lo[2]
    first = layer if first_layer is None else first_layer
    tops = [first]
    n_more = max(int(np.ceil((height - first) / layer - 1e-9)), 0)
    tops += [first + layer * (k + 1) for k in range(n_more)]
    tops = np.array(tops)
    bottoms = np.concatenate([[0.0], tops[:-1]])
    mids = (tops + bottoms) / 2
    contours = []
    for z in mids:
        polys = turned.slice(float(z + lo[2])).to_polygons()
        contours.append([np.asarray(p, dtype=float) for p in polys if len(p) >= 3])
    return Layers(layer, mids, contours), shift


def _segment_distance(points: np.ndarray, seg_a: np.ndarray, seg_b: np.ndarray, k: int = 6) -> np.ndarray:
    """Distance (n,) from 2D points to the nearest of the segments (a, b): the k segments with the
    nearest start points are examined (segments are short next to the distances that matter)."""
    tree = cKDTree(np.concatenate([seg_a, seg_b]))
    k = min(k, 2 * len(seg_a))
    _, idx = tree.query(points, k=k)
    idx = np.atleast_2d(idx) % len(seg_a)
    a, b = seg_a[idx], seg_b[idx]
    ab = b - a
    t = np.clip(np.einsum("nkj,nkj->nk", points[:, None, :] - a, ab) /
                np.maximum(np.einsum("nkj,nkj->nk", ab, ab), 1e-300), 0.0, 1.0)
    foot = a + t[..., None] * ab
    return np.min(np.linalg.norm(points[:, None, :] - foot, axis=-1), axis=1)


@dataclass(frozen=True)
class StepMap:
    """The staircase over a mirror, at the mirror's contour points of every layer.

    ``points`` (n, 3) part frame; ``cusp_slices`` (n,) mm from consecutive contours (NaN on the
    top layer); ``cusp_closed`` (n,) mm = t |n . D| at the same points; ``peak`` / ``valley``
    (n,) mm the signed distances of the step's upper and lower corners from the exact printed
    surface (+ = excess material in front of it).
    """

    direction: tuple[float, float, float]
    layer: float
    points: np.ndarray
    cusp_slices: np.ndarray
    cusp_closed: np.ndarray
    peak: np.ndarray
    valley: np.ndarray

    def summary(self) -> dict:
        ok = np.isfinite(self.cusp_slices)
        s, c = self.cusp_slices[ok], self.cusp_closed[ok]
        diff = np.abs(s - c)
        return {
            "contour_points": int(len(self.points)),
            "cusp_from_slices_mean_mm": float(s.mean()) if len(s) else None,
            "cusp_from_slices_max_mm": float(s.max()) if len(s) else None,
            "cusp_closed_form_mean_mm": float(c.mean()) if len(c) else None,
            "slices_vs_closed_form_mean_rel_diff": float((s.mean() - c.mean()) / c.mean()) if len(c) and c.mean() > 0 else None,
            "slices_vs_closed_form_max_abs_diff_mm": float(diff.max()) if len(diff) else None,
            "slices_vs_closed_form_p95_abs_diff_mm": float(np.percentile(diff, 95)) if len(diff) else None,
            "stepped_surface_peak_mm": float(self.peak.max()) if len(self.peak) else None,
            "stepped_surface_valley_mm": float(self.valley.min()) if len(self.valley) else None,
        }


#: Contour points examined per map: every k-th vertex of each layer so that about this many
#: remain (the dome at 0.05 mm has ~3 million; a map needs far fewer, every layer keeps some).
MAX_MAP_POINTS = 200_000


def step_map(layers: Layers, rotation: np.ndarray, shift: np.ndarray, mirror: MirrorSurface, tol: float,
             max_points: int = MAX_MAP_POINTS) -> StepMap:
    """The staircase over ``mirror`` from the slices (see the module docstring). Contour points
    within ``tol`` mm of the printed mirror are its own; of each layer's contour every k-th vertex
    is examined (k from ``max_points``), the next layer's contour is used whole."""
    t = layers.layer
    total = sum(sum(len(p) for p in polys) for polys in layers.contours)
    stride = max(1, int(np.ceil(total / max_points)))
    d_part = rotation.T @ np.array([0.0, 0.0, 1.0])
    pts_out, cusp_out = [], []
    # per layer: the segments of the layer (for the next layer's search) and its examined points
    per_layer = []
    for z, polys in zip(layers.heights, layers.contours):
        if not polys:
            per_layer.append(None)
            continue
        a = np.concatenate(polys)
        b = np.concatenate([np.roll(p, -1, axis=0) for p in polys])
        pick = a[::stride]
        printer = np.column_stack([pick, np.full(len(pick), z)]) - shift
        part = printer @ rotation  # rotation.T applied to row vectors: printer -> part
        per_layer.append((a, b, pick, part))
    # the mirror's own points: one foot-point solve for every layer (each point converges on its
    # own, so the same bits as layer by layer)
    picked = [entry[3] for entry in per_layer if entry is not None]
    if picked:
        on_mirror = np.abs(mirror.signed_distance(np.concatenate(picked))) < tol
        masks = iter(np.split(on_mirror, np.cumsum([len(p) for p in picked])[:-1]))
        for k, entry in enumerate(per_layer):
            if entry is not None:
                on = next(masks)
                per_layer[k] = (entry[0], entry[1], entry[2][on], entry[3][on])
    for k, entry in enumerate(per_layer):
        if entry is None or len(entry[2]) == 0:
            continue
        _, _, xy, part = entry
        nxt = per_layer[k + 1] if k + 1 < len(per_layer) else None
        if nxt is None:
            cusp = np.full(len(xy), np.nan)
        else:
            delta = _segment_distance(xy, nxt[0], nxt[1])
            cusp = t * delta / np.sqrt(t * t + delta * delta)
        pts_out.append(part)
        cusp_out.append(cusp)
    if not pts_out:
        empty = np.zeros(0)
        return StepMap(tuple(d_part), t, np.zeros((0, 3)), empty, empty, empty, empty)
    pts = np.concatenate(pts_out)
    cusp = np.concatenate(cusp_out)
    top, bottom = np.split(mirror.signed_distance(np.concatenate([pts + 0.5 * t * d_part, pts - 0.5 * t * d_part])), 2)
    closed = closed_form_cusp(mirror.normals(pts), d_part, t)
    return StepMap(tuple(float(v) for v in d_part), t, pts, cusp, closed,
                   np.maximum(top, bottom), np.minimum(top, bottom))


def surface_staircase(faces: MirrorFaces, direction, layer: float) -> dict:
    """Closed-form staircase over a mirror's mesh faces (area-weighted), for comparing orientations."""
    c = closed_form_cusp(faces.normals, direction, layer)
    w = faces.areas / faces.areas.sum()
    order = np.argsort(c)
    cdf = np.cumsum(w[order])
    p95 = float(c[order][np.searchsorted(cdf, 0.95)]) if len(c) else 0.0
    return {"cusp_mean_mm": float(c @ w), "cusp_p95_mm": p95, "cusp_max_mm": float(c.max()),
            "cusp_rms_mm": float(np.sqrt((c * c) @ w))}


def optical_effect(faces: MirrorFaces, direction, mirror_kind: str) -> dict:
    """Normal-angle deviation of the as-printed stepped surface (ideal steps, see the module
    docstring), the reflected-ray angle error (twice it), and for the dome the miss at O."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    cos_t = np.clip(np.abs(faces.normals @ d), 0.0, 1.0)
    theta = np.arccos(cos_t)
    # treads: error theta, area a cos(theta); risers: error pi/2 - theta, area a sin(theta)
    err = np.concatenate([theta, np.pi / 2 - theta])
    w = np.concatenate([faces.areas * cos_t, faces.areas * np.sin(theta)])
    keep = w > 0
    err, w = err[keep], w[keep]
    order = np.argsort(err)
    err, w = err[order], w[order] / w.sum()
    cdf = np.cumsum(w)

    def pct(q: float) -> float:
        return float(err[min(np.searchsorted(cdf, q), len(err) - 1)])

    out = {
        "model": "ideal steps: treads normal to the build direction, risers parallel to it",
        "normal_error_median_deg": np.degrees(pct(0.5)),
        "normal_error_p90_deg": np.degrees(pct(0.9)),
        "ray_angle_error_median_deg": 2 * np.degrees(pct(0.5)),
        "ray_angle_error_p90_deg": 2 * np.degrees(pct(0.9)),
        "area_fraction_within_1mrad": float(w[err <= 1e-3].sum()),
        "histogram_normal_error_deg": {"edges": list(range(0, 91, 10)),
                                       "area_fraction": np.histogram(np.degrees(err), bins=np.arange(0, 91, 10),
                                                                     weights=w)[0].tolist()},
    }
    if mirror_kind == "dome":
        # each dome point reflects straight to O at distance L; the ray error 2 delta misses O by
        # L tan(2 delta) (clipped at 89 deg: beyond that the ray never comes near the sample)
        L = np.linalg.norm(np.concatenate([faces.centroids, faces.centroids])[keep][order], axis=1)  # treads, then risers, as err
        miss = L * np.tan(np.minimum(2 * err, np.radians(89.0)))
        o = np.argsort(miss)
        mc = np.cumsum(w[o])
        out["miss_at_sample_median_mm"] = float(miss[o][min(np.searchsorted(mc, 0.5), len(miss) - 1)])
    return out


def polishing_allowance(steps: StepMap) -> dict:
    """What sanding must remove to level the steps (peak to valley) and the stock the print must
    carry in front of the design surface so that no valley stays below it (mm)."""
    if len(steps.points) == 0:
        return {"sanding_depth_mm": 0.0, "stock_to_add_mm": 0.0}
    return {"sanding_depth_mm": float(np.nanmax(steps.peak - steps.valley)),
            "stock_to_add_mm": float(max(0.0, -steps.valley.min()))}
