"""Deflectometric calibration of the as-built rig: a flat screen at the sample shows phase-shifted
sinusoids and Gray codes, the camera sees it through the paraboloid and the dome at two or more
heights, and each camera pixel's ray in the sample frame follows (the raxel model). A fit of the
rig's misalignment with its own analytic tracer, the dome's residual slope map and the corrected
pixel -> incidence map come from those rays (docs/calibrate.md).

Modules: ``patterns`` (what the screen shows), ``decode`` (camera images -> screen points),
``raxel`` (screen points -> rays), ``model`` (the rig's tracer as the forward model), ``simulate``
(the images a capture would give), ``fit`` (least squares, residual slopes, corrected map),
``images`` (reading and checking a capture), ``run`` (the command's stages), ``kit`` (screen PNGs,
spacers, the manual's page)."""

from __future__ import annotations

#: The camera's corrected map inside a profile's exports folder (written by rigcad calibrate; read
#: by rigcad basis when present).
CORRECTED_MAP = "calibrate/corrected_map.npz"
