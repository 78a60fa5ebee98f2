"""rigcad.engine: the same results, in task order, on every engine; seeds per sample."""

import numpy as np
import pytest

from rigcad.engine import LOCAL_DASK, Engine, EngineError, child_seed, run, split, worker_cache


def _draw(shared, batch):
    """A task: per sample a draw from its own spawned seed, scaled by the shared object."""
    table = worker_cache(("table", shared["seed"]), lambda: np.arange(5.0))
    return [float(np.random.default_rng(child_seed(shared["seed"], i)).normal() * shared["scale"] + table[i % 5])
            for i in batch]


def _jobs(count=40, size=7):
    shared = {"seed": 123, "count": count, "scale": 2.5}
    return shared, split(count, size)


def test_a_child_seed_is_the_one_spawn_gives():
    spawned = np.random.SeedSequence(123).spawn(50)
    for i in (0, 1, 17, 49):
        assert np.array_equal(child_seed(123, i).generate_state(8), spawned[i].generate_state(8))
        assert np.random.default_rng(child_seed(123, i)).normal() == np.random.default_rng(spawned[i]).normal()
    assert not np.array_equal(child_seed(123, 1).generate_state(8), spawned[2].generate_state(8))


def test_split_covers_every_item_once():
    parts = split(23, 5)
    assert [len(p) for p in parts] == [5, 5, 5, 5, 3]
    assert [i for p in parts for i in p] == list(range(23))


def test_loky_matches_serial_bit_for_bit():
    shared, tasks = _jobs()
    serial = run(_draw, shared, tasks, Engine(1))
    seen = []
    loky = run(_draw, shared, tasks, Engine(2), progress=lambda *a: seen.append(a), sizes=[len(t) for t in tasks])
    assert Engine(2).name == "loky" and Engine(1).name == "serial"
    assert loky == serial
    assert seen[-1] == (len(tasks), len(tasks), 40, 40)
    # a different batching gives the same per-sample values: each sample owns its seed
    other = run(_draw, shared, split(40, 3), Engine(2))
    assert [v for b in other for v in b] == [v for b in serial for v in b]


def test_local_dask_matches_serial():
    pytest.importorskip("distributed")
    shared, tasks = _jobs(count=12, size=4)
    assert run(_draw, shared, tasks, Engine(2, LOCAL_DASK)) == run(_draw, shared, tasks, Engine(1))


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:9", "127.0.0.1:9", "bogus://x", "tcp://localhost",
                                     "tcp://no-such-host.invalid:8786"])
def test_unreachable_scheduler_is_one_clear_error(address):
    pytest.importorskip("distributed")
    with pytest.raises(EngineError, match="cannot reach the Dask scheduler") as err:
        run(_draw, *_jobs(count=2, size=1), Engine(1, address))
    assert address in str(err.value) and "tcp://host:8786" in str(err.value)


def test_negative_workers_refused():
    with pytest.raises(EngineError, match="workers = -1"):
        Engine(-1).n_workers


def test_commands_running_at_once_in_one_process_share_one_run_folder():
    """Two commands in threads of one process, the first ending before the second (the order that
    left ``tempfile`` pointing at the first's removed folder when each saved and restored it): both
    see one live folder while they run, and afterwards ``tempfile`` is back where it was."""
    import tempfile
    import threading

    from rigcad.engine import run_temp_dir

    before = tempfile.gettempdir()
    first_in, second_in, first_out = threading.Event(), threading.Event(), threading.Event()
    seen = {}

    def second():
        first_in.wait(60)
        with run_temp_dir() as path:
            seen["second"] = path
            second_in.set()
            first_out.wait(60)
            seen["alive_after_first"] = path.is_dir() and tempfile.gettempdir() == str(path)

    t = threading.Thread(target=second)
    t.start()
    with run_temp_dir() as path:
        seen["first"] = path
        first_in.set()
        assert second_in.wait(60), "the second command never started"
    first_out.set()
    t.join(60)
    assert seen["first"] == seen["second"] and seen["alive_after_first"], seen
    assert tempfile.gettempdir() == before and not seen["first"].exists()
