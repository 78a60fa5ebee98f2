"""The rig's parts: each a function from the validated profile (and the shared layout) to a
:class:`rigcad.parts.recipe.Part`. Only ``_kernel`` touches OpenCascade."""

from __future__ import annotations

from collections.abc import Callable

from rigcad.parts.base import base_cross, base_plate, sample_holder
from rigcad.parts.beam import beam
from rigcad.parts.crosses import camera_cross_hung, projector_backplate, projector_cross, projector_mounting_plate
from rigcad.parts.dome import dome
from rigcad.parts.layout import RigLayout, rig_layout
from rigcad.parts.paraboloid import paraboloid
from rigcad.parts.recipe import Part
from rigcad.parts.templates import dome_template, paraboloid_template
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
}

__all__ = ["PARTS", "Part", "RigLayout", "rig_layout"]
