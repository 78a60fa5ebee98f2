"""The rig's assembly steps as declarations for the feasibility check (rigcad.manual.assembly_check):
each step's parts, the directions it may go in along, what it needs in place and its fasteners,
all read from the rig (meshes, recipes' holes, the tower's hardware), none typed per rig.

- Parts named alike but for a trailing number (projector_shims_1..4) go in one step; an instrument
  and the lens built onto it (projector_body + projector_lens, camera_body + camera_lens) are one
  unit: the lens is on the body before the body goes in.
- A step needs the parts it rests on (the parts its solid, moved 1 mm down, runs into) and the parts
  its fasteners pass through.
- Directions: a part is lowered from above; failing that it slides in level from the side (+-x,
  +-y); failing that it goes up from below. A beam or a plate that slides into slots or grooves
  tries the sideways directions first (SIDEWAYS_FIRST). The travel is the rig's whole size: every
  part comes from outside the assembly.
- Fasteners: every bolt :func:`rigcad.manual.bom.bolt_axes` finds (the upper part's step fits it:
  head on top, a hex screwdriver from above, a washer and a nut under the lower part held by an
  open-end spanner from the side, or, where no nut fits under it, a heat-set insert melted into the
  lower part); a bolt of one part alone goes into the bench; the instruments' screws
  (``rigcad.parts.tower.hardware``) go up (projector) or across (camera) into their sockets.

Frame: mm, rig frame. Screw sizes: ISO 4762 socket-head cap screws (head diameter 1.5 d, height d),
ISO 4032 nuts, ISO 7089 washers, hex keys to ISO 2936.
"""

from __future__ import annotations

import re

import numpy as np

from rigcad.manual.assembly_check import Assembly, Fastener, Step, manifold, penetration
from rigcad.manual.fasteners import DOWN, UP, spanner
from rigcad.manual.fasteners import socket_head as _socket_head
from rigcad.parts.joints import ScrewJoint
from rigcad.parts.locating import DowelRegister
from rigcad.standards import INSERTS, THREADS, longest_screw, shortest_screw

#: Units one step places together: an instrument with the lens built onto it; the splitter holder with the
#: balls its push screws hold in their cups (seat_ball_1..3: a name stands for the parts named alike).
UNITS = (("projector_body", "projector_lens"), ("camera_body", "camera_lens"), ("splitter_holder", "seat_ball"))
#: Parts that slide in from the side into slots or grooves before anything is lowered onto them.
SIDEWAYS_FIRST = ("beam", "beam_splitter")
SIDEWAYS = ((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 1.0, 0.0))
#: How far (mm) a part is moved down to find what it rests on: above CLEARANCE_MM (a contact shows), below
#: the printed fits' gaps (0.2 mm and up: a part in a slot is not taken to rest on the slot's ceiling).
#: A part that touches nothing below within REST_PROBE_MM sits in a pocket or a groove with a gap: the
#: parts under it within REST_SEARCH_MM (mm) hold it.
REST_SEARCH_MM = 5.0
REST_PROBE_MM = 0.08


def _stem(name: str) -> str:
    return re.sub(r"_\d+$", "", name)


def groups(meshes) -> list[tuple[str, tuple[str, ...]]]:
    """Step names and the parts each places, in the meshes' order (markers left out)."""
    out: dict[str, list[str]] = {}
    unit_of = {m: u[0] for u in UNITS for m in u}
    for m in meshes:
        if m.marker:
            continue
        key = unit_of.get(m.name, unit_of.get(_stem(m.name), _stem(m.name)))
        out.setdefault(key, []).append(m.name)
    return [(k, tuple(v)) for k, v in out.items()]


def insert_item(thread: str) -> str:
    """A heat-set insert as the bill lists it (its size from rigcad.standards.INSERTS)."""
    ins = INSERTS[thread]
    return f"{thread} heat-set insert for printed parts, {ins.length:g} mm long, {ins.hole:g} mm hole"


def thread_of(fastener) -> str:
    """The thread of a fastener's item (its item starts with it: "M4 x 12 mm ...")."""
    return fastener.item.split(" x ")[0]


def thread_host(fastener, meshes_by_name: dict) -> str | None:
    """The printed part that takes a fastener's thread in an insert or a nut trap: of the printed parts
    its shank passes, the one whose material about the screw's axis (within its head's radius and 2 mm)
    reaches farthest along the axis from the head (the insert's pocket or the trap is at the far end).
    None when no printed part is near the axis."""
    head, axis = np.asarray(fastener.head, float), np.asarray(fastener.axis, float)
    best, depth = None, -np.inf
    for name in fastener.passes:
        m = meshes_by_name.get(name)
        if m is None or m.bought:
            continue
        rel = np.asarray(m.vertices, float) - head
        t = rel @ axis
        radial = np.linalg.norm(rel - np.outer(t, axis), axis=1)
        near = (radial < fastener.head_radius_mm + 2.0) & (t > 0.0)
        if near.any() and t[near].max() > depth:
            best, depth = name, float(t[near].max())
    return best


def bolt_fasteners(bolt: dict) -> tuple[Fastener, ...]:
    """The ways to fit one bolt of :func:`rigcad.manual.bom.bolt_axes`, best first: through with a
    washer and a nut under the lower part; into a heat-set insert in the lower part; into the bench
    (a bolt of one part alone)."""
    from rigcad.manual.bom import bolt_length, thread_for_hole

    th = thread_for_hole(bolt["hole_mm"])
    thread, nut_h, washer = th.name, th.nut_height, th.washer_thickness
    head = (bolt["x"], bolt["y"], bolt["top_z"] + washer)
    if len(bolt["parts"]) == 1:
        need = bolt["grip_mm"] + washer + 1.5 * th.major  # 1.5 d of thread into the bench (wood or a tapped plate)
        length = shortest_screw(thread, need) or shortest_screw(None, need)
        return (_socket_head(f"{thread} x {length} mm socket-head screw (ISO 4762) into the bench", head, DOWN,
                             length, thread, thread_in="bench", passes=bolt["parts"]),)
    length, _ = bolt_length(bolt["grip_mm"], th)
    out_dir = np.array([bolt["x"], bolt["y"], 0.0])
    out_dir = tuple(out_dir / np.linalg.norm(out_dir)) if np.linalg.norm(out_dir) > 1e-9 else (1.0, 0.0, 0.0)
    nut_r = th.nut_corner_radius
    options = [_socket_head(f"{thread} x {length} mm socket-head bolt (ISO 4762) with 2 washers (ISO 7089) and a "
                            f"nut (ISO 4032)", head, DOWN, length, thread, thread_in="nut",
                            nut_size_mm=(nut_r, nut_h), nut_tool=spanner(thread, nut_h), nut_dir=out_dir,
                            passes=bolt["parts"], grip_mm=bolt["grip_mm"] + 2 * washer)]
    lower = min((n for n in bolt["parts"] if n != bolt["upper"]), key=lambda n: bolt["spans"][n][1])
    lo, hi = bolt["spans"][lower]
    insert = INSERTS.get(thread)
    if insert is not None and hi - lo >= insert.pocket_depth:
        fit = longest_screw(thread, (bolt["top_z"] - hi) + washer + insert.length)
        if fit:
            options.append(_socket_head(
                f"{thread} x {fit} mm socket-head bolt (ISO 4762) with a washer (ISO 7089) into a {thread} "
                f"heat-set insert ({insert.length:g} mm long, in a {insert.hole:g} mm hole) melted into {lower}",
                head, DOWN, fit, thread,
                thread_in="insert", passes=bolt["parts"]))
    return tuple(options)


def joint_fasteners(joint) -> tuple[Fastener, ...]:
    """The screws of a declared joint (rigcad.parts.joints.ScrewJoint), one per point: heads on
    their washers on the upper part, driven from above; into inserts, or nuts under the lower part
    held by a spanner from the side."""
    th = THREADS[joint.thread]
    out = []
    for x, y in joint.points:
        head = (x, y, joint.head_z)
        if joint.into == "insert":
            out.append(_socket_head(joint.item, head, DOWN, joint.length, joint.thread, thread_in="insert",
                                    passes=(joint.upper, joint.lower)))
            continue
        r = np.hypot(x, y)
        out_dir = (x / r, y / r, 0.0) if r > 1e-9 else (1.0, 0.0, 0.0)
        grip = (joint.upper_z[1] - joint.upper_z[0]) + (joint.lower_z[1] - joint.lower_z[0]) + 2 * th.washer_thickness
        out.append(_socket_head(joint.item, head, DOWN, joint.length, joint.thread, thread_in="nut",
                                nut_size_mm=(th.nut_corner_radius, th.nut_height), nut_tool=spanner(joint.thread, th.nut_height),
                                nut_dir=out_dir, passes=(joint.upper, joint.lower), grip_mm=grip))
    return tuple(out)


def instrument_fasteners(rig, meshes_by_name: dict) -> dict[str, tuple[Fastener, ...]]:
    """The projector's and the camera's screws into their own sockets (thread and length from
    ``rigcad.parts.tower.hardware``): the projector's up through the shelf's slots and its shim
    stacks, the camera's across (+y) through the bracket's slot and its shims. Step name -> screws."""
    t = getattr(rig.layout, "tower", None)
    if t is None:
        return {}
    from rigcad.parts.tower import hardware
    rows = [h for h in hardware(rig.profile, rig.layout) if h.get("length_mm") and "socket" in h["joins"]
            or h.get("length_mm") and "mounting holes" in h["joins"]]
    out: dict[str, tuple[Fastener, ...]] = {}
    nominal = _projector_length(rig, t.shims_nominal)  # the stacks as drawn: shims_nominal shims each
    for h in rows:
        item = _screw_item(h["thread"], h["length_mm"], h.get("washers", ()))
        if "projector" in h["joins"] and h["length_mm"] == nominal:
            z = t.shelf_top_z - t.shelf_thickness - 1.0
            shims = sorted(n for n in meshes_by_name if n.startswith("projector_shims_"))
            out["projector_body"] = tuple(
                _socket_head(item, (*_centre(meshes_by_name[n])[:2], z), UP, h["length_mm"], h["thread"],
                             thread_in="instrument", passes=("tower_shelf", n), pierces=(n,)) for n in shims)
        elif "camera" in h["joins"] and "camera_shims" in meshes_by_name:
            out["camera_body"] = tuple(
                _socket_head(item, (x, -t.wall_y[1] - 1.0, z), (0.0, 1.0, 0.0), h["length_mm"], h["thread"],
                             thread_in="instrument", passes=("splitter_holder", "camera_shims"),
                             pierces=("camera_shims",))
                for x, z in _camera_points(rig, meshes_by_name))
    return out


def _screw_item(thread: str, length: float, washers=()) -> str:
    """The screw as ordered, with its washer stack by name, head side first (rigcad.parts.washers: the
    stack the torque table assumes over the slot), or a plain washer."""
    on = " on ".join(w.removeprefix("a ") for w in washers) or "a washer"
    return f"{thread} x {length:g} mm socket-head screw (ISO 4762 / ASME B18.3) with {on}"


def _projector_length(rig, shims: int) -> float:
    """The projector screw's length (mm) for a stack of ``shims`` (rigcad.parts.tower.projector_screws)."""
    from rigcad.parts.tower import projector_screws

    return float(next(r["length_mm"] for r in projector_screws(rig.profile, rig.layout) if r["shims"] == shims))


def projector_screw_rows(rig) -> list[dict]:
    """The projector's screws, one row per length the shim stacks need (rigcad.parts.tower.hardware's
    rows, sized by rigcad.parts.tower.projector_screws): item, quantity (one per foot: any stack may
    end up at any count in the alignment), the stacks it serves and the extra washers per stack."""
    from rigcad.parts.tower import hardware, projector_screws

    extra = {r["shims"]: r["extra_washers"] for r in projector_screws(rig.profile, rig.layout)}
    return [{"item": _screw_item(h["thread"], h["length_mm"], h.get("washers", ())), "length_mm": h["length_mm"], "quantity": h["quantity"],
             "stacks": list(h["for_stacks_of_shims"]),
             "extra_washers": {n: extra[n] for n in h["for_stacks_of_shims"] if extra[n]}}
            for h in hardware(rig.profile, rig.layout) if "for_stacks_of_shims" in h]


def _stacks(ns: list[int]) -> str:
    return f"{ns[0]} shims" if len(ns) == 1 else f"{ns[0]}..{ns[-1]} shims"


def projector_screw_text(rig) -> str:
    """What the projector's step says about its screws' lengths, stack by stack."""
    rows = projector_screw_rows(rig)
    if not rows:
        return ""
    parts = []
    for r in rows:
        washers = "".join(f"; with {w} extra washer{'s' * (w > 1)} under the head for {n} shims"
                          for n, w in r["extra_washers"].items())
        parts.append(f"{r['item'].split(' socket')[0]} for a stack of {_stacks(r['stacks'])}{washers}")
    return (" Each screw's length follows its own stack: " + ", ".join(parts) + " (the shortest ISO 4762 length "
            "that engages the projector's thread without bottoming in it). When the alignment adds or takes out "
            "shims, change that foot's screw to the length of its new stack.")


def _camera_points(rig, meshes_by_name) -> list[tuple[float, float]]:
    """The camera's screws (x, z; mm): the tower's two when it has them, else one at its shims' centre."""
    try:
        from rigcad.parts.tower import camera_screws
    except ImportError:
        c = _centre(meshes_by_name["camera_shims"])
        return [(float(c[0]), float(c[2]))]
    return [(float(x), float(z)) for x, z in camera_screws(rig.layout.tower, rig.profile)]


def _centre(mesh) -> np.ndarray:
    return 0.5 * (mesh.lo + mesh.hi)


def _rests_on(name: str, solids: dict, members: tuple[str, ...], floor: float) -> tuple[str, ...]:
    """What the part ``name`` stands on: the parts it runs into when moved down, first within
    REST_PROBE_MM (a contact), else within REST_SEARCH_MM (it sits in a pocket or groove with a fit's
    gap); () when it stands on the bench (its bottom at ``floor``) or on nothing below (it hangs)."""
    from rigcad.manual.assembly_check import CLEARANCE_MM

    bottom = solids[name].bounding_box()[2]
    if bottom <= floor + REST_PROBE_MM:
        return ()
    # only a part that reaches lower can hold it up (a plate in a holder's grooves does not hold the holder)
    lower = {n: s for n, s in solids.items() if n not in members and s.bounding_box()[2] < bottom + REST_PROBE_MM}
    for drop in (REST_PROBE_MM, REST_SEARCH_MM):
        probe = solids[name].translate((0.0, 0.0, -drop))
        hit = tuple(n for n, s in lower.items() if penetration(probe, s) > CLEARANCE_MM)
        if hit:
            return hit
    return ()


def _held_by(name: str, solids: dict, members: tuple[str, ...], later: set[str]) -> tuple[str, ...]:
    """A part on nothing below (a shim between a bracket and a camera) needs what it touches from the
    side, but for the parts whose screws pass through it (``later``: they hold it, so they come after)."""
    from rigcad.manual.assembly_check import CLEARANCE_MM

    out = set()
    for d in SIDEWAYS:
        probe = solids[name].translate(tuple(REST_PROBE_MM * np.asarray(d)))
        out |= {n for n, s in solids.items() if n not in members and n not in later
                and penetration(probe, s) > CLEARANCE_MM}
    return tuple(sorted(out))


def steps(rig, meshes) -> tuple[list[Step], dict]:
    """The rig's assembly steps (see the module docstring) and the parts' solids (name -> manifold)."""
    from rigcad.manual.assembly_check import _union, bench

    by_name = {m.name: m for m in meshes if not m.marker}
    solids = {n: manifold(m.vertices, m.faces) for n, m in by_name.items()}
    lo = np.min([m.lo for m in by_name.values()], axis=0)
    hi = np.max([m.hi for m in by_name.values()], axis=0)
    travel = float(np.linalg.norm(hi - lo))
    whole = _union([*solids.values(), bench(lo, hi)])
    from rigcad.manual.bom import bolt_axes

    bolts: dict[str, list[Fastener]] = {}
    for b in bolt_axes(rig):  # the through bolts outside the COP tower (its joints: see the module docstring)
        if len(b["parts"]) < 2 or not set(b["parts"]) <= set(solids):
            continue
        options = bolt_fasteners(b)
        fits = [f for f in options if penetration(f.solids(), whole) <= _clearance()]
        bolts.setdefault(b["upper"], []).append((fits or options)[0])
    for part in rig.recipes.values():  # the screw joints the parts declare: fitted as declared
        for j in part.joints:
            if isinstance(j, ScrewJoint) and {j.upper, j.lower} <= set(solids):
                bolts.setdefault(j.upper, []).extend(joint_fasteners(j))
    from rigcad.manual.tower_joints import tower_fasteners

    screws = instrument_fasteners(rig, by_name)
    for name, fs in tower_fasteners(rig, by_name).items():
        screws[name] = screws.get(name, ()) + fs
    out = []
    for name, members in groups(meshes):
        fasteners = tuple(f for m in members for f in bolts.get(m, ())) + screws.get(name, ())
        needs = set()
        for m in members:
            under = _rests_on(m, solids, members, float(lo[2]))
            if not under and by_name[m].lo[2] > lo[2] + REST_PROBE_MM:
                later = {p for fs in screws.values() for f in fs if m in f.passes
                         for p in groups_of(meshes).get(_step_of(screws, f), ())}
                under = _held_by(m, solids, members, later)
            needs |= set(under)
        needs = tuple(sorted(needs))
        first = any(m in SIDEWAYS_FIRST for m in members)
        directions = (*SIDEWAYS, DOWN, UP) if first else (DOWN, *SIDEWAYS, UP)
        out.append(Step(name, members, directions, travel, needs, fasteners,
                        bought=all(by_name[m].bought for m in members)))
    return out, solids


def groups_of(meshes) -> dict[str, tuple[str, ...]]:
    return dict(groups(meshes))


def _step_of(screws: dict, fastener) -> str:
    return next(name for name, fs in screws.items() if fastener in fs)


def _clearance() -> float:
    from rigcad.manual.assembly_check import CLEARANCE_MM

    return CLEARANCE_MM


def assembly(rig, meshes) -> Assembly:
    """The rig's steps and solids, ready for :func:`rigcad.manual.assembly_check.find_order`."""
    declared, solids = steps(rig, meshes)
    return Assembly(solids, declared)


__all__ = ["assembly", "bolt_fasteners", "groups", "insert_item", "thread_host", "thread_of", "instrument_fasteners", "joint_fasteners", "spanner", "steps"]


def hardware(steps: list[Step], rig=None) -> list[dict]:
    """The plan's fasteners as one list: each bolt or screw item with its count and the steps that use
    it, then the nuts, washers and heat-set inserts they need (counted from the items). With ``rig``,
    the projector's screws are one row per length, for the stacks it serves (:func:`projector_screw_rows`)."""
    rows: dict[str, dict] = {}
    extra: dict[str, int] = {}
    per_length = projector_screw_rows(rig) if rig is not None else []
    for r in per_length:
        rows[r["item"]] = {"item": r["item"], "quantity": r["quantity"],
                           "steps": [f"projector_body (stacks of {_stacks(r['stacks'])})"]}
        thread = r["item"].split(" x ")[0]
        extra[f"{thread} washer (ISO 7089)"] = extra.get(f"{thread} washer (ISO 7089)", 0) + max(
            r["extra_washers"].values(), default=0) * r["quantity"]
    for st in steps:
        for f in st.fasteners:
            if per_length and st.name == "projector_body" and f.thread_in == "instrument":
                washer = f"{f.item.split(' x ')[0]} washer (ISO 7089)"  # the screw: a row per length above
                extra[washer] = extra.get(washer, 0) + 1
                continue
            row = rows.setdefault(f.item, {"item": f.item, "quantity": 0, "steps": []})
            row["quantity"] += 1
            if st.name not in row["steps"]:
                row["steps"].append(st.name)
            thread = f.item.split(" x ")[0]
            if f.thread_in == "nut":
                extra[f"{thread} hex nut (ISO 4032)"] = extra.get(f"{thread} hex nut (ISO 4032)", 0) + 1
            if f.washer_count:
                large = "ISO 7093" in f.item or "large washer" in f.item
                washer = f"{thread} large washer (ISO 7093)" if large else f"{thread} washer (ISO 7089)"
                extra[washer] = extra.get(washer, 0) + f.washer_count
            if f.thread_in == "insert":
                ins = INSERTS[thread]
                name = f"{thread} heat-set insert for printed parts, {ins.length:g} mm long, {ins.hole:g} mm hole"
                extra[name] = extra.get(name, 0) + 1
    if rig is not None:  # washers and nuts from every bolt's washer stack (the torque table's), not the items' words
        from rigcad.manual.bom import washer_nut_lines

        extra = {k: v for k, v in extra.items() if "washer" not in k and "hex nut" not in k}
        extra.update(washer_nut_lines(rig))
    out = [{**r, "steps": ", ".join(r["steps"])} for r in rows.values()]
    return out + [{"item": k, "quantity": v, "steps": "with the bolts above"} for k, v in extra.items()]


def step_names(steps: list[Step], named) -> list[str]:
    """The steps that ``named`` (parts' or steps' names, as a hardware row's ``steps`` gives them) stand
    for: a step of that name, else the step whose members are named alike (a unit's seat_ball_1..3)."""
    out = []
    for n in named:
        hit = next((st.name for st in steps if st.name == n), None) or next(
            (st.name for st in steps if any(_stem(m) == n for m in st.members)), None)
        if hit and hit not in out:
            out.append(hit)
    return out


def bill_hardware(rig, steps: list[Step], bill: dict) -> list[dict]:
    """The manual's one hardware list, for its table and manual.json alike: the plan's fasteners and
    what they need (:func:`hardware`: what the assembly steps fit, so the bill and the steps cannot
    disagree), then the COP tower's items no step fits (dowels, balls, springs; the tower's heat-set
    inserts are counted from the steps' fasteners, not again), the paraboloid's shim stops' and the beam
    seats' hardware (set screws, their inserts, the stop pin, the foil: no step's fastener), then the split
    pieces' dowel pins.
    Each row: item, quantity, where (the steps, or what it joins) and a note."""
    from rigcad.manual import tower_joints

    rows = [{"item": r["item"], "quantity": r["quantity"], "where": f"assembly steps: {r['steps']}",
             "note": "as the assembly check fitted it", "steps": [s.split(" (")[0] for s in r["steps"].split(", ")]}
            for r in hardware(steps, rig)]
    rows += [{"item": f["item"], "quantity": f["quantity"],
              "where": (f"assembly steps: {', '.join(step_names(steps, f['steps']))}: " if f.get("steps") else "")
              + f["use"], "note": f["note"], "steps": step_names(steps, f.get("steps", ()))}
             for f in bill["fasteners"] if (f.get("tower") and "mounting holes" not in f["use"]
             and not tower_joints.placed({"joins": f["use"]}) and "heat-set insert" not in f["item"]) or f.get("stops")]
    for part in rig.recipes.values():  # the locating pins the parts declare, in the step of the part they locate
        for j in part.joints:
            if isinstance(j, DowelRegister) and any(j.upper in st.members for st in steps):
                step = next(st.name for st in steps if j.upper in st.members)
                rows.append({"item": j.item, "quantity": len(j.points), "where": f"assembly steps: {step}",
                             "note": f"pressed into the {j.lower.replace('_', ' ')}: the {j.upper.replace('_', ' ')}'s "
                                     "register", "steps": [step]})
    pin = bill["pins"]
    if pin:
        rows.append({"item": pin["item"], "quantity": pin["quantity"], "where": f"aligning split pieces ({pin['use']})",
                     "note": pin["note"], "steps": []})
    return rows


__all__ += ["bill_hardware", "hardware", "projector_screw_rows", "projector_screw_text", "step_names"]
