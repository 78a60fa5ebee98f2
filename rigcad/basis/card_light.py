"""The projector's side of the gray card's calibration (thesis 4.1.2): the zonal basis images up to
order 2 as the rig's projector shows them, on its lit pixels, as plain arrays for
:mod:`rigcad.calibrate.graycard` (which sits below the basis floor and cannot import it).

Wiring module (may import the rig's stages; tests/basis/test_independence.py): the same lit
pixels, directions and solid angles as ``rigcad basis`` (:func:`rigcad.basis.projector.illumination`
on the rig as designed), the images quantised as thesis 4.2.1 with the order's own scale
(:func:`rigcad.basis.gram.quantise_images`), which are the images ``rigcad calibrate --gray-card-kit``
writes to project."""

from __future__ import annotations

import numpy as np

from rigcad.basis.gram import basis_images, quantise_images
from rigcad.basis.projector import illumination, zone_of
from rigcad.basis.zonal import basis_indices, check_order


def card_light(rig, order: int = 2, bits: int = 8, circle=None):
    """The :class:`rigcad.calibrate.graycard.Light` of ``rig``'s projector showing the zonal basis
    up to ``order`` (the frames' levels, positive and negative, ``bits`` deep) on its lit pixels,
    with each pixel's zonal values up to the same order, incidence direction and solid angle (sr).
    ``circle``: the calibration circle as measured (rigcad.basis.measured.MeasuredCircle), whose
    centre and radius set the projector's image centre and focal length as ``rigcad basis`` reads
    them (rigcad.basis.measured.projector_frame); None: the design's circle."""
    from rigcad.basis.measured import Measured, projector_frame
    from rigcad.basis.projector import trace_pixels
    from rigcad.calibrate.graycard import Light

    L = check_order(order)
    zone = zone_of(rig)
    focal, centre = projector_frame(rig, None if circle is None else Measured(circle, None, None))
    illum = illumination(rig, zone, design=trace_pixels(rig, "projector", focal_px=focal, centre=centre))
    s = illum.sampling
    values = basis_images(s, L, zone)
    q = quantise_images(values, bits)
    lit = s.valid
    px = illum.pixels
    return Light(positive=q.positive.T[lit].astype(np.int64), negative=q.negative.T[lit].astype(np.int64),
                 zonal=values[lit], direction=s.directions()[lit], weight_sr=s.weight_sr[lit],
                 row=px.row[lit], col=px.col[lit], resolution=tuple(int(v) for v in px.resolution), bits=bits,
                 scale_per_sqrt_sr=q.scale, alpha_rad=zone.alpha_rad, order=L,
                 lm=tuple((int(l), int(m)) for l, m in basis_indices(L)))

