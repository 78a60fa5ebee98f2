"""The projector's pixels are traced about its lens axis's pixel: with a lens offset the window of
pixels that light the paraboloid moves down the image by the offset, and its rays are the centred
projector's (the offset moves which pixels light the sample, not where they send their light)."""

import dataclasses

import numpy as np

from rigcad.basis.projector import trace_pixels
from rigcad.rig import Rig


def test_an_offset_projector_is_traced_about_its_axis_pixel(table31_rig):
    p = table31_rig.profile
    offset = Rig.from_profile(dataclasses.replace(p, projector=dataclasses.replace(p.projector, lens_offset=0.5)),
                              previous=table31_rig)
    a, b = trace_pixels(table31_rig, "projector", stride=8), trace_pixels(offset, "projector", stride=8)
    assert a.centre == (512.0, 384.0) and b.centre == (512.0, 576.0)  # 384 + 0.5 x 384 rows down
    assert b.window[0] - a.window[0] == 192  # the traced window's first row moves down as far
    # the same pixels about the axis, the same light: x, y from the centre and their arrivals agree
    assert np.array_equal(a.x_px, b.x_px) and np.array_equal(a.y_px, b.y_px)
    assert np.array_equal(a.status, b.status)
    assert np.allclose(a.arrival, b.arrival, equal_nan=True, atol=1e-12)  # same rays: to rounding
