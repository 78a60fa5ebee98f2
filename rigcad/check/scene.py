"""The rig as the ray checker sees it: mirror meshes, occluders, exact surfaces, rigid poses.

Frame: mm, sample point O at the origin, optical axis +z. Three rigid bodies can move
(misalignment): the paraboloid (its mirror with its back, stem and clamp), the dome, and the two
sources (camera, projector; see sources.py). The beam rests in the dome's slots and moves with the dome.

:func:`mirror_meshes` is the one place that obtains the meshes: the exported files when present
(``exports/<profile>/mirrors/{dome,paraboloid}.ply`` written by ``rigcad build``, and
``stl/paraboloid.stl``, ``stl/beam.stl``), else built from the profile (``mirror_mesh`` at the
profile's ``tessellation.mirror_*`` tolerances; the occluders from the boxes and cylinders the
part recipes declare). Where each came from is recorded.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigcad.check import rays as R
from rigcad.errors import CheckError
from rigcad.optics.frames import Pose
from rigcad.parts.recipe import Box

#: Sides of the cylinders of the occluder meshes built when no STL was exported: the polygon's
#: inscribed radius is r cos(pi/256), 0.0075 % short (1 um on the 16 mm back): below any effect
#: on which ray is blocked.
OCCLUDER_SECTIONS = 256


@dataclass(frozen=True)
class RigMeshes:
    """Mirror meshes (design surfaces) and occluder meshes, with where each came from."""

    paraboloid: R.TriMesh
    dome: R.TriMesh
    mount: R.TriMesh
    beam: R.TriMesh
    tolerances: dict  #: chord_error_mm, normal_error_rad of the mirror meshes

    def sources(self) -> dict[str, str]:
        return {m.name: m.source for m in (self.paraboloid, self.dome, self.mount, self.beam)}


def _ply_tolerances(comments: tuple[str, ...]) -> dict[str, float]:
    """The tolerances a rigcad mirror PLY was made at, from its header comment
    ``rings R sectors S chord_error_mm C facet_normal_error_rad N`` (empty if absent)."""
    out = {}
    for c in comments:
        words = c.split()
        for key in ("chord_error_mm", "facet_normal_error_rad"):
            if key in words[:-1]:
                try:
                    out[key] = float(words[words.index(key) + 1])
                except ValueError:
                    pass
    return out


def _occluder_meshes(rig) -> tuple[R.TriMesh, R.TriMesh]:
    """The paraboloid's mount (back, stem, clamp) and the beam as meshes of the occluders their
    recipes declare (used when no STL was exported)."""
    import trimesh

    def mesh(solid):
        if isinstance(solid, Box):
            return trimesh.creation.box(bounds=[solid.lo, solid.hi])
        x, y, z = solid.base
        return trimesh.creation.cylinder(radius=solid.radius, segment=[[x, y, z], [x, y, z + solid.height]],
                                         sections=OCCLUDER_SECTIONS)

    m = trimesh.util.concatenate([mesh(solid) for _, solid in rig.occluders["paraboloid"]])
    b = trimesh.util.concatenate([mesh(solid) for _, solid in rig.occluders["beam"]])
    src = "built from the occluders the part recipes declare (boxes, cylinders): no exported STL"
    return (R.TriMesh("paraboloid_mount", np.asarray(m.vertices, float), np.asarray(m.faces, np.int64), source=src),
            R.TriMesh("beam", np.asarray(b.vertices, float), np.asarray(b.faces, np.int64), source=src))


def _read_stl(path: Path, name: str) -> R.TriMesh:
    import trimesh

    try:
        m = trimesh.load_mesh(path, file_type="stl", process=False)
    except (OSError, ValueError) as err:
        raise CheckError(f"cannot read {path}: {err}") from err
    return R.TriMesh(name, np.asarray(m.vertices, float), np.asarray(m.faces, np.int64), source=str(path))


def mirror_meshes(rig, exports: Path | None = None, chord_error: float | None = None,
                  normal_error: float | None = None) -> RigMeshes:
    """The meshes the checker traces (see the module docstring). ``chord_error`` (mm) and
    ``normal_error`` (rad) override the profile's ``tessellation.mirror_*`` (then the exported
    PLYs, made at the profile's values, are not used)."""
    from rigcad.export.mirror_mesh import mirror_mesh, read_ply

    tess = rig.profile.tessellation
    override = chord_error is not None or normal_error is not None
    chord = tess.mirror_chord_error if chord_error is None else chord_error
    normal = tess.mirror_normal_error if normal_error is None else normal_error
    out_dir = Path(exports) / rig.profile.name if exports is not None else None
    mirrors = {}
    for name, meridian in (("paraboloid", rig.layout.design_paraboloid), ("dome", rig.layout.design_dome)):
        ply = out_dir / "mirrors" / f"{name}.ply" if out_dir is not None else None
        mesh = None
        if ply is not None and ply.is_file() and not override:
            data = read_ply(ply)
            tol = _ply_tolerances(data.comments)
            # use the export only when it was made at the tolerances asked for
            if (tol.get("chord_error_mm"), tol.get("facet_normal_error_rad")) == (chord, normal):
                mesh = R.TriMesh(name, data.vertices, data.faces, data.normals, meridian, source=str(ply))
        if mesh is None:
            mm = mirror_mesh(meridian, name, chord, normal)
            mesh = R.TriMesh(name, mm.vertices, mm.faces, mm.normals, meridian,
                             source=f"mirror_mesh() at {chord:g} mm / {normal:g} rad (no matching exported PLY)")
        mirrors[name] = mesh
    stl = out_dir / "stl" if out_dir is not None else None
    if stl is not None and (stl / "paraboloid.stl").is_file() and (stl / "beam.stl").is_file():
        mount = _read_stl(stl / "paraboloid.stl", "paraboloid_mount")
        beam = _read_stl(stl / "beam.stl", "beam")
    else:
        mount, beam = _occluder_meshes(rig)
    return RigMeshes(mirrors["paraboloid"], mirrors["dome"], mount, beam,
                     {"chord_error_mm": chord, "normal_error_rad": normal})


@dataclass
class Optics:
    """Intersectors of the three bodies, in their own frames, and the poses that place them.

    ``paraboloid``: part 0 is the mirror, parts >= 1 its mount; ``dome``: part 0 the mirror, part 1
    the beam (it rests in the dome's slots and moves with it; one query per segment instead of
    two); ``beam``: the beam alone, also placed by the dome's pose (the return segment starts on
    the dome, which must not be re-hit at its origin). ``mode`` is mesh, smooth, exact_normals or
    analytic."""

    mode: str
    paraboloid: object
    dome: object
    beam: object
    paraboloid_pose: Pose = field(default_factory=Pose)
    dome_pose: Pose = field(default_factory=Pose)
    timer: R.Timer | None = None
    #: the compiled analytic tracer (rigcad.check.analytic.AnalyticTracer) over the same exact
    #: surfaces, for analytic optics; trace3d.trace uses it unless asked for the numpy passes
    fast: object | None = None

    @property
    def backend(self) -> str:
        if self.fast is not None:
            return "; ".join(sorted({self.fast.backend, self.beam.backend}))
        return "; ".join(sorted({self.paraboloid.backend, self.dome.backend, self.beam.backend}))

    def placed(self, paraboloid_pose: Pose | None = None, dome_pose: Pose | None = None) -> "Optics":
        """The same intersectors with other poses (no BVH rebuilt)."""
        return Optics(self.mode, self.paraboloid, self.dome, self.beam, paraboloid_pose or Pose(),
                      dome_pose or Pose(), self.timer, self.fast)


MESH_MODES = {"mesh": "facet", "smooth": "vertex", "exact_normals": "exact"}


def _intersector(solid):
    """A recipe occluder (Box or z Cylinder) as a float64 intersector."""
    if isinstance(solid, Box):
        return R.Box(solid.lo, solid.hi)
    x, y, z = solid.base
    return R.ZCylinder(solid.radius, z, z + solid.height, x, y)


def analytic_optics(rig) -> Optics:
    """Exact surfaces and the occluders the part recipes declare (float64 throughout), placed
    where ``rig`` (a :class:`rigcad.rig.Rig`) puts its paraboloid and dome."""
    geo = rig.geometry
    para = R.Group([R.ExactParaboloid(geo.focal_length, geo.vertex_z, geo.rim_radius)]
                   + [_intersector(solid) for _, solid in rig.occluders["paraboloid"]])
    beam = [_intersector(solid) for _, solid in rig.occluders["beam"]]
    beam_box = beam[0] if len(beam) == 1 else R.Group(beam)
    dome = R.Group([R.ExactDome(rig.layout.design_dome), beam_box])
    from rigcad.check.analytic import AnalyticTracer

    optics = Optics("analytic", para, dome, beam_box, fast=AnalyticTracer.build(rig, para, dome, beam_box))
    return placed_as(optics, rig)


def placed_as(optics: Optics, rig) -> Optics:
    """``optics`` with the paraboloid and the dome where ``rig`` puts them (no BVH rebuilt)."""
    pp, dp = rig.pose("paraboloid"), rig.pose("dome")
    return optics if pp.is_identity and dp.is_identity else optics.placed(pp, dp)


def mesh_optics(meshes: RigMeshes, mode: str = "smooth", refine: bool = True, timer: R.Timer | None = None,
                backend: str = "embree") -> Optics:
    """Embree scenes over the meshes (``backend='numpy'``: the brute-force reference, small meshes).
    ``mode``: mesh (facet normals), smooth (interpolated vertex normals), exact_normals."""
    if mode not in MESH_MODES:
        raise ValueError(f"mode {mode!r}: expected one of {', '.join(MESH_MODES)}")
    model = MESH_MODES[mode]
    timer = timer or R.Timer()
    if backend == "numpy":
        make = lambda ms: R.NumpyMesh(ms, model)  # noqa: E731
    else:
        make = lambda ms: R.EmbreeMesh(ms, model, refine=refine, timer=timer)  # noqa: E731
    return Optics(mode, make([meshes.paraboloid, meshes.mount]), make([meshes.dome, meshes.beam]),
                  make([meshes.beam]), timer=timer)


def share_scenes(optics: Optics, mode: str, refine: bool = True) -> Optics:
    """The same Embree scenes read with another normal model, or without the float64 refinement
    (``refine=False``: Embree's float32 hit and facet normal); no BVH is rebuilt."""
    import copy

    out = copy.copy(optics)
    out.mode = mode if refine else f"{mode}_float32"
    for name in ("paraboloid", "dome", "beam"):
        member = copy.copy(getattr(optics, name))
        member.normal_model = MESH_MODES[mode]
        if hasattr(member, "refine"):
            member.refine = refine
            member.backend = member.backend.split(" + ")[0].split(" (float32 hits")[0] + (
                " + float64 re-intersection of the hit triangle" if refine else " (float32 hits, not refined)")
        setattr(out, name, member)
    return out


def mixed(analytic: Optics, meshed: Optics, mesh_part: str) -> Optics:
    """Exact surfaces except ``mesh_part`` (paraboloid or dome) from ``meshed``: attributes the
    mesh error to one mirror."""
    import copy

    out = copy.copy(analytic)
    out.mode = f"{meshed.mode}_{mesh_part}_only"
    out.fast = None  # the compiled kernels trace exact surfaces only
    setattr(out, mesh_part, getattr(meshed, mesh_part))
    return out
