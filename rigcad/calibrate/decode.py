"""Camera images of one capture (one screen height) -> the screen point each camera pixel sees.

Per axis: the phase of each period by the N-step formula phi = atan2(sum I_n sin d_n, sum I_n cos
d_n), d_n = 2 pi n / N, with mean A = sum I_n / N, amplitude B = 2 |sum I_n e^{i d_n}| / N and
modulation B / A; the Gray code (thresholded halfway between the black and white frames) numbers
the stripes of half the coarsest period, which unwraps the coarsest phase; each finer period is
unwrapped from the one before (temporal unwrapping, Huntley and Saldner 1993). Unwrapping check: a
pixel whose Gray stripe centre lies further than 3/4 of a stripe from its unwrapped coarse position,
or whose next finer position rounds within 0.15 of a period from the ambiguity, is not refined
past the last level that agreed (the coarse level failing: the pixel is not decoded). A pixel is
decoded when it is lit (white - black above ``LIT_FRACTION`` of the image's 99th percentile, or of
the paraboloid's image's where that is lower: :func:`decode`) and its coarsest sinusoids show at
least ``min_modulation`` in both axes. Coordinates as :mod:`rigcad.calibrate.patterns` (screen px,
continuous; mm in the screen frame)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigcad.calibrate.patterns import AXES, Sequence

#: Lit pixels: white - black above this fraction of its 99th percentile over the image (or over the
#: paraboloid's image, if dimmer: :func:`decode`). Below it a pixel sees no screen (the beam, the
#: paraboloid's shadow, past the screen's edge).
LIT_FRACTION = 0.05
#: Unwrapping check margins (fractions of a Gray stripe, of a period): see the module docstring.
GRAY_MARGIN = 0.75
PERIOD_MARGIN = 0.35


@dataclass
class Fringes:
    """One period's phase (rad, [0, 2 pi)), mean and amplitude (image units) per camera pixel, and
    the RMS misfit of the N frames to a sinusoid relative to the amplitude (NaN for N = 3, exact)."""

    phase: np.ndarray
    mean: np.ndarray
    amplitude: np.ndarray
    misfit: np.ndarray

    @property
    def modulation(self) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.mean > 0, self.amplitude / self.mean, 0.0)


def fringes(frames: list[np.ndarray]) -> Fringes:
    """The N-step phase of ``frames`` (N images (h, w), shifted by 2 pi n / N in order)."""
    n = len(frames)
    d = 2 * np.pi * np.arange(n) / n
    stack = np.stack([np.asarray(f, float) for f in frames])
    s = np.tensordot(np.sin(d), stack, axes=1)
    c = np.tensordot(np.cos(d), stack, axes=1)
    mean = stack.mean(axis=0)
    amp = 2 * np.hypot(s, c) / n
    phase = np.mod(np.arctan2(s, c), 2 * np.pi)
    if n > 3:
        dn = d.reshape((-1,) + (1,) * mean.ndim)
        model = mean[None] + amp[None] * np.cos(phase[None] - dn)
        with np.errstate(divide="ignore", invalid="ignore"):
            misfit = np.sqrt(np.mean((stack - model) ** 2, axis=0)) / amp
    else:
        misfit = np.full(mean.shape, np.nan)
    return Fringes(phase, mean, amp, misfit)


def gray_to_index(bits: list[np.ndarray]) -> np.ndarray:
    """Stripe numbers from Gray-code bits (most significant first; bool arrays)."""
    binary = bits[0].astype(np.int64)
    out = binary.copy()
    for b in bits[1:]:
        binary = binary ^ b.astype(np.int64)
        out = (out << 1) | binary
    return out


@dataclass
class AxisDecode:
    """One axis: the unwrapped screen coordinate (px, NaN where not decoded), the finest level
    used per pixel (-1 none), the Gray-unwrapping failures and the fringes of each period."""

    coordinate: np.ndarray
    level: np.ndarray
    gray_failures: np.ndarray
    fringes: list[Fringes] = field(repr=False)
    #: per finer period (levels 1..): (pixels modulated enough to refine, of which disagreed with
    #: the coarser level)
    disagreements: list[tuple[int, int]] = field(default_factory=list)


def decode_axis(seq: Sequence, axis: str, images: dict[str, np.ndarray], white: np.ndarray, black: np.ndarray,
                lit: np.ndarray, min_modulation: float) -> AxisDecode:
    """Decode ``axis`` (module docstring) from ``images`` (frame name -> camera image)."""
    threshold = 0.5 * (white + black)
    g = gray_to_index([images[f"{axis}_gray{b}"] > threshold for b in range(seq.gray_bits)])
    centre = (g + 0.5) * seq.stripe
    fr = [fringes([images[f"{axis}_p{p}_s{n}"] for n in range(seq.steps)]) for p in seq.periods]
    p0 = seq.periods[0]
    x = p0 * fr[0].phase / (2 * np.pi)
    x = x + p0 * np.round((centre - x) / p0)
    ok = lit & (fr[0].modulation >= min_modulation)
    gray_fail = ok & (np.abs(centre - x) > GRAY_MARGIN * seq.stripe)
    ok &= ~gray_fail
    level = np.where(ok, 0, -1)
    active = ok.copy()
    disagreements = []
    for k, p in enumerate(seq.periods[1:], start=1):
        xf = p * fr[k].phase / (2 * np.pi)
        turns = (x - xf) / p
        xf = xf + p * np.round(turns)
        agree = np.abs(turns - np.round(turns)) < PERIOD_MARGIN
        active &= fr[k].modulation >= min_modulation
        disagreements.append((int(active.sum()), int((active & ~agree).sum())))
        active &= agree
        x = np.where(active, xf, x)
        level = np.where(active, k, level)
    return AxisDecode(np.where(ok, x, np.nan), level, gray_fail, fr, disagreements)


def jump_fraction(coordinate: np.ndarray, limit: float) -> float:
    """Fraction of runs of three neighbouring decoded pixels (along rows and columns) whose second
    difference exceeds ``limit`` (screen px): ~0 for a capture in order, where the map is smooth
    however steep (near grazing, neighbours see points millimetres apart) but at the screen's and the
    shadows' edges; a Gray bit or a period out of order tears the map into whole-period steps that no
    per-pixel check sees."""
    c = np.asarray(coordinate, float)
    runs = tears = 0
    for second in (c[2:, :] - 2 * c[1:-1, :] + c[:-2, :], c[:, 2:] - 2 * c[:, 1:-1] + c[:, :-2]):
        ok = np.isfinite(second)
        runs += int(ok.sum())
        tears += int((np.abs(second[ok]) > limit).sum())
    return tears / runs if runs else 0.0


@dataclass
class Decoded:
    """One capture decoded: the screen point (mm, screen frame) each camera pixel sees (u, v: (h, w),
    NaN where not decoded), the masks and the axes' details."""

    u: np.ndarray
    v: np.ndarray
    lit: np.ndarray
    valid: np.ndarray
    axes: dict[str, AxisDecode]

    def jumps(self, stripe: float) -> dict[str, float]:
        """Per axis, :func:`jump_fraction` at one Gray stripe (screen px, half the coarsest period)."""
        return {a: jump_fraction(d.coordinate, stripe) for a, d in self.axes.items()}

    def stats(self) -> dict:
        lit = int(self.lit.sum())
        return {"lit_pixels": lit, "decoded_pixels": int(self.valid.sum()),
                "gray_unwrapping_failures": {a: int(d.gray_failures.sum()) for a, d in self.axes.items()},
                "finest_level_pixels": {a: [int((d.level == k).sum()) for k in range(len(d.fringes))]
                                        for a, d in self.axes.items()},
                "finer_period_disagreements": {a: [list(t) for t in d.disagreements] for a, d in self.axes.items()}}


def decode(seq: Sequence, images: dict[str, np.ndarray], min_modulation: float,
           reference: np.ndarray | None = None) -> Decoded:
    """Decode one capture (``images``: every frame of ``seq.names()``, float camera images).
    ``reference`` ((h, w) bool, optional): the pixels of the paraboloid's image
    (:meth:`rigcad.calibrate.model.Camera.mirrored_core`). The lit threshold is then taken from
    the dimmer of the image's and their 99th percentiles: the mirrors keep ``coating.reflectance``
    squared of the screen's light, and a threshold on the screen seen directly around them would
    drop the mirrored pixels that see a screen's edge in part."""
    white, black = np.asarray(images["white"], float), np.asarray(images["black"], float)
    contrast = white - black
    top = float(np.percentile(contrast, 99)) if contrast.size else 0.0
    if reference is not None and reference.any():
        top = min(top, float(np.percentile(contrast[reference], 99)))
    lit = contrast > LIT_FRACTION * top if top > 0 else np.zeros(contrast.shape, bool)
    axes = {a: decode_axis(seq, a, images, white, black, lit, min_modulation) for a in AXES}
    cx, cy = axes["x"].coordinate, axes["y"].coordinate
    valid = np.isfinite(cx) & np.isfinite(cy)
    u = np.where(valid, seq.to_mm("x", cx), np.nan)
    v = np.where(valid, seq.to_mm("y", cy), np.nan)
    return Decoded(u, v, lit, valid, axes)
