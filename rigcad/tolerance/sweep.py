"""Parameter sweeps on rigcad.engine: ``--set section.key=A..B:N`` builds N designs with the key
at N evenly spaced values from A to B (units as in a profile: ``25cm..35cm:21``; or a list
``v1,v2,...``), each validated as a profile value (a value out of range is refused naming the key)
and built as its own Rig. One row per design: the 2D design's figures, the 3D check's figures on
the analytic tracer (aligned, ``rays`` pinhole rays), and whether every part fits a printer whole
(meshed at FIT_CHORD_MM). A design that cannot be built is a row with ``ok`` false and the reason.
"""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass

import numpy as np

from rigcad.engine import Engine, run
from rigcad.errors import ProfileError, RigcadError

#: Chord error (mm) of the meshes the printer fit is judged on: the fit has centimetre margins or
#: none, 0.3 mm does not change the verdict and meshes every part in about a second.
FIT_CHORD_MM = 0.3
#: Most designs one sweep builds: each is a dome integrated, traced and meshed (about a second
#: each on one core), so 10,000 is a day of a workstation; more is a slip of the keyboard, and
#: ``--set ...:100000000`` would hold a hundred million values before the first design.
MAX_POINTS = 10_000
_RANGE = re.compile(r"^\s*(?P<a>[^.][^:]*?)\s*\.\.\s*(?P<b>[^:]+?)\s*:\s*(?P<n>\d+)\s*$")


@dataclass(frozen=True)
class SweepSpec:
    """The swept key (``section.key``), its kind (length, angle, int, float) and values in
    internal units (mm, rad)."""

    section: str
    key: str
    kind: str
    values: tuple

    @property
    def name(self) -> str:
        return f"{self.section}.{self.key}"

    @property
    def unit(self) -> str:
        return {"length": "mm", "angle": "rad"}.get(self.kind, "")


def parse_set(text: str) -> SweepSpec:
    """``section.key=A..B:N`` or ``section.key=v1,v2,...`` -> SweepSpec; ProfileError naming
    ``--set`` and what would be valid."""
    from rigcad.profile.schema import SECTIONS, convert_value, suggest
    from dataclasses import fields

    if "=" not in text:
        raise ProfileError(f"--set {text!r}: expected section.key=A..B:N (e.g. layout.cop_to_vertex=25cm..35cm:21) "
                           "or section.key=v1,v2,...", param="--set")
    name, spec = text.split("=", 1)
    if name.count(".") != 1:
        raise ProfileError(f"--set {name!r}: expected section.key, e.g. layout.cop_to_vertex", param="--set")
    section, key = name.strip().split(".")
    if section not in SECTIONS:
        raise ProfileError(f"--set: unknown section {section!r}{suggest(section, list(SECTIONS))}; valid: "
                           + ", ".join(SECTIONS), param="--set")
    specs = {f.name: f.metadata["spec"] for f in fields(SECTIONS[section])}
    if key not in specs:
        raise ProfileError(f"--set: unknown key {section}.{key}{suggest(key, list(specs))}; valid keys in "
                           f"{section}: {', '.join(specs)}", param="--set")
    s = specs[key]
    if s.kind not in ("length", "angle", "int", "float"):
        raise ProfileError(f"--set {section}.{key}: a {s.kind} cannot be swept; sweep a length, angle or number",
                           param="--set")

    def value(v: str):
        v = v.strip()
        raw = v if s.kind in ("length", "angle") else _number(v, f"{section}.{key}", s.kind)
        return convert_value(s, raw, f"--set {section}.{key}", "--set")

    m = _RANGE.match(spec)
    if m:
        n = int(m["n"])
        if n < 2 or n > MAX_POINTS:
            raise ProfileError(f"--set {name}: {m['n']} points; a range needs at least 2 and at most {MAX_POINTS} "
                               "(A..B:N): each point is a design built and traced", param="--set")
        a, b = value(m["a"]), value(m["b"])
        values = np.linspace(a, b, n)
        if s.kind == "int":
            values = np.unique(np.round(values).astype(int))
        vals = tuple(int(v) if s.kind == "int" else float(v) for v in values)
    else:
        items = [v for v in spec.split(",") if v.strip()]
        if len(items) > MAX_POINTS:
            raise ProfileError(f"--set {name}: {len(items)} values; a sweep builds at most {MAX_POINTS} designs",
                               param="--set")
        vals = tuple(value(v) for v in items)
        if not vals:
            raise ProfileError(f"--set {name}: no values; expected A..B:N or v1,v2,...", param="--set")
    for v in vals:  # every value must be valid for the key (the ends were; integers rounded stay so)
        convert_value(s, _as_profile_value(v, s.kind), f"--set {section}.{key}", "--set")
    return SweepSpec(section, key, s.kind, vals)


def _number(text: str, key: str, kind: str):
    try:
        return int(text) if kind == "int" else float(text)
    except ValueError:
        raise ProfileError(f"--set {key}: {text!r} is not a {'whole ' if kind == 'int' else ''}number",
                           param="--set") from None


def _as_profile_value(v, kind: str):
    """A value in internal units as a profile would write it."""
    if kind == "length":
        return f"{v!r} mm"
    if kind == "angle":
        return f"{v!r} rad"
    return v


def profile_with(raw, spec: SweepSpec, value):
    """The profile ``raw`` (a RawProfile) with the swept key at ``value``, validated."""
    from dataclasses import replace

    from rigcad.profile.schema import validate

    data = copy.deepcopy(raw.data)
    data.setdefault(spec.section, {})
    if data[spec.section] is None:
        data[spec.section] = {}
    data[spec.section][spec.key] = _as_profile_value(value, spec.kind)
    marks = dict(raw.marks)
    marks[(spec.section, spec.key)] = f"--set {spec.name}"
    depths = {k: d for k, d in raw.depths.items() if k != (spec.section, spec.key)}  # --set: the profile's own
    return validate(replace(raw, data=data, marks=marks, depths=depths))  # the same precedence as the profile


@dataclass(frozen=True)
class SweepJob:
    raw: object
    spec: SweepSpec
    rays: int
    seed: int
    printer: object


def _design_row(job: SweepJob, i: int) -> dict:
    """One design of the sweep (a task)."""
    from rigcad.check import montecarlo as MC
    from rigcad.check.raycheck import pixels_per_degree
    from rigcad.check.scene import analytic_optics
    from rigcad.check.sources import annulus_rays
    from rigcad.check.trace3d import trace
    from rigcad.rig import Rig

    value = job.spec.values[i]
    row = {"index": i, "value": value, "ok": True, "error": ""}
    try:
        rig = Rig.from_profile(profile_with(job.raw, job.spec, value))
        r = rig.design.report
        env, rng = r["envelope"], r["measurable_range"]
        row.update({"dome_width_mm": env["width_mm"], "dome_height_mm": env["height_mm"],
                    "design_theta_min_deg": rng["theta_min_deg"], "design_theta_max_deg": rng["theta_max_deg"],
                    "design_max_miss_mm": r["convergence"]["max_miss_mm"],
                    "pixels_vertex_to_rim": r["pixels"]["vertex_to_rim_px"]})
        optics = analytic_optics(rig)
        design = rig.incidence
        rays = annulus_rays(design, job.rays, job.seed)
        tr = trace(optics, rays.origins, rays.dirs)
        f = MC.figures(tr, design.direction(rays.chief))
        theta = np.degrees(tr.theta[tr.ok])
        fan = pixels_per_degree(optics, design)["summary"]
        row.update({"check_max_spot_radius_mm": f["max_spot_radius_mm"],
                    "check_max_angle_error_rad": f["max_angle_error_rad"],
                    "check_lost_fraction": 1.0 - f["rays_ok"] / f["rays"],
                    "check_theta_min_deg": float(theta.min()), "check_theta_max_deg": float(theta.max()),
                    "check_px_per_deg_min": fan["px_per_deg_min"]})
        if job.printer is not None:
            row.update(_fit(rig, job.printer))
    except RigcadError as err:
        row.update({"ok": False, "error": str(err)})
    return row


def _fit(rig, printer) -> dict:
    """Does every part fit ``printer`` whole, in some candidate orientation?"""
    from rigcad.fab import orientation as O

    split = []
    for name, part in rig.recipes.items():
        m = rig.mesh(name, chord_error=FIT_CHORD_MM)
        cands = O.mirror_candidates(None) if name in ("dome", "paraboloid") else O.generic_candidates()
        if not any(O.fit_spin(np.asarray(m.vertices), o.direction, printer.usable)[0] is not None for o in cands):
            split.append(name)
    return {"printer": printer.name, "parts_to_split": " ".join(split), "parts_to_split_count": len(split),
            "dome_fits_whole": "dome" not in split}


def run_sweep(raw, spec: SweepSpec, rays: int, seed: int, printer=None, engine: Engine = Engine(),
              progress=None) -> list[dict]:
    """Rows of the sweep, in value order (see the module docstring)."""
    job = SweepJob(raw, spec, int(rays), int(seed), printer)
    return run(_design_row, job, list(range(len(spec.values))), engine, progress=progress)


def sweep_csv(spec: SweepSpec, rows: list[dict]) -> bytes:
    """The rows as CSV, the swept value's column named with its key and unit."""
    import csv
    import io

    head = f"{spec.section}_{spec.key}" + (f"_{spec.unit}" if spec.unit else "")
    keys = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([head if k == "value" else k for k in keys])
    for r in rows:
        w.writerow(["" if r.get(k) is None else (repr(r[k]) if isinstance(r.get(k), float) else r.get(k, ""))
                    for k in keys])
    return buf.getvalue().encode()


def finite_or_none(v):
    return v if not isinstance(v, float) or math.isfinite(v) else None
