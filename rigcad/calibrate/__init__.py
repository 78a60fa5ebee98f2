"""Deflectometric calibration of the as-built rig: a flat screen at the sample shows phase-shifted
sinusoids and Gray codes, the camera sees it through the paraboloid and the dome at two or more
heights, which gives each camera pixel's screen points. A fit of the rig's misalignment with its own
analytic tracer, each pixel's ray through its fitted dome point and its screen points, the dome's
residual slope map and the corrected pixel -> incidence map follow (docs/calibrate.md).

Modules: ``patterns`` (what the screen shows), ``decode`` (camera images -> screen points),
``bias`` (the decoding's own bias, from the measured map), ``raxel`` (screen poses, and
the line through screen points), ``model`` (the rig's tracer as the forward model), ``simulate``
(the images a capture would give), ``fit`` (the misalignment by least squares), ``maps`` (measured
rays, residual slopes, the corrected map), ``images`` (reading and checking a capture), ``run`` (the
stages, and a simulation's comparison with what was planted), ``kit`` (screen PNGs, spacers, the
manual's page), ``cli`` (the command)."""

from __future__ import annotations

#: The camera's corrected map inside a profile's exports folder (written by rigcad calibrate; read
#: by rigcad basis when present).
CORRECTED_MAP = "calibrate/corrected_map.npz"


class CorrectedMap:
    """A corrected camera map written by ``rigcad calibrate``: unit incidence directions (from O
    towards the light) per camera pixel of a window, NaN where the map has none."""

    def __init__(self, path, direction, row0: int, col0: int) -> None:
        self.path, self.direction, self.row0, self.col0 = path, direction, int(row0), int(col0)

    def at(self, rows, cols):
        """Directions (n, 3) at camera pixels (rows, cols) (n,); NaN outside the window or the map."""
        import numpy as np

        r, c = np.asarray(rows) - self.row0, np.asarray(cols) - self.col0
        h, w = self.direction.shape[:2]
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        out = np.full((len(r), 3), np.nan)
        out[inside] = self.direction[r[inside], c[inside]]
        return out


def load_corrected_map(exports, profile_name: str) -> "CorrectedMap | None":
    """The corrected map under ``<exports>/<profile>/`` when ``rigcad calibrate`` wrote one, else None."""
    from pathlib import Path

    import numpy as np

    path = Path(exports) / profile_name / CORRECTED_MAP
    if not path.is_file():
        return None
    with np.load(path) as data:
        return CorrectedMap(path, data["direction"], int(data["row0"]), int(data["col0"]))
