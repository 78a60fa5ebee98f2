"""One runner for every hostile case: ``rigcad.cli.main`` in a forked copy of the test process.

The fork has every rigcad module already imported (see :func:`warm_imports`), so what a case costs
is the command's own work, not import time, and it is isolated as a subprocess is: it has its own
process group, a hard timeout (``kill -9`` of the group), a memory watchdog, its own peak memory
(``os.wait4``'s ``ru_maxrss``, which also covers the children it reaped) and its own CPU clock.

Each case is checked against the same contract (:func:`violations`):
- no traceback: success, or one ``rigcad: error:`` line (argparse's usage refusal, ``usage:`` then
  ``rigcad <command>: error:``, counts as one);
- no hang: the case ends before its timeout;
- no command run: the marker file that every injected command would create is absent;
- nothing outside the exports (and TMPDIR) written (an audit hook in the child sees every open for writing,
  rename, removal, link and mode change made from Python), and the decoy folder and every planted
  link's target keep their bytes, mode, times and link count (this also sees what PrusaSlicer or
  any other child program did);
- no secret (the decoy's text, /etc/passwd's root line, an environment variable's value) in the
  output or in any file written under the exports;
- no process the case started left alive after it ended (by process group and by a token in the
  environment that every descendant inherits);
- a refused input: peak memory under 2 GB and under 1 s of CPU from main()'s entry.
"""

from __future__ import annotations

import atexit
import dataclasses
import hashlib
import io
import json
import os
import re
import signal
import stat
import sys
import tempfile
import threading
import time
import traceback
import uuid
from pathlib import Path

#: Done-when bounds for a refused input.
REFUSAL_CPU_S = 1.0  # CPU seconds from main()'s entry (imports excluded: the fork has them)
REFUSAL_MEMORY_MB = 2048.0  # peak resident memory of the command and the children it reaped
#: The watchdog kills a case whose process group grows past this, so that a runaway input cannot take
#: the machine (24 GB, shared) down; it is above the refusal bound, which is checked separately.
WATCHDOG_MB = 4096.0
#: Resident memory of a fresh interpreter that has imported every module a command imports
#: (warm_imports), measured on Linux/CPython 3.11: 156 MB. A fork starts with the test process's
#: resident pages, which a user's command does not have: a case's peak is counted as its growth
#: above the fork plus this.
FRESH_IMPORT_MB = 160.0
#: The token every process a case starts inherits in its environment, so that leftovers are found.
TOKEN_ENV = "RIGCAD_HOSTILE_CASE"
#: A secret in the environment: it must never appear in an output or a file.
SECRET_ENV = "RIGCAD_HOSTILE_SECRET"
SECRET_VALUE = "env-secret-7f3a9c"
DECOY_SECRET = "DECOY-SECRET-not-for-the-exports"

FAST_PROFILE = """extends: achutha2006
tessellation:
  chord_error: 0.03 mm
  mirror_chord_error: 0.02 mm
  mirror_normal_error: 0.05 rad
"""

#: Lines a command may print on stderr besides its one error line.
_CHATTER = re.compile(r"^(rigcad-event: |note: |warning: |rigcad: waiting for |rigcad: fab: |usage: |  |\s*$)")
_ERROR = re.compile(r"^rigcad(?: [\w-]+)*: error: ")


def warm_imports() -> None:
    """Import every module a command imports lazily, once, before the first fork: a case's clock
    then measures its command, not the import of build123d or Dask."""
    import importlib

    for name in ("rigcad.cli", "rigcad.rig", "rigcad.fab.stage", "rigcad.fab.slicer", "rigcad.fab.printers",
                 "rigcad.check.raycheck", "rigcad.check.tolerances", "rigcad.check.trace3d",
                 "rigcad.tolerance.montecarlo", "rigcad.tolerance.limits", "rigcad.tolerance.report",
                 "rigcad.tolerance.sweep", "rigcad.basis.projector", "rigcad.basis.acquire", "rigcad.optimize.run",
                 "rigcad.manual.document", "rigcad.manual.view", "rigcad.export.build", "rigcad.export.design",
                 "rigcad.engine", "rigcad.plots", "tqdm", "matplotlib.pyplot", "joblib", "dask.distributed"):
        try:
            importlib.import_module(name)
        except ImportError:  # an optional extra (Dask) that is not installed: its cases refuse in one line
            pass


# -- the sandbox -----------------------------------------------------------------------------------

class Sandbox:
    """A folder holding everything a case may touch: ``work/`` (the working directory, with the fast
    profile), ``exports/``, ``tmp/`` (TMPDIR) and, outside the exports, ``decoy/``: files that no case
    may change, read into an output or hard-link, and the targets of every planted link."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root).resolve()
        self.work = self.root / "work"
        self.exports = self.root / "exports"
        self.tmp = self.root / "tmp"
        self.decoy = self.root / "decoy"
        self.marker = self.root / "MARKER-a-command-ran"
        for d in (self.work, self.exports, self.tmp, self.decoy / "folder", self.root / "cases"):
            d.mkdir(parents=True, exist_ok=True)
        (self.decoy / "precious.txt").write_text(f"{DECOY_SECRET}\n")
        (self.decoy / "precious.yaml").write_text(f"{DECOY_SECRET}: 1\n")
        (self.decoy / "folder" / "inside.txt").write_text(f"{DECOY_SECRET} inside\n")
        (self.work / "fast.yaml").write_text(FAST_PROFILE)
        self.profile = "fast"
        self.guarded: list[Path] = []  # files in the exports that are not the case's to change
        self.rebase()

    def rebase(self) -> None:
        """Take the decoy's state as it is now (after planting hard links to it, or after a case
        whose change was already reported); files now in the exports are the planted ones."""
        self._before = self.snapshot()
        self._planted = {str(p): p.lstat().st_ino for p in self.exports.rglob("*")}

    def injected(self) -> list[str]:
        """Commands in the forms a value could smuggle one: each creates the marker if it ever runs."""
        m = self.marker
        return [f"/bin/sh -c 'touch {m}'", f"$(touch {m})", f"`touch {m}`", f"x; touch {m}", f"x && touch {m} #",
                f"x\ntouch {m}"]

    def guard(self, *paths: Path) -> None:
        """Hold files or folders in the exports to the decoy's rule: no case may change them."""
        self.guarded += [Path(p) for p in paths]
        self.rebase()

    def snapshot(self) -> dict[str, tuple]:
        """Every decoy (and guarded) file and folder: type, mode, size, times, link count, digest."""
        snap = {}
        for top in (self.decoy, *self.guarded):
            if not top.exists():
                snap[str(top)] = ("missing",)
                continue
            snap.update(self._walk(top))
        return snap

    @staticmethod
    def _entry(p: Path) -> tuple:
        st = p.lstat()
        digest = hashlib.sha256(p.read_bytes()).hexdigest() if stat.S_ISREG(st.st_mode) else ""
        return stat.S_IFMT(st.st_mode), st.st_mode & 0o7777, st.st_size, st.st_mtime_ns, st.st_nlink, digest

    @classmethod
    def _walk(cls, top: Path) -> dict[str, tuple]:
        if top.is_symlink() or not top.is_dir():
            return {str(top): cls._entry(top)}
        snap = {}
        for dirpath, dirnames, filenames in os.walk(top):
            for name in [*dirnames, *filenames, ""]:
                p = Path(dirpath) / name if name else Path(dirpath)
                snap[str(p)] = cls._entry(p)
        return snap

    def decoy_changes(self) -> list[str]:
        now = self.snapshot()
        changed = [f"{p} {'removed' if p not in now or now[p] == ('missing',) else 'changed'}"
                   for p in self._before if now.get(p) != self._before[p]]
        return changed + [f"{p} created" for p in now if p not in self._before]

    def secrets_in_exports(self) -> list[str]:
        """Files under the exports (links not followed) holding a secret."""
        found = []
        for dirpath, _, filenames in os.walk(self.exports):
            for name in filenames:
                p = Path(dirpath) / name
                try:
                    st = p.lstat()
                    if not stat.S_ISREG(st.st_mode) or st.st_size > 20_000_000 or self._planted.get(str(p)) == st.st_ino:
                        continue  # a planted hard link to a decoy file holds its text: only a new copy is a leak
                    data = p.read_bytes()
                except OSError:
                    continue
                if any(s.encode() in data for s in (DECOY_SECRET, SECRET_VALUE, "root:x:0:0")):
                    found.append(str(p))
        return found


# -- watching writes in the child ------------------------------------------------------------------

_watch: list | None = None  # the child's record of mutating calls, None when not watching
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND
#: audit event -> positions of the paths it changes and of its dir_fd arguments
_MUTATING = {"os.rename": ((0, 1), (2, 3)), "os.remove": ((0,), (1,)), "os.rmdir": ((0,), (1,)),
             "os.mkdir": ((0,), (2,)), "os.link": ((1,), (2, 3)), "os.symlink": ((1,), (2,)),
             "os.truncate": ((0,), ()), "os.chmod": ((0,), (2,)), "os.chown": ((0,), (3,)),
             "os.utime": ((0,), (3,)), "shutil.rmtree": ((0,), (1,)), "shutil.copyfile": ((1,), ()),
             "shutil.move": ((1,), ())}


def _audit(event: str, args) -> None:
    if _watch is None:
        return
    if event == "open":
        path, mode, flags = args
        writes = (isinstance(mode, str) and any(c in mode for c in "wax+")) or (
            mode is None and isinstance(flags, int) and flags & _WRITE_FLAGS)
        if writes and isinstance(path, (str, bytes, os.PathLike)):
            _watch.append((event, os.path.abspath(os.fsdecode(path))))
        return
    spec = _MUTATING.get(event)
    if spec is None:
        return
    paths, dirfds = spec
    if any(i < len(args) and args[i] not in (None, -1, -100) for i in dirfds):
        return  # relative to a directory descriptor (rmtree's inner calls): the top call was recorded
    for i in paths:
        if i < len(args) and isinstance(args[i], (str, bytes, os.PathLike)):
            _watch.append((event, os.path.abspath(os.fsdecode(args[i]))))


sys.addaudithook(_audit)


def _allowed_outside() -> tuple[tuple[str, ...], str]:
    """Places outside the sandbox a command may write: the null device, shared memory (joblib's
    semaphores), matplotlib's font cache; and rigcad's own ``__pycache__`` folders (numba caches the
    kernels it compiles beside their module), returned apart."""
    import rigcad

    package = os.path.dirname(rigcad.__file__)
    places = ["/dev/null", "/dev/shm/"]
    try:
        import matplotlib

        places += [matplotlib.get_cachedir() + "/", matplotlib.get_configdir() + "/"]
    except Exception:  # noqa: BLE001 - matplotlib missing or unconfigurable: nothing to allow
        pass
    return tuple(places), package


# -- the child -------------------------------------------------------------------------------------

def _reset_inherited_state() -> None:
    """What the fork inherited and must not share with the test process: signal handlers and timers
    (pytest-timeout's), joblib's reusable executor (the parent's workers are not this process's)."""
    signal.setitimer(signal.ITIMER_REAL, 0)
    for sig in (signal.SIGALRM, signal.SIGTERM, signal.SIGUSR1, signal.SIGCHLD):
        signal.signal(sig, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    loky = sys.modules.get("joblib.externals.loky.reusable_executor")
    if loky is not None:
        loky._executor = None
        loky._executor_kwargs = None


def _child(argv: list[str], sandbox: Sandbox, env: dict[str, str], files: dict[str, Path]) -> None:
    global _watch
    code = 70
    try:
        os.setpgid(0, 0)
        _reset_inherited_state()
        out = os.open(files["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        err = os.open(files["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.dup2(out, 1)
        os.dup2(err, 2)
        sys.stdin = open(0, closefd=False)
        sys.stdout = io.TextIOWrapper(open(1, "wb", buffering=0, closefd=False), write_through=True)
        sys.stderr = io.TextIOWrapper(open(2, "wb", buffering=0, closefd=False), write_through=True)
        os.environ.update(env)
        sys.dont_write_bytecode = True  # a module imported late writes no .pyc into the source tree
        tempfile.tempdir = None  # re-read TMPDIR
        os.chdir(sandbox.work)
        from rigcad.cli import main

        atexit._clear()  # the test process's exit handlers are not this command's
        result = {"escaped": None}
        _watch = []
        t_cpu, t_wall = time.process_time(), time.perf_counter()
        try:
            rc = main(argv)
        except SystemExit as exc:  # argparse's refusals and --help
            rc = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except BaseException as exc:  # noqa: BLE001 - what reaches the user as a traceback
            traceback.print_exc()
            result["escaped"] = type(exc).__name__
            rc = 1
        result.update(rc=rc, cpu_s=time.process_time() - t_cpu, wall_s=time.perf_counter() - t_wall)
        threading._shutdown()  # what the interpreter does on exit: join the threads, run the exit handlers
        atexit._run_exitfuncs()
        writes, _watch = _watch, None
        result["writes"] = sorted({p for _, p in writes})
        sys.stdout.flush()
        sys.stderr.flush()
        files["result"].write_text(json.dumps(result))
        code = 0
    except BaseException:  # noqa: BLE001 - the harness itself failed: say so on the case's stderr
        try:
            traceback.print_exc()
            sys.stderr.flush()
        finally:
            pass
    finally:
        os._exit(code)


# -- the parent ------------------------------------------------------------------------------------

@dataclasses.dataclass
class Outcome:
    argv: list[str]
    rc: int | None = None  # the command's exit code; None when the harness killed it
    stdout: str = ""
    stderr: str = ""
    cpu_s: float | None = None  # CPU seconds of the command (all its threads) from main()'s entry
    wall_s: float = 0.0  # wall seconds from the fork
    maxrss_mb: float = 0.0  # peak resident memory of the command and the children it reaped
    killed: str | None = None  # "timeout", "memory" or the reason the test killed it
    escaped: str | None = None  # the exception that escaped main()
    writes: list[str] = dataclasses.field(default_factory=list)
    leaked: list[str] = dataclasses.field(default_factory=list)

    @property
    def refused(self) -> bool:
        return self.rc not in (0, None)

    def describe(self) -> str:
        tail = "\n".join(self.stderr.strip().splitlines()[-6:])
        rc = self.killed and f"killed ({self.killed})" or f"exit {self.rc}"
        return (f"rigcad {' '.join(repr(a) if (not a or ' ' in a) else a for a in self.argv)}: {rc}, "
                f"cpu {self.cpu_s if self.cpu_s is None else round(self.cpu_s, 2)} s, wall {self.wall_s:.1f} s, "
                f"peak {self.maxrss_mb:.0f} MB; stderr: {tail[-1500:]!r}")


def _pids() -> list[int]:
    return [int(d) for d in os.listdir("/proc") if d.isdigit()]


def _status(pid: int) -> dict[str, str]:
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return {}
    return dict(line.split(":", 1) for line in text.splitlines() if ":" in line)


def _rss_mb(pid: int) -> float:
    value = _status(pid).get("VmRSS", "0 kB").split()
    return float(value[0]) / 1024 if value else 0.0


def _family(pgid: int, token: str) -> list[int]:
    """Live processes of a case: in its process group, or carrying its token in their environment."""
    found = []
    for pid in _pids():
        if pid == os.getpid():
            continue
        try:
            if os.getpgid(pid) == pgid:
                found.append(pid)
                continue
            if token.encode() in Path(f"/proc/{pid}/environ").read_bytes():
                found.append(pid)
        except (OSError, ProcessLookupError):
            continue
    return [p for p in found if _status(p).get("State", "").strip()[:1] not in ("Z", "")]


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()[:160]
    except OSError:
        return "?"


class Child:
    """A running case: ``rigcad <argv>`` in a fork, in its own process group."""

    def __init__(self, argv: list[str], sandbox: Sandbox, env: dict[str, str] | None = None, name: str = "") -> None:
        self.argv = list(argv)
        self.sandbox = sandbox
        self.token = uuid.uuid4().hex
        folder = Path(tempfile.mkdtemp(prefix=f"case-{name}-", dir=sandbox.root / "cases"))
        self.files = {k: folder / k for k in ("stdout", "stderr", "result")}
        child_env = {TOKEN_ENV: self.token, SECRET_ENV: SECRET_VALUE, "TMPDIR": str(sandbox.tmp),
                     "PYTHONWARNINGS": "ignore", **(env or {})}
        sys.stdout.flush()
        sys.stderr.flush()
        self.inherited_mb = _rss_mb(os.getpid())
        self.t0 = time.perf_counter()
        pid = os.fork()
        if pid == 0:
            _child(self.argv, sandbox, child_env, self.files)
        self.pid = pid
        try:
            os.setpgid(pid, pid)  # also here: the group exists before the parent signals it
        except OSError:
            pass
        self.outcome = Outcome(self.argv)
        self._status: int | None = None
        self._peak_seen = 0.0

    # -- signals ---------------------------------------------------------------------------------
    def signal_group(self, sig: int) -> None:
        for pid in _family(self.pid, self.token) or [self.pid]:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass

    def kill(self, reason: str) -> None:
        """kill -9 the case's process itself (its children are left to die with it, or not)."""
        self.outcome.killed = reason
        try:
            os.kill(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def stderr_text(self) -> str:
        try:
            return self.files["stderr"].read_text(errors="replace")
        except OSError:
            return ""

    def events(self) -> list[str]:
        return [ln.split(": ", 1)[1].strip() for ln in self.stderr_text().splitlines() if ln.startswith("rigcad-event: ")]

    # -- waiting ---------------------------------------------------------------------------------
    def poll(self) -> bool:
        """True once the case's process has ended (reaped)."""
        if self._status is not None:
            return True
        pid, status, usage = os.wait4(self.pid, os.WNOHANG)
        if pid == 0:
            self._peak_seen = max(self._peak_seen, _rss_mb(self.pid))
            return False
        self._status = status
        self.outcome.wall_s = time.perf_counter() - self.t0
        self.outcome.maxrss_mb = self._command_mb(max(usage.ru_maxrss / 1024, self._peak_seen))
        return True

    def _command_mb(self, peak_mb: float) -> float:
        """The case's peak as a fresh `rigcad` process would have it (FRESH_IMPORT_MB)."""
        return max(peak_mb - self.inherited_mb, 0.0) + FRESH_IMPORT_MB

    def wait_until(self, predicate, timeout: float, step: float = 0.02) -> bool:
        """Poll until ``predicate()`` holds (True) or the case ends or ``timeout`` passes (False)."""
        end = time.perf_counter() + timeout
        while time.perf_counter() < end:
            if predicate():
                return True
            if self.poll():
                return bool(predicate())
            time.sleep(step)
        return False

    def finish(self, timeout: float, grace: float = 10.0) -> Outcome:
        """Wait for the case to end (kill -9 of its group after ``timeout`` s: a hang), then collect
        its outcome and the processes it left behind (after ``grace`` s for them to go)."""
        # from the fork; for a case the test already killed, from now (it only has to be reaped)
        end = (time.perf_counter() if self.outcome.killed else self.t0) + timeout
        last_scan = 0.0
        while not self.poll():
            now = time.perf_counter()
            if now > end:
                self.outcome.killed = self.outcome.killed or "timeout"
                self.signal_group(signal.SIGKILL)
                os.waitpid(self.pid, 0)
                self._status = 0
                self.outcome.wall_s = now - self.t0
                break
            if now - last_scan > 0.5:  # the whole group's memory, twice a second
                last_scan = now
                group = sum(_rss_mb(p) for p in _family(self.pid, self.token))
                self._peak_seen = max(self._peak_seen, group)
                if group - self.inherited_mb > WATCHDOG_MB:
                    self.outcome.killed = "memory"
                    self.signal_group(signal.SIGKILL)
            time.sleep(0.02)
        o = self.outcome
        o.maxrss_mb = max(o.maxrss_mb, self._command_mb(self._peak_seen))
        o.stdout = self.files["stdout"].read_text(errors="replace") if self.files["stdout"].exists() else ""
        o.stderr = self.stderr_text()
        if self.files["result"].exists() and not o.killed:
            r = json.loads(self.files["result"].read_text())
            o.rc, o.cpu_s, o.escaped, o.writes = r["rc"], r["cpu_s"], r["escaped"], r["writes"]
        elif not o.killed:
            o.escaped = "the harness's child died"
        end = time.perf_counter() + grace
        left = _family(self.pid, self.token)
        while left and time.perf_counter() < end:
            time.sleep(0.1)
            left = _family(self.pid, self.token)
        o.leaked = [f"{p} {_cmdline(p)}" for p in left]
        for p in left:  # processes this case started: end them so the next case starts clean
            try:
                os.kill(p, signal.SIGKILL)
            except ProcessLookupError:
                pass
        return o


def run(argv: list[str], sandbox: Sandbox, timeout: float = 60.0, env: dict[str, str] | None = None,
        name: str = "") -> Outcome:
    """Run one case to its end."""
    return Child(argv, sandbox, env, name).finish(timeout)


# -- the contract ----------------------------------------------------------------------------------

def violations(o: Outcome, sandbox: Sandbox, *, expect_refusal: bool = False, timed: bool = True,
               leak_ok: bool = False) -> list[str]:
    """Everything in ``o`` that breaks the contract (empty: the case passed). ``timed=False`` for a
    refusal that waits on something outside rigcad by design (a network handshake's bound)."""
    v = []
    if o.killed == "timeout":
        v.append(f"hang: still running after {o.wall_s:.0f} s, killed")
    elif o.killed == "memory":
        v.append(f"runaway memory: the process group passed {WATCHDOG_MB:.0f} MB, killed")
    text = o.stdout + o.stderr
    if "Traceback (most recent call last)" in text or o.escaped:
        v.append(f"traceback ({o.escaped or 'printed'})")
    if o.killed is None and o.rc != 0 and not o.escaped:
        lines = [ln for ln in o.stderr.splitlines() if ln.strip()]
        errors = [ln for ln in lines if _ERROR.match(ln)]
        other = [ln for ln in lines if not _ERROR.match(ln) and not _CHATTER.match(ln)]
        if len(errors) != 1 or other:
            v.append(f"refusal is not one 'rigcad: error:' line: {len(errors)} error line(s), other lines {other[:3]}")
    if o.killed is None and o.rc == 0 and expect_refusal:
        v.append("accepted a value that has no valid reading")
    if sandbox.marker.exists():
        v.append("an injected command ran (the marker file exists)")
        sandbox.marker.unlink()
    allowed, package = _allowed_outside()
    roots = [str(sandbox.exports), str(sandbox.tmp)]
    if "--exports" in o.argv[:-1] and o.argv[o.argv.index("--exports") + 1]:  # the root the user named
        given = sandbox.work / o.argv[o.argv.index("--exports") + 1]
        roots += [os.path.abspath(given), os.path.realpath(given)]
    outside = [p for p in o.writes if not any(p == r or p.startswith(r + os.sep) for r in roots)
               and not p.startswith(allowed) and not (p.startswith(package) and "__pycache__" in p)]
    if outside:
        v.append(f"wrote outside the exports: {outside[:5]}")
    changed = sandbox.decoy_changes()
    if changed:
        v.append(f"changed files outside the exports: {changed[:5]}")
    if any(s in text for s in (DECOY_SECRET, SECRET_VALUE, "root:x:0:0")):
        v.append("quoted a secret in its output")
    leaked = sandbox.secrets_in_exports()
    if leaked:
        v.append(f"copied a secret into the exports: {leaked[:3]}")
    if o.leaked and not leak_ok:
        v.append(f"left processes running: {o.leaked[:3]}")
    if o.refused and o.killed is None:
        if o.maxrss_mb >= REFUSAL_MEMORY_MB:
            v.append(f"refused after a peak of {o.maxrss_mb:.0f} MB (bound {REFUSAL_MEMORY_MB:.0f} MB)")
        if timed and o.cpu_s is not None and o.cpu_s >= REFUSAL_CPU_S:
            v.append(f"refused after {o.cpu_s:.2f} s of CPU (bound {REFUSAL_CPU_S} s from main()'s entry)")
    return v
