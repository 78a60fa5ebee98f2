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
    top = shell.flange_thickness + th.washer_thickness + th.head_height + key.short_arm + key.room
    z = np.linspace(shell.flange_thickness, top, 2001)
    o = lay.dome_outer
    pts = o.points(o.sample(20001))
    wall = np.interp(z, pts[:, 1], pts[:, 0]) if pts[0, 1] < pts[-1, 1] else np.interp(z, pts[::-1, 1], pts[::-1, 0])
    assert lay.bolt_circle_r - key.room >= wall.max() - 1e-3  # 1 um: the layout samples the wall on 4001 points


def test_a_dome_leaning_over_its_flange_still_passes_the_gate(tmp_path):
    rig = _rig(tmp_path, 12.0)  # the optimiser's kind of design: the wall leans out over the bolts
    v = gate.verdict(rig, search=False)
    assert v.ok, v.reason
