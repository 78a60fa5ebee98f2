"""Assembly feasibility: can the declared steps be done, in which order, with which tools.

A plan is a list of :class:`Step`: each names the parts it puts in place (meshes of
``rigcad.manual.assembly``), the directions it may go in along (unit vectors, rig frame: the part
moves along one of them by ``travel_mm`` to reach its place), the parts it needs in place before
(what it rests on or is held by) and its :class:`Fastener`s. A step is feasible, given the set of
parts already in place, when

1. everything it needs (and every part its fasteners pass through) is in place;
2. its parts, swept along one of its directions from ``travel_mm`` out to their place, do not
   penetrate anything in place (the parts, the fasteners already fitted, the bench) by more than
   CLEARANCE_MM;
3. every fastener fits: its body in place collides with nothing; its head's approach (the head's
   cylinder from ``approach_mm`` out along the bolt's axis) and its tool (the driver's cylinder, of
   the tool's stated length, straight out from the head) are clear; a nut, when it has one, sits
   clear and its spanner's path is clear. A nut trap, a heat-set insert, an instrument's own
   threaded socket or the bench's thread needs no path.

A step's feasibility depends only on the set in place (not on the order that set came in), so
:func:`find_order` is a depth-first search over sets, remembering the sets that lead nowhere: it
finds a feasible order when there is one and says which steps are stuck when there is none.
:func:`check_order` refuses a given order at its first infeasible step, with the reason.

Penetration is measured against each solid in place in turn (each pair once: a solid in place is
the same whatever came before it), as the thickness of the overlap solid, 2 V / A (V its volume, A
its area: a thin slab's thickness), so parts that touch (a beam on its slot floor, a plate on its collar)
pass while a part pushed through a wall does not; no decision hangs on the last bits of a
coincident face. A convex part's sweep is exact (the hull of its start and end); any other part's
is sampled every SWEEP_STEP_MM along the path (a wall thinner than that could be jumped: see
SWEEP_STEP_MM). Frame: mm, rig frame (O at the origin, +z up).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rigcad.errors import AssemblyError, GeometryError

#: Overlap thickness (mm) above which two solids collide: a printed fit's gap is ~0.2 mm, so 0.05 mm
#: is an interference no hand would push through, and well above the mesher's chord error in a contact.
CLEARANCE_MM = 0.05
#: Spacing (mm) of the sampled positions along an insertion path: half the thinnest solid a rig has
#: (the 1 mm plate beam splitter), so no sampled step jumps over a wall.
SWEEP_STEP_MM = 0.5
#: A bench under the lowest part: this deep (mm) and this far beyond the rig each way.
BENCH_DEPTH_MM = 50.0
BENCH_MARGIN_MM = 1000.0


@dataclass(frozen=True)
class Tool:
    """A hand tool on a straight path: its name with its standard and size, the length it reaches
    (mm) and the radius (mm) of the cylinder its shaft and the hand's grip need around its axis."""

    name: str
    length_mm: float
    radius_mm: float
    #: An L-shaped hex key: its long arm (mm) leaves the short one's end at right angles, along
    #: ``arm_dir`` (unit), the way a hand turns it a little at a time under an overhang.
    arm_mm: float = 0.0
    arm_dir: tuple[float, float, float] | None = None

    def path(self, start, axis):
        """The tool's straight path from ``start`` (the head's top, (3,) mm) out along ``-axis``."""
        a = np.asarray(axis, float)
        end = np.asarray(start, float) - a * self.length_mm
        shaft = cylinder(end, a, self.length_mm, self.radius_mm)
        if not self.arm_mm:
            return shaft
        return _union([shaft, cylinder(end, self.arm_dir, self.arm_mm, self.radius_mm)])


@dataclass(frozen=True)
class Fastener:
    """One bolt or screw in place: its item (an orderable spec), the centre of its head's bearing
    face ``head`` (3,) mm, its ``axis`` (unit, from the head into the joint), its length under the
    head and shank radius, its head (radius, height), the tool that drives it, and what takes its
    thread: "nut" (then ``nut_tool`` and ``nut_dir``, the spanner's way out), "insert" (a heat-set
    insert or nut trap in the part), "tapped" (a thread tapped in the part: a bought extrusion's
    core), "instrument" (the instrument's threaded socket) or "bench". A bolt that goes up from under
    a part standing on the bench is put in with the rig lifted onto blocks ``lift_mm`` high: its
    head's way in and its tools may reach that far below the bench's top."""

    item: str
    head: tuple[float, float, float]
    axis: tuple[float, float, float]
    length_mm: float
    shank_radius_mm: float
    head_radius_mm: float
    head_height_mm: float
    tools: tuple[Tool, ...]  #: any one of them will do, best first
    thread_in: str = "nut"
    nut_size_mm: tuple[float, float] = (0.0, 0.0)  #: across corners / 2 (mm), height (mm)
    nut_tool: Tool | None = None
    nut_dir: tuple[float, float, float] | None = None
    passes: tuple[str, ...] = ()  #: parts the shank goes through (they must be in place)
    grip_mm: float = 0.0  #: head's bearing face to the nut's (mm): washers included
    #: Parts drawn without the hole it goes through (an instrument's or a shim stack's plain box):
    #: its body may run through them.
    pierces: tuple[str, ...] = ()
    lift_mm: float = 0.0
    #: A countersunk head (ISO 10642, 90 deg): a cone from ``head_radius_mm`` at its top down to the
    #: shank, not a cylinder.
    countersunk: bool = False
    #: Plain washers (ISO 7089) it is fitted with: under its head, and under its nut when it has one
    #: held by a spanner (a nut in a trap bears on the part). None: that rule; 0 for a set screw.
    washers: int | None = None

    @property
    def washer_count(self) -> int:
        """The plain washers this fastener takes (see ``washers``)."""
        if self.washers is not None:
            return self.washers
        if self.thread_in == "tapped":  # a bought extrusion's core screws: heads sunk, no washer
            return 0
        return 2 if self.thread_in == "nut" and self.nut_tool is not None else 1

    def solids(self):
        """The fastener in place: its shank and head, and its nut when it has one (a hexagon,
        :func:`hex_prism`)."""
        a, h = np.asarray(self.axis, float), np.asarray(self.head, float)
        under = max(self.head_radius_mm - self.head_height_mm, 0.0) if self.countersunk else None  # 45 deg flanks
        body = [cylinder(h, a, self.length_mm, self.shank_radius_mm),
                cylinder(h - a * self.head_height_mm, a, self.head_height_mm, self.head_radius_mm, under)]
        if self.thread_in == "nut":
            body.append(hex_prism(h + a * self.grip_mm, a, self.nut_size_mm[1], self.nut_size_mm[0]))
        return _union(body)

    def paths(self) -> list[tuple[str, object]]:
        """The straight paths that must be clear: the head's approach along the axis (the bolt goes
        in from outside) and the nut's spanner (named, as solids); the tools' in :meth:`tool_paths`."""
        a, h = np.asarray(self.axis, float), np.asarray(self.head, float)
        top = h - a * self.head_height_mm
        out = [("the head's way in", cylinder(top - a * self.length_mm, a, self.length_mm, self.head_radius_mm))]
        if self.thread_in == "nut" and self.nut_tool is not None:
            n = np.asarray(self.nut_dir, float)
            start = h + a * (self.grip_mm + 0.5 * self.nut_size_mm[1])
            out.append((self.nut_tool.name, cylinder(start, n, self.nut_tool.length_mm, self.nut_tool.radius_mm)))
        return out

    def tool_paths(self) -> list[tuple[Tool, object]]:
        """Each tool with its path from the head's top."""
        a, h = np.asarray(self.axis, float), np.asarray(self.head, float)
        return [(t, t.path(h - a * self.head_height_mm, a)) for t in self.tools]


@dataclass(frozen=True)
class Step:
    """One assembly step (see the module docstring)."""

    name: str
    members: tuple[str, ...]
    directions: tuple[tuple[float, float, float], ...]
    travel_mm: float
    needs: tuple[str, ...] = ()
    fasteners: tuple[Fastener, ...] = ()
    text: str = ""
    bought: bool = False


@dataclass(frozen=True)
class Placed:
    """A step of a feasible order: the step and the direction it goes in along (unit, rig frame)."""

    step: Step
    direction: tuple[float, float, float]
    notes: tuple[str, ...] = field(default=())


# -- solids ----------------------------------------------------------------------------------------
def manifold(vertices: np.ndarray, faces: np.ndarray):
    """A manifold3d solid from a closed mesh (vertices (n, 3) mm, faces (m, 3))."""
    import manifold3d as m3

    mesh = m3.Mesh(vert_properties=np.asarray(vertices, np.float32), tri_verts=np.asarray(faces, np.uint32))
    return m3.Manifold(mesh)


def cylinder(start, axis, length: float, radius: float, radius_end: float | None = None):
    """A solid cylinder (32 sides, circumscribed: it covers the true one) from ``start`` (3,) mm
    along the unit ``axis`` for ``length`` mm; with ``radius_end``, a cone to that radius at the end."""
    import manifold3d as m3

    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    r = radius / np.cos(np.pi / 32)
    c = m3.Manifold.cylinder(length, r, r if radius_end is None else radius_end / np.cos(np.pi / 32), 32)
    m = np.column_stack([u, v, a, np.asarray(start, float)])
    return c.transform(m)


def hex_prism(start, axis, length: float, corner_radius: float, turn: float | None = None):
    """A hexagonal prism (a nut: ISO 4032 across flats = corner_radius x sqrt 3) from ``start`` (3,) mm
    along the unit ``axis`` for ``length`` mm, exact (no circumscribing), one corner ``turn`` rad round
    from the rig's x axis (from y, for an x axis) as seen along the axis; by default as the printed
    nut traps hold a nut (rigcad.parts.tower.NUT_TRAP_TURN)."""
    import manifold3d as m3

    if turn is None:
        from rigcad.parts.tower import NUT_TRAP_TURN as turn

    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    ref = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u0 = ref - np.dot(ref, a) * a
    u0 /= np.linalg.norm(u0)
    v0 = np.cross(a, u0)
    u = np.cos(turn) * u0 + np.sin(turn) * v0
    v = np.cross(a, u)
    c = m3.Manifold.cylinder(length, corner_radius, corner_radius, 6)  # a corner on its local +x
    return c.transform(np.column_stack([u, v, a, np.asarray(start, float)]))


def penetration(a, b) -> float:
    """Thickness (mm) of the overlap of two solids, 2 V / A of their intersection (0 when they only touch)."""
    x = a ^ b
    if x.is_empty():
        return 0.0
    area = x.surface_area()
    return 2.0 * x.volume() / area if area > 0 else 0.0


def _boxes_overlap(a, b) -> bool:
    """Whether two boxes (lo x, y, z, hi x, y, z; mm) share a volume: boxes that only touch do not (their
    solids' overlap is then empty or flat, a penetration of 0)."""
    return all(a[i] < b[i + 3] and b[i] < a[i + 3] for i in range(3))


def _union(solids):
    import manifold3d as m3

    solids = [s for s in solids if s is not None]
    if not solids:
        return m3.Manifold()
    return m3.Manifold.batch_boolean(solids, m3.OpType.Add)


def bench(lo: np.ndarray, hi: np.ndarray):
    """The bench: a slab under the lowest point ``lo`` (3,) of the rig, reaching well beyond it."""
    import manifold3d as m3

    size = (hi[0] - lo[0] + 2 * BENCH_MARGIN_MM, hi[1] - lo[1] + 2 * BENCH_MARGIN_MM, BENCH_DEPTH_MM)
    return m3.Manifold.cube(size).translate((lo[0] - BENCH_MARGIN_MM, lo[1] - BENCH_MARGIN_MM, lo[2] - BENCH_DEPTH_MM))


def swept(solid, direction, travel: float, near=None):
    """The union of ``solid`` moved back along ``direction`` by 0 .. ``travel`` mm, every SWEEP_STEP_MM;
    with ``near`` (boxes (k, 6): lo, hi), only where its bounding box meets one of them (elsewhere it
    meets nothing, so leaving those positions out changes no penetration)."""
    import manifold3d as m3

    d = np.asarray(direction, float)
    if is_convex(solid):  # the exact sweep is one hull
        return m3.Manifold.batch_hull([solid, solid.translate(tuple(-d * travel))])
    s = _near_positions(solid, d, travel, near)
    return _union([solid.translate(tuple(-d * v)) for v in s])


#: A sweep is first tried at every COARSE-th sampled position, one copy at a time: a collision found
#: there refuses the step (its depth a lower bound) without building the whole sweep.
COARSE = 32


def is_convex(solid) -> bool:
    """Whether ``solid`` is its own convex hull (to the volume's last 1e-9): its sweep is then one hull."""
    return solid.hull().volume() <= solid.volume() * (1 + 1e-9) + 1e-9


def sweep_penetration(solid, direction, travel: float, other, convex: bool | None = None, hull_sweep=None) -> float:
    """Penetration (mm) of ``solid`` swept along ``direction`` (see :func:`swept`) into ``other``:
    :func:`coarse_penetration` when its copies find a collision, else :func:`whole_sweep_penetration`.
    ``convex`` (:func:`is_convex`) and, for a convex solid, ``hull_sweep`` (its :func:`swept`) may be
    given when known: a caller measuring one sweep against many solids computes them once."""
    first = coarse_penetration(solid, direction, travel, other, convex)
    return first if first is not None else whole_sweep_penetration(solid, direction, travel, other, convex, hull_sweep)


def whole_sweep_penetration(solid, direction, travel: float, other, convex: bool | None = None,
                            hull_sweep=None) -> float:
    """Penetration (mm) of the whole sweep of ``solid`` (:func:`swept`, near ``other`` only) into ``other``;
    0 when the sweep's box does not meet ``other``'s."""
    if not _boxes_overlap(_reach(solid, direction, travel), other.bounding_box()):
        return 0.0
    d = np.asarray(direction, float)
    if convex if convex is not None else is_convex(solid):
        return penetration(hull_sweep if hull_sweep is not None else swept(solid, d, travel), other)
    return penetration(swept(solid, d, travel, [other.bounding_box()]), other)


def coarse_penetration(solid, direction, travel: float, other, convex: bool | None = None) -> float | None:
    """The first part of :func:`sweep_penetration`, cheap: a non-convex ``solid`` is first tried at
    every COARSE-th sampled position, one copy at a time, and the first copy that runs more than
    CLEARANCE_MM into ``other`` gives the sweep's penetration (mm; a lower bound of the whole sweep's).
    None when that finds nothing (a convex solid, or no copy in the way): the whole sweep decides."""
    if convex if convex is not None else is_convex(solid):
        return None
    if not _boxes_overlap(_reach(solid, direction, travel), other.bounding_box()):
        return None
    d = np.asarray(direction, float)
    for s in _near_positions(solid, d, travel, [other.bounding_box()])[::COARSE]:
        pen = penetration(solid.translate(tuple(-d * s)), other)
        if pen > CLEARANCE_MM:
            return pen
    return None


def _reach(solid, direction, travel: float) -> tuple[float, ...]:
    """The box (lo x, y, z, hi x, y, z; mm) of ``solid`` swept back along ``direction`` by ``travel``."""
    box = np.asarray(solid.bounding_box(), float)
    moved = box - np.tile(np.asarray(direction, float) * travel, 2)
    return (*np.minimum(box[:3], moved[:3]), *np.maximum(box[3:], moved[3:]))


def _near_positions(solid, d: np.ndarray, travel: float, near) -> np.ndarray:
    """Sampled positions (mm back along ``d``) where the moved solid's box meets one of ``near``."""
    n = max(1, int(np.ceil(travel / SWEEP_STEP_MM)))
    s = np.linspace(0.0, travel, n + 1)
    if near is None or not len(near):
        return s
    box = np.asarray(solid.bounding_box(), float)
    lo = box[None, :3] - d[None, :] * s[:, None]  # (n + 1, 3) the moved box at each position
    hi = box[None, 3:] - d[None, :] * s[:, None]
    near = np.asarray(near, float)
    pad = SWEEP_STEP_MM  # a position whose box is within one step of an obstacle is kept
    meets = np.any(np.all((lo[:, None, :] < near[None, :, 3:] + pad) & (hi[:, None, :] > near[None, :, :3] - pad),
                          axis=2), axis=1)
    return s[meets]


@dataclass(frozen=True)
class Refusal:
    """Why a step cannot go next: ``blocked`` when something in place is in the way (then it cannot
    go after any more parts either), else it waits for a part it needs."""

    reason: str
    blocked: bool
    #: The parts (or, for a fitted fastener, the step that fits it) it runs into, shallowest first.
    obstacles: tuple[str, ...] = ()
    #: How far (mm) the way in that comes nearest still runs into something: the least penetration
    #: over the step's directions, or the deepest of its fasteners' collisions (0: waiting, not blocked).
    depth: float = 0.0
    #: Each way in tried, (direction, mm it still runs into something): a direction's sweep, or for
    #: the direction found clear, its fasteners' deepest collision (empty: waiting, not blocked).
    depths: tuple[tuple[tuple[float, float, float], float], ...] = ()

    def __str__(self) -> str:
        return self.reason


# -- the check -------------------------------------------------------------------------------------
class Assembly:
    """The parts' solids (name -> manifold3d solid) and the bench, with the feasibility test of a
    step given the steps already done (see the module docstring). Results are remembered per
    (step, set done): a step's feasibility depends on that set only."""

    def __init__(self, solids: dict, steps: list[Step], with_bench: bool = True) -> None:
        self.solids = solids
        self.steps = list(steps)
        self.by_name = {s.name: s for s in self.steps}
        names = [n for s in self.steps for n in s.members]
        missing = sorted(set(names) - set(solids))
        if missing:
            raise GeometryError(f"assembly steps place {missing}, which the rig has no solid for")
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise GeometryError(f"parts {dup} are placed by more than one assembly step")
        #: The bench's top (mm): the plane under the lowest part; None: no bench. A half-space, so its
        #: penetration is a depth below that plane, computed from bounding boxes (exact for a plane).
        self.bench_top = float(min(s.bounding_box()[2] for s in solids.values())) if with_bench else None
        self._memo: dict = {}
        self._pairs: dict = {}
        #: Solids made once per assembly: each step's solids in place (its parts and fitted fasteners),
        #: each fastener's body, paths and tool paths, each part's convexity and convex sweeps.
        self._placed: dict[str, list] = {}
        self._fittings: dict[tuple[str, int], tuple] = {}
        self._convex: dict[str, bool] = {}
        self._hull_sweeps: dict = {}
        self._coarse: dict = {}
        #: A fitted fastener's name -> the step that fits it (an obstacle is named by its part or step).
        self._owner = {_fastener_name(s, k): s.name for s in self.steps for k in range(len(s.fasteners))}

    def owner(self, obstacle: str) -> str:
        """The part or step an obstacle's name stands for (a fastener: the step that fits it)."""
        return self._owner.get(obstacle, obstacle)

    def _fitting(self, step: Step, k: int) -> tuple:
        """Fastener ``k`` of ``step``: its solids in place, its paths and its tools' paths (made once)."""
        key = (step.name, k)
        if key not in self._fittings:
            f = step.fasteners[k]
            self._fittings[key] = (f.solids(), f.paths(), f.tool_paths())
        return self._fittings[key]

    def _in_place(self, name: str) -> list[tuple[str, object]]:
        """The named solids step ``name`` leaves in place: its parts and its fitted fasteners."""
        if name not in self._placed:
            step = self.by_name[name]
            self._placed[name] = ([(m, self.solids[m]) for m in step.members]
                                  + [(_fastener_name(step, k), self._fitting(step, k)[0])
                                     for k in range(len(step.fasteners))])
        return self._placed[name]

    def _obstacles(self, done: frozenset[str], extra: tuple[str, ...] = ()) -> list[tuple[str, object]]:
        """Named solids in place once the steps ``done`` are: parts, fitted fasteners, the bench."""
        out = []
        for name in sorted(done):
            out += self._in_place(name)
        out += [(m, self.solids[m]) for m in extra]
        return out

    def _sweep_into(self, member: str, d, travel: float, name: str, other) -> float:
        """:func:`sweep_penetration` of part ``member`` into solid ``name``, with its convexity, its
        convex sweep and its coarse copies' answer made once."""
        key = (("sweep", member, d, travel), name)
        if key not in self._coarse:
            self._coarse[key] = coarse_penetration(self.solids[member], d, travel, other, self._is_convex(member))
        if self._coarse[key] is not None:
            return self._coarse[key]
        hull_sweep = None
        if self._is_convex(member):
            hk = (member, tuple(d), travel)
            if hk not in self._hull_sweeps:
                self._hull_sweeps[hk] = swept(self.solids[member], d, travel)
            hull_sweep = self._hull_sweeps[hk]
        return whole_sweep_penetration(self.solids[member], d, travel, other, True, hull_sweep) if hull_sweep is not None \
            else whole_sweep_penetration(self.solids[member], d, travel, other, False)

    def _into(self, key: tuple, make, named: list[tuple[str, object]], low: float | None = None) -> tuple[float, str]:
        """The deepest penetration (mm) of a solid into the named solids (``make(other, its name)`` measures it,
        remembered under ``key``) and the bench (``low``: the solid's lowest point, None: the bench is not in
        its way), and the name of the one it runs into deepest. Each pair is computed once: a solid
        in place is the same whatever came before it."""
        worst = (0.0, "nothing")
        if low is not None and self.bench_top is not None and self.bench_top - low > 0:
            worst = (self.bench_top - low, "the bench")
        for name, other in named:
            pair = (key, name)
            if pair not in self._pairs:
                self._pairs[pair] = make(other, name)
            if self._pairs[pair] > worst[0]:
                worst = (self._pairs[pair], name)
        return worst

    def attempt(self, step: Step, done: frozenset[str]) -> Placed | Refusal:
        """The step placed after ``done`` (a Placed), or why it cannot be (a sentence)."""
        key = (step.name, done)
        if key not in self._memo:
            self._memo[key] = self._attempt(step, done)
        return self._memo[key]

    def blocked(self, step: Step, done: frozenset[str]) -> bool:
        """Whether :meth:`attempt` refuses ``step`` after ``done`` as blocked (something in place is in
        its way), found with fewer solids: a way in is given up at the first solid it runs into
        (solids already measured first), not measured against them all for the refusal's depth."""
        known = self._memo.get((step.name, done))
        if known is not None:
            return isinstance(known, Refusal) and known.blocked
        if self._missing(step, done):
            return False
        obstacles = self._obstacles(done)
        if not any(self._clear(step, d, obstacles) for d in step.directions):
            return True
        return bool(self._fastener_problems(step, self._obstacles(done, step.members), []))

    def place(self, step: Step, done: frozenset[str]) -> Placed | None:
        """:meth:`attempt`'s Placed for ``step`` after ``done``, or None where it refuses; with fewer
        solids (no refusal's depths are measured: see :meth:`blocked`)."""
        known = self._memo.get((step.name, done))
        if known is not None:
            return known if isinstance(known, Placed) else None
        if self._missing(step, done):
            return None
        obstacles = self._obstacles(done)
        direction = next((d for d in step.directions if self._clear(step, d, obstacles)), None)
        if direction is None or self._fastener_problems(step, self._obstacles(done, step.members), []):
            return None
        return Placed(step, tuple(float(v) for v in direction))

    def _clear(self, step: Step, d, obstacles: list) -> bool:
        """Whether ``step``'s parts swept along ``d`` stay within CLEARANCE_MM of everything in
        ``obstacles`` and the bench (:meth:`_attempt`'s test of a direction, to the same bits). The
        cheap evidence first: the bench, the penetrations already measured, then each sweep's coarse
        copies (:func:`coarse_penetration`: a hit there is the sweep's own value); only then whole
        sweeps, the costly part, which a clear way in needs against every solid near it."""
        for m in step.members:
            key = ("sweep", m, d, step.travel_mm)
            low = self.solids[m].bounding_box()[2] - max(0.0, d[2]) * step.travel_mm
            if self.bench_top is not None and self.bench_top - low > CLEARANCE_MM:
                return False
            if any(self._pairs.get((key, name), 0.0) > CLEARANCE_MM for name, _ in obstacles):
                return False
        todo = [(m, ("sweep", m, d, step.travel_mm), name, other) for m in step.members for name, other in obstacles
                if (("sweep", m, d, step.travel_mm), name) not in self._pairs]
        for m, key, name, other in todo:
            if (key, name) not in self._coarse:
                self._coarse[(key, name)] = coarse_penetration(self.solids[m], d, step.travel_mm, other,
                                                               self._is_convex(m))
            if self._coarse[(key, name)] is not None:
                self._pairs[(key, name)] = self._coarse[(key, name)]
                return False
        for m, key, name, other in todo:
            self._pairs[(key, name)] = self._sweep_into(m, d, step.travel_mm, name, other)
            if self._pairs[(key, name)] > CLEARANCE_MM:
                return False
        return True

    def _is_convex(self, member: str) -> bool:
        if member not in self._convex:
            self._convex[member] = is_convex(self.solids[member])
        return self._convex[member]

    def _missing(self, step: Step, done: frozenset[str]) -> list[str]:
        """The parts ``step`` needs in place (its own needs, the parts its fasteners pass through)
        that ``done`` has not put in."""
        in_place = {m for n in done for m in self.by_name[n].members} | set(step.members)
        wanted = [*step.needs, *(p for f in step.fasteners for p in f.passes)]
        return sorted({n for n in wanted if n not in in_place})

    def _attempt(self, step: Step, done: frozenset[str]) -> Placed | Refusal:
        missing = self._missing(step, done)
        if missing:
            return Refusal(f"needs {', '.join(missing)} in place first", False)
        obstacles = self._obstacles(done)
        direction, reasons, hits = None, [], []
        for d in step.directions:
            worst = max((self._into(("sweep", m, d, step.travel_mm),
                                    lambda other, name, m=m, d=d: self._sweep_into(m, d, step.travel_mm, name, other),
                                    obstacles,
                                    self.solids[m].bounding_box()[2] - max(0.0, d[2]) * step.travel_mm)
                         for m in step.members), key=lambda t: t[0])
            if worst[0] <= CLEARANCE_MM:
                direction = d
                break
            reasons.append(f"moved in along {_dir_name(d)} it runs {worst[0]:.2f} mm into {worst[1]}")
            hits.append(worst)
        tried = tuple((d, h[0]) for d, h in zip(step.directions, hits))
        if direction is None:
            return Refusal("; ".join(reasons) or "no direction declared", True, self._named(hits),
                           min((h[0] for h in hits), default=float("inf")), tried)
        blocked = self._fastener_problems(step, self._obstacles(done, step.members), hits)
        if blocked:
            fitting = max((h[0] for h in hits[len(tried):]), default=0.0)
            return Refusal("; ".join(blocked), True, self._named(hits), max((h[0] for h in hits), default=0.0),
                           (*tried, (direction, fitting)))
        return Placed(step, tuple(float(v) for v in direction))

    def _named(self, hits: list[tuple[float, str]]) -> tuple[str, ...]:
        """The obstacles of ``hits`` ((depth, name) pairs) by part or step, each once, the shallowest
        first (the way in that comes nearest); the bench only when nothing else is in the way."""
        out: list[str] = []
        for _, name in sorted(hits, key=lambda h: h[0]):
            if self.owner(name) not in out and name != "nothing":
                out.append(self.owner(name))
        return tuple(n for n in out if n != "the bench") or tuple(out)

    def _fastener_problems(self, step: Step, obstacles: list, hits: list) -> list[str]:
        """Why a step's fasteners cannot be fitted (sentences); each obstacle met is added to ``hits``."""
        out = []
        fitted = list(obstacles)
        for k, f in enumerate(step.fasteners):
            name = _fastener_name(step, k)
            # a screw's thread runs into the bench or into the instrument's socket by design
            into = [(n, s) for n, s in fitted
                    if not (f.thread_in == "instrument" and n in step.members) and n not in f.pierces]
            body, paths, tool_paths = self._fitting(step, k)
            pen, what_in = self._into(("body", name), lambda other, _: penetration(body, other), into,
                                      None if f.thread_in == "bench" else body.bounding_box()[2])
            if pen > CLEARANCE_MM:
                out.append(f"{f.item} #{k + 1} at {_at(f.head)} runs {pen:.2f} mm into {what_in}")
                hits.append((pen, what_in))
            for what, path in paths:
                pen, by = self._into(("path", name, what), lambda other, _, path=path: penetration(path, other), fitted,
                                     path.bounding_box()[2] + f.lift_mm)
                if pen > CLEARANCE_MM:
                    out.append(f"{f.item} #{k + 1} at {_at(f.head)}: {what} is blocked by {by} ({pen:.2f} mm)")
                    hits.append((pen, by))
            tried, tool_hits = [], []
            for tool, path in tool_paths:
                pen, by = self._into(("tool", name, tool.name), lambda other, _, path=path: penetration(path, other), fitted,
                                     path.bounding_box()[2] + f.lift_mm)
                if pen <= CLEARANCE_MM:
                    break
                tried.append(f"the {tool.name}'s path is blocked by {by} ({pen:.2f} mm)")
                tool_hits.append((pen, by))
            else:  # every tool blocked
                hits += tool_hits
                out.append(f"{f.item} #{k + 1} at {_at(f.head)}: " + "; ".join(tried or ["no tool declared"]))
            fitted.append((name, body))
        return out


def _fastener_name(step: Step, k: int) -> str:
    return f"{step.fasteners[k].item} #{k + 1} of step {step.name}"


def _at(p) -> str:
    return "(" + ", ".join(f"{v:.1f}" for v in p) + ") mm"


_AXES = {(1, 0, 0): "+x", (-1, 0, 0): "-x", (0, 1, 0): "+y", (0, -1, 0): "-y", (0, 0, 1): "+z (up)",
         (0, 0, -1): "-z (down)"}


def _dir_name(d) -> str:
    key = tuple(int(round(v)) for v in d)
    if key in _AXES and np.allclose(d, key, atol=1e-9):
        return _AXES[key]
    return "(" + ", ".join(f"{v:+.3f}" for v in d) + ")"


def check_order(assembly: Assembly, names: list[str]) -> list[Placed]:
    """The steps named, in that order, each checked against those before it; GeometryError at the
    first that cannot be done (a planted wrong order, a blocked bolt), naming it and why."""
    done: frozenset[str] = frozenset()
    out = []
    for k, name in enumerate(names):
        r = assembly.attempt(assembly.by_name[name], done)
        if isinstance(r, Refusal):
            raise GeometryError(f"assembly step {k + 1} ({name}) cannot be done: {r}")
        out.append(r)
        done = done | {name}
    return out


#: Sets that lead nowhere before the search finds the pair precedences (must_precede): a passing rig's
#: search turns back a few times, where the pairs cost more than the turns (optimize design 123 of
#: achutha2006_optimize: one turn back, then 11.0 of the search's 18.4 s CPU in the pairs; the plain
#: search 8.7 s, the same order); a rig with no order turns back at every set of the parts that do not matter.
TIGHTEN_AFTER = 4


def find_order(assembly: Assembly) -> list[Placed]:
    """A feasible order of every step: depth-first over the sets of steps done, the declared order
    first at each choice, so the order found is the first feasible one in that search. GeometryError
    when there is no order, naming the steps left and why each cannot go next (:func:`_stuck`).

    Bounded by necessary conditions, each exact because parts only ever add obstacles (a step
    blocked with a set in place is blocked with any larger set): a step blocked with only what it
    must come after in place refuses the rig at once; :func:`must_precede` finds, pair by pair, the
    steps that must go in before others (one put in first would block the other), and a loop among
    them refuses the rig (found at the first set that leads nowhere: a search that never turns back
    does without them); the search puts a step in only after every step it must come after, and
    gives up a set when a step left would be blocked by that set with what it must come after added.
    Sets that lead nowhere are remembered."""
    _refuse_cycles(assembly)
    _refuse_blocked_at_first(assembly)
    # what each step needs, until the first set that leads nowhere: the pairs cost solids a search that
    # never turns back does not need (most rigs that pass), so they are found only when it turns back
    must = {name: frozenset(v) for name, v in _before(assembly).items()}
    bounded = False
    dead: set[frozenset[str]] = set()
    total = len(assembly.steps)

    def hopeless(done: frozenset[str]) -> bool:
        """A step left is blocked with ``done`` and what it must come after in place."""
        return any(assembly.blocked(step, done | must[step.name]) for step in assembly.steps
                   if step.name not in done)

    def search(done: frozenset[str], path: list[Placed]) -> list[Placed] | None:
        if len(path) == total:
            return path
        if done in dead:
            return None
        if not hopeless(done):
            for step in assembly.steps:
                if step.name in done or not must[step.name] <= done:
                    continue
                r = assembly.place(step, done)
                if r is not None:
                    found = search(done | {step.name}, [*path, r])
                    if found is not None:
                        return found
        dead.add(done)
        if len(dead) >= TIGHTEN_AFTER:
            tighten()
        return None

    def tighten() -> None:
        nonlocal bounded
        if not bounded:
            bounded = True
            pairs, no_order = _precedences(assembly)
            if no_order is not None:
                raise no_order
            must.update(pairs)

    order = search(frozenset(), [])
    if order is None:
        raise _stuck(assembly)
    return order


def must_precede(assembly: Assembly) -> dict[str, frozenset[str]] | None:
    """For each step, the steps that must be in place before it in every feasible order: what it
    needs (transitively), and each step ``t`` such that ``s`` put in after ``t`` (with all that must
    precede either) would be blocked, so ``s`` must come before ``t``; repeated until nothing is
    added. None when no order exists: steps would have to precede each other, or a step is blocked
    with only what must precede it in place (:func:`_precedences` says which and why)."""
    must, no_order = _precedences(assembly)
    return None if no_order is not None else must


def _precedences(assembly: Assembly) -> tuple[dict[str, frozenset[str]], AssemblyError | None]:
    """:func:`must_precede`'s precedences, and when they admit no order the AssemblyError naming the
    real blocker: the two steps that would each have to go in before the other, what blocks each
    (the part or the fastener that collides) and the chain of precedences that closes the loop; or
    the step blocked by what must precede it, and why each of those must."""
    before = _before(assembly)
    names = [s.name for s in assembly.steps]
    must = {n: set(before[n]) for n in names}
    #: why a must precede b: ("needs",) or ("blocked", s, t): s after t (with what precedes either) is blocked
    cause: dict[tuple[str, str], tuple] = {(a, b): ("needs",) for b in names for a in before[b]}
    changed = True
    while changed:
        changed = False
        for s in names:
            for t in names:
                if t == s or t in must[s] or s in must[t]:
                    continue
                if not assembly.blocked(assembly.by_name[s], frozenset(must[s] | must[t] | {t})):
                    continue
                # s must precede t, and so must everything that must precede s; and all after t
                with_t = frozenset(must[s] | must[t] | {t})
                ahead = must[s] | {s}
                grown = [u for u in names if (u == t or t in must[u]) and not ahead <= must[u]]
                for u in grown:
                    for a in ahead - must[u]:
                        cause.setdefault((a, u), ("blocked", s, t, with_t))
                    must[u] |= ahead
                    if u in must[u]:
                        return {}, _loop_error(assembly, s, t, u, with_t, cause)
                    if assembly.blocked(assembly.by_name[u], frozenset(must[u])):
                        return {}, _blocked_error(assembly, u, must, cause)
                changed = True
    return {n: frozenset(v) for n, v in must.items()}, None


def _why(assembly: Assembly, a: str, b: str, cause: dict) -> str:
    """Why step ``a`` must go in before step ``b`` (a clause)."""
    c = cause.get((a, b), ("needs",))
    if c[0] == "needs":
        return f"{b} needs {a} in place first"
    _, s, t, done = c
    r = assembly.attempt(assembly.by_name[s], done)
    into = ", ".join(getattr(r, "obstacles", ())) or t
    if (s, t) == (a, b):
        return f"{a} must go in before {b}: put in after it, {a} runs into {into} ({r})"
    return f"{a} must go in before {b} (as {s} must before {t}: put in after it, {s} runs into {into})"


def _loop_error(assembly: Assembly, s: str, t: str, u: str, with_t: frozenset, cause: dict) -> AssemblyError:
    """The loop found by :func:`_precedences`: ``s`` must precede ``t`` (blocked after it, with
    ``with_t`` in place), while ``t`` precedes ``u`` and ``u`` precedes ``s``: no order puts both in."""
    r = assembly.attempt(assembly.by_name[s], with_t)
    into = tuple(getattr(r, "obstacles", ())) or (t,)
    back = [(t, u), (u, s)] if u != t else [(t, s)]
    chain = "; ".join(_why(assembly, a, b, cause) for a, b in back if a != b)
    summary = (f"{s} must go in before {t} (put in after it, {s} runs into {', '.join(into)}), yet {t} must go in "
               f"before {s}" + (f" (through {u})" if u not in (s, t) else ""))
    return AssemblyError(f"no feasible assembly order: {summary}: {s} after {t}: {r}; {chain}", step=s,
                         members=assembly.by_name[s].members, obstacles=into, summary=summary)


def _blocked_error(assembly: Assembly, u: str, must: dict, cause: dict) -> AssemblyError:
    """Step ``u`` is blocked by what must precede it (:func:`_precedences`)."""
    r = assembly.attempt(assembly.by_name[u], frozenset(must[u]))
    owner = {m: st.name for st in assembly.steps for m in st.members}
    into = tuple(getattr(r, "obstacles", ()))
    chain = "; ".join(_why(assembly, owner.get(o, o), u, cause) for o in into if owner.get(o, o) in must[u])
    summary = f"{u} runs into {', '.join(into) or 'what is in place'}, which must go in before it"
    return AssemblyError(f"no feasible assembly order: {summary}: {r}" + (f"; {chain}" if chain else ""), step=u,
                         members=assembly.by_name[u].members, obstacles=into, summary=summary)


def _refuse_cycles(assembly: Assembly) -> None:
    """GeometryError when steps need each other (a cycle in what each needs in place): no order can
    satisfy them, and the search would try every order of the rest before saying so."""
    owner = {m: s.name for s in assembly.steps for m in s.members}
    after = {s.name: {owner[n] for n in (*s.needs, *(p for f in s.fasteners for p in f.passes))
                      if n in owner and owner[n] != s.name} for s in assembly.steps}
    state: dict[str, int] = {}

    def visit(name: str, trail: list[str]) -> None:
        state[name] = 1
        for nxt in sorted(after[name]):
            if state.get(nxt) == 1:
                loop = trail[trail.index(nxt):] + [nxt] if nxt in trail else [name, nxt]
                ring = loop[:-1]
                summary = (f"{' and '.join(ring)} each need the other in place first (each rests on the other or is "
                           "fastened through it)" if len(ring) == 2 else
                           f"{', '.join(ring)} each need the next in place first, in a loop")
                raise AssemblyError("no feasible assembly order: the steps need each other in a loop: "
                                    + " needs ".join(loop), step=loop[0],
                                    members=assembly.by_name[loop[0]].members, obstacles=tuple(loop[1:-1]),
                                    summary=summary)
            if nxt not in state:
                visit(nxt, [*trail, nxt])
        state[name] = 2

    for s in assembly.steps:
        if s.name not in state:
            visit(s.name, [s.name])


def _before(assembly: Assembly) -> dict[str, frozenset[str]]:
    """The steps each step must come after in any order: what it needs, transitively."""
    owner = {m: s.name for s in assembly.steps for m in s.members}
    direct = {s.name: {owner[n] for n in (*s.needs, *(p for f in s.fasteners for p in f.passes))
                       if n in owner and owner[n] != s.name} for s in assembly.steps}
    out: dict[str, frozenset[str]] = {}

    def close(name: str) -> frozenset[str]:
        if name not in out:
            out[name] = frozenset(direct[name]).union(*(close(n) for n in direct[name]))
        return out[name]

    for s in assembly.steps:
        close(s.name)
    return out


def _refuse_blocked_at_first(assembly: Assembly) -> None:
    """GeometryError when a step is blocked with only what it must come after in place: parts only
    ever add obstacles, so it is blocked in every order (the exact answer, found without a search)."""
    for step in assembly.steps:
        r = assembly.attempt(step, _before(assembly)[step.name])
        if isinstance(r, Refusal) and r.blocked:
            raise AssemblyError(f"no feasible assembly order: {step.name} cannot go in even with only what it "
                                f"needs in place: {r}", step=step.name, members=step.members, obstacles=r.obstacles)


def _stuck(assembly: Assembly) -> AssemblyError:
    """Why no order exists: the precedences' loop or blocked step when they admit no order
    (:func:`_precedences`: the parts that collide, named exactly); else the longest feasible prefix
    the declared order first allows, each step put in only after the steps that must precede it,
    and why each step left fails: the error naming the first step left that is blocked (else the
    first left) and what it runs into."""
    must, no_order = _precedences(assembly)
    if no_order is not None:
        return no_order
    done: frozenset[str] = frozenset()
    progress = True
    while progress:
        progress = False
        for step in assembly.steps:
            if step.name not in done and must[step.name] <= done and isinstance(assembly.attempt(step, done), Placed):
                done, progress = done | {step.name}, True
                break
    left = [(s, assembly.attempt(s, done)) for s in assembly.steps if s.name not in done]
    first = next(((s, r) for s, r in left if r.blocked), left[0])
    return AssemblyError("no feasible assembly order: " + "; ".join(f"{s.name}: {r}" for s, r in left),
                         step=first[0].name, members=first[0].members, obstacles=first[1].obstacles)


__all__ = ["Assembly", "CLEARANCE_MM", "Fastener", "Placed", "Refusal", "SWEEP_STEP_MM", "Step", "Tool", "check_order",
           "cylinder", "find_order", "is_convex", "manifold", "must_precede", "penetration", "swept"]
