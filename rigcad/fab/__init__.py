"""Fabrication (project issue 6): printer profiles, fit and split, print orientation, in-process
slicing and the staircase on mirror surfaces, G-code through PrusaSlicer, 2D outlines of the
templates for laser/water-jet cutting, and the fabrication report.

Stages depend only on the stages before them: parts (recipes) -> meshes (rigcad.export.mesh) ->
here. Frame: mm, sample point at the origin, optical axis +z, parts in working position; a
piece's print orientation is a rotation taking its build direction to +z.
"""
