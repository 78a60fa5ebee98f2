"""The assembly gate: a rig that cannot be put together is refused, not printed.

:func:`verdict` runs the assembly check (rigcad.manual.assembly_check.find_order over
rigcad.manual.plan's steps) on a rig and returns a typed :class:`Verdict`: the order found, or the
step that cannot be done, what it runs into, the profile keys that would fix it and, for the keys
the profile itself sets, the nearest value at which that step goes in. ``rigcad stl``, ``fab`` and
``manual`` turn a failed verdict into one line and a non-zero exit.

Which keys: the keys that shape the parts involved (``Part.shaped_by``, recorded as each recipe
read the profile), the keys of the instruments' own sections (the projector, the camera, the
splitter, the focusing lens) and, of the keys the rig's layout read (``RigLayout.shaped_by``), those
the profile's files set. Keys the profile's own file sets come first: they are what the user chose.

The nearest value: the length keys the profile sets are ranked by how much a move of each (one
probe each way) cuts the blocked step's overlap along one of its ways in (per direction); for the :data:`SEARCH_KEYS` that cut it most, the
value is moved away from the profile's own in growing steps each way (``STEP_MM`` doubling, at most
``MAX_PROBES`` probes) until the blocked step goes in with what it needs in place (the exact test
the check uses to refuse it), then bisected to ``RESOLUTION_MM``. Each probe rebuilds the rig's
layout and meshes (the dome is kept), about 2 s on 2 cores. Frame and units: mm.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

from rigcad.errors import AssemblyError, GeometryError

#: Length keys searched for the nearest working value (the rest are named only), chosen among the
#: first RANK_KEYS the profile sets by how much a move of RANK_STEP_MM (mm) each way cuts the overlap.
SEARCH_KEYS = 2
RANK_KEYS = 8
RANK_STEP_MM = 5.0
#: The first step (mm) away from the profile's value, doubled each probe, and the probes per side.
STEP_MM = 1.0
MAX_PROBES = 6
#: The bisection stops when the passing and failing values are this close (mm): a tenth of a
#: printed fit's gap, finer than anyone sets an instrument's size.
RESOLUTION_MM = 0.1
#: Keys a refusal's line names (the rest are in the verdict's keys).
SHOWN_KEYS = 8
#: Instruments' parts -> the profile section that sizes them (the recipes name their own keys).
INSTRUMENT_SECTIONS = {"projector": "projector", "camera": "camera", "beam_splitter": "beam_splitter",
                       "focusing_lens": "lens", "projector_shims": "tower", "camera_shims": "tower"}


@dataclass(frozen=True)
class Fix:
    """A key the profile sets (``where``: its file:line), its value now and the nearest value (mm) at
    which the blocked step goes in; ``value`` None: none found within the probes."""

    key: str
    where: str
    now: float
    value: float | None


@dataclass(frozen=True)
class Verdict:
    """The assembly check's answer for one rig: ``order`` (the steps' names, in a feasible order)
    when it can be put together; else the ``step`` that cannot be done, the parts it places
    (``members``), what it runs into (``obstacles``), the check's ``reason``, the profile ``keys``
    that would fix it and the ``fixes`` found for the keys the profile sets."""

    profile: str
    order: tuple[str, ...] = ()
    step: str | None = None
    members: tuple[str, ...] = ()
    obstacles: tuple[str, ...] = ()
    reason: str = ""
    keys: tuple[str, ...] = ()
    fixes: tuple[Fix, ...] = ()
    #: The real blocker in one phrase, as the check found it (AssemblyError.summary): the parts that
    #: collide and why no order avoids it ("" when the check gave none: then members and obstacles).
    summary: str = ""
    #: Where the check's whole reason is kept (the verdict's file, once written); None: nowhere, and
    #: the line points to no file.
    kept: str | None = None
    #: The direction each step of ``order`` goes in along (unit, rig frame), as the check placed it.
    directions: tuple[tuple[float, float, float], ...] = ()

    @property
    def ok(self) -> bool:
        return self.step is None and not self.reason

    def line(self) -> str:
        """One line: which parts collide, the keys that would fix it, the nearest values found, and
        where the check's whole reason is kept (only when it was written: ``kept``)."""
        if self.ok:
            return f"{self.profile}: the assembly check finds an order of {len(self.order)} steps"
        what = " + ".join(self.members) or (self.step or "a step")
        into = ", ".join(self.obstacles) or "what is in place"
        found = [f"{f.key} {f.now:g} -> {f.value:g} mm ({f.where})" for f in self.fixes if f.value is not None]
        keys = ", ".join(self.keys[:SHOWN_KEYS]) + (", ..." if len(self.keys) > SHOWN_KEYS else "")
        return (f"{self.profile} cannot be assembled: "
                + (self.summary if self.summary else f"{what} cannot go in, it runs into {into}")
                + (f"; nearest values that let it in: {'; '.join(found)}" if found else "")
                + (f"; keys that move it: {keys}" if keys else "")
                + (f" (the check's whole reason: {self.kept})" if self.kept else ""))

    def as_json(self) -> dict:
        """The verdict as the writers store it (assembly.json; units in the keys)."""
        return {"ok": self.ok, "order": list(self.order), "directions": [list(d) for d in self.directions], "step": self.step, "members": list(self.members),
                "obstacles": list(self.obstacles), "reason": self.reason, "summary": self.summary, "keys": list(self.keys),
                "fixes": [{"key": f.key, "where": f.where, "now_mm": f.now, "value_mm": f.value} for f in self.fixes],
                "line": self.line()}


def _order(rig, meshes):
    from rigcad.manual import assembly_check, plan

    return assembly_check.find_order(plan.assembly(rig, meshes))


def verdict(rig, meshes=None, search: bool = True, progress=None) -> Verdict:
    """The assembly check's verdict on ``rig`` (meshes: rigcad.manual.assembly.picture_meshes, made
    when None). ``search``: look for the nearest working values of the keys the profile sets (a few
    seconds a probe; only when the check refuses)."""
    from rigcad.manual.assembly import picture_meshes

    meshes = picture_meshes(rig) if meshes is None else meshes
    try:
        order = _order(rig, meshes)
    except AssemblyError as err:
        return refused(rig, err, search, progress)
    return Verdict(rig.name, order=tuple(p.step.name for p in order), directions=tuple(p.direction for p in order))


def refused(rig, err: AssemblyError, search: bool = True, progress=None) -> Verdict:
    """The verdict for the check's refusal ``err``: the keys and, with ``search``, the fixes."""
    keys = candidate_keys(rig, err.members, err.obstacles)
    fixes = tuple(nearest_values(rig, err, keys, progress)) if search and err.step else ()
    return Verdict(rig.name, step=err.step, members=err.members, obstacles=err.obstacles, reason=str(err),
                   keys=keys, fixes=fixes, summary=getattr(err, "summary", ""))


def candidate_keys(rig, members, obstacles=()) -> tuple[str, ...]:
    """The profile keys that move or size the colliding parts (see the module docstring): the keys
    the profile's own file sets that the layout or the parts read, then the parts' own keys, those
    that shape both sides of the collision first, then the two sides' in turn (so the line's first
    keys name both the parts that go in and what they run into)."""
    p = rig.profile

    def keys_of(names) -> list[str]:
        out: list[str] = []
        for name in names:
            recipe = rig.recipes.get(name)
            if recipe is not None:
                out += list(recipe.shaped_by)
            section = next((s for prefix, s in INSTRUMENT_SECTIONS.items() if name.startswith(prefix)), None)
            if section is not None:
                out += [k for k in rig.layout.shaped_by if k.startswith(section + ".")]
        return list(dict.fromkeys(out))

    a, b = keys_of(members), keys_of(obstacles)
    both = [k for k in a if k in b]
    turns = [k for pair in itertools.zip_longest([k for k in a if k not in both], [k for k in b if k not in both])
             for k in pair if k is not None]
    own = [*both, *turns]
    read = list(dict.fromkeys([*own, *rig.layout.shaped_by]))
    leaf = p.sources[0] if p.sources else None

    def setter(key: str) -> str | None:
        return p.marks.get(tuple(key.split(".")))

    first = [k for k in read if setter(k) and leaf and setter(k).startswith(leaf + ":")]
    return tuple(dict.fromkeys([*first, *own]))


def _with(profile, key: str, value: float):
    section, name = key.split(".")
    return dataclasses.replace(profile, **{section: dataclasses.replace(getattr(profile, section), **{name: value})})


def _ways_in(rig, profile, step: str, obstacles=()) -> dict | None:
    """How far (mm) ``step``, with what it needs and the steps of what it ran into (``obstacles``,
    with what they need) in place, still runs into something on the rig of ``profile`` (its dome
    kept from ``rig``) along each way in the check tried (direction -> mm; every direction 0 when it
    goes in: the check's own test for a blocked step); None when the layout refuses the profile or
    the step waits for a part that never comes. With what it ran into in place, a step that must go
    in before a part that blocks it (a bolt's way in under the dome) is judged with that part there."""
    from rigcad.manual import assembly_check, plan
    from rigcad.manual.assembly import picture_meshes
    from rigcad.rig import Rig

    try:
        other = Rig.from_profile(profile, previous=rig)
        a = plan.assembly(other, picture_meshes(other))
    except GeometryError:  # the layout refuses the value: not a way in
        return None
    if step not in a.by_name:
        return None
    before = assembly_check._before(a)
    owner = {m: s.name for s in a.steps for m in s.members}
    blockers = {owner.get(o, o) for o in obstacles} & set(before) - {step}
    done = frozenset(before[step]).union(*(before[b] | {b} for b in blockers)) - {step}
    r = a.attempt(a.by_name[step], done)
    if isinstance(r, assembly_check.Placed):
        return {d: 0.0 for d in a.by_name[step].directions}
    return dict(r.depths) if r.blocked else None


def _goes_in(rig, profile, step: str, obstacles=()) -> bool:
    ways = _ways_in(rig, profile, step, obstacles)
    return ways is not None and not any(ways.values())


def _gain(base: dict, moved: dict | None) -> float:
    """How much (mm) a move cuts the step's overlap along the way in it helps most: the largest drop
    of one direction's depth (a move that frees one direction counts, whatever blocks the others)."""
    if moved is None:
        return 0.0
    return max((base[d] - moved[d] for d in base if d in moved), default=0.0)


def _set_lengths(rig, keys) -> list[tuple[str, str, float]]:
    """(key, file:line, value) of the length keys among ``keys`` the profile sets."""
    p, out = rig.profile, []
    for key in keys:
        where = p.marks.get(tuple(key.split(".")))
        section, name = key.split(".")
        now = getattr(getattr(p, section), name, None)
        if where is not None and isinstance(now, float) and not isinstance(now, bool):
            out.append((key, where, now))
    return out


def nearest_values(rig, err: AssemblyError, keys, progress=None):
    """Fixes for the SEARCH_KEYS length keys the profile sets whose move brings the blocked step
    nearest to going in: each of the first RANK_KEYS of them is moved RANK_STEP_MM each way once,
    and the keys are ranked by how much that cuts the step's overlap along one of its ways in (per
    direction: a part blocked one way by what the key moves and another way by what it does not is
    freed by the key all the same); a key that cuts no direction's overlap is not searched: it is
    not what blocks the part."""
    p = rig.profile
    base = _ways_in(rig, p, err.step, err.obstacles)
    if base is None:
        return
    gains = []
    for key, where, now in _set_lengths(rig, keys)[:RANK_KEYS]:
        if progress:
            progress(f"assembly gate: how {key} moves {err.step}")
        best = max(_gain(base, _ways_in(rig, _with(p, key, now + s * RANK_STEP_MM), err.step, err.obstacles))
                   for s in (1.0, -1.0)
                   if now + s * RANK_STEP_MM > 0.0)
        if best > 1e-6:
            gains.append((best, key, where, now))
    for _, key, where, now in sorted(gains, key=lambda g: -g[0])[:SEARCH_KEYS]:
        yield Fix(key, where, now, _search(rig, p, key, now, err.step, progress, err.obstacles))


def _search(rig, p, key: str, now: float, step: str, progress, obstacles=()) -> float | None:
    """The value nearest ``now`` at which ``step`` goes in (within RESOLUTION_MM), or None."""
    for k in range(MAX_PROBES):
        delta = STEP_MM * 2 ** k
        for sign in (1.0, -1.0):
            v = now + sign * delta
            if v <= 0.0:
                continue
            if progress:
                progress(f"assembly gate: {key} = {v:g} mm")
            if _goes_in(rig, _with(p, key, v), step, obstacles):
                bad = now + sign * (delta / 2 if k else 0.0)
                good = v
                while abs(good - bad) > RESOLUTION_MM:
                    mid = 0.5 * (good + bad)
                    if progress:
                        progress(f"assembly gate: {key} = {mid:g} mm")
                    if _goes_in(rig, _with(p, key, mid), step, obstacles):
                        good = mid
                    else:
                        bad = mid
                return round(good + (0.05 if good > bad else -0.05), 1)  # rounded away from the failing side
    return None


# -- the checks that need no part's solid: what `rigcad design` reports early ---------------------
@dataclass(frozen=True)
class EarlyRefusal:
    """A refusal `rigcad stl` would make that needs no solid: what refused (``the layout`` or a part's
    recipe), its one-line message (file:line first when it names a key the profile set) and the key
    to change (None when the message names several)."""

    what: str
    message: str
    key: str | None

    def line(self) -> str:
        return f"{self.what}: {self.message}"


def early_refusals(rig) -> tuple[EarlyRefusal, ...]:
    """Every refusal of the rig's placements and part recipes, the checks `rigcad stl` (and the gate
    after it) makes before any solid is built: the layout (the tower, the splitter and the
    instruments against the dome; its first refusal only, as every later placement stands on the
    earlier ones), else each part's recipe on its own (the focusing lens, the seats, the flange, ...)
    and the tower's bought screws against the instruments' sockets, all of them at once, the parts
    refused for one reason named together. Empty when none refuses.
    No solid is made."""
    from rigcad.parts import PARTS, make_recipe, tower

    def refusal(what: str, err: GeometryError) -> EarlyRefusal:
        return EarlyRefusal(what, str(err.located(rig.profile.marks)), err.param)

    try:
        layout = rig.layout
    except GeometryError as err:
        return (refusal("the layout", err),)
    found: dict[str, tuple[list[str], EarlyRefusal]] = {}  # parts refused for one reason are named together
    for name in PARTS:
        try:
            make_recipe(rig.profile, layout, name)
        except GeometryError as err:
            r = refusal(name, err)
            found.setdefault(r.message, ([], r))[0].append(name)
    try:  # the tower's bought screws (their lengths against the instruments' sockets), as `stl`'s bill finds them
        tower.hardware(rig.profile, layout)
    except GeometryError as err:  # a reason a part's recipe gave already is not said twice
        r = refusal("the tower's hardware", err)
        found.setdefault(r.message, ([r.what], r))
    return tuple(EarlyRefusal(", ".join(names), r.message, r.key) for names, r in found.values())


# -- the verdict kept beside the export: stl, fab and manual check a profile once -----------------
#: The verdict's file in exports/<profile>/, keyed by everything `rigcad stl` depends on.
VERDICT_FILE = "assembly.json"


def verdict_path(root, name: str):
    from pathlib import Path

    return Path(root) / name / VERDICT_FILE


def _from_json(data: dict, name: str) -> Verdict:
    fixes = tuple(Fix(str(f["key"]), str(f["where"]), float(f["now_mm"]),
                      None if f["value_mm"] is None else float(f["value_mm"])) for f in data["fixes"])
    return Verdict(name, order=tuple(map(str, data["order"])), step=data["step"], members=tuple(map(str, data["members"])),
                   obstacles=tuple(map(str, data["obstacles"])), reason=str(data["reason"]),
                   keys=tuple(map(str, data["keys"])), fixes=fixes, summary=str(data.get("summary", "")),
                   directions=tuple(tuple(float(v) for v in d) for d in data.get("directions", ())))


def read_verdict(root, profile) -> Verdict | None:
    """The verdict kept for ``profile`` under the exports ``root``, when it was made from this profile
    by this code (the stl cache key, rigcad.export.manifest.inputs_key); None otherwise (missing, not
    a plain file, too large, a nesting bomb, unreadable, another key: it is made anew). Read as
    rigcad reads back its own files (rigcad.export.readback.own_json)."""
    from rigcad.export.manifest import inputs_key
    from rigcad.export.readback import own_json

    doc = own_json(verdict_path(root, profile.name))
    try:
        if not isinstance(doc, dict) or doc.get("inputs_key") != inputs_key(profile):
            return None
        return dataclasses.replace(_from_json(doc, profile.name), kept=f"{VERDICT_FILE} beside the export")
    except (ValueError, TypeError, KeyError, AttributeError):
        return None


def checked(rig, root, progress=None) -> Verdict:
    """The rig's verdict, read back from exports ``root`` when this profile and code made it, else
    checked (:func:`verdict`) and kept there (atomically) for the next command."""
    from rigcad.export.atomic import write_json
    from rigcad.export.manifest import inputs_key

    kept = read_verdict(root, rig.profile)
    if kept is not None:
        _remember(rig, kept)
        return kept
    found = verdict(rig, progress=progress)
    _remember(rig, found)
    path = verdict_path(root, rig.name)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(path, {"inputs_key": inputs_key(rig.profile), **found.as_json()})
    return dataclasses.replace(found, kept=f"{VERDICT_FILE} beside the export")  # written: the line may point to it


#: The orders (names, directions) the gate found or read back in this process, by the resolved
#: profile of a rig as designed (the last few: a watch or an optimize run judges many): what
#: :func:`order` hands on.
_ORDERS: dict[str, tuple[tuple, tuple]] = {}
ORDERS_KEPT = 8


def _remember(rig, v: Verdict) -> None:
    from rigcad.export.manifest import profile_digest
    from rigcad.optics.frames import Misalignment

    if v.ok and v.order and len(v.directions) == len(v.order) and rig.misalignment == Misalignment.none():
        key = profile_digest(rig.profile)
        _ORDERS.pop(key, None)
        _ORDERS[key] = (v.order, v.directions)
        while len(_ORDERS) > ORDERS_KEPT:
            _ORDERS.pop(next(iter(_ORDERS)))


def order(rig, assembly):
    """The assembly check's order of ``assembly`` (rigcad.manual.plan.assembly of ``rig`` as designed,
    as the gate checks it; a list of assembly_check.Placed). When the gate judged ``rig``'s profile in
    this process (:func:`checked`: its verdict found, or read back from the file its key keeps, made by
    this code from this profile, so from this very assembly), the verdict's steps and directions, with
    no search and no sweep: the search's own Placed, to the bits. Else, or when the verdict's steps
    or directions are not the assembly's (another assembly), the search (assembly_check.find_order)."""
    from rigcad.export.manifest import profile_digest
    from rigcad.manual import assembly_check
    from rigcad.optics.frames import Misalignment

    known = _ORDERS.get(profile_digest(rig.profile)) if rig.misalignment == Misalignment.none() else None
    if known is not None and sorted(known[0]) == sorted(s.name for s in assembly.steps):
        steps = [assembly.by_name[name] for name in known[0]]
        if all(any(tuple(float(v) for v in d) == way for d in st.directions) for st, way in zip(steps, known[1])):
            return [assembly_check.Placed(st, way) for st, way in zip(steps, known[1])]
    return assembly_check.find_order(assembly)


def kept_gate(root, profile) -> bool:
    """Whether a verdict kept for ``profile`` under ``root`` (:func:`read_verdict`) lets the rig
    through: True when it does, False when none is kept (the rig must be checked); AssemblyError when
    the kept verdict refuses it. No rig is built."""
    v = read_verdict(root, profile)
    if v is not None and not v.ok:
        raise AssemblyError(v.line(), step=v.step, members=v.members, obstacles=v.obstacles, summary=v.summary,
                            detail=v.reason)
    return v is not None


def gate(rig, root, progress=None) -> Verdict:
    """:func:`checked`, raising AssemblyError (exit code 1, its message the verdict's one line) when
    the rig cannot be put together: what ``fab`` and ``manual`` call before any work."""
    v = checked(rig, root, progress)
    if not v.ok:
        raise AssemblyError(v.line(), step=v.step, members=v.members, obstacles=v.obstacles, summary=v.summary,
                            detail=v.reason)
    return v


__all__ = ["EarlyRefusal", "Fix", "VERDICT_FILE", "Verdict", "candidate_keys", "checked", "early_refusals", "gate", "kept_gate",
           "nearest_values", "order", "read_verdict", "refused", "verdict", "verdict_path"]
