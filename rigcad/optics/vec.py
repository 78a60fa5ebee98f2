"""Vectors in rows, the one home of the small helpers every tracer uses: ``unit``, ``reflect``, the
row-wise ``dot`` and ``cross`` of (n, 3) arrays, and a pose as the compiled kernels take it.

Each keeps its own order of operations: the 2D design and the 3D tracers were measured, and their
outputs are compared bit for bit, with these exact sums."""

from __future__ import annotations

import numpy as np


def unit(v: np.ndarray) -> np.ndarray:
    """Rows of ``v`` (n, 2) or (n, 3) scaled to length 1."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def reflect(d: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Mirror reflection of directions ``d`` about unit normals ``n``, rows of any length (the 2D
    design's (n, 2)); the dot product summed by ``np.sum``."""
    return d - 2.0 * np.sum(d * n, axis=-1, keepdims=True) * n


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product (n,) of (n, 3) arrays, summed x + y + z in that order."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (n, 3) arrays (np.cross is ~3x slower on (n, 3) rows)."""
    out = np.empty_like(a)
    np.subtract(a[:, 1] * b[:, 2], a[:, 2] * b[:, 1], out=out[:, 0])
    np.subtract(a[:, 2] * b[:, 0], a[:, 0] * b[:, 2], out=out[:, 1])
    np.subtract(a[:, 0] * b[:, 1], a[:, 1] * b[:, 0], out=out[:, 2])
    return out


def reflect_rows(d: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Mirror reflection of directions ``d`` (n, 3) about unit normals ``n`` (n, 3), the dot product
    summed by :func:`dot` (the order the compiled kernels use): the 3D tracers' numpy pass."""
    return d - (2.0 * dot(d, n))[:, None] * n


def pose_arrays(pose) -> tuple[np.ndarray, np.ndarray, bool]:
    """(rotation (3, 3), translation (3,) mm, is identity) of a :class:`rigcad.optics.frames.Pose`,
    contiguous float64, as the compiled kernels take them."""
    return (np.ascontiguousarray(pose.rotation, float), np.ascontiguousarray(pose.translation, float),
            bool(pose.is_identity))
