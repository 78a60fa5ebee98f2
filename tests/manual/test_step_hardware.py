"""Every bought item the bill assigns to an assembly step is named in that step's text (the beam's roll bars,
set screws, stop pin and shim foil in the beam's step), and the shim step states its count per foot."""

from __future__ import annotations

import json
import re

import pytest


def _steps(md: str) -> dict[str, str]:
    """Section 5's steps: name -> text (up to the next heading)."""
    parts = re.split(r"^### Step \d+: (.+)$", md, flags=re.M)
    return {parts[i].strip(): re.split(r"^#", parts[i + 1], flags=re.M)[0] for i in range(1, len(parts) - 1, 2)}


def short(item: str) -> str:
    """An item as a step names it: its words up to the first comma or bracket, less a leading size (M3 x 8 mm)."""
    head = re.split(r"[,(]", item)[0].strip()
    return re.sub(r"^M\d+ x [\d.]+ mm ", "", head)


@pytest.mark.e2e
def test_every_bill_item_of_a_step_is_named_in_it(written):
    md = (written / "manual.md").read_text(encoding="utf-8")
    bill = json.loads((written / "manual.json").read_text(encoding="utf-8"))["bill"]["hardware"]
    steps = _steps(md)
    assert "beam" in steps and "paraboloid" in steps, sorted(steps)
    misses = [(r["item"], s) for r in bill for s in r.get("steps") or () if s in steps
              and short(r["item"]).lower() not in steps[s].lower()]
    assert misses == [], misses
    beam = steps["beam"].lower()
    for item in ("set screw", "flat bar", "dowel pin", "shim foil"):  # the reviewer's missing four
        assert item in beam, item
