"""Split a part that does not fit the printer into pieces with alignment pin holes.

Parts of the rig are (nearly) solids of revolution about the optical axis z, so a part is cut by
N vertical half-planes through the axis (sectors) and, when the sectors are still too tall, by
M - 1 horizontal planes (bands): a piece is one (sector, band) cell. The sectors' phase is chosen
so that the cut planes cross as few features (slots, bolt holes) as possible: the slices of the
part on the planes have the fewest loops, and the phase is the middle of the widest such range.

Each face between two neighbouring cells gets dowel-pin holes (a hole of the pin's diameter plus
clearance, ``depth`` into each piece), placed on the cut face where the material around the hole
is at least two perimeters thick (:func:`pin_wall`, from the printer) (a boolean test on the mesh: the hole widened by the wall must lie
inside the part) and, on a mirror part, at least ``MIRROR_CLEARANCE`` from the mirror surface
(measured on the exact surface). The booleans are manifold3d's on the part's mesh.

No cut crosses a datum feature (rigcad.parts.joints.Datum: a dowel hole, a bore, a seat, an insert
pocket, a register, declared on the part): the planner treats each feature's box, grown by its
:func:`datum_margin` (the feature's wall and the glue's squeeze-out; round a hole that takes a fit, the
sample bore bored after gluing or a reamed dowel hole, a hub of twice its diameter), as a keep-out
zone, moving a grid's cut to the nearer clear position (or the farther) and leaving out the sector
phases and band heights that would cross one; when no plan keeps off them the part is refused
(rigcad.fab.choice names the printer and its build volume). The seams that
remain between two datum features of one part (a glue line on its datum chain) are listed by
:func:`datum_seams`.
Frame: the part's working position, mm, rad.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import manifold3d as m3d
import numpy as np

from rigcad.errors import FabricationError
from rigcad.fab.mirror import MirrorSurface
from rigcad.fab.printers import AlignmentPin, perimeter_width
from rigcad.parts.recipe import Cylinder

#: Material kept around a pin hole (mm) when no printer says more: an SLA part's thinnest unsupported
#: wall (Formlabs' design guide: 0.6 mm). An FDM printer's is two perimeters (:func:`pin_wall`).
MIN_WALL = 0.6
#: How far (mm) glue squeezed out of a seam spreads along the cut face (about 1 mm): a seam keeps at
#: least this beyond a datum feature's own wall, so no glue reaches the feature.
GLUE_SQUEEZE_MM = 1.0
#: A datum feature's own wall (mm): two perimeters of an FDM print (~0.9 mm), rounded up.
FEATURE_WALL_MM = 1.0
#: A seam keeps this far (mm) from a datum feature's box: its own wall stays whole and the squeeze-out
#: does not reach it (:func:`datum_margin`: more round a hole that takes a fit).
DATUM_MARGIN = FEATURE_WALL_MM + GLUE_SQUEEZE_MM
#: A round hole that takes a fit (the sample bore, bored H7 on a mill after the pieces are glued; the
#: dowel and register pins' reamed holes) keeps a hub of one printed piece round it, as a hub keeps its
#: bore: "an ordinary rule is to make the outside diameter of the hub twice the diameter of the shaft"
#: (Shop Practice vol. 1, American Technical Society, "Hubs"). So its wall is half its diameter (20 mm
#: round the 40 mm sample bore), the cutting and clamping of its boring or reaming bear on one piece, and
#: no glue line runs inside the hub.
HUB_OVER_BORE = 2.0
#: The datum kinds whose round features take a fit (their keep-out is :func:`datum_margin`'s hub).
FIT_KINDS = ("bore", "dowel", "register")
#: What holds a split mirror's seam that takes no pins (its meridional faces where no pin of
#: pin_choices keeps its wall: the dome's 4.4 mm shell above its flange on a small bed). Its pins would
#: not align it anyway: a mirror's pin holes float (rigcad.fab.seams.float_pin) and the seam is glued on
#: the printed-stage template, which sets the step normal to the mirror; the piece's seat sets the rest.
PINLESS_WHY = ("a glued butt joint set on the printed-stage template (the gauge sets the step normal to the mirror; "
               "the pins of a mirror's seam float and only key the glue), the piece seated on the base plate by its "
               "flange screws or on the band below by its tongue in the groove")
#: Grid cut positions tried per plan (each cut at its equal-slab place or moved off a keep-out).
KEEPOUT_TRIES = 6
#: Distance kept between a pin hole and the printed mirror surface (mm): sanding removes up to
#: ~0.2 mm there and the pin must not print-through as a bump (about five layers of material).
MIRROR_CLEARANCE = 1.0
#: Margin (mm) by which a hole's axis must clear MIRROR_CLEARANCE + its radius for its surface to
#: count as clear unsampled (_mirror_clear): the foot points' error is 1e-11 mm, so 1e-6 mm leaves
#: no decision to their rounding.
LIPSCHITZ_MARGIN = 1e-6
#: Extra erosions (mm) of a cut face where pin centres are sought (see place_pins).
ERODE_SLACK = (0.0, 0.15, 0.3, 0.5, 1.0)
#: Sector counts and band counts tried, fewest pieces first.
SECTOR_COUNTS = (1, 2, 3, 4, 6, 8, 12, 16)
BAND_COUNTS = (1, 2, 3, 4)
#: Pins per cut face: one per this length (mm) of the face, at least two, at most six.
PIN_SPACING = 60.0
_BIG = 1e4
#: Band cuts (horizontal planes across a thin shell) get a tongue and groove instead of pins:
#: the groove is sunk into the lower piece, the tongue is the same region (less the clearance)
#: given to the upper piece. Depths tried (mm, the pin depth first), the widest groove (mm) and
#: the smallest tongue cross-section kept per sector (mm^2).
TONGUE_DEPTHS = (None, 4.0, 3.0, 2.0)
TONGUE_MAX_WIDTH = 3.0
TONGUE_MIN_AREA = 5.0
#: Grid splits of flat, off-axis or tall parts: pieces per axis tried.
GRID_COUNTS = (1, 2, 3, 4, 5, 6)


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
    """A pin hole: centre on a cut face (mm), unit axis (the face's normal); the pin's and the hole's
    diameters (mm; 0: the printer's alignment pin)."""

    centre: tuple[float, float, float]
    axis: tuple[float, float, float]
    face: str
    diameter: float = 0.0
    hole_diameter: float = 0.0


@dataclass(frozen=True)
class GridPlan:
    """A flat, off-axis or tall part cut by planes in its own bounding box: ``x_cuts`` (planes
    x = c), ``y_cuts`` (planes y = c) and ``z_cuts`` (planes z = c: a tall column is cut across its
    height into stacked pieces, as a fabricator would), mm; cell (i, j, k) is the i-th x slab, j-th
    y slab and k-th z slab."""

    x_cuts: tuple[float, ...]
    y_cuts: tuple[float, ...]
    z_cuts: tuple[float, ...] = ()

    @property
    def nx(self) -> int:
        return len(self.x_cuts) + 1

    @property
    def ny(self) -> int:
        return len(self.y_cuts) + 1

    @property
    def nz(self) -> int:
        return len(self.z_cuts) + 1

    @property
    def count(self) -> int:
        return self.nx * self.ny * self.nz

    def cells(self) -> list[tuple[int, int, int]]:
        """Every cell (i, j, k), z slabs outermost, then y, then x."""
        return [(i, j, k) for k in range(self.nz) for j in range(self.ny) for i in range(self.nx)]

    def cuts(self, axis: int) -> tuple[float, ...]:
        return (self.x_cuts, self.y_cuts, self.z_cuts)[axis]

    # the sector interface (no sectors: pieces orient as generic parts)
    sectors = 1
    bands = 1

    def sector_range(self, i: int):
        return None

    def describe(self) -> dict:
        return {"kind": "grid of planes in the part's bounding box", "sectors": 1, "bands": 1,
                "grid": [self.nx, self.ny, self.nz], "pieces": self.count, "x_cuts_mm": list(self.x_cuts),
                "y_cuts_mm": list(self.y_cuts), "z_cuts_mm": list(self.z_cuts), "sector_planes_deg": [],
                "band_cuts_z_mm": []}


@dataclass
class Tongue:
    """A tongue and groove on a band cut at ``z`` (mm): ``groove`` is removed from the lower
    pieces, ``tongue`` (the groove less the clearance) belongs to the upper pieces."""

    z: float
    depth: float
    groove: m3d.Manifold = field(repr=False)
    tongue: m3d.Manifold = field(repr=False)
    face: str = ""
    min_clearance_to_mirror: float | None = None

    def describe(self) -> dict:
        return {"face": self.face, "z_mm": self.z, "depth_mm": self.depth,
                "groove_volume_mm3": self.groove.volume(), "tongue_volume_mm3": self.tongue.volume(),
                "min_clearance_to_mirror_mm": self.min_clearance_to_mirror}


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


def grid_cell(man: m3d.Manifold, plan: GridPlan, i: int, j: int, k: int = 0) -> m3d.Manifold:
    """Cell (x slab i, y slab j, z slab k) of ``man``."""
    out = man
    for axis, idx in enumerate((i, j, k)):
        cuts = plan.cuts(axis)
        normal = [0.0, 0.0, 0.0]
        normal[axis] = 1.0
        if idx > 0:
            out = out.trim_by_plane(tuple(normal), cuts[idx - 1])
        if idx < len(cuts):
            out = out.trim_by_plane(tuple(-v for v in normal), -cuts[idx])
    return out


def is_off_axis(man: m3d.Manifold, rtol: float = 0.05) -> bool:
    """A part not centred on the optical axis (its bounding box's centre off z by more than
    ``rtol`` of its size): it is split by a grid in its own bounding box, not into sectors."""
    bb = np.asarray(man.bounding_box(), dtype=float)
    c = (bb[:2] + bb[3:5]) / 2
    size = float(max(bb[3] - bb[0], bb[4] - bb[1]))
    return bool(np.any(np.abs(c) > rtol * size))


def _grid_options(size: np.ndarray) -> list[tuple[int, int, int]]:
    """Cut counts (x, y, z) to try: fewest pieces first; among equal counts, the most cuts across
    the longest side (sides equal to rounding, 1e-9 of the size, in x, y, z order on every CPU)."""
    tol = 1e-9 * float(size.max())

    def longer_first(a: int, b: int) -> int:
        return -1 if size[a] > size[b] + tol else 1 if size[b] > size[a] + tol else a - b

    order = sorted(range(3), key=functools.cmp_to_key(longer_first))
    return sorted(((a, b, c) for a in GRID_COUNTS for b in GRID_COUNTS for c in GRID_COUNTS),
                  key=lambda n: (n[0] * n[1] * n[2], tuple(-n[a] for a in order)))


#: A pin hole's wall on an FDM print: PIN_WALL_PERIMETERS of the printer's perimeter lines, and never
#: under PIN_WALL_MIN_MM. Every pin hole is drilled to its drawn size after printing (:func:`pin_fit`);
#: the drill, run in by hand, trues a hole that drooped or printed small and can take a line's width
#: off one side, and two perimeters must remain round it (the least that holds a pin without breaking
#: out: the machinist's review measured 0.60-0.90 mm walls break out, and asked more than 0.90-1.20 mm),
#: so three; 1.5 mm, the machinist's figure, when three lines are thinner.
PIN_WALL_PERIMETERS, PIN_WALL_MIN_MM = 3, 1.5


def pin_wall(printer) -> float:
    """Wall (mm) kept around every pin hole: on an FDM printer PIN_WALL_PERIMETERS perimeter lines
    (rigcad.fab.printers.perimeter_width) or PIN_WALL_MIN_MM, whichever is more; MIN_WALL for a resin
    printer."""
    if getattr(printer, "process", "fdm") != "fdm" or not getattr(printer, "nozzle", None):
        return MIN_WALL
    return max(MIN_WALL, PIN_WALL_MIN_MM, PIN_WALL_PERIMETERS * perimeter_width(printer))


#: Hole shrink (mm, diametral) assumed when the printer file states no process errors: FDM holes print
#: 0.1-0.3 mm undersize (the top of that range for a horizontal axis, whose top droops); resin 0.1.
DEFAULT_HOLE_SHRINK = {"fdm": 0.3, "sla": 0.1}


def pin_fit(printer, pins, pin: AlignmentPin | None = None) -> dict:
    """How a part's pins fit their holes (mm): the pin and its hole as drawn, the printer's hole shrink
    for a hole of that size whose axis may lie either way as printed (its ``process_errors``, else
    DEFAULT_HOLE_SHRINK), the hole as it prints, the class (slip: the drawn hole's clearance, ``press``
    when the print's shrink takes it below the pin) and the shop step that makes it right: every pin
    hole drilled to its drawn size after printing (a hole printed with a horizontal axis droops at its
    top; the drill, run in by hand, trues it and two perimeters of wall keep it from breaking out).
    ``pin``: the pin the part was split with (default the printer's; a split mirror's floats,
    rigcad.fab.seams.float_pin: the glue, not the pin, fills its clearance)."""
    pin = pin or printer.alignment_pin
    d = max((p.diameter for p in pins), default=pin.diameter) or pin.diameter
    hole = d + pin.clearance
    errors = getattr(printer, "process_errors", None)
    if errors is not None and hasattr(errors, "shrink"):
        shrink, source = float(errors.shrink(hole, "unknown")), getattr(errors, "source", "the printer file")
    else:
        shrink, source = DEFAULT_HOLE_SHRINK.get(printer.process, 0.3), "rigcad's default (no process errors stated)"
    printed = hole - shrink
    floats = pin.clearance > printer.alignment_pin.clearance + 1e-9
    after = "float (the glue fills it)" if floats else ("clearance" if pin.clearance > 0 else "press")
    return {"pin_diameter_mm": d, "hole_drawn_mm": hole, "hole_shrink_mm": shrink, "shrink_source": source,
            "hole_as_printed_mm": printed, "class_as_printed": "clearance" if printed > d else "press",
            "class_after_drilling": after,
            "step": f"drill every pin hole {hole:g} mm, {pin.depth:g} mm deep, by hand after printing "
                    f"(it prints about {printed:.2f} mm), then push a {d:g} mm pin in: a {after} fit"}


def datum_margin(datum) -> float:
    """How far (mm) every seam keeps from a datum feature (rigcad.parts.joints.Datum): DATUM_MARGIN,
    or round a round hole that takes a fit (FIT_KINDS, a vertical Cylinder) its hub's wall
    ((HUB_OVER_BORE - 1) / 2 x its diameter) plus GLUE_SQUEEZE_MM, whichever is more: 21 mm round the
    default 40 mm sample bore."""
    shape = datum.shape
    if datum.kind in FIT_KINDS and isinstance(shape, Cylinder):
        hub = 0.5 * (HUB_OVER_BORE - 1.0) * 2.0 * shape.radius
        return max(DATUM_MARGIN, hub + GLUE_SQUEEZE_MM)
    return DATUM_MARGIN


def keepouts(datums) -> list[tuple[np.ndarray, np.ndarray]]:
    """The keep-out boxes (lo, hi; mm) of a part's datum features: each feature's bounds grown by its
    :func:`datum_margin`. A cut plane that misses a box misses the feature by at least that margin."""
    return [(np.asarray(d.bounds[0], float) - datum_margin(d), np.asarray(d.bounds[1], float) + datum_margin(d))
            for d in datums]


def _blocked(boxes, axis: int) -> list[tuple[float, float]]:
    """The keep-outs' intervals on ``axis``, merged (sorted, disjoint)."""
    spans = sorted((float(lo[axis]), float(hi[axis])) for lo, hi in boxes)
    out: list[list[float]] = []
    for a, b in spans:
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def clear_cuts(base, lo: float, hi: float, blocked) -> list[tuple[float, ...]]:
    """Cut positions on one axis (between ``lo`` and ``hi``, increasing) near ``base`` that cross no
    ``blocked`` interval: a cut inside one moves to its nearer edge or its farther; the choices in
    order of the total move (ties: the first in order), at most KEEPOUT_TRIES."""
    import itertools

    options = []
    for c in base:
        hit = next(((a, b) for a, b in blocked if a < c < b), None)
        options.append([c] if hit is None else sorted(hit, key=lambda e: (abs(e - c), e)))
    out = []
    for combo in itertools.product(*options):
        if all(lo < c < hi for c in combo) and all(b - a > 1e-6 for a, b in zip(combo, combo[1:])):
            out.append((sum(abs(c - b) for c, b in zip(combo, base)), combo))
    out.sort(key=lambda t: t[0])
    return [tuple(float(c) for c in combo) for _, combo in out[:KEEPOUT_TRIES]]


def plan_grid(man: m3d.Manifold, fits, keep_out=()) -> GridPlan:
    """The fewest-pieces grid (the long side cut first; a tall part is cut across its height) whose
    every cell ``fits(cell_manifold, plan, i, j)``: equal slabs, each cut moved off the ``keep_out``
    boxes (:func:`keepouts`) it would cross (:func:`clear_cuts`); raises if none."""
    import itertools

    bb = np.asarray(man.bounding_box(), dtype=float)
    blocked = [_blocked(keep_out, a) for a in range(3)]
    for n in _grid_options(bb[3:] - bb[:3]):
        per_axis = [clear_cuts(tuple(float(v) for v in np.linspace(bb[a], bb[a + 3], n[a] + 1)[1:-1]),
                               float(bb[a]), float(bb[a + 3]), blocked[a]) for a in range(3)]
        for cuts in itertools.islice(itertools.product(*per_axis), KEEPOUT_TRIES):
            plan = GridPlan(*cuts)
            if all(fits(grid_cell(man, plan, i, j, k), plan, i, j) for i, j, k in plan.cells()):
                return plan
    kept = (f" whose cuts keep off its {len(keep_out)} datum features (each by its split.datum_margin: "
            f"{FEATURE_WALL_MM:g} mm of wall, a hub of half its diameter round a hole that takes a fit, and "
            f"{GLUE_SQUEEZE_MM:g} mm for the glue)") if len(keep_out) else ""
    raise FabricationError(f"no grid of up to {GRID_COUNTS[-1]} x {GRID_COUNTS[-1]} x {GRID_COUNTS[-1]} pieces{kept} fits")


def _grid_interfaces(plan: GridPlan):
    """Every face between two neighbouring cells: (name, normal, origin, keep), ``keep`` the
    points inside the face's slabs of the two other axes."""
    out = []
    slabs = [(-_BIG, *plan.cuts(a), _BIG) for a in range(3)]
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        for c in plan.cuts(axis):
            for s0 in range(len(slabs[others[0]]) - 1):
                for s1 in range(len(slabs[others[1]]) - 1):
                    lo = np.array([slabs[others[0]][s0], slabs[others[1]][s1]])
                    hi = np.array([slabs[others[0]][s0 + 1], slabs[others[1]][s1 + 1]])

                    def keep(p, lo=lo, hi=hi, others=others):
                        q = p[:, others]
                        return np.all((q > lo) & (q < hi), axis=1)
                    n, o = np.zeros(3), np.zeros(3)
                    n[axis], o[axis] = 1.0, c
                    name = f"{'xyz'[axis]} cut {c:.1f} mm, {'xyz'[others[0]]} slab {s0 + 1}, {'xyz'[others[1]]} slab {s1 + 1}"
                    out.append((name, n, o, keep))
    return out


def _grid_planes_clear(pts: np.ndarray, plan: GridPlan, face_normal: np.ndarray, face_origin: np.ndarray,
                       margin: float) -> np.ndarray:
    ok = np.ones(len(pts), bool)
    for axis in range(3):
        for c in plan.cuts(axis):
            if abs(face_normal[axis]) > 0.5 and abs(face_origin[axis] - c) < 1e-9:
                continue
            ok &= np.abs(pts[:, axis] - c) >= margin
    return ok


def _plane_frame(normal: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """3x4 matrix taking the part frame to a frame whose z = 0 is the plane (z along normal)."""
    n = normal / np.linalg.norm(normal)
    e1 = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = e1 - (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    rot = np.stack([e1, e2, n])
    return np.hstack([rot, (-rot @ origin)[:, None]])


def _loops_on_half_plane(man: m3d.Manifold, a: float) -> int:
    """Loops of the part's slice on the half-plane through the axis at angle ``a`` (rad)."""
    n = np.array([-math.sin(a), math.cos(a), 0.0])
    frame = _plane_frame(n, np.zeros(3))
    cs = man.transform(frame.tolist()).slice(0.0)
    # keep the half-plane on the radial side of angle a: in the plane frame, radial = (0, 1)
    # since e1 = z and e2 = n x z = radial
    half = m3d.CrossSection.square((_BIG, _BIG)).translate((-_BIG / 2, 0.0))
    return len((cs ^ half).to_polygons())


def _loops_on_planes(man: m3d.Manifold, sectors: int, phase: float, seen: dict | None = None) -> int:
    """Loops of the part's slices on the sector half-planes (features crossed add loops).
    ``seen`` maps angles (rad, exact floats) already sliced on ``man`` to their loops."""
    seen = {} if seen is None else seen
    total = 0
    for i in range(sectors):
        a = phase + i * 2 * math.pi / sectors
        if a not in seen:
            seen[a] = _loops_on_half_plane(man, a)
        total += seen[a]
    return total


def _half_plane_crosses(a: float, boxes) -> bool:
    """Whether the half-plane through the z axis at angle ``a`` (rad) meets any of ``boxes``."""
    n = np.array([-math.sin(a), math.cos(a)])
    radial = np.array([math.cos(a), math.sin(a)])
    for lo, hi in boxes:
        corners = np.array([(x, y) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
        s = corners @ n
        if s.min() < 0.0 < s.max() and (corners @ radial).max() > 0.0:
            return True
    return False


def choose_phase(man: m3d.Manifold, sectors: int, step_deg: float = 2.5, seen: dict | None = None,
                 keep_out=()) -> float | None:
    """Sector phase (rad) crossing the fewest features; the middle of the widest range of such.
    ``seen``: the slices counted so far on ``man`` (see _loops_on_planes), shared between sector
    counts (2 and 4 sectors share half their half-planes, bit for bit). Phases whose half-planes
    meet a ``keep_out`` box are left out; None when that leaves none."""
    if sectors == 1:
        return 0.0
    period = 360.0 / sectors
    grid = np.arange(0.0, period, step_deg)
    allowed = np.array([not any(_half_plane_crosses(math.radians(g) + i * 2 * math.pi / sectors, keep_out)
                                for i in range(sectors)) for g in grid])
    if not allowed.any():
        return None
    seen = {} if seen is None else seen
    loops = np.array([_loops_on_planes(man, sectors, math.radians(g), seen) if ok else np.iinfo(np.int64).max
                      for g, ok in zip(grid, allowed)])
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


def band_cuts(z0: float, z1: float, bands: int):
    """Band boundaries to try: for two bands the cut from low to high (a dome's wall is steepest
    low down, where vertical pins stay inside it), otherwise equal bands."""
    if bands == 2:
        for f in np.arange(0.2, 0.81, 0.05):
            yield (z0, z0 + f * (z1 - z0), z1)
    else:
        yield tuple(np.linspace(z0, z1, bands + 1))


def plan_split(man: m3d.Manifold, fits, keep_out=()) -> SplitPlan:
    """The fewest-pieces plan whose every cell ``fits(cell_manifold, plan, i, j)`` and whose cuts
    meet no ``keep_out`` box (:func:`keepouts`); raises if none."""
    bb = np.asarray(man.bounding_box(), dtype=float)
    z0, z1 = bb[2], bb[5]
    options = sorted(((s, b) for s in SECTOR_COUNTS for b in BAND_COUNTS), key=lambda sb: (sb[0] * sb[1], sb[1]))
    phases: dict[int, float | None] = {}
    seen: dict[float, int] = {}  # half-plane angle -> loops, shared by the sector counts
    z_blocked = _blocked(keep_out, 2)
    for s, b in options:
        if s not in phases:
            phases[s] = choose_phase(man, s, seen=seen, keep_out=keep_out)
        if phases[s] is None:
            continue
        for cuts in band_cuts(z0, z1, b):
            if any(a < z < c for z in cuts[1:-1] for a, c in z_blocked):
                continue
            plan = SplitPlan(s, b, phases[s], cuts)
            if all(fits(cell(man, plan, i, j), plan, i, j) for i in range(s) for j in range(b)):
                return plan
    raise FabricationError(f"no split into up to {SECTOR_COUNTS[-1]} sectors x {BAND_COUNTS[-1]} bands fits")


def _cylinder(pin_axis: np.ndarray, centre: np.ndarray, radius: float, half_length: float) -> m3d.Manifold:
    cyl = m3d.Manifold.cylinder(2 * half_length, radius, radius, 24).translate((0.0, 0.0, -half_length))
    rot = np.linalg.inv(_plane_frame(pin_axis, np.zeros(3))[:, :3])  # plane frame z -> pin axis
    return cyl.transform(np.hstack([rot, centre[:, None]]).tolist())


def _interfaces(plan: SplitPlan, bb: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray, callable]]:
    """Cut faces between neighbouring cells: (name, normal, origin, keep(points (n,3)) -> bool mask
    of points on this face's part of the plane, inside the two cells). Two sectors' half-planes lie in
    one plane and join the same two cells, so a two-sector band has one face, the whole plane: a part
    that crosses the axis (a beam cut in its middle) takes its pins across the axis, not two pairs
    crowded into each half of its section."""
    out = []
    for j in range(plan.bands):
        zlo, zhi = plan.band_z[j], plan.band_z[j + 1]
        if plan.sectors == 2:
            a = plan.sector_range(0)[0]

            def keep(p, zlo=zlo, zhi=zhi, j=j):
                ok = np.ones(len(p), bool)
                if plan.bands > 1:
                    ok &= (p[:, 2] > zlo if j > 0 else True) & (p[:, 2] < zhi if j < plan.bands - 1 else True)
                return ok

            out.append((f"sector plane {math.degrees(a) % 360:.1f}/{math.degrees(a + math.pi) % 360:.1f} deg, "
                        f"band {j + 1}", np.array([-math.sin(a), math.cos(a), 0.0]), np.zeros(3), keep))
        elif plan.sectors > 1:
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
                        margin: float, below: float = 0.0) -> np.ndarray:
    """Points (n, 3) at least ``margin`` from every cut plane but the face's own (and, under a band
    cut, ``below`` more: its groove)."""
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
        ok &= (pts[:, 2] - z >= margin) | (z - pts[:, 2] >= margin + below)
    return ok


def _boundary_points(section: m3d.CrossSection, guard: float) -> np.ndarray | None:
    """Candidate pin centres (k, 2) in a face's plane: the boundary of ``section`` eroded by ``guard`` plus
    each ERODE_SLACK (a straight pin in a curved wall drifts outwards by depth^2 / (2 radius), so the
    boundary itself may be too close), resampled every 0.5 mm; None when nothing is left."""
    cand = []
    for slack in ERODE_SLACK:
        for p in section.offset(-(guard + slack), m3d.JoinType.Round).to_polygons():
            p = np.asarray(p, float)
            for a, b in zip(p, np.roll(p, -1, axis=0)):
                k = max(1, int(np.ceil(np.linalg.norm(b - a) / 0.5)))
                cand.append(a + (b - a) * (np.arange(k) / k)[:, None])
    return np.concatenate(cand) if cand else None


def _swept_section(moved: m3d.Manifold, reach: float, levels: int = 9) -> m3d.CrossSection:
    """The section common to the part's slices from -``reach`` to +``reach`` mm along the face's normal
    (``moved``: the part in the face's frame, the face at z = 0): where a straight pin through the face
    stays in the part over its whole length, at ``levels`` heights (the mesh test decides)."""
    region = None
    for h in np.linspace(-reach, reach, levels):
        sl = moved.slice(float(h))
        region = sl if region is None else region ^ sl
    return region


def _face_pins(man, face, n, frame, keep, clear, pin, wall, mirror, pins) -> tuple[list, str]:
    """Pin centres on one cut face (``face``: the section candidates come from): the positions that keep
    clear of the other planes, the mirror and the holes already placed (``pins``), chosen farthest apart
    and each passing the mesh test (:func:`_inside`); ([], why) when fewer than two."""
    r = pin.hole_radius
    guard = r + wall
    c2 = _boundary_points(face, guard)
    if c2 is None:
        return [], f"the cut face is too thin for {pin.diameter:g} mm pins (needs {2 * guard:.2f} mm of material)"
    inv = np.linalg.inv(np.vstack([frame, [0, 0, 0, 1]]))[:3]
    pts = np.column_stack([c2, np.zeros(len(c2))]) @ inv[:, :3].T + inv[:, 3]
    # the pin runs +-depth along n: both ends must also stay clear of the other planes
    mask = keep(pts) & clear(pts) & clear(pts + pin.depth * n) & clear(pts - pin.depth * n)
    if mirror is not None and mask.any():  # only where the cheap tests pass (same result, faster)
        idx = np.flatnonzero(mask)
        idx = idx[mirror.signed_distance(pts[idx]) < -(MIRROR_CLEARANCE + r)]  # a necessary condition
        mask[:] = False
        if len(idx):
            mask[idx] = _mirror_clear(pts[idx], n, pin, mirror)
    # the hole widened by its wall keeps clear of the holes already placed on other faces (two cut planes
    # that cross put pins on both near the crossing: their holes can meet inside the part)
    for q in pins:
        mask &= _segment_distance(pts, n, pin.depth + wall, np.array(q.centre), np.array(q.axis),
                                  pin.depth) >= r + wall + q.hole_diameter / 2
    pts = pts[mask]
    if len(pts) < 2:
        return [], (f"no room for two {pin.diameter:g} mm pins" + (f" at {MIRROR_CLEARANCE:g} mm from the mirror and"
                                                                   if mirror is not None else " with")
                    + f" {wall:g} mm walls")
    want = int(min(6, max(2, round(float(np.max(np.ptp(pts, axis=0))) / PIN_SPACING))))
    # two holes of one face (parallel, in its plane) keep the wall between them
    chosen = _farthest(pts, want, lambda p: _inside(man, p, n, guard, pin.depth, wall), apart=2 * r + wall)
    if len(chosen) < 2:
        return [], f"fewer than two pin positions keep {wall:g} mm of wall around the hole for {pin.diameter:g} mm pins"
    return chosen, ""


def place_pins(man: m3d.Manifold, plan, pin: AlignmentPin, mirror: MirrorSurface | None,
               tongues: list[Tongue] | None = None, wall: float | None = None, pinless: list | None = None,
               swept: bool = True) -> list[Pin]:
    """Pin holes on every cut face (see the module docstring); raises if a face gets fewer than two.
    With ``tongues``, the band cuts carry those instead of pins, and pins keep clear of them. Candidates
    come from the face's own section, and (``swept``) when that gives no two positions, from the section
    common to the pin's whole length (:func:`_swept_section`: a plate's chord near its rim, where the face's outline
    narrows along the pin). ``pinless``, a list (a split mirror's, glued on its gauge: PINLESS_WHY): a
    meridional face where no two pins fit is appended to it ({"face", "why"}) instead of refused."""
    wall = MIN_WALL if wall is None else wall
    guard = pin.hole_radius + wall
    bb = np.asarray(man.bounding_box(), dtype=float)
    pins: list[Pin] = []
    if isinstance(plan, GridPlan):
        faces = _grid_interfaces(plan)

        def clear_of(n, origin):
            return lambda p: _grid_planes_clear(p, plan, n, origin, guard)
    else:
        faces = _interfaces(plan, bb)
        below = max((t.depth for t in tongues), default=0.0) if tongues else 0.0
        if tongues:
            faces = [f for f in faces if abs(f[1][2]) < 0.5]  # band cuts: tongue and groove

        def clear_of(n, origin):
            return lambda p: _other_planes_clear(p, plan, n, origin, guard, below)
    for name, n, origin, keep in faces:
        frame = _plane_frame(n, origin)
        moved = man.transform(frame.tolist())
        chosen, why = _face_pins(man, moved.slice(0.0), n, frame, keep, clear_of(n, origin), pin, wall, mirror, pins)
        if not chosen and swept:
            chosen, _ = _face_pins(man, _swept_section(moved, pin.depth + wall), n, frame, keep, clear_of(n, origin),
                                   pin, wall, mirror, pins)
        if not chosen and pinless is not None and isinstance(plan, SplitPlan) and abs(n[2]) < 0.5:
            pinless.append({"face": name, "why": why, "held_by": PINLESS_WHY})
            continue
        if not chosen:
            raise FabricationError(f"{name}: {why}")
        pins += [Pin(tuple(float(v) for v in p), tuple(float(v) for v in n), name, pin.diameter, 2 * pin.hole_radius)
                 for p in chosen]
    return pins


def _segment_distance(centres: np.ndarray, axis: np.ndarray, half: float, centre: np.ndarray, other: np.ndarray,
                      other_half: float) -> np.ndarray:
    """Least distance (mm) from each segment ``centres`` (n, 3) +- ``half`` along the unit ``axis`` to the
    segment ``centre`` +- ``other_half`` along the unit ``other``: (n,). Closest points of two segments
    with clamping (C. Ericson, Real-Time Collision Detection, 5.1.9), vectorised over the first."""
    p1 = centres - half * axis
    d1, d2 = 2 * half * axis, 2 * other_half * other
    p2 = centre - other_half * other
    r = p1 - p2
    a, e, b = float(d1 @ d1), float(d2 @ d2), float(d1 @ d2)
    c, f = r @ d1, r @ d2
    denom = a * e - b * b
    s = np.clip((b * f - c * e) / denom, 0.0, 1.0) if denom > 1e-12 * a * e else np.zeros(len(centres))
    t = (b * s + f) / e
    s = np.where(t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p1 + s[:, None] * d1 - (p2 + t[:, None] * d2), axis=1)


def pin_choices(pin: AlignmentPin) -> list[AlignmentPin]:
    """The pins a part's seams may take, in order: the printer's alignment pin, then thinner ISO 8734
    dowel pins (down to 1 mm) with its clearance and depth, for a wall too thin for two perimeters
    round the printer's pin (a dome's shell)."""
    from dataclasses import replace

    from rigcad.standards import DOWEL_DIAMETERS

    return [pin, *(replace(pin, diameter=d) for d in sorted(DOWEL_DIAMETERS, reverse=True) if d < pin.diameter)]


def _mirror_region(mirror: MirrorSurface, zs: np.ndarray, clearance: float, rmax: float) -> m3d.CrossSection:
    """The region of a horizontal plane (as annuli about the axis) whose points stay at least
    ``clearance`` behind the mirror at every height in ``zs``."""
    r = np.arange(0.0, rmax, 0.02)
    ok = np.ones(len(r), bool)
    for z in zs:
        q = np.column_stack([r, np.zeros_like(r), np.full_like(r, z)])
        ok &= mirror.signed_distance(q) < -(clearance + 0.02)
    n = 720
    grow = 1.0 / math.cos(math.pi / n)  # a polygon hole of circumradius R/cos contains the circle R
    out = m3d.CrossSection()
    k = 0
    while k < len(r):
        if not ok[k]:
            k += 1
            continue
        e = k
        while e + 1 < len(r) and ok[e + 1]:
            e += 1
        outer = (m3d.CrossSection.square((4 * _BIG, 4 * _BIG), True) if e == len(r) - 1
                 else m3d.CrossSection.circle(float(r[e]), n))
        ring = outer - m3d.CrossSection.circle(float(r[k]) * grow, n) if r[k] > 0 else outer
        out = out + ring
        k = e + 1
    return out


def make_tongues(man: m3d.Manifold, plan: SplitPlan, pin: AlignmentPin, mirror: MirrorSurface | None) -> list[Tongue]:
    """A tongue and groove on every band cut (see TONGUE_DEPTHS): the groove is the cut face under
    the plane, kept MIN_WALL inside the part over its depth and MIRROR_CLEARANCE behind the mirror,
    at most TONGUE_MAX_WIDTH wide; raises if a sector gets no tongue."""
    out = []
    if not isinstance(plan, SplitPlan) or plan.bands < 2:
        return out
    bb = np.asarray(man.bounding_box(), dtype=float)
    rmax = float(np.hypot(np.abs(bb[[0, 3]]).max(), np.abs(bb[[1, 4]]).max())) + 1.0
    clr = pin.clearance
    for j, z in enumerate(plan.band_z[1:-1]):
        z = float(z)
        why = ""
        for depth in TONGUE_DEPTHS:
            depth = float(pin.depth if depth is None else depth)
            levels = np.linspace(z - depth - MIN_WALL, z - 1e-3, 9)
            region = None
            for zl in levels:
                sl = man.slice(float(zl))
                region = sl if region is None else region ^ sl
            region = region.offset(-MIN_WALL, m3d.JoinType.Round)
            if mirror is not None:
                region = region ^ _mirror_region(mirror, np.linspace(z - depth, z, 9), MIRROR_CLEARANCE, rmax)
            groove2 = region - region.offset(-TONGUE_MAX_WIDTH, m3d.JoinType.Round)
            tongue2 = groove2.offset(-clr / 2, m3d.JoinType.Round)
            if groove2.is_empty() or tongue2.is_empty():
                why = f"no room for a groove {depth:g} mm deep"
                continue
            g = m3d.Manifold.extrude(groove2, depth + 1.0).translate((0.0, 0.0, z - depth))
            g = g.trim_by_plane((0.0, 0.0, -1.0), -z)
            t = m3d.Manifold.extrude(tongue2, depth + 1.0 - clr).translate((0.0, 0.0, z - depth + clr))
            t = t.trim_by_plane((0.0, 0.0, -1.0), -z)
            areas = [cell(t, plan, i, j).volume() / (depth - clr) for i in range(plan.sectors)]
            if min(areas) < TONGUE_MIN_AREA:
                why = f"a sector gets a tongue of only {min(areas):.1f} mm^2 at {depth:g} mm depth"
                continue
            # the groove widened by the wall lies inside the part
            wall = m3d.Manifold.extrude(groove2.offset(MIN_WALL, m3d.JoinType.Round), depth + MIN_WALL) \
                .translate((0.0, 0.0, z - depth - MIN_WALL))
            outside = (wall - man).volume()
            if outside > 1e-3 * wall.volume():
                why = f"the groove {depth:g} mm deep leaves less than {MIN_WALL:g} mm of wall"
                continue
            clear = None
            if mirror is not None:
                pts2 = np.concatenate([np.asarray(p, float) for p in groove2.to_polygons()])
                pts = np.concatenate([np.column_stack([pts2, np.full(len(pts2), zl)])
                                      for zl in np.linspace(z - depth, z, 9)])
                clear = float(-mirror.signed_distance(pts).max())
                if clear < MIRROR_CLEARANCE:
                    why = f"the groove comes {clear:.2f} mm from the mirror"
                    continue
            out.append(Tongue(z, depth, g, t, f"band cut z {z:.1f} mm", clear))
            break
        else:
            raise FabricationError(f"band cut z {z:.1f} mm: no tongue and groove fits ({why})")
    return out


def _mirror_clear(pts: np.ndarray, axis: np.ndarray, pin: AlignmentPin, mirror: MirrorSurface) -> np.ndarray:
    """Pin holes (centre pts, along axis) whose surface keeps MIRROR_CLEARANCE behind the mirror:
    the hole's surface sampled at 7 depths x 12 azimuths, all in one foot-point solve (each point
    converges on its own: the same bits as one solve per depth and azimuth).

    A signed distance changes by at most the distance moved (1-Lipschitz; the mirror's, from its
    exact foot points, is), and each surface sample lies r from the axis sample at its depth. So a
    hole whose 7 axis samples lie deeper than MIRROR_CLEARANCE + r + LIPSCHITZ_MARGIN has every
    surface sample clear, and only the other holes are sampled around: the same answer from about
    a twelfth of the solves when most candidates are far behind the mirror."""
    r = pin.hole_radius
    frame = _plane_frame(axis, np.zeros(3))[:, :3]
    e1, e2 = frame[0], frame[1]
    depths = np.linspace(-pin.depth, pin.depth, 7)
    on_axis = mirror.signed_distance(np.concatenate([pts + s * axis for s in depths]))
    on_axis = on_axis.reshape(len(depths), len(pts))
    ok = np.all(on_axis < -(MIRROR_CLEARANCE + r + LIPSCHITZ_MARGIN), axis=0)
    rest = np.flatnonzero(~ok)
    if len(rest):
        q = [pts[rest] + s * axis + r * (math.cos(ang) * e1 + math.sin(ang) * e2)
             for s in depths for ang in np.linspace(0, 2 * math.pi, 12, endpoint=False)]
        d = mirror.signed_distance(np.concatenate(q)).reshape(len(q), len(rest))
        ok[rest] = np.all(d < -MIRROR_CLEARANCE, axis=0)
    return ok


def hole_clearance(pins, depth: float, mirror: MirrorSurface, depths: int = 25, azimuths: int = 36) -> float:
    """The least depth (mm) of the pin holes' walls behind the mirror: each hole (its centre and axis
    from ``pins``, its drawn ``hole_diameter``, ``depth`` mm each way along the axis) sampled at
    ``depths`` x ``azimuths`` points of its wall, finer than the placement's 7 x 12 (_mirror_clear);
    the signed distance is 1-Lipschitz, so the true least depth is under this by at most half the
    samples' spacing. inf without pins."""
    if not pins:
        return math.inf
    out = math.inf
    for p in pins:
        c, n = np.asarray(p.centre, float), np.asarray(p.axis, float)
        frame = _plane_frame(n, np.zeros(3))[:, :3]
        ang = np.linspace(0.0, 2 * math.pi, azimuths, endpoint=False)
        ring = (p.hole_diameter / 2) * (np.cos(ang)[:, None] * frame[0] + np.sin(ang)[:, None] * frame[1])
        q = np.concatenate([c + s * n + ring for s in np.linspace(-depth, depth, depths)])
        out = min(out, float(-mirror.signed_distance(q).max()))
    return out


def _inside(man: m3d.Manifold, centre: np.ndarray, axis: np.ndarray, radius: float, depth: float,
            wall: float = MIN_WALL) -> bool:
    """The hole widened by the wall lies inside the part (its part outside has no volume)."""
    cyl = _cylinder(axis, centre, radius, depth + wall)
    outside = cyl - man
    return outside.volume() < 1e-6 * cyl.volume()


def _farthest(pts: np.ndarray, want: int, valid, apart: float = 0.0) -> list[np.ndarray]:
    """Greedy farthest-point choice of up to ``want`` points that pass ``valid``, each at least
    ``apart`` mm from those chosen before it."""
    centre = pts.mean(axis=0)
    alive = np.ones(len(pts), bool)
    chosen: list[np.ndarray] = []
    dist = np.linalg.norm(pts - centre, axis=1)  # first pick: far from the middle
    attempts = 0
    while len(chosen) < want and alive.any() and attempts < 200:  # a boolean per attempt: bounded
        attempts += 1
        # the farthest, ties (distances equal to rounding, 1e-9 relative: a symmetric face's
        # mirror-image points) to the first in ``pts``' order, so the choice is the same on every CPU
        d = np.where(alive, dist, -1.0)
        k = int(np.argmax(d >= d.max() * (1.0 - 1e-9)))
        alive[k] = False
        if any(np.linalg.norm(pts[k] - c) < apart for c in chosen) or not valid(pts[k]):
            continue
        chosen.append(pts[k])
        dist = np.minimum(dist, np.linalg.norm(pts - pts[k], axis=1)) if len(chosen) > 1 else \
            np.linalg.norm(pts - pts[k], axis=1)
    return chosen


def split_part(man: m3d.Manifold, name: str, plan, pin: AlignmentPin,
               mirror: MirrorSurface | None, tongues: list | None = None, wall: float | None = None,
               pinless: list | None = None) -> tuple[list[Piece], list[Pin], m3d.Manifold]:
    """Drill the pin holes, sink the band cuts' grooves and cut ``man`` into the plan's pieces.
    Returns the pieces, the pins and the drilled part (what the pieces reassemble to: the part less
    the pin holes and the clearance between tongue and groove); ``tongues``, a list, receives the
    tongues; ``pinless``, a list, a split mirror's faces left without pins (:func:`place_pins`)."""
    pinless = [] if pinless is None else pinless
    if plan.count == 1:
        return [Piece(name, 0, 0, None, man)], [], man
    if isinstance(plan, GridPlan):
        pins, pin = _pins_that_fit(lambda q, _, swept: place_pins(man, plan, q, mirror, wall=wall, swept=swept), pin)
        holes = [_cylinder(np.array(p.axis), np.array(p.centre), pin.hole_radius, pin.depth) for p in pins]
        drilled = m3d.Manifold.batch_boolean([man, *holes], m3d.OpType.Subtract)
        pieces = []
        counts = (plan.nx, plan.ny, plan.nz)
        for cell_index in plan.cells():
            tag = [f"{'xyz'[a]}{cell_index[a] + 1}of{counts[a]}" for a in range(3) if counts[a] > 1]
            piece = grid_cell(drilled, plan, *cell_index)
            if not piece.is_empty():
                pieces.append(Piece(f"{name}_{'_'.join(tag)}", cell_index[0], cell_index[1], None, piece))
        return pieces, pins, drilled
    tg = make_tongues(man, plan, pin, mirror)
    if tongues is not None:
        tongues.extend(tg)
    pins, pin = _pins_that_fit(lambda q, skipped, swept: place_pins(man, plan, q, mirror, tg, wall=wall, pinless=skipped,
                                                                    swept=swept), pin, pinless if mirror is not None else None)
    holes = [_cylinder(np.array(p.axis), np.array(p.centre), pin.hole_radius, pin.depth) for p in pins]
    gaps = [t.groove - t.tongue for t in tg]
    drilled = m3d.Manifold.batch_boolean([man, *holes, *gaps], m3d.OpType.Subtract)
    pieces = []
    for j in range(plan.bands):
        for i in range(plan.sectors):
            tag = []
            if plan.sectors > 1:
                tag.append(f"s{i + 1}of{plan.sectors}")
            if plan.bands > 1:
                tag.append(f"b{j + 1}of{plan.bands}")
            piece = cell(drilled, plan, i, j)
            if j < plan.bands - 1 and tg:  # the groove under the cut above
                piece = piece - tg[j].groove
            if j > 0 and tg:  # the tongue below the cut under
                piece = piece + cell(tg[j - 1].tongue, plan, i, j - 1)
            if piece.is_empty():
                continue
            pieces.append(Piece(f"{name}_{'_'.join(tag)}", i, j,
                                plan.sector_range(i) if plan.sectors > 1 else None, piece))
    return pieces, pins, drilled


def crossed(datums, plan) -> list[str]:
    """The datum features (rigcad.parts.joints.Datum) a plan's cut planes run through (their boxes,
    not grown: what a fabricator would see cut), by name; empty for a plan that keeps off them."""
    out = []
    for d in datums:
        lo, hi = (np.asarray(v, float) for v in d.bounds)
        box = [(lo, hi)]
        if isinstance(plan, GridPlan):
            hit = any(lo[a] < c < hi[a] for a in range(3) for c in plan.cuts(a))
        else:
            hit = any(lo[2] < z < hi[2] for z in plan.band_z[1:-1]) or (
                plan.sectors > 1 and any(_half_plane_crosses(plan.sector_range(i)[0], box) for i in range(plan.sectors)))
        if hit:
            out.append(d.name)
    return out


def _cell_of(plan, p: np.ndarray) -> tuple:
    """The cell holding point ``p`` (mm): grid (i, j, k), or (sector, band)."""
    if isinstance(plan, GridPlan):
        return tuple(int(np.searchsorted(plan.cuts(a), p[a])) for a in range(3))
    band = int(np.searchsorted(plan.band_z[1:-1], p[2]))
    if plan.sectors == 1:
        return (0, band)
    ang = (math.atan2(p[1], p[0]) - plan.phase) % (2 * math.pi)
    return (int(ang // (2 * math.pi / plan.sectors)) % plan.sectors, band)


def _seams_between(plan, p: np.ndarray, q: np.ndarray) -> list[str]:
    """The cut faces a straight chain from ``p`` to ``q`` (mm) crosses, named as place_pins names
    the planes (a grid's cut by axis and place; a sector plane; a band cut); for sectors, the shorter
    way round."""
    if isinstance(plan, GridPlan):
        return [f"{'xyz'[a]} cut {c:.1f} mm" for a in range(3) for c in plan.cuts(a)
                if min(p[a], q[a]) < c < max(p[a], q[a])]
    out = [f"band cut z {z:.1f} mm" for z in plan.band_z[1:-1] if min(p[2], q[2]) < z < max(p[2], q[2])]
    if plan.sectors > 1:
        i, j = _cell_of(plan, p)[0], _cell_of(plan, q)[0]
        up = (j - i) % plan.sectors
        steps = range(1, up + 1) if up <= plan.sectors - up else range(0, up - plan.sectors, -1)
        for k in steps:
            a = plan.sector_range((i + k) % plan.sectors)[0]
            out.append(f"sector plane {math.degrees(a) % 360:.1f} deg")
    return out


def datum_seams(datums, plan) -> list[dict]:
    """The seams on a part's datum chains: for every two datum features of one part that the plan
    puts in different pieces, the cut faces between them (``between``: the two features' names,
    ``kinds``: theirs, ``seams``: the faces crossed on the straight line between their centres,
    ``count``). A seam there is a glued joint inside what was one printed length: its pins' fit and
    the pieces' hole positions add to the link between the two features (rigcad's tolerance stack
    counts them from this list). Empty for a whole part or when every feature shares one piece."""
    items = [(d, np.asarray(d.centre, float)) for d in datums]
    out = []
    for k, (a, pa) in enumerate(items):
        for b, pb in items[k + 1:]:
            if _cell_of(plan, pa) == _cell_of(plan, pb):
                continue
            seams = _seams_between(plan, pa, pb)
            out.append({"between": [a.name, b.name], "kinds": [a.kind, b.kind], "seams": seams,
                        "count": len(seams)})
    return out


def _pins_that_fit(place, pin: AlignmentPin, pinless: list | None = None) -> tuple[list[Pin], AlignmentPin]:
    """The pins a part's faces take, from ``place(pin, skipped, swept)`` (:func:`place_pins`): the first of
    :func:`pin_choices` whose holes the faces' own sections place with their walls (strict: no face left
    out); else, candidates also from the section along each pin (``swept``), and with ``pinless`` (a split
    mirror's list) meridional faces may be left without pins: the first choice that leaves none, else
    the one that leaves the fewest (the thicker on a tie), its faces appended to ``pinless``. A part the
    first pass places keeps its pins whatever the second would do. Refused, naming the first face that
    took no pin of any size and what would help, when none places."""
    first, best = None, None
    for swept in (False, True):
        for q in pin_choices(pin):
            skipped = [] if pinless is not None and swept else None
            try:
                pins = place(q, skipped, swept)
            except FabricationError as err:
                first = first or err
                continue
            if not skipped:
                return pins, q
            if best is None or len(skipped) < len(best[2]):
                best = (pins, q, skipped)
    if best is not None:
        tried = ", ".join(f"{q.diameter:g}" for q in pin_choices(pin))
        pinless.extend({**s, "why": f"{s['why']}; of the pins tried ({tried} mm) none left fewer faces without pins"}
                       for s in best[2])
        return best[0], best[1]
    sizes = [q.diameter for q in pin_choices(pin)]
    raise FabricationError(f"{first}, with any pin from {max(sizes):g} mm down to {min(sizes):g} mm (split.pin_choices: "
                           "no alignment_pin.diameter fits): choose a printer whose build volume cuts the part in fewer "
                           "or other places (--printer)") from first
