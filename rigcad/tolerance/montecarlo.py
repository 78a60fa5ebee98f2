"""The Monte Carlo of perturbed rigs at scale, on rigcad.engine.

Sample i draws its build (offsets, heights, tilts of the four components:
rigcad.check.montecarlo.sample_build, within the profile's ``tolerancing.*``) from SeedSequence
child i of ``tolerancing.seed`` and traces the same ``rays`` pinhole rays of the projector and of
the camera (seeded once: common random numbers, so that samples differ by their build alone)
through the analytic tracer. Per sample, every perturbation and every figure go into the table;
the worse of the two light paths is the sample's figure. The results depend on nothing but the
sample's own seed: bit-identical for any worker count, batching or engine.

Batches: consecutive samples, sized so a task traces ~TASK_RAYS rays (>= ~100 ms on one core);
each worker builds the analytic tracer once (rigcad.engine.worker_cache), never pickled.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass

import numpy as np

from rigcad.engine import Engine, child_seed, run, split, worker_cache
from rigcad.optics.frames import COMPONENTS

#: Rays a task traces (both paths of all its samples): ~0.2 s on one core (kernel and figures:
#: ~4 ms per sample of 2 x 1000 rays, bench/tolerance.py), above the 100 ms that keeps the
#: engine's per-task overhead (~ms) negligible, and short enough that the progress bar, which
#: advances as tasks finish, moves at least about once a second.
TASK_RAYS = 100_000
#: Figures per light path, as rigcad.check.montecarlo.figures names them.
PATH_FIGURES = ("max_spot_radius_mm", "rms_spot_radius_mm", "max_mirror_angle_error_rad", "max_angle_error_rad",
                "convergence_offset_mm", "lost_fraction")
#: Summary statistics of each figure over the samples.
STATS = ("mean", "p50", "p90", "p99", "max")


@dataclass(frozen=True)
class Job:
    """What every task needs (pickled once per worker): the rig, rays per path and their seed,
    and the per-sample seed root (sample i draws from its child i)."""

    rig: object
    rays: int
    ray_seed: int
    seed: int

    @property
    def key(self) -> str:
        """Identifies the rig for worker caches (its resolved parameters)."""
        return hashlib.sha256(json.dumps(self.rig.profile.as_dict(), sort_keys=True, default=str).encode()).hexdigest()


def worker_optics(rig, key: str):
    """(analytic optics, design map) of ``rig``, built once per worker process."""
    def build():
        from rigcad.check.scene import analytic_optics

        return analytic_optics(rig), rig.incidence

    return worker_cache(("tolerance-optics", key), build)


def aligned_rays(design, rays: int, ray_seed: int, key: str):
    """The seeded aligned pinhole rays and their design directions, made once per worker."""
    def build():
        from rigcad.check.sources import annulus_rays

        r = annulus_rays(design, rays, ray_seed)
        return r, design.direction(r.chief)

    return worker_cache(("tolerance-rays", key, rays, ray_seed), build)


def build_figures(optics, rig, design, mis, rays: int, ray_seed: int, devices=("projector", "camera"),
                  key: str | None = None) -> dict:
    """Figures of one build ``mis`` (a Misalignment): per light path (``projector_*``,
    ``camera_*``) and the worse of them (no prefix); NaN figures (every ray lost) count as inf.
    ``key``: the rig's worker-cache key (the rays are then made once per worker)."""
    from rigcad.check import montecarlo as MC

    base = None if key is None else aligned_rays(design, rays, ray_seed, key)
    out = {}
    for device in devices:
        tr, ddirs, mdirs = MC.trace_path(optics, rig, design, mis, device, rays, ray_seed, base)
        f = MC.figures(tr, ddirs, None, mdirs)
        f["lost_fraction"] = 1.0 - f["rays_ok"] / f["rays"]
        for k in PATH_FIGURES:
            v = float(f[k])
            out[f"{device}_{k}"] = v if math.isfinite(v) else math.inf
    for k in PATH_FIGURES:
        out[k] = max(out[f"{d}_{k}"] for d in devices)
    return out


def _batch(job: Job, batch: range) -> list[dict]:
    """One task: the samples ``batch`` (rows of the table, in order)."""
    from rigcad.check.montecarlo import sample_build

    key = job.key  # hashed once per task, not per sample
    optics, design = worker_optics(job.rig, key)
    tol = job.rig.profile.tolerancing
    rows = []
    for i in batch:
        mis = sample_build(np.random.default_rng(child_seed(job.seed, i)), tol)
        row = {"sample": i}
        for c in COMPONENTS:
            (dx, dy, dz), t, (ax, ay, _) = mis.offsets[c], mis.tilts[c], mis.axes[c]
            row.update({f"{c}_dx_mm": float(dx), f"{c}_dy_mm": float(dy), f"{c}_dz_mm": float(dz),
                        f"{c}_tilt_rad": float(t), f"{c}_tilt_axis_azimuth_rad": float(math.atan2(ay, ax))})
        row.update(build_figures(optics, job.rig, design, mis, job.rays, job.ray_seed, key=key))
        rows.append(row)
    return rows


@dataclass
class MonteCarlo:
    """The per-sample table (column -> (samples,) array, in sample order) and its summary."""

    columns: dict
    summary: dict


def batch_size(samples: int, rays: int, workers: int) -> int:
    """Samples per task: ~TASK_RAYS rays, and at least ~4 tasks per worker to balance the load."""
    by_rays = max(1, TASK_RAYS // (2 * rays))
    by_balance = max(1, math.ceil(samples / (4 * max(1, workers))))
    return max(1, min(by_rays, by_balance))


def run_monte_carlo(rig, samples: int | None = None, rays: int | None = None, engine: Engine = Engine(),
                    progress=None) -> MonteCarlo:
    """``samples`` builds (default ``tolerancing.builds``) of ``rays`` rays per path (default
    ``tolerancing.rays``) on ``engine``; ``progress(tasks done, tasks, samples done, samples)``."""
    tol = rig.profile.tolerancing
    samples = int(tol.builds if samples is None else samples)
    rays = int(tol.rays if rays is None else rays)
    job = Job(rig, rays, int(tol.seed) + 1, int(tol.seed))
    tasks = split(samples, batch_size(samples, rays, engine.n_workers))
    parts = run(_batch, job, tasks, engine, progress=progress, sizes=[len(t) for t in tasks])
    rows = [r for part in parts for r in part]
    columns = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    return MonteCarlo(columns, summarize(columns, tol, samples, rays, job.ray_seed))


def _stats(v: np.ndarray) -> dict:
    return {"mean": float(np.mean(v)), "p50": float(np.percentile(v, 50)), "p90": float(np.percentile(v, 90)),
            "p99": float(np.percentile(v, 99)), "max": float(np.max(v))}


def meets(columns: dict, tol) -> np.ndarray:
    """Which samples meet both targets: spot and (calibrated) mirror angle error."""
    return (columns["max_spot_radius_mm"] <= tol.max_spot_radius) & \
        (columns["max_mirror_angle_error_rad"] <= tol.max_angle_error)


def summarize(columns: dict, tol, samples: int, rays: int, ray_seed: int) -> dict:
    """Summary figures (JSON-ready, units in keys): the yield and each figure's distribution."""
    good = meets(columns, tol)
    return {
        "samples": samples, "seed": int(tol.seed), "rays_per_path": rays, "ray_seed": ray_seed,
        "distribution": "per sample: offsets uniform in a disc (x-y) and in +-height (z), tilt uniform 0..tol "
                        "about a random horizontal axis, for each of projector, camera, paraboloid, dome "
                        "(tolerancing.*); each sample from its own SeedSequence child of tolerancing.seed",
        "figures": {k: _stats(columns[k]) for k in PATH_FIGURES},
        "yield": float(np.mean(good)),
        "samples_meeting_targets": int(good.sum()),
        "target_max_spot_radius_mm": tol.max_spot_radius,
        "target_max_mirror_angle_error_rad": tol.max_angle_error,
        "min_yield": tol.min_yield,
    }


def rank_correlations(columns: dict) -> dict:
    """Spearman rank correlation of each parameter's magnitude in the samples (lateral offset
    |(dx, dy)|, |dz|, tilt) with the sample's spot and mirror angle error."""
    from rigcad.tolerance.params import PARAMETERS

    def ranks(v):
        return np.argsort(np.argsort(v, kind="stable"), kind="stable").astype(float)

    out = {}
    figs = {k: ranks(columns[k]) for k in ("max_spot_radius_mm", "max_mirror_angle_error_rad")}
    for p in PARAMETERS:
        c = p.component
        mag = {"offset": np.hypot(columns[f"{c}_dx_mm"], columns[f"{c}_dy_mm"]),
               "height": np.abs(columns[f"{c}_dz_mm"]), "tilt": columns[f"{c}_tilt_rad"]}[p.kind]
        r = ranks(mag)
        out[p.name] = {}
        for k, fr in figs.items():
            if np.ptp(r) == 0 or np.ptp(fr) == 0:
                out[p.name][k] = 0.0
            else:
                out[p.name][k] = float(np.corrcoef(r, fr)[0, 1])
    return out
