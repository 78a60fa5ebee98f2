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


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata=_PNG_META)
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
