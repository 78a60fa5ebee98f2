"""Atomic writes: one file (a temporary file in the target folder, then a rename) or a whole run's
folder (:class:`Staging`: staged beside it, exchanged in one rename, under a lock).

A failed or interrupted run leaves the previous files intact and no half-written one behind.
Publication never reaches through a link: a lock that is not a plain file rigcad made, or a
published folder (or a folder between it and the exports root) that is a symbolic link, is refused
with one line, and nothing is written. A result folder records the profile it was made from
(``<name>.made_from.json`` beside it); publishing a profile's whole folder removes the results
of another profile (:func:`stale_results`).
"""

from __future__ import annotations

import contextlib
import contextvars
import ctypes
import errno
import fcntl
import glob
import json
import math
import os
import re
import shutil
import stat
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


#: What a run publishing a given folder stages last, just before its exchange: (absolute folder,
#: hook(staging)) pairs set by :func:`before_commit`.
_BEFORE_COMMIT: contextvars.ContextVar[tuple] = contextvars.ContextVar("before_commit", default=())


@contextlib.contextmanager
def before_commit(folder: Path, hook: Callable[["Staging"], None]):
    """Within the block, every :class:`Staging` of this thread publishing ``folder`` calls
    ``hook(staging)`` at :meth:`Staging.commit`, once its files are staged and before the exchange,
    so that what the hook stages is published with them, under the same lock (a stage's published
    record, rigcad.export.reuse.recording, whichever writer publishes the folder)."""
    token = _BEFORE_COMMIT.set((*_BEFORE_COMMIT.get(), (Path(folder).absolute(), hook)))
    try:
        yield
    finally:
        _BEFORE_COMMIT.reset(token)


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

    ``made_from`` (a result folder: check/, fab/<printer>/, ...): the SHA-256 of the profile the
    results were made from (export.manifest.profile_digest), recorded beside the folder at commit;
    the previous folder's files are carried over only when it records the same profile.
    ``results_of`` (a whole ``exports/<profile>`` folder): the SHA-256 of the profile it is now built
    from; result folders inside that record another profile, or none, are not carried over
    (:attr:`stale`, reported on ``say`` at commit and by :meth:`stale_report`).

    The folder, and every folder between the lock's folder (the exports root) and it, must be a
    real folder, not a symbolic link; the staging folder must stay the one this run made.

    I/O failures (no space, permission, read-only file system, a file vanished) raise WriteError
    naming the path; the previous outputs are untouched.
    """

    def __init__(self, folder: Path, lock: Path | None = None, say=None,
                 carry: Callable[[Path], bool] | None = None, made_from: str | None = None,
                 results_of: str | None = None) -> None:
        self.folder = Path(folder)
        self._carry = carry
        self.lock_path = Path(lock) if lock is not None else self.folder.parent / f".{self.folder.name}.lock"
        self._say = say
        self._lock = None
        self._new: Path | None = None
        self._new_id: tuple[int, int] | None = None
        self._written: list[Path] = []
        self._made_from = made_from
        self._results_of = results_of
        #: result folders (relative to ``folder``) made from another profile than ``results_of``, each
        #: with the profile SHA-256 it records (None: no record); they are not carried over
        self.stale: dict[Path, str | None] = {}
        self._carry_previous = True

    # -- the run's lifetime ----------------------------------------------------------------------
    def __enter__(self) -> "Staging":
        self._lock = hold_lock(self.lock_path, self._say)
        try:
            refuse_links(self.folder, self._root())
            clean_leftovers(self.folder)
            if self._results_of is not None:
                self.stale = stale_results(self.folder, self._results_of)
            if self._made_from is not None:  # a result folder: carry only what the same profile made
                self._carry_previous = read_made_from(self.folder) == self._made_from
            self._new = _guard(self.folder.parent, lambda: Path(tempfile.mkdtemp(
                prefix=f".{self.folder.name}.new-", dir=self._mkdir(self.folder.parent))))
            st = os.lstat(self._new)
            self._new_id = (st.st_dev, st.st_ino)
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

    def _root(self) -> Path:
        """The exports root: the lock's folder when ``folder`` lies under it, else ``folder``'s parent."""
        root = self.lock_path.parent
        try:
            self.folder.relative_to(root)
        except ValueError:
            return self.folder.parent
        return root

    def _staged(self) -> Path:
        """The staging folder, checked to be the very folder this run made: one that vanished or was
        replaced (another program deleting it, a link put in its place) is an error, never re-made."""
        new = self._new
        if new is None:
            raise ExportError("Staging is used outside its `with` block")
        try:
            st = os.lstat(new)
        except FileNotFoundError:
            st = None
        if st is None or not stat.S_ISDIR(st.st_mode) or (st.st_dev, st.st_ino) != self._new_id:
            raise WriteError(f"the staging folder {new} vanished or was replaced while rigcad was writing (is "
                             f"another program deleting it?): nothing was published; the previous outputs are unchanged")
        return new

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
        _guard(Path(path), lambda: _mkdirs_below(self._staged(), target.parent))
        _guard(Path(path), lambda: writer(target))
        self._written.append(Path(path))
        return Path(path)

    def write_bytes(self, path: Path, data: bytes) -> Path:
        return self.write_with(path, lambda tmp: tmp.write_bytes(data))

    # -- publishing ------------------------------------------------------------------------------
    def commit(self) -> list[Path]:
        """Carry the untouched files over, exchange the folders, delete the old tree."""
        new = self._staged()
        for folder, hook in _BEFORE_COMMIT.get():
            if folder == self.folder.absolute():
                hook(self)
        refuse_links(self.folder, self._root())  # the folder may have been swapped for a link meanwhile
        if self.folder.is_dir() and self._carry_previous:
            _guard(self.folder, lambda: _carry_over(self.folder, new, self._carries))
        _guard(self.folder, lambda: os.chmod(new, 0o777 & ~_umask()))
        stamp = made_from_path(self.folder)
        if self._made_from is not None:  # no stamp while the folders swap: a kill leaves the results unvouched for
            _guard(stamp, lambda: _unlink_plain(stamp))
        if self.folder.exists():
            _guard(self.folder, lambda: _exchange(new, self.folder))
            old = new.with_name(new.name.replace(".new-", ".old-", 1))
            _guard(self.folder, lambda: os.rename(new, old))  # the old tree, named as such until it is gone
            shutil.rmtree(old, ignore_errors=True)
        else:
            _guard(self.folder, lambda: os.rename(new, self.folder))
        self._new = None
        if self._made_from is not None:
            try:
                write_bytes(stamp, json_bytes({"profile_sha256": self._made_from, "results": self.folder.name}))
            except WriteError as err:  # the results are published; unvouched for, the next build removes them
                self._tell(f"rigcad: warning: {err}; {self.folder} will count as made from another profile")
        for rel, recorded in sorted(self.stale.items()):
            was = f"made from profile sha256 {recorded[:12]}" if recorded else "no record of the profile it was made from"
            self._tell(f"rigcad: removed {rel.as_posix()}/ ({was}; the profile is now {self._results_of[:12]}): "
                       f"run `rigcad {rel.parts[0]}` again for this profile")
        return list(self._written)

    def stale_report(self) -> list[dict]:
        """:attr:`stale` as JSON rows (for a manifest): folder and the profile SHA-256 it recorded."""
        return [{"folder": rel.as_posix(), "made_from_profile_sha256": recorded}
                for rel, recorded in sorted(self.stale.items())]

    def _carries(self, rel: Path) -> bool:
        if self.stale and (_result_unit(rel) in self.stale or _stamp_unit(rel) in self.stale):
            return False
        return self._carry is None or self._carry(rel)

    def _tell(self, message: str) -> None:
        (self._say or (lambda msg: print(msg, file=sys.stderr, flush=True)))(message)

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
    """Hard-link (or copy) every plain file of ``old`` that ``new`` does not have yet (and ``carry``
    accepts, given its path relative to ``old``), skipping rigcad's own hidden staging folders,
    locks and temporaries. Symbolic links (to files or folders) and special files are not carried:
    a link's target is never read, linked or copied into the exports."""
    for dirpath, dirnames, filenames in os.walk(old):  # os.walk does not descend into linked folders
        rel = Path(dirpath).relative_to(old)
        dirnames[:] = [d for d in dirnames if not _ours(d)]
        for name in filenames:
            if _ours(name):
                continue
            source = Path(dirpath) / name
            if not stat.S_ISREG(os.lstat(source).st_mode):
                continue
            target = new / rel / name
            if os.path.lexists(target) or (carry is not None and not carry(rel / name)):
                continue
            _mkdirs_below(new, target.parent)
            try:
                os.link(source, target, follow_symlinks=False)
            except OSError:
                shutil.copy2(source, target, follow_symlinks=False)


def refuse_links(folder: Path, root: Path) -> None:
    """Refuse to publish ``folder`` when it, or a folder between the exports root ``root`` and it, is
    a symbolic link or not a folder: publishing would write through the link into whatever it names
    (and leave the link behind as an ``.old-`` tree). Nothing is touched; the link's target least of all."""
    folder, root = Path(folder), Path(root)
    try:
        rel = folder.relative_to(root)
        chain = [root.joinpath(*rel.parts[:i + 1]) for i in range(len(rel.parts))]
    except ValueError:
        chain = [folder]
    for path in chain:
        if path.is_symlink():
            try:
                target = f" (to {os.readlink(path)})"
            except OSError:
                target = ""
            raise ExportError(f"{path} is a symbolic link{target}: rigcad publishes only into a real folder and "
                              "never writes through a link; remove the link (what it names is left as it is) or "
                              "give --exports a real folder; nothing was written")
        if os.path.lexists(path) and not path.is_dir():
            raise ExportError(f"{path} is not a folder: rigcad publishes its outputs there; move it away or give "
                              "--exports another folder; nothing was written")


def _mkdirs_below(top: Path, folder: Path) -> None:
    """Make ``folder`` and its parents up to ``top`` (which must exist), never through a link."""
    rel = Path(folder).relative_to(top)
    path = Path(top)
    for part in rel.parts:
        path = path / part
        try:
            os.mkdir(path)
        except FileExistsError:
            if not stat.S_ISDIR(os.lstat(path).st_mode):
                raise ExportError(f"{path} is not a folder rigcad made (a link or a file stands in its place): "
                                  "nothing was published; the previous outputs are unchanged") from None


def _unlink_plain(path: Path) -> None:
    """Remove ``path`` (a file or a link, never what a link names) if it is there."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


# -- which profile a result was made from ----------------------------------------------------------
#: Result folders under ``exports/<profile>/`` and how deep a result lies (fab/<printer>/ is one run's
#: result). Each records the profile it was made from in ``<name>.made_from.json`` beside it.
RESULT_FOLDERS = {"check": 1, "basis": 1, "tolerance": 1, "view": 1, "fab": 2, "manual": 2}
MADE_FROM_SUFFIX = ".made_from.json"


def made_from_path(folder: Path) -> Path:
    """Where the result folder ``folder`` records the profile it was made from: beside it, so that
    the folder holds exactly the results (and a kill while it is published leaves no record, which
    counts as another profile's)."""
    folder = Path(folder)
    return folder.parent / f"{folder.name}{MADE_FROM_SUFFIX}"


def read_made_from(folder: Path) -> str | None:
    """The profile SHA-256 the result folder ``folder`` records, or None (no record, not a plain
    file, unreadable)."""
    path = made_from_path(folder)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        data = os.read(fd, 4096)
    except OSError:
        return None
    finally:
        os.close(fd)
    from rigcad.export.readback import parse_json

    try:  # read as data: a nesting bomb or a duplicated key is no record
        value = parse_json(data, str(path)).get("profile_sha256")
    except (ExportError, AttributeError):
        return None
    return value if isinstance(value, str) and re.fullmatch(r"[0-9a-f]{64}", value) else None


def _result_unit(rel: Path) -> Path | None:
    """The result folder (relative to ``exports/<profile>``) the file ``rel`` belongs to, if any."""
    depth = RESULT_FOLDERS.get(rel.parts[0]) if len(rel.parts) > 1 else None
    if depth is None or len(rel.parts) <= depth:
        return None
    return Path(*rel.parts[:depth])


def _stamp_unit(rel: Path) -> Path | None:
    """The result folder whose record ``rel`` is, if it is one."""
    if not rel.name.endswith(MADE_FROM_SUFFIX):
        return None
    return rel.with_name(rel.name[:-len(MADE_FROM_SUFFIX)])


def stale_results(folder: Path, profile_sha256: str) -> dict[Path, str | None]:
    """The result folders under ``folder`` (``exports/<profile>``) not made from the profile whose
    SHA-256 is ``profile_sha256``: result folder (relative) -> the SHA-256 it records (None: none)."""
    folder = Path(folder)
    stale: dict[Path, str | None] = {}
    for top, depth in RESULT_FOLDERS.items():
        base = folder / top
        if base.is_symlink() or not base.is_dir():
            continue
        units = [base] if depth == 1 else [p for p in sorted(base.iterdir())
                                          if p.is_dir() and not p.is_symlink() and not _ours(p.name)]
        for unit in units:
            recorded = read_made_from(unit)
            if recorded != profile_sha256:
                stale[unit.relative_to(folder)] = recorded
    return stale


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
    name = glob.escape(folder.name)  # a name with [ ] * ? matches itself only, never another's trees
    return [*parent.glob(f".{name}.new-*"), *parent.glob(f".{name}.old-*")]


def clean_leftovers(folder: Path) -> list[Path]:
    """Remove what a killed run on ``folder`` left: ``.<name>.new-*`` / ``.old-*`` siblings and
    rigcad's ``.*.tmp`` files inside. Call with the folder's lock held. Returns what was removed."""
    removed = []
    for p in _stale_siblings(folder):
        if p.is_symlink():  # not a tree rigcad made: the link goes, what it names stays
            _unlink_plain(p)
        else:
            shutil.rmtree(p, ignore_errors=True)
        removed.append(p)
    if folder.is_dir() and not folder.is_symlink():
        for dirpath, dirnames, filenames in os.walk(folder):  # not into linked folders
            for name in filenames:
                p = Path(dirpath) / name
                if name.startswith(".") and name.endswith(".tmp") and stat.S_ISREG(os.lstat(p).st_mode):
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
        refuse_links(Path(folder), Path(lock).parent)
        return clean_leftovers(folder)
    finally:
        held.release()


def profile_lock(exports: Path, profile: str) -> Path:
    """The one lock of everything written for ``profile`` under the exports root ``exports``
    (stl, design, check and fab runs all hold it): ``exports/.<profile>.lock``."""
    return Path(exports) / f".{profile}.lock"


def check_exports(exports: Path, profile: str, folder: str | None = None) -> None:
    """Refuse at once, before any work, what publishing into ``exports/<profile>[/<folder>]`` would
    refuse at its end: a symbolic link on the way there, a lock file rigcad did not make. Creates
    nothing; the publication checks again under its lock."""
    exports = check_exports_root(exports)
    target = exports / profile if folder is None else exports / profile / folder
    refuse_links(target, exports)
    lock = profile_lock(exports, profile)
    if os.path.lexists(lock):
        os.close(_open_lock(lock))
    else:
        _refuse_unwritable(lock.parent)


def check_exports_root(exports: Path) -> Path:
    """Refuse now an exports root rigcad could not publish into: a file, not a folder; a name the
    system refuses; a folder this user cannot write (each would fail only after the work). The
    root itself, as a Path."""
    exports = Path(exports)
    try:
        os.lstat(exports)  # a name too long, a file on the way: refused here by the OSError, as main() says it
    except FileNotFoundError:
        pass
    if os.path.exists(exports) and not exports.is_dir():
        raise ExportError(f"--exports {exports} is not a folder: rigcad writes its outputs into a folder there; "
                          "give --exports a folder (it is made if missing); nothing was written")
    _refuse_unwritable(exports)
    return exports


def _refuse_unwritable(folder: Path) -> None:
    """Refuse now when the nearest existing folder on the way to ``folder`` cannot take a new entry
    (the permission bits, as ``access(2)`` judges them for this user): publishing would fail there
    only after the work."""
    near = Path(os.path.abspath(folder))
    while not os.path.lexists(near) and near != near.parent:
        near = near.parent
    if near.is_dir() and not os.access(near, os.W_OK | os.X_OK):
        raise WriteError(f"cannot write {near}: permission denied: choose a folder you can write (--exports); "
                         "nothing was written")


class _Lock:
    def __init__(self, fd: int) -> None:
        self.fd = fd

    def release(self) -> None:
        """Empty the holder line, then unlock: a lock nobody holds names no one (and is the same
        bytes after every run, whoever ran last and when)."""
        try:
            try:
                os.ftruncate(self.fd, 0)
            except OSError:
                pass  # the line is a courtesy; the lock is released all the same
            fcntl.flock(self.fd, fcntl.LOCK_UN)
        finally:
            os.close(self.fd)


#: What rigcad writes into a lock it holds (see :func:`hold_lock`); a lock file holding anything
#: else is not rigcad's and is refused.
_LOCK_TEXT = re.compile(rb"pid \d+: .*, since \d\d:\d\d:\d\d", re.DOTALL)
_LOCK_MAX_BYTES = 4096


class LockRefused(ExportError):
    """The lock path holds something rigcad did not make: a link, a special file, another file's
    name (a hard link) or foreign text. rigcad neither writes it nor quotes it."""


def _open_lock(path: Path) -> int:
    """Open (creating it if needed) the lock file ``path`` without following a link, and check that
    it is what rigcad makes: a plain file with one name, empty or holding a holder line."""
    def refused(why: str) -> LockRefused:
        return LockRefused(f"{path} is not a lock file rigcad made ({why}): rigcad will not write to it; "
                           "remove it if nothing of yours depends on it, then run again; nothing was written")

    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o666)
    except OSError as err:
        if err.errno == errno.ELOOP:
            raise refused("a symbolic link") from None
        if err.errno in (errno.EISDIR, errno.ENXIO, errno.ENODEV, errno.EOPNOTSUPP):
            raise refused("not a plain file") from None
        raise write_error(path, err) from err
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise refused("not a plain file")
        if st.st_nlink != 1:
            raise refused(f"a file with {st.st_nlink} names (hard links)")
        text = os.pread(fd, _LOCK_MAX_BYTES + 1, 0)
        if text and (len(text) > _LOCK_MAX_BYTES or not _LOCK_TEXT.fullmatch(text.strip())):
            raise refused("it holds text rigcad did not write")
    except BaseException:
        os.close(fd)
        raise
    return fd


def hold_lock(path: Path, say=None) -> _Lock:
    """Take the advisory lock ``path`` (fcntl.flock; released by the OS if the process dies). If
    another run holds it, say who (pid, command, since when) and wait for it. The lock file is
    opened without following a link and refused (:class:`LockRefused`, nothing written) when it is
    not a plain, singly named file holding rigcad's holder line or nothing."""
    path = Path(path)
    _guard(path, lambda: path.parent.mkdir(parents=True, exist_ok=True))
    fd = _open_lock(path)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, _LOCK_MAX_BYTES, 0).decode("utf-8", "replace").strip() or "another rigcad run"
        (say or _say_waiting)(f"rigcad: waiting for {path} (held by {holder})")
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


def _say_waiting(message: str) -> None:
    """How a run says it waits for a lock (stderr); a test replaces it to see a run wait."""
    print(message, file=sys.stderr, flush=True)
