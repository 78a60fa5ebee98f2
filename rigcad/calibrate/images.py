"""Reading a capture, and refusing a bad one with one line that names the file.

Naming scheme: a folder with one image per capture and frame, ``{label}_{frame}.{png|tif|tiff}``:
label ``h<k>`` for spacer k's capture, k its index in ``calibration.spacer_heights`` (0 first), and
``h<k>r`` for spacer k's again, turned a half turn (``calibration.half_turn``: the highest's or each's;
:class:`rigcad.calibrate.model.Plan`), ``u<j>`` for the upright display at its stand's turn j
(``calibration.upright_turns``: :mod:`rigcad.calibrate.upright`); frame a name of
:meth:`rigcad.calibrate.patterns.Sequence.names` (white, black, x_gray0.., x_p128_s0.., y_...),
e.g. ``h1_y_p16_s3.png``, ``h1r_white.png``. Grey 8- or 16-bit PNG or TIFF (colour is averaged to
grey), every image at the camera's resolution. Values are scaled to [0, 1] by the format's full scale."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rigcad.calibrate.patterns import Sequence
from rigcad.errors import RigcadError

SUFFIXES = (".png", ".tif", ".tiff")
#: All dark: the white frame's 99th percentile under this fraction of full scale.
DARK_LEVEL = 0.04
#: Saturated: more than this fraction of the lit pixels at full scale in the white frame.
SATURATED_FRACTION = 0.05
#: Too little modulation: fewer than this fraction of the lit pixels decoded.
MIN_DECODED_FRACTION = 0.3
#: Out of order: more than this fraction of runs of three neighbouring decoded pixels with a second
#: difference over a Gray stripe. Measured on Table 3.1 (seeds 102, 103, 105, every capture; the
#: larger axis): 0.12-0.57 % in good captures; two Gray frames of one axis swapped: bits 1 and 3,
#: 1.9-2.5 %; bits 2 and 5 or 4 and 5, 7-9 %; the two most significant, 0.6-1.2 % (caught or not:
#: they tear the map along the coarsest stripes' few edges only). The ring of the screen seen
#: directly past the paraboloid (rigcad.calibrate.model.direct_view) is smooth and dilutes the
#: fraction: 5 % let bits 1 and 3 swapped through.
MAX_JUMP_FRACTION = 0.01
#: Out of order: a finer period disagreeing with the coarser one at more than this fraction of the
#: pixels it modulates (a reversed or shuffled step order still fits a sinusoid, at the wrong phase).
MAX_DISAGREEMENT = 0.2
#: Out of order (N >= 4): the median misfit of a period's frames to a sinusoid above this.
MAX_MISFIT = 0.35
#: Not turned: a half turn's capture whose screen points turn from its partner's by more than this
#: (deg) away from 180 (a forgotten or a quarter turn; the fit finds the hand's degree or so).
HALF_TURN_SLACK_DEG = 20.0


class CaptureError(RigcadError):
    """A capture that cannot be calibrated from: the message names the file and what is wrong."""


def capture_path(folder: Path, label: str, name: str) -> Path:
    """The file of capture ``label`` (``h0``, ``h1r``...) and frame ``name`` (any of SUFFIXES), or the
    .png expected. Whatever is there under one of the names counts (a FIFO, a folder, a link to
    nowhere): :func:`read_image` says what it is."""
    for suffix in SUFFIXES:
        p = folder / f"{label}_{name}{suffix}"
        if os.path.lexists(p):
            return p
    return folder / f"{label}_{name}.png"


#: The naming scheme, said when a frame is missing.
NAMING = ("naming scheme h<spacer>_<frame>.png|tif, h<spacer>r_ for the half turn, u<turn>_ for the upright "
          "display: see docs/calibrate.md")
#: Most bytes a frame's file may hold per camera pixel (a 32-bit float RGBA TIFF, uncompressed: 16),
#: and the headers' allowance.
FRAME_BYTES_PER_PIXEL = 16
FRAME_HEADER_BYTES = 1 << 20


def read_image(path: Path, resolution: tuple[int, int], window=None) -> np.ndarray:
    """One image as float in [0, 1] (rows, cols), checked for existence and size. ``window``: a
    function that cuts the camera's window out of the image as read (``model.Camera.crop``), before
    the colour is averaged and the values made floats: a full 1360 x 1024 frame made floats is
    11 MB, and 240 of them cost more CPU than the decoding (docs/calibrate.md); the same values,
    pixel for pixel. Full scale: 65535 for 16-bit files (as read), else 255.

    Read as data (rigcad.export.readback): a regular file of at most FRAME_BYTES_PER_PIXEL bytes per
    camera pixel, its size from the header checked against the camera's before a pixel is decoded,
    no NaN or infinite value; each refusal one line naming the file."""
    from rigcad.export.readback import open_image, read_bytes, shown

    width, height = resolution
    data = read_bytes(path, "a capture frame", width * height * FRAME_BYTES_PER_PIXEL + FRAME_HEADER_BYTES,
                      CaptureError, missing=NAMING)

    def size_ok(size: tuple[int, int]) -> str | None:
        return None if tuple(size) == (width, height) else f"the camera's is {width} x {height}"

    with open_image(data, shown(path), size_ok, CaptureError) as im:
        arr = np.asarray(im)
    if arr.dtype.kind == "f":
        bad = ~np.isfinite(arr)
        if bad.any():
            raise CaptureError(f"{shown(path)}: {int(bad.sum())} pixel value(s) NaN or infinite: a capture holds "
                               "finite values")
    elif arr.dtype.kind not in "uib":
        raise CaptureError(f"{shown(path)}: pixels of type {arr.dtype}, not integers or floats")
    if arr.shape[:2] != (height, width):
        raise CaptureError(f"{path}: {arr.shape[1]} x {arr.shape[0]} px, the camera's is {width} x {height}")
    full = 65535.0 if arr.dtype == np.uint16 or arr.max() > 255 else 255.0
    if window is not None:
        arr = window(arr)
    if arr.ndim == 3:
        arr = arr[..., :3].mean(axis=2) if arr.shape[2] >= 3 else arr[..., 0]
    return arr.astype(float) / full


def read_capture(folder: Path, seq: Sequence, labels: tuple[str, ...], resolution: tuple[int, int],
                 absent: str = "", window=None) -> list[dict]:
    """Every frame of every capture (``labels``: the plan's, module docstring), exposure-checked on
    the whole white and black frames, then cut to ``window`` (:func:`read_image`; all whole without).
    ``absent``: what to say when a capture has none of its files (how to calibrate without it)."""
    out = []
    for k in labels:
        if absent and not any(os.path.lexists(capture_path(folder, k, n)) for n in seq.names()):
            raise CaptureError(f"{capture_path(folder, k, 'white')}: missing, and every other frame of capture {k}: "
                               f"{absent}")
        whole = ("white", "black")
        frames = {n: read_image(capture_path(folder, k, n), resolution, None if n in whole else window)
                  for n in seq.names()}
        check_exposure(folder, k, frames)
        if window is not None:
            frames.update({n: window(frames[n]).copy() for n in whole})  # the whole frames freed
        out.append(frames)
    return out


def check_exposure(folder: Path, k: str, frames: dict) -> None:
    """All dark, saturated, or white and black swapped."""
    white, black = frames["white"], frames["black"]
    path = capture_path(folder, k, "white")
    if np.percentile(white, 99) < DARK_LEVEL:
        raise CaptureError(f"{path}: all dark (99th percentile {np.percentile(white, 99):.3f} of full scale): "
                           "is the screen on and the lens cap off?")
    if white.mean() < black.mean():
        raise CaptureError(f"{path}: darker than {capture_path(folder, k, 'black').name}: frames in the wrong order")
    lit = white - black > 0.05 * np.percentile(white - black, 99)
    sat = float(np.mean(white[lit] >= 1.0)) if lit.any() else 0.0
    if sat > SATURATED_FRACTION:
        raise CaptureError(f"{path}: saturated ({sat:.0%} of the lit pixels at full scale): shorten the exposure")


def check_decoded(folder: Path, k: str, seq: Sequence, decoded, mirrored: np.ndarray | None = None) -> None:
    """Too little modulation (over the lit pixels, and over those of ``mirrored``, the window's
    pixels that see the paraboloid in any build: :meth:`rigcad.calibrate.model.Camera.mirrored_core`),
    or frames out of order (torn map, misfit to a sinusoid)."""
    lit = int(decoded.lit.sum())
    first = capture_path(folder, k, f"x_p{seq.periods[0]}_s0")
    if lit == 0 or decoded.valid.sum() < MIN_DECODED_FRACTION * lit:
        raise CaptureError(f"{first}: too little modulation: {int(decoded.valid.sum())} of {lit} lit pixels decoded "
                           "(focus on the screen, raise the exposure or the screen's brightness)")
    core = decoded.lit & mirrored if mirrored is not None else None
    if core is not None and core.any() and decoded.valid[core].sum() < MIN_DECODED_FRACTION * core.sum():
        raise CaptureError(f"{first}: too little modulation in the paraboloid's image: {int(decoded.valid[core].sum())} "
                           f"of its {int(core.sum())} lit pixels decoded, though the screen seen directly around it "
                           "decodes (focus on the paraboloid's image; clean the mirrors)")
    for axis, frac in decoded.jumps(seq.stripe).items():
        if frac > MAX_JUMP_FRACTION:
            raise CaptureError(f"{capture_path(folder, k, f'{axis}_gray0')}: the {axis} frames decode to a torn map "
                               f"({frac:.0%} of neighbouring pixels step by a stripe or more): Gray or phase frames in the wrong order")
    for axis, d in decoded.axes.items():
        for p, (tried, failed) in zip(seq.periods[1:], d.disagreements):
            if tried and failed > MAX_DISAGREEMENT * tried:
                raise CaptureError(f"{capture_path(folder, k, f'{axis}_p{p}_s0')}: period {p} disagrees with the "
                                   f"coarser one at {failed / tried:.0%} of the pixels it modulates: phase frames "
                                   "in the wrong order")
    if seq.steps > 3:
        for axis, d in decoded.axes.items():
            for p, fr in zip(seq.periods, d.fringes):
                mis = float(np.nanmedian(fr.misfit[decoded.valid])) if decoded.valid.any() else 0.0
                if mis > MAX_MISFIT:
                    raise CaptureError(f"{capture_path(folder, k, f'{axis}_p{p}_s0')}: the {seq.steps} phase "
                                       f"steps of period {p} do not fit a sinusoid (misfit {mis:.2f}): "
                                       "frames in the wrong order")


def check_half_turns(folder: Path, plan, decoded: list) -> None:
    """A half turn's capture (``plan``: :class:`rigcad.calibrate.model.Plan`) whose screen did not
    turn a half turn from its partner's: the rotation between the screen points the two decode at
    the same camera pixels (2D Procrustes over the pixels both decoded) is its turn."""
    for c, d in enumerate(decoded):
        first = plan.repeats(c)
        if first is None:
            continue
        a, b = decoded[first], d
        both = (a.valid & b.valid).ravel()
        if both.sum() < 3:
            continue  # too little modulation is its own refusal (check_decoded)
        p = np.stack([a.u.ravel()[both], a.v.ravel()[both]], axis=1)
        q = np.stack([b.u.ravel()[both], b.v.ravel()[both]], axis=1)
        p, q = p - p.mean(axis=0), q - q.mean(axis=0)
        turn = float(np.degrees(np.arctan2(np.sum(p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0]), np.sum(p * q))))
        if 180.0 - abs(turn) > HALF_TURN_SLACK_DEG:  # turn in [-180, 180]
            raise CaptureError(f"{capture_path(folder, plan.labels[c], 'white')}: its screen points are turned "
                               f"{abs(turn):.0f} deg from {plan.labels[first]}'s, not a half turn: turn the spacer "
                               "and the screen on it by 180 deg together (docs/calibrate.md, 'The half turn')")
