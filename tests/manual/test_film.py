"""The film test's set-up (rigcad.manual.calibration.film_setup) against the parts as built: the
film on the base plate's top is the sample plane, the cross that marks O is level with it, the
blocks make up the tongue's reach below the disc, and the view from below has room."""

from __future__ import annotations

import numpy as np

from rigcad.manual import calibration as C
from rigcad.manual.document import Doc, _film_step


class _Ctx:
    def __init__(self, rig):
        self.rig = rig


def test_film_setup_matches_the_parts(table31_rig):
    rig = table31_rig
    f = C.film_setup(rig)
    plate = np.asarray(rig.mesh(rig.recipes["base_plate"]).vertices)
    cross = np.asarray(rig.mesh(rig.recipes["camera_cross_base"]).vertices)
    dome = np.asarray(rig.mesh(rig.recipes["dome"]).vertices)
    # the plate's top, the cross's top and the dome's base are one plane: the sample plane z = 0
    for top in (plate[:, 2].max(), cross[:, 2].max(), dome[:, 2].min()):
        assert abs(top) < 1e-6
    # the blocks make up the tongue's reach below the disc (the plate's lowest point is the tongue's)
    disc_bottom = -rig.profile.base_plate.thickness
    assert abs((f["block_under_disc_mm"] - f["block_under_tongue_mm"]) - (disc_bottom - plate[:, 2].min())) < 1e-9
    # the plate has no material inside the bore's radius (where the view from below goes) ...
    r = np.hypot(plate[:, 0], plate[:, 1])
    assert r.min() > f["bore_radius_mm"] - 0.05 * f["bore_radius_mm"]
    # ... the plug that marks O fits it, and a 45 deg mirror as wide as the bore fits under the plate
    assert np.hypot(cross[:, 0], cross[:, 1])[cross[:, 2] > disc_bottom].max() < f["bore_radius_mm"]
    assert f["block_under_disc_mm"] >= 2 * f["bore_radius_mm"]
    assert f["film_diameter_mm"] > 2 * f["bore_radius_mm"]
    # the paraboloid's shadow is larger than the bore for the default rig: direct light is not seen from below
    assert f["direct_light_seen"] is False


def test_the_manual_writes_the_film_step(table31_rig):
    d = Doc()
    _film_step(d, _Ctx(table31_rig))
    text = " ".join(b[-1] if isinstance(b[-1], str) else " ".join(b[-1]) for b in d.blocks)
    f = C.film_setup(table31_rig)
    for want in ("camera_cross_base", f"{f['block_under_tongue_mm']:g} mm", f"{f['block_under_disc_mm']:g} mm",
                 f"{f['film_diameter_mm']:.0f} mm", "indicated in from the bore", "before it is set back and bolted down",
                 "through the bore", "peel the whole film"):
        assert want in text, want
