"""The rig's parts: each a function from the validated profile (and the shared layout) to a
:class:`rigcad.parts.recipe.Part`. Only ``_kernel`` touches OpenCascade."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import is_dataclass, replace

from rigcad.parts.base import base_cross, base_plate, sample_holder
from rigcad.parts.beam import beam
from rigcad.parts.crosses import camera_cross_hung, projector_backplate, projector_cross, projector_mounting_plate
from rigcad.parts.dome import dome
from rigcad.parts.layout import RigLayout, rig_layout
from rigcad.parts.paraboloid import paraboloid
from rigcad.parts.recipe import Part
from rigcad.parts.templates import dome_template, paraboloid_template
from rigcad.parts.tower import lens_mount, splitter_holder, tower_column, tower_shelf, tower_shim
from rigcad.profile.schema import Profile

#: Every part, in build order.
PARTS: dict[str, Callable[[Profile, RigLayout], Part]] = {
    "dome": dome,
    "paraboloid": paraboloid,
    "beam": beam,
    "base_plate": base_plate,
    "sample_holder": sample_holder,
    "projector_cross": projector_cross,
    "projector_backplate": projector_backplate,
    "projector_mounting_plate": projector_mounting_plate,
    "camera_cross_hung": camera_cross_hung,
    "camera_cross_base": base_cross,
    "dome_template": dome_template,
    "paraboloid_template": paraboloid_template,
    "tower_column": tower_column,
    "tower_shelf": tower_shelf,
    "splitter_holder": splitter_holder,
    "lens_mount": lens_mount,
    "tower_shim": tower_shim,
}

__all__ = ["PARTS", "Part", "RigLayout", "make_layout", "make_recipe", "make_recipes", "rig_layout"]


class _Reads:
    """The profile as a part function sees it, noting each ``section.key`` it reads."""

    def __init__(self, profile: Profile) -> None:
        self._profile = profile
        self.keys: list[str] = []

    def __getattr__(self, name: str):
        value = getattr(self._profile, name)
        return _SectionReads(name, value, self.keys) if is_dataclass(value) else value


class _SectionReads:
    def __init__(self, section: str, values, keys: list[str]) -> None:
        self._section, self._values, self._keys = section, values, keys

    def __getattr__(self, key: str):
        self._keys.append(f"{self._section}.{key}")
        return getattr(self._values, key)


def make_recipe(profile: Profile, layout: RigLayout, name: str) -> Part:
    """One part's recipe on ``layout``, with the profile keys its function read (``Part.shaped_by``:
    what an error names when the kernel cannot build it)."""
    reads = _Reads(profile)
    part = PARTS[name](reads, layout)  # type: ignore[arg-type]  # reads every attribute through to the profile
    return replace(part, shaped_by=tuple(dict.fromkeys(reads.keys)))


def make_layout(profile: Profile, geometry, dome) -> RigLayout:
    """The rig's placements (:func:`rig_layout`), with the profile keys the layout read
    (``RigLayout.shaped_by``)."""
    reads = _Reads(profile)
    layout = rig_layout(reads, geometry, dome)  # type: ignore[arg-type]  # reads every attribute through
    return replace(layout, shaped_by=tuple(dict.fromkeys(reads.keys)))


def make_recipes(profile: Profile, layout: RigLayout) -> dict[str, Part]:
    """Every part's recipe, in build order (:func:`make_recipe`)."""
    return {name: make_recipe(profile, layout, name) for name in PARTS}
