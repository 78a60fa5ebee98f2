"""3D ray check throughput: 1 million pinhole rays through the default mirror meshes, end to end
(ray generation, Embree, float64 refinement, reflections, occluders; then, timed apart, the spot
and angle figures)
against raw embreex on the same rays and meshes (the very EmbreeScene.run calls the tracer made,
replayed with their recorded float32 inputs and timed alone), side by side on one core's worth of
the same process; plus the analytic (exact surfaces, float64) tracer and each reading's errors.

Run from the repository root: ``.venv/bin/python bench/raycheck.py [--rays N] [--exports DIR]``.
Writes bench/results/raycheck.json and bench/results/raycheck.png. Timings (keys ending in ``_s``
and rates) vary run to run; they are never asserted.
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np

from rigcad.check import montecarlo as MC
from rigcad.check.rays import Timer, embree_version
from rigcad.check.scene import analytic_optics, mesh_optics, rig_meshes, share_scenes
from rigcad.check.sources import annulus_rays
from rigcad.check.trace3d import trace
from rigcad.export.atomic import write_bytes, write_json
from rigcad.plots import _png, plt
from rigcad.rig import Rig
from rigcad.profile import load_profile

OUT = Path(__file__).resolve().parent / "results"
REPEATS = 3  # best of, for both sides (the machine may be shared: the best run is the least disturbed)


def end_to_end(optics, design, n, seed):
    """Rays generated and traced (seconds), then reduced to figures (seconds, incl. the design
    direction of every ray: a quintic spline per ray); returns (trace_s, figures_s, figures)."""
    t0 = time.perf_counter()
    rays = annulus_rays(design, n, seed)
    tr = trace(optics, rays.origins, rays.dirs)
    t1 = time.perf_counter()
    f = MC.figures(tr, design.direction(rays.chief))
    return t1 - t0, time.perf_counter() - t1, f


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--exports", default="exports")
    args = ap.parse_args()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
    design = rig.incidence
    t0 = time.perf_counter()
    meshes = rig_meshes(rig, Path(args.exports))
    mesh_s = time.perf_counter() - t0
    timer = Timer()
    base = mesh_optics(meshes, "smooth", timer=timer)
    build_s = sum(m.build_s for m in (base.paraboloid, base.dome, base.beam))
    result = {"profile": profile.name, "rays": args.rays, "machine": platform.processor() or platform.machine(),
              "embreex": embree_version(), "meshes": meshes.sources(),
              "triangles": {"paraboloid": len(meshes.paraboloid.faces), "dome": len(meshes.dome.faces),
                            "paraboloid_mount": len(meshes.mount.faces), "beam": len(meshes.beam.faces)},
              "tessellation": meshes.tolerances, "mesh_obtain_s": mesh_s, "embree_bvh_build_s": build_s,
              "readings": {}}
    analytic = analytic_optics(rig)
    _, _, exact_f = end_to_end(analytic, design, 20000, 1)
    for mode in ("smooth", "mesh"):
        optics = share_scenes(base, mode)
        best = None
        for _ in range(REPEATS):
            timer.embree_s, timer.embree_rays, timer.calls = 0.0, 0, []
            timer.keep_inputs = True
            dt, fig_s, f = end_to_end(optics, design, args.rays, 1)
            timer.keep_inputs = False
            calls = list(timer.calls)
            # raw embreex: replay the same calls (same scenes, same float32 rays and tfar)
            raw = 0.0
            for member, o32, d32, t32 in calls:
                t0 = time.perf_counter()
                member.scene.run(o32, d32, dists=None if t32 is None else t32.copy(), output=1)
                raw += time.perf_counter() - t0
            if best is None or dt < best[0]:
                best = (dt, raw, f, timer.embree_rays, fig_s)
        dt, raw, f, embree_rays, fig_s = best
        result["readings"][mode] = {
            "trace_s": dt, "figures_s": fig_s, "raw_embree_s": raw, "embree_rays_cast": embree_rays,
            "end_to_end_rays_per_s": args.rays / dt, "raw_embree_rays_per_s": args.rays / raw,
            "end_to_end_over_raw": raw / dt,
            "with_figures_rays_per_s": args.rays / (dt + fig_s), "with_figures_over_raw": raw / (dt + fig_s),
            "raw_embree_casts_per_s": embree_rays / raw,
            "max_spot_radius_mm": f["max_spot_radius_mm"], "rms_spot_radius_mm": f["rms_spot_radius_mm"],
            "max_angle_error_rad": f["max_angle_error_rad"],
        }
        print(mode, {k: round(v, 4) if isinstance(v, float) else v for k, v in result["readings"][mode].items()})
    n_an = min(args.rays, 200_000)
    dt, _, f = end_to_end(analytic, design, n_an, 1)
    result["readings"]["analytic"] = {"rays": n_an, "trace_s": dt, "end_to_end_rays_per_s": n_an / dt,
                                      "max_spot_radius_mm": f["max_spot_radius_mm"],
                                      "max_angle_error_rad": f["max_angle_error_rad"]}
    result["exact_reference_20000_rays"] = exact_f
    print("analytic", result["readings"]["analytic"])
    OUT.mkdir(parents=True, exist_ok=True)
    write_json(OUT / "raycheck.json", result)

    fig, ax = plt.subplots(figsize=(8, 4.5))
    names, e2e, raw = [], [], []
    for mode in ("smooth", "mesh"):
        r = result["readings"][mode]
        names.append(mode)
        e2e.append(r["end_to_end_rays_per_s"] / 1e6)
        raw.append(r["raw_embree_rays_per_s"] / 1e6)
    x = np.arange(len(names))
    ax.bar(x - 0.2, raw, 0.4, label="raw embreex (same calls)")
    ax.bar(x + 0.2, e2e, 0.4, label="end to end")
    ax.bar([len(names)], [result["readings"]["analytic"]["end_to_end_rays_per_s"] / 1e6], 0.4,
           label="analytic (float64)")
    ax.set_xticks(list(x) + [len(names)], names + ["analytic"])
    ax.set_ylabel("source rays per second (millions)")
    t = result["triangles"]
    ax.set_title(f"{args.rays} rays, {t['paraboloid'] + t['dome']} mirror triangles")
    ax.legend()
    write_bytes(OUT / "raycheck.png", _png(fig))


if __name__ == "__main__":
    main()
