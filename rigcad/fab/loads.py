"""Loads on the printed rig: bolt torques into plastic, and the sag and first mode of the beam, the
shelf and the column under the instruments' weights, each against the tolerance it eats
(kernel-free; SI inside each formula as stated: N, mm, MPa = N/mm2, kg, Hz).

Closed forms, each from a textbook:

* a bolt's preload from its torque, T = K F d (the short-form torque equation, with the nut factor
  K = 0.2 for plain steel fasteners: Shigley's Mechanical Engineering Design, 9th ed., section 8-8,
  eq. 8-27 and Table 8-15); the pressure under a washer, a nut or a head is the preload over its
  bearing ring (outer circle or hexagon less the hole). The torque rigcad gives is the one that
  puts :data:`BEARING_SHARE` of the material's yield strength under the smaller bearing face;
* a simply supported beam with a central point load P and its own weight q per length: mid-span
  sag P L^3 / (48 E I) + 5 q L^4 / (384 E I) (Roark's Formulas for Stress and Strain, 7th ed.,
  Table 8.1, cases 1a and 2a); its first mode by Rayleigh's method with the beam's effective mass
  17/35 of its own (f = sqrt(k / m) / 2 pi, k = 48 E I / L^3; Blevins, Formulas for Natural
  Frequency and Mode Shape, Table 8-2 footnote);
* a cantilever with point loads P_i at a_i: deflection at x >= a_i, P a^2 (3 x - a) / (6 E I), and
  slope P a^2 / (2 E I) (Roark Table 8.1 case 1a, fixed-free); a uniform load q over length l:
  q l^4 / (8 E I) and q l^3 / (6 E I) at its end;
* the column: a cantilever under the shelf's moment M at its top, deflection M H^2 / (2 E I),
  rotation M H / (E I); its sway mode with a tip mass and 33/140 of its own mass (Blevins Table 8-2);
* the shelf's first mode by Rayleigh's quotient on its static deflection curve under its loads,
  omega^2 = g sum(m_i y_i) / sum(m_i y_i^2) (Blevins, Formulas for Natural Frequency and Mode Shape,
  eq. 4-24: the static deflection as the trial shape, an upper bound within a few per cent of the first
  mode of a cantilever), its own mass lumped in SHELF_LUMPS segments;
* the column's bolted foot and top under the shelf's overturning moment M: the flange a rigid plate
  turning about its compressed edge, the bolts' extra tension in proportion to their distance from it,
  F_i = M d_i / sum(d_j^2) (VDI 2230 Part 1's eccentric-load model taken rigid; Shigley section 8-12's
  bolt group), against the joint's preload (it stays closed while the preload exceeds it) and the
  pressure under the nut and the washer with the whole extra tension in the bolt;
* a lab's uniform temperature swing dT: every printed length grows by alpha dT; the projector's
  virtual COP then moves along the axis against the paraboloid's vertex by alpha dT times the COP's
  height above it (both stand on the same base plate), across by the difference of the base plate's
  and the shelf's growth between the bore and the seat (nothing, both printed; a bought aluminium shelf
  grows less). No gradient (the machinist judged a uniform +-3 C the lab's case).

A printed section is stiffer than its infill and weaker than solid: its second moment of area is
the solid one less (1 - infill) of its core, the core being the section less :data:`SKIN_MM`
of perimeters each side (:func:`printed_inertia`); the shelf, printed flat, less its perimeters and its
top and bottom solid layers as the printer's resolved slicer settings lay them (:func:`skin`,
:func:`printed_plate`). The modulus is taken at the low end of the
material's published range (the largest sag) and the strength as published.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad.errors import FabricationError
from rigcad.fab.printers import Printer
from rigcad.parts import breadboard
from rigcad.parts.dome import flange_joint, flange_washers
from rigcad.parts.tower import _lens_foot, _projector_feet, _shelf_extent, seat_points
from rigcad.standards import LARGE_WASHERS, THREADS

G = 9.80665  #: standard gravity (m/s2)
#: Short-form torque equation's nut factor for plain steel fasteners (Shigley, Table 8-15).
NUT_FACTOR = 0.2
#: A sustained bearing pressure on printed plastic kept to half its yield strength: a creep allowance
#: (assumed; thermoplastics creep under sustained stress well below their short-term yield).
BEARING_SHARE = 0.5
#: Perimeters each side of a printed section (mm): 3 perimeters of a 0.45 mm extrusion (the MK3S
#: file's 3 perimeters; PrusaSlicer's extrusion width for a 0.4 mm nozzle). Used as the skin all round
#: when a printer has no resolved slicer settings (:func:`skin`).
SKIN_MM = 1.35
#: Infill of a printed core (the MK3S file's 20 %), the same fallback.
INFILL = 0.20


@dataclass(frozen=True)
class Skin:
    """A printed section's solid skin (mm): ``side`` (its perimeters, each side), ``top`` and ``bottom`` (its
    solid layers), its core's ``infill`` (fraction) and where the figures were read (``source``)."""

    side: float
    top: float
    bottom: float
    infill: float
    source: str


def _width(value: str, nozzle: float, fallback: str | None = None) -> float:
    """A PrusaSlicer width or height (mm): rigcad.fab.printers.extrusion_width."""
    from rigcad.fab.printers import extrusion_width

    return extrusion_width(value, nozzle, fallback)


def skin(printer: Printer) -> Skin:
    """The solid skin a printer's resolved PrusaSlicer settings (presets and overrides) lay round a section:
    ``perimeters`` x ``perimeter_extrusion_width`` each side; on top ``top_solid_layers`` x ``layer_height`` or
    ``top_solid_min_thickness``, whichever is more; underneath the same with the first layer at
    ``first_layer_height``; ``fill_density``. A printer without them (no preset, or PrusaSlicer not
    installed) keeps SKIN_MM all round and INFILL, as assumed."""
    cfg = printer.slicer_config
    if cfg is None:
        return Skin(SKIN_MM, SKIN_MM, SKIN_MM, INFILL, "assumed (no resolved slicer settings)")
    e = cfg.effective()
    try:
        nozzle = float(str(e.get("nozzle_diameter", printer.nozzle or 0.4)).split(",")[0])
        layer = float(e.get("layer_height", printer.layer_height))
        first = _width(e.get("first_layer_height", layer), layer)  # a percentage of the layer height, or mm
        side = int(e["perimeters"]) * _width(e.get("perimeter_extrusion_width", "0"), nozzle, e.get("extrusion_width"))
        # (the same width as rigcad.fab.printers.perimeter_width, at the preset's own nozzle_diameter)
        top = max(int(e["top_solid_layers"]) * layer, float(e.get("top_solid_min_thickness", 0)))
        n_bottom = int(e["bottom_solid_layers"])
        bottom = max(first + max(n_bottom - 1, 0) * layer if n_bottom else 0.0,
                     float(e.get("bottom_solid_min_thickness", 0)))
        density = str(e.get("fill_density", "20%")).strip()
        infill = float(density[:-1]) / 100.0 if density.endswith("%") else float(density)
    except (KeyError, ValueError) as err:
        raise FabricationError(f"printer {printer.name}: its slicer settings give no solid skin ({err}): "
                               "perimeters, top_solid_layers, bottom_solid_layers and their widths and heights "
                               "must be numbers") from err
    return Skin(side, top, bottom, infill, f"{printer.name}'s resolved slicer settings")
#: A hand-tight screw with a hex key (N m): the torque a lab applies when no figure is given.
HAND_TIGHT_NM = 1.0
#: The printed splitter holder's mass with its plate and lens mount (kg; assumed). The instruments' masses
#: are profile keys, ``projector.mass`` and ``camera.mass`` (their schema defaults are the assumed 3 kg and
#: 0.3 kg: rigcad.profile.schema), read by :func:`_mass`.
ASSUMED_MASS_KG = {"holder": 0.2}
#: A tilt of the shelf under the splitter's seat turns the projector's reflected axis this many times
#: (the law of reflection; the projector's feet stand elsewhere on the shelf): it eats
#: ``tolerancing.projector_tilt`` twice. The column's turn tilts the whole tower: once.
SPLITTER_TURN = 2.0


@dataclass(frozen=True)
class Material:
    """A printed material's published figures: modulus range (MPa), yield strength (MPa; the weaker
    direction), linear thermal expansion (1/K) and where they come from."""

    name: str
    modulus_low: float
    modulus_high: float
    yield_strength: float
    source: str
    expansion: float = 0.0


#: Materials by the printer file's ``material`` (case-insensitive).
MATERIALS = {
    "pla": Material("PLA", 2539.0, 3039.0, 26.0, "Stratasys PLA data sheet (ASTM D638): tensile modulus 2,539 MPa XY, "
                    "3,039 MPa XZ; yield 26 MPa XY; thermal expansion (ASTM E831) 101e-6 /K flow, 102e-6 /K across",
                    102e-6),
    "abs": Material("ABS", 1443.0, 2482.0, 22.1, "Stratasys P400 ABS (FDM 2000 manual, App. M1): 360,000 psi, 5,000 "
                    "psi; printed ABS 1,443 MPa (Kimya, ISO 527); yield the low end of MatWeb's ABS (22.1 MPa); thermal "
                    "expansion the top of omnexus's ABS range (7-15e-5 /K)", 150e-6),
}


#: The bought shelf's plate (``buy.shelf: aluminium_plate``): EN AW-5083-H111, solid; modulus 71 GPa (both ends
#: of the range: a rolled plate), 0.2 % proof 125 MPa, expansion 24.2e-6 /K, density 2.66 g/cm3 (EN 485-2's
#: minimum proof; the others as aluminium suppliers' 5083 data sheets give them, e.g. Aalco's).
ALUMINIUM = Material("EN AW-5083", 71000.0, 71000.0, 125.0, "EN 485-2 (proof); suppliers' 5083 data sheets (modulus, "
                     "expansion)", 24.2e-6)
ALUMINIUM_DENSITY = 2.66e-6  #: kg/mm3
#: The shelf's mass lumped in this many equal segments for its Rayleigh quotient.
SHELF_LUMPS = 60
#: A lab's uniform temperature swing over a day (K, each way): the machinist's figure for a lab.
LAB_SWING_K = 3.0


def material(printer: Printer) -> Material:
    """The printer's material's figures; FabricationError naming the known ones otherwise."""
    m = MATERIALS.get(printer.material.strip().lower())
    if m is None:
        known = ", ".join(v.name for v in MATERIALS.values())
        where = printer.marks.get(("material",)) or printer.source
        raise FabricationError(f"printer {printer.name}: no published strength and stiffness for material "
                               f"{printer.material!r} in rigcad.fab.loads.MATERIALS (known: {known}), so no loads; "
                               f"state the printed material with the printer file's `material:` key (one of {known}; "
                               f"{where})")
    return m


def printed_inertia(width: float, height: float, skin: float = SKIN_MM, infill: float = INFILL) -> float:
    """Second moment of area (mm^4) of a printed ``width`` x ``height`` mm rectangle bending about
    its horizontal axis: the solid one less (1 - infill) of its core's (``skin`` mm all round)."""
    core_w, core_h = max(width - 2 * skin, 0.0), max(height - 2 * skin, 0.0)
    return (width * height ** 3 - (1 - infill) * core_w * core_h ** 3) / 12


def printed_plate(width: float, height: float, s: Skin) -> tuple[float, float]:
    """A ``width`` x ``height`` mm rectangle printed flat (its height along the print's z) with skin ``s``,
    bending about its horizontal axis: its second moment of area (mm^4) about its own neutral axis and the
    largest distance (mm) from that axis to a face. The core (``s.side`` in from each side, ``s.top`` under
    its top, ``s.bottom`` over its underside) has ``s.infill`` of the solid's stiffness; a thinner top than
    bottom moves the neutral axis down."""
    core_w = max(width - 2 * s.side, 0.0)
    core_h = max(height - s.top - s.bottom, 0.0)
    zc = s.bottom + core_h / 2  # the core's centre above the underside
    a_solid, a_void = width * height, (1 - s.infill) * core_w * core_h
    z = (a_solid * height / 2 - a_void * zc) / (a_solid - a_void)
    inertia = (width * height ** 3 / 12 + a_solid * (height / 2 - z) ** 2
               - (1 - s.infill) * (core_w * core_h ** 3 / 12 + core_w * core_h * (zc - z) ** 2))
    return inertia, max(z, height - z)


def printed_tube_inertia(side: float, wall: float, skin: float = SKIN_MM, infill: float = INFILL) -> float:
    """The same for a square tube of ``side`` and ``wall`` (mm): solid wall less the wall's core."""
    outer, inner = side ** 4, (side - 2 * wall) ** 4
    solid = (outer - inner) / 12
    if wall <= 2 * skin:
        return solid
    core_out, core_in = (side - 2 * skin) ** 4, (side - 2 * wall + 2 * skin) ** 4
    return solid - (1 - infill) * (core_out - core_in) / 12


# --------------------------------------------------------------------------------------- bolts

@dataclass(frozen=True)
class BoltLoad:
    """A bolted joint into printed plastic: ``count`` screws of ``thread``; ``bearing``: what bears
    on the plastic (washer, nut); ``area_mm2``: the smaller bearing ring; ``torque_nm`` and
    ``preload_n``: the torque rigcad gives and its preload; ``pressure_mpa`` under it against
    ``allowable_mpa``; ``hand_tight_mpa``: the pressure of a hand-tight HAND_TIGHT_NM; ``spring_washer``:
    whether creep would relax the joint (it locates a datum) so a conical spring washer goes under the head."""

    joint: str
    thread: str
    count: int
    bearing: str
    area_mm2: float
    torque_nm: float
    preload_n: float
    pressure_mpa: float
    allowable_mpa: float
    hand_tight_mpa: float
    spring_washer: bool

    def describe(self) -> dict:
        return {"joint": self.joint, "thread": self.thread, "count": self.count, "bearing": self.bearing,
                "bearing_area_mm2": self.area_mm2, "torque_nm": self.torque_nm, "preload_n": self.preload_n,
                "pressure_mpa": self.pressure_mpa, "allowable_mpa": self.allowable_mpa,
                "hand_tight_pressure_mpa": self.hand_tight_mpa, "spring_washer": self.spring_washer}


def washer_area(thread: str, hole: float, large: bool = False) -> float:
    """Bearing ring (mm2) of an ISO 7089 (or ISO 7093 large) washer on a printed ``hole`` mm."""
    od = LARGE_WASHERS[thread][0] if large else THREADS[thread].washer_od
    return math.pi / 4 * (od ** 2 - hole ** 2)


def nut_area(thread: str, hole: float) -> float:
    """Bearing face (mm2) of an ISO 4032 hex nut on a printed ``hole`` mm: the hexagon less the hole."""
    s = THREADS[thread].nut_af
    return math.sqrt(3) / 2 * s ** 2 - math.pi / 4 * hole ** 2


#: The torque table's rows for the instruments' own screws, by which the manual's lock steps find them
#: (rigcad.manual.calibration.instrument_torques).
PROJECTOR_JOINT, CAMERA_JOINT = "projector on the shelf's slots", "camera on its bracket's slot"


def bolt_load(joint: str, thread: str, count: int, faces: dict[str, float], mat: Material, datum: bool) -> BoltLoad:
    """The torque for ``count`` ``thread`` screws whose bearing faces on plastic are ``faces``
    (name -> area mm2): the smallest face at BEARING_SHARE of the yield."""
    bearing, area = min(faces.items(), key=lambda kv: kv[1])
    allow = BEARING_SHARE * mat.yield_strength
    preload = allow * area
    d = THREADS[thread].major
    torque = NUT_FACTOR * preload * d / 1000.0
    hand = HAND_TIGHT_NM * 1000.0 / (NUT_FACTOR * d) / area
    return BoltLoad(joint, thread, count, bearing, area, torque, preload, allow, allow, hand, datum)


def _faces(stack) -> dict[str, float]:
    """A washer stack (rigcad.parts.washers.WasherStack) as a bearing face: its name and real area."""
    w = stack.bearing
    kind = "large washer" if w.standard == "ISO 7093-1" else "washer"
    what = "slot" if stack.opening[0] == "slot" else "hole"
    return {f"{kind} ({w.standard} {w.size}, {w.outer:g} mm) over the {what}": stack.area_mm2}


def bolt_loads(profile, layout, printer: Printer) -> tuple[BoltLoad, ...]:
    """Every bolted joint into printed plastic with its torque: the dome's flange (into inserts),
    the column's foot (nuts in the tongue's traps) and top (into the shelf's inserts), the lens
    mount's foot, the breadboard's screws (on a breadboard), the projector's and the camera's screws
    through printed slots. Each bears on the area its washer really has: its annulus less the slot or
    the opened hole under it (rigcad.parts.washers; the tower's washers: rigcad.parts.tower.joint_washers).
    The splitter holder's two spring bolts are set by their springs' length, not a torque, and its seat
    screws are adjusters (rigcad.parts.adjusters)."""
    from rigcad.parts.tower import joint_washers

    mat, tw = material(printer), profile.tower
    fj = flange_joint(profile, layout)
    hole = tw.bolt_diameter
    # the flange's bolts run through compression limiters: their washer is the one that seats on the sleeve
    out = [bolt_load("dome flange on the base plate", fj.thread, fj.count, _faces(flange_washers(profile, layout)),
                     mat, True)]
    washers = joint_washers(profile, layout)
    if profile.buy.column == "print":
        # the foot's nuts bear on the bolts' compression limiters (rigcad.parts.tower.COLUMN_LIMITER), not on
        # the traps' roofs: the washer over the column's hole is the face on plastic
        column = _faces(washers["column"])
        out.append(bolt_load("column foot on the tongue", "M4", 4, column, mat, True))
        out.append(bolt_load("column top under the shelf", "M4", 4, column, mat, True))
    lens = len(_lens_foot(layout.tower, profile)[3])
    out.append(bolt_load("lens mount's foot on the shelf", "M4", lens,
                         {**_faces(washers["lens"]), "nut (under the shelf)": nut_area("M4", hole)}, mat, False))
    b = breadboard.board(profile)
    if b is not None:
        held = len([q for qs in breadboard.anchor_points(profile, layout).values() for q in qs])
        hb = breadboard.fit(profile, layout)["hole_mm"]
        out.append(bolt_load("the rig on the breadboard", b.thread, held,
                             {"large washer": washer_area(b.thread, hb, large=True)}, mat, True))
    pj, cm = profile.projector, profile.camera
    out.append(bolt_load(PROJECTOR_JOINT, pj.mount_thread, 4, _faces(washers["projector"]), mat,
                         False))
    out.append(bolt_load(CAMERA_JOINT, cm.mount_thread, 2, _faces(washers["camera"]), mat, False))
    return tuple(out)


# --------------------------------------------------------------------------------- deflections

@dataclass(frozen=True)
class Deflection:
    """A printed part under the instruments' weights: ``sag_mm`` and ``tilt_rad`` where the optics
    sit, at the low modulus; ``first_mode_hz``; ``eats``: the tolerancing key it eats, with
    ``tolerance`` (mm or rad, as the key) and ``share`` (the sag, or tilt, over it); ``model``: the
    closed form; ``holds``: the static figure within the tolerance (the alignment then takes it
    out); ``buy``: what replaces the part when it does not."""

    part: str
    model: str
    sag_mm: float
    tilt_rad: float
    first_mode_hz: float
    eats: str
    tolerance: float
    share: float
    buy: str = ""

    @property
    def holds(self) -> bool:
        return self.share <= 1.0

    def describe(self) -> dict:
        return {"part": self.part, "model": self.model, "sag_mm": float(self.sag_mm),
                "tilt_deg": math.degrees(self.tilt_rad), "first_mode_hz": float(self.first_mode_hz), "eats": [f"tolerancing.{k}" for k in self.eats.split(", ")],
                "share_of_tolerance": float(self.share), "holds": bool(self.holds), "buy": self.buy}


def simply_supported(P: float, q: float, L: float, EI: float, m_point: float, m_beam: float) -> tuple[float, float]:
    """Mid-span sag (mm) of a simply supported beam (span L mm, EI N mm2) under a central load P (N)
    and its weight q (N/mm), and its first mode (Hz) with a central mass m_point and its own mass
    m_beam (kg): Roark Table 8.1 cases 1a, 2a; Rayleigh with 17/35 of the beam's mass."""
    sag = P * L ** 3 / (48 * EI) + 5 * q * L ** 4 / (384 * EI)
    k = 48 * EI / L ** 3 * 1000.0  # N/mm -> N/m
    f = math.sqrt(k / (m_point + 17 / 35 * m_beam)) / (2 * math.pi)
    return sag, f


def cantilever(loads: list[tuple[float, float]], q: float, length: float, x: float, EI: float) -> tuple[float, float]:
    """Deflection (mm) and slope (rad) at ``x`` mm from the root of a cantilever of ``length`` mm
    (EI N mm2) under point loads (P N, a mm) and a uniform q N/mm over its length (superposed
    closed forms, Roark Table 8.1 cases 1a and 2a: the uniform load's q x^2 (6 l^2 - 4 l x + x^2) /
    (24 E I) and slope q x (3 l^2 - 3 l x + x^2) / (6 E I))."""
    y = th = 0.0
    for P, a in loads:
        if x >= a:
            y += P * a ** 2 * (3 * x - a) / (6 * EI)
            th += P * a ** 2 / (2 * EI)
        else:
            y += P * x ** 2 * (3 * a - x) / (6 * EI)
            th += P * x * (2 * a - x) / (2 * EI)
    if q:
        y += q * x ** 2 * (6 * length ** 2 - 4 * length * x + x ** 2) / (24 * EI)
        th += q * x * (3 * length ** 2 - 3 * length * x + x ** 2) / (6 * EI)
    return y, th


def _mass(profile, key: str, masses) -> float:
    if masses and key in masses:
        return masses[key]
    section = getattr(profile, key, None)
    mass = getattr(section, "mass", None)
    return mass if mass is not None else ASSUMED_MASS_KG[key]


def deflections(profile, layout, printer: Printer, masses: dict[str, float] | None = None) -> tuple[Deflection, ...]:
    """The beam (under the paraboloid), the shelf (under the projector, the holder and the camera)
    and the column (under the shelf's moment), at the material's low modulus."""
    mat, tol = material(printer), profile.tolerancing
    E = mat.modulus_low
    rho = printer.material_density_g_cm3 * 1e-6  # kg/mm3
    # the beam: simply supported on the slots' floors, the paraboloid (its back as a solid disc) at mid-span
    b, h = profile.beam.width, profile.beam.height
    L = 2 * layout.slot_r - profile.dome_shell.wall
    rim = layout.printed_paraboloid.points(np.array([layout.printed_paraboloid.u_range[0]]))[0]
    m_para = rho * math.pi * float(rim[0]) ** 2 * (float(rim[1]) - layout.beam_z[1])
    sag, f = simply_supported(m_para * G, rho * b * h * G, L, E * printed_inertia(b, h), m_para, rho * b * h * L)
    beam = Deflection("beam", f"simply supported over {L:.0f} mm, {b:g} x {h:g} mm, the paraboloid "
                      f"({m_para * G:.2f} N, its back as a solid disc) at mid-span", sag, 0.0, f,
                      "paraboloid_height", tol.paraboloid_height, sag / tol.paraboloid_height,
                      "a bought beam: ground steel or aluminium flat bar")
    return (beam, *_tower_deflections(profile, layout, printer, mat, masses))


def _shelf_model(profile, layout, printer: Printer, mat: Material, masses, option: str | None = None) -> dict:
    """The shelf as a cantilever from its column flange's edge towards the axis, as wide as it is, under
    the projector's near feet (a quarter of its weight each), the holder and camera at the seat and its
    own weight, printed (``option`` "print": ``mat`` at its low modulus, the printed section) or bought
    ("aluminium_plate": ALUMINIUM, solid); default the profile's ``buy.shelf``. Returns its sag and tilt
    under the seat, its first mode (Rayleigh on the static curve), its root moment (N mm), the largest
    bending stress (MPa) and the figures the tables state."""
    t = layout.tower
    option = option or profile.buy.shelf
    m_pj, m_cam, m_hold = (_mass(profile, k, masses) for k in ("projector", "camera", "holder"))
    root = t.column_x - t.column_foot_half
    seat = seat_points(t, profile)["cone"][0]
    x0, x1, y0, y1 = _shelf_extent(t, profile)
    width, overhang, a_seat, th = y1 - y0, root - x0, root - seat, t.shelf_thickness
    if option == "print":
        I, c = printed_plate(width, th, skin(printer))  # printed flat: its skin as the slicer lays it
        E, rho, what = mat.modulus_low, printer.material_density_g_cm3 * 1e-6, "printed"
    else:
        E, rho, I, what, c = ALUMINIUM.modulus_low, ALUMINIUM_DENSITY, width * th ** 3 / 12, ALUMINIUM.name, th / 2
    feet = [x for x, _ in _projector_feet(t)]
    near = [(m_pj / 4, root - x) for x in feet if x < root]
    points = near + [(m_cam + m_hold, a_seat)]
    loads = [(m * G, a) for m, a in points]
    q = rho * width * th * G
    EI = E * I
    sag, tilt = cantilever(loads, q, overhang, a_seat, EI)
    # Rayleigh's quotient on the static curve: the point masses and the shelf's own, lumped
    seg = overhang / SHELF_LUMPS
    lumps = points + [(rho * width * th * seg, (k + 0.5) * seg) for k in range(SHELF_LUMPS)]
    ys = [cantilever(loads, q, overhang, a, EI)[0] for _, a in lumps]
    num = sum(m * y for (m, _), y in zip(lumps, ys)) * G * 1000.0  # N mm -> the m/s2 of g over mm: x1000 for Hz
    den = sum(m * y * y for (m, _), y in zip(lumps, ys))
    mode = math.sqrt(num / den) / (2 * math.pi) if den > 0 else math.inf
    moment = sum(P * a for P, a in loads) + q * overhang ** 2 / 2
    stress = moment * c / I
    return {"option": option, "material": what, "sag_mm": sag, "tilt_rad": tilt, "first_mode_hz": mode,
            "root_moment_nmm": moment, "stress_mpa": stress, "width": width, "overhang": overhang, "a_seat": a_seat,
            "thickness": th, "seat_load_n": (m_cam + m_hold) * G, "EI_nmm2": EI, "mass_per_mm_kg": rho * width * th,
            "point_masses": tuple(points), "expansion": mat.expansion if option == "print"
            else ALUMINIUM.expansion}


def _shelf_deflection(profile, model: dict) -> Deflection:
    tol = profile.tolerancing
    section = "printed" if model["option"] == "print" else f"{model['material']}, solid"
    return Deflection("shelf", f"cantilever {model['overhang']:.0f} mm from the column's flange, {model['width']:.0f} x "
                      f"{model['thickness']:g} mm {section}; the holder and camera ({model['seat_load_n']:.1f} N) at the "
                      f"seat {model['a_seat']:.0f} mm out, the projector's near feet, its own weight; its tilt under the seat "
                      f"turns the splitter, whose reflected axis turns {SPLITTER_TURN:g} x as much; first mode by Rayleigh's "
                      f"quotient on its static curve; bending stress {model['stress_mpa']:.2f} MPa",
                      model["sag_mm"], model["tilt_rad"], model["first_mode_hz"], "projector_height, projector_tilt",
                      tol.projector_height, max(model["sag_mm"] / tol.projector_height,
                                                SPLITTER_TURN * model["tilt_rad"] / tol.projector_tilt),
                      "buy.shelf: aluminium_plate" if model["option"] == "print" else "")


def _shelf_moment(profile, layout, printer: Printer, masses) -> tuple[float, float]:
    """The moment (N mm) the shelf and what stands on it put on the column's axis, and the top's mass (kg)."""
    t = layout.tower
    m_pj, m_cam, m_hold = (_mass(profile, k, masses) for k in ("projector", "camera", "holder"))
    seat = seat_points(t, profile)["cone"][0]
    x0, x1, y0, y1 = _shelf_extent(t, profile)
    rho = (printer.material_density_g_cm3 * 1e-6 if profile.buy.shelf == "print" else ALUMINIUM_DENSITY)
    m_shelf = rho * (x1 - x0) * (y1 - y0) * t.shelf_thickness
    feet = [x for x, _ in _projector_feet(t)]
    points = [(m_pj * G / 4, x) for x in feet] + [((m_cam + m_hold) * G, seat), (m_shelf * G, (x0 + x1) / 2)]
    return abs(sum(P * (t.column_x - x) for P, x in points)), m_pj + m_cam + m_hold + m_shelf


def _tower_deflections(profile, layout, printer: Printer, mat: Material, masses) -> tuple[Deflection, Deflection]:
    """The shelf (:func:`_shelf_model` as the profile buys it). The column: a cantilever from the tongue
    under the shelf's moment about its axis; its sway with the top's mass."""
    t, tw, tol = layout.tower, profile.tower, profile.tolerancing
    E, rho = mat.modulus_low, printer.material_density_g_cm3 * 1e-6
    shelf = _shelf_deflection(profile, _shelf_model(profile, layout, printer, mat, masses))
    seat = seat_points(t, profile)["cone"][0]
    H = t.shelf_top_z - t.shelf_thickness - t.column_base_z
    EI_col = E * printed_tube_inertia(tw.column_width, tw.wall)
    moment, top = _shelf_moment(profile, layout, printer, masses)
    rot = moment * H / EI_col
    drop = rot * (t.column_x - seat)
    m_col = rho * 4 * tw.column_width * tw.wall * H
    k = 3 * EI_col / H ** 3 * 1000.0
    f_col = math.sqrt(k / (top + 33 / 140 * m_col)) / (2 * math.pi)
    column = Deflection("column", f"cantilever {H:.0f} mm, {tw.column_width:g} mm square tube, {tw.wall:g} mm printed "
                        f"wall, under the shelf's moment {moment / 1000:.2f} N m (the seat drops by its turn over "
                        f"{t.column_x - seat:.0f} mm); sway with the top's {top * G:.0f} N", drop, rot, f_col,
                        "projector_height, projector_tilt", tol.projector_height,
                        max(drop / tol.projector_height, rot / tol.projector_tilt), "buy.column: extrusion_40x40")
    return shelf, column


def thermal(profile, layout, printer: Printer, swing: float = LAB_SWING_K) -> Deflection:
    """A uniform ``swing`` K (each way) over the printed rig (see the module docstring): the virtual COP
    along the axis against the paraboloid's vertex (alpha dT times the COP's height over the vertex) and
    across (the base plate's growth from the bore to the column less the shelf's from the column to the
    seat), against ``tolerancing.projector_height`` and ``projector_offset``; no tilt (uniform)."""
    tol = profile.tolerancing
    a = material(printer).expansion
    along = a * swing * profile.layout.cop_to_vertex
    across = _thermal_across(profile, layout, printer, swing)
    share = max(along / tol.projector_height, across / tol.projector_offset)
    shelf = "printed" if profile.buy.shelf == "print" else f"{ALUMINIUM.name} ({ALUMINIUM.expansion * 1e6:.1f}e-6 /K)"
    return Deflection(f"thermal, +-{swing:g} K uniform", f"{material(printer).name} {a * 1e6:.0f}e-6 /K: the COP moves "
                      f"{along:.3f} mm along the axis against the vertex ({profile.layout.cop_to_vertex:.0f} mm below it) "
                      f"and {across:.3f} mm across (the shelf {shelf}); a uniform swing tilts nothing", along, 0.0,
                      math.nan, "projector_height, projector_offset", tol.projector_height, share,
                      "buy.shelf: aluminium_plate" if profile.buy.shelf == "print" else "")


@dataclass(frozen=True)
class FlangeJoint:
    """A bolted column flange under the shelf's overturning moment (N mm, mm, N, MPa): the most loaded
    bolt's extra tension against the joint's preload (``margin``: preload over it; the joint stays closed
    above 1), and the pressure under its nut (or insert's flange) and washer with that tension added."""

    joint: str
    moment_nmm: float
    bolt_force_n: float
    preload_n: float
    pressure_mpa: float
    yield_mpa: float

    @property
    def margin(self) -> float:
        return self.preload_n / self.bolt_force_n if self.bolt_force_n > 0 else math.inf

    @property
    def holds(self) -> bool:
        return self.margin > 1.0 and self.pressure_mpa < self.yield_mpa

    def describe(self) -> dict:
        return {"joint": self.joint, "moment_nm": self.moment_nmm / 1000.0, "bolt_force_n": self.bolt_force_n,
                "preload_n": self.preload_n, "preload_over_load": self.margin, "pressure_mpa": self.pressure_mpa,
                "yield_mpa": self.yield_mpa, "holds": self.holds}


def flange_joints(profile, layout, printer: Printer, masses: dict[str, float] | None = None) -> tuple[FlangeJoint, ...]:
    """The printed column's foot (on the tongue) and top (under the shelf) under the shelf's overturning
    moment: each flange turns about its edge on the shelf's side; each bolt row at d_i from that edge
    takes F_i = M d_i / sum(d_j^2) (two bolts a row); the most loaded against its preload
    (:func:`bolt_loads`) and its bearing face. None for a bought extrusion (one core screw each end)."""
    if profile.buy.column != "print":
        return ()
    from rigcad.parts.tower import _column_flange_points

    t = layout.tower
    mat = material(printer)
    moment, _ = _shelf_moment(profile, layout, printer, masses)
    edge = t.column_x - t.column_foot_half  # the shelf reaches out on -x: the flange turns about its -x edge
    d = [x - edge for x, _ in _column_flange_points(t, profile)]
    force = moment * max(d) / sum(v * v for v in d)
    bolts = {b.joint: b for b in bolt_loads(profile, layout, printer)}
    out = []
    for name in ("column foot on the tongue", "column top under the shelf"):
        b = bolts[name]
        out.append(FlangeJoint(name, moment, force, b.preload_n, (b.preload_n + force) / b.area_mm2, mat.yield_strength))
    return tuple(out)


@dataclass(frozen=True)
class Loads:
    """The loads report: the material, every bolted joint and every deflection."""

    material: Material
    bolts: tuple[BoltLoad, ...]
    deflections: tuple[Deflection, ...]
    flanges: tuple[FlangeJoint, ...] = ()
    shelf_options: tuple[dict, ...] = ()

    def record(self) -> dict:
        """JSON-able, units in the keys (a first mode not computed is null)."""
        return {"material": {"name": self.material.name, "modulus_low_mpa": self.material.modulus_low,
                             "modulus_high_mpa": self.material.modulus_high,
                             "yield_strength_mpa": self.material.yield_strength, "source": self.material.source},
                "bolts": [b.describe() for b in self.bolts],
                "deflections": [{k: (None if isinstance(v, float) and math.isnan(v) else v)
                                 for k, v in d.describe().items()} for d in self.deflections],
                "flanges": [f.describe() for f in self.flanges],
                "shelf_options": [{k: v for k, v in o.items()} for o in self.shelf_options]}

    def table_lines(self) -> list[str]:
        """Markdown: the torques, then the deflections."""
        out = ["| joint | screws | bears on | torque | preload | pressure (allowed) | hand-tight 1 N m | spring washer |",
               "|---|---|---|---|---|---|---|---|"]
        for b in self.bolts:
            out.append(f"| {b.joint} | {b.count} x {b.thread} | {b.bearing}, {b.area_mm2:.0f} mm2 | {b.torque_nm:.2f} N m "
                       f"| {b.preload_n:.0f} N | {b.pressure_mpa:.0f} MPa | {b.hand_tight_mpa:.0f} MPa | "
                       f"{'yes' if b.spring_washer else 'no'} |")
        out += ["", "| part | model | sag | tilt | first mode | eats | share | holds |", "|---|---|---|---|---|---|---|---|"]
        for d in self.deflections:
            mode = "-" if math.isnan(d.first_mode_hz) else f"{d.first_mode_hz:.0f} Hz"
            out.append(f"| {d.part} | {d.model} | {d.sag_mm:.3f} mm | {math.degrees(d.tilt_rad):.3f} deg | {mode} | "
                       f"{d.eats} | {100 * d.share:.0f} % | {'yes' if d.holds else 'no: ' + d.buy} |")
        if self.flanges:
            out += ["", "| flange joint | overturning moment | most loaded bolt | preload | preload / load | "
                    "pressure with it | yield | holds |", "|---|---|---|---|---|---|---|---|"]
            for f in self.flanges:
                out.append(f"| {f.joint} | {f.moment_nmm / 1000:.2f} N m | {f.bolt_force_n:.0f} N | {f.preload_n:.0f} N | "
                           f"{f.margin:.1f} | {f.pressure_mpa:.1f} MPa | {f.yield_mpa:.0f} MPa | {'yes' if f.holds else 'no'} |")
        if self.shelf_options:
            out += ["", "| buy.shelf | sag | tilt (its reflected axis 2 x) | first mode | share | bending stress | "
                    "thermal, across |", "|---|---|---|---|---|---|---|"]
            for o in self.shelf_options:
                out.append(f"| {o['option']} | {o['sag_mm']:.3f} mm | {o['tilt_deg']:.3f} deg | {o['first_mode_hz']:.0f} Hz | "
                           f"{100 * o['share']:.0f} % | {o['stress_mpa']:.2f} MPa | {o['thermal_across_mm']:.3f} mm |")
        return out


def shelf_options(profile, layout, printer: Printer, masses: dict[str, float] | None = None) -> tuple[dict, ...]:
    """The shelf under each ``buy.shelf`` option (print, aluminium_plate), whichever the profile takes: its
    sag, tilt, first mode, share of the tolerance, bending stress and the COP's move across under
    LAB_SWING_K (mm, deg, Hz, MPa): the figures the choice is made on."""
    from dataclasses import replace as _replace

    mat, out = material(printer), []
    for option in ("print", "aluminium_plate"):
        m = _shelf_model(profile, layout, printer, mat, masses, option)
        d = _shelf_deflection(profile, m)
        bought = _replace(profile, buy=_replace(profile.buy, shelf=option))
        out.append({"option": option, "sag_mm": d.sag_mm, "tilt_deg": math.degrees(d.tilt_rad),
                    "first_mode_hz": d.first_mode_hz, "share": d.share, "stress_mpa": m["stress_mpa"],
                    "thermal_across_mm": _thermal_across(bought, layout, printer)})
    return tuple(out)


def _thermal_across(profile, layout, printer: Printer, swing: float = LAB_SWING_K) -> float:
    """The COP's move across (mm) under a uniform ``swing`` K: :func:`thermal`'s."""
    t = layout.tower
    a = material(printer).expansion
    a_shelf = a if profile.buy.shelf == "print" else ALUMINIUM.expansion
    seat = seat_points(t, profile)["cone"][0]
    return abs(a * t.column_x - a_shelf * (t.column_x - seat) - a * seat) * swing


def loads(profile, layout, printer: Printer, masses: dict[str, float] | None = None) -> Loads:
    """Torques, deflections (the beam, the shelf, the column, a lab's +-LAB_SWING_K), the column flanges
    under the overturning moment and the shelf's two options, on ``printer``'s material."""
    return Loads(material(printer), bolt_loads(profile, layout, printer),
                 (*deflections(profile, layout, printer, masses), thermal(profile, layout, printer)),
                 flange_joints(profile, layout, printer, masses), shelf_options(profile, layout, printer, masses))


def refuse(report: Loads) -> None:
    """Raise FabricationError when a printed part cannot hold the tolerance its static sag or tilt
    eats, naming the part and its ``buy:`` option."""
    bad = [d for d in report.deflections if not d.holds]
    flanges = [f for f in report.flanges if not f.holds]
    if flanges:
        raise FabricationError("column flange joints the shelf's overturning moment opens or crushes: " + "; ".join(
            f"{f.joint} (its most loaded bolt {f.bolt_force_n:.0f} N against {f.preload_n:.0f} N of preload, "
            f"{f.pressure_mpa:.1f} MPa under it against {f.yield_mpa:.0f} MPa); buy: buy.column: extrusion_40x40"
            for f in flanges))
    if bad:
        raise FabricationError("printed parts that bend past the tolerance they eat: " + "; ".join(
            f"{d.part} ({100 * d.share:.0f} % of tolerancing.{d.eats}); buy: {d.buy}" for d in bad))


__all__ = ["ALUMINIUM", "FlangeJoint", "Skin", "skin", "printed_plate", "LAB_SWING_K", "flange_joints", "shelf_options", "thermal", "refuse", "ASSUMED_MASS_KG", "BoltLoad", "Deflection", "Loads", "MATERIALS", "Material", "bolt_loads", "cantilever",
           "deflections", "loads", "material", "printed_inertia", "printed_tube_inertia", "simply_supported"]
