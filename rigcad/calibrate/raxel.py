"""Screen points at two or more heights -> each camera pixel's ray in the sample frame: the
generic ("raxel") camera model of Grossberg and Nayar (2001) and Sturm and Ramalingam (2004), in
which a pixel is the line of the points it sees, with no lens model.

A screen placement: the emitting surface tilted by the rotation vector (tilt_x, tilt_y, 0) rad
(Rodrigues: R) about its pivot (0, 0, height) mm, and placed within its own plane by hand: its
centre at (du, dv) mm, turned by ``turn`` rad about its normal (T): screen-frame (u, v, 0) ->
global R (T (u, v, 0) + (du, dv, 0)) + (0, 0, height)."""

from __future__ import annotations

import numpy as np

from rigcad.optics.frames import Pose


def screen_pose(height: float, tilt_x: float = 0.0, tilt_y: float = 0.0, du: float = 0.0, dv: float = 0.0,
                turn: float = 0.0) -> Pose:
    """The screen's placement (module docstring) as a Pose."""
    angle = float(np.hypot(tilt_x, tilt_y))
    axis = (tilt_x / angle, tilt_y / angle, 0.0) if angle > 0 else (0.0, 1.0, 0.0)
    tilted = Pose.misaligned((0.0, 0.0, height), angle, axis)
    if not (du or dv or turn):
        return tilted
    return Pose(tilted.rotation @ turn_matrix(turn), tilted.rotation @ np.array([du, dv, 0.0]) + tilted.translation)


def turn_matrix(angle: float) -> np.ndarray:
    """(3, 3) the turn by ``angle`` rad about +z (counter-clockwise seen from above)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def to_global(pose: Pose, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Screen-frame points (u, v) mm (any shape) -> global points (..., 3)."""
    local = np.stack([u, v, np.zeros_like(u)], axis=-1)
    return local @ pose.rotation.T + pose.translation


def on_screen(pose: Pose, points: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where lines (points, dirs: (n, 3)) meet the screen: its frame's (u, v) mm (n,), NaN for a
    line parallel to it."""
    q, d = pose.localize(points, dirs)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(d[:, 2] != 0, -q[:, 2] / d[:, 2], np.nan)
    return q[:, 0] + t * d[:, 0], q[:, 1] + t * d[:, 1]


def rays(points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The line through each pixel's points (a list over heights of (n, 3) arrays; NaN rows where a
    height did not decode the pixel): (point on the line nearest the points' centroid (n, 3),
    unit direction pointing up, +z (n, 3)); NaN where fewer than two heights decoded the pixel.
    Two points: the line through them; more: the total-least-squares line (the principal axis)."""
    stack = np.stack(points, axis=1)  # (n, k, 3)
    good = np.all(np.isfinite(stack), axis=2)
    count = good.sum(axis=1)
    w = good[:, :, None].astype(float)
    filled = np.where(good[:, :, None], stack, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        centroid = filled.sum(axis=1) / count[:, None]
    dev = (filled - centroid[:, None, :]) * w
    scatter = np.einsum("nki,nkj->nij", dev, dev)
    usable = count >= 2
    direction = np.full((len(stack), 3), np.nan)
    if usable.any():
        _, vecs = np.linalg.eigh(scatter[usable])
        d = vecs[:, :, -1]
        d *= np.where(d[:, 2] < 0, -1.0, 1.0)[:, None]
        direction[usable] = d
    centroid[~usable] = np.nan
    return centroid, direction
