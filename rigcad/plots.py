"""Every figure rigcad draws (matplotlib, Agg). Functions take results and return PNG bytes;
they compute nothing that a report does not already hold. PNGs carry no software/date metadata,
so the same result gives the same bytes."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

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
        sec.set_xlabel("projector pixel from the axis")
    else:
        a2.text(0.5, 0.5, "COP at infinity: no pixel grid", ha="center", va="center")
        a2.set_axis_off()
    fig.suptitle(f"{design.profile.name}: incidence angle per paraboloid point", fontsize=10)
    fig.tight_layout()
    return _png(fig)


def render_mesh(vertices: np.ndarray, faces: np.ndarray, title: str, color=(0.7, 0.7, 0.75),
                cutaway: bool = False) -> bytes:
    """A shaded view of a triangle mesh (mm). ``cutaway`` drops the half with y < 0 to show the inside."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    tri = vertices[faces]
    if cutaway:
        tri = tri[tri[:, :, 1].mean(axis=1) > 0]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    light = np.array([-0.4, -0.6, 0.7])
    light /= np.linalg.norm(light)
    shade = 0.35 + 0.65 * np.abs(n @ light)
    rgb = np.clip(np.outer(shade, color), 0, 1)
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(tri, facecolors=rgb, edgecolors="none", linewidths=0))
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    mid, span = (lo + hi) / 2, float((hi - lo).max()) / 2
    ax.set_xlim(mid[0] - span, mid[0] + span)
    ax.set_ylim(mid[1] - span, mid[1] + span)
    ax.set_zlim(mid[2] - span, mid[2] + span)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=15, azim=-90) if cutaway else ax.view_init(elev=22, azim=-60)
    ax.set_axis_off()
    size = hi - lo
    ax.set_title(f"{title}\n{size[0]:.1f} x {size[1]:.1f} x {size[2]:.1f} mm", fontsize=9)
    return _png(fig)


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
    a.set_title(f"{rep['profile']['name']}: landing points, mode {rep['mode']}")
    b.semilogy(theta, np.maximum(tr.miss[ok] * 1e3, 1e-9), ",", alpha=0.5)
    b.set_xlabel("theta (deg)")
    b.set_ylabel("distance from O to the ray (um)")
    b.set_title("spot radius per ray")
    b.grid(True, alpha=0.3)
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
