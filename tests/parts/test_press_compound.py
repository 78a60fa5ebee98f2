"""Every register's dowel pins are pressed into their reamed N7 holes in retaining compound, by default (an N7/m6
press's 0.008-0.028 mm of interference relaxes as the printed part creeps: the machinist's review), in one wording
(rigcad.parts.locating.PRESS_IN_COMPOUND): the dome's register drilled in place, the column's two registers, a
register with printed holes; and the bill's retaining compound says it is for them."""

from __future__ import annotations

import importlib
from dataclasses import replace

from rigcad.manual import bom as B
from rigcad.manual.document import register_text
from rigcad.parts import locating

dome = importlib.import_module("rigcad.parts.dome")  # the module (rigcad.parts exports the part function)


def test_the_domes_register_presses_its_pins_in_compound(table31_rig):
    reg = dome.register(table31_rig.profile, table31_rig.layout)
    assert locating.PRESS_IN_COMPOUND in register_text(reg)


def test_a_register_with_printed_holes_presses_its_pins_in_compound(table31_rig):
    reg = replace(dome.register(table31_rig.profile, table31_rig.layout), drilled=False, procedure="")
    text = register_text(reg)
    assert locating.PRESS_IN_COMPOUND in text and "glued in with epoxy" not in text
    assert f"{reg.diameter:g} {locating.DOWEL_SLIP_HOLE}" in text  # the slip hole as the fit tables have it


def test_the_columns_dowels_and_the_bill_say_compound(table31_rig):
    rows = [h for h in B.tower_hardware(table31_rig)
            if h["item"].startswith("dowel pin") and "the tongue's and the shelf's blind holes" in h["joins"]]
    assert rows and all(locating.PRESS_IN_COMPOUND in h["joins"] for h in rows)
    (compound,) = [item for item, _ in B.CONSUMABLES if item.startswith("Retaining compound")]
    assert "the registers' dowel pins" in compound
