"""Profiles: YAML -> validated, frozen parameters -> derived values."""

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rigcad.profile.derived import Derived, derive
    from rigcad.profile.schema import Profile, load_profile

__all__ = ["Derived", "Profile", "derive", "load_profile"]

#: Imported on first use, so reading the loader alone (finding a printer, listing profiles) does not
#: import the schema and numpy.
_LAZY = {"Derived": "rigcad.profile.derived", "derive": "rigcad.profile.derived",
         "Profile": "rigcad.profile.schema", "load_profile": "rigcad.profile.schema"}


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(_LAZY[name]), name)
        globals()[name] = value  # later lookups skip this function
        return value
    raise AttributeError(f"module 'rigcad.profile' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
