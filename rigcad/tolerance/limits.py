"""One-at-a-time sensitivity and inverse limits (Zemax's "inverse limits": the allowable tolerance
of each parameter on its own), on the analytic tracer.

For each toleranced parameter (rigcad.tolerance.params), the rig is moved by that parameter alone
in the worst of its two directions and traced with the Monte Carlo's rays. ``sensitivity``: the
figures at the profile's tolerance. ``limit``: the largest move keeping the worst arrival-
direction error (after calibration: ``max_mirror_angle_error_rad``) within the declared
``tolerancing.max_angle_error``; found by doubling from the tolerance until the error exceeds
the target (or SEARCH_CAP is reached: no limit there), then bisection until the bracket is
within LIMIT_RTOL of the move. The same search on the spot radius against
``tolerancing.max_spot_radius`` gives ``spot_limit``. Each parameter is one engine task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigcad.check.montecarlo import build_figures, worker_optics
from rigcad.engine import Engine, run
from rigcad.tolerance.params import DEFAULT_PROBE, PARAMETERS, SEARCH_CAP, Parameter

#: Bisection stops when the bracket is this fraction of the move: the error is smooth in the move
#: (~linear for offsets), so the error at the limit is then within ~1e-3 of the target, far
#: inside the 5 % the tests check by tracing at the limit.
LIMIT_RTOL = 1e-3
#: Doublings from the tolerance before giving up below SEARCH_CAP (2^20 x 0.1 mm is past any cap).
MAX_DOUBLINGS = 20


@dataclass(frozen=True)
class LimitJob:
    rig: object
    rays: int
    ray_seed: int
    key: str


def worst_figures(job: LimitJob, p: Parameter, amount: float) -> dict:
    """The worst figures over the parameter's two moves of ``amount`` (mm or rad)."""
    optics, design = worker_optics(job.rig, job.key)
    worst: dict = {}
    for mis in p.moves(amount):
        f = build_figures(optics, job.rig, design, mis, job.rays, job.ray_seed, p.devices, key=job.key)
        for k, v in f.items():
            worst[k] = max(worst.get(k, -math.inf), v)
    return worst


def _search(job: LimitJob, p: Parameter, figure: str, target: float, start: float) -> dict:
    """Largest move with ``figure`` <= ``target`` (see the module docstring)."""
    cap = SEARCH_CAP[p.kind]
    lo, hi = 0.0, None
    x = min(start, cap)
    for _ in range(MAX_DOUBLINGS):
        if worst_figures(job, p, x)[figure] > target:
            hi = x
            break
        lo = x
        if x >= cap:
            break
        x = min(2 * x, cap)
    if hi is None:
        return {"limit": cap, "reached": False, "error_at_limit": worst_figures(job, p, cap)[figure]}
    while hi - lo > LIMIT_RTOL * hi:
        mid = 0.5 * (lo + hi)
        if worst_figures(job, p, mid)[figure] > target:
            hi = mid
        else:
            lo = mid
    return {"limit": lo, "reached": True, "error_at_limit": worst_figures(job, p, lo)[figure]}


def _parameter_task(job: LimitJob, p: Parameter) -> dict:
    tol = job.rig.profile.tolerancing
    value = p.tolerance(tol)
    at_tol = worst_figures(job, p, value) if value > 0 else None
    start = value if value > 0 else DEFAULT_PROBE[p.kind]
    angle = _search(job, p, "max_mirror_angle_error_rad", tol.max_angle_error, start)
    spot = _search(job, p, "max_spot_radius_mm", tol.max_spot_radius, start)
    u = p.unit
    out = {"parameter": p.name, "profile_key": p.key, "unit": u, f"tolerance_{u}": value,
           f"limit_{u}": angle["limit"], "limit_found": angle["reached"],
           "max_mirror_angle_error_rad_at_limit": angle["error_at_limit"],
           f"spot_limit_{u}": spot["limit"], "spot_limit_found": spot["reached"],
           "max_spot_radius_mm_at_spot_limit": spot["error_at_limit"]}
    if at_tol is not None:
        out.update({"max_spot_radius_mm_at_tolerance": at_tol["max_spot_radius_mm"],
                    "max_mirror_angle_error_rad_at_tolerance": at_tol["max_mirror_angle_error_rad"],
                    "lost_fraction_at_tolerance": at_tol["lost_fraction"],
                    # the share of each target this parameter alone uses at its tolerance
                    "spot_budget_used": at_tol["max_spot_radius_mm"] / tol.max_spot_radius,
                    "angle_budget_used": at_tol["max_mirror_angle_error_rad"] / tol.max_angle_error})
    else:
        out.update({"spot_budget_used": 0.0, "angle_budget_used": 0.0})
    out["limit_over_tolerance"] = angle["limit"] / value if value > 0 else math.inf
    return out


def run_limits(rig, key: str, rays: int, ray_seed: int, engine: Engine = Engine(), progress=None,
               parameters=PARAMETERS) -> list[dict]:
    """Sensitivity and inverse limits of every parameter, ranked: the parameter using most of the
    spot or angle budget at its tolerance first."""
    job = LimitJob(rig, rays, ray_seed, key)
    rows = run(_parameter_task, job, list(parameters), engine, progress=progress)
    order = sorted(range(len(rows)), key=lambda i: (-max(rows[i]["spot_budget_used"], rows[i]["angle_budget_used"]), i))
    ranked = [rows[i] for i in order]
    for r, row in enumerate(ranked, 1):
        row["rank"] = r
    return ranked
