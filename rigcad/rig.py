"""The Rig: everything every stage needs, built once from a validated profile and then frozen.

``Rig.from_profile`` derives the geometry and integrates the dome (to the rows its smooth curve
needs: ``optics.design.converged_dome``) exactly once; the rest is computed from those on first
use and kept: the layout and every part's recipe (``rigcad.parts``), the 2D design with its
report, the map from a projector pixel (a COP ray) to its incidence direction, the occluders the
part recipes declare. Every stage (design, build, check, fab) and every figure takes a Rig; no stage
goes back to the YAML, derives the geometry or integrates a dome itself (a test keeps to this).

A Rig is a value: it pickles (for worker processes), and ``rig.moved(...)`` returns a perturbed
copy (a :class:`rigcad.optics.frames.Misalignment` of the projector, camera, paraboloid or dome)
that shares everything the move does not change; nothing is ever changed in place.

Frame: mm, sample point O at the origin, optical axis +z; angles in radians.
"""

from __future__ import annotations

import dataclasses
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from rigcad.errors import ExportError, ProfileError, RigcadError
from rigcad.optics.dome import DomeProfile
from rigcad.optics.frames import COMPONENTS, Misalignment, Pose
from rigcad.profile.derived import Derived
from rigcad.profile.schema import Profile

if TYPE_CHECKING:  # pragma: no cover
    from rigcad.optics.design import Design
    from rigcad.optics.incidence import DesignMap
    from rigcad.optics.paraboloid import Paraboloid
    from rigcad.optics.trace2d import DomeCurve
    from rigcad.parts.layout import RigLayout
    from rigcad.parts.recipe import Part

#: What depends on the geometry and the dome alone: carried over by :meth:`Rig.from_profile` from a
#: previous rig with the same dome inputs.
_DOME_ONLY = ("paraboloid", "curve", "incidence")


class _shared:
    """A rig's value that no move changes (its geometry, layout, recipes, maps, mesh cache): computed
    on first use and kept in the cache that the rig shares with its moved copies (:meth:`Rig.moved`),
    so that a value made on any of them, before the move or after it, serves them all. Read-only."""

    def __init__(self, compute):
        self.compute, self.__doc__ = compute, compute.__doc__

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, rig, owner=None):
        if rig is None:
            return self
        cache = rig._cache
        if self.name not in cache:
            cache[self.name] = self.compute(rig)
        return cache[self.name]


@dataclass(frozen=True)
class Rig:
    """One rig: the resolved ``profile``, its ``geometry`` (derived figures), its converged
    ``dome`` profile, and a ``misalignment`` of its movable components (none by default)."""

    profile: Profile
    geometry: Derived
    dome: DomeProfile
    misalignment: Misalignment = field(default_factory=Misalignment.none)
    #: name -> value of the ``_shared`` properties, one dict for a rig and its moved copies.
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    # -- construction ------------------------------------------------------------------------------
    @classmethod
    def from_profile(cls, profile: Profile, previous: "Rig | None" = None) -> "Rig":
        """Derive the geometry and integrate the dome, once. Raises GeometryError (naming the
        profile key and its file:line) for an impossible rig. ``previous``: the rig of an earlier
        version of the profile (the live edit loop, rigcad.live): when the dome's inputs (the
        ``dome`` section and the derived geometry) are equal, its dome and what was computed from
        the dome alone (_DOME_ONLY) are carried over instead of integrated again."""
        from rigcad.optics.design import converged_dome
        from rigcad.profile.derived import derive

        geometry = derive(profile)
        if previous is not None and previous.profile.dome == profile.dome and previous.geometry == geometry:
            rig = cls(profile, geometry, previous.dome)
            for key in _DOME_ONLY:
                if key in previous._cache:
                    rig._cache[key] = previous._cache[key]  # a cached value of the same inputs
            return rig
        return cls(profile, geometry, converged_dome(profile, geometry))

    @property
    def name(self) -> str:
        return self.profile.name

    # -- the shared geometry, computed on first use ------------------------------------------------
    @_shared
    def paraboloid(self) -> "Paraboloid":
        """The paraboloid mirror in the meridional plane (closed form)."""
        from rigcad.optics.paraboloid import Paraboloid

        g = self.geometry
        return Paraboloid(g.focal_length, g.vertex_z, g.rim_radius)

    @_shared
    def curve(self) -> "DomeCurve":
        """The dome as the 2D tracer reads it (the dome's one spline, or the thesis's polyline)."""
        from rigcad.optics.trace2d import DomeCurve

        return DomeCurve.from_profile(self.dome)

    @_shared
    def design(self) -> "Design":
        """The 2D optical design: traced checks and the report (design.json), figures with units."""
        from rigcad.optics.design import run_design

        return run_design(self)

    @_shared
    def layout(self) -> "RigLayout":
        """Placements and mirror surfaces (design, printed) shared by the parts. Raises
        GeometryError (with file:line) when the parts cannot be laid out (a polyline dome, a bolt
        that does not fit its flange, ...)."""
        from rigcad.parts import make_layout

        with _located(self.profile):
            return make_layout(self.profile, self.geometry, self.dome)

    @_shared
    def recipes(self) -> dict[str, "Part"]:
        """Every part's kernel-free recipe, in build order (``rigcad.parts.PARTS``)."""
        from rigcad.parts import make_recipes

        return make_recipes(self.profile, self.layout)

    @_shared
    def instruments(self) -> tuple["Part", ...]:
        """The bought items (projector, camera, beam splitter, focusing lens, nominal shim stacks) and
        the centre-of-projection markers as named solids in their working positions, for rig.step
        and the tower's checks (``rigcad.parts.tower.instruments``); not printed."""
        from rigcad.parts.tower import instruments

        return instruments(self.profile, self.layout)

    @_shared
    def incidence(self) -> "DesignMap":
        """Projector pixel / COP ray -> design incidence direction at O (finite COP only)."""
        from rigcad.optics.incidence import DesignMap

        with _located(self.profile):
            return DesignMap.from_design(self.geometry, self.dome)

    @_shared
    def occluders(self) -> dict[str, tuple]:
        """Convex solids standing for the parts where light passes them, from the part recipes
        (``Part.occluders``): part name -> ((name, recipe Box or Cylinder), ...)."""
        return {name: part.occluders for name, part in self.recipes.items() if part.occluders}

    def recipe(self, name: str, layout: "RigLayout | None" = None) -> "Part":
        """One part's recipe; an unknown name lists the parts. ``layout``: a variant of this rig's
        layout (``rig.layout.with_sanding_stock(...)``) to make the part on instead (not kept)."""
        if name not in self.recipes:
            raise ProfileError(f"unknown part {name!r}; parts: {', '.join(self.recipes)}")
        if layout is not None and layout is not self.layout:
            from rigcad.parts import make_recipe

            return make_recipe(self.profile, layout, name)
        return self.recipes[name]

    def pose(self, component: str) -> Pose:
        """Where ``component`` (projector, camera, paraboloid, dome) stands: identity as designed."""
        return self.misalignment.pose(component, self.geometry)

    # -- perturbed copies --------------------------------------------------------------------------
    def moved(self, component: str, offset=(0.0, 0.0, 0.0), tilt: float = 0.0, axis=(0.0, 1.0, 0.0)) -> "Rig":
        """A copy with ``component`` shifted by ``offset`` (mm, (3,)) and tilted by ``tilt`` rad
        about the horizontal unit ``axis`` (pivots: see Misalignment.pose); the other components
        keep their placement. Shares the geometry (dome, layout, recipes, maps) with this rig."""
        if component not in COMPONENTS:
            raise ProfileError(f"cannot move {component!r}: components are {', '.join(COMPONENTS)}")
        moved = dataclasses.replace(self, misalignment=self.misalignment.with_(component, offset, tilt, axis))
        object.__setattr__(moved, "_cache", self._cache)  # one cache: what either makes, both read
        return moved

    def __getstate__(self) -> dict:
        """Pickled without the mesh cache (a worker meshes what it needs; the pickle stays small)."""
        state = dict(self.__dict__)
        state["_cache"] = {k: v for k, v in self._cache.items() if k != "_meshes"}
        return state

    # -- the stages, as a Python API ---------------------------------------------------------------
    def part(self, name: str):
        """The part's exact solid as a build123d ``Part`` (mm, working position), with
        ``.to_cadquery()`` and ``.mesh()``; see :class:`rigcad.parts.cad.RigPart`."""
        from rigcad.parts.cad import RigPart

        return RigPart.build(self, name)

    @_shared
    def _meshes(self) -> dict:
        """(recipe content hash, chord error) -> (vertices, faces), read-only: see :meth:`mesh`."""
        return {}

    def mesh(self, part: "str | Part", chord_error: float | None = None):
        """A part's mesh as a ``trimesh.Trimesh`` (mm, working position): its recipe (a part name, or
        a recipe ``Part`` such as an instrument or a part re-made on another layout) meshed by
        manifold3d with every surface within ``chord_error`` mm of the exact one (default the
        profile's ``tessellation.chord_error``: the STL's mesh; ``export.mesh.PICTURE_CHORD_ERROR``
        for pictures). The one place a recipe is meshed: each (recipe, chord error) is meshed once
        per rig and its moved copies; the Trimesh returned is a fresh copy, changing it changes
        nothing shared."""
        import trimesh

        from rigcad.export import mesh as M

        chord = self.profile.tessellation.chord_error if chord_error is None else float(chord_error)
        if not chord > 0:
            raise ExportError(f"chord_error must be > 0 mm, got {chord_error!r}")
        recipe = self.recipe(part) if isinstance(part, str) else part
        key = (recipe.content_hash(), chord)
        if key not in self._meshes:
            vertices, faces = M.mesh_arrays(M.build(recipe.solid, chord))
            vertices.flags.writeable = faces.flags.writeable = False
            self._meshes[key] = (vertices, faces)
        vertices, faces = self._meshes[key]
        return trimesh.Trimesh(vertices.copy(), faces.copy(), process=False)

    # the operations on a rig: rigcad.api holds them, with their folders, locks and cache keys
    def export(self, folder: str | Path | None = None, parts: list[str] | None = None, progress=None):
        """Write the design files and the parts into ``folder`` (default ``exports/<profile>``):
        :func:`rigcad.api.export`."""
        from rigcad import api

        return api.export(self, folder, parts, progress)

    def check(self, rays: int | None = None, mode: str | None = None, exports: str | Path | None = None, **options):
        """The 3D ray check, in memory: :func:`rigcad.api.check`."""
        from rigcad import api

        return api.check(self, rays, mode, exports, **options)

    def basis(self, order: int = 6, alpha: float | None = None):
        """The zonal basis up to ``order`` as this rig's projector shows it: :func:`rigcad.api.basis`."""
        from rigcad import api

        return api.basis(self, order, alpha)

    def fab(self, printer, folder: str | Path | None = None, gcode: bool = False, parts: list[str] | None = None,
            progress=None, workers: int | None = None, slicing=None):
        """Fabrication for ``printer`` into ``folder`` (default ``exports/<profile>/fab/<printer>``):
        :func:`rigcad.api.fab`."""
        from rigcad import api

        return api.fab(self, printer, folder, gcode, parts, progress, workers, slicing)

    def show(self, port: int = 3939, rays: int | None = None):
        """Push the named, coloured parts, ``rays`` traced rays (default: as many as ``rigcad view``
        draws) as polylines and the COP markers to an OCP CAD Viewer running on ``port``; a
        ViewerError saying how to start one when none runs. See :mod:`rigcad.live.ocp`."""
        from rigcad.live.ocp import show

        return show(self, port, rays)


@contextmanager
def _located(profile: Profile):
    """Re-raise a RigcadError that names a profile key with that key's file:line."""
    try:
        yield
    except RigcadError as err:
        located = err.located(profile.marks)
        if located is err:
            raise
        raise located from err


def load(profile: str | Path | Profile) -> Rig:
    """The rig of a profile given by name (searched in ``./profiles``, ``$RIGCAD_PROFILES``, then the
    profiles shipped with rigcad), by path, or as a loaded :class:`Profile`."""
    from rigcad.profile.schema import load_profile

    return Rig.from_profile(profile if isinstance(profile, Profile) else load_profile(profile))
