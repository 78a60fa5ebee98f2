"""The build stage: a Rig -> every part's exact solid (STEP), printable mesh (STL), the mirror
meshes for the ray checker, the rig assembly, and manifest.json.

Each part's cache key is the content hash of its recipe plus the tolerances that shape its files:
a second run with nothing changed rebuilds nothing, a changed key rebuilds the parts whose
geometry it changes. All files of a run are staged and published together at the end.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rigcad._version import __version__
from rigcad.errors import ExportError, ProfileError
from rigcad.export.atomic import Staging, json_bytes
from rigcad.export.manifest import code_version, file_sha, profile_digest
from rigcad.export.manifest import sha256_hex as _sha
from rigcad.parts import PARTS
from rigcad.parts.recipe import Part
from rigcad.profile.schema import Profile

#: STL and STEP volumes must agree within this fraction (the requirement: a re-imported STEP's
#: volume matches the STL's within 0.5 %): the mesh is inscribed in the exact surface at the chord
#: error, so it is slightly smaller.
MESH_VOLUME_RTOL = 5e-3
#: The code that shapes the files (parts, export, plots, surfaces): a change rebuilds what it wrote.
CACHE_VERSION = code_version("parts/*.py", "export/*.py", "plots.py", "optics/surfaces.py")


@dataclass(frozen=True)
class BuildResult:
    manifest: dict
    rebuilt: list[str]
    reused: list[str]
    written: list[Path]


def part_key(part: Part, profile: Profile) -> str:
    t = profile.tessellation
    h = hashlib.sha256(f"{CACHE_VERSION}|{part.content_hash()}|{t.chord_error!r}|{t.fit_tolerance!r}|"
                       f"{part.name}|{part.color!r}".encode())
    return h.hexdigest()


def select_parts(names: list[str] | None) -> list[str]:
    if not names:
        return list(PARTS)
    unknown = [n for n in names if n not in PARTS]
    if unknown:
        raise ProfileError(f"unknown part(s) {', '.join(unknown)}; parts: {', '.join(PARTS)}")
    return [n for n in PARTS if n in names]


def _cached(entry: dict | None, key: str, out: Path) -> bool:
    if not entry or entry.get("key") != key:
        return False
    return all(file_sha(out / rel) == digest for rel, digest in entry.get("files", {}).items())


def build_rig(rig, out: Path, parts: list[str] | None = None, progress=None,
              design: dict[str, bytes] | None = None, inputs_key: str | None = None,
              lock: Path | None = None) -> BuildResult:
    """Build the selected parts (all by default) of ``rig`` (a :class:`rigcad.rig.Rig`) into
    ``out``; see the module docstring.

    ``design``: the design stage's files (name -> bytes, ``export.design.design_files``), staged and
    published with the parts; their hashes and ``inputs_key`` go into the manifest so that
    `rigcad stl` can tell, without computing anything, that nothing changed. The whole folder is
    published at once under ``lock`` (export.atomic.Staging).
    """

    step = progress or (lambda label: None)
    profile, layout = rig.profile, rig.layout
    names = select_parts(parts)
    shapes: dict[str, object] = {}  # part -> its solid, built once for its files and the assembly
    tol = profile.tessellation

    # results (check/, fab/<printer>/, ...) made from another profile are not carried into this build
    with Staging(out, lock, results_of=profile_digest(profile)) as stage:
        old = _read_manifest(out / "manifest.json")
        design_shas = {}
        for name, data in (design or {}).items():
            stage.write_bytes(out / name, data)
            design_shas[name] = _sha(data)
        entries, rebuilt, reused = _build_parts(rig, names, old.get("parts", {}), out, stage, shapes, step)
        mirrors = _build_mirrors(rig, names, old.get("mirrors", {}), out, stage, step)
        assembly = _assembly(rig, entries, old.get("assembly"), out, stage, shapes, step)
        manifest = {
            "rigcad_version": __version__,
            "profile": {"name": profile.name, "sources": list(profile.sources), "sha256": profile_digest(profile)},
            "inputs_key": inputs_key if inputs_key and not parts else None,
            "design_files": design_shas or old.get("design_files"),
            "frame": "mm; sample point at the origin; optical axis +z; parts in their working positions",
            "tolerances": {
                "stl_chord_error_mm": tol.chord_error,
                "bspline_fit_tolerance_mm": tol.fit_tolerance,
                "mirror_chord_error_mm": tol.mirror_chord_error,
                "mirror_normal_error_rad": tol.mirror_normal_error,
                "stl_step_volume_rtol": MESH_VOLUME_RTOL,
            },
            "layout": layout.describe(),
            "tower_hardware": _tower_hardware(rig),
            "alignment": _alignment(rig),
            "occlusion": _occlusion(rig, old.get("occlusion")),
            "parts": {n: _with_stock(entries[n], rig.recipe(n)) for n in PARTS if n in entries},
            "mirrors": mirrors,
            "assembly": assembly,
            "stale_results_removed": stage.stale_report(),
        }
        stage.write_bytes(out / "manifest.json", json_bytes(manifest))
        step("publishing")
        written = stage.commit()
    return BuildResult(manifest, rebuilt, reused, written)


def _build_parts(rig, names: list[str], old_parts: dict, out: Path, stage: Staging, shapes: dict,
                 step) -> tuple[dict, list[str], list[str]]:
    """Build each part of ``names`` whose key changed since the previous manifest (``old_parts``) or
    whose files are not intact; the manifest's part entries (the others carried over), and the
    parts rebuilt and reused."""
    entries, rebuilt, reused = dict(old_parts), [], []
    for name in names:
        part = rig.recipe(name)
        key = part_key(part, rig.profile)
        if _cached(old_parts.get(name), key, out):
            reused.append(name)
            step(f"{name} (unchanged)")
            continue
        step(name)
        entries[name] = _build_part(part, key, rig, out, stage, shapes)
        rebuilt.append(name)
    return entries, rebuilt, reused


def _build_mirrors(rig, names: list[str], old_mirrors: dict, out: Path, stage: Staging, step) -> dict:
    """The mirror meshes (PLY) of the parts ``names``, each rebuilt when its key changed or its file
    is not intact; the manifest's mirror entries."""
    mirrors = dict(old_mirrors)
    for name in names:
        for mirror, meridian in rig.recipe(name).mirrors:
            key = _mirror_key(meridian, rig.profile)
            if _cached(mirrors.get(mirror), key, out):
                continue
            step(f"{mirror} mirror mesh")
            mirrors[mirror] = _build_mirror(mirror, meridian, key, rig.profile, out, stage)
    return mirrors


def _assembly(rig, entries: dict, previous: dict | None, out: Path, stage: Staging, shapes: dict, step) -> dict | None:
    """rig.step, the assembly of the in-rig parts with the instruments and COP markers
    (parts.tower.instruments), rebuilt when any of them changed; the manifest's entry."""
    rig_parts = [n for n in PARTS if n in entries and entries[n].get("in_rig")]
    key = hashlib.sha256("|".join([entries[n]["key"] for n in rig_parts]
                                  + [f"{p.name}:{p.content_hash()}" for p in rig.instruments]).encode()).hexdigest()
    if rig_parts and not _cached(previous, key, out):
        step("assembly")
        return _build_assembly(rig_parts, rig, out, stage, shapes, key)
    return previous


def _tower_hardware(rig) -> list[dict]:
    """The COP tower's bought hardware, computed from its parts (parts.tower.hardware)."""
    from rigcad.parts.tower import hardware

    return hardware(rig.profile, rig.layout)


def _alignment(rig) -> dict:
    """What holds and what adjusts the tower's optics (mm, deg in the keys): the datum chain from the
    base plate (parts.datum), every adjuster's range and resolution against its tolerance
    (parts.adjusters), the focusing lens (optics.focus), and the sizes to measure before printing
    (profile.instruments)."""
    from dataclasses import asdict

    from rigcad.optics.focus import focusing_lens
    from rigcad.parts.adjusters import adjusters
    from rigcad.parts.datum import check_datum_chain, datum_chain
    from rigcad.profile.instruments import measurements

    p, layout = rig.profile, rig.layout
    return {"datum_chain": {**datum_chain(p, layout).describe(), "checks": check_datum_chain(p, layout)},
            "adjusters": [a.describe() for a in adjusters(p, layout)],
            "focusing_lens": focusing_lens(p, layout.geometry).describe(),
            "measure_first": [asdict(m) for m in measurements(p)]}


def _read_manifest(path: Path) -> dict:
    """The previous manifest, or {} when there is none or it is unreadable (then nothing is reused)."""
    from rigcad.export.readback import own_json

    manifest = own_json(path)  # read as data: a FIFO, a giant or a nesting bomb is no manifest
    return manifest if isinstance(manifest, dict) else {}


def _mirror_key(meridian, profile: Profile) -> str:
    from rigcad.parts.recipe import _feed

    t = profile.tessellation
    h = hashlib.sha256(f"{CACHE_VERSION}|{t.mirror_chord_error!r}|{t.mirror_normal_error!r}".encode())
    _feed(h, meridian)
    return h.hexdigest()


def _build_mirror(name: str, meridian, key: str, profile: Profile, out: Path, stage: Staging) -> dict:
    """The design (coated) mirror surface as a structured mesh with exact vertex normals (PLY)."""
    from rigcad.export.mirror_mesh import mirror_mesh, ply_writer

    t = profile.tessellation
    mesh = mirror_mesh(meridian, name, t.mirror_chord_error, t.mirror_normal_error)
    path = out / "mirrors" / f"{name}.ply"
    stage.write_with(path, ply_writer(mesh, path))
    return {"key": key, "surface": "design (coated) mirror surface, exact vertex normals", "report": mesh.report,
            "files": {f"mirrors/{name}.ply": _sha(stage.temp_path(path).read_bytes())}}


def _occlusion(rig, previous: dict | None) -> dict:
    """Solid angle the beam and the paraboloid's mount hide from the sample (see parts.occlusion);
    the previous manifest's figures are reused when the profile and the code are the same."""
    from rigcad.optics.design import profile_table
    from rigcad.parts.occlusion import blocked_solid_angle

    key = hashlib.sha256(f"{CACHE_VERSION}|{profile_digest(rig.profile)}".encode()).hexdigest()
    if previous and previous.get("key") == key:
        return previous
    return {**blocked_solid_angle(rig.occluders, profile_table(rig.geometry, rig.dome)), "key": key}


def _with_stock(entry: dict, part) -> dict:
    """A part's manifest entry with its ``bought`` stock (profile's ``buy``): set apart from the cached
    entry, whose key is the solid's alone (a plate cut from stock has the printed shelf's solid)."""
    out = {k: v for k, v in entry.items() if k != "bought"}
    return {**out, "bought": part.bought} if part.bought else out


def _build_part(part: Part, key: str, rig, out: Path, stage: Staging, shapes: dict) -> dict:
    from rigcad.export import mesh as M
    from rigcad.export.step import reimport_check, step_writer
    from rigcad.parts import _kernel as K

    profile = rig.profile
    tol = profile.tessellation
    fits = K.FitReport()
    shape = K.part_solid(part, tol.fit_tolerance, fits, profile)
    if fits.max_error > 1e-3:
        raise ExportError(f"{part.name}: B-spline fit error {fits.max_error:.3g} mm exceeds 1 um; lower "
                          "tessellation.fit_tolerance")
    shapes[part.name] = shape
    volume = K.volume(shape)
    step_path = out / "step" / f"{part.name}.step"
    stage.write_with(step_path, step_writer([(part.name, shape, part.color)], part.name))
    check = reimport_check(stage.temp_path(step_path), volume, 1)

    mesh = rig.mesh(part, tol.chord_error)
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    mesh_vol = M.mesh_volume(vertices, faces)
    if abs(mesh_vol - volume) > MESH_VOLUME_RTOL * volume:
        raise ExportError(f"{part.name}: STL volume {mesh_vol:.6g} differs from the STEP's {volume:.6g} mm^3 "
                          f"by more than {MESH_VOLUME_RTOL:.1%}")
    stl = M.stl_bytes(vertices, faces, part.name, frame=M.RIG_FRAME)
    stl_path = out / "stl" / f"{part.name}.stl"
    stage.write_bytes(stl_path, stl)
    tmf_path = out / "3mf" / f"{part.name}.3mf"
    stage.write_with(tmf_path, M.threemf_writer(vertices, faces, part.name))
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    mirror_report = {name: _stl_mirror_errors(vertices, faces, meridian.behind(_coating(profile)))
                     for name, meridian in part.mirrors}
    from rigcad import plots

    # The picture needs no print accuracy: a coarse mesh of the same recipe renders in a second.
    picture = rig.mesh(part, M.PICTURE_CHORD_ERROR)
    pv, pf = np.asarray(picture.vertices), np.asarray(picture.faces)
    png = plots.render_mesh(pv, pf, part.name, part.color, cutaway=part.name == "dome")
    stage.write_bytes(out / "renders" / f"{part.name}.png", png)
    files = {f"step/{part.name}.step": _sha(stage.temp_path(step_path).read_bytes()), f"stl/{part.name}.stl": _sha(stl),
             f"renders/{part.name}.png": _sha(png),
             f"3mf/{part.name}.3mf": _sha(stage.temp_path(tmf_path).read_bytes())}
    return {
        "key": key,
        "description": part.description,
        "quantity": part.quantity,
        "in_rig": part.in_rig,
        "volume_mm3": volume,
        "stl_volume_mm3": mesh_vol,
        "stl_volume_rel_diff": (mesh_vol - volume) / volume,
        "bbox_min_mm": lo.tolist(),
        "bbox_max_mm": hi.tolist(),
        "triangles": int(len(faces)),
        "genus": M.genus(vertices, faces),
        "stl_mirror_surface": mirror_report,
        "step_reimport": check,
        "bspline_fits": fits.fits,
        "files": files,
    }


def _coating(profile: Profile) -> float:
    return float(sum(t for _, t in profile.coating.layers))


#: An STL vertex counts as on the printed mirror surface within this distance (mm): manifold3d keeps
#: the section's sample points exactly (float64), so they sit on the exact curve to round-off.
ON_SURFACE_MM = 1e-6


def _stl_mirror_errors(vertices: np.ndarray, faces: np.ndarray, printed) -> dict:
    """Chord and facet-normal errors of the STL's facets on the printed mirror surface, against
    the exact surface (what the printer is asked to make, before any staircase)."""
    from rigcad.export.mirror_mesh import facet_errors, surface_distance

    on = surface_distance(vertices, printed) < ON_SURFACE_MM
    mirror_faces = faces[on[faces].all(axis=1)]
    if not len(mirror_faces):
        raise ExportError(f"no STL facet lies on the printed {printed.kind} surface: the mesh and the recipe disagree")
    # lattice order 6 (28 samples, centroid included): ~2.5 s on the dome's 48k mirror facets at 0.018 mm
    chord, normal = facet_errors(vertices, mirror_faces, printed, order=6)
    return {"facets": int(len(mirror_faces)), "chord_error_mm": float(chord.max()),
            "facet_normal_error_rad": float(normal.max()),
            "measured_on": "every facet with all three vertices on the printed mirror surface, 28 barycentric "
                           "samples each, foot points on the exact meridian"}


def _build_assembly(names: list[str], rig, out: Path, stage: Staging, shapes: dict, key: str) -> dict:
    from rigcad.export.step import reimport_check, step_writer
    from rigcad.parts import _kernel as K

    profile = rig.profile
    items = []
    total = 0.0
    for name in names:
        part = rig.recipe(name)
        if name not in shapes:
            shapes[name] = K.part_solid(part, profile.tessellation.fit_tolerance, K.FitReport(), profile)
        items.append((name, shapes[name], part.color))
        total += K.volume(shapes[name])
    for part in rig.instruments:  # not printed: simple named solids, built here only
        shape = K.part_solid(part, profile.tessellation.fit_tolerance, K.FitReport(), profile)
        items.append((part.name, shape, part.color))
        total += K.volume(shape)
    path = out / "rig.step"
    stage.write_with(path, step_writer(items, f"{profile.name}_rig"))
    check = reimport_check(stage.temp_path(path), total, len(items))
    return {"key": key, "parts": names, "instruments": [p.name for p in rig.instruments], "step_reimport": check,
            "files": {"rig.step": _sha(stage.temp_path(path).read_bytes())}}


__all__ = ["BuildResult", "build_rig"]
