"""The calibration against captures it did not render itself. Every other calibration test fits
images that rigcad.calibrate.simulate draws with the fit's own tracer (rigcad.calibrate.model,
rigcad.check), so a convention both get wrong alike (a tilt's sign, a pivot, the screen's axes,
the Gray code's polarity, the splitter's refraction) cannot show there. Here a renderer written
from the documented conventions alone (docs/calibrate.md, "Capture conventions") draws the
capture: its own pinhole camera, Snell's law through the splitter plate, the paraboloid in closed
form, the dome as a surface of revolution re-splined from its design meridian's points and hit by
bisection, the occluders (the paraboloid's mount, the beam) as trimesh meshes of the recipes' boxes
and cylinders cast by Embree, the screens placed as the docs say, and the patterns written out from
their formulas. From the rig it reads design data only: the geometry's figures, the plate, the
meridian's points, the occluders' sizes, the camera's intrinsics, the window's place.

A planted misalignment (the paraboloid, the dome and the camera moved and tilted within tolerance,
the screens laid off centre, turned, on wedged spacers, one spacer turned a half turn) is rendered,
calibrated by ``rigcad.calibrate.run.calibrate``, and the paraboloid's and the camera's placement
against the dome (what the images fix) must come back within their stated standard errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.ndimage import gaussian_filter
from scipy.spatial.transform import Rotation

#: The small camera of tests/calibrate/test_simulate_fit.py (seconds, not minutes), flat screens only.
SMALL = ("extends: achutha2006\ncamera:\n  resolution: [340, 256]\ncalibration:\n  sim_blur: 0.3\n"
         "  spacer_heights: [2 mm, 9 mm]\n  half_turn: highest\n  upright_turns: 0\n")
#: Sub-rays per pixel side: the renderer point-samples the screen's pixels (no footprint integral).
SUB = 5
#: The exposure (fractions of the full well): the screen's black, its white, a pixel that sees no screen.
BLACK, WHITE, ROOM = 0.015, 0.8, 0.005
DEG = math.pi / 180


def rotation(tilt_x: float, tilt_y: float) -> np.ndarray:
    """The docs' tilt: one rotation, the rotation vector (tilt_x, tilt_y, 0) rad, right-handed."""
    return Rotation.from_rotvec([tilt_x, tilt_y, 0.0]).as_matrix()


def turn(angle: float) -> np.ndarray:
    return Rotation.from_rotvec([0.0, 0.0, angle]).as_matrix()


class Body:
    """A part moved as the docs say: tilted about its pivot, then shifted by its offset (mm)."""

    def __init__(self, pivot, offset, tilt):
        self.pivot, self.offset, self.r = np.asarray(pivot, float), np.asarray(offset, float), rotation(*tilt)

    def to_local(self, p, d):
        return (p - self.pivot - self.offset) @ self.r + self.pivot, d @ self.r

    def to_global(self, p, d):
        return (p - self.pivot) @ self.r.T + self.pivot + self.offset, d @ self.r.T

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.r
        m[:3, 3] = self.pivot + self.offset - self.r @ self.pivot
        return m


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def reflect(d, n):
    return d - 2 * np.sum(d * n, axis=1)[:, None] * n


def refract(d, n, eta):
    """Snell's law: unit d through a face of unit normal n (facing against d), index ratio eta."""
    cos_i = -np.sum(d * n, axis=1)
    k = 1 - eta ** 2 * (1 - cos_i ** 2)
    return unit(eta * d + (eta * cos_i - np.sqrt(k))[:, None] * n)


def plane_hit(p, d, point, normal):
    t = ((point - p) @ normal) / (d @ normal)
    return p + t[:, None] * d


class World:
    """The rig built and misaligned (``planted``: component -> (offset (3,), tilt (2,))), its
    screens (``screens``: per capture (height, tilt_x, tilt_y, du, dv, turn), mm and rad)."""

    def __init__(self, rig, planted: dict, screens: list):
        import trimesh

        from rigcad.optics.camera import camera_model

        geo, tower, self.rig = rig.geometry, rig.layout.tower, rig
        self.f, self.zv, self.rim, self.cop_z = geo.focal_length, geo.vertex_z, geo.rim_radius, geo.cop_z
        cam = camera_model(rig.profile, geo)
        self.focal_px, self.principal = cam.focal_px, cam.principal_point
        self.plate, self.compensation = tower.plate, np.asarray(tower.camera.offset)
        pivots = {"paraboloid": (0, 0, geo.vertex_z), "dome": (0, 0, 0), "camera": (0, 0, geo.cop_z)}
        self.body = {c: Body(pivots[c], *planted[c]) for c in pivots}
        mer = rig.layout.design_dome
        rz = mer.points(np.linspace(*mer.u_range, 4001))
        self.radius = CubicSpline(rz[:, 1], rz[:, 0])
        self.z_lo, self.z_hi = float(rz[0, 1]), float(rz[-1, 1])
        self.screens = screens

        def mesh(solids, body):
            parts = []
            for _, s in solids:
                if hasattr(s, "radius"):  # a recipe Cylinder along +z from its base
                    c = trimesh.creation.cylinder(s.radius, s.height, sections=720)
                    c.apply_translation(np.asarray(s.base) + [0, 0, s.height / 2])
                else:  # a recipe Box between its corners
                    c = trimesh.creation.box(bounds=[s.lo, s.hi])
                parts.append(c)
            m = trimesh.util.concatenate(parts)
            m.apply_transform(body.matrix())
            return m

        self.occluders = [mesh(rig.occluders["paraboloid"], self.body["paraboloid"]),
                          mesh(rig.occluders["beam"], self.body["dome"])]

    def camera_rays(self, x_px, y_px):
        """Pinhole rays through image points (px about the principal point), through the plate."""
        d = unit(np.stack([x_px, y_px, np.full_like(x_px, -self.focal_px)], axis=1))
        o = np.tile([0.0, 0.0, self.cop_z], (len(d), 1))
        o, d = self.body["camera"].to_global(o, d)
        o = o + self.compensation  # the camera stands where the plate's shift is made good
        n, c = np.asarray(self.plate.normal), np.asarray(self.plate.center)
        p = plane_hit(o, d, c - self.plate.thickness * n, n)
        d = refract(d, -n, 1 / self.plate.index)
        p = plane_hit(p, d, c, n)
        return p, refract(d, -n, self.plate.index)

    def paraboloid(self, p, d):
        """The first hit on z = zv - r^2 / (4 f), r <= rim: (t (n,), NaN for none; normal (n, 3)) in
        the paraboloid's frame."""
        a = (d[:, 0] ** 2 + d[:, 1] ** 2) / (4 * self.f)
        b = (p[:, 0] * d[:, 0] + p[:, 1] * d[:, 1]) / (2 * self.f) + d[:, 2]
        c = (p[:, 0] ** 2 + p[:, 1] ** 2) / (4 * self.f) + p[:, 2] - self.zv
        with np.errstate(invalid="ignore", divide="ignore"):
            sq = np.sqrt(b * b - 4 * a * c)
            roots = np.stack([(-b - sq) / (2 * a), (-b + sq) / (2 * a)], axis=1)
        q = p[:, None, :] + roots[:, :, None] * d[:, None, :]
        good = (roots > 1e-7) & (q[:, :, 0] ** 2 + q[:, :, 1] ** 2 <= self.rim ** 2)
        t = np.min(np.where(good, roots, np.inf), axis=1)
        t[~np.isfinite(t)] = np.nan
        x = p + np.nan_to_num(t)[:, None] * d
        return t, unit(np.stack([x[:, 0] / (2 * self.f), x[:, 1] / (2 * self.f), np.ones(len(p))], axis=1))

    def dome(self, p, d):
        """Where rays from inside the dome (its frame) meet r = R(z) by bisection, and the
        reflected directions; NaN where a ray leaves through an opening first."""
        with np.errstate(divide="ignore", invalid="ignore"):
            t_end = np.where(d[:, 2] > 1e-12, (self.z_hi - p[:, 2]) / d[:, 2],
                             np.where(d[:, 2] < -1e-12, (self.z_lo - p[:, 2]) / d[:, 2], 1e3))
        outside = lambda t: (np.hypot(*(p[:, :2] + t[:, None] * d[:, :2]).T)  # noqa: E731
                             - self.radius(np.clip(p[:, 2] + t * d[:, 2], self.z_lo, self.z_hi)))
        hit = outside(t_end) > 0
        lo, hi = np.zeros(len(p)), t_end.copy()
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            out = outside(mid) > 0
            hi, lo = np.where(out, mid, hi), np.where(out, lo, mid)
        x = p + hi[:, None] * d
        r = np.hypot(x[:, 0], x[:, 1])
        n = unit(np.stack([x[:, 0] / r, x[:, 1] / r, -self.radius(x[:, 2], 1)], axis=1))
        return np.where(hit[:, None], x, np.nan), np.where(hit[:, None], reflect(d, n), np.nan)

    def blocked(self, p, d, length):
        """Rays (global) that meet an occluder within ``length`` mm, or the paraboloid's face."""
        out = np.zeros(len(p), bool)
        for m in self.occluders:
            loc, ray, _ = m.ray.intersects_location(p, d, multiple_hits=False)
            dist = np.linalg.norm(loc - p[ray], axis=1)
            out[ray[dist < length[ray]]] = True
        lp, ld = self.body["paraboloid"].to_local(p, d)
        t, _ = self.paraboloid(lp, ld)
        return out | (np.nan_to_num(t, nan=np.inf) < length)

    def trace(self, x_px, y_px):
        """Each image point's last segment towards the screens (global points, unit directions),
        its share of the light (both mirrors' reflectance, or 1 seen directly past the paraboloid),
        whether it reaches the screens at all, whether off the mirrors, and its direction leaving
        the dome (NaN where not off the mirrors)."""
        p, d = self.camera_rays(x_px, y_px)
        para, dome = self.body["paraboloid"], self.body["dome"]
        lp, ld = para.to_local(p, d)
        t, n = self.paraboloid(lp, ld)
        start, way, v = p.copy(), d.copy(), np.full_like(p, np.nan)
        i = np.nonzero(np.isfinite(t))[0]
        x1, u = para.to_global(lp[i] + t[i, None] * ld[i], reflect(ld[i], n[i]))
        x2, v2 = dome.to_global(*self.dome(*dome.to_local(x1, u)))
        keep = np.all(np.isfinite(x2), axis=1)
        i, x1, u, x2, v2 = i[keep], x1[keep], u[keep], x2[keep], v2[keep]
        keep = ~self.blocked(x1 + 1e-6 * u, u, np.linalg.norm(x2 - x1, axis=1))
        keep &= ~self.blocked(x2 + 1e-6 * v2, v2, np.abs(x2[:, 2] / np.minimum(v2[:, 2], -1e-9)))
        mirrored = np.zeros(len(p), bool)
        mirrored[i[keep]] = True
        start[i[keep]], way[i[keep]], v[i[keep]] = x2[keep], v2[keep], v2[keep]
        # seen directly: past the paraboloid, inside the dome's mirror at every height, clear of the mount
        # and the beam down to the sample plane
        j = np.nonzero(~np.isfinite(t) & (d[:, 2] < 0))[0]
        op, od = dome.to_local(p[j], d[j])
        z = np.linspace(self.z_lo, self.z_hi, 130)
        s = (z[None, :] - op[:, 2:3]) / od[:, 2:3]
        r2 = (op[:, :1] + s * od[:, :1]) ** 2 + (op[:, 1:2] + s * od[:, 1:2]) ** 2
        j = j[np.all(r2 < self.radius(z)[None, :] ** 2, axis=1)]
        j = j[~self.blocked(p[j], d[j], np.abs(p[j, 2] / np.minimum(d[j, 2], -1e-9)))]
        direct = np.zeros(len(p), bool)
        direct[j] = True
        gain = np.where(mirrored, self.rig.profile.coating.reflectance ** 2, 1.0)
        return start, way, gain, mirrored | direct, mirrored, v

    def on_screen(self, k, p, d):
        """Screen ``k``'s pixel coordinates (columns, rows; continuous, px) where the rays meet
        its emitting face from above; NaN off it."""
        cal = self.rig.profile.calibration
        h, tx, ty, du, dv, angle = self.screens[k]
        rs = rotation(tx, ty)
        q, e = (p - [0.0, 0.0, h]) @ rs, d @ rs
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(e[:, 2] < 0, -q[:, 2] / e[:, 2], np.nan)
        local = ((q + t[:, None] * e) - [du, dv, 0.0]) @ turn(angle)
        width, height = cal.screen_resolution
        cx = local[:, 0] / cal.screen_pitch + width / 2
        cy = height / 2 - local[:, 1] / cal.screen_pitch
        off = ~((cx >= 0) & (cx < width) & (cy >= 0) & (cy < height))
        return np.where(off, np.nan, cx), np.where(off, np.nan, cy)


def patterns(cal, cx, cy) -> dict[str, np.ndarray]:
    """Each frame's 8-bit value / 255 at screen pixel coordinates (NaN: no screen), from the docs'
    formulas: the pixel centre c = floor + 0.5; sinusoid round(255 (1/2 + 1/2 cos(2 pi c / P -
    2 pi n / N))); Gray bit b (0 the most significant) of k XOR (k >> 1), k = floor(c / S), S half
    the coarsest period, white where 1."""
    out = {"white": np.where(np.isnan(cx), np.nan, 1.0), "black": np.where(np.isnan(cx), np.nan, 0.0)}
    stripe = max(cal.periods) // 2
    for axis, c in (("x", cx), ("y", cy)):
        centre = np.floor(np.nan_to_num(c)) + 0.5
        k = (centre // stripe).astype(np.int64)
        gray = k ^ (k >> 1)
        for b in range(cal.gray_bits):
            bit = (gray >> (cal.gray_bits - 1 - b)) & 1
            out[f"{axis}_gray{b}"] = np.where(np.isnan(c), np.nan, bit.astype(float))
        for period in cal.periods:
            for n in range(cal.phase_steps):
                value = np.round(255 * (0.5 + 0.5 * np.cos(2 * math.pi * centre / period
                                                           - 2 * math.pi * n / cal.phase_steps))) / 255
                out[f"{axis}_p{period}_s{n}"] = np.where(np.isnan(c), np.nan, value)
    return out


def window_points(world: World):
    """The calibration's window (its place only, rigcad.calibrate.model.Camera) and each pixel's
    SUB x SUB sub-ray image points, from the docs: pixel (row j, column i) has its centre at
    x = i + 0.5 - c_x, y = c_y - j - 0.5 about the principal point."""
    from rigcad.calibrate.model import Camera

    cam = Camera.of(world.rig)
    cx, cy = world.principal
    rows, cols = np.meshgrid(np.arange(cam.row0, cam.row0 + cam.shape[0]),
                             np.arange(cam.col0, cam.col0 + cam.shape[1]), indexing="ij")
    off = (np.arange(SUB) + 0.5) / SUB - 0.5
    ox, oy = np.meshgrid(off, off)
    x = (cols.ravel()[:, None] + 0.5 + ox.ravel()[None, :] - cx).ravel()
    y = (cy - rows.ravel()[:, None] - 0.5 - oy.ravel()[None, :]).ravel()
    return cam.shape, x, y


def render(world: World, seed: int) -> tuple[list[dict], np.ndarray, np.ndarray]:
    """Every capture's frames (the window, floats as the capture reader gives them), each pixel's
    true direction from O towards the light (window row-major, (n, 3); NaN off the mirrors) and
    which pixels are off the mirrors. Blur: the profile's ``calibration.sim_blur`` (the lens's, as
    the decoding's bias correction reads it); Poisson and read noise; 8 bits."""
    rig = world.rig
    cal = rig.profile.calibration
    shape, x, y = window_points(world)
    start, way, gain, seen, mirrored, v = world.trace(x, y)
    rng = np.random.default_rng(seed)
    frames = []
    for k in range(len(world.screens)):
        cx, cy = world.on_screen(k, start, way)
        cx, cy = np.where(seen, cx, np.nan), np.where(seen, cy, np.nan)
        capture = {}
        for name, value in patterns(cal, cx, cy).items():
            light = np.where(np.isnan(value), ROOM, gain * (BLACK + (WHITE - BLACK) * np.nan_to_num(value)))
            expected = gaussian_filter(light.reshape(-1, SUB * SUB).mean(axis=1).reshape(shape), cal.sim_blur)
            electrons = rng.poisson(expected * cal.sim_full_well) + rng.normal(0, cal.sim_read_noise, shape)
            capture[name] = np.clip(np.round(electrons * 255 / cal.sim_full_well), 0, 255) / 255
        frames.append(capture)
    centre = SUB * SUB // 2  # the pixel's centre sub-ray
    truth = np.where(mirrored[centre::SUB * SUB, None], -v[centre::SUB * SUB], np.nan)
    return frames, truth, mirrored[centre::SUB * SUB]


#: The planted build (mm, rad): each part's offset and tilt within its ``tolerancing`` (Table 3.1:
#: the paraboloid 0.1 mm sideways, 0.2 mm in height, 0.2 deg; the dome 0.3, 0.3 mm, 0.1 deg; the
#: camera 0.5, 1 mm, 0.5 deg).
PLANTED = {"paraboloid": ((0.06, -0.045, 0.12), (0.12 * DEG, -0.09 * DEG)),
           "dome": ((-0.2, 0.15, 0.2), (0.06 * DEG, 0.05 * DEG)),
           "camera": ((0.3, -0.35, -0.6), (-0.3 * DEG, 0.25 * DEG))}


def planted_screens(rig) -> list:
    """The small profile's captures (h0, h1, then h1 again turned a half turn: docs/calibrate.md,
    "The half turn") as (height, tilt_x, tilt_y, du, dv, turn) mm and rad: each spacer's screen at
    its nominal height (spacer + screen thickness - sample thickness) plus the spacer's error, on
    its wedge (within ``screen_tilt``) plus how it settled (within ``screen_seating``), laid off
    centre and turned by hand; the turned capture the same spacer and wedge, turned with it. The
    first screen's height and centre are the frame's gauge: as nominal."""
    cal, holder = rig.profile.calibration, rig.profile.sample_holder
    h0, h1 = (s + cal.screen_thickness - holder.sample_thickness for s in cal.spacer_heights)
    wedge = np.array([-0.15 * DEG, 0.06 * DEG])
    turned = math.pi - 0.6 * DEG  # the half turn as laid, against the first laying's -0.5 deg
    w_turned = turn(turned - (-0.5 * DEG))[:2, :2] @ wedge
    return [(h0, 0.1 * DEG + 0.004 * DEG, -0.12 * DEG - 0.007 * DEG, 0.0, 0.0, 0.7 * DEG),
            (h1 + 0.15, wedge[0] + 0.006 * DEG, wedge[1] - 0.008 * DEG, 0.4, -0.3, -0.5 * DEG),
            (h1 + 0.15, w_turned[0] - 0.009 * DEG, w_turned[1] + 0.005 * DEG, -0.35, 0.45, turned)]


def against_the_dome(world: World) -> np.ndarray:
    """(10,) the paraboloid's and the camera's pivot offsets (mm) and tilts (rad) in the dome's
    frame, from the planted bodies (docs/calibrate.md, "Reported frames")."""
    dome = world.body["dome"]
    out = []
    for c in ("paraboloid", "camera"):
        b = world.body[c]
        at = dome.r.T @ (b.pivot + b.offset - dome.offset)
        out += [*(at - b.pivot), *Rotation.from_matrix(dome.r.T @ b.r).as_rotvec()[:2]]
    return np.array(out)


def planted_theta(rig, world: World) -> np.ndarray:
    """The planted build as the fit's parameters (rigcad.calibrate.model.parameter_names): each
    screen's height and turn as offsets from its capture's nominal ones."""
    from rigcad.calibrate import model as M

    plan = M.Plan.of(rig.profile)
    theta = np.zeros(len(M.parameter_names(len(plan))))
    for i, c in enumerate(M.COMPONENTS):
        theta[5 * i: 5 * i + 5] = [*world.body[c].offset, *PLANTED[c][1]]
    for k, (h, tx, ty, du, dv, angle) in enumerate(world.screens):
        theta[M.screen_index(k): M.screen_index(k) + 6] = h - plan.heights[k], tx, ty, du, dv, angle - plan.turns[k]
    return theta


@pytest.fixture(scope="module")
def small_world(tmp_path_factory):
    from rigcad.profile.schema import load_profile
    from rigcad.rig import Rig

    path = tmp_path_factory.mktemp("independent") / "small.yaml"
    path.write_text(SMALL)
    rig = Rig.from_profile(load_profile(path))
    return rig, World(rig, PLANTED, planted_screens(rig))


def test_the_fits_tracer_draws_the_planted_rig_as_the_independent_renderer(small_world):
    """The forward model the fit inverts (rigcad.calibrate.model.trace_camera through the planted
    build, its screens by rigcad.calibrate.model.screens) against the renderer written from the
    docs, on every pixel centre of the window: the same pixels off the mirrors (but a few at an
    occluder's or the rim's edge, where a faceted cylinder and an exact one part), the same
    direction leaving the dome, the same point on each planted screen. Measured: 3 pixels of 3,327
    off the mirrors differ (none of 15,562 seen directly), directions within 3.4e-6 deg, screen
    points within 4.3e-7 mm. Planted failures, each seen to fail here: a tilt's y sign or the
    screen's turn reversed in this renderer, the camera's shift for the plate left out, the screen's
    turn reversed in rigcad.calibrate.raxel.screen_pose."""
    from rigcad.calibrate import model as M
    from rigcad.check.scene import analytic_optics

    rig, world = small_world
    theta = planted_theta(rig, world)
    cam = M.Camera.of(rig)
    tr = M.trace_camera(analytic_optics(rig), M.moved(rig, theta), cam.x_px, cam.y_px, cam.design)
    start, way, _, seen, mirrored, v = world.trace(cam.x_px, cam.y_px)
    # pixels whose ray grazes an edge: 720-facet cylinders stand 0.01 um inside the exact ones
    assert np.count_nonzero(mirrored != tr.ok) <= 0.002 * np.count_nonzero(tr.ok), np.count_nonzero(mirrored != tr.ok)
    both = mirrored & tr.ok
    assert np.count_nonzero(both) > 3000
    cos = np.clip(np.sum(v[both] * tr.v[both], axis=1), -1, 1)
    assert np.degrees(np.arccos(cos)).max() < 1e-4  # float64 paths of ~600 mm: 3.4e-6 deg measured
    pitch = rig.profile.calibration.screen_pitch
    width, height = rig.profile.calibration.screen_resolution
    assert np.array_equal(seen & ~mirrored, tr.direct)  # seen directly: the same pixels (15,562)
    seen_both = seen & (tr.ok | tr.direct)
    for k, pose in enumerate(M.screens(M.Plan.of(rig.profile), theta)):
        su, sv = tr.screen(pose)
        cx, cy = world.on_screen(k, start, way)
        u, w = (cx - width / 2) * pitch, (height / 2 - cy) * pitch
        on = seen_both & np.isfinite(u) & np.isfinite(su)
        assert np.count_nonzero(on) > 5000, k
        # mm: 4.3e-7 measured; 1e-5 mm is a thousandth of the decoding's noise
        assert np.abs(u[on] - su[on]).max() < 1e-5 and np.abs(w[on] - sv[on]).max() < 1e-5, k


@pytest.fixture(scope="module")
def independent(small_world):
    """The planted build rendered by :func:`render` (seed 11's noise) and calibrated by
    ``rigcad.calibrate.run.calibrate``, as ``rigcad calibrate --images`` would."""
    from rigcad.calibrate.run import calibrate
    from rigcad.check.scene import analytic_optics

    rig, world = small_world
    frames, truth, mirrored = render(world, seed=11)
    return calibrate(analytic_optics(rig), rig, frames), truth


@pytest.mark.e2e
def test_the_calibration_recovers_the_planted_build_within_its_standard_errors(small_world, independent):
    """The paraboloid's and the camera's placement against the dome (what a technician adjusts) and
    every fitted parameter in the sample frame come back within 3 stated standard errors of the
    planted build; each placement is planted at least 5 standard errors from zero, so finding it is
    not the prior's doing. Measured with seeds 11, 12, 13 of the noise: the worst of the ten 2.1,
    2.2, 1.7 standard errors, none of the 33 sample-frame parameters past 2; a Gaussian puts one of
    ten past 3 in 2.7 % of captures. Planted failure: the Gray code's polarity swapped in this
    renderer fails here."""
    from rigcad.calibrate import model as M

    rig, world = small_world
    result, _ = independent
    fitted = M.in_dome_frame(rig, result.fit.theta)
    se = np.sqrt(np.diag(result.fit.dome_frame_covariance))
    planted = against_the_dome(world)
    assert np.all(np.abs(planted) > 5 * se), dict(zip(M.DOME_FRAME_NAMES, planted / se))
    z = (fitted - planted) / se
    assert np.all(np.abs(z) <= 3), dict(zip(M.DOME_FRAME_NAMES, np.round(z, 2)))
    theta = planted_theta(rig, world)
    free = result.fit.standard_error > 0  # the gauge (model.GAUGE) is held, not fitted
    z = (result.fit.theta[free] - theta[free]) / result.fit.standard_error[free]
    names = np.array(result.fit.names)[free]
    assert np.all(np.abs(z) <= 3), dict(zip(names[np.abs(z) > 3], np.round(z[np.abs(z) > 3], 2)))


@pytest.mark.e2e
def test_the_corrected_map_against_the_independent_truth(independent):
    """The corrected map's measured pixels against the renderer's own rays: the design map is 11 deg
    off at the median (12.8 at p99) on this build, the corrected one 0.023 deg (0.039 at p99); held to
    a hundredth of the design map's p99."""
    result, truth = independent
    direction, source = result.corrected["direction"], result.corrected["source"]
    m = (source == 1) & np.all(np.isfinite(truth), axis=1)
    assert np.count_nonzero(m) > 1500  # 1,822 measured
    err = np.degrees(np.arccos(np.clip(np.sum(direction[m] * truth[m], axis=1), -1, 1)))
    design = np.degrees(np.arccos(np.clip(np.sum(result.design[m] * truth[m], axis=1), -1, 1)))
    worst, design_worst = np.percentile(err, 99), np.nanpercentile(design, 99)  # design: NaN past its table
    assert worst < design_worst / 100, (worst, design_worst)


@pytest.mark.e2e
@pytest.mark.xfail(strict=True, reason="on this independent capture the map's frame is off by 0.014-0.024 deg "
                   "(seeds 11-13; the fit's own renderer: 0.005 deg on the same build): the rig turns against the "
                   "screens along a mode the images hold loosely, which moves the model's dome points the measured "
                   "rays turn about, and the map's uncertainty counts the seating's frame (0.008 deg RMS), not that "
                   "mode: 33 %, 66 %, 47 % of the measured pixels within two uncertainties")
def test_the_maps_stated_uncertainty_covers_the_independent_truth(independent):
    """At least 90 % of the measured pixels within two stated uncertainties of the renderer's rays
    (the bench's own captures: 96 %)."""
    result, truth = independent
    direction, source = result.corrected["direction"], result.corrected["source"]
    m = (source == 1) & np.all(np.isfinite(truth), axis=1)
    err = np.arccos(np.clip(np.sum(direction[m] * truth[m], axis=1), -1, 1))
    assert np.mean(err <= 2 * result.corrected["uncertainty_rad"][m]) >= 0.9
