"""Standard hardware: the one home of every figure rigcad takes from a standard or a maker's table.

Threads, clearance holes, socket-head screws, hex nuts, washers, preferred lengths, hex keys,
heat-set inserts, dowel pins and balls, cup-point set screws, gauge blocks, spring steel, ISO 286 fits
and reaming allowances. Each table names the standard (or the maker's datasheet)
its figures come from; nothing else in rigcad states these numbers (tests/test_standards.py greps
the tree for them). The parts cut their holes from these figures, the bill orders by them and the
assembly steps fit them, so the solid, the bill and the steps cannot disagree.

Units: millimetres throughout. No imports from the rest of rigcad: a leaf every floor may use.
"""

from __future__ import annotations

from dataclasses import dataclass

INCH = 25.4  #: mm per inch (exact, by definition since 1959)


@dataclass(frozen=True)
class Thread:
    """One screw thread and the hardware rigcad uses with it (mm).

    ``major``: nominal (major) diameter; ``pitch``: coarse pitch (ISO 261; UNC: 1 in / threads per
    inch, ASME B1.1); ``clearance_fine``, ``clearance_medium``: through-hole series (ISO 273 fine and
    medium; UNC: ASME B18.2.8 close and normal fit); ``head_diameter``, ``head_height``: the socket
    head cap screw's head (ISO 4762 dk max, k max; UNC: ASME B18.3); ``hex_key``: its socket across
    flats (ISO 4762 s; ASME B18.3); ``nut_af``, ``nut_height``: the hex nut's width across flats and
    height (ISO 4032 s, m max; UNC: ASME B18.2.2 hex nut); ``washer_od``, ``washer_thickness``: the
    plain washer (ISO 7089 d2, h; UNC: ASME B18.22.1 type A narrow)."""

    name: str
    major: float
    pitch: float
    clearance_fine: float
    clearance_medium: float
    head_diameter: float
    head_height: float
    hex_key: float
    nut_af: float
    nut_height: float
    washer_od: float
    washer_thickness: float

    @property
    def clearance(self) -> float:
        """The clearance hole rigcad cuts for a bolt through a part: the medium (normal) series."""
        return self.clearance_medium

    @property
    def nut_corner_radius(self) -> float:
        """A hex nut's centre-to-corner distance (mm): the across-flats width over sqrt 3."""
        return self.nut_af / 3.0 ** 0.5


# name, major, pitch, clearance fine, medium, head dk, k, hex key s, nut s, m, washer d2, h
_METRIC = (
    ("M2", 2.0, 0.4, 2.2, 2.4, 3.8, 2.0, 1.5, 4.0, 1.6, 5.0, 0.3),
    ("M2.5", 2.5, 0.45, 2.7, 2.9, 4.5, 2.5, 2.0, 5.0, 2.0, 6.0, 0.5),
    ("M3", 3.0, 0.5, 3.2, 3.4, 5.5, 3.0, 2.5, 5.5, 2.4, 7.0, 0.5),
    ("M4", 4.0, 0.7, 4.3, 4.5, 7.0, 4.0, 3.0, 7.0, 3.2, 9.0, 0.8),
    ("M5", 5.0, 0.8, 5.3, 5.5, 8.5, 5.0, 4.0, 8.0, 4.7, 10.0, 1.0),
    ("M6", 6.0, 1.0, 6.4, 6.6, 10.0, 6.0, 5.0, 10.0, 5.2, 12.0, 1.6),
    ("M8", 8.0, 1.25, 8.4, 9.0, 13.0, 8.0, 6.0, 13.0, 6.8, 16.0, 1.6),
    ("M10", 10.0, 1.5, 10.5, 11.0, 16.0, 10.0, 8.0, 16.0, 8.4, 20.0, 2.0),
    ("M12", 12.0, 1.75, 13.0, 13.5, 18.0, 12.0, 10.0, 18.0, 10.8, 24.0, 2.5),
)
# Unified coarse threads of camera and projector sockets (ISO 1222 names 1/4-20 and 3/8-16 UNC), in
# inches as their standards give them: major, threads per inch, close and normal clearance
# (ASME B18.2.8), head A and H (ASME B18.3), key, nut F and H (ASME B18.2.2), washer OD and thickness
# (ASME B18.22.1, type A narrow).
_UNC = (
    ("1/4-20 UNC", 0.25, 20, 0.266, 0.281, 0.375, 0.25, 3 / 16, 7 / 16, 7 / 32, 0.625, 0.065),
    ("3/8-16 UNC", 0.375, 16, 0.397, 0.406, 0.5625, 0.375, 5 / 16, 9 / 16, 21 / 64, 0.812, 0.065),
)

#: Every thread rigcad knows, by name.
THREADS: dict[str, Thread] = {
    **{r[0]: Thread(*r) for r in _METRIC},
    **{r[0]: Thread(r[0], r[1] * INCH, INCH / r[2], *(v * INCH for v in r[3:])) for r in _UNC},
}
#: The threads an instrument's mounting holes or an adjuster's screws may have (the profile's choices).
MOUNT_THREADS = ("M3", "M4", "M5", "M6", "1/4-20 UNC", "3/8-16 UNC")
#: Metric threads from the smallest up, for choosing a bolt by the hole it passes through.
METRIC_THREADS = tuple(r[0] for r in _METRIC)


def thread(name: str) -> Thread:
    """The thread named ``name`` (e.g. "M4", "1/4-20 UNC"); KeyError names the valid ones."""
    try:
        return THREADS[name]
    except KeyError:
        raise KeyError(f"unknown thread {name!r}; valid: {', '.join(THREADS)}") from None


def thread_for_hole(hole: float) -> Thread:
    """The largest ISO metric thread whose medium clearance hole (ISO 273) fits in ``hole`` mm;
    ValueError when even M2's does not."""
    fits = [THREADS[n] for n in METRIC_THREADS if THREADS[n].clearance_medium <= hole + 1e-9]
    if not fits:
        raise ValueError(f"a {hole:g} mm hole takes no ISO metric bolt from M2 "
                         f"({THREADS['M2'].clearance_medium:g} mm clearance, ISO 273 medium) up")
    return fits[-1]


#: ISO 4762 (and ISO 4017) preferred nominal lengths (mm) of socket-head and hex bolts.
SCREW_LENGTHS = (5, 6, 8, 10, 12, 16, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 80, 90, 100, 110, 120, 130,
                 140, 150, 160, 180, 200)
#: ISO 4762's range of nominal lengths (mm) per thread, as sold: (shortest, longest).
SCREW_LENGTH_RANGE = {"M2": (3, 20), "M2.5": (4, 25), "M3": (5, 30), "M4": (6, 40), "M5": (8, 50), "M6": (10, 60),
                      "M8": (12, 80), "M10": (16, 100), "M12": (20, 120)}


def screw_lengths(name: str | None = None) -> tuple[int, ...]:
    """The preferred lengths (mm) ISO 4762 sells for thread ``name`` (every preferred length when
    None or an inch thread, whose lengths run in the same steps)."""
    lo, hi = SCREW_LENGTH_RANGE.get(name, (SCREW_LENGTHS[0], SCREW_LENGTHS[-1])) if name else (0, 10 ** 9)
    return tuple(n for n in SCREW_LENGTHS if lo <= n <= hi)


def shortest_screw(name: str | None, need: float) -> int | None:
    """The shortest preferred length (mm) of at least ``need`` mm, or None past the longest."""
    return next((n for n in screw_lengths(name) if n >= need - 1e-9), None)


def longest_screw(name: str | None, reach: float) -> int | None:
    """The longest preferred length (mm) of at most ``reach`` mm, or None under the shortest."""
    fits = [n for n in screw_lengths(name) if n <= reach + 1e-9]
    return fits[-1] if fits else None


#: ASME B18.3 inch socket-head cap screws' nominal lengths (in) as ordered, in 1/8 in steps and then 1/4 in.
INCH_SCREW_LENGTHS = ((0.5, "1/2 in"), (0.625, "5/8 in"), (0.75, "3/4 in"), (0.875, "7/8 in"), (1.0, "1 in"),
                      (1.25, "1 1/4 in"), (1.5, "1 1/2 in"), (1.75, "1 3/4 in"), (2.0, "2 in"))
#: ISO 7093-1 large washers (outer diameter, thickness; mm) per thread; the size-6 washer (6.4 mm bore)
#: also takes a 1/4 in screw.
LARGE_WASHERS = {"M3": (9.0, 0.8), "M4": (12.0, 1.0), "M5": (15.0, 1.2), "M6": (18.0, 1.6), "1/4-20 UNC": (18.0, 1.6)}
#: ISO 7093-1 large washers by size, with their bores: bore d1, outside diameter d2, thickness h (mm; the
#: standard's nominal figures), for the stacks that bridge a slot (rigcad.parts.washers).
ISO_7093 = {"M3": (3.2, 9.0, 0.8), "M4": (4.3, 12.0, 1.0), "M5": (5.3, 15.0, 1.2), "M6": (6.4, 18.0, 1.6),
            "M8": (8.4, 24.0, 2.0), "M10": (10.5, 30.0, 2.5), "M12": (13.0, 37.0, 3.0)}
#: ISO 7089 plain washers' bores (mm): ISO 273's fine clearance.
ISO_7089_BORE = {"M2": 2.2, "M2.5": 2.7, "M3": 3.2, "M4": 4.3, "M5": 5.3, "M6": 6.4, "M8": 8.4, "M10": 10.5,
                 "M12": 13.0}
#: A camera's mounting socket's thread depth (mm) by its thread, when no figure is at hand: M3 from the
#: FLIR Blackfly S's "M3x2.5" holes (profiles/instruments, its cited source); the others assumed (a
#: tripod socket 1/4-20 or 3/8-16: 5 mm; a metric hole: one diameter). Measure yours.
CAMERA_SOCKET_DEPTH = {"1/4-20 UNC": 5.0, "3/8-16 UNC": 5.0, "M3": 2.5, "M4": 4.0, "M5": 5.0, "M6": 6.0}
#: DIN 6796 conical spring washers by thread: bore d1, outside d2, thickness s, free height h max (mm;
#: DIN 6796:1987-10 Table 1, as Aspen Fasteners' "Metric DIN 6796 spec" prints it). Under a preload far
#: below its flattening force the washer stands near its free height: a bolt's grip counts h max.
CONICAL_SPRING_WASHERS = {"M3": (3.2, 7.0, 0.6, 0.85), "M4": (4.3, 9.0, 1.0, 1.3), "M5": (5.3, 11.0, 1.2, 1.55),
                          "M6": (6.4, 14.0, 1.5, 2.0), "M8": (8.4, 18.0, 2.0, 2.6)}

@dataclass(frozen=True)
class Limiter:
    """A compression limiter for a bolt through a printed part: a plain steel spacer sleeve (mm) cut
    from cold-drawn precision tube of ``outer`` x ``wall``, faced to length on a lathe; ``source``:
    where its size comes from. Its bore passes the bolt at ISO 273's fine clearance or more, and is
    smaller than the thread's heat-set insert (rigcad.standards.INSERTS), so that the sleeve's end
    bears on the insert's brass top, not on plastic: the bolt's preload runs head, washer, sleeve,
    insert, thread, a loop of metal that the plastic's creep cannot relax."""

    thread: str
    outer: float
    wall: float
    source: str

    @property
    def bore(self) -> float:
        return self.outer - 2 * self.wall

    def name(self) -> str:
        return f"{self.thread} compression limiter: steel sleeve {self.outer:g} x {self.wall:g} mm ({self.bore:g} mm bore)"


_LIMITER_SOURCE = ("EN 10305-1 cold-drawn seamless precision steel tube, E235+C (outside x wall as stocked; outside "
                   "diameter +-0.08 mm)")
#: Compression limiters by thread: steel sleeves of standard precision tube (outside x wall, mm).
COMPRESSION_LIMITERS = {
    "M3": Limiter("M3", 5.0, 0.8, _LIMITER_SOURCE),
    "M4": Limiter("M4", 6.0, 0.8, _LIMITER_SOURCE),
    "M5": Limiter("M5", 8.0, 1.0, _LIMITER_SOURCE),
    "M6": Limiter("M6", 10.0, 1.5, _LIMITER_SOURCE),
}


#: ISO 8734 dowel pins' preferred lengths (mm).
DOWEL_LENGTHS = (3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32, 35, 40, 45, 50, 55, 60)


def longest_dowel(depth: float) -> int:
    """The longest ISO 8734 dowel (mm) no longer than the two holes' joint ``depth`` mm: a longer pin
    would hold the faces apart. ValueError under the shortest."""
    fits = [n for n in DOWEL_LENGTHS if n <= depth + 1e-9]
    if not fits:
        raise ValueError(f"no ISO 8734 dowel pin is as short as {depth:g} mm (shortest {DOWEL_LENGTHS[0]} mm)")
    return fits[-1]


@dataclass(frozen=True)
class Insert:
    """A heat-set threaded insert for printed parts (mm): the hole its maker says to print or drill
    (``hole``), its knurled outside (``outer``) and its length; ``source``: the maker's table."""

    thread: str
    hole: float
    outer: float
    length: float
    source: str

    @property
    def pocket_depth(self) -> float:
        """The blind pocket's depth: the insert's length and 0.5 mm for the melt to flow into."""
        return self.length + 0.5


_INSERT_SOURCE = "ruthex RX-series datasheet (hole for printed parts; outer diameter of the knurl)"
#: Heat-set inserts by thread: the makers' hole sizes, never the insert's outside (drilling to that
#: leaves nothing for the knurl to grip).
INSERTS = {
    "M3": Insert("M3", 4.0, 4.6, 5.7, _INSERT_SOURCE),
    "M4": Insert("M4", 5.6, 6.3, 8.1, _INSERT_SOURCE),
    "M5": Insert("M5", 6.4, 7.0, 9.5, _INSERT_SOURCE),
    "M6": Insert("M6", 8.0, 8.7, 12.7, _INSERT_SOURCE),
}


#: ISO 8734 dowel pins' diameters (mm), m6.
DOWEL_DIAMETERS = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0)


def dowel_diameter_for(at_most: float) -> float:
    """The largest ISO 8734 dowel diameter (mm) no larger than ``at_most`` mm; ValueError under 1 mm."""
    fits = [d for d in DOWEL_DIAMETERS if d <= at_most + 1e-9]
    if not fits:
        raise ValueError(f"no ISO 8734 dowel pin is as thin as {at_most:g} mm (thinnest {DOWEL_DIAMETERS[0]:g} mm)")
    return fits[-1]


#: ISO 286-2 limit deviations (micrometres) of the hole and shaft tolerance classes rigcad's fits use,
#: by nominal size range (over, up to] in mm: class -> ((over, up_to, lower, upper), ...). H, F, G
#: and N holes and m, g and f shafts for sizes to 50 mm (ISO 286-2:2010, tables of the holes' and
#: shafts' limit deviations; ISO 8734 dowel pins are made to m6).
ISO_286 = {
    "H7": ((1, 3, 0, 10), (3, 6, 0, 12), (6, 10, 0, 15), (10, 18, 0, 18), (18, 30, 0, 21), (30, 50, 0, 25)),
    "F7": ((1, 3, 6, 16), (3, 6, 10, 22), (6, 10, 13, 28), (10, 18, 16, 34), (18, 30, 20, 41), (30, 50, 25, 50)),
    "N7": ((1, 3, -14, -4), (3, 6, -16, -4), (6, 10, -19, -4), (10, 18, -23, -5), (18, 30, -28, -7),
           (30, 50, -33, -8)),
    "m6": ((1, 3, 2, 8), (3, 6, 4, 12), (6, 10, 6, 15), (10, 18, 7, 18), (18, 30, 8, 21), (30, 50, 9, 25)),
    "g6": ((1, 3, -8, -2), (3, 6, -12, -4), (6, 10, -14, -5), (10, 18, -17, -6), (18, 30, -20, -7),
           (30, 50, -25, -9)),
    "f7": ((1, 3, -16, -6), (3, 6, -22, -10), (6, 10, -28, -13), (10, 18, -34, -16), (18, 30, -41, -20),
           (30, 50, -50, -25)),
}


def tolerance_zone(size: float, cls: str) -> tuple[float, float]:
    """The ISO 286-2 zone of class ``cls`` (e.g. "H7", "m6") at nominal ``size`` mm: (lower, upper)
    deviations in mm. ValueError for a class or size the table does not hold."""
    try:
        rows = ISO_286[cls]
    except KeyError:
        raise ValueError(f"no ISO 286 class {cls!r} in rigcad's table; valid: {', '.join(ISO_286)}") from None
    for lo, hi, low, up in rows:
        if lo < size <= hi:
            return low / 1000.0, up / 1000.0
    raise ValueError(f"{size:g} mm is outside rigcad's ISO 286 table ({rows[0][0]} to {rows[-1][1]} mm)")


@dataclass(frozen=True)
class Fit:
    """An ISO 286 fit of a ``shaft`` class in a ``hole`` class at nominal ``size`` mm (a pin or a
    plug in its hole): ``kind`` as a machinist names it ("press", "slip", "sliding")."""

    size: float
    hole: str
    shaft: str
    kind: str

    @property
    def clearance(self) -> tuple[float, float]:
        """(least, most) diametral clearance (mm; negative: interference) over the two zones."""
        h_lo, h_hi = tolerance_zone(self.size, self.hole)
        s_lo, s_hi = tolerance_zone(self.size, self.shaft)
        return h_lo - s_hi, h_hi - s_lo

    @property
    def name(self) -> str:
        """e.g. "4 N7/m6"."""
        return f"{self.size:g} {self.hole}/{self.shaft}"

    def describe(self) -> str:
        """e.g. "4 N7/m6 (press: interference 0.008-0.028 mm)" from the zones."""
        lo, hi = self.clearance
        span = (f"interference {-hi:.3f}-{-lo:.3f} mm" if hi <= 0 else f"clearance {lo:.3f}-{hi:.3f} mm" if lo >= 0
                else f"clearance {lo:+.3f} to {hi:+.3f} mm")
        return f"{self.name} ({self.kind}: {span})"


#: The fits of an ISO 8734 (m6) dowel pin: pressed into the part that keeps it, in a hole reamed N7
#: (interference over the whole zones: the pin never works loose, nor needs glue); sliding in the part
#: that lifts off it, in a hole reamed F7 (clearance but for the zones' worst pair, 0.002 mm tight on
#: 3-6 mm, which a printed hole's wall takes up elastically).
DOWEL_PRESS_HOLE, DOWEL_SLIP_HOLE, DOWEL_SHAFT = "N7", "F7", "m6"
#: Reaming allowance (mm, on the diameter) left for a reamer by the drill before it, by the hole's
#: size (over, up to]: the larger figure of the makers' ranges (Guehring and Hoffmann Garant's
#: reaming guides, as tabulated in Tabellenbuch Metall, Europa-Lehrmittel: to 5 mm 0.1-0.2, 5-20 mm
#: 0.2-0.3, 20-32 mm 0.3, 32-50 mm 0.5).
REAMING_ALLOWANCE = ((0, 5, 0.2), (5, 20, 0.3), (20, 32, 0.3), (32, 50, 0.5))


def reaming_allowance(size: float) -> float:
    """The diametral stock (mm) a reamer of ``size`` mm wants from the drill before it; ValueError past 50 mm."""
    for lo, hi, a in REAMING_ALLOWANCE:
        if lo < size <= hi:
            return a
    raise ValueError(f"no reaming allowance for a {size:g} mm hole (rigcad's table: to 50 mm)")


def pre_ream_drill(size: float) -> float:
    """The twist drill (mm, DIN 338, sold in 0.1 mm steps) before a ``size`` mm reamer: the size less
    its reaming allowance, rounded down to the 0.1 mm step."""
    return int(round((size - reaming_allowance(size)) * 10, 9)) / 10.0


#: The reamer that sizes a dowel's blind hole, turned in a drill press at low speed: a machine (chucking)
#: reamer, whose lead is a short 45 deg chamfer. A hand reamer (DIN 206) starts on a long taper, several
#: millimetres of under-size flutes, and cannot bring a blind hole a few millimetres deep to size.
MACHINE_REAMER, MACHINE_REAMER_SPEC = "machine (chucking) reamer", "DIN 212, HSS, straight shank, 45 deg chamfer lead"
#: The machine reamer's lead along its axis (mm): the under-size zone it leaves at a blind hole's floor,
#: so a blind hole is at least the pin's engagement and this deep. ASSUMED, not sourced: DIN 212 machine
#: reamers are sold with a 45 deg chamfer lead, but no maker's table of the chamfer's length (nor the
#: standard's) was at hand; a hand reamer's (DIN 206) long taper lead is not this figure. What bounds it:
#: a 45 deg chamfer is as long along the axis as it is deep, it must be at least half the reaming
#: allowance deep to start in the drilled hole (0.1 mm at 4 mm: REAMING_ALLOWANCE), and it cannot be
#: deeper than the reamer's radius; 1.0 mm, a quarter of a 4 mm reamer's diameter, is taken as a
#: generous figure for the 3-6 mm sizes. The manual's step says to measure the bought reamer's chamfer
#: against it (a longer one needs deeper holes; rigcad.parts.locating.check_blind_hole refuses a hole
#: shorter than the pin's engagement plus this).
REAMER_LEAD_MM = 1.0
#: The gauge pins that check a reamed hole (DIN 2269 cylindrical measuring pins, 0.1-20 mm, sold in
#: 0.001 mm steps): the go pin at the hole class's lower limit enters, the no-go pin at its upper limit does
#: not. DIN 2269:1998-11 has tolerance classes 0, 1, 2 and the calibration class K (its foreword, read);
#: class 1 is the shop's class (0 and K are for gauge rooms).
GAUGE_PIN, GAUGE_PIN_SPEC = "cylindrical gauge pin", "DIN 2269, class 1"
#: A class 1 gauge pin's diameter limits (mm, +-): a typical gauge-pin maker's catalogue figure for DIN 2269
#: class 1 up to 20 mm, not read from the standard's own table here. It must stay small against the
#: zone the pins bracket: at most a tenth of every ISO 286 zone a register's holes are reamed to (the
#: gauge makers' rule of thumb; tests/parts/test_reaming.py checks it for the dowel sizes).
GAUGE_PIN_TOLERANCE_MM = 0.001


def gauge_pins(size: float, hole: str) -> tuple[float, float]:
    """The go and no-go gauge pins (mm, to 0.001 mm) of a ``size`` mm hole of ISO 286 class ``hole``: its
    zone's lower and upper limits (:func:`tolerance_zone`)."""
    lo, hi = tolerance_zone(size, hole)
    return round(size + lo, 3), round(size + hi, 3)


#: Cup-point socket set screws: the cup's diameter (mm, dp max): ISO 4029 for metric threads, ASME
#: B18.3 (C max, in inches as printed) for the unified ones. A ball larger than the cup sits on its rim.
CUP_POINT = {"M3": 1.4, "M4": 2.0, "M5": 2.5, "M6": 3.0, "M8": 5.0,
             "1/4-20 UNC": 0.132 * INCH, "3/8-16 UNC": 0.212 * INCH}
#: ISO 4029's range of nominal lengths (mm) per thread, from SET_SCREW_LENGTHS.
SET_SCREW_LENGTHS = (3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 30)
SET_SCREW_LENGTH_RANGE = {"M3": (3, 16), "M4": (4, 20), "M5": (5, 25), "M6": (6, 30), "M8": (8, 30)}


def shortest_set_screw(name: str, need: float) -> int | None:
    """The shortest ISO 4029 set screw length (mm) of at least ``need`` mm for thread ``name``, or None
    past the longest (an inch thread: the same steps, which ASME B18.3 also stocks near enough)."""
    lo, hi = SET_SCREW_LENGTH_RANGE.get(name, (SET_SCREW_LENGTHS[0], SET_SCREW_LENGTHS[-1]))
    return next((n for n in SET_SCREW_LENGTHS if lo <= n <= hi and n >= need - 1e-9), None)


#: Precision shim foil (mm): stainless steel strip (EN 10088-2 1.4310, thickness tolerances EN 10140),
#: the thicknesses shim assortments are sold in. A pack of these under a stop sets a part in steps of
#: the thinnest; the packs are cut to size with scissors.
SHIM_FOIL = (0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5)


#: ISO 3650 gauge blocks of nominal length 0.5 to 10 mm: their measuring faces' size (mm): 30 x 9.
GAUGE_BLOCK_FACE = (30.0, 9.0)
#: Shear modulus (N/mm^2) of patented cold-drawn spring steel wire (EN 10270-1), as EN 13906-1 gives it
#: for the spring rate R = G d^4 / (8 D^3 n).
SPRING_STEEL_G = 81500.0


def spring_rate(wire: float, mean_diameter: float, active_coils: float) -> float:
    """A helical compression spring's rate (N/mm) by EN 13906-1: G d^4 / (8 D^3 n), d the wire and
    D the mean coil diameter (mm), n the active coils; G: SPRING_STEEL_G."""
    return SPRING_STEEL_G * wire ** 4 / (8.0 * mean_diameter ** 3 * active_coils)


@dataclass(frozen=True)
class HexKey:
    """An L hex key (ISO 2936) across flats ``size`` (mm): its long and short arms (mm)."""

    size: float
    long_arm: float
    short_arm: float

    @property
    def room(self) -> float:
        """The radius (mm) a key and the hand turning it need around its axis: its corners (across
        flats / sqrt 3) and half a millimetre of play."""
        return self.size / 3 ** 0.5 + 0.5


#: ISO 2936 hex keys, short series: across flats (mm) -> long arm, short arm (mm); inch keys by the
#: same table's nearest rows.
HEX_KEYS = {s: HexKey(s, lo, sh) for s, lo, sh in (
    (1.5, 45.0, 14.0), (2.0, 50.0, 16.0), (2.5, 56.0, 18.0), (3.0, 63.0, 20.0), (4.0, 70.0, 25.0),
    (3 / 16 * INCH, 80.0, 28.0), (5.0, 80.0, 28.0), (6.0, 90.0, 32.0), (5 / 16 * INCH, 100.0, 36.0),
    (8.0, 100.0, 36.0), (10.0, 112.0, 40.0))}
#: A hex screwdriver's blade (mm): a hand needs this much straight room above a socket head.
DRIVER_BLADE_MM = 100.0
#: An open-end spanner's reach (mm; DIN 3110 spanners for M3-M6 nuts are 90-120 mm long).
SPANNER_MM = 80.0

__all__ = ["GAUGE_PIN", "GAUGE_PIN_SPEC", "GAUGE_PIN_TOLERANCE_MM", "MACHINE_REAMER", "MACHINE_REAMER_SPEC", "REAMER_LEAD_MM", "gauge_pins", "DOWEL_PRESS_HOLE", "DOWEL_SHAFT", "DOWEL_SLIP_HOLE", "Fit", "ISO_286", "REAMING_ALLOWANCE", "pre_ream_drill", "reaming_allowance", "tolerance_zone", "CAMERA_SOCKET_DEPTH", "ISO_7089_BORE", "ISO_7093", "CUP_POINT", "SHIM_FOIL", "DOWEL_DIAMETERS", "GAUGE_BLOCK_FACE", "SET_SCREW_LENGTHS", "SET_SCREW_LENGTH_RANGE",
           "SPRING_STEEL_G", "dowel_diameter_for", "shortest_set_screw", "spring_rate", "INCH_SCREW_LENGTHS", "LARGE_WASHERS", "DOWEL_LENGTHS", "longest_dowel", "DRIVER_BLADE_MM", "HEX_KEYS", "HexKey", "INCH", "INSERTS",
           "Insert", "METRIC_THREADS", "MOUNT_THREADS", "SCREW_LENGTHS", "SCREW_LENGTH_RANGE", "SPANNER_MM", "THREADS",
           "Thread", "longest_screw", "screw_lengths", "shortest_screw", "thread", "thread_for_hole"]

#: Hex socket set screws (ISO 4026 flat point, ISO 4029 cup point): the hex key (mm, ISO 2936, s nominal)
#: their socket takes.
SET_SCREW_KEY = {"M3": 1.5, "M4": 2.0, "M5": 2.5, "M6": 3.0, "M8": 4.0}
__all__ += ["SET_SCREW_KEY", "COMPRESSION_LIMITERS", "Limiter"]
