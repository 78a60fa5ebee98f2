"""The upright display: a second, small screen stood on edge in the holder's bore, its face towards
the dome at ``calibration.upright_offset`` from the axis, its active area from
``upright_depth`` below the sample plane up, captured at ``upright_turns`` equal turns of its stand
about the axis (labels ``u<j>``, turn j: the face towards azimuth 360 j / turns deg from +x).

Why: the rays that reach the sample near grazing (the last ~10 deg) come off the dome within a few
millimetres of the sample plane and run nearly parallel to it, so they pass under a flat screen
lying on a spacer, or meet its plane past its edge with footprints tens of millimetres long
(docs/calibrate.md). Stood on edge a few millimetres from O, a display meets them nearly face on: a
camera pixel's footprint there is its angular size times the ~8 mm to O, ~0.1-0.3 mm.

A capture's placement (six parameters in the display's own frame, :data:`rigcad.calibrate.model.SCREEN_KEYS`
order: along its normal, its tilts about its width and its height, sideways, up, its turn about its
normal; :func:`rigcad.calibrate.raxel.screen_pose`) is fitted, as a resection, against the rays the
flat captures measured (:func:`rigcad.calibrate.maps.pivot_rays`): where a pixel was measured there
and decoded on the upright display, its ray (through the fitted model's dome point, along the
measured direction) must meet the display at the decoded point. Fitting against the model's rays
instead would read the dome's surface error over the pixels the display sees as a misplaced display
(a mean slope moves every point alike). Each pixel the display decoded then gets its ray from its
decoded point to the model's dome point, like a flat screen's."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import on_screen, screen_pose
from rigcad.optics.frames import Pose

#: The edge rule's reach for the upright display's decoded points (camera px;
#: :func:`rigcad.calibrate.maps.away_from_edges`): a flat screen's pixels near grazing have
#: footprints millimetres long, which an edge pulls (:data:`rigcad.calibrate.maps.HEIGHT_EDGE_PX`,
#: 3); on the upright display they are ~0.1-0.3 mm.
EDGE_PX = 0
#: The fewest pixels measured by the flat captures that a capture's display must have decoded to be
#: placed (a resection of six parameters; the default's captures have ~5,000-9,000 each).
MIN_REFERENCE_PIXELS = 200
#: The resection's robust first solve (mm on the display): the measured rays meet it within ~0.01 mm
#: (0.1 mrad over ~100 mm) but near the flat screens' edges.
ROBUST_SCALE_MM = 0.05
#: The simulated placement (:func:`random_placement`): how far the display sits from its slot's face
#: along its normal, and from its ledge, within +- this (mm): a printed slot holds it to ~0.2 mm.
SEAT_MM = 0.2


@dataclass(frozen=True)
class Uprights:
    """The upright captures (module docstring): labels, nominal poses (screen frame: u along the
    display's width, horizontal; v up; its normal towards the dome) and the display's pattern sequence."""

    labels: tuple[str, ...]
    nominal: tuple[Pose, ...]
    seq: Sequence

    @classmethod
    def of(cls, profile) -> "Uprights":
        cal = profile.calibration
        seq = Sequence.from_profile(cal, "upright")
        height = seq.size_mm[1]
        poses = []
        for j in range(cal.upright_turns):
            psi = 2 * math.pi * j / cal.upright_turns
            normal = np.array([math.cos(psi), math.sin(psi), 0.0])
            across = np.array([-math.sin(psi), math.cos(psi), 0.0])
            poses.append(Pose(np.stack([across, [0.0, 0.0, 1.0], normal], axis=1),
                              cal.upright_offset * normal + np.array([0.0, 0.0, height / 2 - cal.upright_depth])))
        return cls(tuple(f"u{j}" for j in range(cal.upright_turns)), tuple(poses), seq)

    def __len__(self) -> int:
        return len(self.labels)

    def poses(self, placement: np.ndarray) -> list[Pose]:
        """Each capture's pose: its nominal one moved by its placement ((captures, 6), module docstring)."""
        return [compose(p0, screen_pose(*(float(v) for v in p))) for p0, p in zip(self.nominal, placement)]


def compose(outer: Pose, inner: Pose) -> Pose:
    """``outer`` after ``inner``: global = outer(inner(local))."""
    return Pose(outer.rotation @ inner.rotation, outer.rotation @ inner.translation + outer.translation)


def placement_scale(profile) -> np.ndarray:
    """(6,) each placement parameter's tolerance (mm, rad): the fit's scale and prior."""
    tilt = profile.calibration.upright_tilt
    return np.array([0.5, tilt, tilt, M.PLACEMENT_MM, M.PLACEMENT_MM, M.PLACEMENT_TURN_RAD])


def random_placement(profile, rng: np.random.Generator) -> np.ndarray:
    """A seeded placement of each upright capture ((captures, 6)), from a stream of its own
    (spawned: ``rng``'s draws stay as they were): within :data:`SEAT_MM` along its normal and up,
    leaning or turned within ``upright_tilt`` (uniform magnitude, any direction), sideways and about
    its normal within the hand's tolerance (:func:`placement_scale`)."""
    count = profile.calibration.upright_turns
    if not count:
        return np.zeros((0, 6))
    hand = rng.spawn(1)[0]
    scale = placement_scale(profile)
    out = np.empty((count, 6))
    for c in range(count):
        mag, ang = hand.uniform(0, scale[1]), hand.uniform(0, 2 * math.pi)
        out[c] = (hand.uniform(-SEAT_MM, SEAT_MM), mag * math.cos(ang), mag * math.sin(ang),
                  hand.uniform(-1, 1) * scale[3], hand.uniform(-SEAT_MM, SEAT_MM), hand.uniform(-1, 1) * scale[5])
    return out


@dataclass
class Placed:
    """One upright capture's fitted placement (6,) (NaN when it could not be placed), its standard
    errors, the RMS of its residuals (mm, unweighted), the reference pixels read and dropped."""

    placement: np.ndarray
    standard_error: np.ndarray
    rms_mm: float
    pixels: int
    outliers: int

    @property
    def placed(self) -> bool:
        return bool(np.all(np.isfinite(self.placement)))


def place(nominal: Pose, scale: np.ndarray, decoded, model_tr: M.Traced, measured: np.ndarray,
          shape: tuple[int, int]) -> Placed:
    """The resection of one upright capture (module docstring): ``decoded`` its decoding,
    ``measured`` (n, 3) the flat captures' rays (up; NaN where none), ``model_tr`` the fitted model."""
    from scipy.optimize import least_squares

    from rigcad.calibrate.fit import CLUSTER_PX, outlying_rows, posterior_covariance
    from rigcad.calibrate.maps import away_from_edges

    inner = (away_from_edges(decoded.valid, model_tr.direct, EDGE_PX) & model_tr.ok
             & np.all(np.isfinite(measured), axis=1))
    rows = np.nonzero(inner)[0]
    if rows.size < MIN_REFERENCE_PIXELS:
        return Placed(np.full(6, np.nan), np.full(6, np.nan), math.nan, int(rows.size), 0)
    p, d = model_tr.p2[rows], -measured[rows]
    target = np.stack([decoded.u.ravel()[rows], decoded.v.ravel()[rows]], axis=1)
    keep = np.ones(2 * rows.size, bool)

    def fun(z: np.ndarray) -> np.ndarray:
        su, sv = on_screen(compose(nominal, screen_pose(*(z * scale))), p, d)
        return np.nan_to_num((np.stack([su, sv], axis=1) - target).ravel()[keep], nan=1.0)

    res = least_squares(fun, np.zeros(6), method="trf", loss="soft_l1", f_scale=ROBUST_SCALE_MM, xtol=1e-12,
                        ftol=1e-12)
    # residuals past the fit's outlier limit (its robust sigmas) dropped, as the misalignment fit does
    drop, _ = outlying_rows(res.fun, np.ones(len(res.fun), bool), np.zeros(len(res.fun), bool))
    keep[drop] = False
    res = least_squares(fun, res.x, method="trf", xtol=1e-12, ftol=1e-12)
    tiles = (rows // shape[1] // CLUSTER_PX) * (shape[1] // CLUSTER_PX + 1) + rows % shape[1] // CLUSTER_PX
    # no prior: thousands of rays converging on O hold all six (standard errors ~1 um, ~0.1 mrad)
    cov = posterior_covariance(np.vstack([res.jac, np.zeros((6, 6))]), np.concatenate([res.fun, np.zeros(6)]),
                               np.zeros((6, 6)), np.repeat(tiles, 2)[keep])
    r = res.fun
    return Placed(res.x * scale, np.sqrt(np.diag(cov)) * scale, float(np.sqrt(np.mean(r ** 2))), int(rows.size),
                  int(drop.sum()))
