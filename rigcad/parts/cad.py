"""The Python API's CAD objects: a rig part as a build123d ``Part`` that also converts to CadQuery
and meshes like the exported STL. Reached through :class:`rigcad.rig.Rig` (``rig.part(name)``);
this module and ``parts/_kernel.py`` are the ones that touch build123d.

Frame: mm, sample point at the origin, optical axis +z, each part in its working position.
"""

from __future__ import annotations

from build123d import Color, Part, Solid

from rigcad.errors import ExportError


class RigPart(Part):
    """A rig part's exact solid (the STEP's B-rep) as a build123d ``Part``: everything build123d
    does with a Part works on it (booleans, ``export_step``, ``.volume``, ``.bounding_box()``).
    ``label`` is the part's name and ``color`` its display colour. Extra: :meth:`to_cadquery` and
    :meth:`mesh` (the printable mesh from the same recipe as the STL)."""

    _rig = None
    _name = ""

    @classmethod
    def build(cls, rig, name: str) -> "RigPart":
        """The solid of ``rig``'s part ``name`` (raises KernelError if OpenCascade cannot build it)."""
        from rigcad.parts import _kernel as K

        recipe = rig.recipe(name)
        solid = K.part_solid(recipe, rig.profile.tessellation.fit_tolerance, K.FitReport(), rig.profile)
        part = cls([Solid(solid)], label=name, color=Color(*recipe.color))
        part._rig, part._name = rig, name
        return part

    def to_cadquery(self):
        """The same solid as a ``cadquery.Workplane`` (both libraries share one OCP wheel)."""
        try:
            import cadquery as cq
        except ImportError as err:  # pragma: no cover - cadquery is pinned with the cad extra
            raise ExportError("to_cadquery needs cadquery: pip install -e '.[cad]'") from err
        return cq.Workplane("XY").add(cq.Shape.cast(self.wrapped))

    def mesh(self, chord_error: float | None = None):
        """The printable mesh as a ``trimesh.Trimesh`` (mm): the recipe meshed by manifold3d at
        ``chord_error`` mm (default the profile's ``tessellation.chord_error``), as in the STL
        (:meth:`rigcad.rig.Rig.mesh`)."""
        if self._rig is None:
            raise ExportError("mesh() needs a part made by Rig.part(); for another build123d shape use "
                              "its tessellate() method")
        return self._rig.mesh(self._name, chord_error)
