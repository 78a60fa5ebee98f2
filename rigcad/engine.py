"""Parallel batches on this machine's cores (joblib's loky process pool) or on Dask, with one
result whatever ran them.

The contract: a job is a top-level function ``func(shared, task) -> result`` (picklable by name),
one ``shared`` object for every task (a Rig, tables...) and a list of ``tasks``. Results come back
in task order. A task must depend only on its own arguments (draw its randomness from a seed it
carries, e.g. a :func:`child_seed`), so the results are bit-identical for any worker count
and either engine. ``shared`` is pickled once in the parent and unpickled once per worker process
(cached by its SHA-256); expensive per-worker state built from it (an Embree scene) goes in
:func:`worker_cache`, built in the worker, never pickled.

Engines: ``serial`` (in this process), ``loky`` (joblib's process pool, the default for
``workers > 1``), ``dask`` (a ``dask.distributed`` scheduler at an address, or ``local-dask``: a
``LocalCluster`` of ``workers`` single-threaded processes started for the run). Dask is the optional
``rigcad[dask]`` extra; without it ``--scheduler`` says what to install.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import socket
import time
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from rigcad.errors import RigcadError

#: Scheduler value that starts a Dask LocalCluster for the run.
LOCAL_DASK = "local-dask"
#: Seconds to reach a Dask scheduler given by address before the run is refused.
CONNECT_TIMEOUT_S = 10

#: Called after each finished task with (tasks done, tasks in all, items done, items in all).
Progress = Callable[[int, int, int, int], None] | None


class EngineError(RigcadError):
    """A parallel run could not be started or a worker failed."""


@dataclass(frozen=True)
class Engine:
    """Where tasks run. ``workers``: processes (>= 1; ``0`` or ``None`` = every core);
    ``scheduler``: None (loky, or serial for one worker), ``"local-dask"`` or a Dask address."""

    workers: int | None = 1
    scheduler: str | None = None

    @property
    def n_workers(self) -> int:
        if self.workers is None or self.workers == 0:
            return os.cpu_count() or 1
        if self.workers < 0:
            raise EngineError(f"workers = {self.workers}: need a positive count, or 0 for every core",
                              param="--workers")
        return int(self.workers)

    @property
    def name(self) -> str:
        """``serial``, ``loky`` or ``dask``: what runs the tasks (recorded in reports)."""
        if self.scheduler is not None:
            return "dask"
        return "loky" if self.n_workers > 1 else "serial"


def child_seed(seed: int, i: int) -> np.random.SeedSequence:
    """Child i of ``SeedSequence(seed)``, the one ``.spawn`` would give as its i-th (same entropy,
    spawn key (i,)), made alone: sample i draws from it whatever batch or worker it lands in, and
    a task builds only its own samples' seeds (spawning all 10,000 took 0.13 s per task)."""
    return np.random.SeedSequence(int(seed), spawn_key=(int(i),))


def split(count: int, size: int) -> list[range]:
    """``range(count)`` cut into consecutive batches of at most ``size`` items."""
    size = max(1, int(size))
    return [range(a, min(a + size, count)) for a in range(0, count, size)]


# -- worker side --------------------------------------------------------------------------------------
_SHARED: dict[str, Any] = {}
_CACHE: dict[tuple, Any] = {}


def worker_cache(key: tuple, build: Callable[[], Any]) -> Any:
    """State this worker process builds once and keeps (an Embree scene, tables): ``build()`` on
    first use of ``key``, the same object after. Runs in the parent for the serial engine."""
    if key not in _CACHE:
        if len(_CACHE) > 64:  # a long-lived Dask worker sees many rigs: keep the memory bounded
            _CACHE.clear()
        _CACHE[key] = build()
    return _CACHE[key]


def _unpickled(digest: str, blob: bytes) -> Any:
    if digest not in _SHARED:
        if len(_SHARED) > 8:
            _SHARED.clear()
        _SHARED[digest] = pickle.loads(blob)
    return _SHARED[digest]


def _run_one(func: Callable, digest: str, blob: bytes, task: Any) -> Any:
    return func(_unpickled(digest, blob), task)


def _run_dask(func: Callable, shared: Any, task: Any) -> Any:
    return func(shared, task)


# -- parent side --------------------------------------------------------------------------------------
def run(func: Callable[[Any, Any], Any], shared: Any, tasks: Sequence[Any], engine: Engine = Engine(),
        progress: Progress = None, sizes: Sequence[int] | None = None) -> list:
    """``[func(shared, t) for t in tasks]`` on ``engine``, in task order. ``sizes``: items per task
    (samples in a batch) for the progress callback; default 1 each."""
    tasks = list(tasks)
    sizes = list(sizes) if sizes is not None else [1] * len(tasks)
    total_items = int(sum(sizes))
    report = progress or (lambda *a: None)
    out: list = [None] * len(tasks)
    done_items = 0
    if engine.name == "serial":
        for i, t in enumerate(tasks):
            out[i] = func(shared, t)
            done_items += sizes[i]
            report(i + 1, len(tasks), done_items, total_items)
        return out
    blob = pickle.dumps(shared, protocol=pickle.HIGHEST_PROTOCOL)
    digest = hashlib.sha256(blob).hexdigest()
    if engine.name == "loky":
        from joblib import Parallel, delayed

        par = Parallel(n_jobs=min(engine.n_workers, max(1, len(tasks))), backend="loky",
                       return_as="generator", batch_size=1, pre_dispatch="2*n_jobs")
        for i, r in enumerate(par(delayed(_run_one)(func, digest, blob, t) for t in tasks)):
            out[i] = r
            done_items += sizes[i]
            report(i + 1, len(tasks), done_items, total_items)
        return out
    return _run_on_dask(func, shared, tasks, engine, report, sizes, total_items, out)


def _listening(address: str) -> None:
    """Raise OSError at once when nothing listens at a tcp/tls scheduler address: distributed's
    Client would retry a refused connection for its whole timeout before saying so."""
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port

    protocol, location = parse_address(address)
    if protocol in ("tcp", "tls"):
        with socket.create_connection(parse_host_port(location), timeout=CONNECT_TIMEOUT_S):
            pass


def _run_on_dask(func, shared, tasks, engine, report, sizes, total_items, out) -> list:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as err:
        raise EngineError("--scheduler needs Dask: pip install 'rigcad[dask]' (dask[distributed])",
                          param="--scheduler") from err
    cluster = None
    try:
        if engine.scheduler == LOCAL_DASK:
            cluster = LocalCluster(n_workers=engine.n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1")
            client = Client(cluster)
        else:
            _listening(engine.scheduler)
            client = Client(engine.scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
    except (OSError, TimeoutError, ValueError) as err:  # ValueError: an address Dask cannot read
        if cluster is not None:
            cluster.close()
        raise EngineError(f"cannot reach the Dask scheduler {engine.scheduler!r}: {err}; give a running "
                          f"scheduler's address (tcp://host:8786) or {LOCAL_DASK!r}", param="--scheduler") from err
    try:
        [shared_f] = client.scatter([shared], broadcast=True, hash=False)
        futures = [client.submit(_run_dask, func, shared_f, t, pure=False) for t in tasks]
        index = {f.key: i for i, f in enumerate(futures)}
        done = done_items = 0
        for fut in as_completed(futures):
            i = index[fut.key]
            out[i] = fut.result()
            done += 1
            done_items += sizes[i]
            report(done, len(tasks), done_items, total_items)
        return out
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


class Rate:
    """Items per second and ETA for a progress line, from the wall clock."""

    def __init__(self) -> None:
        self.t0 = time.perf_counter()

    def __call__(self, done: int, total: int) -> tuple[float, float]:
        dt = max(time.perf_counter() - self.t0, 1e-9)
        rate = done / dt
        return rate, (total - done) / rate if rate > 0 else float("inf")
