"""The 2K coats' hardener and reducer are consumables: every two-component layer of the recipe (whose method
says 'with its hardener') has its hardener and reducer in the list, in proportion to the paint the bill buys."""

from __future__ import annotations

import dataclasses
import re

import rigcad
from rigcad.manual import bom as B
from rigcad.manual import finishing as F


def test_every_2k_layer_has_its_hardener_and_reducer():
    rig = rigcad.load("achutha2006")
    coat = [dataclasses.asdict(r) for r in B.coating_rows(rig)]
    rows = F.paint_companions(coat)
    # the recipe's 'with its hardener' or '2K' layers (the black base was '1K acrylic or 2K polyurethane', its
    # hardener in no list) are 2K here
    hardened = [name for name, _ in rig.profile.coating.layers
                if re.search(r"hardener|\b2K\b", F.LAYER_METHODS.get(name, ("",))[0])]
    assert "black base paint" in hardened and set(hardened) <= set(F.TWO_COMPONENT), (hardened, F.TWO_COMPONENT)
    for layer in hardened:
        paint = sum(r["to_buy_cm3"] for r in coat if r["layer"] == layer)
        for what, share in (("Hardener", F.HARDENER_SHARE), ("Reducer", F.REDUCER_SHARE)):
            row = next((r for r in rows if r[0].startswith(what) and f"the {layer}'s" in r[0]), None)
            assert row is not None, (layer, what, rows)
            ml = float(re.match(r"(\d+) ml", row[1]).group(1))
            assert ml >= share * paint, (row, paint)  # rounded up, never under the share of the paint bought
    assert len(rows) == 2 * len(hardened)  # nothing for a 1K layer
