"""The order search's bounds (rigcad.manual.assembly_check.find_order): on small assemblies of boxes
it answers as the plain search over sets does (the same order found, the same refusal), and a
rig that cannot go together because two parts block each other is refused after judging a few
sets, not every set of the parts that do not matter.

The plain search (``plain_order``) is the search before the bounds: depth-first over the sets of
steps done, the declared order first at each choice, a set given up when a step left is blocked,
dead sets remembered. Counts of the sets judged are deterministic (no timing)."""

from __future__ import annotations

import manifold3d as m3
import numpy as np
import pytest

from rigcad.errors import AssemblyError, GeometryError
from rigcad.manual import assembly_check as AC

DOWN, UP = (0.0, 0.0, -1.0), (0.0, 0.0, 1.0)
SIDES = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0))


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return m3.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))


def plain_order(assembly: AC.Assembly) -> list[str] | None:
    """The search without bounds (module docstring): the order's step names, or None."""
    dead: set = set()
    total = len(assembly.steps)

    def search(done, path):
        if len(path) == total:
            return path
        if done in dead:
            return None
        left = [(s, assembly.attempt(s, done)) for s in assembly.steps if s.name not in done]
        if not any(isinstance(r, AC.Refusal) and r.blocked for _, r in left):
            for s, r in left:
                if isinstance(r, AC.Placed):
                    found = search(done | {s.name}, [*path, s.name])
                    if found is not None:
                        return found
        dead.add(done)
        return None

    return search(frozenset(), [])


def random_assembly(seed: int) -> AC.Assembly:
    """Six to eight boxes on a floor, in a 3 x 3 grid of 20 mm cells, some stacked, some tall
    enough to lean over a neighbour (a lintel), each going in along a random subset of the six
    axes, some needing the one under it: a mix of orders that work and rigs that cannot go together."""
    rng = np.random.default_rng(seed)
    solids = {"floor": box((-40, -40, -5), (80, 80, 0))}
    steps = [AC.Step("floor", ("floor",), (DOWN,), 50.0)]
    height = {}
    for k in range(int(rng.integers(6, 9))):
        i, j = (int(v) for v in rng.integers(0, 3, 2))
        z0 = height.get((i, j), 0.0)
        h = float(rng.uniform(3, 12))
        lo, hi = np.array([20 * i + 1, 20 * j + 1, z0]), np.array([20 * i + 19, 20 * j + 19, z0 + h])
        if rng.random() < 0.3:  # a lintel over the next cell in x, 2 mm above whatever stands there
            hi[0] += 20
            lo[2] = max(z0, height.get((i + 1, j), 0.0)) + 2.0
            hi[2] = lo[2] + 3.0
        name = f"p{k}"
        solids[name] = box(lo, hi)
        dirs = [d for d in (DOWN, *SIDES, UP) if rng.random() < 0.5] or [DOWN]
        below = [s.name for s in steps[1:] if s.name in solids and height.get((i, j)) and
                 abs(solids[s.name].bounding_box()[5] - z0) < 1e-9]
        steps.append(AC.Step(name, (name,), tuple(dirs), 50.0, needs=("floor", *below[-1:])))
        height[(i, j)] = float(hi[2])
    order = rng.permutation(len(steps))
    return AC.Assembly(solids, [steps[k] for k in order], with_bench=False)


def plain_find_order(assembly: AC.Assembly) -> list[str]:
    """find_order before the bounds: its refusals before any search (a loop of needs, a step blocked
    with only what it needs), the plain search, and its refusal naming the steps left (_stuck)."""
    AC._refuse_cycles(assembly)
    AC._refuse_blocked_at_first(assembly)
    order = plain_order(assembly)
    if order is None:
        raise AC._stuck(assembly)
    return order


def answer(fn, assembly):
    try:
        out = fn(assembly)
        return ("order", [p if isinstance(p, str) else p.step.name for p in out])
    except AssemblyError as err:
        return ("refused", err.step, err.obstacles, str(err))


@pytest.mark.parametrize("seed", range(40))
def test_the_bounded_search_answers_as_the_plain_one(seed):
    """The same order found, or the same refusal word for word; and an order found is one the
    check accepts step by step."""
    plain = answer(plain_find_order, random_assembly(seed))
    assert answer(AC.find_order, random_assembly(seed)) == plain
    if plain[0] == "order":
        AC.check_order(random_assembly(seed), plain[1])


def test_the_random_assemblies_have_both_answers():
    """The comparison above means something only if both kinds of answer occur among its seeds."""
    answers = [answer(plain_find_order, random_assembly(seed)) for seed in range(40)]
    refused = [a for a in answers if a[0] == "refused"]
    assert 0 < len(refused) < len(answers)
    # and some refusals come from the search itself, not from the checks before it
    assert any("cannot go in even with only" not in a[3] and "loop" not in a[3] for a in refused)


@pytest.mark.parametrize("seed", range(10))
def test_blocked_and_place_agree_with_attempt(seed):
    """The search's quick judgements (Assembly.blocked, Assembly.place) are attempt's, set by set,
    each on an assembly of its own (no measurement shared)."""
    rng = np.random.default_rng(100 + seed)
    a = random_assembly(seed)
    names = [s.name for s in a.steps]
    for _ in range(30):
        done = frozenset(n for n in names if rng.random() < 0.5)
        step = a.steps[int(rng.integers(len(a.steps)))]
        if step.name in done:
            continue
        r = random_assembly(seed).attempt(step, done)
        assert random_assembly(seed).blocked(step, done) == (isinstance(r, AC.Refusal) and r.blocked)
        placed = random_assembly(seed).place(step, done)
        assert placed == (r if isinstance(r, AC.Placed) else None)


def locked_pair(spare: int) -> AC.Assembly:
    """A wall with a square hole and a dumbbell pin through it (its shaft in the hole with 2 mm all
    round, its heads wider than the hole, 8 mm off the wall each side): once either is in place the
    other has no way in, though each alone goes in; no order exists. Around them ``spare`` free
    blocks that go in any order."""
    solids = {"floor": box((-100, -100, -5), (100, 100, 0)),
              "wall": box((-2, -20, 0), (2, 20, 40)) - box((-3, -5, 15), (3, 5, 25)),
              "pin": box((-15, -3, 17), (15, 3, 23)) + box((-15, -8, 12), (-10, 8, 28)) + box((10, -8, 12), (15, 8, 28))}
    steps = [AC.Step("floor", ("floor",), (DOWN,), 50.0),
             AC.Step("wall", ("wall",), (DOWN, *SIDES), 80.0, needs=("floor",)),
             AC.Step("pin", ("pin",), (DOWN, *SIDES), 80.0, needs=("floor",))]
    for k in range(spare):
        x = -90 + 12 * k
        solids[f"b{k}"] = box((x, 60, 0), (x + 8, 68, 8))
        steps.append(AC.Step(f"b{k}", (f"b{k}",), (DOWN,), 50.0, needs=("floor",)))
    return AC.Assembly(solids, steps, with_bench=False)


def judged(monkeypatch) -> list:
    """The (step, set) pairs the search judges, counted through Assembly.place and Assembly.blocked."""
    seen: list = []
    place, blocked = AC.Assembly.place, AC.Assembly.blocked

    def counted_place(self, step, done):
        seen.append(done)
        return place(self, step, done)

    def counted_blocked(self, step, done):
        seen.append(done)
        return blocked(self, step, done)

    monkeypatch.setattr(AC.Assembly, "place", counted_place)
    monkeypatch.setattr(AC.Assembly, "blocked", counted_blocked)
    return seen


def test_two_parts_that_lock_each_other_are_refused_without_trying_every_set(monkeypatch):
    """Either of the wall and the pin through it blocks every way in of the other. Ten spare blocks
    make 2^10 sets the plain search tries before saying no; the bounded search finds that the two
    would each have to precede the other and refuses at once: it judged 2 (step, set) pairs, where
    with the pair bounds taken out (must_precede giving only what each step needs) it judged 16,398
    over 3,073 sets (measured once; the bound below fails then)."""
    sets: list = []
    attempt = AC.Assembly.attempt

    def counted(self, step, done):
        sets.append(done)
        return attempt(self, step, done)

    monkeypatch.setattr(AC.Assembly, "attempt", counted)
    assert plain_order(locked_pair(10)) is None
    assert len(set(sets)) >= 2 ** 10  # the plain search tries every set of the spare blocks
    monkeypatch.undo()
    assert AC.must_precede(locked_pair(3)) is None  # the loop: each must precede the other
    seen = judged(monkeypatch)
    with pytest.raises(GeometryError, match="no feasible assembly order") as e:
        AC.find_order(locked_pair(10))
    assert e.value.step in ("wall", "pin")
    assert len(seen) < 50, len(seen)


def test_the_refusal_names_the_parts_that_lock_not_a_part_the_declared_order_put_in_wrong():
    """A planted lock (the wall and the pin through it: each blocks the other's every way in) behind a
    decoy: a lid declared before the cup it covers, so the declared order's greedy prefix puts the lid
    in first and then finds the cup blocked by it. The refusal names the wall and the pin, the parts
    that collide, not the cup (which only has to go in before its lid). Seen to fail with the greedy
    prefix naming the first blocked step (the cup, into the lid)."""
    a = locked_pair(0)
    solids = dict(a.solids)
    solids["cup"] = box((40, -10, 0), (60, 10, 10))
    solids["lid"] = box((38, -12, 10), (62, 12, 12)) + box((38, -12, 0), (40, 12, 10)) + box((60, -12, 0), (62, 12, 10)) \
        + box((40, -12, 0), (60, -10, 10)) + box((40, 10, 0), (60, 12, 10))
    steps = [a.by_name["floor"], AC.Step("lid", ("lid",), (DOWN,), 50.0, needs=("floor",)),
             AC.Step("cup", ("cup",), (DOWN, *SIDES), 50.0, needs=("floor",)), a.by_name["wall"], a.by_name["pin"]]
    with pytest.raises(AssemblyError) as e:
        AC.find_order(AC.Assembly(solids, steps, with_bench=False))
    err = e.value
    assert {err.step, *err.obstacles} == {"wall", "pin"}, (err.step, err.obstacles, str(err))
    assert "cup" not in err.summary and "wall" in err.summary and "pin" in err.summary
    assert "must go in before" in err.summary  # why no order avoids it: each would have to precede the other
    # the decoy alone (no lock) goes together: the cup before its lid
    order = AC.find_order(AC.Assembly({k: v for k, v in solids.items() if k not in ("wall", "pin")},
                                      steps[:3], with_bench=False))
    assert [p.step.name for p in order].index("cup") < [p.step.name for p in order].index("lid")
