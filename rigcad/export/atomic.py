"""Atomic writes: one file (a temporary file in the target folder, then a rename) or a whole run's
folder (:class:`Staging`: staged beside it, exchanged in one rename, under a lock).

A failed or interrupted run leaves the previous files intact and no half-written one behind.
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import json
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rigcad.errors import ExportError, WriteError


def _temp_beside(path: Path) -> Path:
    """A new, empty, hidden temporary file in ``path``'s folder (created if needed)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
    except OSError as err:
        raise write_error(path, err) from err
    return Path(tmp)


def write_with(path: Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer(tmp_path)`` on a temporary file beside ``path``, then rename it onto ``path``."""
    path = Path(path)
    tmp_path = _temp_beside(path)
    try:
        writer(tmp_path)
        os.chmod(tmp_path, 0o666 & ~_umask())
        os.replace(tmp_path, path)
    except OSError as err:
        raise write_error(path, err) from err
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_bytes(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    return write_with(Path(path), lambda tmp: tmp.write_bytes(data))


def _clean(value: Any) -> Any:
    """JSON has no NaN or inf: write them as null and "inf"."""
    if isinstance(value, float):
        if math.isnan(value):
            return None
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return value
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if hasattr(value, "item"):  # numpy scalar
        return _clean(value.item())
    return value


def json_bytes(data: Any) -> bytes:
    """Deterministic JSON: sorted keys, two-space indent, shortest float repr, NaN as null."""
    return (json.dumps(_clean(data), indent=2, sort_keys=True, allow_nan=False) + "\n").encode()


def write_json(path: Path, data: Any) -> Path:
    """Write ``data`` as deterministic JSON, atomically."""
    return write_bytes(path, json_bytes(data))


class Staging:
    """Stage a run's outputs and publish them together, as one folder.

    Every file is written under a hidden sibling of ``folder`` (``.<name>.new-<token>``); files of
    the previous ``folder`` that the run does not rewrite are carried over (hard links, else copies);
    :meth:`commit` then exchanges the two folders in one atomic ``renameat2(RENAME_EXCHANGE)``
    (Linux; elsewhere two renames) and deletes the old tree. Whatever happens before the exchange
    (an error, a full disk, a kill) leaves ``folder`` as it was; a kill after it leaves the new
    folder in place. Leftovers of a killed run (``.<name>.new-*``, ``.<name>.old-*``, stray
    ``.*.tmp`` files) are removed by the next run, which holds ``lock`` (default
    ``.<name>.lock`` beside ``folder``) for its whole duration: two runs on one folder never
    interleave; the second waits and says who holds the lock.

    ``carry(rel_path) -> bool`` chooses which untouched files of the previous folder are carried
    over (default: all); a run that owns a family of files (say ``*bit/z_*.png``) drops the stale
    ones of an earlier run by refusing them here.

    I/O failures (no space, permission, read-only file system, a file vanished) raise WriteError
    naming the path; the previous outputs are untouched.
    """

    def __init__(self, folder: Path, lock: Path | None = None, say=None,
                 carry: Callable[[Path], bool] | None = None) -> None:
        self.folder = Path(folder)
        self._carry = carry
        self.lock_path = Path(lock) if lock is not None else self.folder.parent / f".{self.folder.name}.lock"
        self._say = say
        self._lock = None
        self._new: Path | None = None
        self._written: list[Path] = []

    # -- the run's lifetime ----------------------------------------------------------------------
    def __enter__(self) -> "Staging":
        self._lock = hold_lock(self.lock_path, self._say)
        try:
            clean_leftovers(self.folder)
            self._new = _guard(self.folder.parent, lambda: Path(tempfile.mkdtemp(
                prefix=f".{self.folder.name}.new-", dir=self._mkdir(self.folder.parent))))
        except BaseException:
            self._release()
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            self.abort()
        finally:
            self._release()

    def _release(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    @staticmethod
    def _mkdir(folder: Path) -> Path:
        folder.mkdir(parents=True, exist_ok=True)
        return folder

    # -- writing ---------------------------------------------------------------------------------
    def temp_path(self, path: Path) -> Path:
        """Where ``path`` (inside ``folder``) is staged: read a staged file back before commit."""
        if self._new is None:
            raise ExportError("Staging is used outside its `with` block")
        path = Path(path)
        try:
            rel = path.relative_to(self.folder)
        except ValueError as err:
            raise ExportError(f"{path} is outside the folder this run publishes ({self.folder})") from err
        return self._new / rel

    def write_with(self, path: Path, writer: Callable[[Path], None]) -> Path:
        """Stage ``path``: ``writer(tmp)`` fills its staged file now; it is published at commit."""
        target = self.temp_path(path)
        _guard(Path(path), lambda: self._mkdir(target.parent))
        _guard(Path(path), lambda: writer(target))
        self._written.append(Path(path))
        return Path(path)

    def write_bytes(self, path: Path, data: bytes) -> Path:
        return self.write_with(path, lambda tmp: tmp.write_bytes(data))

    # -- publishing ------------------------------------------------------------------------------
    def commit(self) -> list[Path]:
        """Carry the untouched files over, exchange the folders, delete the old tree."""
        new = self._new
        if new is None:
            raise ExportError("Staging.commit outside its `with` block")
        if self.folder.is_dir():
            _guard(self.folder, lambda: _carry_over(self.folder, new, self._carry))
        _guard(self.folder, lambda: os.chmod(new, 0o777 & ~_umask()))
        if self.folder.exists():
            _guard(self.folder, lambda: _exchange(new, self.folder))
            old = new.with_name(new.name.replace(".new-", ".old-", 1))
            _guard(self.folder, lambda: os.rename(new, old))  # the old tree, named as such until it is gone
            shutil.rmtree(old, ignore_errors=True)
        else:
            _guard(self.folder, lambda: os.rename(new, self.folder))
        self._new = None
        return list(self._written)

    def abort(self) -> None:
        if self._new is not None:
            shutil.rmtree(self._new, ignore_errors=True)
            self._new = None
        self._written = []


def _guard(path: Path, action):
    """Run ``action``; an OSError becomes a WriteError naming ``path`` and what to do."""
    try:
        return action()
    except OSError as err:
        raise write_error(path, err) from err


def write_error(path: Path, err: OSError) -> "WriteError":
    what = {errno.ENOSPC: "no space left on the device: free some space or choose another --exports folder",
            errno.EDQUOT: "disk quota exceeded: free some space or choose another --exports folder",
            errno.EACCES: "permission denied: choose a folder you can write (--exports)",
            errno.EPERM: "operation not permitted: choose a folder you can write (--exports)",
            errno.EROFS: "read-only file system: choose a writable folder (--exports)",
            errno.ENOENT: "a file or folder vanished while rigcad was writing: is another program deleting it?"}
    hint = what.get(err.errno, f"{err.strerror or err}")
    return WriteError(f"cannot write {err.filename or path}: {hint}; the previous outputs are unchanged")


def _carry_over(old: Path, new: Path, carry: Callable[[Path], bool] | None = None) -> None:
    """Hard-link (or copy) every file of ``old`` that ``new`` does not have yet (and ``carry``
    accepts, given its path relative to ``old``), skipping rigcad's own hidden staging folders,
    locks and temporaries."""
    for dirpath, dirnames, filenames in os.walk(old):
        rel = Path(dirpath).relative_to(old)
        dirnames[:] = [d for d in dirnames if not _ours(d)]
        for name in filenames:
            if _ours(name):
                continue
            target = new / rel / name
            if target.exists() or (carry is not None and not carry(rel / name)):
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.link(Path(dirpath) / name, target)
            except OSError:
                shutil.copy2(Path(dirpath) / name, target)


def _ours(name: str) -> bool:
    """rigcad's hidden working names: staging folders, locks, temporaries."""
    return name.startswith(".") and (".new-" in name or ".old-" in name or name.endswith((".lock", ".tmp")))


def _exchange(a: Path, b: Path) -> None:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); elsewhere b -> a.old, a -> b."""
    if _renameat2 is not None:
        if _renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
            return
        code = ctypes.get_errno()
        if code not in (errno.ENOSYS, errno.EINVAL):  # anything but "not supported here" is real
            raise OSError(code, os.strerror(code), str(b))
    aside = b.with_name(f".{b.name}.old-{os.getpid()}")
    os.rename(b, aside)
    os.rename(a, b)
    os.rename(aside, a)


def _load_renameat2():
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    return fn


_AT_FDCWD, _RENAME_EXCHANGE = -100, 2
_renameat2 = _load_renameat2() if sys.platform.startswith("linux") else None


def _stale_siblings(folder: Path) -> list[Path]:
    """The staged (``.<name>.new-*``) and retired (``.<name>.old-*``) trees beside ``folder``."""
    parent = folder.parent
    if not parent.is_dir():
        return []
    return [*parent.glob(f".{folder.name}.new-*"), *parent.glob(f".{folder.name}.old-*")]


def clean_leftovers(folder: Path) -> list[Path]:
    """Remove what a killed run on ``folder`` left: ``.<name>.new-*`` / ``.old-*`` siblings and
    rigcad's ``.*.tmp`` files inside. Call with the folder's lock held. Returns what was removed."""
    removed = []
    for p in _stale_siblings(folder):
        shutil.rmtree(p, ignore_errors=True)
        removed.append(p)
    if folder.is_dir():
        for p in folder.rglob(".*.tmp"):
            if p.is_file():
                p.unlink(missing_ok=True)
                removed.append(p)
    return removed


def tidy(folder: Path, lock: Path) -> list[Path]:
    """Remove a killed run's leftovers beside ``folder`` when this run publishes nothing (an
    up-to-date folder: a run killed after its exchange, while it deleted the old tree, left the new
    one complete). The lock is taken only when there is something to remove."""
    if not _stale_siblings(Path(folder)):
        return []
    held = hold_lock(lock)
    try:
        return clean_leftovers(folder)
    finally:
        held.release()


def profile_lock(exports: Path, profile: str) -> Path:
    """The one lock of everything written for ``profile`` under the exports root ``exports``
    (stl, design, check and fab runs all hold it): ``exports/.<profile>.lock``."""
    return Path(exports) / f".{profile}.lock"


class _Lock:
    def __init__(self, fd: int) -> None:
        self.fd = fd

    def release(self) -> None:
        try:
            fcntl.flock(self.fd, fcntl.LOCK_UN)
        finally:
            os.close(self.fd)


def hold_lock(path: Path, say=None) -> _Lock:
    """Take the advisory lock ``path`` (fcntl.flock; released by the OS if the process dies). If
    another run holds it, say who (pid, command, since when) and wait for it."""
    path = Path(path)
    _guard(path, lambda: path.parent.mkdir(parents=True, exist_ok=True))
    fd = _guard(path, lambda: os.open(path, os.O_RDWR | os.O_CREAT, 0o666))
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 4096, 0).decode("utf-8", "replace").strip() or "another rigcad run"
        (say or (lambda msg: print(msg, file=sys.stderr, flush=True)))(
            f"rigcad: waiting for {path} (held by {holder})")
        fcntl.flock(fd, fcntl.LOCK_EX)
    except OSError as err:
        os.close(fd)
        raise write_error(path, err) from err
    info = f"pid {os.getpid()}: {' '.join(sys.argv[:3])[:200]}, since {time.strftime('%H:%M:%S')}".encode()
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, info, 0)
    except OSError:
        pass  # who holds the lock is a courtesy to the next run; the lock itself is held
    return _Lock(fd)
