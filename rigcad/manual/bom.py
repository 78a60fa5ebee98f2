"""The bill of materials, computed: printed pieces (with time and filament from the fab stage's
report), cut templates, bolts, nuts and washers (their size and length from the flange and the
plate), dowel pins (their count from the fab stage's split, their size from the printer), the
purchased optics and instruments named by the profile, and the paint and clearcoat volumes (the
mirror areas from the part recipes' mirror meridians, times each coating layer's thickness, times
``coating.margin``).

Nothing is typed in twice: a part added to ``rigcad.parts`` appears in the printed list, a mirror
added to a recipe adds its area to the paint, a printer that splits the dome differently changes
the pin count. Units: mm, mm^2, cm^3 (ml), g, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigcad import standards
from rigcad.errors import GeometryError

# -- fasteners (their figures: rigcad.standards, the one home of them) ------------------------------
#: A bolt shows at least this many thread pitches beyond its nut (common practice: 1-2 pitches).
PROTRUSION_PITCHES = 2
#: A dowel pin is cut this much (mm) shorter than its two holes' depths together (2 x alignment_pin.depth),
#: so that an end sitting on a hole's bottom (and its burr) never holds the cut faces apart.
PIN_END_GAP_MM = 0.5


def thread_for_hole(hole: float) -> standards.Thread:
    """The largest ISO metric thread whose medium clearance hole (ISO 273) fits in ``hole`` mm."""
    try:
        return standards.thread_for_hole(hole)
    except ValueError as err:
        raise GeometryError(str(err), param="dome_shell.bolt_diameter") from err


def bolt_length(grip: float, thread: standards.Thread) -> tuple[int, float]:
    """The shortest preferred length (mm) for a bolt of ``thread`` through ``grip`` mm of parts with a
    washer under its head and under its nut, and PROTRUSION_PITCHES pitches beyond the nut; and the
    length needed."""
    need = grip + 2 * thread.washer_thickness + thread.nut_height + PROTRUSION_PITCHES * thread.pitch
    length = standards.shortest_screw(thread.name, need)
    if length is None:
        raise GeometryError(f"{thread.name} bolts of {need:.1f} mm are longer than the longest ISO 4762 length "
                            f"({standards.screw_lengths(thread.name)[-1]} mm): the flange and plate are too thick",
                            param="base_plate.thickness")
    return length, need


# -- mirror areas and coating ---------------------------------------------------------------------
def revolved_area(meridian, samples: int = 20001) -> float:
    """Area (mm^2) of the surface swept by ``meridian`` (r, z) over its parameter range, revolved a
    full turn about z: 2 pi * integral of r ds (midpoint rule on ``samples`` points; second order:
    1e-9 relative at the default, checked against the paraboloid's closed form)."""
    p = meridian.points(meridian.sample(samples))
    ds = np.linalg.norm(np.diff(p, axis=0), axis=1)
    r_mid = 0.5 * (p[1:, 0] + p[:-1, 0])
    return float(2 * math.pi * np.sum(np.abs(r_mid) * ds))


@dataclass(frozen=True)
class CoatRow:
    """One coating layer on one mirror: where its top lies behind the design surface (mm), the
    area it covers (mm^2), its film volume and the volume to have at hand (cm^3 = ml)."""

    layer: str
    mirror: str
    part: str
    thickness_mm: float
    top_behind_design_mm: float
    area_mm2: float
    film_cm3: float
    to_buy_cm3: float


def coating_rows(rig) -> list[CoatRow]:
    """Every coating layer (``coating.layers``, bottom to top) on every mirror the part recipes
    carry (``Part.mirrors``: design meridians). A layer's area is that of its own mid-surface
    (behind the design surface by the layers above it plus half its own thickness)."""
    layers = rig.profile.coating.layers
    margin = rig.profile.coating.margin
    rows = []
    for part_name, part in rig.recipes.items():
        for mirror, design in part.mirrors:
            above = float(sum(t for _, t in layers))
            for name, t in layers:
                above -= t
                area = revolved_area(design.behind(above + t / 2))
                film = area * t / 1000.0
                rows.append(CoatRow(name, mirror, part_name, t, above, area, film, film * margin))
    return rows


# -- the bill -------------------------------------------------------------------------------------
#: Holes cut into a part's recipe run this far (mm) past each face it goes through (the recipes'
#: convention, so that the boolean leaves no skin): a bolt's grip is the holes' joint span less twice it.
HOLE_OVERSHOOT_MM = 1.0
#: A vertical cut counts as a bolt hole (or slot) when it is at most this wide (mm) in x and y: the
#: bore for the sample holder and the hole that passes the projector's bundle are wider.
BOLT_HOLE_MAX_MM = 16.0


def _holes(solid, offset=(0.0, 0.0, 0.0), cut=False):
    """Vertical bolt holes and slots cut into a recipe: (x, y, z0, z1, width, round) per hole, mm."""
    from rigcad.parts.recipe import Box, Cylinder, Difference, Translate, Union_

    off = np.asarray(offset, float)
    if isinstance(solid, Difference):
        yield from _holes(solid.base, off, cut)
        for c in solid.cuts:
            yield from _holes(c, off, True)
    elif isinstance(solid, Union_):
        for c in solid.items:
            yield from _holes(c, off, cut)
    elif isinstance(solid, Translate):
        yield from _holes(solid.solid, off + np.asarray(solid.offset, float), cut)
    elif cut and isinstance(solid, Cylinder) and 2 * solid.radius <= BOLT_HOLE_MAX_MM:
        b = np.asarray(solid.base, float) + off
        yield (b[0], b[1], b[2], b[2] + solid.height, 2 * solid.radius, True)
    elif cut and isinstance(solid, Box):
        lo, hi = np.asarray(solid.lo, float) + off, np.asarray(solid.hi, float) + off
        w = hi - lo
        if w[0] <= BOLT_HOLE_MAX_MM and w[1] <= BOLT_HOLE_MAX_MM and w[2] < max(w[0], w[1]) * 4:
            yield ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2], hi[2], min(w[0], w[1]), False)


def _own_rows(rig) -> list[tuple[float, float]]:
    """Hole axes (x, y; mm) whose fasteners another module lists: the breadboard's screws, the joints
    the parts declare (``Part.joints``), and the column's joint in the base plate's tongue (bolts,
    dowels, or a bought extrusion's core screw)."""
    from rigcad.parts import breadboard

    out = ([q for qs in breadboard.anchor_points(rig.profile, rig.layout).values() for q in qs]
           if breadboard.board(rig.profile) else [])
    out += [q for part in rig.recipes.values() for j in part.joints for q in j.points]  # declared: plan fits them
    t = getattr(rig.layout, "tower", None)
    if t is not None:
        from rigcad.parts.tower import _column_flange_points, column_dowel_points

        out += ([*_column_flange_points(t, rig.profile), *column_dowel_points(t, rig.profile)]
                if rig.profile.buy.column == "print" else [(t.column_x, 0.0)])
    return out


def bolt_axes(rig, tower: bool = False) -> list[dict]:
    """Every bolt of the rig, found in the recipes: vertical holes of the in-rig printed parts that
    share an axis (x, y within 0.05 mm) and touch in z are one bolt through those parts; a round hole
    of one part alone is a bolt into what it stands on (the bench). One dict per bolt: the parts it
    joins (sorted), x and y, the z of its top and bottom faces, its grip and the narrowest hole (mm).
    The COP tower's parts are left out unless ``tower`` (their counts have their own home:
    tower_hardware)."""
    try:
        from rigcad.parts.tower import TOWER_PARTS
    except ImportError:  # pragma: no cover - a rig without the tower module
        TOWER_PARTS = ()
    # a breadboard's screws and the tower's joints in the base plate's tongue have their own rows
    # (breadboard.hardware, tower.hardware): not bolts found here
    board = _own_rows(rig) if not tower else []
    holes = []
    for name, part in rig.recipes.items():
        if part.in_rig and (tower or name not in TOWER_PARTS):
            holes += [(name, *h) for h in _holes(part.solid)
                      if not any(abs(h[0] - x) < 0.05 and abs(h[1] - y) < 0.05 for x, y in board)]
    axes: dict[tuple, list] = {}
    for h in holes:
        axes.setdefault((round(h[1] / 0.05), round(h[2] / 0.05)), []).append(h)
    out = []
    for key in sorted(axes):
        stack = sorted(axes[key], key=lambda h: (h[3], h[0]))
        runs, run = [], [stack[0]]
        for h in stack[1:]:
            if h[3] <= max(r[4] for r in run) + 1e-6:
                run.append(h)
            else:
                runs.append(run)
                run = [h]
        runs.append(run)
        for run in runs:
            parts = tuple(sorted({h[0] for h in run}))
            if len(parts) == 1 and not all(h[6] for h in run):
                continue  # a slot or channel of one part alone (a clamp, the projector's slots): no bolt of its own
            top, bottom = max(h[4] for h in run) - HOLE_OVERSHOOT_MM, min(h[3] for h in run) + HOLE_OVERSHOOT_MM
            upper = max(run, key=lambda h: (h[4], h[0]))[0]
            spans = {n: (min(h[3] for h in run if h[0] == n) + HOLE_OVERSHOOT_MM,
                         max(h[4] for h in run if h[0] == n) - HOLE_OVERSHOOT_MM) for n in parts}
            out.append({"parts": parts, "upper": upper, "spans": spans, "x": run[0][1], "y": run[0][2], "top_z": top,
                        "bottom_z": bottom, "grip_mm": top - bottom, "hole_mm": min(h[5] for h in run)})
    return out


def bolt_joints(rig) -> list[dict]:
    """Every bolted joint of the rig outside the COP tower (whose joints the tower module computes:
    tower_hardware), from :func:`bolt_axes`. Grouped by (parts joined, thread, length): count, grip,
    the bolt, its nut and washers."""
    groups: dict[tuple, dict] = {}
    for b in bolt_axes(rig):
        key = (b["parts"], round(b["grip_mm"], 3), round(b["hole_mm"], 3))
        groups.setdefault(key, {"parts": b["parts"], "grip_mm": b["grip_mm"], "hole_mm": b["hole_mm"],
                                "count": 0})["count"] += 1
    rows = []
    for g in sorted(groups.values(), key=lambda g: (-len(g["parts"]), g["parts"], g["grip_mm"])):
        th = thread_for_hole(g["hole_mm"])
        thread = th.name
        alone = len(g["parts"]) == 1
        row = {**g, "thread": thread, "joins": " + ".join(g["parts"]) + (" to what it stands on" if alone else "")}
        if alone:  # into the bench or a part's slot: the user's fixing; the grip is what a bolt passes
            row.update(item=f"{thread} bolt, length to suit (passes {g['grip_mm']:g} mm of {g['parts'][0]})",
                       short=f"{thread} bolts", length_mm=None, nuts=0, washers=g["count"],
                       note="into the bench (or what the part stands on): choose its length on site")
        else:
            length, need = bolt_length(g["grip_mm"], th)
            row.update(item=f"{thread} x {length} mm socket-head bolt (ISO 4762)", short=f"{thread} x {length} mm bolts",
                       length_mm=length, nuts=g["count"], washers=2 * g["count"],
                       note=f"needs {need:.1f} mm: {g['grip_mm']:g} mm grip + 2 washers + nut {th.nut_height:g} mm + "
                            f"{PROTRUSION_PITCHES} pitches")
        rows.append(row)
    return rows


def tower_hardware(rig) -> list[dict]:
    """The COP tower's bolts and screws as the tower computes them (``rigcad.parts.tower.hardware``,
    the one home of the tower's joints: bracket, shims, slots); its optics are listed with the
    profile's instruments. Empty for a rig without a tower."""
    if getattr(rig.layout, "tower", None) is None:
        return []
    from rigcad.parts.tower import hardware

    return [h for h in hardware(rig.profile, rig.layout) if "spec" not in h]  # the optics: the purchased rows


def tower_item(h: dict) -> str:
    """A tower hardware row's item as it is ordered: thread and length, or its size."""
    if h.get("thread"):
        return f"{h['thread']} x {h['length_mm']:g} mm {h['item']}" if h.get("length_mm") else f"{h['item']} ({h['thread']})"
    size = ([h["diameter_mm"]] if h.get("diameter_mm") else []) + ([h["length_mm"]] if h.get("length_mm") else [])
    return f"{h['item']}, " + " x ".join(f"{v:g}" for v in size) + " mm" if size else h["item"]


def fasteners(rig) -> list[dict]:
    """Bolts, nuts and washers of every bolted joint (bolt_joints), then the tower's (tower_hardware)."""
    rows = []
    for j in bolt_joints(rig):
        rows.append({"item": j["item"], "short": j["short"], "quantity": j["count"], "use": j["joins"],
                     "length_mm": j["length_mm"], "note": j["note"], "thread": j["thread"]})
    nuts: dict[str, int] = {}
    washers: dict[str, int] = {}
    for j in bolt_joints(rig):
        nuts[j["thread"]] = nuts.get(j["thread"], 0) + j["nuts"]
        washers[j["thread"]] = washers.get(j["thread"], 0) + j["washers"]
    for thread, n in nuts.items():
        if n:
            rows.append({"item": f"{thread} hex nut (ISO 4032)", "short": f"{thread} nuts", "quantity": n,
                         "use": "one per through bolt", "length_mm": None,
                         "note": f"{standards.THREADS[thread].nut_height:g} mm high"})
    for thread, n in washers.items():
        if n:
            rows.append({"item": f"{thread} washer (ISO 7089)", "short": f"{thread} washers", "quantity": n,
                         "use": "under each bolt head and nut", "length_mm": None,
                         "note": f"{standards.THREADS[thread].washer_thickness:g} mm thick"})
    from rigcad.parts import breadboard

    for h in breadboard.hardware(rig.profile, rig.layout):
        rows.append({"item": h["item"], "short": h["item"], "quantity": h["quantity"], "use": h["joins"],
                     "length_mm": h["length_mm"], "note": "on the breadboard's grid (parts.breadboard)",
                     "thread": h["thread"]})
    for h in tower_hardware(rig):
        item = tower_item(h)
        rows.append({"item": item, "short": item, "quantity": h["quantity"],
                     "use": h["joins"], "length_mm": h.get("length_mm"), "note": "COP tower (parts.tower.hardware)",
                     "thread": h["thread"], "tower": True, "steps": list(h.get("steps", ()))})
    from rigcad.parts.paraboloid import hardware as stop_hardware

    for h in stop_hardware(rig.profile, rig.layout) if "paraboloid" in (getattr(rig, "recipes", None) or {}) else ():
        item = tower_item(h)
        rows.append({"item": item, "short": item, "quantity": h["quantity"], "use": h["joins"],
                     "length_mm": h.get("length_mm"), "thread": h["thread"], "steps": list(h["steps"]),
                     "note": "the paraboloid's shim stops and the beam's seats (parts.paraboloid.hardware)",
                     "stops": True})
    return rows


def dowel_pins(fab_report: dict, printer) -> dict | None:
    """The dowel pins the split pieces need: count (pins per part x the part's quantity), diameter and
    cut length from the printer's alignment_pin; None when no part is split."""
    count = sum(len(e.get("pins", [])) * e.get("quantity", 1) for e in fab_report["parts"].values())
    if not count:
        return None
    pin = printer.alignment_pin
    length = 2 * pin.depth - PIN_END_GAP_MM
    per_part = {n: len(e["pins"]) * e.get("quantity", 1) for n, e in fab_report["parts"].items() if e.get("pins")}
    filament = math.isclose(pin.diameter, getattr(printer, "filament_diameter", float("nan")) or float("nan"))
    by_d: dict[float, int] = {}  # a thin shell takes thinner pins than the printer's (fab.json's pins)
    for e in fab_report["parts"].values():
        for p in e.get("pins", []):
            d = float(p.get("diameter_mm") or pin.diameter) if isinstance(p, dict) else pin.diameter
            by_d[d] = by_d.get(d, 0) + e.get("quantity", 1)
    sizes = " and ".join(f"{k} x {d:g} mm" for d, k in sorted(by_d.items(), reverse=True)) if len(by_d) > 1 else ""
    return {"item": f"dowel pin {pin.diameter:g} mm x {length:g} mm" if not sizes else
            f"dowel pins {length:g} mm long: {sizes}", "quantity": count,
            "diameter_mm": pin.diameter, "length_mm": length, "per_part": per_part,
            "by_diameter_mm": {f"{d:g}": k for d, k in sorted(by_d.items(), reverse=True)},
            "use": ", ".join(f"{n}: {k}" for n, k in per_part.items()),
            "note": (f"holes {_pin_holes(fab_report)} x {pin.depth:g} mm deep into each piece "
                     f"(alignment_pin in {printer.source}; a split mirror's wider: its seams are glued on a gauge)"
                     + (("; cut from the printer's own filament" if not sizes else
                         f"; the {pin.diameter:g} mm ones cut from the printer's own filament, the others bought") if filament
                        else ""))}


def _pin_holes(fab_report: dict) -> str:
    """The split parts' pin holes as drawn (fab.json's ``pin_fit``), each with its parts."""
    by: dict[float, list[str]] = {}
    for n, e in fab_report["parts"].items():
        if e.get("pin_fit"):
            by.setdefault(round(e["pin_fit"]["hole_drawn_mm"], 3), []).append(n)
    return ", ".join(f"{h:g} mm ({', '.join(ns)})" for h, ns in sorted(by.items()))


def glue_rows(fab_report: dict) -> list[tuple[str, str]]:
    """The glues the split parts' cut faces need (fab.json's ``seams``: rigcad.fab.seams.glue_for),
    each with the parts it joins; the pins are set in the same glue."""
    by: dict[str, list[str]] = {}
    for n, e in fab_report["parts"].items():
        if e.get("seams"):
            by.setdefault(e["seams"]["glue"], []).append(n)
    return [(f"{g[:1].upper() + g[1:]}, for the cut faces and pins of {', '.join(ns)}", "1") for g, ns in by.items()]


def printed(rig, fab_report: dict) -> list[dict]:
    """One row per part of the fab report: printed pieces with time and material (the slicer's when
    G-code was made, else rigcad's estimate), or the plate a template is cut from."""
    rows = []
    for name, e in fab_report["parts"].items():
        part = rig.recipes.get(name)
        use = "rig" if part is not None and part.in_rig else "tool"
        if "error" in e:
            rows.append({"part": name, "use": use, "quantity": None, "process": "not printable", "note": e["error"]})
            continue
        if e.get("process") == "bought":  # the profile's buy: stock to order, nothing printed or cut
            rows.append({"part": name, "use": use, "quantity": e["quantity"], "process": "bought",
                         "pieces": 0, "time_s": None, "material_g": None, "source": None, "note": e["stock"]})
            continue
        if "pieces" not in e:
            rows.append({"part": name, "use": use, "quantity": e["quantity"], "process": e["process"],
                         "pieces": 0, "time_s": None, "material_g": None, "source": None,
                         "note": f"{e['plate_thickness_mm']:g} mm plate, outline {e['outline_size_mm'][0]:.1f} x "
                                 f"{e['outline_size_mm'][1]:.1f} mm (fab outlines/{name}.dxf, .svg)"})
            continue
        pcs = e["pieces"]
        sliced = all("gcode" in pc and pc["gcode"].get("estimates", {}).get("print_time_s") for pc in pcs)
        t = sum(pc["gcode"]["estimates"]["print_time_s"] if sliced else pc["estimate"]["print_time_s"] for pc in pcs)
        g = sum((pc["gcode"]["estimates"].get("filament_g") or pc["estimate"]["material_g"]) if sliced
                else pc["estimate"]["material_g"] for pc in pcs)
        q = e["quantity"]
        rows.append({"part": name, "use": use, "quantity": q, "process": e["process"], "pieces": len(pcs),
                     "time_s": t * q, "material_g": g * q, "source": "slicer" if sliced else "rigcad estimate",
                     "note": ", ".join(sorted({pc["orientation"] for pc in pcs}))})
    return rows


def purchased(rig) -> list[dict]:
    """Optics and instruments the profile names (its projector and camera; with the COP tower, the
    beam splitter and the lens): one row each, every figure from the profile."""
    p = rig.profile
    chosen = getattr(p, "instrument", lambda *k: None)  # the instrument file the profile names, if any
    rows = []
    for section in ("projector", "camera", "beam_splitter", "splitter", "lens"):
        obj = getattr(p, section, None)
        if obj is None:
            continue
        inst = chosen(section, "model")
        rows.append({"item": _ITEMS.get(section, section.replace("_", " ")) + (f": {inst.title}" if inst else ""),
                     "quantity": 1, "spec": _lead(rig, section) + _describe(obj, p, section),
                     "source": p.where(section, _first_field(obj)) or "default"})
        lens = chosen(section, "lens") if section == "camera" else None
        if lens:
            rows.append({"item": f"camera lens: {lens.title}", "quantity": 1, "source": lens.file,
                         "spec": "; ".join(f"{k.replace('_', ' ')} {v}" for k, v in lens.figures.items())})
    return rows


#: What a profile section is, as one orders it.
_ITEMS = {"lens": "focusing lens", "beam_splitter": "plate beam splitter"}


def _lead(rig, section: str) -> str:
    """What an optic's row says before the profile's figures: the catalogue line the tower states for it
    (rigcad.parts.tower.hardware: the focusing lens's focal length from rigcad.optics.focus and which
    way it faces; the splitter's ratio and its coated face), the one home of those facts."""
    if getattr(getattr(rig, "layout", None), "tower", None) is None:
        return ""
    from rigcad.parts.tower import hardware

    item = {"lens": "focusing lens", "beam_splitter": "plate beam splitter"}.get(section)
    row = next((h for h in hardware(rig.profile, rig.layout) if h["item"] == item), None)
    return f"**{row['spec']}** ({row['joins']}); " if row else ""


def _first_field(obj) -> str:
    from dataclasses import fields

    return fields(obj)[0].name


def _describe(obj, profile=None, section: str = "") -> str:
    """A one-line description of a profile section: every field with its unit, "(assumed)" on a
    field whose doc says so and that neither the profile nor an instrument file set
    (``profile.set_by``)."""
    from dataclasses import fields

    from rigcad.units import DEG

    out = []
    for f in fields(obj):
        spec = f.metadata.get("spec")
        v = getattr(obj, f.name)
        if v is None:
            continue
        kind = getattr(spec, "kind", "")
        if kind == "length":
            text = f"{v:.4g} mm"
        elif kind == "angle":
            text = f"{v / DEG:.4g} deg"
        elif kind == "mass":
            text = f"{v:.4g} kg"
        elif kind == "pixels":
            text = f"{v[0]} x {v[1]} px"
        else:
            text = str(list(v) if isinstance(v, tuple) else v)
        set_by = getattr(profile, "set_by", None)
        assumed = ("assumed" in (getattr(spec, "doc", "") or "").lower()
                   and (set_by is None or set_by(section, f.name) == "default"))
        out.append(f"{f.name.replace('_', ' ')} {text}" + (" (assumed)" if assumed else "")
                   + _inherited(profile, section, f.name))
    return "; ".join(out)


def _inherited(profile, section: str, key: str) -> str:
    """" (set in FILE:LINE, not with the model)" for a figure a profile file set other than the file that
    chose the section's instrument (``section.model``): a base profile's figure for its own instrument
    (its throw ratio) that a profile extending it inherits with another model; "" otherwise."""
    here = profile.apart_from_model(section, key) if hasattr(profile, "apart_from_model") else None
    return f" (set in `{here}`, not with the model: check it is this {section.replace('_', ' ')}'s)" if here else ""


def bill(rig, fab_report: dict, printer) -> dict:
    """Every list of the bill, for the manual (units in the keys)."""
    coats = coating_rows(rig)
    layers: dict[str, dict] = {}
    for c in coats:
        row = layers.setdefault(c.layer, {"layer": c.layer, "thickness_mm": c.thickness_mm, "film_cm3": 0.0,
                                          "to_buy_cm3": 0.0, "area_mm2": 0.0})
        row["film_cm3"] += c.film_cm3
        row["to_buy_cm3"] += c.to_buy_cm3
        row["area_mm2"] += c.area_mm2
    mirrors = {}
    for c in coats:
        mirrors.setdefault(c.mirror, {"mirror": c.mirror, "part": c.part, "design_area_mm2": None})
    for part in rig.recipes.values():
        for mirror, design in part.mirrors:
            mirrors[mirror]["design_area_mm2"] = revolved_area(design)
    return {"printed": printed(rig, fab_report), "fasteners": fasteners(rig), "pins": dowel_pins(fab_report, printer),
            "purchased": purchased(rig), "coating": list(layers.values()), "coating_by_mirror": [c.__dict__ for c in coats],
            "mirrors": list(mirrors.values()), "coating_margin": rig.profile.coating.margin,
            "totals": fab_report.get("totals", {})}


__all__ = ["bill", "bolt_axes", "bolt_joints", "bolt_length", "coating_rows", "dowel_pins", "fasteners", "printed", "purchased",
           "revolved_area", "thread_for_hole", "tower_hardware", "tower_item"]


# -- consumables and tools ------------------------------------------------------------------------
#: Consumables with an orderable spec (standard or product class); the paint itself is the profile's.
CONSUMABLES = (
    ("Wet-or-dry silicon carbide paper, P120 P240 P400 P600 P800 P1000 P1500 P2000 P3000 (ISO 6344), 230 x 280 mm "
     "sheets", "2 sheets of each"),
    ("Dry guide coat powder (black, e.g. 3M 05861) with its applicator", "1"),
    ("Cutting compound and finishing polish (automotive, e.g. 3M 06085 + 06068 class), 250 ml each", "1 each"),
    ("Foam polishing pads, 75 mm, cutting and finishing", "2 each"),
    ("Isopropyl alcohol 99 %, 500 ml, and lint-free wipes (degreasing before each coat)", "1"),
    ("Tack cloths", "5"),
    ("Wicking threadlocker, low strength (Loctite 290 class), 10 ml: locks the splitter seat's push screws once set",
     "1"),
    ("Retaining compound, high strength (Loctite 638 class), 10 ml: the registers' dowel pins in their reamed "
     "holes, the beam's stop pin in its slip-fit hole, the seat screws' balls in their cups", "1"),
    ("Cyanoacrylate glue, medium viscosity, 20 g: a drop in each nut trap before its nut goes in", "1"),
    ("Packing tape, polypropylene, 48 mm, 1 roll: over the base plate under the dome's seams while they are glued",
     "1"),
)
#: The glue faces' lapping straightedge (mm), in TOOLS; a template read against a straightedge of that
#: length uses the same one (:func:`template_straightedge`).
LAPPING_STRAIGHTEDGE_MM = 300.0
#: Tools with an orderable spec.
TOOLS = (
    ("Digital caliper 150 mm, 0.01 mm (DIN 862)", "1"),
    ("Engineer's square 100 mm (DIN 875, grade 1)", "1"),
    ("Spirit level 200 mm, 0.3 mm/m", "1"),
    ("Hex screwdrivers 2.5, 3, 4 mm and 3/16 in, 100 mm blades; L hex key set (ISO 2936)", "1 set"),
    ("Open-end spanners 5.5, 7, 8 mm (DIN 3110)", "1 set"),
    ("Torque screwdriver 0.2-3 N m with hex bits 2.5, 3, 4 mm and 3/16 in (ISO 6789)", "1"),
    ("Soldering iron with a heat-set insert tip (M3, M4)", "1"),
    ("HVLP spray gun 1.3-1.4 mm nozzle and a compressor (or aerosol cans only)", "1"),
    ("Respirator, half mask with A2P3 filters (EN 14387); supplied-air hood for 2K isocyanate coats", "1"),
    ("Nitrile gloves and safety glasses (EN 166)", "1 box / 1"),
    ("Sanding blocks: flat rubber block and blocks curved to the mirrors' radii (section 3)", "see section 3"),
    ("Tin snips, straight cut, and scissors (the shim stock and the shim foil)", "1 each"),
    ("Files: a 150 mm flat file (cut 2) and a needle file set, flat and round (slots, deburring)", "1 set"),
    (f"Float glass plate 300 x 300 x 6 mm and a steel straightedge {LAPPING_STRAIGHTEDGE_MM:g} mm (DIN 874, grade 1), "
     "for lapping glue "
     "faces flat", "1 each"),
    ("Drill press with a depth stop and a vise for it: the dowels' blind holes are drilled and machine-reamed "
     "in the drill press at low speed (a machine reamer's short lead sizes a blind hole; a hand reamer's long taper cannot); "
     "a hand drill for the holes drilled in place through a part that guides it; a tap wrench to turn the hand "
     "reamer of a pin set in retaining compound", "1 each"),
    ("Bench vise with soft jaws and a soft-faced hammer (pressing dowel pins and balls in)", "1 each"),
    ("Lathe (bench lathe whose chuck takes the holder's bar) with turning and parting tools and a boring bar, "
     "for the sample holder; the base plate's H7 bore is bored with the boring bar on the lathe's faceplate, or "
     "with a boring head on a mill", "1 (or a machine shop)"),
    ("Outside micrometer covering the sample holder's diameter (25-50 mm for the default's 40 mm), 0.001 mm "
     "(DIN 863): the holder's f7 body", "1"),
    ("Airbrush 0.3-0.5 mm, or an HVLP gun with a 0.8-1.0 mm nozzle at about 1 bar: the MirraChrome coat "
     "(its maker's low-pressure spray)", "1"),
)
#: The words section 2-6 name a tool by (lower case, as a word): each must be in some line of the tools
#: (or of the calibration kit), so a tool a step uses and the bill forgets shows (tests/manual).
TOOL_WORDS = ("caliper", "engineer's square", "spirit level", "hex key", "spanner", "torque screwdriver",
              "soldering iron", "feeler", "tin snips", "scissors", "file", "float glass", "straightedge", "drill",
              "reamer", "machine reamer", "drill press", "gauge pin",
              "dial test indicator", "vise", "hammer", "scalpel", "circle cutter", "leather punch", "lathe",
              "boring bar", "boring head", "micrometer", "airbrush")


def feeler_gauge(gaps_mm: list[float]) -> tuple[str, str]:
    """A feeler gauge set (DIN 2275 / ISO 2768 leaves) with the leaves the template checks need: the
    gaps rounded to the set's 0.01 mm steps; a gap under 0.02 mm (the thinnest leaf) is checked
    against the light instead."""
    from rigcad.fab.seams import FEELER_LEAF

    leaves = sorted({round(g, 2) for g in gaps_mm if g >= FEELER_LEAF})
    return (f"Feeler gauge set 0.02-1.00 mm in 0.01 mm steps (DIN 2275); leaves used: "
            + (", ".join(f"{v:.2f}" for v in leaves) + " mm" if leaves else "none (check against the light)"),
            "1")


def dowel_drills(fab_report: dict, rig=None) -> tuple[str, str]:
    """The drills for the split pieces' pin holes (each part's hole as drawn, fab.json's ``pin_fit``), and
    with ``rig`` the drill and the press and slip ends' reamers of the COP tower's dowels (``datum.dowel_diameter``,
    rigcad.parts.locating.reamers)."""
    from rigcad.parts.locating import reamers

    holes = _pin_holes(fab_report)
    dowel = getattr(getattr(getattr(rig, "profile", None), "datum", None), "dowel_diameter", None)
    tower = getattr(getattr(rig, "layout", None), "tower", None) is not None
    return (f"HSS twist drills (DIN 338) for the pin holes: {holes or 'none'}"
            + (f"; for the column's dowel holes {reamers(dowel)}" if dowel and tower else "") + _stop_pin_tools(rig),
            "1 each")


def _stop_pin_tools(rig) -> str:
    """The drill and the reamer of the paraboloid's stop pin's hole in the beam (a slip fit set in retaining
    compound: rigcad.parts.paraboloid)."""
    if "paraboloid" not in (getattr(rig, "recipes", None) or {}):
        return ""
    from rigcad.parts.locating import slip_fit
    from rigcad.parts.paraboloid import mount
    from rigcad.standards import pre_ream_drill

    d = 2 * mount(rig.profile, rig.layout).pin.radius
    return (f"; for the beam's stop pin a {pre_ream_drill(d):g} mm twist drill (DIN 338) and a {d:g} mm "
            f"{slip_fit(d).hole} hand reamer")


def register_tools(rig) -> list[tuple[str, str]]:
    """The tools each locating register needs (rigcad.parts.locating.DowelRegister, read from the parts'
    joints): its pins' drill and reamers (``locating.reamers``), and for a register drilled in place (the
    part indicated in first) the dial test indicator that centres it."""
    from rigcad.parts import locating

    out = []
    for part in rig.recipes.values():
        for reg in part.joints:
            if not isinstance(reg, locating.DowelRegister):
                continue
            tools = locating.reamers(reg.diameter)
            out.append((f"For the {reg.upper.replace('_', ' ')}'s register on the {reg.lower.replace('_', ' ')} "
                        f"({len(reg.points)} x {reg.diameter:g} mm pins): {tools}; a dial test indicator of "
                        f"{locating.REPEAT_INDICATOR_MM:g} mm graduation (DIN 2270) that reads its return", "1 each"))
            if reg.drilled:
                out.append(("Dial test indicator, 0.01 mm graduation (DIN 2270), on an articulated arm clamped to "
                            "the sample holder (turned to its sliding fit in the bore), which turns in the bore: it "
                            f"centres the {reg.upper.replace('_', ' ')} before its register is drilled", "1"))
    return out


def template_straightedge(rig) -> tuple[str, str] | None:
    """The steel straightedge the templates whose datum is the base's corner are read against
    (rigcad.manual.finishing.straightedge: the longest such template's, laid across the part's base), or None
    when no template needs one."""
    from rigcad.manual import finishing as F

    rows = [r for r in F.template_datums(rig) if r["datum"] not in ("rim", "edge")]
    if not rows:
        return None
    rule, reach = F.straightedge(max(rows, key=lambda r: r["datum_r_mm"]))
    names = ", ".join(f"`{r['template']}`" for r in rows)
    if rule == LAPPING_STRAIGHTEDGE_MM:
        return (f"The lapping straightedge ({rule:g} mm, above) also reads the datum of {names}, laid across the "
                "base", "(same)")
    size = f"{rule:g} mm" if rule else f"at least {reach:.0f} mm long (longer than DIN 874's lengths: a ground flat bar)"
    return (f"Steel straightedge {size} (DIN 874, grade 1), laid across the base to read the datum of {names}", "1")


def set_screw_keys(hardware_rows: list[dict]) -> tuple[str, str] | None:
    """The hex keys the bill's set screws take (rigcad.standards.SET_SCREW_KEY, by each row's thread)."""
    from rigcad.standards import SET_SCREW_KEY

    threads = sorted({r["item"].split(" x ")[0] for r in hardware_rows if "set screw" in r["item"]})
    keys = [f"{SET_SCREW_KEY[t]:g} mm ({t})" for t in threads if t in SET_SCREW_KEY]
    return (f"Hex keys for the set screws (ISO 4026 / 4029, ISO 2936 keys): {', '.join(keys)}", "1 each") if keys else None


__all__ += ["CONSUMABLES", "TOOLS", "TOOL_WORDS", "dowel_drills", "feeler_gauge", "glue_rows", "register_tools",
            "set_screw_keys", "template_straightedge"]


# -- washers and nuts, from the washer stacks -----------------------------------------------------
def _washer_line(w) -> str:
    """A washer as the bill orders it (rigcad.parts.washers.Washer): standard, size, outside diameter."""
    big = "large " if w.standard.startswith("ISO 7093") else ""
    return f"{w.size} {big}washer ({w.standard}, {w.outer:g} mm outside, {w.thickness:g} mm)"


def bolt_stacks(rig) -> list[dict]:
    """Every bolt and screw row of the rig with what each bolt takes: the washers of its stack
    (rigcad.parts.washers, as the torque table's loads use them; head side first, plain ones last) and
    its nuts. Rows: the joints the parts declare (``Part.joints``' ScrewJoint), the bolts found in the
    recipes (bolt_joints), the breadboard's screws, the COP tower's rows (``rigcad.parts.tower.hardware``:
    ``washers``, ``plain_washers``, ``nuts``; an instrument's screws with the extra washers their longest
    stack needs, rigcad.parts.tower.projector_screws / camera_stack_screws: one stack per foot, as the
    washers go from one screw length to the next). Each: use, thread, count (bolts), washers (bill lines
    per bolt), nuts (per bolt)."""
    from rigcad.parts import breadboard
    from rigcad.parts.joints import ScrewJoint
    from rigcad.parts.washers import Washer, large, plain

    by_name = {}

    def washer(name_or_washer) -> str:
        if isinstance(name_or_washer, Washer):
            return _washer_line(name_or_washer)
        name = name_or_washer.removeprefix("a ").removeprefix("an ")
        return by_name.get(name, name)

    for size in standards.ISO_7093:
        by_name[large(size).name()] = _washer_line(large(size))
    for thread in standards.THREADS:
        if standards.THREADS[thread].washer_od:
            by_name[plain(thread).name()] = _washer_line(plain(thread))
    rows = []
    for part in rig.recipes.values():
        for j in part.joints:
            if isinstance(j, ScrewJoint):
                rows.append({"use": j.name, "thread": j.thread, "count": j.count,
                             "washers": [washer(j.washer_spec or plain(j.thread))], "nuts": int(j.into == "nut")})
    for j in bolt_joints(rig):
        per = j["washers"] // j["count"]
        rows.append({"use": j["joins"], "thread": j["thread"], "count": j["count"],
                     "washers": [washer(plain(j["thread"]))] * per, "nuts": j["nuts"] // j["count"]})
    for h in breadboard.hardware(rig.profile, rig.layout) if breadboard.board(rig.profile) else ():
        rows.append({"use": h["joins"], "thread": h["thread"], "count": h["quantity"], "nuts": 0,
                     "washers": [f"{h['thread']} large washer ({h['item'].split('large washer (')[1]}"]})
    extra = {}
    if getattr(rig.layout, "tower", None) is not None:
        from rigcad.parts.tower import camera_stack_screws, projector_screws

        extra = {"for_stacks_of_shims": {r["shims"]: r["extra_washers"] or 0
                                         for r in projector_screws(rig.profile, rig.layout)},
                 "for_camera_stacks_of_shims": {r["shims"]: r["extra_washers"] or 0
                                                for r in camera_stack_screws(rig.profile, rig.layout)}}
    stacked: dict[str, dict] = {}  # an instrument's screws, a row per length: one washer stack per foot
    for h in tower_hardware(rig):
        if not h.get("thread") or not any(k in h for k in ("washers", "plain_washers", "nuts")):
            continue  # an insert, a set screw (no washer, no nut)
        key = next((k for k in extra if k in h), None)
        more = max((extra[key][n] for n in extra[key]), default=0) if key else 0
        row = {"use": h["joins"], "thread": h["thread"], "count": h["quantity"], "nuts": h.get("nuts", 0),
               "washers": [washer(n) for n in h.get("washers", [])]
               + [washer(plain(h["thread"]))] * (h.get("plain_washers", 0) + more)}
        if key is None:
            rows.append(row)
        elif key not in stacked or row["count"] > stacked[key]["count"]:
            stacked[key] = row  # the washers move with the foot's screw from one length to the next
    return rows + list(stacked.values())


def limiter_lines(rig) -> dict[str, int]:
    """The bill's compression limiter lines (item -> quantity): one sleeve per screw of every joint the
    parts declare with limiters (``ScrewJoint.limiter``) and of the COP tower's rows that carry one
    (``limiter``, ``limiter_mm``: rigcad.parts.tower.hardware), summed from the joints as the washers are."""
    from rigcad.parts.joints import ScrewJoint

    out: dict[str, int] = {}
    for part in rig.recipes.values():
        for j in part.joints:
            if isinstance(j, ScrewJoint) and j.limiter:
                lim = j.limiter_part
                item = (f"{lim.name()}, parted off from tube ({lim.source}) and faced to {j.limiter_length:.2f} mm "
                        f"(under {j.upper}'s bolts)")
                out[item] = out.get(item, 0) + j.count
    for h in tower_hardware(rig):  # the COP tower's column joints (rigcad.parts.tower.COLUMN_LIMITER)
        if h.get("limiter"):
            item = f"{h['limiter']}, parted off from tube and faced to {h['limiter_mm']:.2f} mm ({h['joins'].split(' (')[0].split(':')[0]})"
            out[item] = out.get(item, 0) + h["quantity"]
    return out


def washer_nut_lines(rig) -> dict[str, int]:
    """The bill's washer and nut lines (item -> quantity), summed over every bolt of :func:`bolt_stacks`:
    each washer of each stack, and an ISO 4032 hex nut per nut; and the compression limiters
    (:func:`limiter_lines`), which stand under the washers."""
    out: dict[str, int] = dict(limiter_lines(rig))
    for r in bolt_stacks(rig):
        for w in r["washers"]:
            out[w] = out.get(w, 0) + r["count"]
        if r["nuts"]:
            nut = f"{r['thread']} hex nut (ISO 4032)"
            out[nut] = out.get(nut, 0) + r["nuts"] * r["count"]
    return out


__all__ += ["bolt_stacks", "limiter_lines", "washer_nut_lines"]
