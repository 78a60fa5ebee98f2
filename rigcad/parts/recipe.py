"""A small, kernel-free description of each part's solid: a CSG tree of revolved sections,
extruded sections, boxes and cylinders.

Every part is a function from the validated profile to a :class:`Part` holding such a tree. Two
backends read the same tree: ``rigcad.parts._kernel`` builds the exact B-rep (OpenCascade, for
STEP) and ``rigcad.export.mesh`` builds the printable mesh (manifold3d, for STL), so the two can
never disagree about a slot or a hole. Values are frozen and hashable: the content hash of a
part's tree is its cache key. Frame: mm, sample point at the origin, optical axis +z.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field, fields, is_dataclass, replace
from typing import Union

import numpy as np

from rigcad.optics.surfaces import Meridian

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Line:
    """A straight edge of a section, from ``p0`` to ``p1`` (section coordinates, mm)."""

    p0: tuple[float, float]
    p1: tuple[float, float]


@dataclass(frozen=True)
class Curve:
    """A piece of a mirror meridian from parameter ``u0`` to ``u1`` (either direction); with
    ``mirror_x`` the curve is reflected to x < 0 (for a template spanning the axis)."""

    meridian: Meridian
    u0: float
    u1: float
    mirror_x: bool = False

    def points(self, u: np.ndarray) -> np.ndarray:
        p = self.meridian.points(u)
        if self.mirror_x:
            p = p * np.array([-1.0, 1.0])
        return p

    @property
    def p0(self) -> tuple[float, float]:
        return tuple(self.points(np.array([self.u0]))[0])

    @property
    def p1(self) -> tuple[float, float]:
        return tuple(self.points(np.array([self.u1]))[0])

    def _oriented(self, u: np.ndarray) -> np.ndarray:
        return self.points(u if self.u0 < self.u1 else u[::-1])

    def _piece(self) -> Meridian:
        return replace(self.meridian, u_range=(min(self.u0, self.u1), max(self.u0, self.u1)))

    def dense(self, count: int = 2001) -> np.ndarray:
        """Exact points (count, 2) from u0 to u1, evenly spaced in arc length."""
        piece = self._piece()
        p = piece.points(piece.sample(4001))
        length = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
        return self._oriented(piece.arc_length_parameters(length / (count - 1)))

    def polyline(self, chord_error: float) -> np.ndarray:
        """Points (n, 2) from u0 to u1 whose polyline stays within ``chord_error`` mm of the curve."""
        return self._oriented(self._piece().chord_parameters(chord_error))


Segment = Union[Line, Curve]


@dataclass(frozen=True)
class Section:
    """A closed loop of segments, each starting where the previous one ends (checked)."""

    segments: tuple[Segment, ...]

    def __post_init__(self) -> None:
        segs = self.segments
        for a, b in zip(segs, segs[1:] + segs[:1]):
            gap = np.hypot(a.p1[0] - b.p0[0], a.p1[1] - b.p0[1])
            if gap > 1e-9:
                raise ValueError(f"section is not closed: gap of {gap:.3g} mm between {a.p1} and {b.p0}")

    def polygon(self, chord_error: float) -> np.ndarray:
        """The loop as a counter-clockwise polygon (n, 2) within ``chord_error`` mm of the segments."""
        pts = []
        for seg in self.segments:
            p = np.array([seg.p0, seg.p1]) if isinstance(seg, Line) else seg.polyline(chord_error)
            pts.append(p[:-1])
        poly = np.concatenate(pts)
        area = 0.5 * np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
        return poly if area > 0 else poly[::-1]


@dataclass(frozen=True)
class Revolve:
    """A section in the (r, z) half-plane revolved a full turn about the z axis."""

    section: Section


@dataclass(frozen=True)
class Prism:
    """A section in the x-z plane extruded symmetrically along y to ``thickness`` mm."""

    section: Section
    thickness: float


@dataclass(frozen=True)
class Box:
    """Axis-aligned box between corners ``lo`` and ``hi`` (mm)."""

    lo: Vec3
    hi: Vec3


@dataclass(frozen=True)
class Cylinder:
    """Cylinder along +z from ``base`` (its bottom centre), radius and height in mm."""

    base: Vec3
    radius: float
    height: float


@dataclass(frozen=True)
class HexPrism:
    """Regular hexagonal prism along +z from ``base`` (its bottom centre): ``across_flats`` and
    ``height`` in mm, one corner ``turn`` rad round from +x (a nut trap)."""

    base: Vec3
    across_flats: float
    height: float
    turn: float = 0.0

    def corners(self) -> list[tuple[float, float]]:
        """The six corners (x, y; mm), counter-clockwise from the one at ``turn``."""
        r = self.across_flats / math.sqrt(3.0)
        return [(self.base[0] + r * math.cos(self.turn + k * math.pi / 3),
                 self.base[1] + r * math.sin(self.turn + k * math.pi / 3)) for k in range(6)]


@dataclass(frozen=True)
class Union_:
    """Union of solids."""

    items: tuple["Solid", ...]


@dataclass(frozen=True)
class Difference:
    """``base`` minus every solid in ``cuts``."""

    base: "Solid"
    cuts: tuple["Solid", ...]


@dataclass(frozen=True)
class Translate:
    """A solid moved by ``offset`` (mm)."""

    solid: "Solid"
    offset: Vec3


Solid = Union[Revolve, Prism, Box, Cylinder, HexPrism, Union_, Difference, Translate]


@dataclass(frozen=True)
class Part:
    """One part: its solid, how a viewer should show it, and what it is for.

    ``mirrors`` names the mirror meridians (design surfaces, coating included) that this part
    carries, for the ray checker's meshes. ``occluders`` names the convex solids (boxes, z
    cylinders) that stand for the rest of the part where light passes it: the ray checker and the
    occlusion report trace them, so a part's size is stated once, here. ``in_rig`` is False for
    tools kept out of the rig assembly (calibration targets, templates) or placed elsewhere in it.
    """

    name: str
    solid: Solid
    color: tuple[float, float, float]
    description: str
    quantity: int = 1
    in_rig: bool = True
    #: Empty: the part is made (printed, or cut from plate). Else the stock to buy instead, as one
    #: would order it: a bought part is drawn in the rig and listed in the bill, never printed.
    bought: str = ""
    mirrors: tuple[tuple[str, Meridian], ...] = field(default=(), compare=False)
    occluders: tuple[tuple[str, Box | Cylinder], ...] = field(default=(), compare=False)
    #: The profile keys ("section.key") this part's function read: named when the kernel fails.
    shaped_by: tuple[str, ...] = field(default=(), compare=False)
    #: The joints this part's screws make with another part (rigcad.parts.joints.ScrewJoint), declared
    #: by the part the heads bear on; its holes and the other part's are cut from them.
    joints: tuple = field(default=(), compare=False)
    #: The part's datum features (rigcad.parts.joints.Datum: dowel holes, bores, seats, insert pockets,
    #: registers), declared where the part cuts them: a split keeps its cut planes off them.
    datums: tuple = field(default=(), compare=False)
    #: A bought part's mass (kg) when its drawn solid is not its material all through (an extrusion's
    #: profile is drawn as its square envelope); None: its solid's volume times its material's density.
    mass_kg: float | None = field(default=None, compare=False)

    def content_hash(self) -> str:
        """SHA-256 of the solid's full definition (every number, every curve's coefficients)."""
        h = hashlib.sha256()
        _feed(h, self.solid)
        return h.hexdigest()


def bounds(solid: Solid) -> tuple[Vec3, Vec3]:
    """The axis-aligned box (lo, hi; mm) that holds ``solid``: exact for boxes, z cylinders, hexagonal
    prisms and their unions and translations; a difference is bounded by its base; a revolved
    section by its largest radius and its z range; a prism by its section's x-z range and its
    thickness (the sections' curves sampled densely: mirror meridians are monotone pieces)."""
    if isinstance(solid, Box):
        return solid.lo, solid.hi
    if isinstance(solid, Cylinder):
        (x, y, z), r = solid.base, solid.radius
        return (x - r, y - r, z), (x + r, y + r, z + solid.height)
    if isinstance(solid, HexPrism):
        c = np.array(solid.corners())
        z = solid.base[2]
        return (float(c[:, 0].min()), float(c[:, 1].min()), z), (float(c[:, 0].max()), float(c[:, 1].max()),
                                                                z + solid.height)
    if isinstance(solid, Union_):
        boxes = [bounds(s) for s in solid.items]
        return (tuple(min(b[0][k] for b in boxes) for k in range(3)),
                tuple(max(b[1][k] for b in boxes) for k in range(3)))
    if isinstance(solid, Difference):
        return bounds(solid.base)
    if isinstance(solid, Translate):
        lo, hi = bounds(solid.solid)
        o = solid.offset
        return tuple(lo[k] + o[k] for k in range(3)), tuple(hi[k] + o[k] for k in range(3))
    if isinstance(solid, (Revolve, Prism)):
        pts = np.concatenate([np.array([seg.p0, seg.p1]) if isinstance(seg, Line) else seg.dense(201)
                              for seg in solid.section.segments])
        if isinstance(solid, Revolve):
            r = float(np.abs(pts[:, 0]).max())
            return (-r, -r, float(pts[:, 1].min())), (r, r, float(pts[:, 1].max()))
        h = solid.thickness / 2
        return (float(pts[:, 0].min()), -h, float(pts[:, 1].min())), (float(pts[:, 0].max()), h, float(pts[:, 1].max()))
    raise TypeError(f"no bounds for {type(solid).__name__}")  # pragma: no cover - a new solid type


def _feed(h, value) -> None:
    if is_dataclass(value):
        h.update(type(value).__name__.encode())
        for f in fields(value):
            h.update(f.name.encode())
            _feed(h, getattr(value, f.name))
    elif isinstance(value, (tuple, list)):
        h.update(b"(")
        for v in value:
            _feed(h, v)
        h.update(b")")
    elif isinstance(value, np.ndarray):
        h.update(np.ascontiguousarray(value, dtype=float).tobytes())
    elif isinstance(value, float):
        h.update(np.float64(value).tobytes())
    elif value is None or isinstance(value, (int, str, bool)):
        h.update(repr(value).encode())
    elif hasattr(value, "t") and hasattr(value, "c"):  # a scipy BSpline inside a Meridian
        h.update(np.asarray(value.t, dtype=float).tobytes())
        h.update(np.asarray(value.c, dtype=float).tobytes())
        h.update(repr(value.k).encode())
    else:  # pragma: no cover - a new value type must be taught to the hash
        raise TypeError(f"cannot hash {type(value).__name__}")
