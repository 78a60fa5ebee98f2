"""The live edit loop's model: a profile on disk -> the last good rig, rebuilt incrementally.

:class:`LiveSession` reloads the profile (and the printer files it was given) on each call to
:meth:`LiveSession.update` and rebuilds only what the change touches, each stage behind a key of
its inputs (SHA-256 of their ``repr``: frozen dataclasses of float64, exact):

* ``dome``: the dome's parameters and the derived geometry -> the integrated dome, and with it
  the paraboloid, the curve and the pixel-to-direction map (``Rig``'s cached values);
* ``design``: the dome key and the profile keys the design read when it last ran (recorded while it
  runs: rigcad.live.reads, never a list kept by hand) -> the 2D design (its report's ``profile``
  entry refreshed: ``optics.design.profile_entry``);
* each part: its recipe's content hash (``Part.content_hash``, the export cache's part key) ->
  its picture mesh (``Rig.mesh``'s cache, shared from one rig to the next and pruned to the parts
  in use); the mirrors (dome, paraboloid) are parts like the others, so an edit that leaves the
  dome alone does not re-mesh it;
* ``check`` (and the view's ``rays``): the dome and design keys, the layout, the occluders, every
  part's recipe hash, and the profile keys the check (the rays) read when it last ran -> the
  design-level check rows (``check.tolerances``) on the analytic tracer (``rigcad.check.raycheck``,
  mode ``analytic``, no Monte Carlo, no pixel grid) and the rays the view draws.

A profile with an error gives a frame holding the error (with file:line) and the last good rig.
:attr:`LiveSession.builds` counts each stage's runs (``mesh:<part>`` per part meshed), so that a
test can tell what an edit rebuilt. Frame: mm, sample point O at the origin, optical axis +z.
"""

from __future__ import annotations

import dataclasses
import hashlib
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigcad.errors import RigcadError
from rigcad.live.reads import recording, unrecorded, values_at

#: The stages of an update, in order, as the timings name them (seconds); ``push`` is the server's.
STAGES = ("reload", "design", "parts", "meshes", "check", "push")
#: Headline figures of a design (from its report): key -> (label, unit, path into the report).
HEADLINE = {
    "mirror_width_mm": ("dome mirror width", "mm", ("envelope", "width_mm")),
    "mirror_height_mm": ("dome mirror height", "mm", ("envelope", "height_mm")),
    "theta_min_deg": ("theta min", "deg", ("measurable_range", "theta_min_deg")),
    "theta_max_deg": ("theta max", "deg", ("measurable_range", "theta_max_deg")),
    "px_per_deg_min": ("pixels per degree (min)", "px/deg", ("pixels", "px_per_deg_min")),
    "px_per_deg_mean": ("pixels per degree (mean)", "px/deg", ("pixels", "px_per_deg_mean")),
}
def key_of(*items) -> str:
    """SHA-256 (hex) of the ``repr`` of ``items``: frozen parameters and recipes are exact there."""
    return hashlib.sha256("\x1f".join(repr(i) for i in items).encode()).hexdigest()


def stage_key(profile, paths, *upstream) -> str | None:
    """The key of a stage that read ``paths`` of ``profile`` when it last ran (rigcad.live.reads) and
    takes ``upstream`` (earlier stages' keys) from before: None when it never ran."""
    if paths is None:
        return None
    return key_of(*upstream, values_at(profile, paths))


@dataclass
class Frame:
    """What the view shows after one update. ``parts``: every in-rig part (assembly.PartMesh, in
    assembly order); ``keys``: part -> its content key; ``changed``/``removed``: parts whose mesh the
    view must swap or drop since the previous frame; ``moved``: changed parts whose bounding box
    moved; ``rays``: manual.view.traced_rays; ``figures``: HEADLINE key -> value, ``deltas`` the
    change since the previous good state; ``rows``: check rows (dicts, check.tolerances.Row.as_dict)
    or None when the check is off; ``check_pending``: the rows are the previous ones, being redone;
    ``error``: the message (file:line first) when the profile could not be built, else None."""

    seq: int
    profile: str
    parts: list
    keys: dict[str, str]
    changed: tuple[str, ...]
    removed: tuple[str, ...]
    moved: tuple[str, ...]
    rays: dict | None
    figures: dict[str, float]
    deltas: dict[str, float]
    rows: list[dict] | None
    check_pending: bool
    timings: dict[str, float]
    ran: tuple[str, ...]
    error: str | None = None
    printers: dict[str, dict] = field(default_factory=dict)


@dataclass
class _Good:
    """The last good state: the rig, the stage keys, each part's key and mesh, the view's rays,
    the figures and the check rows."""

    rig: object
    dome_key: str
    design_key: str
    check_key: str | None
    keys: dict[str, str]
    parts: list
    rays: dict | None
    figures: dict[str, float]
    rows: list[dict] | None
    printers: dict[str, dict]
    #: stage -> the profile keys it read when it last ran (rigcad.live.reads)
    reads: dict[str, frozenset] = field(default_factory=dict)


class LiveSession:
    """The profile ``spec`` (a name or path) watched and rebuilt; see the module docstring.
    ``check``: run the design-level check rows; ``printers``: printer names or paths whose files
    are watched too and against which each printed part's fit is reported."""

    def __init__(self, spec: str | Path, check: bool = True, printers: tuple[str, ...] = ()) -> None:
        self.spec = spec
        self.check_enabled = check
        self.printer_specs = tuple(printers)
        self.builds: Counter = Counter()
        self.good: _Good | None = None
        self.seq = 0
        self.files: tuple[Path, ...] = ()
        self._instruments: tuple[Path, ...] = ()  # the instrument files the last valid profile named
        self._mesh_cache: dict = {}
        self._printers: dict[str, object] = {}
        self._pending: tuple | None = None
        self._reads: dict[str, frozenset] = {}

    # -- the update ------------------------------------------------------------------------------
    def update(self) -> Frame:
        """Reload and rebuild what changed, all but the check rows (:meth:`finish_check` runs them,
        so that the view shows the parts first); a RigcadError gives a frame with the error and
        the last good rig."""
        self.seq += 1
        timings: dict[str, float] = {}
        ran: list[str] = []
        try:
            return self._update(timings, ran)
        except RigcadError as err:
            return self._error_frame(str(err), timings, ran)

    def _update(self, timings: dict, ran: list) -> Frame:
        t0 = time.perf_counter()
        profile = self._reload()
        timings["reload"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        rig, dome_key, design_key = self._rig(profile, ran)
        figures = headline(rig.design.report)
        timings["design"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        parts = [p for p in [*rig.recipes.values(), *rig.instruments] if p.in_rig]
        keys = {p.name: p.content_hash() for p in parts}
        check_key = self._check_key(rig, dome_key, design_key, keys)
        timings["parts"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        meshes = self._meshes(rig, parts, keys, ran)
        rays = self._rays(rig, self._check_key(rig, dome_key, design_key, keys, "rays"),
                          self._upstream(rig, dome_key, design_key, keys), ran)
        printers = self._printer_fits(rig, meshes, keys, ran)
        timings["meshes"] = time.perf_counter() - t0

        old = self.good
        rows, rows_key = (old.rows, old.check_key) if old is not None else (None, None)
        self.good = _Good(rig, dome_key, design_key, rows_key, keys, meshes, rays, figures, rows, printers,
                          dict(self._reads))
        pending = self.check_enabled and (check_key is None or rows_key != check_key)
        self._pending = (rig, self._upstream(rig, dome_key, design_key, keys)) if pending else None
        return self._frame(old, timings, ran, pending)

    def finish_check(self) -> Frame | None:
        """Run the check rows the last update left pending: the frame with them (None when no
        check was pending; an error frame when the check could not run)."""
        if self._pending is None or self.good is None:
            return None
        (rig, upstream), self._pending = self._pending, None
        t0 = time.perf_counter()
        self.seq += 1
        try:
            with recording(rig.profile) as seen:
                rows = check_rows(rig)
        except RigcadError as err:
            return self._error_frame(str(err), {"check": time.perf_counter() - t0}, ["check"])
        self.builds["check"] += 1
        self._reads["check"] = self.good.reads["check"] = frozenset(seen.paths)
        self.good.rows, self.good.check_key = rows, stage_key(rig.profile, self._reads["check"], upstream)
        return self._frame(None, {"check": time.perf_counter() - t0}, ["check"], False, swap=False)

    # -- stages ----------------------------------------------------------------------------------
    def _reload(self):
        """The profile; the files to watch (its extends: chain, the printers) kept current."""
        from rigcad.profile.loader import load_raw
        from rigcad.profile.schema import validate

        named = self._named()
        files = [Path(self.spec).resolve()] if Path(str(self.spec)).is_file() else list(self.files[:1])
        try:
            raw = load_raw(self.spec)
            files = list(raw.files)
        finally:
            # the profile's own path as found (a link there is not followed: whatever a rename puts at
            # that name is seen), then its extends: chain as read, then the printer files
            self.files = tuple(dict.fromkeys([*named, *files, *self._printer_files(), *self._instruments]))
        profile = validate(raw)
        self._instruments = profile.instrument_files  # its projector, camera, lens, splitter files
        self.files = tuple(dict.fromkeys([*self.files, *self._instruments]))
        self._load_printers()
        return profile

    def _named(self) -> list[Path]:
        """The profile's own file where the spec finds it, absolute, links not followed ([] when the
        spec finds none now: the last one found is kept in :attr:`files`)."""
        import os

        from rigcad.profile.loader import resolve_profile_path

        try:
            return [Path(os.path.abspath(resolve_profile_path(self.spec)))]
        except RigcadError:
            return [f for f in self.files[:1]]

    def _rig(self, profile, ran: list):
        """The rig of ``profile``: the dome (Rig.from_profile with the last good rig) and the design
        carried over when their inputs are unchanged, else computed (and counted)."""
        from rigcad.optics.design import profile_entry
        from rigcad.rig import Rig

        old = self.good
        rig = Rig.from_profile(profile, previous=old.rig if old is not None else None)
        if old is None or rig.dome is not old.rig.dome:
            self.builds["dome"] += 1
            ran.append("dome")
        dome_key = key_of(profile.dome, rig.geometry)
        reads = dict(old.reads) if old is not None else {}
        design_key = stage_key(profile, reads.get("design"), dome_key)
        if old is not None and design_key is not None and old.design_key == design_key:
            design = old.rig.design
            rig._cache["design"] = dataclasses.replace(
                design, profile=profile, report={**design.report, "profile": profile_entry(profile)})
        else:
            from rigcad.optics import design as design_module

            # the report's copy of the whole profile is refreshed on reuse (above): no input of the design
            with recording(profile) as seen, unrecorded(design_module, "profile_entry"):
                rig.design
            reads["design"] = frozenset(seen.paths)
            design_key = stage_key(profile, reads["design"], dome_key)
            self.builds["design"] += 1
            ran.append("design")
        self._reads = reads
        rig._cache["_meshes"] = self._mesh_cache  # Rig.mesh's cache, keyed by recipe content
        rig.layout
        return rig, dome_key, design_key

    def _meshes(self, rig, parts, keys: dict, ran: list) -> list:
        """Every in-rig part's picture mesh (manual.assembly.picture_meshes): only the parts whose key
        is not cached are meshed; the cache is then pruned to this rig's parts."""
        from rigcad.export.mesh import PICTURE_CHORD_ERROR
        from rigcad.manual.assembly import picture_meshes

        for p in parts:
            if (keys[p.name], PICTURE_CHORD_ERROR) not in self._mesh_cache:
                self.builds[f"mesh:{p.name}"] += 1
                ran.append(f"mesh:{p.name}")
        meshes = picture_meshes(rig, PICTURE_CHORD_ERROR)
        used = {(k, PICTURE_CHORD_ERROR) for k in keys.values()}
        for stale in [k for k in self._mesh_cache if k not in used]:  # memory stays one rig's meshes
            del self._mesh_cache[stale]
        return meshes

    def _upstream(self, rig, dome_key: str, design_key: str, keys: dict) -> str:
        """What the check rows and the view's rays take from earlier stages, made before they run:
        the dome and design keys, the layout, the occluders and every part's recipe hash."""
        return key_of(dome_key, design_key, rig.layout.describe(), rig.occluders, sorted(keys.items()))

    def _check_key(self, rig, dome_key: str, design_key: str, keys: dict, stage: str = "check") -> str | None:
        """The inputs of the check rows (``stage`` "check") or of the view's rays ("rays"): the
        earlier stages' keys and the profile keys the stage read when it last ran (None: it never ran)."""
        return stage_key(rig.profile, self._reads.get(stage), self._upstream(rig, dome_key, design_key, keys))

    def _rays(self, rig, rays_key: str | None, upstream: str, ran: list) -> dict:
        """The view's rays (manual.view.traced_rays), traced again only when their inputs changed
        (``rays_key``: :meth:`_check_key` of "rays"; None when they were never traced)."""
        from rigcad.manual.view import VIEW_RAYS, traced_rays

        old = self.good
        if rays_key is not None and old is not None and old.rays is not None and old.rays.get("key") == rays_key:
            return old.rays
        self.builds["rays"] += 1
        ran.append("rays")
        with recording(rig.profile) as seen:
            rays = traced_rays(rig, VIEW_RAYS)
        self._reads["rays"] = frozenset(seen.paths)
        return {**rays, "key": stage_key(rig.profile, self._reads["rays"], upstream)}

    # -- printers --------------------------------------------------------------------------------
    def _printer_files(self) -> list[Path]:
        """The printer files given (each with its extends chain), to watch."""
        from rigcad.fab.printers import printer_path
        from rigcad.profile.loader import load_raw

        files = []
        for spec in self.printer_specs:
            try:
                files += list(load_raw(printer_path(spec)).files)
            except RigcadError:  # reported by _load_printers; still watch the file named
                path = Path(spec)
                files += [path.resolve()] if path.is_file() else []
        return files

    def _load_printers(self) -> None:
        from rigcad.fab.printers import load_printer

        self._printers = {}
        for spec in self.printer_specs:
            printer = load_printer(spec)
            self._printers[printer.name] = printer

    def _printer_fits(self, rig, meshes, keys: dict, ran: list) -> dict[str, dict]:
        """Per printer: the printed parts that fit its usable volume whole (fab.choice's orientations
        and fit, on the picture meshes) and those that must be split."""
        if not self._printers:
            return {}
        from rigcad.fab import choice
        from rigcad.fab.orientation import plate_axis

        def whole(name: str, vertices, printer) -> bool:  # as rigcad fab decides it (fab.choice.split_plan)
            mirror = bool(rig.recipe(name).mirrors)
            return choice.fits(vertices, choice.candidates(mirror, None if mirror else plate_axis(vertices)), printer)

        old = self.good.printers if self.good is not None else {}
        out = {}
        printed = {m.name: m for m in meshes if m.name in rig.recipes}  # the instruments are bought
        for name, printer in self._printers.items():
            key = key_of(printer, sorted((n, keys[n]) for n in printed))
            if old.get(name, {}).get("key") == key:
                out[name] = old[name]
                continue
            self.builds[f"fit:{name}"] += 1
            ran.append(f"fit:{name}")
            split = sorted(n for n, m in printed.items() if not whole(n, m.vertices, printer))
            out[name] = {"key": key, "parts": len(printed), "split": split, "usable_mm": list(printer.usable)}
        return out

    # -- frames ----------------------------------------------------------------------------------
    def _frame(self, old: _Good | None, timings: dict, ran: list, pending: bool, swap: bool = True) -> Frame:
        """The frame of the good state. ``old``: the state the view shows (None: nothing yet),
        whose parts are swapped where they differ; ``swap`` False: no part changed (the rows of
        a check arriving)."""
        g = self.good
        before = (old.keys if old is not None else {}) if swap else dict(g.keys)
        boxes = {m.name: (m.lo, m.hi) for m in old.parts} if old is not None and swap else {}
        changed = tuple(n for n in g.keys if before.get(n) != g.keys[n])
        moved = tuple(n for n in changed if n in boxes and not _same_box(boxes[n], g.parts, n))
        deltas = {k: v - old.figures[k] for k, v in g.figures.items() if old is not None and k in old.figures}
        return Frame(self.seq, g.rig.name, g.parts, dict(g.keys), changed, tuple(n for n in before if n not in g.keys),
                     moved, g.rays, g.figures, deltas, g.rows, pending, timings, tuple(ran), None, g.printers)

    def _error_frame(self, message: str, timings: dict, ran: list) -> Frame:
        """A frame with ``message`` and the last good rig unchanged (no part to swap)."""
        g = self.good
        if g is None:
            return Frame(self.seq, Path(str(self.spec)).stem, [], {}, (), (), (), None, {}, {}, None, False,
                         timings, tuple(ran), message)
        return Frame(self.seq, g.rig.name, g.parts, dict(g.keys), (), (), (), g.rays, g.figures, {}, g.rows, False,
                     timings, tuple(ran), message, g.printers)


def _same_box(box, parts, name: str) -> bool:
    for m in parts:
        if m.name == name:
            return bool(np.allclose(box[0], m.lo, rtol=0, atol=1e-6) and np.allclose(box[1], m.hi, rtol=0, atol=1e-6))
    return False


def headline(report: dict) -> dict[str, float]:
    """The design's headline figures (HEADLINE) from its report; a figure the rig has not (a COP at
    infinity has no pixels per degree) is left out."""
    out = {}
    for key, (_, _, path) in HEADLINE.items():
        value = report
        for step in path:
            value = value.get(step) if isinstance(value, dict) else None
        if isinstance(value, (int, float)):
            out[key] = float(value)
    return out


def check_rows(rig) -> list[dict]:
    """The design-level check rows of ``rig`` on the analytic tracer (exact surfaces, the profile's
    ray count and seed; no Monte Carlo, no pixel grid): check.tolerances rows as dicts."""
    from rigcad.check.raycheck import run_raycheck

    result = run_raycheck(rig, mode="analytic", monte_carlo=False, grid=False)
    return [row.as_dict() for row in result.rows]


__all__ = ["Frame", "HEADLINE", "LiveSession", "STAGES", "check_rows", "headline", "key_of"]
