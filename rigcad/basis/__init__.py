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

#: Every 32nd camera pixel in both directions: ~50 exitant directions over the zone, ~10 deg apart
#: (the simulated acquisition's default, :mod:`rigcad.basis.acquire`; here so that ``rigcad basis --help``
#: shows it without importing the simulation).
CAMERA_STRIDE_PX = 32
