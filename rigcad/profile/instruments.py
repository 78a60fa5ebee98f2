"""The instrument library: projectors and cameras a profile picks by name (``projector.model``,
``camera.model``), with the sizes the COP tower is built around (mm), each with its source.

A dimension is *sourced* when a maker's published page gives it (the address is in ``sources``);
every other dimension the tower needs is *assumed*: the profile schema's default stands in, and
:func:`measurements` lists it for the lab to measure before printing (the manual opens with that
list). A profile that gives a key itself (``projector.pupil_height: 52 mm``) has measured it: it
leaves the list.

Sourcing (this module was written without web access; the makers' pages were read through a
stored-page search): Basler publishes the ace U body size per model (docs.baslerweb.com); FLIR
publishes the Blackfly S mounting holes (softwareservices.flir.com, "Physical Interface"); the
C-mount flange distance is the standard's. No projector drawing (body, mounting holes, lens
position) was found: every projector size is assumed and marked so. Kernel-free, numpy-free data.
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: The keys of ``projector`` / ``camera`` whose values describe the body and its optics (mm, or a
#: thread name): what a library entry may source and what :func:`measurements` may ask for.
PROJECTOR_SIZES = ("body_width", "body_height", "body_depth", "lens_diameter", "lens_length", "pupil_depth",
                   "pupil_height", "pupil_lateral", "mount_thread", "mount_depth", "focus_min", "focus_max")
CAMERA_SIZES = ("body_width", "body_height", "body_depth", "lens_diameter", "lens_length", "pupil_depth",
                "pupil_height", "mount_thread", "mount_spacing")

#: C-mount flange focal distance (mm): the lens seat to the image plane, fixed by the standard
#: (17.526 mm = 0.69 in; LUCID's back-focal-distance table lists it for every C-mount body,
#: https://support.thinklucid.com/knowledgebase/back-focal-distance).
C_MOUNT_FLANGE = 17.526


@dataclass(frozen=True)
class Instrument:
    """One library entry: ``sizes`` maps profile keys (``PROJECTOR_SIZES`` / ``CAMERA_SIZES``) to
    sourced values (mm, or a thread name), ``sources`` maps each such key to where it was read,
    ``resolution`` is the sensor's or modulator's [width, height] in pixels, ``note`` what a reader
    should know (discontinued, which variant)."""

    kind: str  #: "projector" or "camera"
    name: str
    title: str
    resolution: tuple[int, int]
    resolution_source: str
    sizes: dict[str, object] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)
    note: str = ""

    def sourced(self, key: str) -> bool:
        return key in self.sizes


_BASLER_ACA2040_55UC = "https://docs.baslerweb.com/aca2040-55uc/ (Specifications: Size, Lens Mount, Resolution)"
_FLIR_BFS_PHYSICAL = "https://softwareservices.flir.com/BFS-U3-200S6/latest/Family/PhysicalDescription.htm"
_FLIR_BFS_32S4_SPEC = "https://softwareservices.flir.com/BFS-U3-32S4/latest/Model/spec.html"

LIBRARY: dict[str, Instrument] = {e.name: e for e in (
    # -- projectors --------------------------------------------------------------------------------
    Instrument("projector", "benq_pb6210", "BenQ PB6210 (the thesis's, 3.1; discontinued)", (1024, 768),
               "thesis 3.1", note="no datasheet at hand: every size is the schema's assumed default"),
    Instrument("projector", "ti_dlp_lightcrafter_4500", "Texas Instruments DLP LightCrafter 4500 EVM (DLPLCR4500EVM)",
               (912, 1140), "TI DLPC350/DLP4500 0.45 in WXGA DMD, 912 x 1140 diamond array (TI product page; "
               "not re-read here: assumed)",
               note="the mechanical drawing (DLPU011 user's guide) was not found by the stored-page search: the "
                    "optical engine's sizes, its M2.5/M3 mounting holes and its focus range are assumed; measure them"),
    Instrument("projector", "benq_mw632st", "BenQ MW632ST short-throw business projector (WXGA)", (1280, 800),
               "BenQ product page (not found by the stored-page search: assumed)",
               note="no drawing found: sizes assumed; its ceiling-mount holes are M4 on BenQ's business models "
                    "(assumed)"),
    Instrument("projector", "epson_eb_w52", "Epson EB-W52 business projector (WXGA, 3LCD)", (1280, 800),
               "Epson product page (not found by the stored-page search: assumed)",
               note="no drawing found: sizes assumed"),
    # -- cameras -----------------------------------------------------------------------------------
    Instrument("camera", "prosilica_ec1350c", "Prosilica EC 1350C (the thesis's, 3.1; discontinued)", (1360, 1024),
               "thesis 3.1", note="no datasheet at hand: every size is the schema's assumed default"),
    Instrument("camera", "basler_ace_u_aca2040_55uc", "Basler ace U acA2040-55uc (USB 3.0, C-mount)", (2048, 1536),
               _BASLER_ACA2040_55UC,
               sizes={"body_width": 29.0, "body_height": 29.0, "body_depth": 29.3},
               sources={"body_width": _BASLER_ACA2040_55UC, "body_height": _BASLER_ACA2040_55UC,
                        "body_depth": _BASLER_ACA2040_55UC + ": 29.3 x 29 x 29 mm without lens mount or connectors"},
               note="the ace has no 1/4-20 socket on the body (a tripod adapter or its M3 holes, spacing not "
                    "published on the page read): mount_thread and mount_spacing assumed; the lens (and so its "
                    "pupil) is the lab's choice"),
    Instrument("camera", "flir_blackfly_s_bfs_u3_32s4c", "FLIR Blackfly S BFS-U3-32S4C (USB 3, C-mount)", (2048, 1536),
               _FLIR_BFS_32S4_SPEC,
               sizes={"mount_thread": "M3"},
               sources={"mount_thread": _FLIR_BFS_PHYSICAL + ": M3x2.5 and M2x2.5 mounting holes"},
               note="body size (29 x 29 x 30 mm in FLIR's drawing, not re-read here) and the M3 holes' spacing "
                    "assumed; the lens is the lab's choice"),
    Instrument("camera", "allied_vision_alvium_1800_u_319c", "Allied Vision Alvium 1800 U-319c (USB 3, C-mount)",
               (2064, 1544), "Allied Vision Alvium 1800 U data sheet (not found by the stored-page search: assumed)",
               note="no drawing found: sizes and mounting holes assumed"),
)}


def names(kind: str) -> tuple[str, ...]:
    """The library's entries of ``kind`` ("projector" or "camera"), in library order."""
    return tuple(n for n, e in LIBRARY.items() if e.kind == kind)


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
    "focus_min": ("side", "entrance pupil (the COP)", "nearest wall the projector focuses sharply"),
    "focus_max": ("side", "entrance pupil (the COP)", "farthest wall the projector focuses sharply"),
}


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


def measurements(profile) -> list[Measurement]:
    """What must be measured before printing, for ``profile`` (a validated Profile): each projector
    and camera size that neither the chosen library entry sources nor the profile gives."""
    from dataclasses import fields

    out: list[Measurement] = []
    for section, keys in (("projector", PROJECTOR_SIZES), ("camera", CAMERA_SIZES)):
        params = getattr(profile, section)
        entry = LIBRARY[params.model]
        docs = {f.name: f.metadata["spec"] for f in fields(params)}
        for key in keys:
            if entry.sourced(key) or (section, key) in profile.marks:
                continue
            view, a, b = FIGURES[key]
            value = getattr(params, key)
            out.append(Measurement(f"{section}.{key}", docs[key].doc, value,
                                   "" if isinstance(value, str) else "mm", view, (a, b)))
    return out


__all__ = ["CAMERA_SIZES", "C_MOUNT_FLANGE", "FIGURES", "Instrument", "LIBRARY", "Measurement", "PROJECTOR_SIZES",
           "Sketch", "measurements", "names", "sketch"]
