"""Meridians: the mirror surfaces of revolution as exact curves (r(u), z(u)) about the +z axis.

Both mirrors are surfaces of revolution; every 3D stage (solids, meshes, ray checks) takes them
from here. Each :class:`Meridian` gives points, unit normals on the *reflecting* side (the side
light comes from), curvature, and its offset *behind* the mirror by a distance (the printed
surface under a coating). Lengths in mm; u is the curve's own parameter, increasing from the
bottom of the surface (rim, dome base) to its top (vertex, dome opening).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.spatial import cKDTree

from rigcad.errors import GeometryError
from rigcad.optics.dome import DomeProfile
from rigcad.optics.vec import unit
from rigcad.profile.derived import Derived


#: Samples of a meridian that seed the foot-point search. At 20001 the dome's samples are 0.014 mm
#: apart, well inside Newton's basin (the mirrors' radii of curvature are >= 5.9 mm); the same count
#: the mirror meshes plan with.
FOOT_SAMPLES = 20001
#: Samples per leaf of the seeds' KD tree. The samples lie on a curve, so a query from a point
#: millimetres off it visits many small leaves: 128 (scipy's default is 16) finds the same nearest
#: sample about 1.8x faster on fabrication's points, 2.4x on points far behind the mirrors.
FOOT_TREE_LEAFSIZE = 128
#: Newton steps for a foot point. Each step shrinks the tangential residual by about curvature x
#: distance (< 0.02 / mm x 0.1 mm on a facet), so 3-4 steps reach rounding.
FOOT_NEWTON_STEPS = 8
#: Tangential step (mm) at which foot points count as converged. A foot-point error d moves the
#: distance by ~ k d^2 / 2 and the normal by ~ k d: both negligible at 1e-11 mm.
FOOT_POINT_TOL_MM = 1e-11


@dataclass(frozen=True)
class _FootTable:
    """A meridian sampled for the foot-point search: u, points (r, z) mm, ds/du, the sign that
    turns (n_z, -n_r) along +u, and a KD tree of the points."""

    u: np.ndarray
    points: np.ndarray
    dsdu: np.ndarray
    tangent_sign: float
    tree: cKDTree


@dataclass(frozen=True)
class Meridian:
    """A meridional curve moved ``offset`` mm behind its mirror (0 = the design surface).

    ``kind`` is ``dome`` or ``paraboloid``; ``u_range`` the parameter interval (bottom -> top).
    """

    kind: str
    u_range: tuple[float, float]
    offset: float
    _spline: object | None = None  # dome: quintic spline D(s) of the design surface
    _focal_length: float = 0.0
    _vertex_z: float = 0.0

    # -- the design surface -------------------------------------------------------------------
    def _design_points(self, u: np.ndarray) -> np.ndarray:
        u = np.atleast_1d(np.asarray(u, dtype=float))
        if self.kind == "paraboloid":
            # u = -r, so u increases from the rim (-rim_radius) to the vertex (0)
            r = -u
            return np.stack([r, self._vertex_z - r * r / (4.0 * self._focal_length)], axis=-1)
        return self._spline(u)

    def _design_tangents(self, u: np.ndarray) -> np.ndarray:
        """d(point)/du (not unit)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        if self.kind == "paraboloid":
            r = -u
            return np.stack([-np.ones_like(r), r / (2.0 * self._focal_length)], axis=-1)
        return self._dome_derivatives[0](u)

    @cached_property
    def _dome_derivatives(self) -> tuple:
        """The dome spline's first and second derivative splines, built once (scipy's splder costs
        as much as evaluating a few hundred points); dropped from pickles like ``_table``."""
        return self._spline.derivative(), self._spline.derivative(2)

    def normals(self, u: np.ndarray) -> np.ndarray:
        """Unit normals (n, 2) pointing to the reflecting side: up/out for the convex paraboloid,
        towards the axis (inside) for the dome. The same for every offset (parallel curves)."""
        t = unit(self._design_tangents(u))
        # u runs bottom -> top; the left normal (-t_z, t_r) points inwards for the dome's wall and
        # down into the body for the paraboloid, whose reflecting side is the other one.
        left = np.stack([-t[:, 1], t[:, 0]], axis=-1)
        return (-left if self.kind == "paraboloid" else left) + 0.0  # + 0.0: no negative zeros in files

    def tangents(self, u: np.ndarray) -> np.ndarray:
        """d(point)/du (n, 2) of this curve (mm per unit u); parallel curves share tangent directions,
        the length scales by (1 +- offset x curvature)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        t = self._design_tangents(u)
        k = self._design_curvature(u)
        scale = 1.0 - self.offset * k if self.kind == "paraboloid" else 1.0 + self.offset * k
        return t * scale[:, None]

    def points(self, u: np.ndarray) -> np.ndarray:
        """Points (n, 2) of this (possibly offset) curve in (r, z), mm."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        if self.offset == 0.0:
            return self._design_points(u)
        return self._design_points(u) - self.offset * self.normals(u)

    def _points_normals(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``points(u)`` and ``normals(u)`` with the normals evaluated once (the same arithmetic,
        the same bits)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        n = self.normals(u)
        p = self._design_points(u)
        return (p if self.offset == 0.0 else p - self.offset * n), n

    def curvature(self, u: np.ndarray) -> np.ndarray:
        """Unsigned curvature (1/mm) of this curve. Moving behind the mirror grows the concave
        dome's radius of curvature by the offset and shrinks the convex paraboloid's; an offset
        past the paraboloid's centre of curvature has no regular parallel curve and is refused."""
        k = self._design_curvature(u)
        radius = 1.0 / k
        radius = radius - self.offset if self.kind == "paraboloid" else radius + self.offset
        if np.any(radius <= 0):
            raise GeometryError(f"an offset of {self.offset:g} mm behind the {self.kind} passes its centre of "
                                f"curvature (radius {float(np.min(1.0 / k)):.3g} mm): no regular parallel surface")
        return 1.0 / radius

    def _design_curvature(self, u: np.ndarray) -> np.ndarray:
        u = np.atleast_1d(np.asarray(u, dtype=float))
        if self.kind == "paraboloid":
            r = -u
            f = self._focal_length
            k = (1.0 / (2.0 * f)) / (1.0 + (r / (2.0 * f)) ** 2) ** 1.5
        else:
            der1, der2 = self._dome_derivatives
            d1, d2 = der1(u), der2(u)
            k = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=-1) ** 3
        return k

    # -- nearest points: the one foot-point solver for both mirrors and every offset ------------
    @cached_property
    def _table(self) -> "_FootTable":
        u = self.sample(FOOT_SAMPLES)
        p = self.points(u)
        n = self.normals(u)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        # the sign that makes (n_z, -n_r) point along +u (finite-difference tangent against the normal)
        t = np.gradient(p, u, axis=0)
        side = float(np.sign(t[0, 0] * n[0, 1] - t[0, 1] * n[0, 0]))
        return _FootTable(u, p, np.gradient(s, u), side, cKDTree(p, leafsize=FOOT_TREE_LEAFSIZE))

    def foot_points(self, rz: np.ndarray) -> np.ndarray:
        """Parameters u (n,) of the points of this curve nearest to ``rz`` (n, 2) in (r, z), mm.

        Seeded at the nearest of FOOT_SAMPLES samples (a KD tree), then Newton on the tangential
        offset, du = t.(q - c) / (ds/du), clamped to ``u_range`` (a point beyond an end is nearest
        to that end). Each point iterates until its own step is under FOOT_POINT_TOL_MM or
        FOOT_NEWTON_STEPS were taken, so its result does not depend on the other points of the
        call (batching callers get the same bits as point-by-point calls). Near the curve (closer
        than its radius of curvature) Newton converges quadratically; a point whose iteration has
        not settled (far behind a convex mirror, past its centre of curvature) keeps the nearer of
        its seed and its last iterate. The one foot-point solver: the meshes' error measurement,
        the ray checker's exact normals and fabrication's distances all use it."""
        rz = np.asarray(rz, dtype=float).reshape(-1, 2)
        tab = self._table
        _, nearest = tab.tree.query(rz)
        seed = tab.u[nearest]
        u = seed.copy()
        lo, hi = self.u_range
        active = np.arange(len(u))  # the points still iterating
        for _ in range(FOOT_NEWTON_STEPS):
            if len(active) == 0:
                return u
            ua, q = u[active], rz[active]
            c, n = self._points_normals(ua)
            step = tab.tangent_sign * ((q[:, 0] - c[:, 0]) * n[:, 1] - (q[:, 1] - c[:, 1]) * n[:, 0])
            dsdu = np.interp(ua, tab.u, tab.dsdu)
            new = np.clip(ua + step / dsdu, lo, hi)
            u[active] = new
            active = active[np.abs(new - ua) * dsdu >= FOOT_POINT_TOL_MM]
        if len(active):  # unsettled after the last step
            far = np.linalg.norm(rz[active] - self.points(u[active]), axis=1)
            near = np.linalg.norm(rz[active] - tab.points[nearest[active]], axis=1)
            u[active] = np.where(near < far, seed[active], u[active])
        return u

    def distance(self, rz: np.ndarray) -> np.ndarray:
        """Signed distance (n,) mm of (r, z) points (n, 2) from this curve: positive on the
        reflecting side (in front of the mirror), negative behind it."""
        rz = np.asarray(rz, dtype=float).reshape(-1, 2)
        c, n = self._points_normals(self.foot_points(rz))
        return np.einsum("ij,ij->i", rz - c, n)

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_table", None)  # rebuilt on first use: a KD tree of 20001 samples is cheap
        state.pop("_dome_derivatives", None)  # likewise: two splder calls
        return state

    def behind(self, distance: float) -> "Meridian":
        """The parallel curve ``distance`` mm further behind the mirror."""
        return Meridian(self.kind, self.u_range, self.offset + distance, self._spline, self._focal_length,
                        self._vertex_z)

    def sample(self, count: int) -> np.ndarray:
        """``count`` parameters evenly spaced over ``u_range``."""
        return np.linspace(self.u_range[0], self.u_range[1], count)

    def arc_length_parameters(self, spacing: float, oversample: int = 20001) -> np.ndarray:
        """Parameters whose points are about ``spacing`` mm apart along this curve, ends included."""
        u = self.sample(oversample)
        p = self.points(u)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        n = max(int(np.ceil(s[-1] / spacing)), 1)
        return np.interp(np.linspace(0.0, s[-1], n + 1), s, u)

    def chord_parameters(self, chord_error: float) -> np.ndarray:
        """Parameters such that the polyline through their points deviates from this meridian by at
        most ``chord_error`` mm: a chord of length h on curvature k has sagitta k h^2 / 8, so points
        are placed at equal steps of the integral of sqrt(k / (8 chord_error)) ds (the local density
        that meets the bound), taking the largest curvature over each fine cell."""
        u = self.sample(20001)
        p = self.points(u)
        ds = np.linalg.norm(np.diff(p, axis=0), axis=1)
        k = self.curvature(u)
        k_cell = np.maximum(k[:-1], k[1:])
        density = np.sqrt(k_cell / (8.0 * chord_error))
        budget = np.concatenate([[0.0], np.cumsum(density * ds)])
        n = max(int(np.ceil(budget[-1])), 1)
        return np.interp(np.linspace(0.0, budget[-1], n + 1), budget, u)


def dome_meridian(dome: DomeProfile) -> Meridian:
    """The dome's design surface: the profile's one spline (``DomeProfile.spline``, u = -s) over
    its rows (smooth profiles only; the thesis's Euler polyline is not a smooth surface)."""
    if dome.kind != "smooth":
        raise GeometryError("3D surfaces need a smooth dome profile (dome.method dop853, rk45 or equal_path), "
                            f"not the {dome.method} polyline", param="dome.method")
    return Meridian("dome", (float(-dome.s.max()), float(-dome.s.min())), 0.0, dome.spline)


def paraboloid_meridian(geo: Derived) -> Meridian:
    """The paraboloid's design surface, closed form, from the rim (u = -rim_radius) to the vertex (u = 0)."""
    return Meridian("paraboloid", (-geo.rim_radius, 0.0), 0.0, None, geo.focal_length, geo.vertex_z)
