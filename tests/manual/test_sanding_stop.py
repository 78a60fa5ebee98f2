"""One rule stops the sanding of the print's staircase, gauged with the sanded-stage template fab writes
(``outlines/<mirror>_template_sanded.dxf``): section 3's words and the finishing recipe's first stage state
the same rule, and the manual names that file. (The lab technician read "stops where the template shows its
first gap: it never reaches the design surface" in section 3 against "the template's gap 0.114 mm all along
it" in the recipe, with no template named for the sanded surface.)"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from rigcad.manual import document as D
from rigcad.manual import finishing as F

#: A fab report's mirror entries as the MK3S run leaves them, for what section 3 reads (mm).
MIRRORS = {"dome": {"polishing": {"stock_to_add_mm": 0.092, "sanding_depth_mm": 0.150},
                    "sanding_stock": {"stock_mm": 0.159}},
           "paraboloid": {"polishing": {"stock_to_add_mm": 0.081, "sanding_depth_mm": 0.149},
                          "sanding_stock": {"stock_mm": 0.113}}}


def _text(doc: D.Doc) -> str:
    out = []
    for b in doc.blocks:
        if b[0] in ("p", "h"):
            out.append(str(b[-1]))
        elif b[0] in ("ul", "ol"):
            out += b[1]
        elif b[0] == "table":
            out += [" | ".join(map(str, r)) for r in b[2]]
    return "\n".join(out)


def stop_rule_misfits(section3: str, first_stage_check: str, gap: float) -> list[str]:
    """Where section 3 and the recipe's first stage disagree on when sanding stops."""
    out = []
    for where, text in (("section 3", section3), ("the recipe's stage 1", first_stage_check)):
        if "first gap" in text or "never reaches the design surface" in text:
            out.append(f"{where}: stops at the template's first gap")
        if "_template_sanded.dxf" not in text or "fits flush along its whole edge" not in text:
            out.append(f"{where}: does not stop at the sanded-stage template fitting flush")
        if f"gap {gap:.3f} mm" not in text:
            out.append(f"{where}: does not say what the finished template reads then ({gap:.3f} mm)")
    return out


@pytest.fixture(scope="module")
def section3(table31_rig):
    d = D.Doc()
    c = SimpleNamespace(rig=table31_rig, p=table31_rig.profile, files={}, fab_report={"parts": MIRRORS})
    D._section_sand(d, c)
    return _text(d)


def test_section_3_and_the_recipe_state_one_stop_rule(table31_rig, section3):
    p = table31_rig.profile
    gap = F.template_gaps(p)[0]  # the bare print behind the finished template: the layers up to the gauged one
    assert gap == pytest.approx(4.5 * 0.0254)  # the shipped coats: 1.5 + 1.5 + 1.5 mil under the gauged clear coat
    first = F.recipe(p, {n: e["sanding_stock"]["stock_mm"] for n, e in MIRRORS.items()})[0][4]
    assert stop_rule_misfits(section3, first, gap) == []
    for mirror in MIRRORS:  # each mirror's line names its own sanded-stage template
        line = next(s for s in section3.splitlines() if s.startswith(f"`{mirror}`: sand"))
        assert f"`outlines/{mirror}_template_sanded.dxf`" in line, line
    # planted: section 3 as the lab technician read it is caught
    old = section3.replace(F.sanding_stop(gap, ("dome",)), "stops where the guide coat is gone from the valleys "
                           "and the template shows its first gap: it never reaches the design surface")
    assert old != section3 and stop_rule_misfits(old, first, gap)


def test_the_sanded_template_named_is_the_file_fab_writes(table31_rig, tmp_path):
    """sanded_template's path is one of the outlines fab's stage templates write (rigcad.fab.stage)."""
    from rigcad.fab import stage

    written: list[str] = []
    run = SimpleNamespace(printer=SimpleNamespace(sanding_stock=0.159), chord=0.05, out=tmp_path,
                          stage=SimpleNamespace(write_bytes=lambda path, data: written.append(
                              path.relative_to(tmp_path).as_posix())))
    rows = stage._stage_templates(table31_rig, "dome_template", run, {"dome": 0.159})
    assert F.sanded_template("dome") in written
    assert F.sanded_template("dome") in rows["sanded"]["files"]
    assert rows["sanded"]["depth_behind_design_mm"] == pytest.approx(sum(t for _, t in table31_rig.profile.coating.layers))
