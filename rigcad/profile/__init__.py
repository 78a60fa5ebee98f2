"""Profiles: YAML -> validated, frozen parameters -> derived values."""

from rigcad.profile.derived import Derived, derive
from rigcad.profile.schema import Profile, load_profile

__all__ = ["Derived", "Profile", "derive", "load_profile"]
