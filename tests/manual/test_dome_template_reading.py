"""The dome's template is held and read where a hand and an eye can reach: the whole dome upside down, its
open base up, a straightedge across the base long enough to rest on it, the gap read against a light from the
top opening; the schedule's sanding stage stands the dome that way."""

from __future__ import annotations

import rigcad
from rigcad.manual import finishing as F
from rigcad.manual import schedule as S


def test_the_dome_template_is_read_from_the_open_base():
    rig = rigcad.load("achutha2006")
    dome = next(r for r in F.template_datums(rig) if r["template"] == "dome_template")
    text = F.template_text(dome)
    assert "upside down, its open base up" in text and "torch" in text and "from the open base" in text, text
    rule = next(n for n in F.STRAIGHTEDGES_MM if f"a {n:g} mm steel straightedge" in text)
    assert rule >= 2 * dome["datum_r_mm"] + 2 * F.STRAIGHTEDGE_OVERHANG_MM  # it spans the mirror's base and rests
    sand = next(st for st in S.schedule(rig) if st.where == S.SAND)
    assert "upside down" in sand.what and "open base up" in sand.what, sand.what
