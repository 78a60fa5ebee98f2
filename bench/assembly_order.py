"""The assembly check's order search (rigcad.manual.assembly_check.find_order) on the rigs the gate
judges: the default profile (passes), the low-pupil rig of tests/manual/test_gate.py (refused: the
splitter cannot go in even alone with its holder), and the designs `rigcad optimize
achutha2006_optimize` sends to its certified path (the first MAX_CERTIFY in preference, each with the
custom focusing lens the certified path gives it), some passing, some refused.

For each rig: the time to make its steps and solids (``plan.assembly`` over ``picture_meshes``), the
search's wall and CPU time (``time.process_time``: this process's own), how many (step, set) pairs it
judged (each Assembly._attempt, which memory spares a repeat, and each call of the bounded search's
quick place/blocked where the tree has them) and how many penetrations it measured, and its answer: the order found, or the step the
refusal names with what it runs into. Every case has a time limit (``--limit``, s; SIGALRM): a search
still running then is recorded as stopped, with its time so far.

Run it on this tree, and on another tree to compare (``--label``: the run's name in the JSON; the
tree is whatever ``PYTHONPATH`` puts first, e.g. a ``git archive`` of an older commit):

    .venv/bin/python bench/assembly_order.py [--quick] [--limit 600] [--label after] [--out bench/results]
    PYTHONPATH=/tmp/old .venv/bin/python bench/assembly_order.py --label before --limit 900

Each run is merged into ``assembly_order.json`` under its label (other labels kept), so one file holds
the times before and after; ``--quick`` (the smoke test) runs the refused low-pupil rig only.
"""

from __future__ import annotations

import json
import signal
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._common import arguments, run_info  # noqa: E402

LOW = "extends: achutha2006\nprojector:\n  pupil_height: 25 mm\n  lens_diameter: 25 mm\n"


class Stopped(Exception):
    """The case's time limit passed."""


def _stop(signum, frame):
    raise Stopped()


def optimize_designs(limit: int):
    """The rigs of `rigcad optimize achutha2006_optimize`'s certified path, in preference order: (name,
    rig) for the first ``limit`` designs its search prefers (rigcad.optimize.run.certify's rig, with
    its custom focusing lens when no stock lens focuses it); a design the certified path refuses
    before the gate is skipped with its reason."""
    import dataclasses

    from rigcad.engine import Engine
    from rigcad.errors import RigcadError
    from rigcad.optimize.run import _custom_focal_length, certified_rig, load_problem, preference
    from rigcad.optimize.search import optimize
    from rigcad.rig import Rig

    pb = load_problem("achutha2006_optimize", {"workers": 1, "seed": None, "evaluations": None})
    result = optimize(pb, Engine(workers=1), None)
    for row, _ in preference(pb, result)[:limit]:
        name = f"achutha2006_optimize design {row['index']}"
        try:
            rig, _ = certified_rig(pb, row)
            f = _custom_focal_length(rig.profile, rig.geometry)  # before the layout: the tower is laid out about the lens
            if f is not None:
                p = rig.profile
                rig = Rig.from_profile(dataclasses.replace(p, lens=dataclasses.replace(p.lens, focal_length=f)),
                                       previous=rig)
            rig.recipes
        except RigcadError as err:
            yield name, None, str(err)
            continue
        yield name, rig, None


def measure(name: str, rig, limit: float) -> dict:
    """One rig's search (module docstring)."""
    from rigcad.errors import AssemblyError, GeometryError
    from rigcad.manual import assembly_check as AC
    from rigcad.manual import plan
    from rigcad.manual.assembly import picture_meshes

    t0 = time.perf_counter()
    a = plan.assembly(rig, picture_meshes(rig))
    made = time.perf_counter() - t0
    counts = {"judged": 0, "penetrations": 0}
    pen = AC.penetration
    # the (step, set) judgements: attempt's, and the quick ones of the bounded search where they exist
    judges = {n: getattr(AC.Assembly, n) for n in ("_attempt", "place", "blocked") if hasattr(AC.Assembly, n)}

    def counting(fn):
        def judged(self, step, done):
            counts["judged"] += 1
            return fn(self, step, done)
        return judged

    def measured(x, y):
        counts["penetrations"] += 1
        return pen(x, y)

    for n, fn in judges.items():
        setattr(AC.Assembly, n, counting(fn))
    AC.penetration = measured
    signal.signal(signal.SIGALRM, _stop)
    w0, c0 = time.perf_counter(), time.process_time()
    signal.alarm(int(limit))
    try:
        order = AC.find_order(a)
        answer = {"passes": True, "order": [p.step.name for p in order]}
    except AssemblyError as err:
        answer = {"passes": False, "step": err.step, "obstacles": list(err.obstacles), "reason": str(err)[:400]}
    except GeometryError as err:
        answer = {"passes": False, "step": None, "reason": str(err)[:400]}
    except Stopped:
        answer = {"passes": None, "stopped_at_limit_s": limit}
    finally:
        signal.alarm(0)
        for n, fn in judges.items():
            setattr(AC.Assembly, n, fn)
        AC.penetration = pen
    return {"case": name, "steps": len(a.steps), "assembly_made_s": made, "search_s": time.perf_counter() - w0,
            "search_cpu_s": time.process_time() - c0, **counts, **answer}


def main() -> int:
    import rigcad

    parser = arguments(__doc__)
    parser.add_argument("--label", default="after", help="this run's name in the JSON (default: after)")
    parser.add_argument("--limit", type=float, default=600.0, help="time limit per case, s (default: 600)")
    parser.add_argument("--designs", type=int, default=None,
                        help="optimize designs to judge (default: rigcad.optimize.run.MAX_CERTIFY)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    from rigcad.optimize.run import MAX_CERTIFY

    low = args.out / "assembly_order_low.yaml"
    low.write_text(LOW, encoding="utf-8")
    run = {"run": run_info(), "limit_s": args.limit, "cases": []}
    try:
        cases = [("low pupil (refused alone with its holder)", lambda: rigcad.load(low), None)]
        if not args.quick:
            cases.insert(0, ("achutha2006", lambda: rigcad.load("achutha2006"), None))
            for name, rig, why in optimize_designs(args.designs or MAX_CERTIFY):
                cases.append((name, (lambda rig=rig: rig), why))
        for name, make, why in cases:
            if why is not None:
                run["cases"].append({"case": name, "refused_before_the_gate": why[:400]})
                continue
            row = measure(name, make(), args.limit)
            print(f"{name}: {row['search_s']:.1f} s, {row['judged']} judged, {row['penetrations']} penetrations, "
                  + ("order found" if row.get("passes") else f"refused at {row.get('step')}" if row.get("passes") is False
                     else "stopped at the limit"), flush=True)
            run["cases"].append(row)
    finally:
        low.unlink()
    path = args.out / "assembly_order.json"
    doc = json.loads(path.read_text()) if path.is_file() else {}
    doc = {"what": "rigcad.manual.assembly_check.find_order's time on the gate's rigs (bench/assembly_order.py)",
           "runs": {**doc.get("runs", {}), args.label: run}}
    path.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
