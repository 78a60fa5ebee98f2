"""rigcad: CAD and fabrication toolchain for the image-based BRDF acquisition rig (Achutha 2006).

The pipeline flows one way: YAML profile -> validated parameters (``rigcad.profile``) -> 2D optical
design (``rigcad.optics``) -> exports (``rigcad.export``). Internally everything is millimetres and
radians in float64.
"""

__version__ = "0.1.0"
