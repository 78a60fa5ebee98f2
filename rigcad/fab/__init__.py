"""Fabrication: printer profiles, fit and split, print orientation (no
support on a mirror), sanding stock printed in front of every mirror, in-process slicing and the
staircase on mirror surfaces, G-code through PrusaSlicer with its vendor presets and the support
contact read from it (support.py), time and material estimates fitted to PrusaSlicer
(estimate.py), 2D outlines of the templates for laser/water-jet cutting (one per finishing
stage), and the fabrication report.

Stages depend only on the stages before them: parts (recipes) -> meshes (rigcad.export.mesh) ->
here. Frame: mm, sample point at the origin, optical axis +z, parts in working position; a
piece's print orientation is a rotation taking its build direction to +z.
"""
