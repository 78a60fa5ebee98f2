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

Resources: worker processes on this machine are at most its cores (:func:`cores`; a remote Dask
scheduler may have more), and each one dies with the process that started it (Linux
``PR_SET_PDEATHSIG``), so a run killed with SIGKILL leaves no worker behind. A count a user gives
(rays, builds, samples) is checked against the machine's memory (:func:`machine_memory`) before
anything is allocated (:func:`require_memory`). Temporary files of a run go into one folder,
``rigcad-run-<pid>-*`` (:func:`run_temp_dir`), removed at the end and, after a kill, by the next run.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import pickle
import shutil
import signal
import socket
import struct
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

from rigcad.errors import RigcadError

if TYPE_CHECKING:
    import numpy as np

#: Scheduler value that starts a Dask LocalCluster for the run.
LOCAL_DASK = "local-dask"
#: Seconds to reach a Dask scheduler given by address and hear its first message (the whole
#: handshake, not only the TCP connect) before the run is refused.
CONNECT_TIMEOUT_S = 10
#: Largest first message (bytes) a Dask scheduler sends: its handshake is a small dict (versions,
#: compression and pickle protocol; ~100 bytes); a server whose first 8 bytes read as more is not
#: speaking Dask's protocol (an HTTP "HTTP/1.1" read as a length is 3.5e18).
MAX_HANDSHAKE_BYTES = 1 << 20
#: Workers a remote Dask scheduler may be asked to balance the tasks over (only the batch sizes
#: depend on it): a large cluster, not a typo.
MAX_DASK_WORKERS = 4096
#: Prefix of a run's temporary folder in the system temp folder; the pid of the run follows.
RUN_TEMP_PREFIX = "rigcad-run-"

#: Called after each finished task with (tasks done, tasks in all, items done, items in all).
Progress = Callable[[int, int, int, int], None] | None


class EngineError(RigcadError):
    """A parallel run could not be started or a worker failed."""


class ResourceError(RigcadError):
    """A count asks for more memory than this machine has: the message names the argument and the
    largest value that would fit."""


def cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def machine_memory() -> int:
    """Physical memory of this machine in bytes, or the cgroup's limit when it is lower (a container)."""
    total = 0
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        try:
            import psutil

            total = int(psutil.virtual_memory().total)
        except ImportError:
            total = 0
    for limit_file in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(limit_file).read_text().strip()
        except OSError:
            continue
        if text.isdigit() and 0 < int(text) < (total or int(text) + 1):
            total = int(text)
    return total or 8 << 30  # unknown: assume a small 8 GB machine rather than none


def require_memory(param: str, value: int, per_item: float, fixed: float = 0.0, what: str = "",
                   memory: int | None = None, most: float | None = None) -> None:
    """Refuse ``param = value`` when ``fixed + per_item * value`` bytes (an estimate, made before
    anything is allocated) exceed this machine's memory; the message names the largest value that
    fits (and is at most ``most``, the parameter's own bound)."""
    memory = machine_memory() if memory is None else memory
    need = fixed + per_item * float(value)
    if need <= memory:
        return
    largest = int(max(0.0, memory - fixed) // per_item)
    if most is not None:
        largest = min(largest, int(most))
    raise ResourceError(f"{param} {value}: {what + ' ' if what else ''}would need about {need / 2**30:.3g} GiB of "
                        f"memory, more than this machine's {memory / 2**30:.3g} GiB; the largest {param} that fits "
                        f"is {largest}", param=param)


@dataclass(frozen=True)
class Engine:
    """Where tasks run. ``workers``: processes (>= 1; ``0`` or ``None`` = every core);
    ``scheduler``: None (loky, or serial for one worker), ``"local-dask"`` or a Dask address."""

    workers: int | None = 1
    scheduler: str | None = None

    @property
    def n_workers(self) -> int:
        """Processes the run uses: at most this machine's cores (more only on a remote Dask
        scheduler, up to MAX_DASK_WORKERS): a process per task beyond the cores only adds memory."""
        if self.workers is None or self.workers == 0:
            return cores()
        if self.workers < 0:
            raise EngineError(f"workers = {self.workers}: need a positive count, or 0 for every core",
                              param="--workers")
        if self.scheduler is not None and self.scheduler != LOCAL_DASK:
            return min(int(self.workers), MAX_DASK_WORKERS)
        return min(int(self.workers), cores())

    @property
    def name(self) -> str:
        """``serial``, ``loky`` or ``dask``: what runs the tasks (recorded in reports)."""
        if self.scheduler is not None:
            return "dask"
        return "loky" if self.n_workers > 1 else "serial"


def child_seed(seed: int, i: int) -> "np.random.SeedSequence":
    """Child i of ``SeedSequence(seed)``, the one ``.spawn`` would give as its i-th (same entropy,
    spawn key (i,)), made alone: sample i draws from it whatever batch or worker it lands in, and
    a task builds only its own samples' seeds (spawning all 10,000 took 0.13 s per task)."""
    import numpy as np

    return np.random.SeedSequence(int(seed), spawn_key=(int(i),))


def split(count: int, size: int) -> list[range]:
    """``range(count)`` cut into consecutive batches of at most ``size`` items."""
    size = max(1, int(size))
    return [range(a, min(a + size, count)) for a in range(0, count, size)]


# -- a run's temporary folder ---------------------------------------------------------------------------
#: Folders earlier rigcad versions made directly in the temp folder (one per slicer run or key
#: listing); a kill left them for good. Removed when older than this (s): no run lasts a day.
_LEGACY_TEMP = ("rigcad-keys-", "rigcad-slice-", "rigcad-check-")
LEGACY_TEMP_AGE_S = 24 * 3600


#: The file in a run folder that its process holds an exclusive ``flock`` on while it runs: the
#: kernel drops the lock when the process (and every child that inherited it) has ended, however it
#: ended, so a sweep tells a live run from a killed one without reading /proc or trusting a pid.
RUN_OWNER_FILE = ".owner"


def _hold_owner(path: Path) -> int:
    """Create ``path/.owner`` and hold an exclusive lock on it; returns the descriptor to close."""
    fd = os.open(path / RUN_OWNER_FILE, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)
    return fd


def _run_alive(folder: str, pid: int) -> bool:
    """Whether the run that made ``folder`` may still be running: its owner file is locked, or (no
    owner file yet: the moment between making the folder and locking it) process ``pid`` exists.
    Anything that is not rigcad's plain owner file counts as alive: the sweep leaves it alone."""
    try:
        fd = os.open(os.path.join(folder, RUN_OWNER_FILE), os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK)
    except FileNotFoundError:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:  # another user's process
            return True
        return True
    except OSError:  # a link or something else planted there
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


def sweep_stale_runs(base: Path) -> list[Path]:
    """Remove the temporary folders of rigcad runs that ended without their clean-up (killed):
    ``rigcad-run-<pid>-*`` whose owner lock is free (the run ended without its clean-up), and the folders older versions left (see
    _LEGACY_TEMP). Only this user's real folders (never through a link). Returns what was removed."""
    removed = []
    try:
        entries = list(os.scandir(base))
    except OSError:
        return removed
    now = time.time()
    for e in entries:
        name = e.name
        if name.startswith(RUN_TEMP_PREFIX):
            pid_text = name[len(RUN_TEMP_PREFIX):].split("-", 1)[0]
            if not pid_text.isdigit() or int(pid_text) == os.getpid():
                continue
        elif not name.startswith(_LEGACY_TEMP):
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue
        if not e.is_dir(follow_symlinks=False) or st.st_uid != os.getuid():
            continue
        if name.startswith(RUN_TEMP_PREFIX):
            if _run_alive(e.path, int(pid_text)):
                continue
        elif now - st.st_mtime < LEGACY_TEMP_AGE_S:
            continue
        shutil.rmtree(e.path, ignore_errors=True)
        removed.append(Path(e.path))
    return removed


#: The run folder of this process while one or more commands run in it (commands run in threads of
#: one process share it: ``tempfile.tempdir`` is process-wide), and how many are running.
_RUN_TEMP = {"path": None, "owner": None, "users": 0, "saved": (None, None)}
_RUN_TEMP_LOCK = threading.Lock()


@contextmanager
def run_temp_dir():
    """One temporary folder for everything a command and its children write to a temp folder
    (slicer runs, key listings, joblib's memory maps, Dask's worker scratch): ``tempfile`` and
    ``TMPDIR`` point into it while the command runs; it is removed at the end, and by the next
    run (:func:`sweep_stale_runs`) when this one was killed. The pool of loky workers started in
    it is shut down with it. Commands running at once in one process (threads) share one folder,
    made by the first and removed by the last, so none removes another's files or leaves
    ``tempfile`` pointing at a removed folder. Yields the folder."""
    with _RUN_TEMP_LOCK:
        if _RUN_TEMP["users"] == 0:
            base = Path(tempfile.gettempdir())
            sweep_stale_runs(base)
            path = Path(tempfile.mkdtemp(prefix=f"{RUN_TEMP_PREFIX}{os.getpid()}-", dir=base))
            owner = _hold_owner(path)
            _RUN_TEMP.update(path=path, owner=owner, saved=(tempfile.tempdir, os.environ.get("TMPDIR")))
            tempfile.tempdir = str(path)
            os.environ["TMPDIR"] = str(path)
        _RUN_TEMP["users"] += 1
        path = _RUN_TEMP["path"]
    try:
        yield path
    finally:
        with _RUN_TEMP_LOCK:
            _RUN_TEMP["users"] -= 1
            if _RUN_TEMP["users"] == 0:
                _end_run_temp(path, _RUN_TEMP["saved"])
                os.close(_RUN_TEMP["owner"])
                _RUN_TEMP.update(path=None, owner=None, saved=(None, None))


def _end_run_temp(path: Path, saved: tuple[str | None, str | None]) -> None:
    """Shut down the loky pool started in the run folder, point ``tempfile`` back, remove the folder."""
    loky = sys.modules.get("joblib.externals.loky.reusable_executor")
    executor = getattr(loky, "_executor", None) if loky else None
    if executor is not None:
        executor.shutdown(wait=True, kill_workers=True)
    tempfile.tempdir = saved[0]
    if saved[1] is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = saved[1]
    shutil.rmtree(path, ignore_errors=True)


# -- worker side --------------------------------------------------------------------------------------
#: prctl option: the signal this process gets when the thread that started it ends (linux/prctl.h).
PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> None:
    """In a worker process: be killed (SIGKILL) when the process that started it ends, however it
    ends (SIGKILL included, where no clean-up of the parent runs). Linux only (prctl); elsewhere a
    worker still ends when its pool's pipe closes. Used as the loky workers' initializer. Linux
    sends the signal when the *thread* that started the worker ends: see :func:`run`."""
    if sys.platform.startswith("linux"):
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) != 0:  # pragma: no cover - a kernel without it
            return
    if os.getppid() != parent_pid:  # the parent ended before the line above: nothing would signal us
        os._exit(1)


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

        # the death signal follows the thread that started a worker: only the main thread, which
        # lives as long as the process, may arm it (a pool started from a passing thread would
        # lose its workers with that thread)
        arm = threading.current_thread() is threading.main_thread()
        par = Parallel(n_jobs=min(engine.n_workers, max(1, len(tasks))), backend="loky",
                       return_as="generator", batch_size=1, pre_dispatch="2*n_jobs",
                       temp_folder=tempfile.gettempdir(),
                       **(dict(initializer=die_with_parent, initargs=(os.getpid(),)) if arm else {}))
        for i, r in enumerate(par(delayed(_run_one)(func, digest, blob, t) for t in tasks)):
            out[i] = r
            done_items += sizes[i]
            report(i + 1, len(tasks), done_items, total_items)
        return out
    return _run_on_dask(func, shared, tasks, engine, report, sizes, total_items, out)


def _handshake(address: str, timeout: float = None) -> None:
    """Raise OSError unless a Dask scheduler answers at a tcp/tls address within ``timeout`` s:
    the TCP connect AND its first message (a scheduler speaks first, its handshake), whose length
    must be a handshake's. distributed's Client bounds only the connect: a server that accepts and
    says nothing would hang it for good, and one that speaks HTTP has its "HTTP/1.1" read as a
    3-exabyte length."""
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port

    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout
    protocol, location = parse_address(address)
    if protocol not in ("tcp", "tls"):
        return
    deadline = time.monotonic() + timeout
    with socket.create_connection(parse_host_port(location), timeout=timeout) as sock:
        if protocol == "tls":  # the TLS handshake comes first and needs the certificates: Client's timeout covers it
            return
        head = b""
        while len(head) < 8:
            sock.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                chunk = sock.recv(8 - len(head))
            except socket.timeout:
                raise TimeoutError(f"it accepted the connection but sent nothing in {timeout:g} s "
                                   "(a Dask scheduler greets at once)") from None
            if not chunk:
                raise ConnectionError("it closed the connection without a Dask handshake")
            head += chunk
        if head.startswith(b"HTTP") or struct.unpack("<Q", head)[0] > MAX_HANDSHAKE_BYTES:
            what = "an HTTP server (the dashboard? the scheduler listens on port 8786)" if head.startswith(b"HTTP") \
                else "a server that does not speak Dask's protocol"
            raise ConnectionError(f"it answered as {what}")


def _client_within(address: str, timeout: float):
    """``Client(address)`` made in a daemon thread and given up after ``timeout`` s: a server that
    passed the greeting check and then stalls must not hang the run."""
    from distributed import Client

    box: dict[str, Any] = {}

    def make() -> None:
        try:
            box["client"] = Client(address, timeout=f"{timeout}s")
        except BaseException as err:  # handed to the caller, which turns it into one line
            box["error"] = err

    t = threading.Thread(target=make, daemon=True, name="rigcad-dask-connect")
    t.start()
    t.join(timeout + 1.0)
    if t.is_alive():
        raise TimeoutError(f"no Dask handshake in {timeout:g} s")
    if "error" in box:
        err = box["error"]
        if isinstance(err, (OSError, TimeoutError, ValueError, MemoryError, OverflowError)):
            raise OSError(str(err) or type(err).__name__) from err
        raise err
    return box["client"]


def _run_on_dask(func, shared, tasks, engine, report, sizes, total_items, out) -> list:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as err:
        raise EngineError("--scheduler needs Dask: pip install 'rigcad[dask]' (dask[distributed])",
                          param="--scheduler") from err
    cluster = None
    try:
        if engine.scheduler == LOCAL_DASK:
            # the workers' scratch folders go in the run's temporary folder (run_temp_dir), which
            # the next run removes when this one is killed
            cluster = LocalCluster(n_workers=engine.n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1", local_directory=tempfile.gettempdir())
            client = Client(cluster)
        else:
            _handshake(engine.scheduler)
            client = _client_within(engine.scheduler, CONNECT_TIMEOUT_S)
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
