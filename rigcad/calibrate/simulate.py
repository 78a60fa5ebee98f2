"""The camera images a calibration capture would give, without hardware (``rigcad calibrate
--simulate``): the rig moved by a seeded random misalignment within ``tolerancing``, a planted
surface error on the dome, each camera pixel's sub-rays traced to the screen with the pattern
integrated over each sub-ray's footprint and dimmed by the two mirrors' reflectance, defocus blur,
photon and read noise, 8-bit quantisation.

The dome's surface error h (mm, along the reflecting side's normal, in the dome's own frame): a
Gaussian bump of ``calibration.sim_bump_amplitude`` and width ``sim_bump_width`` centred on a
seeded point of the dome, plus the ripple that sanding across the print's layers leaves,
``sim_ripple_amplitude`` x sin(2 pi z / ``sim_ripple_period``) (layers are planes of constant z).
To first order it tilts the normal by its tangential gradient: n' = unit(n - grad_s h) (slopes in
rad; the ~um height change moves the hit point negligibly). The screen emits uniformly in angle
and linearly in its 8-bit values (a calibrated display)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import turn_matrix

#: Fraction of full exposure the screen's black (and the room) gives: a display's contrast ~1000:1
#: and some stray light.
BLACK_LEVEL = 0.01
#: Fraction of the camera's full well a white screen pixel fills (exposure advice: just short of saturation).
WHITE_LEVEL = 0.85


@dataclass(frozen=True)
class SurfaceError:
    """The planted dome error (module docstring): bump centre (3,) mm in the dome's frame."""

    bump_centre: np.ndarray
    bump_amplitude: float
    bump_width: float
    ripple_amplitude: float
    ripple_period: float

    def gradient(self, p: np.ndarray) -> np.ndarray:
        """grad h (n, 3) at points p (n, 3) (dome frame), before projection on the surface."""
        d = p - self.bump_centre
        bump = self.bump_amplitude * np.exp(-np.sum(d * d, axis=1) / (2 * self.bump_width ** 2))
        g = -bump[:, None] * d / self.bump_width ** 2
        k = 2 * math.pi / self.ripple_period
        g[:, 2] += self.ripple_amplitude * k * np.cos(k * p[:, 2])
        return g


def planted_surface(rig, rng: np.random.Generator) -> SurfaceError:
    """A seeded bump centre on the dome (parameter in the middle 60 % of its meridian, any azimuth)."""
    cal = rig.profile.calibration
    mer = rig.layout.design_dome
    lo, hi = mer.u_range
    u = rng.uniform(lo + 0.2 * (hi - lo), hi - 0.2 * (hi - lo))
    r, z = mer.points(np.array([u]))[0]
    phi = rng.uniform(0, 2 * math.pi)
    return SurfaceError(np.array([r * math.cos(phi), r * math.sin(phi), z]), cal.sim_bump_amplitude,
                        cal.sim_bump_width, cal.sim_ripple_amplitude, cal.sim_ripple_period)


def surface_slopes(rig, surface: SurfaceError | None, tr: M.Traced) -> np.ndarray:
    """The planted error's tangential gradient grad_s h (n, 3) (global frame, rad) at each ray's
    dome point (0 without a surface error; NaN where lost)."""
    out = np.where(tr.ok[:, None], 0.0, np.nan)
    if surface is None:
        return out
    pose = rig.pose("dome")
    local, _ = pose.localize(np.nan_to_num(tr.p2), np.nan_to_num(tr.p2))
    g = pose.globalize_dirs(surface.gradient(local))
    n = tr.v - tr.u
    n /= np.linalg.norm(n, axis=1)[:, None]
    g = g - np.sum(g * n, axis=1)[:, None] * n
    return np.where(tr.ok[:, None], g, np.nan)


def with_surface(rig, surface: SurfaceError | None, tr: M.Traced) -> M.Traced:
    """The traced rays re-reflected off the dome with the planted error: v' = reflect(u, n')."""
    if surface is None:
        return tr
    g = np.nan_to_num(surface_slopes(rig, surface, tr))
    n = tr.v - tr.u
    n /= np.linalg.norm(n, axis=1)[:, None]
    n2 = n - g
    n2 /= np.linalg.norm(n2, axis=1)[:, None]
    v = tr.u - 2 * np.sum(tr.u * n2, axis=1)[:, None] * n2
    return M.Traced(tr.p2, np.where(tr.ok[:, None], v, tr.v), tr.u, tr.ok, tr.direct)


def random_misalignment(rig, plan: M.Plan, rng: np.random.Generator, laying: int = 0) -> np.ndarray:
    """A seeded build: each offset uniform within +- its tolerance, each tilt's rotation vector
    uniform in magnitude (0..tolerance) and direction. Each spacer's capture: the screen's height
    +-0.2 mm, its wedge's tilt within ``calibration.screen_tilt`` (a printed spacer, the screen's
    back); a turned capture (:class:`model.Plan`): its spacer's height and wedge, turned with the
    screen. Each screen laid by hand: turned uniformly within +- the placement tolerance about its
    nominal turn and, but the first, off centre within +- its tolerance along u and v; its tilt
    is the wedge's plus a seating tilt within ``screen_seating``. The first screen's height and
    centre are the fit's gauge (:data:`model.GAUGE`): they define the frame. ``laying`` k > 0: the
    same rig, spacers and wedges, each screen laid anew (the k-th time): its placement by hand and
    its seating from streams of their own."""
    cal = rig.profile.calibration
    tol = M.tolerance_scale(rig, len(plan))
    theta = np.zeros(len(tol))
    for i in range(len(M.COMPONENTS)):
        j = 5 * i
        theta[j: j + 3] = rng.uniform(-1, 1, 3) * tol[j: j + 3]
        mag, ang = rng.uniform(0, tol[j + 3]), rng.uniform(0, 2 * math.pi)
        theta[j + 3: j + 5] = mag * math.cos(ang), mag * math.sin(ang)
    # the hand's placement and the seating from streams of their own (spawning leaves ``rng``'s
    # draws as they were; the k-th laying's are the (2k, 2k + 1)-th children)
    hand, seat = rng.spawn(2 + 2 * laying)[-2:]
    for c in sorted(range(len(plan)), key=lambda c: plan.repeats(c) is not None):  # spacers first
        j, first = M.screen_index(c), plan.repeats(c)
        if first is None:
            mag, ang = rng.uniform(0, cal.screen_tilt), rng.uniform(0, 2 * math.pi)
            # (the first spacer draws no offset: the seeds' streams stay as they were)
            theta[j: j + 3] = rng.uniform(-0.2, 0.2) if c else 0.0, mag * math.cos(ang), mag * math.sin(ang)
        theta[j + 3: j + 6] = *(hand.uniform(-1, 1, 2) * tol[j + 3: j + 5]), hand.uniform(-1, 1) * tol[j + 5]
        if first is not None:  # the same spacer and wedge, turned with the screen
            f = M.screen_index(first)
            turn = plan.turns[c] + theta[j + 5] - plan.turns[first] - theta[f + 5]
            w = theta[f + 1: f + 3]
            theta[j: j + 3] = theta[f], *(turn_matrix(turn)[:2, :2] @ w)
    for c in range(len(plan)):
        mag, ang = seat.uniform(0, cal.screen_seating), seat.uniform(0, 2 * math.pi)
        theta[M.screen_index(c) + 1: M.screen_index(c) + 3] += mag * math.cos(ang), mag * math.sin(ang)
    theta[[M.parameter_names(len(plan)).index(n) for n in M.GAUGE]] = 0.0
    return theta


def sub_offsets(s: int) -> np.ndarray:
    return (np.arange(s) + 0.5) / s - 0.5


def as_read(cam: M.Camera, images: list[dict[str, np.ndarray]]) -> list[dict[str, np.ndarray]]:
    """:func:`render`'s captures as ``rigcad calibrate --images`` reads files: the camera's window
    of each frame, as float in [0, 1] (:func:`rigcad.calibrate.images.read_image`)."""
    return [{n: cam.crop(im).astype(float) / 255.0 for n, im in f.items()} for f in images]


def render(optics, rig, theta: np.ndarray, surface: SurfaceError | None, cam: M.Camera, seq: Sequence,
           plan: M.Plan, rng: np.random.Generator, placement: np.ndarray | None = None) -> list[dict[str, np.ndarray]]:
    """Per capture (``plan``, then the upright display's, :mod:`rigcad.calibrate.upright`), every
    frame as the camera records it: full-resolution uint8 images (rows, cols) (module docstring).
    ``theta``: the true misalignment (model parameters); ``placement``: the upright captures' true
    placements (:func:`rigcad.calibrate.upright.random_placement`), with ``calibration.upright_turns``.
    The upright display is seen off the mirrors only, on its face (its back, and the screen seen
    edge on past the paraboloid, are dark), and exposed for the paraboloid's image: nothing else
    of the window is lit, so its mirrors' loss costs no exposure."""
    from rigcad.calibrate.upright import Uprights

    ups = Uprights.of(rig.profile)
    if len(ups) and (placement is None or len(placement) != len(ups)):
        raise ValueError(f"render: {len(ups)} upright captures need their placements")
    s = rig.profile.calibration.sim_supersample
    true_rig = M.moved(rig, theta)
    off = sub_offsets(s)
    ox, oy = [a.ravel() for a in np.meshgrid(off, off)]
    x = (cam.x_px[:, None] + ox[None, :]).ravel()
    y = (cam.y_px[:, None] - oy[None, :]).ravel()
    tr = with_surface(true_rig, surface, M.trace_camera(optics, true_rig, x, y, cam.design))
    gain = mirror_loss(rig, tr)
    # pixels with a sub-ray on a screen's side, off the mirrors or direct
    out = [_capture(rig, cam, seq, *tr.screen(pose), tr.ok | tr.direct, gain, rng) for pose in M.screens(plan, theta)]
    for pose in ups.poses(placement if len(ups) else np.zeros((0, 6))):
        su, sv = tr.screen(pose)
        face = tr.ok & (np.nan_to_num(tr.v) @ pose.rotation[:, 2] < 0)
        out.append(_capture(rig, cam, ups.seq, np.where(face, su, np.nan), np.where(face, sv, np.nan), face,
                            np.ones_like(gain), rng))
    return out


def _capture(rig, cam: M.Camera, seq: Sequence, su: np.ndarray, sv: np.ndarray, seen: np.ndarray, gain: np.ndarray,
             rng: np.random.Generator) -> dict[str, np.ndarray]:
    """One capture's frames from each sub-ray's screen point (``su``, ``sv`` mm; ``seen``: the
    sub-rays on the screen's side) and its share of the light (``gain``)."""
    from scipy.ndimage import gaussian_filter

    cal = rig.profile.calibration
    s = cal.sim_supersample
    n = len(cam.x_px)
    width, height = cam.resolution
    cx, cy = seq.from_mm(su, sv)
    edges = sub_edges(cx.reshape(n, s, s), cy.reshape(n, s, s), cam.shape)
    lit = np.repeat(seen.reshape(n, s * s).any(axis=1), s * s)
    means = seq.footprint_means(seq.names(), np.nan_to_num(cx[lit], nan=-1e9), np.nan_to_num(cy[lit], nan=-1e9),
                                edges[lit])
    frames = {}
    for name in seq.names():
        val = np.zeros(n * s * s)
        val[lit] = means[name]
        expected = (gain * (BLACK_LEVEL + (WHITE_LEVEL - BLACK_LEVEL) * val)).reshape(n, s * s).mean(axis=1)
        expected = gaussian_filter(expected.reshape(cam.shape), cal.sim_blur) if cal.sim_blur > 0 else \
            expected.reshape(cam.shape)
        frames[name] = _expose(expected, cam, (height, width), cal, rng)
    return frames


def mirror_loss(rig, tr: M.Traced) -> np.ndarray:
    """Each sub-ray's share of the screen's light that reaches the camera (n,): the two mirrors'
    ``coating.reflectance`` squared off the mirrors, 1 seen directly past the paraboloid, 1 where it
    sees no screen (the black level there is the room's)."""
    return np.where(tr.ok, rig.profile.coating.reflectance ** 2, 1.0)


def sub_edges(cx: np.ndarray, cy: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Each sub-ray's footprint edges on the screen (n * s * s, 2, 2) px: the landing point's change
    over one sub-pixel step along the camera's columns and rows, from neighbouring pixels' centre
    sub-rays (central differences over the window; NaN neighbours give a point sample)."""
    n, s, _ = cx.shape
    mid = s // 2
    cxm, cym = cx[:, mid, mid].reshape(shape), cy[:, mid, mid].reshape(shape)
    e = np.zeros((n, 2, 2))
    for k, c in enumerate((cxm, cym)):
        with np.errstate(invalid="ignore"):
            e[:, 0, k] = np.nan_to_num(np.gradient(c, axis=1).ravel()) / s
            e[:, 1, k] = np.nan_to_num(np.gradient(c, axis=0).ravel()) / s
    return np.repeat(e, s * s, axis=0)


def _expose(expected: np.ndarray, cam: M.Camera, size: tuple[int, int], cal, rng) -> np.ndarray:
    """Photon (Poisson) and read (Gaussian) noise on the window's expected exposure (fractions of
    the full well), read noise elsewhere, quantised to 8 bits (255 = the full well)."""
    full = cal.sim_full_well
    image = rng.normal(0.0, cal.sim_read_noise, size)
    win = image[cam.row0: cam.row0 + cam.shape[0], cam.col0: cam.col0 + cam.shape[1]]
    win += rng.poisson(np.clip(expected, 0, None) * full)
    return np.clip(np.round(image * 255.0 / full), 0, 255).astype(np.uint8)
