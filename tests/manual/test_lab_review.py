"""The lab technician's read-through, point by point, as checks on the manual's own data: no step says a
sentence twice, a figure a base profile set for its own instrument is flagged when inherited with
another model, the tools a step uses are in the bill, the gray card's height and the lab's temperature
are stated from the data that sets them."""

from __future__ import annotations

import re
import textwrap

import pytest

import rigcad
from rigcad.manual import bom as B
from rigcad.manual import document as D


def _profile(tmp_path, name: str, body: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent(body), encoding="utf-8")
    return rigcad.load(path)


def repeated_sentences(text: str) -> list[str]:
    """The sentences (split at '. ' and at the end) that occur more than once in ``text``, normalised for
    spaces; sentences under 40 characters ('Tighten them.') may repeat."""
    seen, out = set(), []
    for s in re.split(r"(?<=[.!?])\s+", " ".join(text.split())):
        if len(s) >= 40 and s in seen and s not in out:
            out.append(s)
        seen.add(s)
    return out


def test_repeated_sentences_are_found():
    once = "Fit the shim between the printed shims of each stack. Tighten the screw."
    assert repeated_sentences(once) == []
    assert repeated_sentences(once + " " + once) == ["Fit the shim between the printed shims of each stack."]


def test_the_bought_items_a_step_fits_are_one_sentence_per_use(table31_rig):
    """The precision shims (one row per thickness, the same use) are named in one sentence: step 14 said
    the same sentence four times."""
    rows = [{"kind": "placed", "item": B.tower_item(h), "quantity": h["quantity"], "into": None, "for": "projector_body",
             "joins": h["joins"]} for h in B.tower_hardware(table31_rig) if "precision shim" in h["item"]]
    assert len(rows) >= 2, "the tower buys more than one thickness of shim"
    text = D.placed_text(rows)
    assert repeated_sentences(text) == [], text
    for r in rows:  # every thickness is still named, with its count per stack
        assert r["item"] in text
    # the use is said once: planted back as one sentence per row, it repeats
    planted = "".join(f" Press them in: {r['joins'].split(' ', 1)[1]}." for r in rows)
    assert repeated_sentences(planted)


def test_an_inherited_instrument_figure_is_flagged_with_its_file(tmp_path):
    """A profile that extends the thesis's and names another projector inherits the BenQ's throw ratio:
    the bill says which file set it (the base profile's line), not the file that chose the projector."""
    epson = _profile(tmp_path, "epson", """
        projector:
          model: epson_eb_w52
        """)
    spec = B._describe(epson.profile.projector, epson.profile, "projector")
    assert re.search(r"throw ratio 1\.75 \(set in `profiles/achutha2006\.yaml:\d+`, not with the model", spec), spec
    own = rigcad.load("achutha2006")
    assert "not with the model" not in B._describe(own.profile.projector, own.profile, "projector")
