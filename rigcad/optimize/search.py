"""The search: a seeded global search, then a local polish, every evaluation recorded.

* One objective: scipy's ``differential_evolution`` (vectorised: each generation is one batch on
  the engine) on the penalty merit, the base design placed in the first population; then COBYLA
  from the best point, with the objective and every constraint given to it separately (they are
  smooth in the parameters: closed forms and fixed quadrature nodes, not binned ray counts).
* Two or more: optuna's NSGA-II (constrained: a design that meets every constraint beats one that
  does not, and violations are compared by size), a generation per batch; the Pareto set of the
  feasible designs; the chosen design is the one that improves most on the base in every objective
  at once (the largest smallest relative improvement), or, if none beats the base in all, the one
  nearest the ideal point; then COBYLA minimises the first objective keeping the others no worse.

Parameters move in the unit cube of their bounds. Results are identical for any worker count:
each batch's evaluations depend only on the points, and the points only on the seed and the
results so far (rigcad.engine returns results in task order).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from rigcad.engine import Engine, run, split
from rigcad.errors import RigcadError
from rigcad.optimize.problem import (CONSTRAINT_KEYS, CONSTRAINT_UNITS, UNIT_SCALE, Problem, evaluate_task,
                                     stack_refusals, violation)
from rigcad.optimize.spec import OBJECTIVES, target_of

#: Merit of a design that violates a constraint: above every feasible design's merit (objectives
#: in their merit units stay far below), then ordered by the size of the violation.
INFEASIBLE = 1e6
#: Merit of a design the geometry refuses.
REFUSED = 1e12
#: Share of the evaluation budget kept for the local polish.
POLISH_SHARE = 0.2
#: COBYLA's first step in the unit cube (a twentieth of each bound's range).
POLISH_STEP = 0.05


class OptimizeError(RigcadError):
    """No design met the constraints (exit 1): the message names each constraint never met and the
    best value reached."""

    exit_code = 1


@dataclass
class History:
    """Every evaluation in order, with the phase that asked for it."""

    rows: list = field(default_factory=list)

    def add(self, rows: list[dict], phase: str) -> None:
        for r in rows:
            r["index"] = len(self.rows)
            r["phase"] = phase
            self.rows.append(r)


class Evaluator:
    """Evaluates batches on the engine, records them, reports progress (with the best merit)."""

    def __init__(self, problem: Problem, engine: Engine, progress=None):
        self.problem, self.engine, self.progress = problem, engine, progress
        self.history = History()
        self.best = math.inf
        self.budget = problem.spec.evaluations  #: the polish stops when the history reaches it

    def __call__(self, X: np.ndarray, phase: str) -> list[dict]:
        X = np.atleast_2d(np.asarray(X, float))
        n = self.engine.n_workers if self.engine.name != "serial" else 1
        chunks = split(len(X), max(1, math.ceil(len(X) / n)))
        out = run(evaluate_task, self.problem, [[X[i].tolist() for i in c] for c in chunks], self.engine)
        rows = [r for batch in out for r in batch]
        for r in rows:
            r["merit"] = merit(self.problem, r)
            self.best = min(self.best, r["merit"])
        self.history.add(rows, phase)
        if self.progress is not None:
            self.progress(len(self.history.rows), self.best)
        return rows


def scaled_objectives(problem: Problem, row: dict) -> np.ndarray:
    """Objectives as minimised merit units: divided by each objective's scale, negated when
    maximised; for a target, the squared scaled distance from it."""
    out = []
    for name, sense in problem.spec.objectives:
        v = row["objectives"][name] / OBJECTIVES[name][2]
        target = target_of(sense)
        if target is not None:
            out.append((v - target / OBJECTIVES[name][2]) ** 2)
        else:
            out.append(v if sense == "minimize" else -v)
    return np.array(out)


def merit(problem: Problem, row: dict) -> float:
    """The penalty merit of the first objective (the single-objective search's function)."""
    if row["objectives"] is None:
        return REFUSED
    v = violation(row)
    f = float(scaled_objectives(problem, row)[0])
    return f if v == 0 else INFEASIBLE * (1.0 + v) + f


def pareto(problem: Problem, rows: list[dict]) -> list[dict]:
    """The feasible rows no other feasible row dominates (in every objective as good, in one better)."""
    feas = [r for r in rows if r["feasible"]]
    if not feas:
        return []
    F = np.array([scaled_objectives(problem, r) for r in feas])
    keep = []
    for i in range(len(F)):
        dominated = np.any(np.all(F <= F[i], axis=1) & np.any(F < F[i], axis=1))
        if not dominated:
            keep.append(i)
    # one row per distinct objective vector, in evaluation order
    seen, out = set(), []
    for i in keep:
        key = tuple(F[i])
        if key not in seen:
            seen.add(key)
            out.append(feas[i])
    return out


def improvement(problem: Problem, row: dict, ref: dict | None) -> float:
    """Smallest relative improvement of ``row`` over ``ref`` across the objectives (> 0: better in all)."""
    if ref is None or ref["objectives"] is None:
        return -math.inf
    a, b = scaled_objectives(problem, row), scaled_objectives(problem, ref)
    return float(np.min((b - a) / np.maximum(np.abs(b), 1e-12)))


def ranked(problem: Problem, front: list[dict], ref: dict | None) -> list[tuple[dict, str]]:
    """The front's designs in order of preference, each with why (see the module docstring)."""
    scores = np.array([improvement(problem, r, ref) for r in front])
    F = np.array([scaled_objectives(problem, r) for r in front])
    lo, hi = F.min(axis=0), F.max(axis=0)
    d = np.max((F - lo) / np.where(hi > lo, hi - lo, 1.0), axis=1)
    out = []
    for k in sorted(range(len(front)), key=lambda i: (-scores[i] if scores[i] > 0 else math.inf, d[i], i)):
        why = (f"beats the base design in every objective, by at least {100 * scores[k]:.2f} %" if scores[k] > 0
               else "no design beats the base in every objective: the front's point nearest the ideal")
        out.append((front[k], why))
    return out


def choose(problem: Problem, front: list[dict], ref: dict | None) -> tuple[dict, str]:
    """The chosen design of a Pareto front and why (see the module docstring)."""
    return ranked(problem, front, ref)[0]


def preference(problem: Problem, result: "Result") -> list[tuple[dict, str]]:
    """Every feasible design worth writing, best first: the chosen one, then (two or more objectives)
    the rest of the front by the same rule, with the feasible designs off the front by that rule among
    themselves (what the later stages try when they refuse the front's): those that beat the base in
    every objective before the front's that do not; or (one objective) the others by merit."""
    if result.chosen is None:
        return []
    if len(problem.spec.objectives) > 1:
        # the front by that rule; the feasible designs off it that beat the base in every objective come
        # before the front's designs that do not (the later stages may refuse the front's best), the rest last
        on = {r["index"] for r in result.front}
        rest = [r for r in result.history if r["feasible"] and r["index"] not in on]
        front = ranked(problem, result.front, result.base)
        off = [(r, f"off the Pareto front (the designs before it were refused by later stages): {why}")
               for r, why in (ranked(problem, rest, result.base) if rest else [])]
        beats = [(r, w) for r, w in front if improvement(problem, r, result.base) > 0]
        better = [(r, w) for r, w in off if improvement(problem, r, result.base) > 0]
        return beats + better + [x for x in front if x not in beats] + [x for x in off if x not in better]
    feas = sorted((r for r in result.history if r["feasible"]), key=lambda r: (r["merit"], r["index"]))
    return [(r, "lowest merit of the feasible designs" if i == 0 else f"feasible design {i + 1} by merit")
            for i, r in enumerate(feas)]


def _polish(ev: Evaluator, x0_unit: np.ndarray, budget: int, objective, bounds_on: list[tuple[int, float]],
            restore: bool = False) -> None:
    """COBYLA from ``x0_unit``: minimise scaled objective ``objective`` subject to every constraint
    and, for each (objective index, limit) in ``bounds_on``, that objective <= limit (scaled). With
    ``restore``: minimise the scaled violation instead, unconstrained (no design is feasible yet)."""
    from scipy.optimize import minimize

    problem = ev.problem
    cache: dict[bytes, dict] = {}
    # a fixed list for COBYLA: every constraint some design so far was judged on (a later stage's is judged
    # only on designs that meet the closed-form ones: where it was not, it counts as met)
    judged = set().union(*(r["constraints"] for r in ev.history.rows if r["constraints"]))
    names = [k for k in CONSTRAINT_UNITS if k in judged]

    def row_at(u):
        u = np.clip(np.asarray(u, float), 0.0, 1.0)
        key = u.tobytes()
        if key not in cache:
            if len(ev.history.rows) >= ev.budget:
                raise _Budget
            cache[key] = ev(problem.to_x(u)[None, :], "polish")[0]
        return cache[key]

    def f(u):
        r = row_at(u)
        if restore:
            return min(violation(r), REFUSED)
        return REFUSED if r["objectives"] is None else float(scaled_objectives(problem, r)[objective])

    def g(u):  # >= 0 when met (COBYLA's convention)
        r = row_at(u)
        if r["constraints"] is None:
            return -np.ones(len(names) + len(bounds_on)) * 1e3
        vals = [-r["constraints"].get(k, 0.0) / UNIT_SCALE[CONSTRAINT_UNITS[k]] for k in names]
        sc = scaled_objectives(problem, r) if r["objectives"] is not None else None
        vals += [lim - sc[i] for i, lim in bounds_on]
        return np.array(vals, float)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            minimize(f, x0_unit, method="COBYLA", constraints=[] if restore else [{"type": "ineq", "fun": g}],
                     bounds=[(0.0, 1.0)] * len(x0_unit),
                     options={"maxiter": max(budget, len(x0_unit) + 2), "rhobeg": POLISH_STEP, "tol": 1e-9})
        except _Budget:
            pass


class _Budget(Exception):
    """The evaluation budget is spent."""


@dataclass
class Result:
    history: list
    chosen: dict | None
    reason: str
    front: list
    base: dict
    method: str
    timings: dict


def optimize(problem: Problem, engine: Engine = Engine(), progress=None) -> Result:
    """Run the search (module docstring). Raises OptimizeError when no design meets the constraints."""
    spec = problem.spec
    ev = Evaluator(problem, engine, progress)
    t0 = time.perf_counter()
    base_unit = np.clip(problem.to_unit(problem.base_x), 0.0, 1.0)
    d = len(spec.parameters)
    polish_budget = max(d + 2, int(POLISH_SHARE * spec.evaluations))
    global_budget = spec.evaluations - polish_budget
    pop = int(min(max(8 * d, 16), max(global_budget // 4, 4)))
    base_row = None
    if len(spec.objectives) == 1:
        method = "differential_evolution + COBYLA"
        from scipy.optimize import differential_evolution

        popsize = max(1, pop // d)
        total = popsize * d
        gens = max(0, global_budget // total - 1)

        def func(U):  # U: (d, S)
            rows = ev(np.array([problem.to_x(u) for u in U.T]), "global")
            return np.array([r["merit"] for r in rows])

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            differential_evolution(func, [(0.0, 1.0)] * d, seed=np.random.default_rng(spec.seed), popsize=popsize,
                                   maxiter=gens, polish=False, vectorized=True, updating="deferred", tol=0.0,
                                   atol=0.0, init="latinhypercube", x0=base_unit)
        base_row = ev.history.rows[0]  # x0 replaces the first member of the initial population
        t1 = time.perf_counter()
        feas = [r for r in ev.history.rows if r["feasible"]]
        if feas:
            best = min(feas, key=lambda r: r["merit"])
            _polish(ev, problem.to_unit(best["x"]), spec.evaluations - len(ev.history.rows), 0, [])
        feas = [r for r in ev.history.rows if r["feasible"]]
        chosen = min(feas, key=lambda r: r["merit"]) if feas else None
        reason = "lowest merit of the feasible designs" if chosen is not None else ""
        front = pareto(problem, ev.history.rows) if chosen else []
    else:
        method = "optuna NSGA-II + COBYLA"
        base_row = _nsga(ev, problem, pop, global_budget, base_unit)
        t1 = time.perf_counter()
        front = pareto(problem, ev.history.rows)
        chosen, reason = (choose(problem, front, base_row) if front else (None, ""))
        if chosen is not None:
            limits = [(i, float(v)) for i, v in enumerate(scaled_objectives(problem, chosen)) if i > 0]
            _polish(ev, problem.to_unit(chosen["x"]), spec.evaluations - len(ev.history.rows), 0, limits)
            front = pareto(problem, ev.history.rows)
            chosen, reason = choose(problem, front, base_row)
    if chosen is None:  # nothing feasible: spend the polish on the violation, to say how close it gets
        valued = [r for r in ev.history.rows if r["constraints"] is not None]
        if valued and len(ev.history.rows) < spec.evaluations:
            start_row = min(valued, key=lambda r: (violation(r), r["index"]))
            _polish(ev, problem.to_unit(start_row["x"]), spec.evaluations - len(ev.history.rows), 0, [], restore=True)
            feas = [r for r in ev.history.rows if r["feasible"]]
            if feas:  # restoration found feasible designs: choose among them as the search would
                if len(spec.objectives) == 1:
                    chosen, reason = min(feas, key=lambda r: r["merit"]), "lowest merit of the feasible designs"
                    front = pareto(problem, ev.history.rows)
                else:
                    front = pareto(problem, ev.history.rows)
                    chosen, reason = choose(problem, front, base_row)
    timings = {"global_s": t1 - t0, "polish_s": time.perf_counter() - t1, "total_s": time.perf_counter() - t0}
    result = Result(ev.history.rows, chosen, reason, front, base_row, method, timings)
    return result


def _nsga(ev: Evaluator, problem: Problem, pop: int, budget: int, base_unit: np.ndarray) -> dict:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    spec = problem.spec
    names = [f"x{i}" for i in range(len(spec.parameters))]
    ncons = len(CONSTRAINT_UNITS)

    def constraints(trial):
        return trial.user_attrs["constraints"]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sampler = optuna.samplers.NSGAIISampler(population_size=pop, seed=spec.seed, constraints_func=constraints)
        study = optuna.create_study(directions=["minimize"] * len(spec.objectives), sampler=sampler)
        study.enqueue_trial(dict(zip(names, base_unit.tolist())))
        done = 0
        while done < budget:
            k = min(pop, budget - done)
            trials = [study.ask() for _ in range(k)]
            U = np.array([[t.suggest_float(n, 0.0, 1.0) for n in names] for t in trials])
            rows = ev(np.array([problem.to_x(u) for u in U]), "global")
            for t, r in zip(trials, rows):
                if r["objectives"] is None:
                    t.set_user_attr("constraints", [1e9] * ncons)
                    study.tell(t, [1e9] * len(spec.objectives))
                    continue
                cons = [r["constraints"][c] / UNIT_SCALE[CONSTRAINT_UNITS[c]] if c in r["constraints"] else -1.0
                        for c in CONSTRAINT_UNITS]
                t.set_user_attr("constraints", cons)
                study.tell(t, scaled_objectives(problem, r).tolist())
            done += k
    return ev.history.rows[0]


def infeasible_message(problem: Problem, rows: list[dict]) -> str:
    """Which constraints no design met, each with the best value reached (and where the search was)."""
    valued = [r for r in rows if r["constraints"] is not None]
    if not valued:
        errors: dict[str, int] = {}
        for r in rows:
            errors[r["error"]] = errors.get(r["error"], 0) + 1
        common = max(errors, key=errors.get)
        return (f"every one of the {len(rows)} designs tried was refused by the geometry; most often: {common}; "
                "narrow optimize.parameters to designs that build")
    parts = []
    for name in CONSTRAINT_UNITS:
        vals = [(r["constraints"][name], r) for r in valued if name in r["constraints"]]
        if not vals:
            continue
        best, row = min(vals, key=lambda vr: vr[0])
        if best > 0:
            unit = CONSTRAINT_UNITS[name]
            at = ", ".join(f"{p.key} = {p.shown(v)}" for p, v in zip(problem.spec.parameters, row["x"]))
            which = ""
            if name == "later.tolerance_stack":  # the count names placements: say which, at that design
                refused = stack_refusals(problem, row["x"])
                which = f": {'; '.join(refused)}" if refused else ""
            parts.append(f"{name} ({CONSTRAINT_KEYS[name]}): never met; best value reached {best:+.4g} {unit} over its "
                         f"limit (at {at}){which}".replace("  ", " "))
    if not parts:  # each met somewhere, never all together
        worst = min(valued, key=violation)
        missed = [k for k, v in worst["constraints"].items() if v > 0]
        return ("each constraint is met by some design but none meets them all together; the closest misses "
                + ", ".join(f"{k} by {worst['constraints'][k]:+.4g} {CONSTRAINT_UNITS[k]}" for k in missed))
    return "no design meets the constraints: " + "; ".join(parts)
