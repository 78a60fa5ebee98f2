"""rigcad: CAD and fabrication toolchain for the image-based BRDF acquisition rig (Achutha 2006).

The pipeline flows one way: YAML profile -> validated parameters (``rigcad.profile``) -> a
:class:`Rig` built once (its 2D optical design, dome, layout and part recipes) -> exports, ray
check, fabrication. Internally everything is millimetres and radians in float64.

    import rigcad
    rig = rigcad.load("achutha2006")     # by name: ./profiles, $RIGCAD_PROFILES, the shipped profiles
    rig.design.report["envelope"]        # figures with units in the keys
    dome = rig.part("dome")              # a build123d Part (.to_cadquery(), .mesh())
    rig.export("exports/achutha2006")    # STEP, STL, 3MF, PLY, renders, manifest.json
    rig.check(rays=100_000).passed
    rig.fab("prusa_mk3s")

See docs/api.md.
"""

from typing import TYPE_CHECKING

from rigcad._lazy import lazy_names
from rigcad._version import __version__

if TYPE_CHECKING:
    from rigcad.rig import Rig, load

__all__ = ["Rig", "__version__", "load"]

#: Public names imported on first use: ``import rigcad`` (and so every ``rigcad`` command, ``--help``
#: included) loads no numpy or scipy until a rig is asked for.
_LAZY = {"Rig": "rigcad.rig", "load": "rigcad.rig"}


__getattr__, __dir__ = lazy_names("rigcad", _LAZY, globals(), __all__)
