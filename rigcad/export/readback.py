"""Reading back what rigcad wrote, or what a lab hands it: files are data, read with the profiles'
discipline (rigcad.profile.loader).

One reader per kind, each refusing in one line that names the file (and the key), never quoting
its content:

* every file (:func:`read_file`): opened without blocking and checked from ``fstat`` before a byte
  is read: a regular file (a FIFO, a device, a socket, a folder, a loop of links each named as such,
  not "missing"), at most a cap of bytes (a sparse or endless file is refused from its size, and the
  read itself stops at the cap);
* JSON (:func:`read_json`): strict UTF-8, nesting at most :data:`JSON_MAX_DEPTH` deep (counted before
  parsing, in linear time), no key twice in one object, no NaN or Infinity, integers of at most
  :data:`JSON_MAX_DIGITS` digits, every float finite;
* ``.npz`` (:func:`read_npz`): only the arrays asked for, each from its ``.npy`` header first: no
  Python objects (pickles), the dtype kinds and shape the caller allows, the bytes it claims within
  the caller's budget before anything is allocated or inflated; then exactly those bytes;
* images (:func:`open_image`): the size from the header checked against the caller's before the
  pixels are decoded; Pillow's decompression-bomb warning and error, and what libtiff prints on the
  process's stderr while decoding, become the refusal's reason instead of lines on the terminal.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import io
import json
import math
import os
import re
import stat
import sys
import tempfile
import warnings
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rigcad.errors import ExportError, RigcadError, one_line

#: Deepest nesting of a JSON document rigcad reads back (its own reports nest 6 deep).
JSON_MAX_DEPTH = 64
#: Most digits of a JSON integer: past 2**63 an integer is no count or index rigcad wrote.
JSON_MAX_DIGITS = 19
#: Longest text of a key or name quoted in a refusal, and most names listed.
QUOTE_CHARS = 40
QUOTE_NAMES = 8

_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)


def shown(path: os.PathLike | str) -> str:
    """A path as a refusal shows it: on one line, control characters escaped."""
    return one_line(os.fspath(path))


def quoted(value: Any) -> str:
    """``repr(value)`` cut to :data:`QUOTE_CHARS` characters, on one line."""
    text = one_line(repr(value))
    return text if len(text) <= QUOTE_CHARS else text[:QUOTE_CHARS - 3] + "..."


def names(items) -> str:
    """A sorted list of names as a refusal quotes it: at most :data:`QUOTE_NAMES`, each cut."""
    items = sorted(str(i) for i in items)
    head = [quoted(i) for i in items[:QUOTE_NAMES]]
    more = f", ... ({len(items)} in all)" if len(items) > QUOTE_NAMES else ""
    return f"[{', '.join(head)}{more}]"


def _kind(mode: int) -> str | None:
    """What a file that is not a regular file is, in words (None for a regular file)."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def size_text(n: int) -> str:
    for unit, scale in (("GiB", 2 ** 30), ("MiB", 2 ** 20), ("KiB", 2 ** 10)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} bytes"


def read_file(path: os.PathLike | str, what: str, limit: int, error: type[RigcadError] = ExportError,
              missing: str = "") -> tuple[bytes, os.stat_result]:
    """The bytes of ``path`` (a ``what``: "a calibration.json", "a capture frame") and its ``fstat``,
    refused with ``error`` unless it is a regular file of at most ``limit`` bytes. ``missing``: what
    to add when the file is not there (where it would come from)."""
    p = shown(path)
    try:
        fd = os.open(path, _FLAGS)
    except FileNotFoundError:
        gone = " (a symbolic link to nowhere)" if os.path.islink(path) else ""
        raise error(f"{p}: missing{gone}{'; ' + missing if missing else ''}") from None
    except OSError as err:
        reason = ("a loop of symbolic links" if err.errno == errno.ELOOP else
                  "not a folder on the way" if err.errno == errno.ENOTDIR else err.strerror or str(err))
        raise error(f"{p}: cannot be read as {what}: {reason}") from None
    try:
        st = os.fstat(fd)
        kind = _kind(st.st_mode)
        if kind:
            raise error(f"{p}: {kind}, not a file: {what} is a regular file")
        if st.st_size > limit:
            raise error(f"{p}: {size_text(st.st_size)}, more than the {size_text(limit)} {what} can be: "
                        "is it the right file?")
        chunks, total = [], 0
        while total <= limit:
            try:
                chunk = os.read(fd, min(limit + 1 - total, 1 << 24))
            except OSError as err:
                raise error(f"{p}: cannot be read as {what}: {err.strerror or err}") from None
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > limit:
            raise error(f"{p}: more than the {size_text(limit)} {what} can be (it grew while read)")
        return b"".join(chunks), st
    finally:
        os.close(fd)


def read_bytes(path, what: str, limit: int, error: type[RigcadError] = ExportError, missing: str = "") -> bytes:
    """:func:`read_file`'s bytes alone."""
    return read_file(path, what, limit, error, missing)[0]


# -- JSON --------------------------------------------------------------------------------------------

def json_depth(data: bytes) -> int:
    """The deepest nesting of brackets and braces in a JSON text, those inside strings left out:
    linear in the length (a quote is escaped after an odd run of backslashes); vectorised past 64 KiB,
    a plain loop below (no numpy import for a small manifest)."""
    if len(data) <= 1 << 16:
        return _json_depth_small(data)
    import numpy as np

    b = np.frombuffer(data, dtype=np.uint8)
    if not b.size:
        return 0
    idx = np.arange(b.size)
    backslash = b == ord("\\")
    last_other = np.maximum.accumulate(np.where(backslash, -1, idx))  # last position that is no backslash
    run_before = np.empty(b.size, dtype=np.int64)
    run_before[0] = 0
    run_before[1:] = idx[:-1] - last_other[:-1]  # backslashes just before each position
    quote = (b == ord('"')) & (run_before % 2 == 0)
    outside = np.cumsum(quote) % 2 == 0
    steps = (np.isin(b, (ord("["), ord("{"))) & outside).astype(np.int64) - (
        np.isin(b, (ord("]"), ord("}"))) & outside).astype(np.int64)
    return int(np.cumsum(steps).max())


def _json_depth_small(data: bytes) -> int:
    depth = deepest = 0
    inside = escaped = False
    for c in data:
        if inside:
            if escaped:
                escaped = False
            elif c == 0x5C:  # backslash
                escaped = True
            elif c == 0x22:  # quote
                inside = False
        elif c == 0x22:
            inside = True
        elif c in (0x5B, 0x7B):  # [ {
            depth += 1
            deepest = max(deepest, depth)
        elif c in (0x5D, 0x7D):  # ] }
            depth -= 1
    return deepest


class _Refused(ValueError):
    pass


def parse_json(data: bytes, where: str, error: type[RigcadError] = ExportError) -> Any:
    """Parse ``data`` (from ``where``) as :func:`read_json` does."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise error(f"{where}: not a readable JSON file (not UTF-8: byte 0x{data[err.start]:02x} at offset "
                    f"{err.start})") from None
    depth = json_depth(data)
    if depth > JSON_MAX_DEPTH:
        raise error(f"{where}: not a readable JSON file (nested {depth} levels deep; rigcad reads at most "
                    f"{JSON_MAX_DEPTH})")

    def no_twice(pairs):
        out = {}
        for key, value in pairs:
            if key in out:
                raise _Refused(f"the key {quoted(key)} twice in one object")
            out[key] = value
        return out

    def integer(text: str) -> int:
        digits = len(text.lstrip("-"))
        if digits > JSON_MAX_DIGITS:
            raise _Refused(f"an integer of {digits} digits (at most {JSON_MAX_DIGITS})")
        return int(text)

    def number(text: str) -> float:
        value = float(text)
        if not math.isfinite(value):
            raise _Refused(f"the number {quoted(text)}, past the largest float")
        return value

    def constant(name: str):
        raise _Refused(f"{name}, not a number JSON allows")

    try:
        return json.loads(text, object_pairs_hook=no_twice, parse_int=integer, parse_float=number,
                          parse_constant=constant)
    except _Refused as err:
        raise error(f"{where}: not a readable JSON file ({err})") from None
    except (ValueError, RecursionError) as err:
        reason = one_line(err) if isinstance(err, ValueError) else "nested too deep"
        raise error(f"{where}: not a readable JSON file ({reason[:200]})") from None


def read_json(path, what: str, limit: int, error: type[RigcadError] = ExportError,
              missing: str = "") -> tuple[Any, os.stat_result]:
    """A JSON file read as data (module docstring), and its ``fstat``."""
    data, st = read_file(path, what, limit, error, missing)
    return parse_json(data, shown(path), error), st


#: The largest manifest rigcad reads back (its own list files and hashes: tens of KB).
MANIFEST_MAX_BYTES = 64 << 20


def own_json(path) -> Any:
    """A JSON file rigcad wrote and reads back for itself (a manifest): its content, or None when it
    is missing or not one rigcad could have written (then the caller rebuilds). Read with
    :func:`read_json`'s discipline, at most MANIFEST_MAX_BYTES: a FIFO, a sparse giant or a nesting
    bomb is None, never a hang or a traceback."""
    try:
        return read_json(path, "a manifest", MANIFEST_MAX_BYTES)[0]
    except ExportError:
        return None


def number_in(value: Any, where: str, low: float, high: float, unit: str, error: type[RigcadError] = ExportError,
              what: str = "") -> float:
    """``value`` as a float when it is a finite number (not a bool) in [low, high], else ``error``
    naming ``where`` (file and key), the value and the range."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise error(f"{where} is {quoted(value)}, not a finite number{what}")
    if not low <= value <= high:
        raise error(f"{where} is {value:.4g}, outside {low:g}..{high:g} {unit}{what}")
    return float(value)


# -- npz ---------------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class ArraySpec:
    """What an array of an npz may be: dtype ``kinds`` (numpy's letters: "f" float, "i" and "u"
    integers, "b" bool), ``ndim``, and ``check(shape) -> str | None``: why the shape is not valid (None:
    valid). ``optional``: absent is fine."""

    kinds: str
    ndim: int
    check: Callable[[tuple[int, ...]], str | None] | None = None
    optional: bool = False


def read_npz(path, what: str, arrays: dict[str, ArraySpec], limit: int, budget: int,
             error: type[RigcadError] = ExportError, missing: str = "") -> dict[str, Any]:
    """The arrays ``arrays`` names from the npz at ``path`` (at most ``limit`` bytes on disk), each
    checked from its header (:class:`ArraySpec`; no object arrays) and all together at most
    ``budget`` bytes once read, before one is inflated. Other members are never read."""
    import numpy as np

    data = read_bytes(path, what, limit, error, missing)
    p = shown(path)
    out: dict[str, Any] = {}
    spent = 0
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            members = set(zf.namelist())
            for key, spec in arrays.items():
                if f"{key}.npy" not in members:
                    if spec.optional:
                        continue
                    raise error(f"{p}: no {key!r} array: not {what} rigcad wrote")
                with zf.open(f"{key}.npy") as fh:
                    shape, fortran, dtype = _npy_header(fh, p, key, error)
                    if dtype.hasobject or dtype.fields is not None:
                        raise error(f"{p}: {key!r} holds Python objects or records (a pickle), not numbers: "
                                    "rigcad reads numbers only")
                    if dtype.kind not in spec.kinds:
                        raise error(f"{p}: {key!r} is of type {dtype.str}, not {_kinds(spec.kinds)}")
                    if len(shape) != spec.ndim:
                        raise error(f"{p}: {key!r} has {len(shape)} dimensions {shape}, need {spec.ndim}")
                    why = spec.check(shape) if spec.check else None
                    if why:
                        raise error(f"{p}: {key!r} of shape {shape}: {why}")
                    nbytes = math.prod(shape) * dtype.itemsize
                    if spent + nbytes > budget:
                        raise error(f"{p}: {key!r} of shape {shape} would take {size_text(nbytes)}, more than "
                                    f"{what} can hold ({size_text(budget)} in all)")
                    raw = fh.read(nbytes + 1)
                    if len(raw) != nbytes:
                        raise error(f"{p}: {key!r} holds {len(raw)} bytes where its header says {nbytes}")
                    spent += nbytes
                    arr = np.frombuffer(raw, dtype=dtype).reshape(shape, order="F" if fortran else "C")
                    out[key] = arr.astype(dtype.newbyteorder("="), copy=True)
    except RigcadError:
        raise
    except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError, OSError, ValueError,
            RuntimeError) as err:
        raise error(f"{p}: not a readable .npz ({one_line(err)[:160]})") from None
    return out


def _kinds(kinds: str) -> str:
    words = {"f": "float", "i": "integer", "u": "unsigned integer", "b": "bool"}
    return " or ".join(words.get(k, k) for k in kinds)


def _npy_header(fh, p: str, key: str, error):
    import numpy as np

    try:
        version = np.lib.format.read_magic(fh)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(fh)
        if version == (2, 0):
            return np.lib.format.read_array_header_2_0(fh)
    except (ValueError, OSError, EOFError, zlib.error, zipfile.BadZipFile, SyntaxError) as err:
        raise error(f"{p}: {key!r} is not a readable .npy array ({one_line(err)[:160]})") from None
    raise error(f"{p}: {key!r} is a .npy of format {version}, which rigcad does not read (1.0 or 2.0)")


# -- images ------------------------------------------------------------------------------------------

@contextlib.contextmanager
def captured_stderr():
    """What C libraries (libtiff) write to the process's stderr meanwhile, kept off the terminal:
    yields a list that holds the text afterwards."""
    out: list[str] = []
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError, OSError):
        pass
    try:
        saved = os.dup(2)
    except OSError:  # no stderr to guard
        yield out
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield out
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            out.append(tmp.read(4096).decode("utf-8", "replace"))


def open_image(data: bytes, where: str, size_ok: Callable[[tuple[int, int]], str | None],
               error: type[RigcadError] = ExportError, formats: tuple[str, ...] = ("PNG", "TIFF")):
    """The decoded image (a Pillow image, loaded) of ``data`` read from ``where``, refused with
    ``error`` unless its header's size passes ``size_ok(width, height)`` (None: fine; else why not),
    checked before any pixel is decoded. Pillow's warnings and libtiff's lines go into the refusal."""
    from PIL import Image, UnidentifiedImageError

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        try:
            im = Image.open(io.BytesIO(data), formats=list(formats))
        except Image.DecompressionBombError as err:
            pixels = re.search(r"\((\d+) pixels\)", str(err))
            claim = f"{int(pixels.group(1)):,} px" if pixels else "more pixels than Pillow decodes"
            raise error(f"{where}: its header claims {claim}: {size_ok((0, 0)) or 'too large'}") from None
        except (OSError, UnidentifiedImageError, ValueError, SyntaxError) as err:
            raise error(f"{where}: not a readable {' or '.join(formats)} ({one_line(err)[:160]})") from None
        why = size_ok(im.size)
        if why:
            im.close()
            raise error(f"{where}: {im.size[0]} x {im.size[1]} px, {why}")
        with captured_stderr() as said:
            try:
                im.load()
            except (OSError, ValueError, SyntaxError, MemoryError, Image.DecompressionBombError) as err:
                failure = one_line(err)[:160]
            else:
                failure = None
        if failure is not None:
            im.close()
            library = " ".join(one_line(s.strip()) for s in said if s.strip())[:160]
            raise error(f"{where}: not a readable {' or '.join(formats)} ({failure}"
                        f"{'; ' + library if library else ''})")
    return im


__all__ = ["ArraySpec", "JSON_MAX_DEPTH", "JSON_MAX_DIGITS", "captured_stderr", "json_depth", "names", "number_in",
           "open_image", "own_json", "parse_json", "quoted", "read_bytes", "read_file", "read_json", "read_npz", "shown",
           "size_text"]
