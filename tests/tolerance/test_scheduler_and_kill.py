"""A Dask scheduler address that is not one (silent, HTTP) is one line within the handshake's
bound; a run killed with SIGKILL leaves no process and, after the next run, no temporary folder."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import rigcad.engine as E
from rigcad.engine import Engine, EngineError, run

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]


def _task(shared, t):
    return t


class _Server:
    """A TCP server on 127.0.0.1 that accepts and then does ``behave(conn)``."""

    def __init__(self, behave):
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.conns: list[socket.socket] = []
        self.behave = behave
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            threading.Thread(target=self.behave, args=(conn,), daemon=True).start()

    def close(self):
        self.sock.close()
        for c in self.conns:
            c.close()


def _silent(conn):
    """Accept and say nothing, ever."""


def _http_replying(conn):
    """An HTTP server: waits for a request, answers 400 to anything."""
    try:
        conn.recv(65536)
        conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")
    except OSError:  # the test closed the server first
        pass


def _http_first(conn):
    """A server that speaks first, in HTTP (a banner or a proxy's error page)."""
    conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")


def _refusal_within(address: str, bound_s: float) -> str:
    """Run two tasks on ``address`` in a thread; the run must end (an EngineError) within ``bound_s``:
    a hang bound, not a speed figure (the old code waited past 115 s)."""
    box = {}

    def go():
        try:
            run(_task, None, [1, 2], Engine(1, address))
            box["result"] = "ran"
        except BaseException as err:  # recorded and judged below
            box["error"] = err

    t = threading.Thread(target=go, daemon=True)
    t.start()
    t.join(bound_s)
    assert not t.is_alive(), f"the run on {address} still waits after {bound_s} s"
    err = box.get("error")
    assert isinstance(err, EngineError), repr(err)
    return str(err)


@pytest.mark.parametrize("behave,says", [(_silent, "sent nothing"), (_http_replying, "sent nothing"),
                                         (_http_first, "HTTP server")])
def test_a_server_that_is_not_a_scheduler_is_refused_within_the_handshake_bound(behave, says, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(E, "CONNECT_TIMEOUT_S", 2)
    server = _Server(behave)
    try:
        # bound: the 2 s handshake timeout plus the Client's own bounded attempt, with room for a
        # loaded machine; the old code had no bound at all for the silent server
        msg = _refusal_within(f"tcp://127.0.0.1:{server.port}", 60)
    finally:
        server.close()
    assert "cannot reach the Dask scheduler" in msg and says in msg and "\n" not in msg, msg


def test_a_real_scheduler_passes_the_handshake_check():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None, protocol="tcp://",
                                  host="127.0.0.1") as cluster:
        assert run(_task, None, [3, 1, 2], Engine(1, cluster.scheduler_address)) == [3, 1, 2]


def test_the_http_scheduler_on_the_command_line_is_one_line(tmp_path):
    pytest.importorskip("distributed")
    server = _Server(_http_first)
    try:
        env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(tmp_path))
        proc = subprocess.run([sys.executable, "-c", "import sys; from rigcad.cli import main; sys.exit(main())",
                               "tolerance", "achutha2006", "--samples", "4", "--rays", "100", "--no-limits",
                               "--scheduler", f"tcp://127.0.0.1:{server.port}", "--exports", str(tmp_path / "x")],
                              capture_output=True, text=True, env=env, timeout=300)
    finally:
        server.close()
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1 and "HTTP server" in proc.stderr, proc.stderr


# -- kill -9 ------------------------------------------------------------------------------------------
def _children(pid: int) -> set[int]:
    """Every live descendant of ``pid`` (from /proc)."""
    parent_of = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z":
                parent_of[int(entry.name)] = int(fields[1])
    out, frontier = set(), {pid}
    while frontier:
        frontier = {c for c, p in parent_of.items() if p in frontier} - out
        out |= frontier
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie has ended; only its exit status waits for a reaper


def _poll(condition, bound_s: float, step_s: float = 0.05):
    """``condition()`` until it is truthy or ``bound_s`` passes; returns its last value."""
    end = time.monotonic() + bound_s
    while True:
        value = condition()
        if value or time.monotonic() > end:
            return value
        time.sleep(step_s)


def _start(argv: list[str], tmp: Path) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(tmp), RIGCAD_EVENTS="1")
    return subprocess.Popen([sys.executable, "-c", "import sys; from rigcad.cli import main; sys.exit(main())",
                             *argv, "--exports", str(tmp / "exports")],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)


def _kill_and_check(proc: subprocess.Popen, tmp: Path) -> None:
    """SIGKILL ``proc``; every process it started must end (bounded wait), and the next rigcad run
    must leave no temporary folder of it behind."""
    kids = _children(proc.pid)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    # bound: the kernel delivers the death signal at once; 30 s leaves room for a loaded machine
    survivors = _poll(lambda: not [k for k in kids if _alive(k)], 30) or [k for k in kids if _alive(k)]
    try:
        assert survivors is True, f"still alive after the parent's SIGKILL: {survivors}"
    finally:
        for k in kids:  # never leave them running, whatever the verdict
            if _alive(k):
                os.kill(k, signal.SIGKILL)
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(tmp))
    subprocess.run([sys.executable, "-c", "import sys; from rigcad.cli import main; sys.exit(main())",
                    "profile", "show", "achutha2006"], env=env, capture_output=True, timeout=300, check=True)
    left = sorted(p.name for p in tmp.iterdir() if p.name != "exports")
    assert left == [], f"left in the temp folder after the next run: {left}"


def _kill_once_running(argv: list[str], tmp: Path, running, what: str, step_s: float) -> None:
    """Start rigcad with ``argv``, wait (bounded: 300 s on a loaded machine) until ``running(proc)``
    is truthy, then SIGKILL it and check what it leaves (:func:`_kill_and_check`); never leaves it running."""
    proc = _start(argv, tmp)
    try:
        assert _poll(lambda: running(proc), 300, step_s), what
        _kill_and_check(proc, tmp)
    finally:
        if proc.poll() is None:
            proc.kill()


def test_a_killed_tolerance_run_leaves_no_worker_and_no_temp(tmp_path):
    # running: the loky pool's two workers and its resource tracker
    _kill_once_running(["tolerance", "achutha2006", "--workers", "2", "--samples", "20000", "--rays", "2000",
                        "--no-limits"], tmp_path, lambda proc: len(_children(proc.pid)) >= 3,
                       "the pool never started", 0.2)


def test_a_killed_local_dask_run_leaves_no_worker_and_no_scratch(tmp_path):
    pytest.importorskip("distributed")
    _kill_once_running(["tolerance", "achutha2006", "--workers", "2", "--scheduler", "local-dask", "--samples",
                        "20000", "--rays", "2000", "--no-limits"], tmp_path,
                       lambda proc: list(tmp_path.rglob("dask-scratch-space/worker-*")), "the Dask workers never started",
                       0.2)


def test_a_killed_fab_leaves_no_slicer_temp(tmp_path):
    if shutil.which("prusa-slicer") is None:
        pytest.skip("PrusaSlicer is not installed")
    _kill_once_running(["fab", "achutha2006", "--printer", "prusa_mk3s", "--gcode", "--parts", "beam"], tmp_path,
                       lambda proc: list(tmp_path.rglob("rigcad-slice-*")) or list(tmp_path.rglob("rigcad-keys-*")),
                       "fab never made its slicer folder", 0.01)


def test_the_sweep_spares_live_runs_and_other_files(tmp_path):
    """A run folder is live while its owner file is locked (by whatever process, whatever its pid),
    or, before it has an owner file, while its pid exists; the rest of the temp folder is not
    rigcad's to touch."""
    import fcntl

    def folder(pid, owner):
        d = tmp_path / f"{E.RUN_TEMP_PREFIX}{pid}-{len(list(tmp_path.iterdir()))}"
        (d / "sub").mkdir(parents=True)
        if owner:
            (d / E.RUN_OWNER_FILE).write_text("")
        return d

    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    locked = folder(gone.pid, owner=True)  # a pid that ended, but the lock is held: live
    fd = os.open(locked / E.RUN_OWNER_FILE, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    unlocked = folder(1, owner=True)  # pid 1 lives (a reused pid), but nobody holds the lock: killed
    new_live = folder(1, owner=False)  # no owner file yet, its pid lives: being made right now
    new_dead = folder(gone.pid, owner=False)  # no owner file and its pid is gone: killed while made
    planted = folder(gone.pid, owner=False)
    (planted / E.RUN_OWNER_FILE).symlink_to(tmp_path / "elsewhere")  # not rigcad's: left alone
    mine = tmp_path / "rigcad-run-notes.txt"
    mine.write_text("not a folder")
    try:
        removed = E.sweep_stale_runs(tmp_path)
    finally:
        os.close(fd)
    assert sorted(removed) == sorted([unlocked, new_dead]), removed
    assert locked.exists() and new_live.exists() and planted.exists() and mine.exists()
    assert E.sweep_stale_runs(tmp_path) == [locked]  # its lock released: swept by the next run
