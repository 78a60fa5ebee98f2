"""3D misalignment: component poses, the sensitivity table, and the one seeded Monte Carlo of
perturbed rigs (thesis 3.2.2: offsets of camera, projector, paraboloid and dome, here also vertical
offsets and tilts, in 3D), on rigcad.engine.

Pivots of the tilts: the COP for camera and projector (their pixel rays turn about it), the vertex
for the paraboloid, the sample point O for the dome (it stands on the base plate). Each build is
its own set of frozen poses; nothing shared is perturbed in place.

The Monte Carlo (:func:`run_monte_carlo`): sample i draws its build (:func:`sample_build`, within
the profile's ``tolerancing.*``) from SeedSequence child i of ``tolerancing.seed`` and traces the
same ``rays`` pinhole rays of the projector and of the camera (seeded once with
``tolerancing.seed + 1``: common random numbers, so that samples differ by their build alone)
through the analytic tracer (exact surfaces). Per sample, every perturbation and every figure go
into the table; the worse of the two light paths is the sample's figure. The results depend on
nothing but the sample's own seed: bit-identical for any worker count, batching or engine. The ray
check runs it in-process on a small sample (:func:`check_report`), ``rigcad tolerance`` at scale:
the same seed and sample count give both the same yield and the same per-sample figures.

Batches: consecutive samples, sized so a task traces ~TASK_RAYS rays (>= ~100 ms on one core);
each worker builds the analytic tracer once (rigcad.engine.worker_cache), never pickled.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass

import numpy as np

from rigcad.check.figures import figures
from rigcad.check.scene import Optics, analytic_optics
from rigcad.check.sources import annulus_rays
from rigcad.check.tower import through_splitter
from rigcad.check.trace3d import Trace3D, trace
from rigcad.engine import Engine, child_seed, run, split, worker_cache
from rigcad.optics.frames import COMPONENTS, DOFS, Misalignment
from rigcad.optics.incidence import DesignMap

#: Rays a task traces (both paths of all its samples): ~0.2 s on one core (kernel and figures:
#: ~4 ms per sample of 2 x 1000 rays, bench/tolerance.py), above the 100 ms that keeps the
#: engine's per-task overhead (~ms) negligible, and short enough that the progress bar, which
#: advances as tasks finish, moves at least about once a second.
TASK_RAYS = 100_000
#: Figures per light path, as :func:`rigcad.check.figures.figures` names them.
PATH_FIGURES = ("max_spot_radius_mm", "rms_spot_radius_mm", "max_mirror_angle_error_rad", "max_angle_error_rad",
                "convergence_offset_mm", "lost_fraction")
#: What a sample is drawn from, as both reports say it.
DISTRIBUTION = ("per sample: offsets uniform in a disc (x-y) and in +-height (z), tilt uniform 0..tol "
                "about a random horizontal axis, for each of projector, camera, paraboloid, dome "
                "(tolerancing.*); each sample from its own SeedSequence child of tolerancing.seed")


def declared(profile) -> Misalignment:
    """The misalignment the profile declares (misalignment.*: dx, dz and tilts about +y)."""
    mis = profile.misalignment
    m = Misalignment.none()
    for c in ("camera", "projector"):
        m = m.with_(c, offset=(getattr(mis, f"{c}_dx"), 0.0, getattr(mis, f"{c}_dz")), tilt=getattr(mis, f"{c}_tilt"))
    m = m.with_("paraboloid", offset=(mis.paraboloid_dx, 0.0, 0.0), tilt=mis.paraboloid_tilt)
    return m.with_("dome", offset=(mis.dome_dx, 0.0, 0.0), tilt=mis.dome_tilt)


def trace_path(optics: Optics, rig, design: DesignMap, mis: Misalignment, device: str,
               count: int, seed: int, aligned=None) -> tuple[Trace3D, np.ndarray, np.ndarray]:
    """Trace ``count`` seeded pinhole rays of ``device`` (projector or camera; the camera's through
    the beam splitter, :func:`rigcad.check.tower.through_splitter`) through the misaligned rig; returns the trace,
    the design arrival direction of each ray's pixel, and the design direction of the paraboloid
    point it hit (rotated with the paraboloid). ``aligned``: (rays, design directions) of
    ``annulus_rays(design, count, seed)`` made once by a caller that traces many builds (the same
    numbers: the source pose is applied to them here)."""
    pose = mis.pose(device, rig.geometry)
    if aligned is None:
        rays = annulus_rays(design, count, seed, pose)
        ddirs = design.direction(rays.chief)
        origins, dirs = rays.origins, rays.dirs
    else:
        rays, ddirs = aligned
        origins, dirs = rays.origins, rays.dirs
        if not pose.is_identity:
            origins, dirs = pose.globalize_points(origins), pose.globalize_dirs(dirs)
    if device == "camera":  # the camera looks through the beam splitter, from its compensated COP
        origins, dirs, _ = through_splitter(rig, origins, dirs)
    pp = mis.pose("paraboloid", rig.geometry)
    placed = optics.placed(pp, mis.pose("dome", rig.geometry))
    tr = trace(placed, origins, dirs)
    local, _ = pp.localize(tr.p1, tr.p1)
    return tr, ddirs, pp.globalize_dirs(design.direction_at(local))


def sensitivity(optics: Optics, rig, design: DesignMap, probe: float, probe_tilt: float,
                count: int, seed: int) -> dict:
    """Per component and degree of freedom: the figures at ``probe`` mm (``probe_tilt`` rad) and
    per unit (mm of convergence error per mm or per mrad)."""
    base, ddirs, _ = trace_path(optics, rig, design, Misalignment.none(), "projector", count, seed)
    table = {}
    for comp in COMPONENTS:
        device = "camera" if comp == "camera" else "projector"
        for dof in DOFS:
            m = Misalignment.none()
            if dof == "dx":
                m, amount, unit = m.with_(comp, offset=(probe, 0, 0)), probe, "mm"
            elif dof == "dz":
                m, amount, unit = m.with_(comp, offset=(0, 0, probe)), probe, "mm"
            else:
                m, amount, unit = m.with_(comp, tilt=probe_tilt), probe_tilt * 1e3, "mrad"
            tr, _, mdirs = trace_path(optics, rig, design, m, device, count, seed)
            f = figures(tr, ddirs, base, mdirs)
            f["probe"] = f"{amount:g} {unit}"
            f[f"spot_shift_mm_per_{unit}"] = f["convergence_offset_mm"] / amount
            f[f"max_spot_radius_mm_per_{unit}"] = f["max_spot_radius_mm"] / amount
            f[f"max_angle_change_rad_per_{unit}"] = f["max_angle_change_rad"] / amount
            f[f"max_mirror_angle_error_rad_per_{unit}"] = f["max_mirror_angle_error_rad"] / amount
            table[f"{comp}_{dof}"] = f
    return table


def sample_build(rng: np.random.Generator, tol) -> Misalignment:
    """One random build within the tolerances (see TolerancingParams)."""
    m = Misalignment.none()
    for c in COMPONENTS:
        lateral, height, tilt = getattr(tol, f"{c}_offset"), getattr(tol, f"{c}_height"), getattr(tol, f"{c}_tilt")
        r = lateral * np.sqrt(rng.uniform())
        a = rng.uniform(0, 2 * np.pi)
        b = rng.uniform(0, 2 * np.pi)
        m = m.with_(c, offset=(r * np.cos(a), r * np.sin(a), rng.uniform(-height, height)),
                    tilt=rng.uniform(0, tilt), axis=(np.cos(b), np.sin(b), 0.0))
    return m


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
        return analytic_optics(rig), rig.incidence

    return worker_cache(("tolerance-optics", key), build)


def aligned_rays(design, rays: int, ray_seed: int, key: str):
    """The seeded aligned pinhole rays and their design directions, made once per worker."""
    def build():
        r = annulus_rays(design, rays, ray_seed)
        return r, design.direction(r.chief)

    return worker_cache(("tolerance-rays", key, rays, ray_seed), build)


def build_figures(optics, rig, design, mis, rays: int, ray_seed: int, devices=("projector", "camera"),
                  key: str | None = None) -> dict:
    """Figures of one build ``mis`` (a Misalignment): per light path (``projector_*``,
    ``camera_*``) and the worse of them (no prefix); NaN figures (every ray lost) count as inf.
    ``key``: the rig's worker-cache key (the rays are then made once per worker)."""
    base = None if key is None else aligned_rays(design, rays, ray_seed, key)
    out = {}
    for device in devices:
        tr, ddirs, mdirs = trace_path(optics, rig, design, mis, device, rays, ray_seed, base)
        f = figures(tr, ddirs, None, mdirs)
        f["lost_fraction"] = 1.0 - f["rays_ok"] / f["rays"]
        for k in PATH_FIGURES:
            v = float(f[k])
            out[f"{device}_{k}"] = v if math.isfinite(v) else math.inf
    for k in PATH_FIGURES:
        out[k] = max(out[f"{d}_{k}"] for d in devices)
    return out


def _batch(job: Job, batch: range) -> list[dict]:
    """One task: the samples ``batch`` (rows of the table, in order)."""
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
        "distribution": DISTRIBUTION,
        "figures": {k: _stats(columns[k]) for k in PATH_FIGURES},
        "yield": float(np.mean(good)),
        "samples_meeting_targets": int(good.sum()),
        "target_max_spot_radius_mm": tol.max_spot_radius,
        "target_max_mirror_angle_error_rad": tol.max_angle_error,
        "min_yield": tol.min_yield,
    }


def check_report(rig, builds: int, rays: int) -> dict:
    """The ray check's Monte Carlo section (JSON-ready, units in keys): :func:`run_monte_carlo` of
    ``builds`` samples of ``rays`` rays per path in this process (the serial engine), so the check
    and ``rigcad tolerance`` report the same yield and per-sample figures for the same seed and
    sample count. Per build, the worse of the projector's and the camera's path: largest spot
    radius (mm) and mirror angle error (rad, see :func:`rigcad.check.figures.figures`: per-pixel
    errors of a misplaced source are calibrated away, thesis 4.1); the yield meeting both targets."""
    tol = rig.profile.tolerancing
    mc = run_monte_carlo(rig, builds, rays, Engine(1))
    c, s = mc.columns, mc.summary
    return {
        "builds": s["samples"],
        "seed": s["seed"],
        "rays_per_build_and_path": s["rays_per_path"],
        "distribution": f"{DISTRIBUTION}; the same pinhole rays (seed {s['ray_seed']}) for every build; camera "
                        "and projector paths traced on the exact surfaces, the worse kept",
        "max_spot_radius_mm": s["figures"]["max_spot_radius_mm"],
        "max_mirror_angle_error_rad": s["figures"]["max_mirror_angle_error_rad"],
        "max_pixel_angle_error_rad_uncalibrated": s["figures"]["max_angle_error_rad"],
        "convergence_offset_mm": s["figures"]["convergence_offset_mm"],
        "target_max_spot_radius_mm": tol.max_spot_radius,
        "target_max_mirror_angle_error_rad": tol.max_angle_error,
        "yield": s["yield"],
        "min_yield": tol.min_yield,
        "per_build": {"max_spot_radius_mm": c["max_spot_radius_mm"].tolist(),
                      "max_mirror_angle_error_rad": c["max_mirror_angle_error_rad"].tolist()},
    }
