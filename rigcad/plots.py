"""Every figure rigcad draws (matplotlib, Agg). Functions take results and return PNG bytes;
they compute nothing that a report does not already hold. PNGs carry no software/date metadata,
so the same result gives the same bytes."""

from __future__ import annotations

import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

_PNG_META = {"Software": None}


def _png(fig, dpi: int = 110) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, metadata=_PNG_META)
    plt.close(fig)
    return buf.getvalue()


def ray_diagram(design, max_rays: int = 24) -> bytes:
    """Meridional ray diagram like the thesis's Figure 3.6: COP, paraboloid, dome, rays to O."""
    geo, para, dome, tr = design.geometry, design.paraboloid, design.dome, design.aligned
    fig, ax = plt.subplots(figsize=(7.5, 8.5))
    pts = dome.points
    style = "-" if dome.kind == "smooth" else ".-"
    for sign in (1, -1):
        ax.plot(sign * pts[:, 0], pts[:, 1], style, color="0.2", lw=1.6, ms=2,
                label="dome (mirror surface)" if sign == 1 else None)
    x = np.linspace(-geo.rim_radius, geo.rim_radius, 201)
    ax.fill_between(x, para.z(x), geo.rim_z, color="tab:blue", alpha=0.35, lw=0)
    ax.plot(x, para.z(x), color="tab:blue", lw=1.5, label="paraboloid")
    ok = np.nonzero(tr.ok)[0]
    pick = ok[np.linspace(0, len(ok) - 1, min(max_rays, len(ok))).astype(int)] if len(ok) else ok
    top = geo.cop_z if not geo.cop_at_infinity else geo.vertex_z + 0.5 * (pts[:, 1].max() - geo.vertex_z) + 40
    cmap = plt.get_cmap("plasma")
    for k, i in enumerate(pick):
        P, D = tr.paraboloid_point[i], tr.dome_point[i]
        start = design.chief_origins[i] if not geo.cop_at_infinity else np.array([P[0], top])
        c = cmap(0.1 + 0.8 * k / max(len(pick) - 1, 1))
        ax.plot([start[0], P[0], D[0], tr.landing_x[i]], [start[1], P[1], D[1], 0.0], color=c, lw=0.6)
    w = pts[:, 0].max() * 1.1
    theta = geo.occlusion_theta
    ax.plot([0, np.tan(theta) * pts[:, 1].max()], [0, pts[:, 1].max()], ":", color="tab:red", lw=1,
            label=f"occlusion limit {np.degrees(theta):.1f} deg")
    ax.plot([-np.tan(theta) * pts[:, 1].max(), 0], [pts[:, 1].max(), 0], ":", color="tab:red", lw=1)
    ax.axhline(0, color="0.5", lw=0.8)
    ax.plot([0], [0], "k*", ms=10, label="sample point O")
    if not geo.cop_at_infinity:
        ax.plot([0], [geo.cop_z], "kv", ms=8, label="centre of projection")
    r = design.report
    ax.set_title(f"{design.profile.name}: dome {r['envelope']['width_in']:.2f} x {r['envelope']['height_in']:.2f} in, "
                 f"theta {r['measurable_range']['theta_min_deg']:.1f}..{r['measurable_range']['theta_max_deg']:.0f} deg\n"
                 f"dome by {dome.method}; max miss at O {r['convergence']['max_miss_mm']:.2g} mm", fontsize=10)
    ax.set_xlim(-w, w)
    ax.set_ylim(-10, top + 15)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z, optical axis (mm)")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    return _png(fig)


def incidence_plot(design) -> bytes:
    """Incidence angle against the paraboloid radius, and projector pixels per degree against theta."""
    t = design.table
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(t["paraboloid_r_mm"], t["incidence_theta_deg"], color="tab:blue")
    a1.set_xlabel("paraboloid radius where the ray reflects (mm)")
    a1.set_ylabel("incidence angle at the sample, theta (deg)")
    a1.grid(alpha=0.3)
    pix = t["projector_pixel"]
    if np.all(np.isfinite(pix)):
        theta = t["incidence_theta_deg"]
        a2.plot(theta, np.abs(np.gradient(pix, theta)), color="tab:orange")
        a2.set_xlabel("incidence angle theta (deg)")
        a2.set_ylabel("projector pixels per degree")
        a2.grid(alpha=0.3)
        sec = a1.secondary_xaxis("top", functions=(lambda r: np.interp(r, t["paraboloid_r_mm"][::-1], pix[::-1]),
                                                     lambda p: np.interp(p, pix[::-1], t["paraboloid_r_mm"][::-1])))
        # ticks only inside the pixel range: beyond it the inverse map clamps, and ticks past the rim
        # would all land on the rim's radius, printed over each other
        lo, hi = float(np.nanmin(pix)), float(np.nanmax(pix))
        ticks = MaxNLocator(nbins=6).tick_values(lo, hi)
        sec.set_xticks(ticks[(ticks >= lo) & (ticks <= hi)])
        sec.set_xlabel("projector pixel from the axis")
    else:
        a2.text(0.5, 0.5, "COP at infinity: no pixel grid", ha="center", va="center")
        a2.set_axis_off()
    fig.suptitle(f"{design.profile.name}: incidence angle per paraboloid point", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def _shade(tri: np.ndarray, color, alpha: float = 1.0) -> np.ndarray:
    """RGBA (m, 4) of flat-shaded triangles (m, 3, 3) mm, lit from the viewer's upper left."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    light = np.array([-0.4, -0.6, 0.7])
    light /= np.linalg.norm(light)
    shade = 0.35 + 0.65 * np.abs(n @ light)
    return np.column_stack([np.clip(np.outer(shade, color), 0, 1), np.full(len(tri), alpha)])


def _shaded(ax, tri: np.ndarray, color, alpha: float = 1.0) -> None:
    """Flat-shaded triangles (m, 3, 3) mm on a 3D axes, lit from the viewer's upper left."""
    _draw(ax, [(tri, color, alpha)])


def _draw(ax, groups) -> None:
    """Several meshes ((triangles (m, 3, 3) mm, colour, alpha), ...) as ONE collection, so that
    matplotlib's painter's sort orders every triangle against every other, not part against part.
    Long thin triangles (a plate's fan) are split at their longest edge first: sorted by centroid
    they would poke through their neighbours."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    tris, cols = [], []
    for tri, color, alpha in groups:
        if not len(tri):
            continue
        tri = _split_long(tri)
        tris.append(tri)
        cols.append(_shade(tri, color, alpha))
    if tris:
        ax.add_collection3d(Poly3DCollection(np.concatenate(tris), facecolors=np.concatenate(cols),
                                             edgecolors="none", linewidths=0))


def _split_long(tri: np.ndarray, rounds: int = 4) -> np.ndarray:
    """Triangles (m, 3, 3) with every edge longer than 1/12 of the mesh's size split in two at its
    midpoint (at most ``rounds`` times): painter's sorting works on pieces of similar size."""
    size = float(np.ptp(tri.reshape(-1, 3), axis=0).max()) if len(tri) else 0.0
    limit = size / 12
    for _ in range(rounds):
        e = np.stack([np.linalg.norm(tri[:, (k + 1) % 3] - tri[:, k], axis=1) for k in range(3)], axis=1)
        k = e.argmax(axis=1)
        long = e[np.arange(len(tri)), k] > limit
        if not long.any():
            break
        t = tri[long]
        kk = k[long]
        i = np.arange(len(t))
        a, b, c = t[i, kk], t[i, (kk + 1) % 3], t[i, (kk + 2) % 3]
        m = 0.5 * (a + b)
        tri = np.concatenate([tri[~long], np.stack([a, m, c], 1), np.stack([m, b, c], 1)])
    return tri


def _fit_axes(ax, lo: np.ndarray, hi: np.ndarray) -> None:
    """Axis limits on the geometry's own extents (mm), equal scale on all three axes: the box's
    aspect is the geometry's, so a long beam fills the frame's width instead of a cube's diagonal."""
    mid, size = (lo + hi) / 2, np.maximum(hi - lo, 1e-3)
    size = np.maximum(size, 0.04 * size.max())  # a flat part keeps a visible thickness
    for setter, m, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), mid, size / 2):
        setter(m - h, m + h)
    ax.set_box_aspect(tuple(size), zoom=0.95)  # below 1: no corner of the box leaves the frame
    ax.set_axis_off()


def _trimmed_png(fig, title: str = "", dpi: int = 110, pad: int = 12) -> bytes:
    """The figure as PNG, cropped to what is drawn (non-white pixels) plus ``pad`` px, with
    ``title`` above it: a 3D axes leaves most of its frame empty whatever its margins."""
    fig.set_dpi(dpi)
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    plt.close(fig)
    ink = np.nonzero((rgba[:, :, :3] < 250).any(axis=2))
    if len(ink[0]):
        r0, r1 = max(ink[0].min() - pad, 0), min(ink[0].max() + pad + 1, rgba.shape[0])
        c0, c1 = max(ink[1].min() - pad, 0), min(ink[1].max() + pad + 1, rgba.shape[1])
        rgba = rgba[r0:r1, c0:c1]
    lines = title.count("\n") + 1 if title else 0
    head = 16 * lines + 8 if title else 0  # px: 9 pt text at 110 dpi is ~14 px a line
    h, w = rgba.shape[:2]
    w_out = max(w, 7 * max(len(t) for t in title.split("\n")) + 2 * pad) if title else w  # ~7 px a character
    out = plt.figure(figsize=(w_out / dpi, (h + head) / dpi), dpi=dpi)
    out.figimage(np.ascontiguousarray(rgba), xo=int((w_out - w) // 2), yo=0, origin="upper")
    if title:
        out.text(0.5, 1.0 - 4 / (h + head), title, ha="center", va="top", fontsize=9)
    buf = io.BytesIO()
    out.savefig(buf, format="png", dpi=dpi, metadata=_PNG_META)
    plt.close(out)
    return buf.getvalue()


def render_mesh(vertices: np.ndarray, faces: np.ndarray, title: str, color=(0.7, 0.7, 0.75),
                cutaway: bool = False) -> bytes:
    """A shaded view of a triangle mesh (mm), cropped to the part. ``cutaway`` drops the half
    with y < 0 to show the inside."""
    tri = vertices[faces]
    if cutaway:
        tri = tri[tri[:, :, 1].mean(axis=1) > 0]
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_axes((0, 0, 1, 0.9), projection="3d")
    _shaded(ax, tri, color)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    _fit_axes(ax, lo, hi)
    ax.view_init(elev=15, azim=-90) if cutaway else ax.view_init(elev=22, azim=-60)
    size = hi - lo
    return _trimmed_png(fig, f"{title}\n{size[0]:.1f} x {size[1]:.1f} x {size[2]:.1f} mm")


# -- the assembled rig (rigcad view, rigcad manual) ---------------------------------------------------
def _cut_front(tri: np.ndarray) -> np.ndarray:
    """Triangles (m, 3, 3) of the far half (y > 0): a cutaway that shows what a part encloses. Long
    triangles (a flange's planar ring is triangulated in long chords) are split first, so that none
    reaches across the cut."""
    tri = _split_long(tri, rounds=8)
    return tri[(tri[:, :, 1] > -1e-9).all(axis=1)]


def rig_picture(meshes, rays: dict | None, title: str, elev: float = 18.0, azim: float = -118.0, *,
                cut_away: set[str]) -> bytes:
    """The assembled rig: every part (``rigcad.manual.assembly.PartMesh``) in its working position,
    the parts named in ``cut_away`` (those that enclose others, the dome: assembly.encloses) cut away
    in front, and ``rays`` (view.traced_rays: COP -> paraboloid -> dome -> sample polylines, mm)
    coloured by incidence angle."""
    cut = cut_away
    fig = plt.figure(figsize=(7, 8))
    ax = fig.add_axes((0, 0, 1, 0.93), projection="3d")
    lo = np.min([m.lo for m in meshes], axis=0)
    hi = np.max([m.hi for m in meshes], axis=0)
    _draw(ax, [(_cut_front(m.vertices[m.faces]) if m.name in cut else m.vertices[m.faces], m.color, 1.0)
               for m in meshes])
    if rays is not None and len(rays["lines"]):
        cmap = plt.get_cmap("viridis")
        ax.computed_zorder = False  # rays over the parts: the dome's front is cut away, so they are in view
        for line, t in zip(rays["lines"][::3], rays["theta"][::3]):
            ax.plot(line[:, 0], line[:, 1], line[:, 2], color=cmap(np.degrees(t) / 90.0), lw=0.6, zorder=5)
        lo = np.minimum(lo, rays["lines"].reshape(-1, 3).min(axis=0))
        hi = np.maximum(hi, rays["lines"].reshape(-1, 3).max(axis=0))
    _fit_axes(ax, lo, hi)
    ax.view_init(elev=elev, azim=azim)
    return _trimmed_png(fig, title + ("\nfront of the dome cut away; rays coloured by incidence angle, 0 (dark) .. 90 deg (yellow)"
                                      if rays is not None else ""))


def assembly_step(meshes, done: list[int], new: list[int], offsets: dict, title: str, elev: float = 18.0,
                  azim: float = -118.0, *, cut_away: set[str], fasteners=()) -> bytes:
    """Exploded picture of one assembly step: the parts ``done`` (indices into ``meshes``,
    ``rigcad.manual.assembly.PartMesh``) in place (grey), the parts ``new`` highlighted (orange)
    moved by ``offsets`` (index -> (3,) mm), with a dashed line to where they go; the parts named in
    ``cut_away`` (assembly.encloses) cut away in front. Parts that go in from below are seen from below.
    ``fasteners``: (start (3,), end (3,)) mm of each bolt or screw of the step, drawn as thick dark
    lines from head to tip; an x, y, z axis triad in the corner of every picture."""
    cut = cut_away
    fig = plt.figure(figsize=(6, 6.5))
    ax = fig.add_axes((0, 0, 1, 0.92), projection="3d")
    shown = [*done, *new]
    lo = np.min([meshes[i].lo for i in shown], axis=0)
    hi = np.max([meshes[i].hi for i in shown], axis=0)
    groups = []
    for i in shown:
        m = meshes[i]
        off = offsets.get(i, np.zeros(3)) if i in new else np.zeros(3)
        tri = m.vertices[m.faces] + off
        tri = _cut_front(tri) if m.name in cut and i in done else tri
        groups.append((tri, (0.95, 0.55, 0.15) if i in new else (0.8, 0.8, 0.82), 1.0))
        lo, hi = np.minimum(lo, m.lo + off), np.maximum(hi, m.hi + off)
    _draw(ax, groups)
    lift = offsets.get(new[0], np.zeros(3))
    if np.any(lift):
        ax.computed_zorder = False  # the path over the parts
        for i in new:
            c = 0.5 * (meshes[i].lo + meshes[i].hi)
            a = c + lift
            ax.plot([a[0], c[0]], [a[1], c[1]], [a[2], c[2]], "--", color="tab:red", lw=1.4, zorder=5)
            ax.scatter([c[0]], [c[1]], [c[2]], color="tab:red", s=16, marker="v" if lift[2] > 0 else "^", zorder=6)
    for a, b in fasteners:
        ax.plot([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], "-", color="black", lw=2.2, zorder=7)
        ax.scatter([a[0]], [a[1]], [a[2]], color="black", s=10, zorder=7)
    _triad(ax, lo, hi)
    _fit_axes(ax, lo, hi)
    ax.view_init(elev=-elev if lift[2] < 0 else elev, azim=azim)
    return _trimmed_png(fig, title)


def _triad(ax, lo: np.ndarray, hi: np.ndarray) -> None:
    """x (red), y (green), z (blue) arrows, a tenth of the picture's size, at its low corner."""
    size = 0.12 * float(np.max(hi - lo))
    for k, (name, color) in enumerate((("x", "tab:red"), ("y", "tab:green"), ("z", "tab:blue"))):
        d = np.zeros(3)
        d[k] = size
        ax.quiver(lo[0], lo[1], lo[2], d[0], d[1], d[2], color=color, lw=1.5, arrow_length_ratio=0.25)
        ax.text(lo[0] + 1.15 * d[0], lo[1] + 1.15 * d[1], lo[2] + 1.15 * d[2], name, color=color, fontsize=9)


# -- the 3D ray check (rigcad check) -----------------------------------------------------------
def spot_diagram(result) -> bytes:
    """Left: where the returning rays cross the sample plane z = 0 (um), theta <= 80 deg (nearer
    grazing the landing point is ill-conditioned); right: the spot radius (distance from O to each
    ray) against theta."""
    tr = result.trace
    ok = tr.ok
    theta = np.degrees(tr.theta[ok])
    land = tr.landing[ok] * 1e3
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    sel = theta <= 80
    sc = a.scatter(land[sel, 0], land[sel, 1], c=theta[sel], s=1, cmap="viridis")
    fig.colorbar(sc, ax=a, label="theta (deg)")
    a.set_aspect("equal")
    a.set_xlabel("x on the sample (um)")
    a.set_ylabel("y on the sample (um)")
    rep = result.report
    a.set_title(f"{rep['profile']['name']}: landing points\nmode {rep['mode']}, theta <= 80 deg", fontsize=10)
    b.semilogy(theta, np.maximum(tr.miss[ok] * 1e3, 1e-9), ",", alpha=0.5)
    b.set_xlabel("theta (deg)")
    b.set_ylabel("distance from O to the ray (um)")
    b.set_title("spot radius per ray", fontsize=10)
    b.grid(True, alpha=0.3)
    fig.tight_layout()
    return _png(fig)


def theta_map(result) -> bytes:
    """Incidence angle theta per projector pixel over the traced window, lost pixels grey; and
    theta against pixel radius along the fan (with px/deg)."""
    tm = result.theta_map
    g = result.report["pixel_grid"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    r0, c0 = g["window_origin_row_col"]
    h, w = tm.shape
    a.imshow(np.where(result.status_map > 1, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2,
             extent=(c0, c0 + w, r0 + h, r0), interpolation="nearest")
    im = a.imshow(tm, cmap="viridis", extent=(c0, c0 + w, r0 + h, r0), interpolation="nearest")
    fig.colorbar(im, ax=a, label="theta (deg)")
    a.set_xlabel("projector column (px)")
    a.set_ylabel("projector row (px)")
    a.set_title("incidence angle per pixel (grey: occluded)")
    f = result.fan
    b.plot(f["theta_deg"], f["pixel_radius_px"], "-")
    b2 = b.twinx()
    b2.plot(f["theta_deg"], f["px_per_deg"], "r-", lw=0.8)
    b2.set_ylabel("pixels per degree", color="r")
    b.set_xlabel("theta (deg)")
    b.set_ylabel("pixel radius from the axis (px)")
    b.set_title(f"fan at azimuth {f['summary']['azimuth_deg']:.0f} deg")
    b.grid(True, alpha=0.3)
    return _png(fig)


# -- fabrication (rigcad fab) ---------------------------------------------------------------------
def staircase_map(points: np.ndarray, cusp: np.ndarray, layer: float, title: str) -> bytes:
    """Cusp height (um) over the mirror at its contour points: azimuth (deg) x height z (mm) in
    the part's working frame; ``points`` (n, 3) mm, ``cusp`` (n,) mm."""
    ok = np.isfinite(cusp)
    p, c = points[ok], cusp[ok] * 1000.0
    if len(p) > 60000:  # enough dots for the eye; a fixed stride keeps the picture deterministic
        s = int(np.ceil(len(p) / 60000))
        p, c = p[::s], c[::s]
    az = np.degrees(np.arctan2(p[:, 1], p[:, 0])) % 360.0
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    sc = ax.scatter(az, p[:, 2], c=c, s=1.5, cmap="viridis", vmin=0.0, vmax=layer * 1000.0, linewidths=0)
    fig.colorbar(sc, ax=ax, label="cusp height (um)")
    ax.set_xlim(0, 360)
    ax.set_xlabel("azimuth about the optical axis (deg)")
    ax.set_ylabel("height z (mm, working position)")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return _png(fig, dpi=100)


def support_contact(points: np.ndarray, touched: np.ndarray, on_mirror: np.ndarray, beads: np.ndarray,
                    title: str) -> bytes:
    """Where the slicer's support touches a piece in print position (mm): the piece's surface
    samples (grey; the mirror light blue), those touched by support (orange on other faces, red
    on the mirror) and the support beads (faint), seen from the front (x-z) and from the side
    (y-z). ``points`` (n, 3), masks (n,), ``beads`` (m, 3)."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.4))
    stride = max(1, int(np.ceil(len(points) / 40000)))  # a fixed stride: deterministic pictures
    bead_stride = max(1, int(np.ceil(len(beads) / 30000)))
    for ax, (i, name) in zip(axes, ((0, "x"), (1, "y"))):
        p, m = points[::stride], on_mirror[::stride]
        ax.scatter(p[~m, i], p[~m, 2], s=0.4, c="0.75", linewidths=0, label="other faces")
        ax.scatter(p[m, i], p[m, 2], s=0.4, c="#9cc3e6", linewidths=0, label="mirror")
        if len(beads):
            b = beads[::bead_stride]
            ax.scatter(b[:, i], b[:, 2], s=0.3, c="#e0c080", alpha=0.3, linewidths=0, label="support beads")
        t_o, t_m = touched & ~on_mirror, touched & on_mirror
        ax.scatter(points[t_o, i], points[t_o, 2], s=1.5, c="#e07b00", linewidths=0, label="support contact, other")
        ax.scatter(points[t_m, i], points[t_m, 2], s=3.0, c="#d00000", linewidths=0, label="support contact, mirror")
        ax.set_xlabel(f"{name} (mm, print position)")
        ax.set_ylabel("z (mm, build direction)")
        ax.set_aspect("equal", adjustable="datalim")
    axes[0].legend(loc="upper right", fontsize=6, markerscale=6)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return _png(fig, dpi=100)


# -- basis illumination (rigcad basis) --------------------------------------------------------------
def _pyramid(tiles: np.ndarray, indices: np.ndarray, scale: float, title: str, tile_in: tuple[float, float],
             extent=None, xlabel: str | None = None, ylabel: str | None = None, aspect: str = "auto") -> bytes:
    """Tiles (K, rows, cols) of signed values laid out as the SH pyramid: row l, column m (-l..l);
    diverging colours on one scale +-``scale``, NaN (black) where nothing is shown."""
    L = int(indices[:, 0].max())
    cols = 2 * L + 1
    fig, axes = plt.subplots(L + 1, cols, figsize=(tile_in[0] * cols + 0.8, tile_in[1] * (L + 1) + 0.9),
                             squeeze=False)
    cmap = plt.get_cmap("RdBu_r").with_extremes(bad="black")
    im = None
    for ax in axes.ravel():
        ax.set_axis_off()
    for k, (l, m) in enumerate(indices):
        ax = axes[l, m + L]
        im = ax.imshow(tiles[k], cmap=cmap, vmin=-scale, vmax=scale, interpolation="nearest", aspect=aspect,
                       extent=extent)
        ax.set_title(f"l={l} m={m:+d}", fontsize=7, pad=2)
        if extent is not None and l == L and m == -L:
            ax.set_axis_on()
            ax.tick_params(labelsize=6)
            ax.set_xlabel(xlabel, fontsize=7)
            ax.set_ylabel(ylabel, fontsize=7)
    fig.suptitle(title, fontsize=9)
    fig.subplots_adjust(left=0.03, right=0.9, bottom=0.04, top=0.9, wspace=0.08, hspace=0.35)
    cax = fig.add_axes([0.92, 0.15, 0.012, 0.7])
    fig.colorbar(im, cax=cax).set_label("value (1/sqrt(sr))", fontsize=7)
    return _png(fig, dpi=100)


def basis_contact_sheet(basis) -> bytes:
    """Every projector image of a ProjectorBasis (8-bit, positive minus negative, the traced window
    only), as the SH pyramid; black: pixels that do not light the sample."""
    px = basis.pixels
    shown = basis.displayed("analytic", 8)
    tiles = np.where(basis.illumination.lit[:, None], shown, np.nan).T.reshape((-1,) + px.shape)
    rep = basis.report
    z = rep["zone"]
    return _pyramid(tiles, basis.indices, basis.images[8].scale,
                    f"{basis.profile}: projector images of the zonal basis, order {basis.order} "
                    f"(zone {z['alpha_deg']:.2f}..{z['beta_deg']:.0f} deg; {rep['projector']['pixels_lit']} lit "
                    f"pixels of {px.resolution[0]} x {px.resolution[1]}; 8 bit, positive minus negative)",
                    (1.05, 1.05), aspect="equal")


def basis_latlong_sheet(basis) -> bytes:
    """The latitude-longitude maps of thesis 4.2.1 (theta down, phi across), as the SH pyramid."""
    th, ph = np.degrees(basis.latlong_theta_rad), np.degrees(basis.latlong_phi_rad)
    step_t, step_p = (th[1] - th[0]) if len(th) > 1 else 1.0, (ph[1] - ph[0]) if len(ph) > 1 else 1.0
    extent = (ph[0] - step_p / 2, ph[-1] + step_p / 2, th[-1] + step_t / 2, th[0] - step_t / 2)
    return _pyramid(basis.latlong, basis.indices, float(np.max(np.abs(basis.latlong))),
                    f"{basis.profile}: latitude-longitude maps of the zonal basis, order {basis.order} "
                    f"(thesis 4.2.1; float values)", (1.5, 0.7), extent, "phi (deg)", "theta (deg)")


def basis_simulation(report: dict) -> bytes:
    """The simulated acquisition on the rig (rigcad.basis.acquire's report): coefficient errors
    (Gram recovery) per model and order, against eq. 4.3 over the lit part of the zone and over the
    whole zone, for the rig as designed and moved; and the lobe-width study."""
    rigs = report["rigs"]
    names = list(report["models"])
    orders = report["orders"]
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.4))
    markers = ["o", "s", "^", "D", "v"]
    colours = plt.get_cmap("tab10")
    for ax, key, rec, title in ((axes[0], "coefficients_vs_lit_zone_rel_l2", "none",
                                 "no correction, against eq. 4.3 over the lit zone"),
                                (axes[1], "coefficients_vs_zone_rel_l2", "gram",
                                 "Gram recovery, against eq. 4.3 over the whole zone")):
        for ri, (rk, rv) in enumerate(rigs.items()):
            for oi, o in enumerate(orders):
                y = [rv["models"][n][f"order_{o}"][key][rec] for n in names]
                x = np.arange(len(names)) + (ri - (len(rigs) - 1) / 2) * 0.22
                ax.semilogy(x, y, markers[oi % len(markers)], color=colours(ri), ms=5,
                            label=f"{rv['rig']}, order {o}" if ax is axes[0] else None)
        ax.axhline(0.01, color="0.4", ls="--", lw=0.8)
        ax.set_xticks(np.arange(len(names)))
        ax.set_xticklabels(names, fontsize=8, rotation=20)
        ax.set_ylabel("relative L2 error of the zonal coefficients")
        ax.set_title(f"{report['bits']} bit, {title}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=len(rigs), frameon=False)
    lobe = report["lobe_width_study"]["rows"]
    ax = axes[2]
    if lobe:
        r = [row["width_over_pitch"] for row in lobe]
        e = [max(row["rel_l2_error"], 1e-13) for row in lobe]  # log axis: round-off shown at 1e-13
        ax.loglog(r, e, "o-")
        ax.axvline(1.0, color="0.4", ls="--", lw=0.8)
        ax.set_xlabel("lobe width / projector pixel pitch")
        ax.set_ylabel("relative L2 error (no correction)")
        ax.set_title(f"Ward lobe narrowing (order {report['lobe_width_study']['order']}, "
                     f"pitch {np.degrees(lobe[0]['pitch_rad']):.2f} deg)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    else:
        ax.set_axis_off()
    fig.suptitle(f"{report['profile']}: simulated acquisition on the rig (thesis 3.3.1), zone "
                 f"{report['zone']['alpha_deg']:.2f}..{report['zone']['beta_deg']:.0f} deg, "
                 f"{report['camera']['exitant_directions']} exitant directions", fontsize=10)
    fig.tight_layout(rect=(0, 0.05 + 0.035 * len(orders), 1, 1))
    return _png(fig, dpi=100)


def optimize_history(report: dict) -> bytes:
    """``rigcad optimize``: the merit of every evaluation in order (feasible, infeasible, polish) and
    the best so far; a second panel per objective for two or more."""
    rows = [r for r in report["evaluations"] if r["objectives"] is not None]
    objectives = report["spec"]["objectives"]
    n = len(objectives)
    fig, axes = plt.subplots(1, n, figsize=(6.5 * n, 4.2), squeeze=False)
    for k, obj in enumerate(objectives):
        ax = axes[0, k]
        name, sense = obj["name"], obj["sense"]
        idx = np.array([r["index"] for r in rows])
        val = np.array([r["objectives"][name] for r in rows])
        feas = np.array([r["feasible"] for r in rows])
        pol = np.array([r["phase"] == "polish" for r in rows])
        ax.scatter(idx[~feas], val[~feas], s=8, color="0.75", label="violates a constraint")
        ax.scatter(idx[feas & ~pol], val[feas & ~pol], s=10, color="tab:blue", label="feasible (global search)")
        ax.scatter(idx[feas & pol], val[feas & pol], s=12, color="tab:orange", label="feasible (local polish)")
        if sense.startswith("target "):
            ax.axhline(float(sense.split()[1]), color="k", lw=1.2, label="target")
        elif feas.any():
            best = np.where(feas, val if sense == "minimize" else -val, np.inf)
            run = np.minimum.accumulate(best)
            ok = np.isfinite(run)
            ax.step(idx[ok], (run if sense == "minimize" else -run)[ok], where="post", color="k", lw=1.2,
                    label="best feasible so far" if n == 1 else None)
        base = report.get("base")
        if base and base.get("objectives"):
            ax.axhline(base["objectives"][name], color="tab:red", ls="--", lw=1, label="base design")
        unit = obj["unit"]
        ax.set_xlabel("evaluation")
        ax.set_ylabel(f"{name} ({unit})" if unit else name)
        ax.set_title(f"{name}: {sense}", fontsize=10)
        ax.grid(alpha=0.3)
        if feas.any():
            lo, hi = np.nanmin(val[feas]), np.nanmax(val[feas])
            ref = base["objectives"][name] if base and base.get("objectives") else lo
            lo, hi = min(lo, ref), max(hi, ref)
            pad = 0.15 * (hi - lo) + 1e-9
            ax.set_ylim(lo - pad, hi + pad)
        if k == 0:
            ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{report['profile']}: {report['method']}, {len(report['evaluations'])} evaluations, seed "
                 f"{report['spec']['seed']}", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def optimize_pareto(report: dict) -> bytes:
    """``rigcad optimize``: the first two objectives of every feasible design, the Pareto front, the
    base design (e.g. Table 3.1) and the chosen design."""
    objectives = report["spec"]["objectives"]
    a = objectives[0]
    b = objectives[1] if len(objectives) > 1 else {"name": "px_per_deg_cv", "unit": "", "sense": "minimize"}
    rows = [r for r in report["evaluations"] if r["objectives"] is not None]

    def val(r, o):
        return r["objectives"][o["name"]] if o["name"] in r["objectives"] else r["figures"][_FIGURE.get(o["name"], o["name"])]

    fig, ax = plt.subplots(figsize=(7, 5.2))
    inf = [r for r in rows if not r["feasible"]]
    feas = [r for r in rows if r["feasible"]]
    if inf:
        ax.scatter([val(r, a) for r in inf], [val(r, b) for r in inf], s=7, color="0.8", label="violates a constraint")
    if feas:
        ax.scatter([val(r, a) for r in feas], [val(r, b) for r in feas], s=10, color="tab:blue", alpha=0.6,
                   label="feasible")
    front = sorted(report["pareto"], key=lambda r: val(r, a))
    if front:
        ax.plot([val(r, a) for r in front], [val(r, b) for r in front], "-o", color="tab:green", ms=4, lw=1.2,
                label=f"Pareto front ({len(front)})")
    base = report.get("base")
    if base and base.get("objectives"):
        ax.plot([val(base, a)], [val(base, b)], "r*", ms=14, label="base design")
    chosen = report.get("chosen")
    if chosen:
        ax.plot([val(chosen, a)], [val(chosen, b)], "D", color="tab:orange", ms=9, mec="k", label="chosen design")
    ax.set_xlabel(f"{a['name']} ({a['unit']})" if a["unit"] else a["name"])
    ax.set_ylabel(f"{b['name']} ({b['unit']})" if b["unit"] else b["name"])
    ax.set_title(f"{report['profile']}: objectives of every design", fontsize=10)
    if feas:
        xs = [val(r, a) for r in feas] + ([val(base, a)] if base and base.get("objectives") else [])
        ys = [val(r, b) for r in feas] + ([val(base, b)] if base and base.get("objectives") else [])
        px, py = 0.1 * (max(xs) - min(xs)) + 1e-9, 0.1 * (max(ys) - min(ys)) + 1e-9
        ax.set_xlim(min(xs) - px, max(xs) + px)
        ax.set_ylim(min(ys) - py, max(ys) + py)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _png(fig)


#: Figure keys of the objectives (rigcad.optimize.spec.OBJECTIVES), for the Pareto plot's second axis.
_FIGURE = {"px_per_deg_cv": "px_per_deg_cv", "theta_min": "theta_min_deg"}


def tolerance_histograms(profile, columns: dict, summary: dict) -> bytes:
    """Monte Carlo of the rig's builds: histograms of the worst spot radius (mm) and calibrated
    angle error (deg) per build, the targets marked, the yield in the title."""
    tol = profile.tolerancing
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    spot = np.asarray(columns["max_spot_radius_mm"], float)
    ang = np.degrees(np.asarray(columns["max_mirror_angle_error_rad"], float))
    for ax, v, target, label, unit in ((a1, spot, tol.max_spot_radius, "largest spot radius per build (mm)", "mm"),
                                       (a2, ang, np.degrees(tol.max_angle_error),
                                        "largest calibrated angle error per build (deg)", "deg")):
        finite = v[np.isfinite(v)]
        ax.hist(finite, bins=60, color="tab:blue", alpha=0.8)
        ax.axvline(target, color="tab:red", lw=1.5, label=f"target {target:g} {unit}")
        ax.set_xlabel(label)
        ax.set_ylabel("builds")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{profile.name}: {summary['samples']} builds, yield {summary['yield']:.1%} "
                 f"(required {tol.min_yield:.0%})", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def tolerance_sensitivity(profile, limits: list[dict]) -> bytes:
    """Per toleranced parameter (ranked): the share of the spot and angle targets it uses alone at
    its tolerance, and its inverse limit over its tolerance (log scale)."""
    names = [r["parameter"] for r in limits]
    y = np.arange(len(names))[::-1]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 0.35 * len(names) + 1.8), sharey=True)
    a1.barh(y + 0.2, [r["spot_budget_used"] * 100 for r in limits], 0.4, label="spot radius", color="tab:blue")
    a1.barh(y - 0.2, [r["angle_budget_used"] * 100 for r in limits], 0.4, label="angle error", color="tab:orange")
    a1.set_yticks(y, names)
    a1.set_xlabel("share of the target used at the tolerance (%)")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3, axis="x")
    ratio = [r["limit_over_tolerance"] for r in limits]
    finite = [v if np.isfinite(v) else np.nan for v in ratio]
    colors = ["tab:green" if r["limit_found"] else "0.6" for r in limits]
    a2.barh(y, finite, 0.5, color=colors)
    a2.axvline(1.0, color="tab:red", lw=1)
    a2.set_xscale("log")
    a2.set_xlabel("inverse limit (angle target) / tolerance\n(grey: none below the search cap)")
    a2.grid(alpha=0.3, axis="x")
    fig.suptitle(f"{profile.name}: sensitivity and inverse limits", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def sweep_plot(key: str, unit: str, rows: list[dict], columns: list[tuple[str, str]]) -> bytes:
    """A parameter sweep: each of ``columns`` ((row key, axis label)) against the swept value."""
    x = np.array([r["value"] for r in rows], float)
    fig, axes = plt.subplots(1, len(columns), figsize=(4 * len(columns), 3.6))
    for ax, (k, label) in zip(np.atleast_1d(axes), columns):
        yv = np.array([r.get(k, np.nan) if r.get(k) is not None else np.nan for r in rows], float)
        ok = np.array([r["ok"] for r in rows])
        ax.plot(x[ok], yv[ok], "o-", ms=3, color="tab:blue")
        if (~ok).any():
            ax.plot(x[~ok], np.zeros((~ok).sum()), "x", color="tab:red", label="refused")
            ax.legend(fontsize=8)
        ax.set_xlabel(f"{key} ({unit})")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return _png(fig)


def calibration_maps(phase: np.ndarray, slope_mrad: np.ndarray, planted_mrad: np.ndarray | None,
                     corrected_deg: np.ndarray | None, design_deg: np.ndarray | None, title: str,
                     causes: np.ndarray | None = None, cause_names: tuple[str, ...] = ()) -> bytes:
    """Deflectometric calibration (rigcad calibrate), over the camera window: the decoded phase of the
    finest x period (rad), the dome's residual slope magnitude (mrad) and, for a simulation, the
    planted one and the corrected and design maps' incidence errors (deg); last, why each lit pixel
    is or is not measured (``causes``: index into ``cause_names``, -1 not lit). Arrays (rows, cols),
    NaN where there is nothing to show."""
    panels = [("decoded x phase, finest period (rad)", phase, "twilight"),
              ("residual slope |grad h| (mrad)", slope_mrad, "magma")]
    if planted_mrad is not None:
        panels.append(("planted slope |grad h| (mrad)", planted_mrad, "magma"))
    if corrected_deg is not None and design_deg is not None:
        panels += [("corrected map: incidence error (deg)", corrected_deg, "viridis"),
                   ("design map: incidence error (deg)", design_deg, "viridis")]
    if causes is not None:
        panels.append(("measured, or why not", causes, "causes"))
    fig, axes = plt.subplots(1, len(panels), figsize=(3.4 * len(panels), 3.4))
    slope_top = np.nanpercentile(np.concatenate([slope_mrad[np.isfinite(slope_mrad)]] + (
        [planted_mrad[np.isfinite(planted_mrad)]] if planted_mrad is not None else [])), 99)
    for ax, (name, data, cmap) in zip(np.atleast_1d(axes), panels):
        if cmap == "causes":
            _cause_panel(fig, ax, data, cause_names, name)
            continue
        top = slope_top if "slope" in name else (np.nanpercentile(data, 99) if np.isfinite(data).any() else 1.0)
        im = ax.imshow(data, cmap=cmap, vmin=0, vmax=top, interpolation="nearest")
        ax.set_title(name, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return _png(fig)


def _cause_panel(fig, ax, causes: np.ndarray, names: tuple[str, ...], title: str) -> None:
    """One categorical panel: each pixel's cause in its own colour (not lit: blank), named on the bar."""
    from matplotlib.colors import ListedColormap

    colours = ["#2a9d8f", "#264653", "#8d99ae", "#e9c46a", "#f4a261", "#e76f51", "#9b5de5", "#00bbf9"][:len(names)]
    shown = np.where(causes >= 0, causes, np.nan).astype(float)
    im = ax.imshow(shown, cmap=ListedColormap(colours), vmin=-0.5, vmax=len(names) - 0.5, interpolation="nearest")
    ax.set_title(title, fontsize=8)
    ax.set_xticks([])
    ax.set_yticks([])
    bar = fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04, ticks=range(len(names)))
    bar.ax.set_yticklabels([n.replace("_", " ") for n in names], fontsize=6)


def template_drawing(row: dict) -> bytes:
    """A profile template drawn flat in its gauging plane (``rigcad.manual.finishing.template_datums``'
    row, mm): its outline, the gauging edge (thick), the datum (red: an edge or a corner) and the rig's
    axis (dashed), with the template's width and height."""
    fig, ax = plt.subplots(figsize=(4.4, 4.8))
    xy = np.asarray(row["outline_mm"], float)
    xy = np.vstack([xy, xy[:1]])
    ax.fill(xy[:, 0], xy[:, 1], color=(0.95, 0.85, 0.3), alpha=0.5, lw=0)
    ax.plot(xy[:, 0], xy[:, 1], color="0.3", lw=1.0)
    for g in row["gauging_edge_mm"]:
        g = np.asarray(g, float)
        ax.plot(g[:, 0], g[:, 1], color="tab:blue", lw=2.4)
    d = np.asarray(row["datum_mm"], float)
    if row["datum"] == "rim":  # the feet from the cut-out's ends, in the rim's plane
        for x, z in d:
            ax.plot([x, x + np.sign(x) * row["datum_length_mm"]], [z, z], color="tab:red", lw=3.0)
        label = f"datum: the feet in the rim's plane, z = {row['datum_z_mm']:.1f} mm"
    elif row["datum"] == "edge":
        ax.plot(d[:, 0], d[:, 1], color="tab:red", lw=3.0)
        label = f"datum edge, z = {row['datum_z_mm']:.1f} mm"
    else:
        ax.plot(d[:, 0], d[:, 1], "o", color="tab:red", ms=9)
        label = f"datum corner: on the plate, {row['datum_r_mm']:.1f} mm from the axis"
    ax.annotate(label, tuple(d.mean(axis=0)), xytext=(0.5, 0.04), textcoords="axes fraction", ha="center", color="0.1",
                fontsize=8, arrowprops={"arrowstyle": "->", "color": "0.1", "lw": 0.8})  # only the datum is red
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    pad = 0.08 * float(np.max(hi - lo))
    ax.plot([row["axis_x_mm"]] * 2, [lo[1] - pad, hi[1] + pad], "--", color="0.2", lw=1.0)
    ax.text(row["axis_x_mm"], hi[1] + pad, " axis", fontsize=8, va="bottom")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("mm from the rig's axis")
    ax.set_ylabel("mm above the sample plane")
    ax.grid(alpha=0.3)
    return _trimmed_png(fig, f"{row['template']} ({row['width_mm']:.1f} x {row['height_mm']:.1f} mm)\n"
                             "gauging edge blue, datum red")


def scale_bar_length(extent: float) -> float:
    """A scale bar's length (mm) for a drawing ``extent`` mm across: the largest 1, 2 or 5 x 10^k at most a
    quarter of it."""
    target = extent / 4.0
    k = 10.0 ** math.floor(math.log10(target))
    return max(m * k for m in (1.0, 2.0, 5.0) if m * k <= target)


def _scale_bar(ax) -> float:
    """A scale bar in the axes' lower left corner (data units: mm), labelled; returns its length."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    length = scale_bar_length(x1 - x0)
    bx, by = x0 + 0.05 * (x1 - x0), y0 + 0.06 * (y1 - y0)
    ax.plot([bx, bx + length], [by, by], color="0.1", lw=3, solid_capstyle="butt")
    ax.text(bx + length / 2, by + 0.02 * (y1 - y0), f"{length:g} mm", ha="center", va="bottom", fontsize=7)
    return length


def measurement_figure(sketch, what: str, extra=(), dims=(), fmt: str = "png") -> bytes:
    """One size to measure before printing (rigcad.profile.instruments.sketch): the instrument's
    outline in its view (or the sketch's detail window), the dimension drawn between its two
    features (an arrow at each end; a call-out when the two are one feature), labelled with its
    assumed value; ``what`` (the features in words) under the title; a scale bar (mm). ``extra``:
    named outlines drawn dashed blue over it (what receives the feature: the shelf's slots);
    ``dims``: further dimensions ((x0, y0), (x1, y1), label) drawn thin with their labels. ``fmt``:
    "png", or "svg" with its text kept as text (a reader can read the labels back)."""
    import textwrap

    with plt.rc_context({"svg.fonttype": "none", "svg.hashsalt": "rigcad"}):
        return _measurement_figure(sketch, what, extra, dims, fmt, textwrap)


def _measurement_figure(sketch, what: str, extra, dims, fmt: str, textwrap) -> bytes:
    fig, ax = plt.subplots(figsize=(4.4, 3.6))
    for _name, pts in extra:
        xy = np.asarray(pts, float)
        ax.plot(xy[:, 0], xy[:, 1], "--", color="tab:blue", lw=0.9)
    for (dx0, dy0), (dx1, dy1), text in dims:
        ax.annotate("", (dx1, dy1), (dx0, dy0), arrowprops={"arrowstyle": "<->", "color": "0.15", "lw": 0.8,
                                                             "shrinkA": 0, "shrinkB": 0})
        ax.text(0.5 * (dx0 + dx1), 0.5 * (dy0 + dy1), text, ha="center", va="center", fontsize=7, color="0.1",
                bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1})
    for name, pts in sketch.outlines:
        xy = np.asarray(pts, float)
        dashed = name in ("centre line", "wall") or "(cut)" in name
        ax.plot(xy[:, 0], xy[:, 1], "--" if dashed else "-", color="0.35", lw=1.0 if dashed else 1.4)
    for _name, (cx, cy), r in sketch.circles:
        t = np.linspace(0.0, 2 * np.pi, 97)
        ax.plot(cx + r * np.cos(t), cy + r * np.sin(t), color="0.35", lw=1.2)
    (x0, y0), (x1, y1) = sketch.dimension
    red = {"color": "tab:red", "fontsize": 8, "bbox": {"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1}}
    if (x0, y0) != (x1, y1):
        ax.annotate("", (x1, y1), (x0, y0), arrowprops={"arrowstyle": "<->", "color": "tab:red", "lw": 1.6,
                                                         "shrinkA": 0, "shrinkB": 0})
    # the label off the dimension's middle, up and right in the axes, with a leader to it
    ax.annotate(sketch.label, (0.5 * (x0 + x1), 0.5 * (y0 + y1)), xytext=(0.62, 0.9), textcoords="axes fraction",
                ha="center", arrowprops={"arrowstyle": "-" if (x0, y0) != (x1, y1) else "->", "color": "tab:red",
                                         "lw": 0.8}, **red)
    ax.set_aspect("equal", adjustable="datalim")
    if sketch.window is not None:
        (wx0, wy0), (wx1, wy1) = sketch.window
        ax.set_xlim(wx0, wx1)
        ax.set_ylim(wy0, wy1)
        ax.set_aspect("equal", adjustable="box")
    else:
        ax.margins(0.12)
    ax.set_xlabel(sketch.axes[0], fontsize=7)
    ax.set_ylabel(sketch.axes[1], fontsize=7)
    ax.tick_params(labelsize=7)
    detail = ", detail" if sketch.window is not None else ""
    ax.set_title(f"{sketch.key} ({sketch.view} view{detail})\n" + "\n".join(textwrap.wrap(what, 58)), fontsize=8)
    fig.tight_layout()
    ax.apply_aspect()  # the limits as drawn, before the bar is placed in them
    ax.set_autoscale_on(False)
    _scale_bar(ax)
    if fmt == "svg":
        buf = io.BytesIO()
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
        plt.close(fig)
        return buf.getvalue()
    return _png(fig, dpi=100)


def turned_part_drawing(drawing, fmt: str = "png") -> bytes:
    """A part turned from bar (rigcad.manual.drawings.TurnedDrawing) as a dimensioned side view: its
    outline and axis, each diameter across its step, each length beside the part (the labels as the
    drawing states them, tolerances included), a 10 mm scale bar and the notes under it. ``fmt``: "png",
    or "svg" with its text kept as text (a reader can read the dimensions back); both deterministic."""
    import textwrap

    steps = drawing.steps
    width = max(d for d, _ in steps)
    total = sum(h for _, h in steps)
    with plt.rc_context({"svg.fonttype": "none", "svg.hashsalt": "rigcad"}):
        fig, ax = plt.subplots(figsize=(6.4, 3.6))
        z = 0.0
        outline = []
        for d, h in steps:  # the right half, bottom up, then mirrored
            outline += [(d / 2, z), (d / 2, z + h)]
            z += h
        right = np.array([(0.0, 0.0), *outline, (0.0, total)])
        xy = np.vstack([right, right[::-1] * [-1, 1]])
        ax.fill(xy[:, 0], xy[:, 1], color=(0.8, 0.85, 0.9), lw=0)
        ax.plot(xy[:, 0], xy[:, 1], color="0.1", lw=1.4)
        z = 0.0
        for d, h in steps[:-1]:  # the shoulders between the steps
            z += h
            ax.plot([-d / 2, d / 2], [z, z], color="0.1", lw=1.0)
        ax.plot([0, 0], [-0.15 * total, 1.15 * total], "-.", color="0.3", lw=0.8)
        arrow = {"arrowstyle": "<->", "color": "tab:red", "lw": 1.0, "shrinkA": 0, "shrinkB": 0}
        red = {"color": "tab:red", "fontsize": 8, "ha": "center",
               "bbox": {"fc": "white", "ec": "none", "alpha": 0.9, "pad": 1}}
        dims = {dim.name: dim for dim in drawing.dimensions}
        diameters = [dim for dim in drawing.dimensions if dim.diameter]
        z = 0.0
        for (d, h), dim in zip(steps, sorted(diameters, key=lambda m: m.value)[::-1] if len(steps) > 1 else diameters):
            ax.annotate("", (d / 2, z + h / 2), (-d / 2, z + h / 2), arrowprops=arrow)
            ax.text(0, z + h / 2, dim.label, va="center", **red)
            z += h
        x = width / 2
        z = 0.0
        for k, ((_, h), name) in enumerate(zip(steps, ("collar_thickness", "body_length"))):
            if name in dims:
                ax.annotate("", (x + 4, z), (x + 4, z + h), arrowprops=arrow)
                ax.text(x + 5, z + h / 2, dims[name].label, va="center", **{**red, "ha": "left"})
            z += h
        if "overall_length" in dims:
            ax.annotate("", (x + 16, 0), (x + 16, total), arrowprops=arrow)
            ax.text(x + 17, total / 2, dims["overall_length"].label, va="center", **{**red, "ha": "left"})
        ax.plot([-width / 2, -width / 2 + 10], [-0.12 * total] * 2, color="0.1", lw=3)  # the scale bar
        ax.text(-width / 2 + 5, -0.12 * total - 1.0, "10 mm", ha="center", va="top", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlim(-width / 2 - 4, width / 2 + 30)
        ax.set_ylim(-0.3 * total - 2, 1.2 * total)
        ax.axis("off")
        ax.set_title(drawing.title, fontsize=10)
        fig.text(0.04, 0.02, "\n".join(textwrap.fill(n, 100) for n in drawing.notes), fontsize=7, va="bottom")
        fig.subplots_adjust(left=0.02, right=0.98, bottom=0.3, top=0.9)
        buf = io.BytesIO()
        if fmt == "svg":
            fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
        else:
            fig.savefig(buf, format="png", dpi=130, metadata=_PNG_META)
        plt.close(fig)
    return buf.getvalue()
