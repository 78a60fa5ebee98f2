"""The reflectance calibration of thesis 4.1.2: an 18 % diffuse gray card in the sample holder, the
zonal basis images up to order 2 projected, each captured at several exposures; from those
captures the camera's response curve, the linear radiance of each capture and the rig's scale
factors, with a pass criterion (``rigcad calibrate PROFILE --gray-card DIR``, docs/calibrate.md).

The capture (:class:`Plan`): per basis function Z_l^m (l <= 2, the thesis's order: a Lambertian
slice lies in the first two orders) its positive and its negative image, named as ``rigcad basis``
names them (``z_<l>_<m signed>_<pos|neg>``), each at every exposure: files
``z_<l>_<m>_<pos|neg>_<ms>ms.png|tif|tiff`` (e.g. ``z_1_+0_neg_62.5ms.png``), 8- or 16-bit, grey or
colour (averaged to grey), every image at the camera's resolution, as ``--images`` reads them
(:func:`rigcad.calibrate.images.read_image`). The thesis's exposures: 62.5, 125 and 250 ms.

The model. A camera pixel p sees the card along its exitant direction; the card (Lambertian,
albedo rho) sends the same radiance every way, so with frame k shown the pixel records

    X_k(p) = t(p) * sum_j q_jk kappa g_j (rho / pi) cos(theta_j) w_j

(j the lit projector pixels: level q_jk, incidence angle theta_j, solid angle w_j sr; kappa the
projector's radiance per level; g_j the light path's own throughput towards direction j: mirror
coat, projector vignetting; t(p) the camera side's: coat, lens vignetting). X is separable: the
camera side t(p) times a vector over the frames. The fit: X = t v by the first singular pair,
t normalised to a median of 1; kappa g expanded in the zonal basis to the capture's order (the
thesis: the card's hemispherical reflectance from the measured coefficients),
v = (rho / pi) A b with A_km = sum_j q_jk Z_m(w_j) cos(theta_j) w_j. The scale factors are then
1 / t(p) per camera pixel and lambda(w_i) = 1 / (kappa g(w_i)) per incidence direction: eq. 4.2,
lambda = f_r,0.18 / f_r,gray, with the card's measured reflectance f_r,gray = kappa g rho / pi.
:func:`calibrated` applies them to a sample's captures of any order.

The response curve: Debevec and Malik (SIGGRAPH 1997), the log inverse response g(z) on 256 knots
over the full scale (values between knots interpolated, so 16-bit captures need no binning)
solved by least squares with a second-difference smoothness term, the hat weighting, anchored at
mid-scale; written here because OpenCV's CalibrateDebevec takes 8-bit images only. Each capture's
linear radiance (per second of exposure, the curve's arbitrary unit) is the weighted mean over its
exposures.

Units: mm and radians inside; exposures in seconds (ms in file names and reports); radiance in the
response curve's unit per second.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigcad.calibrate.images import SUFFIXES, CaptureError

#: The thesis's card (4.1.2): 18 % diffuse reflectance.
CARD_ALBEDO = 0.18
#: The thesis's order (4.1.2): a Lambertian slice lies in the first two orders (Ramamoorthi).
ORDER = 2
#: The thesis's exposures (Figure 4.4), ms.
EXPOSURES_MS = (62.5, 125.0, 250.0)
#: The response curve's bracket (ms): the flat white field (every lit projector pixel at full level)
#: at seven exposures a factor 2 apart, from an eighth of the shortest to twice the longest (the
#: thesis fitted its curve to 6-7 images of a scene at different exposures, 4.2.3): the card's
#: frames alone span too little of the scale (their medians lie within 0.25-0.8 of full scale).
RESPONSE_EXPOSURES_MS = (7.8125, 15.625, 31.25, 62.5, 125.0, 250.0, 500.0)
#: The flat field's frame name.
WHITE = "white"
#: The prefix of the frames captured again with the card turned a half turn.
TURNED = "turned_"
#: A value at or above this fraction of full scale is saturated (8 bit: 250 of 255): it says only
#: that the radiance is at least so much, and gets no weight.
SATURATED = 250.0 / 255.0
#: Refused: more than this share of the card's pixels saturated at the shortest exposure (no
#: exposure measures them).
SATURATED_SHARE = 0.005
#: Refused as all dark: the brightest frame's 99th percentile over the card at the longest exposure
#: under this fraction of full scale (as the deflectometric capture's check, images.DARK_LEVEL).
DARK_LEVEL = 0.04
#: The curve's toe (fraction of full scale): below it a value is read as linear to 0 at 0, not from
#: the fitted curve. There the levels are few and the noise their size (the darkest frames, the room's
#: light alone, read 0-11 of 255 on the simulation), and the curve, extrapolated, read a frame of
#: nothing but the room's light as 8 % of the brightest frame's radiance on an S-shaped camera.
TOE = 0.05
#: Knots of the response curve over the full scale (one per 8-bit level).
KNOTS = 256
#: The curve's smoothness weight against the data's (Debevec and Malik's lambda, values in [0, 1]):
#: a second difference of 1e-3 (log units per knot) costs as much as a 1 % misfit of ~30 samples.
SMOOTHNESS = 30.0
#: The smoothness weight's floor, as a share of the hat's peak: where the hat gives the data little
#: weight (the darkest levels) the curve still follows them rather than a straight line.
SMOOTHNESS_FLOOR = 0.005
#: Card pixels of the flat field the curve is fitted to: ranked by brightness, evenly spread.
CURVE_SAMPLES = 400
#: Brightness bins the samples are spread over.
CURVE_BINS = 40
#: Well exposed, for the exposures' agreement: a value between these fractions of full scale (below,
#: an 8-bit level is over 2 % of a gamma-2.2 camera's radiance; above, the knee).
WELL_EXPOSED = (0.2, 0.9)
#: The separable fit's residual is judged over blocks of this many pixels a side (~6 deg of exitant
#: direction at the camera's ~0.8 deg per pixel): a pixel's own is mostly noise and 8-bit levels.
BLOCK_PX = 8
#: Pixels within this many of the edge of the card's region in the camera (the beam's shadow, the
#: paraboloid's rim) are left out: their footprint straddles it.
EDGE_PX = 2

# -- the pass criterion (each figure, its bound, and why) -------------------------------------------
#: The exposures' agreement: the RMS relative spread of a well-exposed block's radiance between its
#: exposures once the curve is applied. With the right curve and exposure times only noise and the
#: 8-bit levels are left: 0.19-0.39 % on the simulation (gamma and S-shaped cameras, seeds 0-9,
#: bench/results/graycard.json); tests/calibrate/test_graycard.py fails a mislabelled exposure and a
#: camera taken as linear on it.
MAX_EXPOSURE_SPREAD = 0.015
#: The card's departure from a separable response (camera side times light side), over BLOCK_PX
#: blocks, the 95th percentile: a Lambertian card's radiance is the same towards every camera pixel,
#: so what is left is noise and the curve's error: 0.39-0.45 % on the simulation. A glossy card, or a
#: camera pixel that sees something else than the card (the holder's rim), leaves more.
MAX_SEPARABLE_RESIDUAL = 0.02
#: The light side's spread over the lit directions, largest over smallest kappa g: the projector's
#: light through two mirrors varies smoothly; past 2x the weakest-lit directions get under half the
#: median's light (a dirty zone of a mirror, a shadow). The simulation plants ~1.23x (measured
#: 1.22-1.30x). A card tilted in its holder cannot be told from the light (cos of the tilted normal
#: over cos theta reads as light): 1 deg gives 1.32-1.39x and moves the light side by 7-10 % from a
#: flat card's, 2 deg 1.47-1.53x and 13-16 % (seeds 0-9): the card must lie flat in the holder; this
#: bound does not catch a small tilt.
MAX_ILLUMINATION_RATIO = 2.0
#: The card's tilt, when the half turn measures it (deg). The two captures' mean takes it out of the
#: light side: tilted 0.5, 1 and 2 deg, the light side is within 3.0-3.7 % of the flat card's, as
#: flat (3.4 %), against 6-16 % from one capture; the tilt itself is measured within 0.05 deg (seed 0,
#: one-off; tests/calibrate/test_graycard.py holds 1 deg). A card leaning more than this does not lie
#: on the holder's seat, where a sample will lie: seat it again.
MAX_TILT_DEG = 1.0
#: Camera pixels whose throughput t is off the median by more than this factor are outliers (dust, a
#: scratch in the coat, the holder's edge); at most MAX_OUTLIER_SHARE of the card's pixels may be.
OUTLIER_FACTOR = 2.0
MAX_OUTLIER_SHARE = 0.005
#: The brightest frame at the longest exposure must fill at least this fraction of full scale
#: (median over the card): below, one 8-bit level is over 1.5 % of the signal.
MIN_FILL = 0.25


class GrayCardError(CaptureError):
    """A gray card capture that cannot be calibrated from: the message names the file and what is
    expected."""


# -- the capture -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Plan:
    """The frames (basis functions up to ``order``, positive and negative image each) and the
    exposures (ms) of a gray card capture (module docstring)."""

    order: int = ORDER
    exposures_ms: tuple[float, ...] = EXPOSURES_MS
    response_exposures_ms: tuple[float, ...] = RESPONSE_EXPOSURES_MS
    #: the frames again with the card turned a half turn in the holder (files ``turned_<frame>_<ms>ms``):
    #: a tilt of the card turns with it, the light does not (:func:`card_tilt`)
    turned: bool = False

    def __post_init__(self) -> None:
        for name, e, least in (("--exposures-ms", self.exposures_ms, 2),
                               ("--response-exposures-ms", self.response_exposures_ms, 3)):
            if (len(e) < least or any(not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0) for v in e)
                    or len(set(e)) != len(e)):
                raise GrayCardError(f"{name} {' '.join(f'{v:g}' for v in e)}: need {least} or more different "
                                    "exposure times in ms, each > 0 (defaults: "
                                    f"{' '.join(f'{v:g}' for v in (EXPOSURES_MS if least == 2 else RESPONSE_EXPOSURES_MS))})")
            object.__setattr__(self, "exposures_ms" if least == 2 else "response_exposures_ms",
                               tuple(sorted(float(v) for v in e)))
        if not (isinstance(self.order, int) and 1 <= self.order <= ORDER):
            raise GrayCardError(f"gray card order {self.order!r}: need 1 or 2 (thesis 4.1.2: 2)")

    @property
    def lm(self) -> tuple[tuple[int, int], ...]:
        """(l, m) of each basis function, in basis order k = l^2 + l + m."""
        return tuple((l, m) for l in range(self.order + 1) for m in range(-l, l + 1))

    def frames(self) -> tuple[str, ...]:
        """Each projected image's name (``rigcad basis``'s file names without .png), positive then
        negative per function."""
        return tuple(f"z_{l}_{m:+d}_{part}" for l, m in self.lm for part in ("pos", "neg"))

    @property
    def exposures_s(self) -> np.ndarray:
        return np.array(self.exposures_ms) / 1e3

    @property
    def response_exposures_s(self) -> np.ndarray:
        return np.array(self.response_exposures_ms) / 1e3

    def files(self) -> list[tuple[str, float]]:
        """Every (frame, exposure ms) the capture holds: the flat field's bracket, then the frames."""
        return ([(WHITE, e) for e in self.response_exposures_ms]
                + [(f, e) for f in self.frames() for e in self.exposures_ms]
                + ([(TURNED + f, e) for f in self.frames() for e in self.exposures_ms] if self.turned else []))

    def path(self, folder: Path, frame: str, e: int) -> Path:
        """The file of ``frame`` at exposure ``e`` (index into the frame's exposures, the bracket's
        for WHITE): whichever of SUFFIXES is there, else .png."""
        ms = (self.response_exposures_ms if frame == WHITE else self.exposures_ms)[e]
        stem = f"{frame}_{ms:g}ms"
        for suffix in SUFFIXES:
            p = Path(folder) / f"{stem}{suffix}"
            if os.path.lexists(p):
                return p
        return Path(folder) / f"{stem}.png"

    def with_turned(self, folder: Path) -> "Plan":
        """This plan, with the half turn's frames when ``folder`` holds any of them."""
        import dataclasses

        turned = any(os.path.lexists(self.path(folder, TURNED + f, e))
                     for f in self.frames() for e in range(len(self.exposures_ms)))
        return dataclasses.replace(self, turned=turned)

    def naming(self) -> str:
        return (f"the white field at {', '.join(f'{v:g}' for v in self.response_exposures_ms)} ms and "
                f"{len(self.frames())} frames z_<l>_<m>_<pos|neg> (l <= {self.order}) at "
                f"{', '.join(f'{v:g}' for v in self.exposures_ms)} ms, named <frame>_<ms>ms.png|tif "
                f"(e.g. white_{self.response_exposures_ms[0]:g}ms.png, {self.frames()[2]}_{self.exposures_ms[0]:g}ms.png)"
                + (f", and the frames again with the card turned a half turn, {TURNED}<frame>_<ms>ms" if self.turned else ""))


@dataclass(frozen=True)
class Light:
    """The projector's side (:func:`rigcad.basis.card_light.card_light`), per lit projector pixel j
    (n,): the levels shown in each frame, ``positive`` and ``negative`` (n, K), the zonal basis
    values ``zonal`` (n, K) at its unit incidence ``direction`` (n, 3) (sample frame, from O
    towards the light), its solid angle ``weight_sr`` (sr), its ``row``/``col`` in the projector's ``resolution`` (width,
    height); the images' ``bits`` and scale (the value of full level, 1/sqrt(sr)), the zone's lower
    edge ``alpha_rad``, the ``order`` and each function's (l, m) ``lm``."""

    positive: np.ndarray
    negative: np.ndarray
    zonal: np.ndarray
    direction: np.ndarray
    weight_sr: np.ndarray
    row: np.ndarray
    col: np.ndarray
    resolution: tuple[int, int]
    bits: int
    scale_per_sqrt_sr: float
    alpha_rad: float
    order: int
    lm: tuple

    @property
    def cos_theta(self) -> np.ndarray:
        return self.direction[:, 2]

    @property
    def levels(self) -> np.ndarray:
        """Signed levels (n, K): positive minus negative image."""
        return self.positive - self.negative

    def cosine_matrix(self) -> np.ndarray:
        """A (K, K): A_km = sum_j q_jk Z_m(w_j) cos(theta_j) w_j (module docstring)."""
        return self.levels.T.astype(float) @ (self.zonal * (self.cos_theta * self.weight_sr)[:, None])

    @property
    def full_level(self) -> int:
        return (1 << self.bits) - 1

    def image(self, frame: str) -> np.ndarray:
        """The projector frame (uint8/uint16) of ``frame``: a :meth:`Plan.frames` name, or WHITE
        (every lit pixel at full level)."""
        width, height = self.resolution
        out = np.zeros((height, width), dtype=np.uint8 if self.bits == 8 else np.uint16)
        out[self.row, self.col] = self.frame_levels(frame)
        return out

    def frame_levels(self, frame: str) -> np.ndarray:
        """The levels (n,) the lit pixels show in ``frame`` (a :meth:`Plan.frames` name or WHITE)."""
        if frame == WHITE:
            return np.full(len(self.row), self.full_level, dtype=np.int64)
        _, l, m, part = frame.split("_")
        k = self.lm.index((int(l), int(m)))
        return (self.positive if part == "pos" else self.negative)[:, k]


@dataclass(frozen=True)
class View:
    """The camera's side: the window of the calibration's camera (:class:`rigcad.calibrate.model.Camera`),
    which of its pixels see the card through the mirrors (``used`` (rows, cols), away from every
    edge), and each window pixel's design exitant direction (theta_o, phi_o rad; NaN where none)."""

    cam: object
    used: np.ndarray
    theta_o: np.ndarray
    phi_o: np.ndarray


def view_of(rig) -> View:
    """The card's pixels in the camera: traced through the rig as designed (the calibration's own
    tracer, :func:`rigcad.calibrate.model.trace_camera`), reaching the sample off both mirrors, in the
    annulus that sees the paraboloid in any build within ``tolerancing``
    (:meth:`~rigcad.calibrate.model.Camera.mirrored_core`), EDGE_PX from any other pixel."""
    from scipy.ndimage import binary_erosion

    from rigcad.calibrate import model as M
    from rigcad.check.scene import analytic_optics
    from rigcad.check.sources import pixel_rays

    cam = M.Camera.of(rig)
    tr = M.trace_camera(analytic_optics(rig), rig, cam.x_px, cam.y_px, cam.design)
    seen = tr.ok.reshape(cam.shape) & cam.mirrored_core(rig)
    used = binary_erosion(seen, iterations=EDGE_PX, border_value=0)
    d = cam.design.direction(pixel_rays(cam.design, cam.x_px, cam.y_px).dirs)
    theta = np.arctan2(np.hypot(d[:, 0], d[:, 1]), d[:, 2])
    return View(cam, used, theta, np.arctan2(d[:, 1], d[:, 0]))


@dataclass(frozen=True)
class Capture:
    """A gray card capture cut to the camera's window, in [0, 1] of full scale: the flat field's
    bracket ``white`` (response exposures, rows, cols) and the basis frames ``frames`` (frames,
    exposures, rows, cols), in :class:`Plan`'s orders."""

    white: np.ndarray
    frames: np.ndarray
    turned: np.ndarray | None = None


def check_present(folder: Path, plan: Plan) -> list[Path]:
    """Every file of the capture (:meth:`Plan.files`'s order), or a refusal naming the first missing
    one and the naming scheme (no image read: before any work)."""
    folder = Path(folder)
    index = {WHITE: plan.response_exposures_ms} | {f: plan.exposures_ms for f in plan.frames()} | {
        TURNED + f: plan.exposures_ms for f in plan.frames()}
    paths = [plan.path(folder, f, index[f].index(e)) for f, e in plan.files()]
    missing = [p for p in paths if not os.path.lexists(p)]
    if missing:
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        raise GrayCardError(f"{_shown(missing[0])}: missing{more}; the gray card's capture is {plan.naming()}")
    return paths


def read(folder: Path, plan: Plan, view: View) -> Capture:
    """Every file of the capture (:meth:`Plan.files`), cut to the camera's window; each missing,
    mis-sized, saturated, dark or mislabelled one refused with one line naming its file."""
    from rigcad.calibrate.images import read_image

    cam = view.cam
    paths = check_present(folder, plan)
    images = np.stack([read_image(p, cam.resolution, window=cam.crop) for p in paths])
    nw, nf = len(plan.response_exposures_ms), len(plan.frames()) * len(plan.exposures_ms)
    shape = (len(plan.frames()), len(plan.exposures_ms)) + cam.shape
    capture = Capture(images[:nw], images[nw:nw + nf].reshape(shape),
                      images[nw + nf:].reshape(shape) if plan.turned else None)
    check_exposures(folder, plan, view, capture)
    return capture


def check_exposures(folder: Path, plan: Plan, view: View, capture: Capture) -> None:
    """Refuse a capture whose card pixels are saturated at the shortest exposure (a frame's, or the
    flat field's), all dark, or whose exposures do not brighten as their times grow (mislabelled)."""
    used = view.used
    shortest = ([(WHITE, capture.white[0])] + [(f, capture.frames[i, 0]) for i, f in enumerate(plan.frames())]
                + ([(TURNED + f, capture.turned[i, 0]) for i, f in enumerate(plan.frames())] if plan.turned else []))
    for f, image in shortest:
        sat = float(np.mean(image[used] >= SATURATED))
        if sat > SATURATED_SHARE:
            ms = (plan.response_exposures_ms if f == WHITE else plan.exposures_ms)[0]
            raise GrayCardError(f"{_shown(plan.path(folder, f, 0))}: saturated ({sat:.1%} of the card's pixels at full "
                                f"scale at the shortest exposure, {ms:g} ms): shorten the exposures or dim the "
                                "projector")
    top = capture.white[-1][used]
    if np.percentile(top, 99) < DARK_LEVEL:
        raise GrayCardError(f"{_shown(plan.path(folder, WHITE, len(plan.response_exposures_ms) - 1))}: all dark (99th "
                            f"percentile {np.percentile(top, 99):.3f} of full scale over the card): is the projector "
                            "on, the lens cap off, the card in the holder?")
    bright = int(np.argmax([np.median(capture.frames[i, -1][used]) for i in range(len(plan.frames()))]))
    series_checked = [(WHITE, capture.white, plan.response_exposures_ms),
                      (plan.frames()[bright], capture.frames[bright], plan.exposures_ms)]
    if plan.turned:
        series_checked.append((TURNED + plan.frames()[bright], capture.turned[bright], plan.exposures_ms))
    for f, series, ms in series_checked:
        med = [float(np.median(im[used])) for im in series]
        for e in range(1, len(med)):
            if med[e - 1] < SATURATED and med[e] <= med[e - 1]:
                raise GrayCardError(f"{_shown(plan.path(folder, f, e))}: not brighter than {_shown(plan.path(folder, f, e - 1).name)} "
                                    f"(median {med[e]:.3f} against {med[e - 1]:.3f} of full scale) though exposed "
                                    f"{ms[e]:g} ms against {ms[e - 1]:g} ms: exposures mislabelled")


def _shown(path) -> str:
    from rigcad.export.readback import shown

    return shown(path)


# -- the response curve --------------------------------------------------------------------------------
def weight(v: np.ndarray) -> np.ndarray:
    """Debevec and Malik's hat over [0, 1] of full scale, 0 at and above SATURATED."""
    v = np.asarray(v, float)
    return np.where(v >= SATURATED, 0.0, np.clip(np.minimum(v, SATURATED - v), 0.0, None))


@dataclass(frozen=True)
class Response:
    """The camera's log inverse response ``log_radiance`` g (KNOTS,) at ``knots`` (fractions of full
    scale): a value v comes from the linear exposure exp(g(v)) (arbitrary unit, g = 0 at mid-scale),
    linear between knots; ``covered``: the range of values the fit saw with weight."""

    knots: np.ndarray
    log_radiance: np.ndarray
    covered: tuple[float, float]

    @property
    def toe(self) -> float:
        """The value below which the curve is not read (:data:`TOE`, or the lowest value the fit saw
        with weight if higher): the exposure falls linearly from there to 0 at 0."""
        return max(TOE, self.covered[0])

    def exposure(self, v: np.ndarray) -> np.ndarray:
        """Linear exposure (radiance x time, the curve's unit) of values ``v`` in [0, 1]."""
        v = np.asarray(v, float)
        toe = self.toe
        at_toe = math.exp(float(np.interp(toe, self.knots, self.log_radiance)))
        return np.where(v >= toe, np.exp(np.interp(v, self.knots, self.log_radiance)),
                        at_toe * np.clip(v, 0.0, None) / toe)

    def monotone(self) -> bool:
        """Whether g rises over the covered range."""
        lo, hi = (int(round(c * (KNOTS - 1))) for c in self.covered)
        return bool(np.all(np.diff(self.log_radiance[lo:hi + 1]) > 0))


def block_means(images: np.ndarray, used: np.ndarray) -> np.ndarray:
    """(..., blocks) the mean of ``images`` (..., rows, cols) over the card's pixels in each
    BLOCK_PX x BLOCK_PX block of the window holding at least half its pixels."""
    rows, cols = np.nonzero(used)
    nb = -(-used.shape[1] // BLOCK_PX)
    _, inv, count = np.unique((rows // BLOCK_PX) * nb + cols // BLOCK_PX, return_inverse=True, return_counts=True)
    keep = count >= BLOCK_PX * BLOCK_PX // 2
    flat = images[..., rows, cols].reshape(-1, len(rows))
    sums = np.stack([np.bincount(inv, weights=f, minlength=len(count)) for f in flat])
    return (sums / count)[:, keep].reshape(images.shape[:-2] + (int(keep.sum()),))


def series_blocks(series: np.ndarray, used: np.ndarray) -> np.ndarray:
    """(frames, exposures, blocks) the block means (:func:`block_means`) of ``series`` (frames,
    exposures, rows, cols), a block holding a saturated pixel set to full scale (no weight): a
    pixel's own noise is a regressor's error, which biased the curve by ~1 % on the simulation; a
    block's mean has an eighth of it."""
    means = block_means(series, used)
    sat = block_means((series >= SATURATED).astype(float), used) > 0
    return np.where(sat, 1.0, means)


def curve_samples(means: np.ndarray, n: int = CURVE_SAMPLES) -> np.ndarray:
    """(<= n, exposures) values of (frame, block) pairs of ``means`` (:func:`series_blocks`'s) spread
    evenly over the brightness they hold: their mean value's range cut into CURVE_BINS equal bins, as
    many pairs from each (evenly over its ranks; all of a bin that holds fewer), so the curve sees
    every level the capture reaches, not mostly the commonest (deterministic)."""
    pairs = means.transpose(0, 2, 1).reshape(-1, means.shape[1])
    mean = pairs.mean(axis=1)
    order = np.argsort(mean, kind="stable")
    edges = np.linspace(mean.min(), mean.max(), CURVE_BINS + 1)
    cut = np.searchsorted(mean[order], edges[1:-1])
    per = max(1, n // CURVE_BINS)
    pick = [b[np.linspace(0, len(b) - 1, min(per, len(b))).round().astype(int)]
            for b in np.split(order, cut) if len(b)]
    return pairs[np.concatenate(pick)]


def fit_response(groups: list[tuple[np.ndarray, np.ndarray]], smoothness: float = SMOOTHNESS) -> Response:
    """Debevec and Malik's least squares (module docstring) over ``groups`` of (samples (n, e) of
    values in [0, 1], their exposures_s (e,)): unknowns g at the KNOTS and each sample's log
    radiance; sparse normal equations (each row touches two knots and one sample)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.linalg import spsolve

    knots = np.linspace(0.0, 1.0, KNOTS)
    rows, cols, vals, rhs = [], [], [], []
    row = col = 0
    for samples, exposures_s in groups:
        samples = samples[weight(samples).sum(axis=1) > 0]  # a sample no exposure weighs says nothing
        n, ne = samples.shape
        pos = np.clip(samples, 0.0, 1.0) * (KNOTS - 1)
        i0 = np.minimum(np.floor(pos).astype(int), KNOTS - 2).ravel()
        frac = (pos.ravel() - i0)
        w = weight(samples).ravel()
        r = row + np.arange(n * ne)
        rows += [r, r, r]
        cols += [i0, i0 + 1, KNOTS + col + np.repeat(np.arange(n), ne)]
        vals += [w * (1 - frac), w * frac, -w]
        rhs.append(w * np.tile(np.log(exposures_s), n))
        row, col = row + n * ne, col + n
    s = np.arange(KNOTS - 2)
    lam = smoothness * np.maximum(weight(knots[1:-1]), SMOOTHNESS_FLOOR)
    for j, c in enumerate((1.0, -2.0, 1.0)):
        rows.append(row + s)
        cols.append(s + j)
        vals.append(c * lam)
    rhs.append(np.zeros(KNOTS - 2))
    rows.append(np.array([row + KNOTS - 2]))  # g = 0 at mid-scale: the curve's unit
    cols.append(np.array([KNOTS // 2]))
    vals.append(np.array([1.0]))
    rhs.append(np.zeros(1))
    a = coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(row + KNOTS - 1, KNOTS + col)).tocsr()
    x = spsolve((a.T @ a).tocsc(), a.T @ np.concatenate(rhs))
    seen = np.concatenate([v[weight(v) > 0] for v, _ in groups])
    covered = (float(seen.min()), float(seen.max())) if seen.size else (0.5, 0.5)
    return Response(knots, np.asarray(x[:KNOTS]), covered)


def radiance(response: Response, stack: np.ndarray, exposures_s: np.ndarray) -> np.ndarray:
    """Linear radiance (per second) of each capture in ``stack`` (..., exposures, rows, cols): the
    weighted mean of its exposures (the hat's weights, a floor of 1e-3 below saturation so a dark
    capture keeps its reading); NaN where every exposure is saturated."""
    t = exposures_s.reshape((-1, 1, 1))
    w = np.where(stack >= SATURATED, 0.0, np.maximum(weight(stack), 1e-3))
    num = (w * response.exposure(stack) / t).sum(axis=-3)
    den = w.sum(axis=-3)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / den, np.nan)


def exposure_spread(response: Response, v: np.ndarray, exposures_s: np.ndarray) -> dict:
    """How the exposures agree once linearised: over every (frame, block) of ``v``
    (:func:`series_blocks`'s) with two or more exposures in WELL_EXPOSED, each exposure's radiance
    against their mean (relative), RMS and 99th percentile."""
    lo, hi = WELL_EXPOSED
    good = (v >= lo) & (v <= hi)
    est = response.exposure(v) / exposures_s[None, :, None]
    n = good.sum(axis=1)
    keep = n >= 2
    mean = np.where(keep, (est * good).sum(axis=1) / np.maximum(n, 1), np.nan)
    rel = (est / mean[:, None, :] - 1.0)[good & keep[:, None, :]]
    if not rel.size:
        return {"pairs": 0, "rms": math.nan, "p99": math.nan}
    return {"pairs": int(keep.sum()), "rms": float(np.sqrt(np.mean(rel ** 2))), "p99": float(np.percentile(np.abs(rel), 99))}


# -- the card ----------------------------------------------------------------------------------------
def coefficients(plan: Plan, radiance_frames: np.ndarray) -> np.ndarray:
    """(K, rows, cols) each function's response: its positive image's radiance minus its negative's
    (thesis 4.2.3; the room's light and the projector's black level cancel)."""
    return radiance_frames[0::2] - radiance_frames[1::2]


@dataclass(frozen=True)
class CardFit:
    """The card's separable fit (module docstring): the camera side ``t`` (P,) over the card's pixels
    (median 1), the frames' vector ``v`` (K,), the illumination side's zonal coefficients ``b`` (K,)
    and its values ``light_g`` (n,) at the lit projector pixels (kappa g: radiance per second per level
    per unit f cos(theta) per sr), each pixel's relative ``residual`` (P,)."""

    t: np.ndarray
    v: np.ndarray
    b: np.ndarray
    light_g: np.ndarray
    residual: np.ndarray
    albedo: float


def fit_card(c: np.ndarray, light: Light, albedo: float = CARD_ALBEDO) -> CardFit:
    """The separable fit of the card's responses ``c`` (P pixels, K functions) (module docstring)."""
    u, s, vt = np.linalg.svd(c, full_matrices=False)
    t, v = u[:, 0] * s[0], vt[0]
    if np.median(t) < 0:
        t, v = -t, -v
    med = float(np.median(t))
    t, v = t / med, v * med
    model = np.outer(t, v)
    residual = np.linalg.norm(c - model, axis=1) / np.maximum(np.linalg.norm(model, axis=1), 1e-300)
    b = np.linalg.solve(light.cosine_matrix(), v * math.pi / albedo)
    return CardFit(t, v, b, light.zonal @ b, residual, albedo)


def block_residual(c: np.ndarray, fit: CardFit, view: View) -> np.ndarray:
    """The separable fit's relative residual over BLOCK_PX x BLOCK_PX blocks of the camera window
    (the card's pixels' mean response in each block against the fit's mean model), for blocks
    holding at least half their pixels: (blocks,)."""
    rows, cols = np.nonzero(view.used)
    nb = -(-view.cam.shape[1] // BLOCK_PX)
    label = (rows // BLOCK_PX) * nb + cols // BLOCK_PX
    _, inv, count = np.unique(label, return_inverse=True, return_counts=True)
    keep = count >= BLOCK_PX * BLOCK_PX // 2
    mean_c = np.stack([np.bincount(inv, weights=c[:, k]) for k in range(c.shape[1])], axis=1) / count[:, None]
    mean_t = np.bincount(inv, weights=fit.t) / count
    model = np.outer(mean_t, fit.v)
    return (np.linalg.norm(mean_c - model, axis=1) / np.linalg.norm(model, axis=1))[keep]


def card_tilt(first: CardFit, turned: CardFit, light: Light, albedo: float = CARD_ALBEDO) -> tuple[float, float]:
    """The card's tilt (n_x, n_y) (rad, first order) in the first capture, from its fit and the half
    turn's: tilted, the card takes n . w for cos(theta), n turned with it, so half their frames'
    difference is (rho / pi) sum_j q_jk kappa g_j (n_x w_x + n_y w_y) w_j (kappa g from both: their
    mean), solved by least squares."""
    d = (first.v - turned.v) / 2
    light_g = (first.light_g + turned.light_g) / 2
    q = light.levels.astype(float).T
    m = np.stack([q @ (light_g * light.direction[:, a] * light.weight_sr) for a in (0, 1)], axis=1) * albedo / math.pi
    nx, ny = np.linalg.lstsq(m, d, rcond=None)[0]
    return float(nx), float(ny)


def combined(first: CardFit, turned: CardFit, light: Light, albedo: float = CARD_ALBEDO) -> CardFit:
    """One fit from a capture and its half turn: the mean camera side and frames' vector (the card's
    tilt cancels to first order: n . w + n' . w = 2 n_z cos(theta)), its light side solved anew."""
    t, v = (first.t + turned.t) / 2, (first.v + turned.v) / 2
    b = np.linalg.solve(light.cosine_matrix(), v * math.pi / albedo)
    return CardFit(t, v, b, light.zonal @ b, np.maximum(first.residual, turned.residual), albedo)


def calibrated(fit: CardFit, light_levels: np.ndarray, zonal: np.ndarray, weight_sr: np.ndarray,
               responses: np.ndarray) -> np.ndarray:
    """A sample's zonal coefficients of f(., w_o) cos(theta_i) (P, M) from its responses (P, K) at
    the card's pixels, measured with the images whose signed levels ``light_levels`` (n, K) the rig's
    lit projector pixels showed (the same pixels as the card's Light; any order): each response
    divided by the pixel's camera side t, then e = B^-1 r with B_km = sum_j q_jk kappa g_j Z_m(w_j) w_j,
    ``zonal`` (n, M) the basis at those pixels up to the order wanted (M <= K)."""
    B = np.asarray(light_levels, float).T @ (zonal * (fit.light_g * weight_sr)[:, None])
    r = responses / fit.t[:, None]
    return np.linalg.lstsq(B, r.T, rcond=None)[0].T


def lambert_albedo(e: np.ndarray, light: Light) -> np.ndarray:
    """The albedo (P,) a Lambertian sample's calibrated coefficients ``e`` (P, K) give: cos(theta)
    lies in the span of Z_0^0 and Z_1^0 (its coefficients zeta, least squares on the lit pixels,
    exact to round-off), f cos(theta) = (rho / pi) cos(theta): rho = pi e.zeta / zeta.zeta."""
    zeta = np.linalg.lstsq(light.zonal, light.cos_theta, rcond=None)[0]
    return math.pi * (e @ zeta) / float(zeta @ zeta)


# -- the whole analysis --------------------------------------------------------------------------------
@dataclass
class Result:
    """One gray card calibration: the curve, the figures, the verdict and the maps."""

    plan: Plan
    response: Response
    fit: CardFit
    report: dict
    passed: bool
    failures: list = field(default_factory=list)
    camera_scale: np.ndarray | None = None


def analyse(plan: Plan, capture: Capture, view: View, light: Light, albedo: float = CARD_ALBEDO) -> Result:
    """The curve, each capture's radiance, the card's fit and the pass criterion, from ``capture``
    (:func:`read`'s) and the rig's two sides."""
    exp_s = plan.exposures_s
    used = view.used
    stack = capture.frames
    white_b, frames_b = series_blocks(capture.white[None], used), series_blocks(stack, used)
    response = fit_response([(curve_samples(white_b), plan.response_exposures_s), (curve_samples(frames_b), exp_s)])
    rad = radiance(response, stack, exp_s)  # (frames, rows, cols)
    c = coefficients(plan, rad)[:, used].T  # (P, K)
    fit = fit_card(c, light, albedo)
    blocks = block_residual(c, fit, view)
    tilt = None
    if capture.turned is not None:  # the half turn: the light side from both, the card's tilt from their difference
        c2 = coefficients(plan, radiance(response, capture.turned, exp_s))[:, used].T
        fit2 = fit_card(c2, light, albedo)
        blocks = np.maximum(blocks, block_residual(c2, fit2, view))
        tilt = card_tilt(fit, fit2, light, albedo)
        fit = combined(fit, fit2, light, albedo)
        c = (c + c2) / 2
    frames_spread = exposure_spread(response, frames_b, exp_s)
    white_spread = exposure_spread(response, white_b, plan.response_exposures_s)
    spread = max((frames_spread, white_spread), key=lambda d: d["rms"])
    own = lambert_albedo(calibrated(fit, light.levels, light.zonal, light.weight_sr, c), light)
    bright = int(np.argmax([np.median(stack[i, -1][used]) for i in range(stack.shape[0])]))
    fill = float(np.median(stack[bright, -1][used]))
    g = fit.light_g
    ratio = float(g.max() / g.min()) if g.min() > 0 else math.inf
    outliers = float(np.mean((fit.t > OUTLIER_FACTOR) | (fit.t < 1 / OUTLIER_FACTOR)))
    f = dict(plan=plan, view=view, response=response, fit=fit, blocks=blocks, tilt=tilt, albedo=albedo,
             frames_spread=frames_spread, white_spread=white_spread, spread=spread, own=own, bright=bright, fill=fill,
             ratio=ratio, outliers=outliers)
    checks = _checks(f)
    failures = [text for _, ok, text in checks if not ok]
    report = _report(f, checks, failures)
    scale = np.full(view.cam.shape, np.nan)
    scale[used] = 1.0 / fit.t
    return Result(plan, response, fit, report, not failures, failures, scale)


def _checks(f: dict) -> list[tuple[str, bool, str]]:
    """The pass criterion's checks (name, passed, the figure in words) from :func:`analyse`'s figures."""
    spread, response, blocks, ratio = f["spread"], f["response"], f["blocks"], f["ratio"]
    outliers, fill = f["outliers"], f["fill"]
    tilt_deg = None if f["tilt"] is None else math.degrees(math.hypot(*f["tilt"]))
    checks = [
        ("card_level", tilt_deg is None or tilt_deg <= MAX_TILT_DEG,
         "the card's tilt not measured (no half turn)" if tilt_deg is None else
         f"the card tilted {tilt_deg:.2f} deg (the half turn; bound {MAX_TILT_DEG:g} deg)"),
        ("exposures_agree", spread["rms"] <= MAX_EXPOSURE_SPREAD,
         f"exposures agree to {spread['rms']:.2%} RMS once linearised (bound {MAX_EXPOSURE_SPREAD:.1%})"),
        ("curve_rises", response.monotone(), "the response curve rises over the values captured"),
        ("card_lambertian", float(np.percentile(blocks, 95)) <= MAX_SEPARABLE_RESIDUAL,
         f"the card's response separates to {np.percentile(blocks, 95):.2%} over {BLOCK_PX} x {BLOCK_PX} px blocks "
         f"(95th percentile; bound {MAX_SEPARABLE_RESIDUAL:.0%})"),
        ("card_flat", 0 < ratio <= MAX_ILLUMINATION_RATIO,
         f"the light's throughput over the lit directions varies {ratio:.2f}x (bound {MAX_ILLUMINATION_RATIO:g}x)"),
        ("no_outliers", outliers <= MAX_OUTLIER_SHARE,
         f"{outliers:.2%} of the card's pixels off the median throughput by over {OUTLIER_FACTOR:g}x (bound "
         f"{MAX_OUTLIER_SHARE:.1%})"),
        ("exposed", fill >= MIN_FILL, f"the brightest frame fills {fill:.0%} of full scale at the longest exposure "
                                      f"(at least {MIN_FILL:.0%})"),
    ]
    return checks


def _report(f: dict, checks: list, failures: list) -> dict:
    """graycard.json's figures (units in keys) from :func:`analyse`'s figures and checks."""
    plan, view, response, fit, blocks, tilt, albedo = (f[k] for k in ("plan", "view", "response", "fit", "blocks",
                                                                         "tilt", "albedo"))
    used, g, own, bright, fill = view.used, fit.light_g, f["own"], f["bright"], f["fill"]
    frames_spread, white_spread, ratio, outliers = f["frames_spread"], f["white_spread"], f["ratio"], f["outliers"]
    theta_o = view.theta_o.reshape(view.cam.shape)[used]
    tilt_deg = None if tilt is None else math.degrees(math.hypot(*tilt))
    pct = lambda a, q: float(np.percentile(a, q))  # noqa: E731
    report = {
        "thesis": "4.1.2 (reflectance calibration, eqs. 4.1-4.2); HDR from multiple exposures (4.2.2-4.2.3)",
        "verdict": "FAIL" if failures else "PASS",
        "checks": {name: {"passed": bool(ok), "figure": text} for name, ok, text in checks},
        "capture": {"order": plan.order, "frames": list(plan.frames()), "exposures_ms": list(plan.exposures_ms),
                    "card_pixels": int(used.sum()),
                    "exitant_theta_deg": [math.degrees(float(theta_o.min())), math.degrees(float(theta_o.max()))],
                    "brightest_frame": plan.frames()[bright], "brightest_fill_of_full_scale": fill},
        "response_curve": {
            "method": "Debevec & Malik 1997: log inverse response on 256 knots, smoothness "
                      f"{SMOOTHNESS:g}, hat weights, g = 0 at mid-scale",
            "samples": CURVE_SAMPLES, "covered_of_full_scale": list(response.covered),
            "exposure_spread": {"about": f"each well-exposed {BLOCK_PX} x {BLOCK_PX} px block's radiance over its "
                                         "exposures against their mean, relative (the frames' exposures; the flat "
                                         "field's bracket)",
                                "frames": frames_spread, "white_field": white_spread},
            "log_radiance_every_16th_knot": [float(x) for x in response.log_radiance[::16]],
        },
        "card": {
            "albedo_assumed": albedo,
            "separable_residual": {"about": f"|c - t v| / |t v| per card pixel, and over {BLOCK_PX} x {BLOCK_PX} px "
                                            "blocks (their means: the noise averaged out, a systematic departure kept)",
                                   "pixels": {"p50": pct(fit.residual, 50), "p95": pct(fit.residual, 95)},
                                   "blocks": {"count": int(blocks.size), "p50": pct(blocks, 50), "p95": pct(blocks, 95)}},
            "camera_side": {"about": "t per card pixel, median 1: the albedo each camera direction reads with one "
                                     "scale for all (coat, lens vignetting); its scale factor is 1 / t",
                            "p1": pct(fit.t, 1), "p50": pct(fit.t, 50), "p99": pct(fit.t, 99),
                            "outlier_share": outliers},
            "illumination_side": {"about": "kappa g over the lit projector pixels (eq. 4.2's f_r,gray = kappa g rho / "
                                           "pi); lambda = 1 / (kappa g)",
                                  "min": float(g.min()), "median": float(np.median(g)), "max": float(g.max()),
                                  "max_over_min": ratio, "zonal_coefficients": [float(x) for x in fit.b]},
            "tilt": ({"measured": False, "about": "capture the frames again with the card turned a half turn "
                                                  "(turned_<frame>_<ms>ms) to measure it and take it out of the light side"}
                     if tilt is None else
                     {"measured": True, "tilt_deg": tilt_deg,
                      "normal_towards_deg": math.degrees(math.atan2(tilt[1], tilt[0])),
                      "about": "the first capture's card normal's lean from the sample's (first order, from the "
                               "two captures' difference); the light side is their mean, the tilt taken out"}),
            "albedo_after_calibration": {"about": "the card's albedo from its own captures through the scale factors, "
                                                  "per camera direction",
                                         "p5": pct(own, 5), "p50": pct(own, 50), "p95": pct(own, 95)},
        },
    }
    return report


def summary(result: Result) -> str:
    """The verdict and its figures on one line."""
    r = result.report
    c = r["card"]
    head = (f"gray card {r['verdict']}: response curve from {r['capture']['card_pixels']} card pixels x "
            f"{len(r['capture']['frames'])} frames x {len(r['capture']['exposures_ms'])} exposures, exposures agree to "
            f"{max(d['rms'] for d in r['response_curve']['exposure_spread'].values() if isinstance(d, dict)):.2%} RMS; card separable to "
            f"{c['separable_residual']['blocks']['p95']:.2%} (p95 of blocks); camera side {c['camera_side']['p1']:.2f}-"
            f"{c['camera_side']['p99']:.2f} of its median, light {c['illumination_side']['max_over_min']:.2f}x over "
            f"the lit directions; albedo after calibration {c['albedo_after_calibration']['p5']:.4f}-"
            f"{c['albedo_after_calibration']['p95']:.4f} (p5-p95)")
    return head + ("" if result.passed else "; failed: " + "; ".join(result.failures))


# -- simulated captures ----------------------------------------------------------------------------------
def gamma_curve(gamma: float = 2.2):
    """A response v = x^(1 / gamma) (x the linear exposure, 1 = full scale)."""
    return lambda x: np.clip(x, 0.0, 1.0) ** (1.0 / gamma)


def s_curve(contrast: float = 1.6, knee: float = 0.25):
    """A film-like S-shaped response v = (1 + c) x^a / (x^a + c), a = ``contrast``, c = ``knee``^a:
    v(0) = 0, v(1) = 1, steep in the middle tones."""
    c = knee ** contrast
    return lambda x: (1 + c) * np.clip(x, 0.0, 1.0) ** contrast / (np.clip(x, 0.0, 1.0) ** contrast + c)


#: The exposure a simulation's ``fill`` refers to (s): the thesis's longest.
REFERENCE_EXPOSURE_S = 0.25


@dataclass(frozen=True)
class Planted:
    """What a simulated capture plants: the response ``curve`` (linear exposure -> value), the card's
    ``albedo``, the camera side ``t`` over the window (rows * cols,), the light's throughput ``g`` at
    the lit projector pixels (n,), ``fill`` (the brightest frame's median linear exposure at the
    longest exposure), the room's light ``ambient`` (linear exposure per second, everywhere) and
    the noise: ``read_noise`` (linear, of full scale), ``full_well`` (electrons at full scale).
    ``fill`` is the 18 % card's at REFERENCE_EXPOSURE_S: a brighter card or other exposures scale it."""

    curve: object
    albedo: float
    t: np.ndarray
    g: np.ndarray
    #: the light side the card turned a half turn sees (its tilt turned), and a flat card's
    g_turned: np.ndarray | None = None
    g_flat: np.ndarray | None = None
    tilt_rad: float = 0.0
    fill: float = 0.6
    ambient: float = 0.004
    read_noise: float = 0.002
    full_well: float = 20000.0


def planted(view: View, light: Light, curve=None, albedo: float = CARD_ALBEDO, tilt_rad: float = 0.0) -> Planted:
    """A plausible rig to simulate: the camera side falls 20 % from the axis to grazing with a 5 %
    tilt across (coat and lens), the light side 15 % (the coat at grazing incidence) with a 5 % tilt
    (Z_1^1's share), both in the span the fit expands the light side in; ``tilt_rad``: the card tilted about the y axis (its normal towards +x), planted
    in the light side as cos of the tilted normal over cos theta."""
    th, ph = view.theta_o, view.phi_o
    t = (1.0 - 0.2 * np.sin(np.nan_to_num(th)) ** 2) * (1.0 + 0.05 * np.cos(np.nan_to_num(ph)))
    k11 = next(i for i, lm in enumerate(light.lm) if lm == (1, 1)) if light.order >= 1 else None
    g = 1.0 - 0.15 * (1.0 - light.cos_theta) ** 2
    if k11 is not None:
        z = light.zonal[:, k11]
        g = g + 0.05 * z / np.max(np.abs(z))
    def tilted(sign: float) -> np.ndarray:
        normal_dot = light.direction[:, 2] * math.cos(tilt_rad) + sign * light.direction[:, 0] * math.sin(tilt_rad)
        return g * np.clip(normal_dot, 0, None) / light.cos_theta

    return Planted(curve or gamma_curve(2.2), albedo, t, tilted(1.0), tilted(-1.0), g, tilt_rad)


def render(plan: Plan, view: View, light: Light, truth: Planted, rng: np.random.Generator,
           bits: int = 8) -> dict[tuple[str, float], np.ndarray]:
    """The simulated capture of the camera's window, (frame, exposure ms) -> ``bits``-deep integer
    image (uint8/uint16) for every file of :meth:`Plan.files`: each frame's card radiance (the model
    of the module docstring with the planted sides and albedo; the flat field's with every lit
    pixel at full level) on the card's pixels, the room's light everywhere, photon and read noise,
    the planted curve, quantised. The 18 % card's brightest frame is at ``truth.fill`` at
    REFERENCE_EXPOSURE_S, whatever the plan's exposures."""
    used = view.used.ravel()
    light_g = truth.g * light.cos_theta * light.weight_sr
    irr = {f: light.frame_levels(f).astype(float) @ light_g for f in (WHITE,) + plan.frames()}
    if plan.turned:
        turned_g = (truth.g if truth.g_turned is None else truth.g_turned) * light.cos_theta * light.weight_sr
        irr |= {TURNED + f: light.frame_levels(f).astype(float) @ turned_g for f in plan.frames()}
    scale = truth.fill / (max(irr[f] for f in plan.frames()) * float(np.median(truth.t[used])) * REFERENCE_EXPOSURE_S)
    full = (1 << bits) - 1
    out = {}
    for f, ms in plan.files():
        lin = np.full(used.size, truth.ambient)
        lin[used] += truth.t[used] * irr[f] * scale * truth.albedo / CARD_ALBEDO
        x = lin * ms / 1e3
        x = x + rng.normal(0.0, 1.0, x.size) * np.sqrt(np.clip(x, 0, None) / truth.full_well + truth.read_noise ** 2)
        v = truth.curve(np.clip(x, 0.0, 1.0))
        out[(f, ms)] = np.clip(np.round(v * full), 0, full).reshape(view.cam.shape).astype(
            np.uint8 if bits == 8 else np.uint16)
    return out


def as_read(plan: Plan, images: dict, bits: int = 8) -> Capture:
    """A rendered capture (:func:`render`) as :func:`read` returns one (fractions of full scale)."""
    full = float((1 << bits) - 1)
    white = np.stack([images[(WHITE, ms)] for ms in plan.response_exposures_ms]) / full
    frames = np.stack([np.stack([images[(f, ms)] for ms in plan.exposures_ms]) for f in plan.frames()]) / full
    turned = (np.stack([np.stack([images[(TURNED + f, ms)] for ms in plan.exposures_ms]) for f in plan.frames()]) / full
              if plan.turned else None)
    return Capture(white, frames, turned)


def full_frame(view: View, window: np.ndarray, fill: int = 0) -> np.ndarray:
    """A window image placed in the camera's full frame (``fill`` elsewhere), as a capture file holds it."""
    cam = view.cam
    width, height = cam.resolution
    out = np.full((height, width), fill, dtype=window.dtype)
    out[cam.row0: cam.row0 + cam.shape[0], cam.col0: cam.col0 + cam.shape[1]] = window
    return out


def compare(result: Result, truth: Planted, view: View, light: Light) -> dict:
    """A simulation's recovery against what was planted: the curve (its linear exposure against the
    planted inverse, both scaled to agree at mid-scale, over the well-exposed values WELL_EXPOSED the
    capture covered: the largest relative error), the camera side (a ratio to the planted, normalised
    by its median: per pixel its 99th percentile, per BLOCK_PX block its largest) and the light side
    (the same ratio, over the lit pixels the planted light reaches: the largest; against what the
    capture can give, the tilted card's light with one capture, the flat card's with the half turn,
    and against the flat card's); with the half turn, the tilt's error (deg)."""
    lo, hi = max(result.response.covered[0], WELL_EXPOSED[0]), min(result.response.covered[1], WELL_EXPOSED[1])
    v = np.linspace(lo, hi, 200)
    x = np.linspace(0.0, 1.0, 200001)
    planted_inv = np.interp(v, truth.curve(x), x)  # the planted curve rises: its inverse by table
    r = result.response.exposure(v) / planted_inv
    used = view.used.ravel()
    ct = result.fit.t / truth.t[used]
    ct = ct / np.median(ct) - 1
    mean_ratio = block_means(_on_window(view, result.fit.t / truth.t[used]), view.used)
    def light_error(g: np.ndarray) -> float:
        lit = g > 0.2 * np.median(g)
        lg = result.fit.light_g[lit] / g[lit]
        return float(np.max(np.abs(lg / np.median(lg) - 1)))

    tilt = result.report["card"]["tilt"]
    own = truth.g_flat if tilt["measured"] and truth.g_flat is not None else truth.g
    flat = truth.g if truth.g_flat is None else truth.g_flat
    extra = {} if not tilt["measured"] else {"tilt_error_deg": abs(tilt["tilt_deg"] - math.degrees(abs(truth.tilt_rad)))}
    return {**extra,
            "light_side_vs_flat_card_max_relative_error": light_error(flat),"curve_max_relative_error": float(np.max(np.abs(r / np.interp(0.5, v, r) - 1.0))),
            "curve_range_of_full_scale": [float(lo), float(hi)],
            "camera_side_p99_relative_error": float(np.percentile(np.abs(ct), 99)),
            "camera_side_block_max_relative_error": float(np.max(np.abs(mean_ratio / np.median(mean_ratio) - 1))),
            "light_side_max_relative_error": light_error(own)}


def _on_window(view: View, values: np.ndarray) -> np.ndarray:
    """Card-pixel values (P,) on the camera window (rows, cols), 0 elsewhere."""
    out = np.zeros(view.used.shape)
    out[view.used] = values
    return out


# -- the manual's paragraph ------------------------------------------------------------------------------
def manual_text(rig) -> str:
    """The procedure for the manual (thesis 4.1.2), with the command that checks it."""
    holder = 2 * rig.profile.sample_holder.radius
    plan = Plan()
    return (f"Put an 18 % diffuse gray card (photographic, e.g. a Kodak R-27 class card cut to a {holder:g} mm disc, "
            "the sample holder's diameter) in the sample holder, flat, its face at z = 0. Write the images to project "
            f"with `rigcad calibrate {rig.name} --gray-card-kit` (the zonal basis up to order {plan.order}: "
            f"{len(plan.frames())} images, each function's positive and negative part, and a white field). Show each on "
            "the projector and "
            f"capture it at {', '.join(f'{v:g}' for v in plan.exposures_ms)} ms (thesis Figure 4.4; the white field at "
            f"{plan.response_exposures_ms[0]:g}-{plan.response_exposures_ms[-1]:g} ms, for the response curve), the camera's gain "
            "fixed and its automatic exposure off, into one folder named as the kit's capture_plan.json lists "
            "(white_<ms>ms.png, z_<l>_<m>_<pos|neg>_<ms>ms.png); then turn the card a half turn in the holder and "
            "capture the z_ frames again as turned_<frame>_<ms>ms.png (a tilt of the card turns with it, the "
            "light does not: the command measures the tilt and takes it out). "
            f"Then run `rigcad calibrate {rig.name} --gray-card FOLDER`: it fits the "
            "camera's response curve from the exposures, the card's radiance per camera pixel and per lit direction, "
            "and prints PASS or FAIL with its figures (exposures agreeing once linearised, the card's response "
            "separable as a Lambertian card's is, the card tilted under 1 degree, the light varying less than 2x "
            "over the directions, no dirty pixels, the brightest frame a quarter of full scale or more); it exits "
            "non-zero on FAIL and writes graycard.json and scale_factors.npz, the scale factors of thesis eq. 4.2, into "
            f"exports/{rig.name}/calibrate_graycard/. Keep the card dry and out of the light between uses.")
