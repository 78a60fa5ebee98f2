"""The figures docs/assembly.md and docs/manual.md state outside `make docs`' markers are the code's:
the projector's screw per shim stack, the dome's flange bolts. A figure the pages state and no test
holds drifts (the pages said M4 x 16 and M4 x 25 after the code had moved on)."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import rigcad
from rigcad.manual import plan
from rigcad.parts.joints import ScrewJoint

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _flat(page: str) -> str:
    return " ".join((DOCS / page).read_text(encoding="utf-8").split())


def screw_list(rig) -> str:
    """The projector's screws per stack as docs/assembly.md states them (plan.projector_screw_rows)."""
    rows = plan.projector_screw_rows(rig)
    parts = []
    for k, r in enumerate(rows):
        s = r["stacks"]
        span = f"{s[0]}" if len(s) == 1 else f"{s[0]}..{s[-1]}"
        parts.append(f"{r['item'].split(' socket')[0].replace(' mm', '')} for {span}" + (" shims" if k == 0 else ""))
    return ", ".join(parts)


def test_the_projector_screws_the_page_lists_are_the_codes(table31_rig):
    text = _flat("assembly.md")
    want = screw_list(table31_rig)
    assert want.startswith("M4 x ") and want in text, f"docs/assembly.md should say: {want}"
    # planted: one length off is not in the page
    assert re.sub(r"M4 x (\d+)", lambda m: f"M4 x {int(m.group(1)) + 5}", want, count=1) not in text


def _dome_joint(rig) -> ScrewJoint:
    return next(j for j in rig.recipes["dome"].joints if isinstance(j, ScrewJoint))


def test_the_dome_bolts_the_page_names_are_the_dome_joints(table31_rig, tmp_path):
    text = _flat("manual.md")
    j = _dome_joint(table31_rig)
    assert f"come out {j.thread} x {j.length:g} into the base plate's heat-set inserts" in text
    path = tmp_path / "bolts.yaml"
    path.write_text("extends: achutha2006\n" + textwrap.dedent("""
        base_plate:
          thickness: 20 mm
        dome_shell:
          bolt_diameter: 5.5 mm
          bolts: 12
          flange_width: 24 mm
        """), encoding="utf-8")
    m5 = _dome_joint(rigcad.load(path))
    assert f"{m5.thread} x {m5.length:g} for a 5.5 mm hole" in text
