"""Split a part that does not fit the printer into pieces with alignment pin holes.

Parts of the rig are (nearly) solids of revolution about the optical axis z, so a part is cut by
N vertical half-planes through the axis (sectors) and, when the sectors are still too tall, by
M - 1 horizontal planes (bands): a piece is one (sector, band) cell. The sectors' phase is chosen
so that the cut planes cross as few features (slots, bolt holes) as possible: the slices of the
part on the planes have the fewest loops, and the phase is the middle of the widest such range.

Each face between two neighbouring cells gets dowel-pin holes (a hole of the pin's diameter plus
clearance, ``depth`` into each piece), placed on the cut face where the material around the hole
is at least ``MIN_WALL`` thick (a boolean test on the mesh: the hole widened by the wall must lie
inside the part) and, on a mirror part, at least ``MIRROR_CLEARANCE`` from the mirror surface
(measured on the exact surface). The booleans are manifold3d's on the part's mesh.
Frame: the part's working position, mm, rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import manifold3d as m3d
import numpy as np

from rigcad.errors import FabricationError
from rigcad.fab.mirror import MirrorSurface
from rigcad.fab.printers import AlignmentPin

#: Material kept around a pin hole (mm): two FDM perimeters of a 0.4 mm nozzle, less a little.
MIN_WALL = 0.6
#: Distance kept between a pin hole and the printed mirror surface (mm): sanding removes up to
#: ~0.2 mm there and the pin must not print-through as a bump (about five layers of material).
MIRROR_CLEARANCE = 1.0
#: Extra erosions (mm) of a cut face where pin centres are sought (see place_pins).
ERODE_SLACK = (0.0, 0.15, 0.3, 0.5, 1.0)
#: Sector counts and band counts tried, fewest pieces first.
SECTOR_COUNTS = (1, 2, 3, 4, 6, 8, 12, 16)
BAND_COUNTS = (1, 2, 3, 4)
#: Pins per cut face: one per this length (mm) of the face, at least two, at most six.
PIN_SPACING = 60.0
_BIG = 1e4


@dataclass(frozen=True)
class SplitPlan:
    """``sectors`` x ``bands`` cells; sector i spans [phase + i 2pi/N, phase + (i+1) 2pi/N),
    band j spans [band_z[j], band_z[j+1]] (mm)."""

    sectors: int
    bands: int
    phase: float
    band_z: tuple[float, ...]

    @property
    def count(self) -> int:
        return self.sectors * self.bands

    def sector_range(self, i: int) -> tuple[float, float]:
        step = 2 * math.pi / self.sectors
        return (self.phase + i * step, self.phase + (i + 1) * step)

    def describe(self) -> dict:
        return {"sectors": self.sectors, "bands": self.bands, "pieces": self.count,
                "sector_phase_deg": math.degrees(self.phase),
                "sector_planes_deg": [math.degrees(self.phase + i * 2 * math.pi / self.sectors) % 360
                                      for i in range(self.sectors)] if self.sectors > 1 else [],
                "band_cuts_z_mm": list(self.band_z[1:-1])}


@dataclass(frozen=True)
class Pin:
    """A pin hole: centre on a cut face (mm), unit axis (the face's normal)."""

    centre: tuple[float, float, float]
    axis: tuple[float, float, float]
    face: str


@dataclass
class Piece:
    name: str
    sector: int
    band: int
    sector_range: tuple[float, float] | None
    manifold: m3d.Manifold = field(repr=False)


def cell(man: m3d.Manifold, plan: SplitPlan, i: int, j: int) -> m3d.Manifold:
    """Cell (sector i, band j) of ``man``."""
    out = man
    if plan.sectors > 1:
        a0, a1 = plan.sector_range(i)
        out = out.trim_by_plane((-math.sin(a0), math.cos(a0), 0.0), 0.0)
        out = out.trim_by_plane((math.sin(a1), -math.cos(a1), 0.0), 0.0)
    if plan.bands > 1:
        if j > 0:
            out = out.trim_by_plane((0.0, 0.0, 1.0), plan.band_z[j])
        if j < plan.bands - 1:
            out = out.trim_by_plane((0.0, 0.0, -1.0), -plan.band_z[j + 1])
    return out


def _plane_frame(normal: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """3x4 matrix taking the part frame to a frame whose z = 0 is the plane (z along normal)."""
    n = normal / np.linalg.norm(normal)
    e1 = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = e1 - (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    rot = np.stack([e1, e2, n])
    return np.hstack([rot, (-rot @ origin)[:, None]])


def _loops_on_planes(man: m3d.Manifold, sectors: int, phase: float) -> int:
    """Loops of the part's slices on the sector half-planes (features crossed add loops)."""
    total = 0
    for i in range(sectors):
        a = phase + i * 2 * math.pi / sectors
        n = np.array([-math.sin(a), math.cos(a), 0.0])
        frame = _plane_frame(n, np.zeros(3))
        cs = man.transform(frame.tolist()).slice(0.0)
        # keep the half-plane on the radial side of angle a: in the plane frame, radial = (0, 1)
        # since e1 = z and e2 = n x z = radial
        half = m3d.CrossSection.square((_BIG, _BIG)).translate((-_BIG / 2, 0.0))
        total += len((cs ^ half).to_polygons())
    return total


def choose_phase(man: m3d.Manifold, sectors: int, step_deg: float = 2.5) -> float:
    """Sector phase (rad) crossing the fewest features; the middle of the widest range of such."""
    if sectors == 1:
        return 0.0
    period = 360.0 / sectors
    grid = np.arange(0.0, period, step_deg)
    loops = np.array([_loops_on_planes(man, sectors, math.radians(g)) for g in grid])
    best = loops == loops.min()
    # widest circular run of best phases
    n = len(grid)
    run, best_run, best_end = 0, 0, 0
    for k in range(2 * n):
        run = run + 1 if best[k % n] else 0
        if run > best_run and run <= n:
            best_run, best_end = run, k
    mid = (best_end - (best_run - 1) / 2) % n
    return math.radians(float(np.interp(mid, np.arange(n), grid)) if mid < n - 1 else grid[int(mid)])


def _band_cuts(z0: float, z1: float, bands: int):
    """Band boundaries to try: for two bands the cut from low to high (a dome's wall is steepest
    low down, where vertical pins stay inside it), otherwise equal bands."""
    if bands == 2:
        for f in np.arange(0.2, 0.81, 0.05):
            yield (z0, z0 + f * (z1 - z0), z1)
    else:
        yield tuple(np.linspace(z0, z1, bands + 1))


def plan_split(man: m3d.Manifold, fits) -> SplitPlan:
    """The fewest-pieces plan whose every cell ``fits(cell_manifold, plan, i, j)``; raises if none."""
    bb = np.asarray(man.bounding_box(), dtype=float)
    z0, z1 = bb[2], bb[5]
    options = sorted(((s, b) for s in SECTOR_COUNTS for b in BAND_COUNTS), key=lambda sb: (sb[0] * sb[1], sb[1]))
    phases: dict[int, float] = {}
    for s, b in options:
        if s not in phases:
            phases[s] = choose_phase(man, s)
        for cuts in _band_cuts(z0, z1, b):
            plan = SplitPlan(s, b, phases[s], cuts)
            if all(fits(cell(man, plan, i, j), plan, i, j) for i in range(s) for j in range(b)):
                return plan
    raise FabricationError(f"no split into up to {SECTOR_COUNTS[-1]} sectors x {BAND_COUNTS[-1]} bands fits this "
                           "printer; use a larger printer")


def _cylinder(pin_axis: np.ndarray, centre: np.ndarray, radius: float, half_length: float) -> m3d.Manifold:
    cyl = m3d.Manifold.cylinder(2 * half_length, radius, radius, 24).translate((0.0, 0.0, -half_length))
    rot = np.linalg.inv(_plane_frame(pin_axis, np.zeros(3))[:, :3])  # plane frame z -> pin axis
    return cyl.transform(np.hstack([rot, centre[:, None]]).tolist())


def _interfaces(plan: SplitPlan, bb: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray, callable]]:
    """Cut faces between neighbouring cells: (name, normal, origin, keep(points (n,3)) -> bool mask
    of points on this face's part of the plane, inside the two cells)."""
    out = []
    for j in range(plan.bands):
        zlo, zhi = plan.band_z[j], plan.band_z[j + 1]
        if plan.sectors > 1:
            for i in range(plan.sectors):
                a = plan.sector_range(i)[0]
                n = np.array([-math.sin(a), math.cos(a), 0.0])
                radial = np.array([math.cos(a), math.sin(a), 0.0])

                def keep(p, radial=radial, zlo=zlo, zhi=zhi, j=j):
                    ok = p @ radial > 0
                    if plan.bands > 1:
                        ok &= (p[:, 2] > zlo if j > 0 else True) & (p[:, 2] < zhi if j < plan.bands - 1 else True)
                    return ok

                out.append((f"sector plane {math.degrees(a) % 360:.1f} deg, band {j + 1}", n, np.zeros(3), keep))
        if j < plan.bands - 1:
            for i in range(plan.sectors):
                rng = plan.sector_range(i) if plan.sectors > 1 else None

                def keep(p, rng=rng):
                    if rng is None:
                        return np.ones(len(p), bool)
                    ang = (np.arctan2(p[:, 1], p[:, 0]) - rng[0]) % (2 * math.pi)
                    return ang < rng[1] - rng[0]

                out.append((f"band cut z {zhi:.1f} mm, sector {i + 1}", np.array([0.0, 0.0, 1.0]),
                            np.array([0.0, 0.0, zhi]), keep))
    return out


def _other_planes_clear(pts: np.ndarray, plan: SplitPlan, face_normal: np.ndarray, face_origin: np.ndarray,
                        margin: float) -> np.ndarray:
    """Points (n, 3) at least ``margin`` from every cut plane but the face's own."""
    ok = np.ones(len(pts), bool)
    for i in range(plan.sectors if plan.sectors > 1 else 0):
        a = plan.sector_range(i)[0]
        n = np.array([-math.sin(a), math.cos(a), 0.0])
        if np.allclose(np.abs(n @ face_normal), 1.0) and abs(face_normal[2]) < 0.5:
            continue
        radial = np.array([math.cos(a), math.sin(a), 0.0])
        # a half-plane: only points on its radial side can come near it
        near = (np.abs(pts @ n) < margin) & (pts @ radial > -margin)
        ok &= ~near
    for z in plan.band_z[1:-1]:
        if abs(face_normal[2]) > 0.5 and abs(z - face_origin[2]) < 1e-9:
            continue
        ok &= np.abs(pts[:, 2] - z) >= margin
    return ok


def place_pins(man: m3d.Manifold, plan: SplitPlan, pin: AlignmentPin, mirror: MirrorSurface | None) -> list[Pin]:
    """Pin holes on every cut face (see the module docstring); raises if a face gets fewer than two."""
    r = pin.hole_radius
    guard = r + MIN_WALL
    bb = np.asarray(man.bounding_box(), dtype=float)
    pins: list[Pin] = []
    for name, n, origin, keep in _interfaces(plan, bb):
        frame = _plane_frame(n, origin)
        inv = np.linalg.inv(np.vstack([frame, [0, 0, 0, 1]]))[:3]
        face = man.transform(frame.tolist()).slice(0.0)
        cand = []
        # candidate centres on the face eroded by the guard plus a slack: a straight pin in a curved
        # wall drifts outwards by depth^2 / (2 radius), so the boundary itself may be too close
        for slack in ERODE_SLACK:
            for p in face.offset(-(guard + slack), m3d.JoinType.Round).to_polygons():
                p = np.asarray(p, float)
                q = np.roll(p, -1, axis=0)
                for a, b in zip(p, q):  # the eroded boundary resampled every 0.5 mm
                    k = max(1, int(np.ceil(np.linalg.norm(b - a) / 0.5)))
                    cand.append(a + (b - a) * (np.arange(k) / k)[:, None])
        if not cand:
            raise FabricationError(f"{name}: the cut face is too thin for {pin.diameter:g} mm pins "
                                   f"(needs {2 * guard:.2f} mm of material)")
        c2 = np.concatenate(cand)
        pts = np.column_stack([c2, np.zeros(len(c2))]) @ inv[:, :3].T + inv[:, 3]
        mask = keep(pts) & _other_planes_clear(pts, plan, n, origin, guard)
        # the pin runs +-depth along n: both ends must also stay clear of the other planes
        mask &= _other_planes_clear(pts + pin.depth * n, plan, n, origin, guard)
        mask &= _other_planes_clear(pts - pin.depth * n, plan, n, origin, guard)
        if mirror is not None:
            mask &= _mirror_clear(pts, n, pin, mirror)
        pts = pts[mask]
        if len(pts) < 2:
            raise FabricationError(f"{name}: no room for two {pin.diameter:g} mm pins at {MIRROR_CLEARANCE:g} mm from "
                                   f"the mirror and {MIN_WALL:g} mm walls; use thinner pins (alignment_pin.diameter)")
        extent = float(np.max(np.ptp(pts, axis=0)))
        want = int(min(6, max(2, round(extent / PIN_SPACING))))
        chosen = _farthest(pts, want, lambda p: _inside(man, p, n, guard, pin.depth))
        if len(chosen) < 2:
            raise FabricationError(f"{name}: fewer than two pin positions keep {MIN_WALL:g} mm of wall around the "
                                   f"hole; use thinner pins (alignment_pin.diameter)")
        pins += [Pin(tuple(float(v) for v in p), tuple(float(v) for v in n), name) for p in chosen]
    return pins


def _mirror_clear(pts: np.ndarray, axis: np.ndarray, pin: AlignmentPin, mirror: MirrorSurface) -> np.ndarray:
    """Pin holes (centre pts, along axis) whose surface keeps MIRROR_CLEARANCE behind the mirror."""
    r = pin.hole_radius
    frame = _plane_frame(axis, np.zeros(3))[:, :3]
    e1, e2 = frame[0], frame[1]
    ok = np.ones(len(pts), bool)
    for s in np.linspace(-pin.depth, pin.depth, 7):
        for ang in np.linspace(0, 2 * math.pi, 12, endpoint=False):
            q = pts + s * axis + r * (math.cos(ang) * e1 + math.sin(ang) * e2)
            ok &= mirror.signed_distance(q) < -MIRROR_CLEARANCE
    return ok


def _inside(man: m3d.Manifold, centre: np.ndarray, axis: np.ndarray, radius: float, depth: float) -> bool:
    """The hole widened by the wall lies inside the part (its part outside has no volume)."""
    cyl = _cylinder(axis, centre, radius, depth + MIN_WALL)
    outside = cyl - man
    return outside.volume() < 1e-6 * cyl.volume()


def _farthest(pts: np.ndarray, want: int, valid) -> list[np.ndarray]:
    """Greedy farthest-point choice of up to ``want`` points that pass ``valid``."""
    centre = pts.mean(axis=0)
    alive = np.ones(len(pts), bool)
    chosen: list[np.ndarray] = []
    dist = np.linalg.norm(pts - centre, axis=1)  # first pick: far from the middle
    attempts = 0
    while len(chosen) < want and alive.any() and attempts < 200:  # a boolean per attempt: bounded
        attempts += 1
        k = int(np.argmax(np.where(alive, dist, -1.0)))
        alive[k] = False
        if not valid(pts[k]):
            continue
        chosen.append(pts[k])
        dist = np.minimum(dist, np.linalg.norm(pts - pts[k], axis=1)) if len(chosen) > 1 else \
            np.linalg.norm(pts - pts[k], axis=1)
    return chosen


def split_part(man: m3d.Manifold, name: str, plan: SplitPlan, pin: AlignmentPin,
               mirror: MirrorSurface | None) -> tuple[list[Piece], list[Pin], m3d.Manifold]:
    """Drill the pin holes and cut ``man`` into the plan's pieces. Returns the pieces, the pins
    and the drilled part (what the pieces reassemble to)."""
    if plan.count == 1:
        return [Piece(name, 0, 0, None, man)], [], man
    pins = place_pins(man, plan, pin, mirror)
    holes = [_cylinder(np.array(p.axis), np.array(p.centre), pin.hole_radius, pin.depth) for p in pins]
    drilled = m3d.Manifold.batch_boolean([man, *holes], m3d.OpType.Subtract)
    pieces = []
    for j in range(plan.bands):
        for i in range(plan.sectors):
            tag = []
            if plan.sectors > 1:
                tag.append(f"s{i + 1}of{plan.sectors}")
            if plan.bands > 1:
                tag.append(f"b{j + 1}of{plan.bands}")
            piece = cell(drilled, plan, i, j)
            if piece.is_empty():
                continue
            pieces.append(Piece(f"{name}_{'_'.join(tag)}", i, j,
                                plan.sector_range(i) if plan.sectors > 1 else None, piece))
    return pieces, pins, drilled
