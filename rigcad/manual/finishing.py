"""Finishing the printed mirrors so that thesis 4.4's failure (surfaces right in form, wrong in
slope) does not repeat: the sanding blocks sized from each mirror's curvature, the template gaps as
feeler-gauge leaves, and an optical acceptance test with a pass limit computed from the angle
target.

- Curvature: each mirror's design meridian (``Part.mirrors``) gives its principal radii along the
  meridian (meridional, from the plane curve's curvature) and across it (sagittal: r / |n_r|, the
  distance along the normal to the axis). A flat block of length L on a curve of radius R stands
  off by the sagitta L^2 / (8 R): the longest block that keeps it under BLOCK_SAG_MM is
  sqrt(8 R BLOCK_SAG_MM); a longer block must be curved to R (convex for a concave mirror).
- Slope: every ray of a right rig lands on O (the sample point); a mirror tilted by e turns a
  reflected ray by 2 e, and it lands off O. The acceptance test looks at that directly: a white disc
  of radius ``tolerancing.max_spot_radius`` on black at O, seen by the camera through the rig, is
  white over the paraboloid's whole image when every ray lands inside it (slope_acceptance).

Units: mm and rad inside; the figures carry their unit in their keys.
"""

from __future__ import annotations

import math

import numpy as np

#: Largest stand-off (mm) of a flat sanding block from the design curve: 1 mil (0.0254 mm), the
#: thinnest coat: a sanding error a coat cannot fill must stay under it.
BLOCK_SAG_MM = 0.0254


def principal_radii(meridian, samples: int = 4001) -> dict:
    """Smallest meridional and sagittal radii of curvature (mm) of the surface of revolution of
    ``meridian`` (r, z), from finite differences on ``samples`` points (second order)."""
    p = meridian.points(meridian.sample(samples))
    r, z = p[:, 0], p[:, 1]
    dr, dz = np.gradient(r), np.gradient(z)
    ddr, ddz = np.gradient(dr), np.gradient(dz)
    speed = np.hypot(dr, dz)
    kappa = np.abs(dr * ddz - dz * ddr) / speed ** 3
    n_r = np.abs(dz) / speed  # the normal's radial component
    inner = slice(2, -2)  # one-sided differences at the ends are first order: left out
    meridional = 1.0 / np.max(kappa[inner])
    with np.errstate(divide="ignore"):
        sagittal = np.where(n_r > 1e-9, np.abs(r) / np.maximum(n_r, 1e-300), np.inf)
    return {"meridional_mm": float(meridional), "sagittal_mm": float(np.min(sagittal[inner]))}


def sanding_blocks(rig) -> list[dict]:
    """Per mirror: its smallest radii, the smaller one, and the longest flat block (mm) it takes."""
    rows = []
    for part_name, part in rig.recipes.items():
        for mirror, design in part.mirrors:
            radii = principal_radii(design)
            r_min = min(radii.values())
            rows.append({"mirror": mirror, "part": part_name, **radii, "smallest_radius_mm": r_min,
                         "flat_block_max_mm": math.sqrt(8.0 * r_min * BLOCK_SAG_MM),
                         "concave": mirror != "paraboloid"})
    return rows


#: Chief rays of the meridional trace that gives the paraboloid's placement spot (placement_spot).
PLACEMENT_RAYS = 2000


def placement_spot(rig, offset: float) -> float:
    """How far (mm) the design's chief rays land from O, at most, when the paraboloid alone sits ``offset``
    mm off the axis (the meridional trace of rigcad.optics.misalignment, the design's chief rays across
    the paraboloid's useful annulus): the spot the slope test sees from the paraboloid's placement alone."""
    from rigcad.optics.design import chief_rays
    from rigcad.optics.misalignment import Offsets, misaligned_trace

    origins, dirs = chief_rays(rig.geometry, rig.paraboloid, rig.dome, PLACEMENT_RAYS)
    tr = misaligned_trace(rig.paraboloid, rig.curve, origins, dirs, Offsets(paraboloid_dx=offset))
    return float(np.max(np.abs(tr.miss[tr.ok])))


#: The share of the paraboloid's image the slope test must see lit: 99 %, so that the test before the mirror
#: coat passes on the same figure as the calibration after it (rigcad.calibrate.kit.pass_criterion: the dome's
#: residual slope's 99th percentile within the same slope tolerance, seen by the same camera). A pixel is lit
#: when its ray lands within the disc, i.e. its slope error is within the tolerance: 99 % lit is that p99.
SLOPE_PASS_FRACTION = 0.99


def slope_acceptance(rig) -> dict:
    """The optical acceptance test's figures: every camera pixel's ray lands on the sample plane within
    ``tolerancing.max_spot_radius`` of O when the mirrors are right, so a lit disc of that radius at O
    fills the paraboloid's whole image with light; a pixel that stays dark marks a mirror area whose
    slope is off. The disc is the film of the circle test (rigcad.manual.calibration.film_setup: on the
    base plate's top, z = 0, over the bore, O traced on it) under a black mask with a hole of that
    radius, lit from below through the bore by a lamp on the bench, the rig on the film test's blocks.
    The dome's slope tolerance that this test holds: a slope error e turns the ray by 2 e, which lands
    2 e D off O, D the dome's farthest point from O (mm). A reference picture with the mask off (the
    whole bore lit) tells a slope error from a dark corner of the light: a ray that lands past the disc
    but inside the bore is lit there only.
    The paraboloid is indicated in on the dome's axis before the test, to ``tolerancing.paraboloid_offset``:
    unplaced, its lateral stack alone throws rays past the disc, and the test could not tell a slope error
    from a misplaced paraboloid; placed, what its placement alone adds is ``placement_spot_mm``
    (:func:`placement_spot`), and ``slope_room_mm`` of the disc is left to the slopes."""
    from rigcad.calibrate.kit import dome_farthest_from_o, dome_slope_tolerance
    from rigcad.manual.calibration import film_setup

    p = rig.profile
    far = dome_farthest_from_o(rig)
    limit = p.tolerancing.max_spot_radius
    f = film_setup(rig)
    placed = placement_spot(rig, p.tolerancing.paraboloid_offset)
    return {"disc_radius_mm": limit, "placement_offset_mm": p.tolerancing.paraboloid_offset,
            "placement_spot_mm": placed, "slope_room_mm": limit - placed, "dome_farthest_from_o_mm": far,
            "dome_slope_tolerance_mrad": dome_slope_tolerance(rig), "pass_fraction": SLOPE_PASS_FRACTION,
            "bore_radius_mm": f["bore_radius_mm"], "bore_slope_mrad": 1e3 * f["bore_radius_mm"] / (2.0 * far),
            "lamp_room_mm": f["block_under_disc_mm"], "film_above_bench_mm": f["block_under_disc_mm"]
            + f["plate_thickness_mm"], "block_under_disc_mm": f["block_under_disc_mm"],
            "block_under_tongue_mm": f["block_under_tongue_mm"]}


# -- the sanding blocks: printed, their face the mirror's own surface -------------------------------
#: The abrasive on every block: silicon carbide on a polyester film backing with a pressure-sensitive
#: adhesive (PSA) back, cut to the block's face; grades by stage (FEPA P, ISO 6344). Film, not paper:
#: its backing is even in thickness (paper's varies by about its grit), so the face stands where the block
#: puts it. Its thickness with the grit (mm): the block's face is cut this far in front of the surface.
ABRASIVE = (("P120, P240, P400", "the print's layer lines"), ("P600, P800", "the primer"),
            ("P1500, P2000, P3000", "the clear coat"))
ABRASIVE_SPEC = ("PSA-backed silicon carbide film (polyester backing, e.g. 3M 260L / Mirka Polarstar class "
                 "sheets, 115 x 230 mm), cut to each block's face")
ABRASIVE_MM = 0.15
#: A block's size (mm): along the meridian (a hand's grip, several staircase steps of the print under it),
#: across it, and its body behind the face. Blocks along one meridian overlap by BLOCK_OVERLAP_MM.
BLOCK_LENGTH_MM = 40.0
BLOCK_WIDTH_MM = 25.0
BLOCK_THICKNESS_MM = 12.0
BLOCK_OVERLAP_MM = 10.0


def _arc(design, samples: int = 4001) -> tuple[np.ndarray, np.ndarray]:
    """Parameters u (n,) over the meridian and the arc length s (n,) mm from its first end."""
    u = design.sample(samples)
    p = design.points(u)
    return u, np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])


def block_bands(design) -> list[tuple[float, float]]:
    """The bands (u0, u1) of the meridian the blocks' faces copy: BLOCK_LENGTH_MM of arc each (the whole
    meridian when it is shorter), overlapping by BLOCK_OVERLAP_MM, the last one ending at the meridian's end."""
    u, s = _arc(design)
    total = float(s[-1])
    if total <= BLOCK_LENGTH_MM:
        return [(float(u[0]), float(u[-1]))]
    n = math.ceil((total - BLOCK_OVERLAP_MM) / (BLOCK_LENGTH_MM - BLOCK_OVERLAP_MM))
    step = (total - BLOCK_LENGTH_MM) / (n - 1)
    return [(float(np.interp(k * step, s, u)), float(np.interp(k * step + BLOCK_LENGTH_MM, s, u))) for k in range(n)]


def _curvatures(design, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Meridional and sagittal curvature (1/mm) of the surface of revolution at ``u``."""
    p, n = design.points(u), design.normals(u)
    with np.errstate(divide="ignore", invalid="ignore"):
        sag = np.where(p[:, 0] > 1e-6, np.abs(n[:, 0]) / np.maximum(p[:, 0], 1e-300), design.curvature(u))
    return design.curvature(u), sag


def block_slide(design, band, length: float, width: float) -> float:
    """How far (mm of arc) a block made on ``band`` may slide along the meridian either way before its
    face stands off the surface by more than BLOCK_SAG_MM: the curvatures it meets change by dk, and a face
    of length L stands off by L^2 dk / 8 (meridional, over ``length``; sagittal, over ``width``)."""
    u, s = _arc(design)
    km, ks = _curvatures(design, u)
    inside = (u >= min(band) - 1e-12) & (u <= max(band) + 1e-12)
    s_in = s[inside]
    limits, reach = [], [0.0]
    for sign in (1.0, -1.0):
        last = 0.0  # the farthest slide this way found within BLOCK_SAG_MM
        for d in np.linspace(0.0, float(s[-1]), 4001)[1:]:
            t = s_in + sign * d
            if t.min() < 0.0 or t.max() > s[-1]:
                break  # past the mirror's end: the way stops there
            if block_gap(km, ks, s, inside, t, length, width) > BLOCK_SAG_MM:
                limits.append(last)
                break
            last = float(d)
            reach.append(last)
    return min(limits) if limits else max(reach)


def block_gap(km, ks, s, inside, t, length: float, width: float) -> float:
    """The stand-off (mm) of a block's face made where ``inside`` is (a mask on the meridian's arc
    ``s``, curvatures ``km``, ``ks``) when moved to arc positions ``t``: L^2 dk / 8, both ways."""
    return float(length ** 2 * np.max(np.abs(np.interp(t, s, km) - km[inside]))
                 + width ** 2 * np.max(np.abs(np.interp(t, s, ks) - ks[inside]))) / 8.0


def block_part(mirror: str, design, k: int, band):
    """Sanding block ``k`` of a mirror as a recipe Part: its face is the mirror's surface over ``band``
    moved ABRASIVE_MM to the reflecting side (the abrasive film fills that), its body
    BLOCK_THICKNESS_MM behind the face on the reflecting side, revolved and cut to BLOCK_WIDTH_MM across
    (|y| <= width / 2, x >= 0)."""
    from rigcad.parts.recipe import Box, Curve, Difference, Line, Part, Revolve, Section

    face = design.behind(-ABRASIVE_MM)
    back = design.behind(-(ABRASIVE_MM + BLOCK_THICKNESS_MM))
    u0, u1 = band
    segs = [Curve(face, u0, u1), Line(Curve(face, u0, u1).p1, Curve(back, u1, u0).p0), Curve(back, u1, u0),
            Line(Curve(back, u1, u0).p1, Curve(face, u0, u1).p0)]
    big = 10.0 * (BLOCK_LENGTH_MM + BLOCK_THICKNESS_MM + float(np.max(np.abs(design.points(design.sample(64))))))
    half = BLOCK_WIDTH_MM / 2
    cuts = (Box((-big, half, -big), (big, big, big)), Box((-big, -big, -big), (big, -half, big)),
            Box((-big, -big, -big), (0.0, big, big)))
    return Part(f"sanding_block_{mirror}_{k + 1}", Difference(Revolve(Section(tuple(segs))), cuts), (0.4, 0.6, 0.8),
                f"sanding block {k + 1} of the {mirror}: its face is the {mirror}'s surface over its band, "
                f"{ABRASIVE_MM:g} mm proud for the abrasive film", in_rig=False)


def sanding_block_set(rig) -> list[dict]:
    """Every mirror's printed sanding blocks: per block its band (arc mm from the meridian's first end:
    the dome's base, the paraboloid's rim), its face's least radii, how far it may slide along the
    meridian (:func:`block_slide`) and its recipe Part (``part``)."""
    rows = []
    for part_name, part in rig.recipes.items():
        for mirror, design in part.mirrors:
            u, s = _arc(design)
            for k, band in enumerate(block_bands(design)):
                inside = (u >= band[0]) & (u <= band[1])
                km, ks = _curvatures(design, u[inside])
                length = float(np.interp(band[1], u, s) - np.interp(band[0], u, s))
                rows.append({"mirror": mirror, "block": k + 1, "from_mm": float(np.interp(band[0], u, s)),
                             "to_mm": float(np.interp(band[1], u, s)), "length_mm": length,
                             "width_mm": BLOCK_WIDTH_MM, "thickness_mm": BLOCK_THICKNESS_MM,
                             "meridional_radius_mm": float(1.0 / np.max(km)), "sagittal_radius_mm": float(1.0 / np.max(ks)),
                             "slide_mm": block_slide(design, band, length, BLOCK_WIDTH_MM),
                             "part": block_part(mirror, design, k, band)})
    return rows


# -- the templates' datums ------------------------------------------------------------------------
def template_datums(rig) -> list[dict]:
    """Each profile template's drawing and datum, read from its recipe's section (the x-z outline of
    its Prism, mm, in its gauging position: x from the rig's axis, z up from the sample plane): the
    outline, the gauging edge (the section's curves on the gauged surface, ``templates.gauged_layer``)
    and the datum: the level straight edges that run from the gauging edge's ends when the section has
    them ("rim": the template's feet in the plane of the mirror's rim, where it meets the part's side), else
    the longest level straight edge ("edge": set level, its centre on the axis), else the gauging edge's
    lowest end ("corner": it stands on the base plate's top, z = 0, where the mirror meets the plate)."""
    from rigcad.parts.recipe import Curve, Line
    from rigcad.parts.templates import gauged_depth

    out = []
    depth = gauged_depth(rig.profile)
    for name in ("dome_template", "paraboloid_template"):
        part = rig.recipes.get(name)
        if part is None:
            continue
        section = part.solid.section
        outline = section.polygon(0.05)
        gauge = [seg.dense(401) for seg in section.segments
                 if isinstance(seg, Curve) and abs(seg.meridian.offset - depth) < 1e-9]
        level = [seg for seg in section.segments if isinstance(seg, Line) and abs(seg.p0[1] - seg.p1[1]) < 1e-9]
        edge = np.concatenate(gauge)
        row = {"template": name, "outline_mm": outline.tolist(), "gauging_edge_mm": [g.tolist() for g in gauge],
               "axis_x_mm": 0.0, "width_mm": float(np.ptp(outline[:, 0])), "height_mm": float(np.ptp(outline[:, 1]))}
        ends = [edge[0], edge[-1]] if len(gauge) == 1 else [gauge[0][0], gauge[-1][-1]]
        def touching(seg):  # the end of a level edge that is an end of the gauging edge, or None
            return next((list(q) for q in (seg.p0, seg.p1) if any(np.hypot(*(np.asarray(q) - e)) < 1e-6 for e in ends)),
                        None)

        feet = [seg for seg in level if touching(seg) is not None]
        if feet:  # the cut-out's ends at the mirror's rim, the feet level from them: the rim's plane
            corners = sorted((touching(seg) for seg in feet), key=lambda q: q[0])
            row.update(datum="rim", datum_mm=corners, datum_z_mm=float(corners[0][1]),
                       datum_r_mm=float(max(abs(q[0]) for q in corners)),
                       datum_length_mm=float(max(abs(seg.p1[0] - seg.p0[0]) for seg in feet)))
        elif level:
            seg = max(level, key=lambda g: abs(g.p1[0] - g.p0[0]))
            row.update(datum="edge", datum_mm=[list(seg.p0), list(seg.p1)], datum_z_mm=float(seg.p0[1]),
                       datum_length_mm=float(abs(seg.p1[0] - seg.p0[0])),
                       datum_centre_x_mm=float(0.5 * (seg.p0[0] + seg.p1[0])))
        else:
            low = edge[int(np.argmin(edge[:, 1]))]
            high = edge[int(np.argmax(edge[:, 1]))]
            row.update(datum="corner", datum_mm=[low.tolist()], datum_z_mm=float(low[1]),
                       datum_r_mm=float(abs(low[0])), top_r_mm=float(abs(high[0])), top_z_mm=float(high[1]))
        out.append(row)
    return out


#: Steel straightedges as sold (mm, DIN 874 / DIN 866 lengths), for laying across a dome's open base; each
#: stands this far (mm) past the base's edge on either side to rest on it.
STRAIGHTEDGES_MM = (300.0, 500.0, 750.0, 1000.0)
STRAIGHTEDGE_OVERHANG_MM = 10.0


def straightedge(row: dict) -> tuple[float | None, float]:
    """The straightedge a "corner" template's datum is read from (:func:`template_datums`' row): laid across
    the part's base, standing STRAIGHTEDGE_OVERHANG_MM past it on each side: (the shortest length sold,
    STRAIGHTEDGES_MM, or None when none reaches; the reach, mm)."""
    reach = 2 * row["datum_r_mm"] + 2 * STRAIGHTEDGE_OVERHANG_MM
    return next((n for n in STRAIGHTEDGES_MM if n >= reach), None), reach


def template_text(row: dict) -> str:
    """How a template is held, from its datum (:func:`template_datums`)."""
    name = row["template"].replace("_template", "")
    if row["datum"] == "rim":
        return (f"`{row['template']}`: the datum is the {name}'s rim, the circle where its mirror meets its side, "
                f"{2 * row['datum_r_mm']:.1f} mm across at z = {row['datum_z_mm']:.1f} mm: the template's two feet "
                f"(red in its drawing, {row['datum_length_mm']:.1f} mm each) run level from the cut-out's ends, in the "
                f"rim's plane. Lower the template over the {name} in a meridional plane (the engineer's square on the "
                "beam's or the bench's top against its face) until its cut-out rests on the mirror: it centres itself. "
                "Then both feet must lie level with the rim's edge on each side (sight along them against the light): "
                "that is the height; the gap under the cut-out is the form.")
    if row["datum"] == "edge":
        return (f"`{row['template']}`: the datum is its straight edge, **{row['datum_length_mm']:.1f} mm** long at "
                f"z = {row['datum_z_mm']:.1f} mm (red in its drawing), with the axis line at its middle (dashed: scribe "
                f"it on the template). Hold the template in a meridional plane over the {name}, the datum edge level (the "
                "spirit level on it) and its axis line over the vertex: the cut-out then lies on the gauged surface.")
    rule, reach = straightedge(row)
    rule_text = f"a {rule:g} mm steel straightedge" if rule else f"a steel straightedge at least {reach:.0f} mm long"
    return (f"`{row['template']}`: the datum is the lower corner of its curved edge (red in its drawing), "
            f"{row['datum_r_mm']:.1f} mm from the axis at z = {row['datum_z_mm']:.1f} mm: the plane of the {name}'s "
            f"base, where the mirror meets the face that stands on the base plate. A closed {name} cannot be read from "
            f"its top opening, so it is sanded and gauged **upside down, its open base up**, standing on three blocks "
            f"on the bench round its top opening (the schedule's sanding and coating stages; the seams are glued by "
            f"then). Lay {rule_text} across the base's face through the axis (its centre mark), stand the template "
            "upright under it in that meridional plane (the engineer's square standing on the straightedge, against "
            "the template's face) and hold its datum corner up against the straightedge's underside where the mirror "
            f"meets the base; its curved edge then runs down along the mirror to {row['top_r_mm']:.1f} mm from the "
            f"axis, {row['top_z_mm']:.1f} mm down, by the top opening (the axis {row['top_r_mm']:.1f} mm beyond its "
            "end, dashed in the drawing). Read the gap against the light: a torch on the bench under the top opening "
            "lights the mirror behind the template; look along the edge from the open base, and slide the feeler leaf "
            "in from there. Turn the straightedge a quarter turn for the next plane.")


#: Specular reflectance of a polished clear coat over a black base at normal incidence: Fresnel's
#: ((n - 1) / (n + 1))^2 for a clear of index n = 1.5 (polyurethane 1.49-1.52): 0.04.
CLEAR_REFLECTANCE = 0.04

#: How each coat of the shipped profiles' ``coating.layers`` goes on, by the layer's name as the profile
#: gives it: (what, how, cure / wait). A layer not named here is applied as its maker's data sheet says.
#: A 2K (isocyanate) coat needs a supplied-air or A2/P3 respirator; 1K products are the safer choice.
LAYER_METHODS = {
    "black base paint": ("2K polyurethane gloss black base with its hardener, the ground the mirror coat needs",
                         "HVLP gun, 1.3-1.4 mm nozzle at ~2 bar, 2-3 thin wet coats, 10 min flash-off "
                         "between, 20-25 cm from the surface", "per data sheet (about 12 h at 20 C)"),
    "polyurethane primer": ("2K polyurethane primer-surfacer with its hardener: it fills what sanding left",
                            "HVLP 1.4 mm, 2 coats, 10 min flash; then block it wet P600-P800 on the sanding blocks "
                            "with a guide coat until the guide coat is gone", "per data sheet (about 12 h at 20 C) "
                            "before sanding"),
    "polyurethane clearcoat": ("2K polyurethane clear with its hardener", "HVLP 1.3 mm, 2 coats, 10-15 min flash; "
                               "after the cure wet-sand P1500, P2000, P3000 on the blocks, then cutting compound "
                               "(e.g. 3M 06085 class) and a finishing polish on a 75 mm foam pad, by hand or a DA "
                               "polisher at low speed", "24 h at 20 C before sanding; a week before polishing hard"),
    "MirraChrome": ("MirraChrome (Alsa Corp.) spray chrome, over the polished gloss coat",
                    "its own low-pressure spray system (an airbrush or a 0.8-1.0 mm HVLP at ~1 bar), mist coats "
                    "until the surface turns mirror, no more; dust-free room, 20-25 C, gloves: never touch it",
                    "per its data sheet (dust-dry in minutes; handle after 24 h); no clear on top unless the data "
                    "sheet allows it"),
}


# -- the templates' material, cutting and check ---------------------------------------------------------
#: What the templates are made of: stainless sheet keeps its edge (a file and an oil stone finish it, it does
#: not dent under a feeler leaf, and it does not rust under the wet sanding).
TEMPLATE_MATERIAL = "stainless steel sheet 1.4301 (AISI 304), cold rolled"
#: How far (mm) a laser or waterjet cut edge lands from its path, typical of job-shop cutting in 1-3 mm sheet:
#: far coarser than the gaps a template must show, so the gauging edge is cut this much proud and finished.
CUT_EDGE_MM = 0.1
#: An optical comparator (profile projector) with a measuring stage reads an edge point to (3 + L / 50) um
#: over a stage travel of L mm: the check of a template's edge against its drawing's coordinates. A typical
#: maker's figure, not a standard's: the XY stage accuracy profile-projector makers state for their 20x
#: measuring projectors ("(3 + 2L/100) um", as Mitutoyo's PJ-A3000 series lists it; taken from that
#: maker's catalogue as remembered, its table not read here). A shop's own comparator's calibration
#: certificate replaces it.
COMPARATOR_UM = (3.0, 1.0 / 50.0)
#: A template's edge may stand off its outline by at most this share of the smallest gap it must show: a
#: quarter, so that an edge error cannot turn a right gap into a leaf's wrong reading.
EDGE_SHARE = 0.25


def template_gaps(profile) -> list[float]:
    """The gaps (mm) a template must show, in the recipe's order: the bare print sanded to size (every layer up
    to and including the gauged one still to come), then after each layer up to the gauged one (0: flush)."""
    from rigcad.parts.templates import gauged_depth

    gap = float(sum(t for _, t in profile.coating.layers)) - gauged_depth(profile)
    out = [gap]
    for _, t in profile.coating.layers:
        if gap <= 1e-9:
            break
        gap -= t
        out.append(max(0.0, gap) if abs(gap) > 1e-9 else 0.0)
    return out


def template_making(profile, templates: list[dict]) -> list[dict]:
    """How each template (a :func:`template_datums` row) is made and checked: its material and sheet thickness
    (``templates.thickness``), the cut with CUT_EDGE_MM left on the gauging edge, the edge finished to its
    outline and checked on an optical comparator, whose accuracy over the template's width (COMPARATOR_UM)
    must be within the edge tolerance: EDGE_SHARE of the smallest non-zero gap the template shows (mm)."""
    gaps = template_gaps(profile)
    smallest = min(g for g in gaps if g > 1e-9) if any(g > 1e-9 for g in gaps) else 0.0
    tolerance = EDGE_SHARE * smallest
    out = []
    for row in templates:
        span = max(row["width_mm"], row["height_mm"])
        accuracy = 1e-3 * (COMPARATOR_UM[0] + COMPARATOR_UM[1] * span)
        out.append({"template": row["template"], "material": TEMPLATE_MATERIAL, "thickness_mm": profile.templates.thickness,
                    "cut_edge_mm": CUT_EDGE_MM, "gaps_mm": gaps, "smallest_gap_mm": smallest,
                    "edge_tolerance_mm": tolerance, "span_mm": span, "comparator_accuracy_mm": accuracy,
                    "checkable": accuracy <= tolerance})
    return out


def _uncheckable(row: dict) -> str:
    """What the manual says of a template whose comparator accuracy over its span is more than its edge
    tolerance: check it in sections short enough, or, when even a zero-length section's (COMPARATOR_UM's
    constant term) is more, that no comparator of that class can check it."""
    if row["checkable"]:
        return ""
    section = (row["edge_tolerance_mm"] * 1e3 - COMPARATOR_UM[0]) / COMPARATOR_UM[1]
    if section < 1.0:
        return (f" (**more than its {row['edge_tolerance_mm'] * 1e3:.1f} um edge tolerance, which is under the "
                f"comparator's own {COMPARATOR_UM[0]:g} um: no comparator of this class can check it; a coordinate "
                "measuring machine, or wider gaps (thicker coats in `coating.layers`)**)")
    return (f" (**more than its edge tolerance: check it in sections of at most {section:.0f} mm of stage travel, "
            "re-zeroed on the drawing between them**)")


def template_making_text(rows: list[dict]) -> str:
    """The manual's paragraph on making the templates, from :func:`template_making`'s rows."""
    if not rows:
        return ""
    r0 = rows[0]
    each = "; ".join(f"`{r['template']}` {r['span_mm']:.0f} mm across: {r['comparator_accuracy_mm']:.4f} mm"
                     + _uncheckable(r) for r in rows)
    gaps = ", ".join("flush" if g <= 1e-9 else f"{g:.3f} mm" for g in r0["gaps_mm"])
    return (f"**The templates' material and accuracy.** Each template is {r0['material']}, {r0['thickness_mm']:g} mm "
            f"(`templates.thickness`), laser or waterjet cut from its `outlines/<template>.dxf` with the cutter's path "
            f"half a kerf outside the outline and the gauging edge left {r0['cut_edge_mm']:g} mm proud (a cut edge "
            f"lands within about {r0['cut_edge_mm']:g} mm of its path, coarser than any gap it must show). The gauging "
            f"edge is then filed and stoned to its outline on an optical comparator (a profile projector with a "
            f"measuring stage, 20x), point by point against the drawing's coordinates, and the datum marked as its "
            f"drawing shows it. The gaps it must show are {gaps}: its edge must lie within "
            f"**{r0['edge_tolerance_mm']:.4f} mm** of the outline ({EDGE_SHARE:g} of the smallest gap, "
            f"{r0['smallest_gap_mm']:.3f} mm), and the comparator's stage reads to ({COMPARATOR_UM[0]:g} + "
            f"L/{1 / COMPARATOR_UM[1]:g}) um over L (a typical "
            f"maker's figure for a measuring projector's stage: your comparator's calibration certificate wins): {each}. "
            "A laser-cut edge unfinished, or one checked against a paper print (a printer places a line to about "
            "0.1 mm), cannot show these gaps.")


#: The two-component (2K) coats of LAYER_METHODS: each is bought with its own system's hardener and reducer
#: (thinner), by the product's data sheet. The most each can take by volume, as a share of the paint, for the
#: quantities to order: 2K polyurethane bases, primers and clears mix 2:1 to 4:1 paint : hardener (at most half the
#: paint's volume) and take up to 20 % reducer.
TWO_COMPONENT = ("black base paint", "polyurethane primer", "polyurethane clearcoat")
HARDENER_SHARE = 0.5
REDUCER_SHARE = 0.2


def paint_companions(coat_rows) -> list[tuple[str, str]]:
    """The consumables a 2K coat needs besides itself: per TWO_COMPONENT layer of ``coat_rows`` (the bill's
    coating rows: ``layer`` and ``to_buy_cm3`` per mirror), its hardener and its reducer, with the most the
    paint bought can take (ml, HARDENER_SHARE and REDUCER_SHARE of the paint's volume)."""
    paint: dict[str, float] = {}
    for r in coat_rows:
        if r["layer"] in TWO_COMPONENT:
            paint[r["layer"]] = paint.get(r["layer"], 0.0) + r["to_buy_cm3"]
    out = []
    for layer, ml in paint.items():
        out.append((f"Hardener (activator) of the {layer}'s own 2K system, mixed by its data sheet's ratio (2:1 to 4:1 "
                    f"paint : hardener by volume)", f"{math.ceil(HARDENER_SHARE * ml)} ml for the {ml:.0f} ml of paint (in proportion to what you mix)"))
        out.append((f"Reducer (thinner) of the {layer}'s own system, up to {100 * REDUCER_SHARE:g} % by its data sheet",
                    f"{math.ceil(REDUCER_SHARE * ml)} ml for the {ml:.0f} ml of paint (in proportion to what you mix)"))
    return out


def sanded_template(mirror: str) -> str:
    """The outline fab writes of the sanded-stage template that gauges ``mirror`` (rigcad.fab.stage's
    ``outlines/<template>_sanded.dxf``): its edge is the sanded surface, the design surface behind by the
    whole coating, the surface the coats go on."""
    from rigcad.fab.stage import TEMPLATE_MIRROR

    name = next(t for t, m in TEMPLATE_MIRROR.items() if m == mirror)
    return f"outlines/{name}_sanded.dxf"


def sanding_stop(gap_mm: float, mirrors=("dome", "paraboloid")) -> str:
    """The one rule that stops the knock-down of the print's staircase (section 3 and the recipe's first
    stage both state it): the guide coat gone from the valleys and the sanded-stage template
    (:func:`sanded_template`) flush along its whole edge, the thinnest feeler leaf (rigcad.fab.seams.
    FEELER_LEAF, mm) passing under it nowhere. The finished template (the gauged layer's surface) reads the
    same state as its gap ``gap_mm`` (mm: the layers up to and including the gauged one) all along it."""
    from rigcad.fab.seams import FEELER_LEAF

    files = " / ".join(f"`{sanded_template(m)}`" for m in mirrors)
    return (f"stop where the guide coat is gone from the valleys and the sanded-stage template ({files}, the "
            f"surface the coats go on) sits on its datum and fits flush along its whole edge: a {FEELER_LEAF:g} mm "
            "feeler leaf passes under it nowhere. Where a leaf does pass, that area is past the surface already: sand "
            f"it no more. (The finished template reads the same surface as the template's gap {gap_mm:.3f} mm "
            f"({gap_mm / 0.0254:.1f} mil) all along it: one rule, two gauges.)")


def recipe(profile, stock_mm: dict[str, float] | None = None) -> list[tuple[str, str, str, str, str]]:
    """The finishing recipe, stage by stage, from print to mirror: (stage, what, how, cure / wait, check).

    One recipe for the profile's ``coating.layers`` in their order, nothing else sprayed: knock the
    staircase down to the template (the print stands forward by its sanding stock, ``stock_mm`` by
    mirror), then each coat, with the template's check after each up to the gauged layer, and the slope
    test on the polished coat before the last (the mirror) coat goes on."""
    from rigcad.parts.templates import gauged_depth

    layers = list(profile.coating.layers)
    total = float(sum(t for _, t in layers))
    gap = total - gauged_depth(profile)
    stock = "" if not stock_mm else " (" + ", ".join(f"{k} {v:.3f} mm" for k, v in stock_mm.items()) + " of stock)"
    rows = [("1. Knock down the layer lines", "SiC abrasive film P120, P240, P400 (ISO 6344) on the printed sanding "
             "blocks below", "wet, a drop of soap in the water; strokes around the axis, each block within its "
             "slide along the meridian", "-",
             f"the print's staircase gone (dry black powder as guide coat, e.g. 3M 05861){stock}: "
             + sanding_stop(gap, tuple(stock_mm) if stock_mm else ("dome", "paraboloid")))]
    for k, (name, t) in enumerate(layers):
        gap -= t
        what, how, cure = LAYER_METHODS.get(name, (name, "as its maker's data sheet says", "per data sheet"))
        if k == len(layers) - 1 and len(layers) > 1:
            rows.append((f"{k + 2}. Slope test before the mirror coat", "the optical acceptance test below, on the "
                         "polished coat", "the rig assembled as for the test; the polished coat reflects about "
                         f"{100 * CLEAR_REFLECTANCE:g} % where the mirror coat will reflect "
                         f"{100 * profile.coating.reflectance:.0f} % (`coating.reflectance`): light the disc brighter "
                         f"or expose {(profile.coating.reflectance / CLEAR_REFLECTANCE) ** 2:.0f} times longer (two "
                         "reflections)", "-", "pass as below; a black patch: block and polish that area again, never "
                         "under the mirror coat"))
            k += 1
        check = ("template flush along its whole edge" if abs(gap) < 1e-9 else
                 f"template gap {gap:.3f} mm ({gap / 0.0254:.1f} mil)" if gap > 0 else
                 "past the gauged layer: do not force the template")
        rows.append((f"{k + 2}. {name} ({t / 0.0254:g} mil)", what, how, cure, check))
    return rows


__all__ = ["ABRASIVE", "ABRASIVE_MM", "BLOCK_LENGTH_MM", "BLOCK_SAG_MM", "block_bands", "block_part", "block_slide",
           "sanding_block_set", "sanded_template", "sanding_stop", "template_datums", "template_text", "CLEAR_REFLECTANCE", "LAYER_METHODS", "principal_radii", "recipe",
           "placement_spot", "sanding_blocks", "slope_acceptance", "COMPARATOR_UM", "CUT_EDGE_MM",
           "EDGE_SHARE", "TEMPLATE_MATERIAL", "template_gaps", "template_making", "template_making_text",
           "HARDENER_SHARE", "REDUCER_SHARE", "SLOPE_PASS_FRACTION", "STRAIGHTEDGES_MM", "STRAIGHTEDGE_OVERHANG_MM", "TWO_COMPONENT", "paint_companions"]
