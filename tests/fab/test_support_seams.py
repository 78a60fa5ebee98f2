"""Support the slicer puts on a mirror, read from its G-code: within a split mirror's seam band (which
the seam's fairing sands) it is counted apart; anywhere else on the mirror it is a fab problem naming
the piece, the area, the model's figure and the keys to change."""

from __future__ import annotations

import manifold3d as m3d
import numpy as np

from rigcad.export import mesh as M
from rigcad.fab import seams as SE
from rigcad.fab import support as SU


def _plate_contact(x0: float):
    """A 40 x 40 x 2 mm plate (its top the mirror, x >= 0) cut along the meridional plane x = 0
    (normal (-1, 0, 0): the half-plane at 90 deg, as rigcad.fab.seams.cut_normals gives it), with a
    3 x 3 mm patch of support beads 0.3 mm over its top starting at x = ``x0``."""
    v, f = M.mesh_arrays(m3d.Manifold.cube((40.0, 40.0, 2.0)).translate((0.0, -20.0, 0.0)))
    tri = v[f]
    top = np.nonzero(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2] > 0)[0]
    seg = np.array([(x0, y, x0 + 3.0, y, 2.3) for y in np.arange(-1.5, 1.5 + 1e-9, 0.2)])
    normals = SE.cut_normals_of_angles([np.pi / 2])
    band = (v, lambda p: SE.seam_distance(p, normals), SE.SEAM_BAND_MM)
    return SU.contact_areas(v, f, top, SU.SupportBeads(seg, 3.0 * len(seg), 1), 0.6, band)


def test_support_at_a_seam_is_counted_apart_and_is_no_problem():
    # the patch spans x 0-3 mm; a reach of 0.6 mm from beads 0.3 mm above the top touches it
    # sqrt(0.6^2 - 0.3^2) = 0.52 mm past the patch: to x = 3.52
    c = _plate_contact(0.0)
    assert c["band_mm"] == SE.SEAM_BAND_MM == 2.0
    # touched mirror within 2 mm of the cut: about 2 x 3.8 mm (the patch's 3 mm dilated by the reach)
    assert 5.0 < c["mirror_in_band_mm2"] < 10.0, c
    assert 0.0 < c["mirror_off_band_mm2"] < c["mirror_in_band_mm2"], c  # x 2-3.52 mm lies outside the band
    assert abs(c["mirror_in_band_mm2"] + c["mirror_off_band_mm2"] - c["mirror_mm2"]) < 1e-9
    near = _plate_contact(-2.0)  # beads over x -2..1 mm: the mirror is touched to x = 1.52 mm, inside the band
    assert near["mirror_off_band_mm2"] == 0.0 and near["mirror_in_band_mm2"] > 5.0, near
    assert SU.mirror_problems("dome_1", near, 0.0, "profiles/printers/x.yaml") == []


def test_support_elsewhere_on_the_mirror_is_a_problem_naming_piece_area_and_keys():
    c = _plate_contact(20.0)
    assert c["mirror_in_band_mm2"] == 0.0 and c["mirror_off_band_mm2"] > 10.0, c  # 3 x 3 mm dilated
    (msg,) = SU.mirror_problems("dome_2", c, 0.0, "profiles/printers/ender3v2.yaml")
    assert msg.startswith("dome_2: the slicer's support touches ") and f"{c['mirror_off_band_mm2']:.1f} mm2" in msg
    for word in ("predicted 0.0 mm2", "slicer.overrides in profiles/printers/ender3v2.yaml",
                 "support_material_threshold", "another orientation", "outside the 2 mm band"):
        assert word in msg, (word, msg)


def test_a_mirror_without_seams_is_refused_for_any_support():
    v, f = M.mesh_arrays(m3d.Manifold.cube((10.0, 10.0, 2.0)))
    tri = v[f]
    top = np.nonzero(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2] > 0)[0]
    c = SU.contact_areas(v, f, top, SU.SupportBeads(np.array([(2.0, 5.0, 4.0, 5.0, 2.3)]), 2.0, 1), 0.6)
    assert "band_mm" not in c and c["mirror_mm2"] > 0
    assert len(SU.mirror_problems("paraboloid", c, 0.0, "p.yaml")) == 1


def test_seam_distance_is_to_the_meridional_planes_only():
    n = SE.cut_normals_of_angles([0.0, np.pi / 2])  # half-planes along +x and +y
    d = SE.seam_distance(np.array([[5.0, 1.0, 3.0], [1.5, 5.0, 0.0], [4.0, 4.0, 9.0]]), [*n, np.array([0, 0, 1.0])])
    assert np.allclose(d, [1.0, 1.5, 4.0])  # the band cut (normal along the axis) is no meridional seam
