"""The dome's flange bolts stay reachable: where the dome's wall leans out over its flange (a design
the optimiser or a profile makes), the bolt circle moves out until each bolt's L key, short arm in
its head and long arm out from the arm's end, clears the wall (rigcad.parts.layout). Checked against
the wall's points sampled here and against the assembly gate's own tool paths."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import rigcad
from rigcad.manual import gate
from rigcad.standards import HEX_KEYS, THREADS


def _rig(tmp_path, angle_deg: float):
    path = tmp_path / f"tau{angle_deg:g}.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent(f"""\
        paraboloid:
          tangent_angle: {angle_deg:g} deg
        """), encoding="utf-8")
    return rigcad.load(path)


@pytest.mark.parametrize("angle", [12.0, 20.0])
def test_the_hex_key_clears_the_wall_over_the_flange(tmp_path, angle):
    rig = _rig(tmp_path, angle)
    lay, shell = rig.layout, rig.profile.dome_shell
    th = THREADS["M4"]
    key = HEX_KEYS[th.hex_key]
    shaft = shell.flange_thickness + th.washer_thickness + th.head_height + key.short_arm  # the short arm's end
    o = lay.dome_outer
    pts = o.points(o.sample(20001))
    order = np.argsort(pts[:, 1])

    def wall(z0, z1):
        z = np.linspace(z0, z1, 2001)
        return np.interp(z, pts[order, 1], pts[order, 0]).max()

    # the short arm and its room clear the wall up to its end; the long arm's end face (on the bolt's
    # axis, the arm going outwards) clears it over the arm's thickness above (1 um: the layout samples
    # the wall on 4001 points)
    assert lay.bolt_circle_r - key.room >= wall(shell.flange_thickness, shaft) - 1e-3
    assert lay.bolt_circle_r >= wall(shaft, shaft + key.room) - 1e-3


def test_a_dome_leaning_over_its_flange_still_passes_the_gate(tmp_path):
    rig = _rig(tmp_path, 12.0)  # the optimiser's kind of design: the wall leans out over the bolts
    v = gate.verdict(rig, search=False)
    assert v.ok, v.reason
