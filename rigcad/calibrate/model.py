"""The rig's own analytic tracer as the calibration's forward model: a camera pixel's ray from the
camera's COP (as placed by its pose), through the beam splitter's plate (as the ray check traces
the camera), off the paraboloid and the dome (``Rig.moved`` poses), to the screen.

Parameters (mm, rad): the paraboloid's, the dome's and the camera's offsets (x, y, z) and tilts
(the rotation vector's x and y; pivots as :meth:`rigcad.optics.frames.Misalignment.pose`), then per
capture (:class:`Plan`) the screen's height offset, its tilt (x, y) and where the hand laid it
within its plane: its centre's offset (u, v) and its turn about its normal from the capture's
nominal one (:func:`rigcad.calibrate.raxel.screen_pose`).
Frame: mm, O at the origin, +z up; the gauge (:data:`GAUGE`) puts the first screen's centre on the
axis at its nominal height."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rigcad.calibrate.raxel import on_screen, screen_pose

COMPONENTS = ("paraboloid", "dome", "camera")
RIG_NAMES = tuple(f"{c}_{k}" for c in COMPONENTS for k in ("dx_mm", "dy_mm", "dz_mm", "tilt_x_rad", "tilt_y_rad"))
#: Pixels of margin around the paraboloid's design image in the camera window: a camera tilted by the
#: largest tolerance the profile accepts moves the image ~ f tan(tilt) (21 px at 0.5 deg on Table 3.1).
WINDOW_MARGIN_PX = 40


#: Each screen height's parameters, in order (:func:`screens`).
SCREEN_KEYS = ("dz_mm", "tilt_x_rad", "tilt_y_rad", "du_mm", "dv_mm", "turn_rad")
#: How well a hand lays the screen on a spacer, centred on the axis and square (the kit's page asks
#: for it): the placement parameters' tolerance (mm, rad).
PLACEMENT_MM = 1.0
PLACEMENT_TURN_RAD = math.radians(1.0)
#: The parameters no image can tell from the rest, held at zero: moving the rig and every screen up
#: together, or sideways together, changes no image; the first screen fixes both (its height and
#: its centre: the frame's origin, which moves no direction).
GAUGE = ("screen0_dz_mm", "screen0_du_mm", "screen0_dv_mm")


@dataclass(frozen=True)
class Plan:
    """The captures, in the order the kit's page gives them: one per spacer (label ``h<k>``), then,
    with ``calibration.half_turn`` 'highest', the highest spacer's again with the spacer and the
    screen on it turned a half turn together (``h<k>r``): up there a tilt of the screen shows most
    on the rays (docs/calibrate.md, "The half turn"); with 'every', each spacer's. Per capture: the
    screen's nominal height (mm above O, :func:`nominal_heights`), its nominal turn about the axis
    (rad: 0, or pi), the spacer's index."""

    heights: np.ndarray
    turns: np.ndarray
    labels: tuple[str, ...]
    spacers: tuple[int, ...]

    @classmethod
    def of(cls, profile) -> "Plan":
        z = nominal_heights(profile)
        again = {"highest": (int(np.argmax(z)),), "every": tuple(range(len(z))), "none": ()}
        spacers = tuple(range(len(z))) + again[profile.calibration.half_turn]
        turned = [c >= len(z) for c in range(len(spacers))]
        return cls(z[list(spacers)], np.where(turned, math.pi, 0.0),
                   tuple(f"h{k}r" if t else f"h{k}" for k, t in zip(spacers, turned)), spacers)

    def __len__(self) -> int:
        return len(self.labels)

    def repeats(self, c: int) -> int | None:
        """The capture that capture ``c`` repeats turned (same spacer, taken before), or None."""
        first = self.spacers.index(self.spacers[c])
        return first if first != c else None


def screen_names(k: int) -> tuple[str, ...]:
    return tuple(f"screen{k}_{key}" for key in SCREEN_KEYS)


def parameter_names(captures: int) -> tuple[str, ...]:
    return RIG_NAMES + tuple(n for k in range(captures) for n in screen_names(k))


def screen_index(k: int) -> int:
    """Where screen ``k``'s parameters (:data:`SCREEN_KEYS`, in order) start in the parameter vector."""
    return len(RIG_NAMES) + len(SCREEN_KEYS) * k


def tolerance_scale(rig, captures: int) -> np.ndarray:
    """Each parameter's tolerance (``tolerancing``; the screen's: 0.5 mm for its height, the
    ``calibration.screen_tilt`` wedge and ``screen_seating`` together for its tilt,
    :data:`PLACEMENT_MM` and :data:`PLACEMENT_TURN_RAD` within its plane), for ``captures`` screens: the
    fit's scale and prior (:func:`prior_root`), and the recovery targets' reference."""
    t = rig.profile.tolerancing
    out = []
    for c in COMPONENTS:
        off, hgt, tilt = getattr(t, f"{c}_offset"), getattr(t, f"{c}_height"), getattr(t, f"{c}_tilt")
        out += [off, off, hgt, tilt, tilt]
    cal = rig.profile.calibration
    tilt = math.hypot(cal.screen_tilt, cal.screen_seating)
    out += [0.5, tilt, tilt, PLACEMENT_MM, PLACEMENT_MM, PLACEMENT_TURN_RAD] * captures
    return np.array(out)


def recovery_targets(rig, captures: int) -> np.ndarray:
    """Each parameter's recovery target (mm, rad): a tenth of its tolerance (:func:`tolerance_scale`),
    but at least 0.02 mm or 0.01 deg: what the bench holds the fit to, and what a correlation has to
    spoil to matter (:meth:`rigcad.calibrate.fit.FitResult.as_dict`)."""
    floor = [math.radians(0.01) if n.endswith("_rad") else 0.02 for n in parameter_names(captures)]
    return np.maximum(0.1 * tolerance_scale(rig, captures), floor)


def prior_root(rig, plan: Plan) -> np.ndarray:
    """A square root R (R^T R = C^-1) of the prior's inverse covariance C over the parameters in
    :func:`tolerance_scale`'s units: each ~ N(0, 1), independent, but for a turned capture's tilt
    and the one it repeats. Their wedge w (``screen_tilt``) is one, turned a half turn: tilts w + e
    and -w + e', each e within ``screen_seating``, so per axis the pair's mean is known to the
    seating / sqrt 2 and their half difference to the wedge: the rows are the mean's and the half
    difference's, whitened (the turn's hand error, ~1 deg of the half turn, leaves ~1/60 of the
    wedge in the mean: 0.003 deg at 0.2 deg). No image shows the sample plane; these priors, with the
    rig's tolerances, set the map's frame (docs/calibrate-notes.md, "What fixes the frame")."""
    root = np.eye(len(RIG_NAMES) + len(SCREEN_KEYS) * len(plan))
    cal = rig.profile.calibration
    rho = cal.screen_tilt ** 2 / (cal.screen_tilt ** 2 + cal.screen_seating ** 2)  # -correlation, per axis
    for c in range(len(plan)):
        first = plan.repeats(c)
        if first is None:
            continue
        for axis in (1, 2):
            i, j = screen_index(first) + axis, screen_index(c) + axis
            root[[i, j]] = 0.0
            root[i, [i, j]] = 1 / math.sqrt(2 * (1 - rho))  # the mean, (z_i + z_j) / 2, over its sigma
            root[j, [i, j]] = 1 / math.sqrt(2 * (1 + rho)), -1 / math.sqrt(2 * (1 + rho))
    return root


def frame_tilt_variance(profile, plan: Plan) -> float:
    """The variance (rad^2) per axis of the map's frame: the tilt of the sample plane under the rig,
    which no image shows and the screens' placement on their spacers alone fixes. The profile's
    ``screen_tilt`` (the wedge) and ``screen_seating`` are bounds, read as the simulation plants them
    and as ``rigcad calibrate --seating`` states a seat: a tilt uniform in size within the bound and
    in direction, whose spread per axis is the bound^2 / 6. A turned capture and the one it repeats
    (the half turn) cancel their wedge: their mean is known to the seating^2 / 12; a capture with no
    partner only to (wedge^2 + seating^2) / 6. The captures combine by their inverse variances. The
    rig's tolerances, which the fit's prior also holds the frame by, are not counted: they state how
    a part may be built, not where this one is."""
    cal = profile.calibration
    paired = {c for c in range(len(plan)) if plan.repeats(c) is not None}
    paired |= {plan.repeats(c) for c in paired}
    pairs = sum(plan.repeats(c) is not None for c in range(len(plan)))
    alone = len(plan) - len(paired)
    information = pairs * 12 / cal.screen_seating ** 2 + alone * 6 / (cal.screen_tilt ** 2 + cal.screen_seating ** 2)
    return 1.0 / information


def moved(rig, theta: np.ndarray):
    """``rig`` moved by the rig parameters ``theta[:15]`` (module docstring). The copies share the
    rig's layout (:func:`direct_view` reads its dome) and maps, whichever of them makes them first
    (``Rig.moved``)."""
    out = rig
    for i, c in enumerate(COMPONENTS):
        dx, dy, dz, tx, ty = (float(v) for v in theta[5 * i: 5 * i + 5])
        angle = math.hypot(tx, ty)
        axis = (tx / angle, ty / angle, 0.0) if angle > 0 else (0.0, 1.0, 0.0)
        out = out.moved(c, (dx, dy, dz), angle, axis)
    return out


#: The paraboloid's and the camera's placement against the dome (:func:`in_dome_frame`), named as
#: their parameters in the sample frame.
DOME_FRAME_NAMES = tuple(n for n in RIG_NAMES if not n.startswith("dome"))


def in_dome_frame(rig, theta: np.ndarray) -> np.ndarray:
    """(10,) the paraboloid's and the camera's offsets (mm) and tilts (rad) against the dome, as
    ``theta[:15]`` places the three (:data:`DOME_FRAME_NAMES`): each component's pose taken into
    the dome's frame (the dome's pose undone) and read back as an offset of its pivot and a tilt
    about it (:meth:`rigcad.optics.frames.Misalignment.pivot`); exact, not linearised. Turning or
    shifting the whole rig together changes none of them: they are what the images fix apart from
    the frame (the sample plane's tilt under the rig, which only the priors fix; docs/calibrate-notes.md,
    "The rig against its dome"). A turn about the dome's axis is not a parameter and is dropped."""
    from scipy.spatial.transform import Rotation

    from rigcad.optics.frames import Misalignment

    placed = moved(rig, theta)
    dome = placed.pose("dome")
    out = []
    for c in ("paraboloid", "camera"):
        pose, pivot = placed.pose(c), np.array(Misalignment.pivot(c, rig.geometry), float)
        at = (pose.globalize_points(pivot[None])[0] - dome.translation) @ dome.rotation
        tilt = Rotation.from_matrix(dome.rotation.T @ pose.rotation).as_rotvec()
        out += [*(at - pivot), tilt[0], tilt[1]]
    return np.array(out)


def in_dome_frame_covariance(rig, theta: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """(10, 10) :func:`in_dome_frame`'s covariance from the parameters' (``covariance``, over
    ``theta``; the rig's 15 first), through :func:`covariance_through`."""
    return covariance_through(lambda t: in_dome_frame(rig, t), theta, covariance, RIG_NAMES)


def covariance_through(f, theta: np.ndarray, covariance: np.ndarray, names) -> np.ndarray:
    """The covariance of ``f(theta)`` from the parameters' (``covariance``, over ``theta``), through
    f's Jacobian in the parameters ``names`` (the first ``len(names)`` of theta; f does not move
    with the rest) by central differences: steps of 0.1 um and 10 urad, a thousandth of the
    tightest tolerances (with ten times smaller steps :func:`in_dome_frame`'s covariance moves by
    ~3e-9 of its scale at a tolerance-sized misalignment, measured one-off)."""
    n = len(names)
    step = np.array([1e-5 if name.endswith("_rad") else 1e-4 for name in names])
    columns = []
    for i in range(n):
        e = np.zeros(len(theta))
        e[i] = step[i]
        columns.append((np.ravel(f(theta + e)) - np.ravel(f(theta - e))) / (2 * step[i]))
    jac = np.stack(columns, axis=1)
    return jac @ covariance[:n, :n] @ jac.T


def screens_in_dome_frame(rig, plan: Plan, theta: np.ndarray) -> np.ndarray:
    """(captures, 2) each screen's tilt against the dome (rad): the x and y of the rotation vector
    of the shortest turn from the dome's axis to the screen's normal, in the dome's frame; exact,
    not linearised. Turning the rig and every screen together changes none of them, and neither
    does a screen's turn about its normal: across calibrations of one rig, left as it is, the same
    spacer's screen laid again differs only by how it settles (rigcad.calibrate.seating)."""
    dome = moved(rig, theta).pose("dome")
    normals = np.array([pose.rotation[:, 2] for pose in screens(plan, theta)]) @ dome.rotation
    axes = np.cross([0.0, 0.0, 1.0], normals)  # sin(angle) times the turn's unit axis
    sin = np.linalg.norm(axes, axis=1)
    scale = np.where(sin > 0, np.arctan2(sin, normals[:, 2]) / np.where(sin > 0, sin, 1.0), 1.0)
    return axes[:, :2] * scale[:, None]


def screens(plan: Plan, theta: np.ndarray) -> list:
    """The screens' poses: each capture's nominal height and turn plus its parameters in ``theta``."""
    s = np.asarray(theta[len(RIG_NAMES):]).reshape(-1, len(SCREEN_KEYS))
    return [screen_pose(float(h + p[0]), *(float(v) for v in p[1:5]), turn=float(t + p[5]))
            for h, t, p in zip(plan.heights, plan.turns, s)]


@dataclass(frozen=True)
class Camera:
    """The camera's pixels in a window around the paraboloid's image: ``shape`` (rows, cols), the
    window's first ``row0``/``col0``, image coordinates x_px, y_px (n,) row-major (pixel centre
    x = col + 0.5 - c_x, y = c_y - row - 0.5 about the principal point (c_x, c_y), the image's centre
    (W / 2, H / 2) unless ``camera.principal_point`` moves it) and the design map in the camera's
    pixels (its focal length the lens's: rigcad.optics.camera)."""

    resolution: tuple[int, int]
    shape: tuple[int, int]
    row0: int
    col0: int
    x_px: np.ndarray
    y_px: np.ndarray
    design: object
    principal_point: tuple[float, float] = (math.nan, math.nan)

    @classmethod
    def of(cls, rig, stride: int = 1) -> "Camera":
        import dataclasses

        from rigcad.optics.camera import camera_model

        model = camera_model(rig.profile, rig.geometry)
        design = dataclasses.replace(rig.incidence, focal_px=model.focal_px)
        width, height = rig.profile.camera.resolution
        cx, cy = model.principal_point
        r = float(design.pixel_radius(np.array([design.alpha_max]))[0])
        side = 2 * math.ceil(r) + 2 * WINDOW_MARGIN_PX
        w, h = min(width, side), min(height, side)
        # the window about the principal point, kept on the sensor ((W - w) // 2 for the centre)
        c0 = min(max(math.floor(cx - w / 2), 0), width - w)
        r0 = min(max(math.floor(cy - h / 2), 0), height - h)
        rows, cols = np.arange(r0, r0 + h, stride), np.arange(c0, c0 + w, stride)
        jj, ii = np.meshgrid(rows, cols, indexing="ij")
        return cls((width, height), (len(rows), len(cols)), int(r0), int(c0), ii.ravel() + 0.5 - cx,
                   cy - jj.ravel() - 0.5, design, (cx, cy))

    def crop(self, image: np.ndarray) -> np.ndarray:
        """The window of a full camera image (rows, cols, ...); an image of the window's size is taken
        as the window already (the capture reader cuts it first: ``images.read_capture``)."""
        if image.shape[:2] == self.shape:
            return image
        return image[self.row0: self.row0 + self.shape[0], self.col0: self.col0 + self.shape[1]]

    def mirrored_core(self, rig) -> np.ndarray:
        """(rows, cols) the window's pixels that see the paraboloid's useful annulus in any build
        within ``tolerancing``: the design's annulus (alpha_min to alpha_max) shrunk on both sides by
        the most the camera's tilt and the camera's and the paraboloid's lateral offsets move the
        image, f tan(tilt) + f (offsets) / (COP to vertex): 26 px of the 9-134 px annulus on Table
        3.1. The capture check counts the decoded pixels there, where the screen seen directly past
        the paraboloid (:func:`direct_view`, more pixels of the window than the mirrors') cannot
        stand in for the mirrors."""
        t, g = rig.profile.tolerancing, rig.geometry
        f = self.design.focal_px
        shift = f * math.tan(t.camera_tilt) + f * (t.camera_offset + t.paraboloid_offset) / (g.cop_z - g.vertex_z)
        lo, hi = self.design.pixel_radius(np.array([self.design.alpha_min, self.design.alpha_max]))
        r = np.hypot(self.x_px, self.y_px)
        return ((r > lo + shift) & (r < hi - shift)).reshape(self.shape)


@dataclass
class Traced:
    """Per pixel: the ray leaving the dome (point ``p2`` and unit direction ``v``, going down), the
    direction ``u`` from the paraboloid to the dome, and ``ok`` (reached the sample plane off both
    mirrors). ``direct``: the pixel's ray passes the paraboloid and its mount, through the dome's top
    opening and past the beam, to the sample plane (:func:`direct_view`); ``p2`` and ``v`` are then
    the ray below the splitter, and ``u`` is NaN."""

    p2: np.ndarray
    v: np.ndarray
    u: np.ndarray
    ok: np.ndarray
    direct: np.ndarray

    def screen(self, pose) -> tuple[np.ndarray, np.ndarray]:
        """Where each ray, off the mirrors or direct, meets a screen: (u, v) mm in its frame, NaN
        where lost."""
        p2, v, seen = self._finite
        su, sv = on_screen(pose, p2, v)
        return np.where(seen, su, np.nan), np.where(seen, sv, np.nan)

    @cached_property
    def _finite(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``p2`` and ``v`` with the lost rays' NaNs replaced (a ray a screen is met along), and
        the rays seen: made once for every screen a trace is met with."""
        return np.nan_to_num(self.p2), np.nan_to_num(self.v, nan=1.0), self.ok | self.direct


def trace_camera(optics, rig, x_px: np.ndarray, y_px: np.ndarray, design) -> Traced:
    """Trace camera image points (x, y) px through ``rig`` (moved copy of the rig ``optics`` was
    built for): from the camera's pose, through the splitter (compensated, as built), to the dome."""
    from rigcad.check.scene import placed_as
    from rigcad.check.sources import pixel_rays
    from rigcad.check.tower import through_splitter
    from rigcad.check.trace3d import MISSED_PARABOLOID, trace

    rays = pixel_rays(design, x_px, y_px, rig.pose("camera"))
    p, d, _ = through_splitter(rig, rays.origins, rays.dirs)
    placed = placed_as(optics, rig)
    tr = trace(placed, p, d)
    with np.errstate(invalid="ignore"):
        u = tr.p2 - tr.p1
        u /= np.linalg.norm(u, axis=1)[:, None]
    direct = direct_view(placed, rig, p, d, tr.status == MISSED_PARABOLOID)
    return Traced(np.where(direct[:, None], p, tr.p2), np.where(direct[:, None], d, tr.v), u, tr.ok, direct)


#: Points along the dome's meridian that a direct ray must pass inside (:func:`direct_view`).
DIRECT_MERIDIAN_POINTS = 65


def direct_view(optics, rig, p: np.ndarray, d: np.ndarray, passed: np.ndarray) -> np.ndarray:
    """(n,) which rays (points ``p`` below the splitter, unit directions ``d``, going down) the camera
    sees the sample plane along directly: ``passed`` the paraboloid and its mount (the tracer's
    status), then in the dome's frame inside its mirror at each of :data:`DIRECT_MERIDIAN_POINTS`
    heights of its meridian (the first is the top opening's edge), and clear of the beam down to the
    sample plane. The dome's top opening is wider than the paraboloid's image: on Table 3.1 the
    camera sees the screen directly between ~134 and ~337 px from the axis, past the tower's parts."""
    out = np.zeros(len(p), bool)
    i = np.nonzero(passed & (d[:, 2] < 0))[0]
    if not i.size:
        return out
    lo, ld = optics.dome_pose.localize(p[i], d[i])
    mer = rig.layout.design_dome
    rz = mer.points(np.linspace(*mer.u_range, DIRECT_MERIDIAN_POINTS))
    # the line's squared distance from the axis at height z, a quadratic a z^2 + b z + c: fewer
    # passes over the (rays, heights) table than x(t), y(t) and their hypot (every trace of the
    # fit, and of the map's Jacobian over the whole window, classifies its rays here: 3x faster, the
    # same decisions on 17,301 rays, one-off)
    sx, sy = ld[:, 0] / ld[:, 2], ld[:, 1] / ld[:, 2]
    x0, y0 = lo[:, 0] - lo[:, 2] * sx, lo[:, 1] - lo[:, 2] * sy
    a, b, c = sx * sx + sy * sy, 2 * (x0 * sx + y0 * sy), x0 * x0 + y0 * y0
    z = rz[:, 1]
    inside = np.all(np.outer(a, z * z) + np.outer(b, z) + c[:, None] < rz[:, 0] ** 2, axis=1)
    to_plane = -p[i, 2] / d[i, 2]
    clear = ~np.isfinite(optics.beam.intersect(lo, ld, to_plane).t)
    out[i] = inside & clear
    return out


def nominal_heights(profile) -> np.ndarray:
    """The screen's emitting surface at each spacer (mm above O): spacer + screen thickness - the
    sample's thickness (the spacer stands on the holder's seat, where a sample's underside rests)."""
    cal = profile.calibration
    return np.array(cal.spacer_heights) + cal.screen_thickness - profile.sample_holder.sample_thickness
