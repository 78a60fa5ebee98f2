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

__version__ = "0.1.0"

from rigcad.rig import Rig, load  # noqa: E402  (after __version__, which the manifest reads)

__all__ = ["Rig", "__version__", "load"]
