"""Atomic writes: a temporary file in the target folder, then a rename.

A failed or interrupted run leaves the previous file intact and no half-written one behind.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rigcad.errors import ExportError


def _temp_beside(path: Path) -> Path:
    """A new, empty, hidden temporary file in ``path``'s folder (created if needed)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
    except OSError as err:
        raise ExportError(f"cannot write {path}: {err.strerror}") from err
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
        raise ExportError(f"cannot write {path}: {err.strerror}") from err
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
    """Stage several outputs and publish them together: each is written to a hidden temporary
    file beside its target; :meth:`commit` renames them all into place, :meth:`abort` (or an
    exception inside ``with``) deletes them, so a failed run leaves the previous files untouched."""

    def __init__(self) -> None:
        self._staged: list[tuple[Path, Path]] = []

    def write_with(self, path: Path, writer: Callable[[Path], None]) -> Path:
        """Stage ``path``: ``writer(tmp)`` fills a temporary file now; the rename waits for commit."""
        path = Path(path)
        tmp_path = _temp_beside(path)
        self._staged.append((tmp_path, path))
        writer(tmp_path)
        os.chmod(tmp_path, 0o666 & ~_umask())
        return path

    def write_bytes(self, path: Path, data: bytes) -> Path:
        return self.write_with(path, lambda tmp: tmp.write_bytes(data))

    def temp_path(self, path: Path) -> Path:
        """Where ``path`` is staged (to read back a staged file before commit)."""
        for tmp, target in self._staged:
            if target == Path(path):
                return tmp
        raise KeyError(path)

    def commit(self) -> list[Path]:
        done = []
        try:
            for tmp, target in self._staged:
                os.replace(tmp, target)
                done.append(target)
        except OSError as err:
            raise ExportError(f"cannot publish {target}: {err.strerror}") from err
        finally:
            self.abort()
        return done

    def abort(self) -> None:
        for tmp, _ in self._staged:
            if tmp.exists():
                tmp.unlink()
        self._staged = []

    def __enter__(self) -> "Staging":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None:
            self.abort()
