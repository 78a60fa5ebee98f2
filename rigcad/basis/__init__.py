"""Basis illumination maths (thesis 3.3, 3.3.1, 4.1.2, 4.2): independent of the rig's geometry.

- ``zonal``: the zonal basis Z_l^m over a spherical zone (eqs. 3.1-3.4) and quadrature over the zone
- ``gram``: the basis on discrete illumination samples (projector pixels), quantisation (4.2.1),
  re-orthonormalisation
- ``brdf``: analytic BRDF models for simulation (3.3.1 step 2)
- ``merl``: MERL BRDF tables (read, write, tabulate, look up)
- ``sh``: zonal to spherical harmonics through the dual basis (eqs. 3.5-3.7), extrapolation into the cap
- ``simulate``: simulated acquisition (eq. 4.3) and coefficient recovery against Gauss quadrature

Angles in radians, solid angles in steradians, local frame: normal +z, tangent +x. See docs/basis.md.
"""
