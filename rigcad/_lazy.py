"""Public names a package imports on first use (PEP 562), so importing the package stays cheap."""

from __future__ import annotations

from importlib import import_module
from typing import Callable


def lazy_names(package: str, names: dict[str, str], namespace: dict, public: list[str]) -> tuple[Callable, Callable]:
    """The ``__getattr__`` and ``__dir__`` of ``package``: each of ``names`` (name -> module that
    defines it) is imported when first looked up and kept in ``namespace`` (the package's globals),
    so later lookups skip the hook."""

    def __getattr__(name: str):
        if name in names:
            value = getattr(import_module(names[name]), name)
            namespace[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(public))

    return __getattr__, __dir__
