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

from rigcad.errors import ExportError

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


class CalibrationMapError(ExportError):
    """A corrected map that cannot be read as one: the message names the file and the array."""


#: How far a direction of the corrected map may be from unit length (it is written unit to ~1e-16).
UNIT_SLACK = 1e-6


def load_corrected_map(exports, profile_name: str, resolution: tuple[int, int] | None = None) -> "CorrectedMap | None":
    """The corrected map under ``<exports>/<profile>/`` when ``rigcad calibrate`` wrote one, else None.

    Read as data (rigcad.export.readback): the ``direction``, ``row0``, ``col0`` (and ``resolution``)
    arrays only, each checked from its header (no pickles; ``direction`` (h, w, 3) float within the
    camera's ``resolution`` (width, height) px, the window's corner integers placing it inside it);
    every pixel a unit vector or all NaN (no map there), and at least one a direction. Anything else
    is refused (CalibrationMapError naming the file and the array), never replaced by the design map."""
    import os
    from pathlib import Path

    import numpy as np

    from rigcad.export.readback import ArraySpec, read_npz, shown

    path = Path(exports) / profile_name / CORRECTED_MAP
    if not os.path.lexists(path):
        return None
    width, height = resolution if resolution is not None else (1 << 16, 1 << 16)

    def window(shape) -> str | None:
        if shape[2] != 3 or not (1 <= shape[0] <= height and 1 <= shape[1] <= width):
            return f"need (rows <= {height}, cols <= {width}, 3): the camera's window of unit directions"
        return None

    scalar = ArraySpec("iu", 0)
    arrays = read_npz(path, "a corrected map", {
        "direction": ArraySpec("f", 3, window), "row0": scalar, "col0": scalar,
        "resolution": ArraySpec("iu", 1, lambda s: None if s == (2,) else "need (2,): width, height", optional=True)},
        limit=width * height * 128 + (1 << 20), budget=width * height * 24 + 4096, error=CalibrationMapError,
        missing="")
    p = shown(path)
    direction = np.asarray(arrays["direction"], dtype=float)
    h, w = direction.shape[:2]
    row0, col0 = int(arrays["row0"]), int(arrays["col0"])
    if resolution is not None and "resolution" in arrays and tuple(int(v) for v in arrays["resolution"]) != (width, height):
        raise CalibrationMapError(f"{p}: made for a {int(arrays['resolution'][0])} x {int(arrays['resolution'][1])} px "
                                  f"camera, the profile's is {width} x {height} (camera.resolution): calibrate again")
    if not (0 <= row0 <= height - h and 0 <= col0 <= width - w):
        raise CalibrationMapError(f"{p}: a {w} x {h} px window at row0 {row0}, col0 {col0} does not lie inside the "
                                  f"{width} x {height} px camera")
    finite = np.isfinite(direction)
    whole = finite.all(axis=2)
    if (finite.any(axis=2) & ~whole).any() or np.isinf(direction).any():
        raise CalibrationMapError(f"{p}: 'direction' holds infinite values or pixels only partly NaN: a pixel is a "
                                  "unit direction or all NaN (no map there)")
    if not whole.any():
        raise CalibrationMapError(f"{p}: 'direction' is NaN at every pixel: the map holds no direction; calibrate "
                                  "again, or remove it to use the design map")
    kept = direction[whole]
    largest = float(np.max(np.abs(kept)))
    if largest > 1.0 + UNIT_SLACK:  # before the norm, which would overflow on 1e300
        raise CalibrationMapError(f"{p}: 'direction' holds a component of {largest:.4g}, not unit directions")
    norm = np.linalg.norm(kept, axis=1)
    if float(np.max(np.abs(norm - 1.0))) > UNIT_SLACK:
        raise CalibrationMapError(f"{p}: 'direction' holds vectors of length up to {float(np.max(norm)):.4g} "
                                  f"(down to {float(np.min(norm)):.4g}), not unit directions (within {UNIT_SLACK:g})")
    return CorrectedMap(path, direction, row0, col0)

