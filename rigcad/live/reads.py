"""Which profile keys a stage reads, recorded while it runs: the live loop's stage keys are made of
what each stage touched, never of a list of sections kept by hand.

:func:`recording` runs a block with every profile section (the frozen dataclasses of
rigcad.profile.schema reachable from the profile's fields) reporting its field reads: ``("projector",
"resolution")`` when a stage reads ``profile.projector.resolution``. A read of a field that holds a
section is not recorded itself (the section's own reads are); a read that bypasses the fields (the
instance's ``__dict__``, pickling, copying) records the whole section. :func:`values_at` gives the
values at recorded paths in another profile: a stage whose recorded values are unchanged would read
the same, so it would compute the same.

The hook is installed on the sections' classes only for the block and only counts reads made by the
thread that runs it; sections of other profiles (the previous rig's) are not recorded.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
from collections.abc import Iterator

#: Reads that hand out a section's fields without naming them: the whole section is recorded.
WHOLE = frozenset({"__dict__", "__reduce__", "__reduce_ex__", "__getstate__", "__copy__", "__deepcopy__"})
#: The value at a path that a profile does not have (a section that is gone or a field renamed).
ABSENT = "<absent>"

_active: "Reads | None" = None
_lock = threading.Lock()


class Reads:
    """The paths read from one profile while :func:`recording` is active."""

    def __init__(self, profile) -> None:
        self.paths: set[tuple[str, ...]] = set()
        self.thread = threading.get_ident()
        self.paused = 0
        self._where: dict[int, tuple[str, ...]] = {}
        self._fields: dict[type, frozenset[str]] = {}
        self._walk(profile, ())

    def _walk(self, obj, path: tuple[str, ...]) -> None:
        if not dataclasses.is_dataclass(obj) or isinstance(obj, type) or id(obj) in self._where:
            return
        self._where[id(obj)] = path
        names = self._fields.setdefault(type(obj), frozenset(f.name for f in dataclasses.fields(obj)))
        for name in names:
            self._walk(object.__getattribute__(obj, name), path + (name,))

    @property
    def classes(self) -> tuple[type, ...]:
        return tuple(self._fields)

    def saw(self, obj, name: str, value) -> None:
        where = self._where.get(id(obj))
        if where is None or self.paused or threading.get_ident() != self.thread:
            return
        if name in self._fields.get(type(obj), ()):
            if id(value) not in self._where:  # a section: its own reads are recorded
                self.paths.add(where + (name,))
        elif name in WHOLE:
            self.paths.add(where)


def _hook(self, name: str):
    value = object.__getattribute__(self, name)
    rec = _active
    if rec is not None:
        rec.saw(self, name, value)
    return value


@contextlib.contextmanager
def recording(profile) -> Iterator[Reads]:
    """Record the profile keys read inside the block (:class:`Reads`.paths)."""
    global _active
    reads = Reads(profile)
    with _lock:  # one recording at a time: the hook is per class
        saved = {cls: cls.__dict__.get("__getattribute__") for cls in reads.classes}
        for cls in saved:
            cls.__getattribute__ = _hook
        _active = reads
        try:
            yield reads
        finally:
            _active = None
            for cls, old in saved.items():
                if old is None:
                    del cls.__getattribute__
                else:
                    cls.__getattribute__ = old


@contextlib.contextmanager
def unrecorded(module, name: str) -> Iterator[None]:
    """Inside the block, calls of ``module.name`` record nothing: for what a stage writes that the
    caller refreshes itself when it reuses the stage (the design report's copy of the whole profile)."""
    inner = getattr(module, name)

    def quiet(*args, **kwargs):
        rec = _active
        if rec is not None:
            rec.paused += 1
        try:
            return inner(*args, **kwargs)
        finally:
            if rec is not None:
                rec.paused -= 1

    setattr(module, name, quiet)
    try:
        yield
    finally:
        setattr(module, name, inner)


def values_at(profile, paths) -> tuple:
    """(path, value) for each of ``paths`` (sorted) in ``profile``: :data:`ABSENT` where it has none."""
    out = []
    for path in sorted(paths):
        value = profile
        for name in path:
            try:
                value = object.__getattribute__(value, name)
            except AttributeError:
                value = ABSENT
                break
        out.append((path, value))
    return tuple(out)


__all__ = ["ABSENT", "Reads", "recording", "unrecorded", "values_at"]
