"""float32 against float64 in the ray path, measured on the same rays (issue 7, table e).

Run from the repository root: ``.venv/bin/python bench/float32.py [--exports DIR]``. Writes
bench/results/float32.json and float32.png.

Embree's BVH and its hits are float32 (rigcad.check.rays.EmbreeMesh); the checker re-intersects
each hit's triangle in float64 (Moller-Trumbore) and computes the normal from float64 barycentrics.
``refine=False`` keeps Embree's own float32 distance, barycentrics and facet normal. Over the same
seeded pinhole rays, at three mirror tessellations (coarse, the profile's default, fine), this
compares per ray:

* float32 - float64 on the same mesh (``float32_minus_float64``): what float32 alone contributes;
* float64 mesh - exact surfaces (``mesh_minus_exact``): what the tessellation contributes;
* float32 mesh - exact (``float32_mesh_minus_exact``): both together (what an unrefined checker reports);

for the smooth (vertex-normal) and facet (STL-literal) readings: paraboloid and dome hit points
(mm), arrival directions (rad), spot radius at O (mm), and the fraction of rays whose fate
(reached the sample, occluded, ...) differs. The exact reference is the analytic float64 tracer.
Timings (``*_s``) are one trace each. Not asserted.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import arguments, png, pyplot, run_info

from rigcad.check.figures import _angles
from rigcad.check.scene import analytic_optics, mesh_optics, mirror_meshes, share_scenes
from rigcad.check.sources import annulus_rays
from rigcad.check.trace3d import trace
from rigcad.export.atomic import write_bytes, write_json
from rigcad.rig import Rig
from rigcad.profile import load_profile

RAYS = 200_000
SEED = 2006
#: (name, mirror chord error mm, facet-normal error rad); "default" is the profile's pair.
LEVELS = (("coarse", 0.01, 0.03), ("default", None, None), ("fine", 0.0003, 0.003))


def compare(a, b) -> dict:
    """Per-ray differences between traces a and b of the same rays (units in keys)."""
    both = a.ok & b.ok
    dp1 = np.linalg.norm(a.p1[both] - b.p1[both], axis=1)
    dp2 = np.linalg.norm(a.p2[both] - b.p2[both], axis=1)
    ang = _angles(a.arrival[both], b.arrival[both])
    dmiss = np.abs(a.miss[both] - b.miss[both])

    def mr(v):
        return {"max": float(v.max()), "p99": float(np.percentile(v, 99)), "rms": float(np.sqrt(np.mean(v ** 2)))} \
            if v.size else None

    return {"rays_compared": int(both.sum()), "paraboloid_hit_mm": mr(dp1), "dome_hit_mm": mr(dp2),
            "arrival_angle_rad": mr(ang), "spot_radius_mm": mr(dmiss),
            # in the facet reading a ray that moves onto a neighbouring facet turns by up to twice the
            # facet-normal step between them: count those jumps apart from the smooth part
            "arrival_angle_over_1e-4_rad_fraction": float(np.mean(ang > 1e-4)) if ang.size else None,
            "fate_differs_fraction": float(np.mean(a.status != b.status))}


def spot(tr) -> dict:
    m = tr.miss[tr.ok]
    return {"max_spot_radius_mm": float(m.max()), "rms_spot_radius_mm": float(np.sqrt(np.mean(m ** 2)))}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--exports", default="exports")
    ap.add_argument("--rays", type=int, default=RAYS)
    args = ap.parse_args()
    n = 5_000 if args.quick else args.rays
    levels = LEVELS[1:2] if args.quick else LEVELS
    run = run_info()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
    design = rig.incidence
    rays = annulus_rays(design, n, SEED)
    t0 = time.perf_counter()
    exact = trace(analytic_optics(rig), rays.origins, rays.dirs)
    result = {"profile": profile.name, "rays": n, "seed": SEED, "analytic": {**spot(exact), "trace_s": time.perf_counter() - t0},
              "levels": [], "run": run}
    for name, chord, normal in levels:
        if chord is None:
            meshes = mirror_meshes(rig, Path(args.exports))
        else:
            meshes = mirror_meshes(rig, None, chord, normal)
        base = mesh_optics(meshes, "smooth")
        level = {"level": name, "tessellation": meshes.tolerances,
                 "triangles": {"paraboloid": len(meshes.paraboloid.faces), "dome": len(meshes.dome.faces)},
                 "readings": {}}
        for reading in ("smooth", "mesh"):
            traces, times = {}, {}
            for refine in (True, False):
                t0 = time.perf_counter()
                traces[refine] = trace(share_scenes(base, reading, refine=refine), rays.origins, rays.dirs)
                times["float64_refined_s" if refine else "float32_embree_s"] = time.perf_counter() - t0
            f64, f32 = traces[True], traces[False]
            level["readings"][reading] = {
                "float64": spot(f64), "float32": spot(f32),
                "float32_minus_float64": compare(f32, f64),
                "mesh_minus_exact": compare(f64, exact),
                "float32_mesh_minus_exact": compare(f32, exact),
                "trace_s": times,
            }
            r = level["readings"][reading]
            print(f"{name:>8} {reading:>6}: angle max f32-f64 {r['float32_minus_float64']['arrival_angle_rad']['max']:.2e}"
                  f"  mesh-exact {r['mesh_minus_exact']['arrival_angle_rad']['max']:.2e} rad; spot max f32-f64 "
                  f"{r['float32_minus_float64']['spot_radius_mm']['max']:.2e}  mesh-exact "
                  f"{r['mesh_minus_exact']['spot_radius_mm']['max']:.2e} mm; dome hit f32-f64 "
                  f"{r['float32_minus_float64']['dome_hit_mm']['max']:.2e} mm", flush=True)
        result["levels"].append(level)
        del base, meshes
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "float32.json", result))
    write_bytes(args.out / "float32.png", plot(result))


def plot(result: dict) -> bytes:
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.6))
    tri = [lv["triangles"]["paraboloid"] + lv["triangles"]["dome"] for lv in result["levels"]]
    for ax, key, unit in ((axes[0], "arrival_angle_rad", "rad"), (axes[1], "spot_radius_mm", "mm")):
        for reading, mark in (("smooth", "o"), ("mesh", "s")):
            for comp, style, lab in (("float32_minus_float64", "-", "float32 - float64 (same mesh)"),
                                     ("mesh_minus_exact", "--", "float64 mesh - exact")):
                ax.loglog(tri, [lv["readings"][reading][comp][key]["max"] for lv in result["levels"]],
                          mark + style, label=f"{reading}: {lab}")
        ax.set_xlabel("mirror triangles (paraboloid + dome)")
        ax.set_ylabel(f"max over {result['rays']} rays ({unit})")
        ax.set_title({"arrival_angle_rad": "arrival direction", "spot_radius_mm": "spot radius at O"}[key], fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("What Embree's float32 hits contribute, against the tessellation error", fontsize=11)
    fig.tight_layout()
    return png(fig)


if __name__ == "__main__":
    main()
