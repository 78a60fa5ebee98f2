"""Profiles: YAML -> validated, frozen parameters -> derived values."""

from typing import TYPE_CHECKING

from rigcad._lazy import lazy_names

if TYPE_CHECKING:
    from rigcad.profile.derived import Derived, derive
    from rigcad.profile.schema import Profile, load_profile

__all__ = ["Derived", "Profile", "derive", "load_profile"]

#: Imported on first use, so reading the loader alone (finding a printer, listing profiles) does not
#: import the schema and numpy.
_LAZY = {"Derived": "rigcad.profile.derived", "derive": "rigcad.profile.derived",
         "Profile": "rigcad.profile.schema", "load_profile": "rigcad.profile.schema"}


__getattr__, __dir__ = lazy_names("rigcad.profile", _LAZY, globals(), __all__)
