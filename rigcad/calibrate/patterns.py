"""What the calibration screen shows (Knauer, Kaminski and Häusler 2004): per axis (x along the
screen's columns, y along its rows), Gray-code stripes and phase-shifted sinusoids at each period,
plus a white and a black frame; 8-bit, at the screen's resolution.

Screen frame: pixel (column i, row j) has its centre at the continuous coordinates c_x = i + 0.5,
c_y = j + 0.5 (screen pixels); in mm on the emitting surface, u = c_x p - W p / 2 (towards +x) and
v = H p / 2 - c_y p (towards +y, rows run towards -y), p the pitch: the screen's centre at (0, 0).

Sinusoid ``{axis}_p{P}_s{n}``: I = 1/2 + 1/2 cos(2 pi c / P - 2 pi n / N), N = phase steps.
Gray code ``{axis}_gray{b}`` (b = 0 the most significant bit): stripe g = floor(c / S) of width
S = P_0 / 2 (half the coarsest period), white where bit b of g XOR (g >> 1) is set.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AXES = ("x", "y")
#: Narrowest footprint edge (screen px) :meth:`Sequence.footprint_mean` integrates over: below it the
#: second antiderivatives' difference loses digits (values ~1e6 px^2, float64), and a camera pixel's
#: footprint is never that thin.
MIN_WIDTH_PX = 0.02


def _cell(c: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Continuous coordinates c -> (pixel index clipped to [0, n], offset in it, beyond the end)."""
    c = np.asarray(c, float)
    i = np.clip(np.floor(c), 0, n).astype(np.int64)
    return i, np.clip(c, 0, n) - i, np.maximum(c - n, 0.0)


class _Staircase:
    """G with G'' = the staircase ``prof`` (value prof[i] on [i, i + 1), 0 outside), exact: a
    piecewise quadratic through the cumulative sums, evaluated at :func:`_cell` cells."""

    def __init__(self, prof: np.ndarray) -> None:
        self.first = np.concatenate([[0.0], np.cumsum(prof)])  # F at the integers
        self.second = np.concatenate([[0.0], np.cumsum(self.first[:-1] + prof / 2)])  # G at the integers
        self.value = np.append(prof, 0.0)

    def __call__(self, cell) -> np.ndarray:
        i, t, beyond = cell
        return self.second[i] + self.first[i] * t + self.value[i] * t * t / 2 + self.first[-1] * beyond


@dataclass(frozen=True)
class Sequence:
    """The frames of one capture in order, and what sets them: ``periods`` (screen px, coarse to
    fine), ``steps`` (N), ``gray_bits``, the screen's ``resolution`` (width, height) and ``pitch`` (mm)."""

    periods: tuple[int, ...]
    steps: int
    gray_bits: int
    resolution: tuple[int, int]
    pitch: float

    @classmethod
    def from_profile(cls, cal, display: str = "screen") -> "Sequence":
        """From a profile's ``calibration`` section, for its flat ``screen`` or its ``upright`` display
        (the same frames at that display's resolution and pitch)."""
        return cls(tuple(cal.periods), int(cal.phase_steps), int(cal.gray_bits),
                   tuple(getattr(cal, f"{display}_resolution")), float(getattr(cal, f"{display}_pitch")))

    @property
    def size_mm(self) -> tuple[float, float]:
        """The display's active area (width, height), mm."""
        return self.resolution[0] * self.pitch, self.resolution[1] * self.pitch

    @property
    def stripe(self) -> float:
        """The Gray code's stripe width (screen px): half the coarsest period."""
        return self.periods[0] / 2

    def names(self) -> list[str]:
        """Every frame's name, in capture order: white, black, then per axis the Gray bits (most
        significant first) and the sinusoids (coarse period first, steps in order)."""
        out = ["white", "black"]
        for axis in AXES:
            out += [f"{axis}_gray{b}" for b in range(self.gray_bits)]
            out += [f"{axis}_p{p}_s{n}" for p in self.periods for n in range(self.steps)]
        return out

    def length(self, axis: str) -> int:
        """Screen pixels along ``axis``."""
        return self.resolution[0] if axis == "x" else self.resolution[1]

    def profile(self, name: str) -> np.ndarray:
        """The frame ``name`` along its axis: 8-bit values (L,) per screen column (x frames) or row
        (y frames); white and black as a 1-pixel profile."""
        if name in ("white", "black"):
            return np.array([255 if name == "white" else 0], np.uint8)
        axis, kind = name.split("_", 1)
        c = np.arange(self.length(axis)) + 0.5
        if kind.startswith("gray"):
            b = int(kind[4:])
            g = np.floor(c / self.stripe).astype(np.int64)
            code = g ^ (g >> 1)
            return np.where((code >> (self.gray_bits - 1 - b)) & 1, 255, 0).astype(np.uint8)
        period, step = kind[1:].split("_s")
        value = 0.5 + 0.5 * np.cos(2 * np.pi * c / int(period) - 2 * np.pi * int(step) / self.steps)
        return np.round(255 * value).astype(np.uint8)

    def image(self, name: str) -> np.ndarray:
        """The frame ``name`` as the screen shows it: (height, width) uint8."""
        w, h = self.resolution
        prof = self.profile(name)
        if name in ("white", "black"):
            return np.full((h, w), prof[0], np.uint8)
        return np.broadcast_to(prof[None, :] if name.startswith("x") else prof[:, None], (h, w)).copy()

    def sample(self, name: str, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
        """The frame's displayed value in [0, 1] at continuous screen coordinates (cx, cy) (screen px,
        any shape): the value of the screen pixel each point falls in, 0 off the screen."""
        w, h = self.resolution
        i, j = np.floor(cx), np.floor(cy)
        on = (i >= 0) & (i < w) & (j >= 0) & (j < h)
        prof = self.profile(name).astype(float) / 255.0
        if name in ("white", "black"):
            return np.where(on, prof[0], 0.0)
        k = np.clip(i if name.startswith("x") else j, 0, len(prof) - 1).astype(np.int64)
        return np.where(on, prof[k], 0.0)

    def footprint_mean(self, name: str, cx: np.ndarray, cy: np.ndarray, edges: np.ndarray) -> np.ndarray:
        """The frame's mean value in [0, 1] over parallelograms on the screen: centres (cx, cy) px
        and edge vectors ``edges`` (..., 2, 2) px (edges[..., k, :] the k-th edge's (x, y)); see
        :meth:`footprint_means`."""
        return self.footprint_means([name], cx, cy, edges)[name]

    def footprint_means(self, names: list[str], cx: np.ndarray, cy: np.ndarray, edges: np.ndarray) -> dict:
        """:meth:`footprint_mean` of several frames, sharing the footprints' cells. A frame varies
        along one axis only, so its mean is the staircase of screen pixels integrated against the
        parallelogram's projection on that axis (a trapezoid: two boxes convolved), exactly, by
        second antiderivatives. Off the screen (centre outside) 0; white and black by the centre."""
        w, h = self.resolution
        on = (cx >= 0) & (cx < w) & (cy >= 0) & (cy < h)
        out, cells = {}, {}
        for name in names:
            if name in ("white", "black"):
                out[name] = np.where(on, 1.0 if name == "white" else 0.0, 0.0)
                continue
            k = 0 if name.startswith("x") else 1
            if k not in cells:
                c = cx if k == 0 else cy
                a = np.maximum(np.abs(edges[..., 0, k]), MIN_WIDTH_PX)
                b = np.maximum(np.abs(edges[..., 1, k]), MIN_WIDTH_PX)
                points = [c + (a + b) / 2, c + (a - b) / 2, c - (a - b) / 2, c - (a + b) / 2]
                cells[k] = ([_cell(p, self.length("x" if k == 0 else "y")) for p in points], a * b)
            parts, area = cells[k]
            g = _Staircase(self.profile(name).astype(float) / 255.0)
            total = g(parts[0]) - g(parts[1]) - g(parts[2]) + g(parts[3])
            out[name] = np.where(on, total / area, 0.0)
        return out

    def to_mm(self, axis: str, c: np.ndarray) -> np.ndarray:
        """Screen coordinate (px, continuous) along ``axis`` -> mm in the screen's frame (module docstring)."""
        half = self.length(axis) * self.pitch / 2
        return c * self.pitch - half if axis == "x" else half - c * self.pitch

    def from_mm(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Screen-frame mm (u, v) -> continuous screen coordinates (c_x, c_y) px."""
        w, h = self.resolution
        return (u + w * self.pitch / 2) / self.pitch, (h * self.pitch / 2 - v) / self.pitch
