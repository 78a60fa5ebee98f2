"""Instruments as data: one YAML file per projector, camera, lens and beam splitter, which a profile
names by file name (``projector.model``, ``camera.model``, ``camera.lens``, ``beam_splitter.model``).

Instrument files are found like profiles (rigcad.profile.paths): in ``instruments/`` beside the
profile, then under each folder of the profile search path (``./profiles/instruments``,
``$RIGCAD_PROFILES/<folder>/instruments``, the shipped ``profiles/instruments``), first match wins:
a lab adds its own camera in its own folder without touching rigcad. Each file crosses the same
hostile-input boundary as a profile (rigcad.profile.loader.parse) and its errors name its file:line.

A file says its ``kind`` (projector, camera, lens or splitter), a ``title`` (what to buy), an
optional ``note``, its figures as the profile's own keys (``resolution: [2048, 1536]``,
``pixel_pitch: 3.45 um``, ``body_width: 29 mm``; a lens file fills the camera's lens keys) and
``sources:`` (per figure, where it was read: a datasheet's address, or the thesis). The shipped files
give a figure only with its source. A figure no file gives and the profile does not set is the
schema's default: *assumed*, and :func:`measurements` lists the instrument sizes among those for the
lab to measure before printing (the manual opens with that list). Precedence, most specific first
(rigcad.profile.schema): what the profile's own file states (the lab's measurement) > the instrument
files it names > what it inherits by ``extends:`` > the schema's defaults; in a chain, each profile's
own keys win over the files it names, and those over what it extends.

Sourcing (the shipped files were written without web access; the makers' pages were read through a
stored-page search): Basler publishes the ace U body size, sensor and pixel size per model
(docs.baslerweb.com); FLIR publishes the Blackfly S mounting holes; the C-mount flange distance is
the standard's. No projector drawing (body, mounting holes, lens position) was found: every projector
size is assumed. Kernel-free, numpy-free.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from rigcad.errors import ProfileError
from rigcad.profile.paths import INSTRUMENTS_SUBDIR, display, search_path

#: The keys of ``projector`` / ``camera`` whose values describe the body and its optics (mm, or a
#: thread name): what an instrument file may source and what :func:`measurements` may ask for.
PROJECTOR_SIZES = ("body_width", "body_height", "body_depth", "lens_diameter", "lens_length", "pupil_depth",
                   "pupil_height", "pupil_lateral", "mount_thread", "mount_depth", "mount_holes", "focus_min",
                   "focus_max")
CAMERA_SIZES = ("body_width", "body_height", "body_depth", "lens_diameter", "lens_length", "pupil_depth",
                "pupil_height", "mount_thread", "mount_spacing")

#: C-mount flange focal distance (mm): the lens seat to the image plane, fixed by the standard
#: (17.526 mm = 0.69 in; LUCID's back-focal-distance table lists it for every C-mount body,
#: https://support.thinklucid.com/knowledgebase/back-focal-distance).
C_MOUNT_FLANGE = 17.526

#: Each kind of instrument file: the profile key that names one, and the profile section its
#: figures fill (a lens file fills the camera's lens keys).
NAMED_BY: dict[str, tuple[str, str]] = {"projector": ("projector", "model"), "camera": ("camera", "model"),
                                        "lens": ("camera", "lens"), "splitter": ("beam_splitter", "model")}
#: The figures each kind of file may give, as the keys of the section it fills.
FIGURE_KEYS: dict[str, tuple[str, ...]] = {
    "projector": ("resolution", "native_resolution", "throw_ratio", "lens_offset") + PROJECTOR_SIZES,
    "camera": ("resolution", "pixel_pitch") + CAMERA_SIZES,
    "lens": ("focal_length", "lens_diameter", "lens_length", "pupil_depth", "min_working_distance"),
    "splitter": ("width", "length", "thickness", "reflectance", "coating", "index"),
}
#: The keys of a file besides its figures.
HEADER_KEYS = ("kind", "title", "note", "sources")
#: An instrument's name: its file's name without ``.yaml`` (no path: a profile names a file, it
#: cannot reach outside the instrument folders).
INSTRUMENT_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,99}")
#: A key an error may quote as written (the schema quotes anything else only by its kind).
_KEY = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,39}")


@dataclass(frozen=True)
class Instrument:
    """One instrument file as read: ``figures`` maps the section's keys to the values as written
    (the schema converts them with the key's own Spec), ``marks`` each figure to the ``file:line``
    that gives it, ``sources`` each figure that says so to where it was read (a datasheet)."""

    kind: str  #: "projector", "camera", "lens" or "splitter"
    name: str
    title: str
    file: str  #: the file as messages name it (``profiles/instruments/<name>.yaml``)
    figures: dict[str, object] = field(default_factory=dict)
    marks: dict[str, str] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)
    note: str = ""
    path: str = ""  #: the file, absolute (what a watcher of the profile watches)

    @property
    def section(self) -> str:
        return NAMED_BY[self.kind][0]

    def sourced(self, key: str) -> bool:
        """True when the file gives ``key`` with the source it was read from."""
        return key in self.figures and key in self.sources


def unknown_key(key: object) -> str:
    """A key as an error shows it: quoted when it looks like a setting's name, else not shown (a
    line of a file that is no instrument file is never echoed)."""
    return repr(key) if isinstance(key, str) and _KEY.fullmatch(key) else "(not a setting's name; not shown)"


def suggest(name: str, valid: list[str]) -> str:
    close = difflib.get_close_matches(name, valid, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def folders(near: Path | None = None) -> list[Path]:
    """Where instrument files are looked for, first match wins: ``near`` (the profile's own
    ``instruments/``), then ``instruments/`` under each folder of the profile search path."""
    return ([near] if near is not None else []) + search_path(INSTRUMENTS_SUBDIR)


def find(name: object, kind: str, where: str | None, near: Path | None = None) -> Path:
    """The file of instrument ``name`` (a ``kind``, named by the profile key NAMED_BY[kind] at
    ``where``), or a ProfileError naming the key, where it looked and the closest names found."""
    from rigcad.profile.loader import find_file

    key = ".".join(NAMED_BY[kind])
    if not isinstance(name, str) or not INSTRUMENT_NAME.fullmatch(name):
        raise ProfileError(f"{key}: {str(name)[:60]!r} is not an instrument's name; name a {kind} file under "
                           f"{INSTRUMENTS_SUBDIR}/ by its name without .yaml (letters, digits, '_', '.', '+', '-')",
                           where=where)
    try:
        return find_file(name, kind, sub=INSTRUMENTS_SUBDIR, near=near, as_path=False)
    except ProfileError as err:  # it says where it looked and the closest name found
        raise ProfileError(f"{key}: {err.message}; add your own as {INSTRUMENTS_SUBDIR}/{name}.yaml beside the "
                           "profile", where=where) from None


def read(path: Path, kind: str, named_where: str | None = None) -> Instrument:
    """Read and check instrument file ``path``, which the profile names as a ``kind``: its structure,
    its kind, its keys (those of FIGURE_KEYS[kind]) and its sources (each names a figure of the
    file). The values are converted by the schema. Raises ProfileError with the file:line."""
    from rigcad.profile.loader import parse

    shown = display(path)
    data, marks = parse(path, "instrument")
    key = ".".join(NAMED_BY[kind])
    if not isinstance(data, dict):
        raise ProfileError(f"an instrument file is a mapping of keys (kind, title, its figures, sources), named by "
                           f"{key}" + (f" at {named_where}" if named_where else ""), where=f"{shown}:1")

    def at(*k: str) -> str:
        return marks.get(k) or f"{shown}:1"

    given = data.get("kind")
    if given not in NAMED_BY:
        raise ProfileError(f"kind: {str(given)[:40]!r}: an instrument file says its kind, one of "
                           f"{', '.join(NAMED_BY)}", where=at("kind"))
    if given != kind:
        raise ProfileError(f"kind: {given}, but {key}" + (f" ({named_where})" if named_where else "")
                           + f" names a {kind}: name a {kind} file there, or this file under "
                           f"{'.'.join(NAMED_BY[given])}", where=at("kind"))
    valid = list(HEADER_KEYS) + list(FIGURE_KEYS[kind])
    for k in data:
        if k not in valid:
            raise ProfileError(f"unknown key {unknown_key(k)} in a {kind} file{suggest(str(k), valid)}; valid: "
                               f"{', '.join(valid)}", where=at(str(k)))
    title = data.get("title")
    if not isinstance(title, str) or not title.strip():
        raise ProfileError(f"title: a {kind} file names what it is (the maker's name and model, what the bill "
                           "lists), as text", where=at("title"))
    note = data.get("note", "")
    if not isinstance(note, str):
        raise ProfileError("note: expected text", where=at("note"))
    figures = {k: v for k, v in data.items() if k not in HEADER_KEYS}
    sources = data.get("sources") or {}
    if not isinstance(sources, dict):
        raise ProfileError("sources: expected a mapping of each figure to where it was read (a datasheet's "
                           "address)", where=at("sources"))
    for k, v in sources.items():
        if k not in figures:
            shown_key = k if isinstance(k, str) and _KEY.fullmatch(k) else unknown_key(k)
            raise ProfileError(f"sources.{shown_key}: not a figure of this file; the sources name its figures: "
                               f"{', '.join(figures) or 'none given'}", where=at("sources", str(k)))
        if not isinstance(v, str) or not v.strip():
            raise ProfileError(f"sources.{k}: expected where the figure was read, as text", where=at("sources", k))
    return Instrument(kind=kind, name=path.stem, title=title.strip(), file=shown, figures=figures,
                      marks={k: at(k) for k in figures}, sources=dict(sources), note=note.strip(),
                      path=str(path.absolute()))


def shipped(kind: str | None = None) -> list[Instrument]:
    """The instrument files shipped with rigcad (of ``kind``, or all), by name."""
    from rigcad.profile.paths import SHIPPED_PROFILES

    out = []
    for path in sorted((SHIPPED_PROFILES / INSTRUMENTS_SUBDIR).glob("*.yaml")):
        from rigcad.profile.loader import parse

        data, _ = parse(path, "instrument")
        k = data.get("kind") if isinstance(data, dict) else None
        if k in NAMED_BY and (kind is None or k == kind):
            out.append(read(path, k))
    return out


@dataclass(frozen=True)
class Measurement:
    """One dimension the lab must measure: the profile key, what it is, the value now assumed, and
    the figure that shows it (``view``: side / top / front of the instrument; ``between``: the two
    features the dimension runs between, as the figure draws them)."""

    key: str
    what: str
    assumed: object
    unit: str
    view: str
    between: tuple[str, str]


#: How each size is measured and drawn: (view, from, to).
FIGURES: dict[str, tuple[str, str, str]] = {
    "body_width": ("top", "left side face", "right side face"),
    "body_height": ("side", "bottom (mounting) face", "top face"),
    "body_depth": ("side", "front face (lens excluded)", "back face"),
    "lens_diameter": ("front", "lens barrel, one side", "lens barrel, other side"),
    "lens_length": ("side", "body's front face", "lens barrel's front"),
    "pupil_depth": ("side", "lens barrel's front", "entrance pupil (no-parallax point: rotate the instrument "
                    "about a vertical axis until near and far targets stay aligned)"),
    "pupil_height": ("side", "bottom (mounting) face", "optical axis (centre of the lens barrel)"),
    "pupil_lateral": ("top", "body's centre line", "optical axis (centre of the lens barrel)"),
    "mount_thread": ("bottom", "mounting hole", "its thread (screw a gauge or a known screw in)"),
    "mount_depth": ("side (cut through a hole)", "mounting hole's mouth", "its bottom (a depth gauge or a screw "
                    "with a nut)"),
    "mount_spacing": ("bottom", "first mounting hole's centre", "second mounting hole's centre"),
    "mount_holes": ("bottom", "entrance pupil (the COP) on the optical axis, projected onto the bottom face",
                    "centre of each mounting hole: along the axis back from the pupil, and across it (+ to the "
                    "right seen from behind)"),
    "focus_min": ("side", "entrance pupil (the COP)", "nearest wall the projector focuses sharply"),
    "focus_max": ("side", "entrance pupil (the COP)", "farthest wall the projector focuses sharply"),
}


#: The projector's entrance pupil cannot be sighted through (the no-parallax point is a camera's method):
#: it is where the lines through the projected image's side edges cross. Project a full white frame on a
#: flat wall square to the axis from these two distances (mm, lens barrel's front to the wall) and read
#: the image's width at each (the width: a projector's lens shift moves the image up, not sideways).
PUPIL_WALLS_MM = (1000.0, 2000.0)
#: Each distance and width read with a steel tape to this (mm).
PUPIL_READ_MM = 1.0


def projector_pupil(throw_ratio: float, pupil_depth: float, walls=PUPIL_WALLS_MM, read=PUPIL_READ_MM) -> dict:
    """The two-wall measure of the projector's pupil (mm): with widths w1, w2 at distances d1, d2 from the
    barrel's front, w = (d + p) / throw_ratio gives p = (w1 d2 - w2 d1) / (w2 - w1) behind the front. Its
    uncertainty, every reading off by ``read`` independently (first order, root sum of squares of
    dp/dw1 = T (d2 + p) / (d2 - d1), dp/dw2 = -T (d1 + p) / (d2 - d1), dp/dd1 = -(d2 + p) / (d2 - d1),
    dp/dd2 = (d1 + p) / (d2 - d1)), at the assumed ``pupil_depth`` p and ``throw_ratio`` T."""
    d1, d2 = walls
    t, p = throw_ratio, pupil_depth
    a, b = d1 + p, d2 + p
    sigma = read * math.sqrt((1 + t * t) * (a * a + b * b)) / (d2 - d1)
    return {"walls_mm": [d1, d2], "widths_mm": [a / t, b / t], "read_mm": read, "uncertainty_mm": sigma}


def pupil_from_widths(walls, widths) -> float:
    """The pupil's depth behind the barrel's front (mm) from the two walls' distances and the image's
    widths there (:func:`projector_pupil`'s formula)."""
    (d1, d2), (w1, w2) = walls, widths
    return (w1 * d2 - w2 * d1) / (w2 - w1)


def _projector_pupil_text(projector, height_tolerance: float) -> str:
    """The measure's text; ``height_tolerance`` (mm, ``tolerancing.projector_height``): the splitter turns an
    error along the projector's axis into the COP's height."""
    m = projector_pupil(projector.throw_ratio, projector.pupil_depth)
    worse = m["uncertainty_mm"] > height_tolerance
    (d1, d2), (w1, w2) = m["walls_mm"], m["widths_mm"]
    return (f"entrance pupil (a projector cannot be sighted through, so project a full white frame on a flat wall "
            f"square to the axis from {d1:g} mm and {d2:g} mm (lens barrel's front to the wall) and read the image's "
            f"width at each (about {w1:.0f} and {w2:.0f} mm at the assumed sizes); the lines through its edges cross "
            f"at the pupil, p = (w1 d2 - w2 d1) / (w2 - w1) behind the barrel's front, to ±{m['uncertainty_mm']:.1f} mm "
            f"with each reading to {m['read_mm']:g} mm"
            + (f", wider than the COP's height tolerance (`tolerancing.projector_height`, {height_tolerance:g} mm; the "
               "splitter turns this error into the COP's height): take the maker's figure where it gives one, or "
               "read more walls and fit the line" if worse else "") + ")")


#: The assumed mounting pattern when nothing gives ``projector.mount_holes``: four holes this far (mm)
#: in from the body's bottom corners, along and across.
DEFAULT_MOUNT_INSET = 30.0


def mount_pattern(projector) -> tuple[tuple[float, float], ...]:
    """The projector's mounting holes (mm), each (along, across): along its optical axis back from
    its COP, across it to the right seen from behind (``projector.mount_holes``); when nothing gives
    them, the assumed four, DEFAULT_MOUNT_INSET in from the bottom face's corners of the body that
    ``body_depth``, ``body_width``, ``lens_length``, ``pupil_depth`` and ``pupil_lateral`` place."""
    if projector.mount_holes is not None:
        return tuple(projector.mount_holes)
    back = projector.lens_length - projector.pupil_depth  # the body's front face, back from the COP
    left = -projector.pupil_lateral - projector.body_width / 2  # its left side, across from the axis
    e = DEFAULT_MOUNT_INSET
    return tuple((a, c) for a in (back + e, back + projector.body_depth - e)
                 for c in (left + e, left + projector.body_width - e))


def _pattern_text(holes) -> str:
    return "[" + ", ".join(f"[{a:g}, {c:g}]" for a, c in holes) + "]"


@dataclass(frozen=True)
class Sketch:
    """A measurement's figure as lines in the plane of its view (mm; ``axes``: what the horizontal
    and vertical run along): the instrument's outline (``outlines``: named closed polylines,
    ``circles``: named (centre, radius)), and the dimension drawn between its two features
    (``dimension``: two points; equal points: a call-out pointing at one feature); ``window``: the
    detail shown ((x0, y0), (x1, y1)) when the feature is small against the body, else None."""

    key: str
    view: str
    axes: tuple[str, str]
    outlines: tuple[tuple[str, tuple[tuple[float, float], ...]], ...]
    circles: tuple[tuple[str, tuple[float, float], float], ...]
    dimension: tuple[tuple[float, float], tuple[float, float]]
    label: str
    window: tuple[tuple[float, float], tuple[float, float]] | None = None


def _around(x: float, y: float, half: float) -> tuple[tuple[float, float], tuple[float, float]]:
    return ((x - half, y - half), (x + half, y + half))


def _rect(x0: float, y0: float, x1: float, y1: float) -> tuple[tuple[float, float], ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0))


def _holes_along(params) -> list[float]:
    """Where the mounting holes are drawn along the body's depth (mm from its back face): the
    camera's two, mount_spacing apart about the middle; a projector's one, in the middle."""
    d = params.body_depth
    spacing = getattr(params, "mount_spacing", None)
    return [d / 2 - spacing / 2, d / 2 + spacing / 2] if spacing else [d / 2]


def _side(params, key: str, m: Measurement) -> Sketch:
    """Side view: along the axis from the body's back face (0) to the lens front; up from the bottom face."""
    d, h, ld, ll = params.body_depth, params.body_height, params.lens_diameter, params.lens_length
    ph, front = params.pupil_height, params.body_depth + params.lens_length
    pupil = front - params.pupil_depth
    outlines = [("body", _rect(0.0, 0.0, d, h)), ("lens", _rect(d, ph - ld / 2, front, ph + ld / 2))]
    dims = {"body_height": ((-0.1 * d, 0.0), (-0.1 * d, h)), "body_depth": ((0.0, -0.1 * h), (d, -0.1 * h)),
             "lens_length": ((d, ph + ld / 2 + 0.1 * h), (front, ph + ld / 2 + 0.1 * h)),
             "pupil_depth": ((pupil, ph), (front, ph)), "pupil_height": ((pupil, 0.0), (pupil, ph))}
    if key in ("focus_min", "focus_max"):
        wall = pupil + getattr(params, key)
        outlines.append(("wall", ((wall, -0.5 * h), (wall, 1.5 * h))))
        return Sketch(m.key, m.view, ("along the optical axis (mm)", "height (mm)"), tuple(outlines), (),
                      ((pupil, ph), (wall, ph)), _label(m))
    if key == "mount_depth":
        x, r = _holes_along(params)[0], 2.5
        outlines.append(("mounting hole (cut)", _rect(x - r, 0.0, x + r, params.mount_depth)))
        return Sketch(m.key, m.view, ("along the optical axis (mm)", "height (mm)"), tuple(outlines), (),
                      ((x + 2 * r, 0.0), (x + 2 * r, params.mount_depth)), _label(m),
                      _around(x, params.mount_depth / 2, 2 * params.mount_depth))
    return Sketch(m.key, m.view, ("along the optical axis (mm)", "height (mm)"), tuple(outlines), (), dims[key],
                  _label(m))


def _top(params, key: str, m: Measurement) -> Sketch:
    """Top view: along the axis as in the side view; across from the body's centre line."""
    d, w, ld, front = params.body_depth, params.body_width, params.lens_diameter, params.body_depth + params.lens_length
    lat = getattr(params, "pupil_lateral", 0.0)
    outlines = (("body", _rect(0.0, -w / 2, d, w / 2)), ("lens", _rect(d, lat - ld / 2, front, lat + ld / 2)),
                ("centre line", ((-0.05 * d, 0.0), (front + 0.05 * d, 0.0))))
    dims = {"body_width": ((0.5 * d, -w / 2), (0.5 * d, w / 2)), "pupil_lateral": ((front, 0.0), (front, lat))}
    return Sketch(m.key, m.view, ("along the optical axis (mm)", "across (mm)"), outlines, (), dims[key], _label(m))


def _front(params, key: str, m: Measurement) -> Sketch:
    """Front view, into the lens: across from the centre line, up from the bottom face."""
    w, h, ld, ph = params.body_width, params.body_height, params.lens_diameter, params.pupil_height
    lat = getattr(params, "pupil_lateral", 0.0)
    return Sketch(m.key, m.view, ("across (mm)", "height (mm)"), (("body", _rect(-w / 2, 0.0, w / 2, h)),),
                  (("lens barrel", (lat, ph), ld / 2),), ((lat - ld / 2, ph), (lat + ld / 2, ph)), _label(m))


def _bottom(params, key: str, m: Measurement) -> Sketch:
    """Bottom view: along the axis from the back face; across from the centre line; the mounting holes."""
    d, w = params.body_depth, params.body_width
    if key == "mount_holes":  # the projector's pattern, from its COP (at the lens front less the pupil depth)
        cop = d + params.lens_length - params.pupil_depth
        lat = params.pupil_lateral
        holes = [(cop - a, lat + c) for a, c in mount_pattern(params)]
        circles = tuple((f"mounting hole {k + 1}", p, 2.5) for k, p in enumerate(holes))
        outlines = (("body", _rect(0.0, -w / 2, d, w / 2)),
                    ("optical axis", ((-0.05 * d, lat), (d + params.lens_length, lat))))
        return Sketch(m.key, m.view, ("along the optical axis (mm)", "across (mm)"), outlines, circles,
                      ((cop, lat), holes[0]), _label(m))
    xs = _holes_along(params)
    circles = tuple((f"mounting hole {k + 1}", (x, 0.0), 2.5) for k, x in enumerate(xs))
    dim = ((xs[0], 0.0), (xs[-1], 0.0)) if key == "mount_spacing" else ((xs[0], 0.0), (xs[0], 0.0))
    window = _around(0.5 * (xs[0] + xs[-1]), 0.0, max(15.0, xs[-1] - xs[0]))
    return Sketch(m.key, m.view, ("along the optical axis (mm)", "across (mm)"), (("body", _rect(0.0, -w / 2, d, w / 2)),),
                  circles, dim, _label(m), window)


def _label(m: Measurement) -> str:
    value = f"{m.assumed:g} {m.unit}" if isinstance(m.assumed, (int, float)) else f"{m.assumed} {m.unit}".strip()
    return f"{value} (assumed)"


def sketch(profile, m: Measurement) -> Sketch:
    """The figure of measurement ``m`` (one of :func:`measurements` for ``profile``): the instrument's
    outline in ``m.view``, drawn at the profile's (assumed) sizes, with the dimension between the two
    features FIGURES names for it."""
    section, key = m.key.split(".", 1)
    params = getattr(profile, section)
    draw = {"side": _side, "top": _top, "front": _front, "bottom": _bottom}[m.view.split(" ")[0]]
    return draw(params, key, m)


def size_origin(profile, section: str, keys: tuple[str, ...]) -> str:
    """Where an instrument's size (``keys`` of ``section``) came from, for a label: "assumed size"
    when no key was set, "size set in the profile" or "size from <instrument file name>" when every
    key was, else "size partly assumed (<the keys nothing set>)" (``profile.set_by``)."""
    by = {k: profile.set_by(section, k) for k in keys}
    if all(v == "default" for v in by.values()):
        return "assumed size"
    assumed = [k for k, v in by.items() if v == "default"]
    if assumed:
        return f"size partly assumed ({', '.join(assumed)})"
    if all(v == "profile" for v in by.values()):
        return "size set in the profile"
    files = sorted({profile.origin(section, k).rsplit(":", 1)[0].rsplit("/", 1)[-1].removesuffix(".yaml")
                    for k, v in by.items() if v == "instrument"})
    return f"size from {', '.join(files)}" + (" and the profile" if "profile" in by.values() else "")


#: The figures that decide the optics (the field of view, where the paraboloid's disc sits in the image,
#: the lens in millimetres, what the camera can focus on), with how a lab reads or checks each: not sizes
#: of a body, so no outline figure; the manual lists them before printing with where each came from.
OPTICS_FIGURES: dict[str, str] = {
    "projector.throw_ratio": "the projector's datasheet, or: project a full white image on a wall square to the "
                             "axis, throw distance (wall to the lens's pupil) / the image's width",
    "projector.lens_offset": "the datasheet's offset, or: on that wall, (the image's centre height - the lens "
                             "axis's height) / half the image's height",
    "camera.pixel_pitch": "the camera's or its sensor's datasheet (sensor width / pixels across)",
    "camera.min_working_distance": "the lens's datasheet (MOD), or: focus at its nearest setting and measure from "
                                   "the lens's front to the nearest sharp object",
}


@dataclass(frozen=True)
class OpticsFigure:
    """One figure that decides the optics, as section 0 of the manual lists it: its key, its value in
    force (text with its unit), what it is, how a lab reads or checks it, where it came from
    (``profile.origin``: a file:line or "default") and ``state``: "datasheet" (an instrument file
    gives it with its source), "instrument file" (given without a source), "profile" (the profile's
    file states it), "assumed" (the schema's default) or "unknown" (no default: not checked)."""

    key: str
    value: str
    what: str
    how: str
    origin: str
    state: str


def optics_figures(profile) -> list[OpticsFigure]:
    """The figures of :data:`OPTICS_FIGURES` for ``profile`` (a validated Profile), each with where it
    came from; the throw ratio, lens offset, pixel pitch and the camera lens's closest focus."""
    from dataclasses import fields

    out = []
    for key, how in OPTICS_FIGURES.items():
        section, name = key.split(".")
        params = getattr(profile, section)
        spec = next(f.metadata["spec"] for f in fields(params) if f.name == name)
        value = getattr(params, name)
        by = profile.set_by(section, name)
        if value is None:
            text, state = "unknown", "unknown"
        else:
            text = {"length": f"{value * 1000:g} um" if name == "pixel_pitch" else f"{value:g} mm",
                    "fraction": f"{value:g} half image heights", "float": f"{value:g}"}.get(spec.kind, f"{value}")
            state = {"profile": "profile", "default": "assumed"}.get(
                by, "datasheet" if profile.source(section, name) else "instrument file")
        out.append(OpticsFigure(key, text, spec.doc, how, profile.origin(section, name), state))
    return out


def measurements(profile) -> list[Measurement]:
    """What must be measured before printing, for ``profile`` (a validated Profile): each projector
    and camera size that neither an instrument file the profile names gives nor the profile sets
    (``profile.set_by(section, key) == "default"``)."""
    from dataclasses import fields

    out: list[Measurement] = []
    for section, keys in (("projector", PROJECTOR_SIZES), ("camera", CAMERA_SIZES)):
        params = getattr(profile, section)
        docs = {f.name: f.metadata["spec"] for f in fields(params)}
        for key in keys:
            if profile.set_by(section, key) != "default":
                continue
            view, a, b = FIGURES[key]
            if (section, key) == ("projector", "pupil_depth"):
                b = _projector_pupil_text(params, profile.tolerancing.projector_height)
            value = getattr(params, key)
            if key == "mount_holes":  # the pattern assumed, as [along, across] pairs
                value = _pattern_text(mount_pattern(params))
            out.append(Measurement(f"{section}.{key}", docs[key].doc, value,
                                   "mm" if key == "mount_holes" else "" if isinstance(value, str) else "mm", view,
                                   (a, b)))
    return out


__all__ = ["CAMERA_SIZES", "C_MOUNT_FLANGE", "DEFAULT_MOUNT_INSET", "FIGURES", "FIGURE_KEYS", "Instrument", "Measurement",
           "NAMED_BY", "OPTICS_FIGURES", "OpticsFigure", "PROJECTOR_SIZES", "PUPIL_READ_MM", "PUPIL_WALLS_MM", "Sketch", "find", "folders", "measurements", "mount_pattern", "optics_figures", "projector_pupil", "pupil_from_widths", "read", "shipped",
           "size_origin", "sketch"]
