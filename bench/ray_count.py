"""Ray count against the statistical error of the ray checker's figures (issue 7, table c).

Run from the repository root: ``.venv/bin/python bench/ray_count.py [--exports DIR]``. Writes
bench/results/ray_count.json and ray_count.png. For each ray count N the pinhole check of
``rigcad check`` (smooth reading: the profile's default mode, the exported mirror meshes when they
match the profile's tolerances, else meshed from it) is repeated with SEEDS different seeds; the
scatter between seeds is the statistical error of each figure at that N:

* RMS spot radius, RMS angle error and the fraction of rays lost are means over the rays: their
  scatter falls as N^-1/2 (fitted slope in ``slopes``); ``predicted_std`` is the central-limit
  value from the pooled rays (delta method for an RMS, binomial sqrt(p (1 - p) / N) for the lost
  fraction), and a bootstrap over one seed's rays gives the same from a single run;
* max spot radius and max angle error are extremes: a sample maximum is biased low and converges
  to the supremum from below at a rate set by the shape of the figure near its peak over the
  annulus, not by the central limit theorem; reported as the mean shortfall from the largest value
  seen in all the runs (``reference``: every ray of every run), with its fitted slope.

Timings (``trace_s``) are the seeded trace plus the figures, best of the seeds. Not asserted.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import arguments, loglog_slope, png, pyplot, run_info

from rigcad.check.figures import _angles
from rigcad.check.scene import mesh_optics, mirror_meshes
from rigcad.check.sources import annulus_rays
from rigcad.check.trace3d import trace
from rigcad.export.atomic import write_bytes, write_json
from rigcad.rig import Rig
from rigcad.profile import load_profile

COUNTS = (1_000, 3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000)
SEEDS = 12  #: the scatter of an SD estimated from k seeds is itself ~1/sqrt(2 (k - 1)): +-21 % at 12
BOOTSTRAP = 100  #: resamples of one run's rays (N <= BOOTSTRAP_MAX_N)
BOOTSTRAP_MAX_N = 300_000
MEANS = ("rms_spot_radius_mm", "rms_angle_error_rad", "lost_fraction")
MAXIMA = ("max_spot_radius_mm", "max_angle_error_rad")


def per_ray(optics, design, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spot radius (mm) and angle error against the design (rad) of the rays that reach the sample,
    and the ok mask of all n rays."""
    rays = annulus_rays(design, n, seed)
    tr = trace(optics, rays.origins, rays.dirs)
    ok = tr.ok
    err = _angles(tr.arrival[ok], design.direction(rays.chief)[ok])
    return tr.miss[ok], err, ok


def figures(miss: np.ndarray, err: np.ndarray, ok: np.ndarray) -> dict:
    return {"rms_spot_radius_mm": float(np.sqrt(np.mean(miss ** 2))), "max_spot_radius_mm": float(miss.max()),
            "rms_angle_error_rad": float(np.sqrt(np.mean(err ** 2))), "max_angle_error_rad": float(err.max()),
            "lost_fraction": float(1.0 - ok.mean())}


def bootstrap(miss: np.ndarray, err: np.ndarray, ok: np.ndarray, rng: np.random.Generator) -> dict:
    """Standard deviation of each figure over BOOTSTRAP resamples (with replacement) of one run."""
    n = len(ok)
    idx_ok = np.cumsum(ok) - 1  # index into miss/err for rays that reached the sample
    vals = {k: [] for k in MEANS + MAXIMA}
    for _ in range(BOOTSTRAP):
        pick = rng.integers(0, n, n)
        sel = pick[ok[pick]]
        f = figures(miss[idx_ok[sel]], err[idx_ok[sel]], ok[pick])
        for k in vals:
            vals[k].append(f[k])
    return {k: float(np.std(v, ddof=1)) for k, v in vals.items()}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--exports", default="exports")
    args = ap.parse_args()
    counts, seeds = ((1_000, 3_000, 10_000), 3) if args.quick else (COUNTS, SEEDS)
    run = run_info()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
    design = rig.incidence
    meshes = mirror_meshes(rig, Path(args.exports))
    optics = mesh_optics(meshes, "smooth")
    rng = np.random.default_rng(7)
    rows = []
    pooled = {"miss": [], "err": [], "ok": []}
    for n in counts:
        runs, times = [], []
        boot = None
        for s in range(seeds):
            t0 = time.perf_counter()
            miss, err, ok = per_ray(optics, design, n, 1000 + s)
            f = figures(miss, err, ok)
            times.append(time.perf_counter() - t0)
            runs.append(f)
            if s == 0 and n <= BOOTSTRAP_MAX_N:
                boot = bootstrap(miss, err, ok, rng)
            if n == counts[-1]:
                pooled["miss"].append(miss)
                pooled["err"].append(err)
                pooled["ok"].append(ok)
        row = {"rays": n, "seeds": seeds, "trace_s": min(times),
               "mean": {k: float(np.mean([r[k] for r in runs])) for k in MEANS + MAXIMA},
               "std_between_seeds": {k: float(np.std([r[k] for r in runs], ddof=1)) for k in MEANS + MAXIMA},
               "bootstrap_std_one_run": boot, "per_seed": runs}
        rows.append(row)
        print(f"{n:>9} rays: rms spot {row['mean']['rms_spot_radius_mm']:.4e} +- "
              f"{row['std_between_seeds']['rms_spot_radius_mm']:.2e} mm, lost {row['mean']['lost_fraction']:.4f} +- "
              f"{row['std_between_seeds']['lost_fraction']:.1e}, max spot {row['mean']['max_spot_radius_mm']:.4e} mm, "
              f"{min(times):.2f} s", flush=True)
    miss = np.concatenate(pooled["miss"])
    err = np.concatenate(pooled["err"])
    ok = np.concatenate(pooled["ok"])
    ref = figures(miss, err, ok)
    ref_max = {k: max(r[k] for row in rows for r in row["per_seed"]) for k in MAXIMA}
    ref.update(ref_max)
    p = ref["lost_fraction"]
    unit_std = {  # standard deviation of each mean-type figure for N = 1 (central limit theorem)
        "rms_spot_radius_mm": float(np.std(miss ** 2) / (2 * ref["rms_spot_radius_mm"]) * np.sqrt(1 / (1 - p))),
        "rms_angle_error_rad": float(np.std(err ** 2) / (2 * ref["rms_angle_error_rad"]) * np.sqrt(1 / (1 - p))),
        "lost_fraction": float(np.sqrt(p * (1 - p))),
    }
    for row in rows:
        row["predicted_std"] = {k: v / np.sqrt(row["rays"]) for k, v in unit_std.items()}
        row["max_shortfall"] = {k: ref_max[k] - row["mean"][k] for k in MAXIMA}
        row["relative_std"] = {k: row["std_between_seeds"][k] / ref[k] for k in MEANS}
    ns = [r["rays"] for r in rows]
    slopes = {f"std_{k}": loglog_slope(ns, [r["std_between_seeds"][k] for r in rows]) for k in MEANS}
    # the largest N's shortfall is measured against a reference that includes its own rays: left out
    slopes.update({f"max_shortfall_{k}": loglog_slope(ns[:-1], [r["max_shortfall"][k] for r in rows[:-1]])
                   for k in MAXIMA})
    needed = {k: int(np.ceil((unit_std[k] / (0.01 * ref[k])) ** 2)) for k in MEANS}
    result = {
        "profile": profile.name, "reading": "smooth (interpolated vertex normals), pinhole rays over the annulus",
        "meshes": meshes.sources(), "tessellation": meshes.tolerances,
        "reference_all_rays_of_largest_n": {"rays": int(len(ok)), **ref,
                                            "maxima_over": "every ray of every run at every N"},
        "slopes_log_log_vs_rays": slopes,
        "rays_for_1_percent_relative_std": needed,
        "rows": rows,
        "run": run,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "ray_count.json", result))
    print("slopes", {k: None if v is None else round(v, 3) for k, v in slopes.items()})
    print("rays for 1 % relative std", needed)
    write_bytes(args.out / "ray_count.png", plot(rows, slopes))


def plot(rows: list[dict], slopes: dict) -> bytes:
    plt = pyplot()
    ns = np.array([r["rays"] for r in rows], float)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    labels = {"rms_spot_radius_mm": "RMS spot radius", "rms_angle_error_rad": "RMS angle error",
              "lost_fraction": "fraction lost"}
    for k, lab in labels.items():
        rel = [r["relative_std"][k] for r in rows]
        line, = axes[0].loglog(ns, rel, "o-", label=f"{lab} (slope {slopes[f'std_{k}']:.2f})")
        axes[0].loglog(ns, [r["predicted_std"][k] / (r["std_between_seeds"][k] / r["relative_std"][k])
                            for r in rows], ":", color=line.get_color(), lw=1)
    axes[0].loglog(ns, rows[0]["relative_std"]["rms_spot_radius_mm"] * np.sqrt(ns[0] / ns), "k--", lw=0.8,
                   label="N^-1/2")
    axes[0].set_title("scatter between seeds / value (dotted: central-limit prediction)", fontsize=9)
    axes[0].set_ylabel("relative standard deviation")
    for k, lab in (("max_spot_radius_mm", "max spot radius"), ("max_angle_error_rad", "max angle error")):
        short = [r["max_shortfall"][k] / (r["max_shortfall"][k] + r["mean"][k]) for r in rows[:-1]]
        axes[1].loglog(ns[:-1], short, "s-", label=f"{lab} (slope {slopes[f'max_shortfall_{k}']:.2f})")
    axes[1].loglog(ns[:-1], 0.05 * ns[0] / ns[:-1], "k--", lw=0.8, label="N^-1")
    axes[1].set_title("maxima: mean shortfall from the largest value seen / that value", fontsize=9)
    axes[1].set_ylabel("relative shortfall")
    axes[2].loglog(ns, [r["trace_s"] for r in rows], "o-")
    axes[2].set_title("trace + figures, smooth reading (best of the seeds)", fontsize=9)
    axes[2].set_ylabel("seconds (this machine)")
    for ax in axes:
        ax.set_xlabel("rays traced (N)")
        ax.grid(True, which="both", lw=0.3)
        if ax is not axes[2]:
            ax.legend(fontsize=7)
    fig.suptitle("rigcad ray checker: statistical error of the figures against ray count", fontsize=11)
    fig.tight_layout()
    return png(fig)


if __name__ == "__main__":
    main()
