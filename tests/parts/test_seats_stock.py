"""The dome's beam seats are datums: the sanding stock a printer asks for brings the mirror forward and
moves nothing else (rigcad.parts.dome.beam_seats reads the surface as designed, not as stocked)."""

from __future__ import annotations

import rigcad
from rigcad.parts.dome import beam_seats

#: More than the MK3S's 0.159 mm stock (tests/fab/test_stock.py) and than a coarse printer's.
STOCK_MM = 0.4


def test_the_beam_seats_do_not_move_with_the_sanding_stock():
    rig = rigcad.load("achutha2006")
    bare = beam_seats(rig.profile, rig.layout)
    stocked = beam_seats(rig.profile, rig.layout.with_sanding_stock(dome=STOCK_MM, paraboloid=0.0))
    assert stocked == bare
    # and the stocked mirror stays clear of the blocks: their inner face is outside it by the margin
    # and the stock (x_in is a millimetre outside the unstocked surface)
    inner = rig.layout.with_sanding_stock(dome=STOCK_MM, paraboloid=0.0).as_printed_dome
    x_in = min(b.lo[0] for b in bare.blocks if b.lo[0] > 0)
    pts = inner.points(inner.sample(4001))
    top = max(b.hi[2] for b in bare.blocks)
    band = (pts[:, 1] >= rig.profile.dome_shell.flange_thickness) & (pts[:, 1] <= top)
    assert x_in - pts[band, 0].max() >= 1.0
