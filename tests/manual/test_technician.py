"""What the lab technician's read-through checks, held from data: the step pictures draw the shims the
text counts; the templates' drawings mark the datum the text names, on the template's own outline; the
sanding blocks' faces are the mirrors' surfaces (the abrasive's thickness proud) over bands that cover
each meridian; the slope test's light path comes from the film test's set-up."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rigcad.manual import finishing as F
from rigcad.manual.assembly import PartMesh
from rigcad.manual.document import shim_stacks, step_picture, step_text


def _box(name: str, lo, hi, bought: bool = False) -> PartMesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return PartMesh(name, v, f, (0.9, 0.8, 0.3), f"{name}", 1, np.zeros(3), bought)


def test_a_shim_step_pictures_the_shims_its_text_counts():
    """Four stacks of 4 mm on a shelf, 1 mm shims: the text says 4 stacks of 4 (16 shims) and the picture
    draws 16 boxes of 1 mm, each stack's shims apart along the step's direction."""
    shelf = _box("tower_shelf", (-50, -50, -10), (50, 50, 0))
    stacks = [_box(f"projector_shims_{k + 1}", (x - 5, y - 5, 0), (x + 5, y + 5, 4))
              for k, (x, y) in enumerate(((-30, -30), (30, -30), (-30, 30), (30, 30)))]
    meshes = [shelf, *stacks]
    step = SimpleNamespace(name="projector_shims", members=tuple(m.name for m in stacks), needs=("tower_shelf",),
                           fasteners=(), bought=False)
    by_name = {m.name: m for m in meshes}
    assert shim_stacks(step, by_name, 1.0) == (4, 4)
    text = step_text(SimpleNamespace(step=step, direction=(0.0, 0.0, -1.0)), by_name, shim_mm=1.0)
    assert "4 stacks of 4 printed `tower_shim`s (16 shims)" in text
    offsets = {i: np.array([0.0, 0.0, 60.0]) for i in range(1, 5)}
    shown, new, moved = step_picture(meshes, [0], [1, 2, 3, 4], offsets, (0.0, 0.0, -1.0), 1.0)
    assert len(new) == 16  # the count the text states
    for i in new:
        assert float(np.ptp(shown[i].vertices[:, 2])) == pytest.approx(1.0)  # one shim each
    for k in range(4):  # in a stack, each shim drawn above the one under it, with a visible gap
        z = [float(shown[i].vertices[:, 2].min() + moved[i][2]) for i in new[4 * k:4 * k + 4]]
        assert all(b - a > 1.0 + 1.0 for a, b in zip(z, z[1:])), z
    # a 2 mm shim reads the stacks as 2 shims each: the count follows the drawing, not a typed number
    assert shim_stacks(step, by_name, 2.0) == (4, 2)
    assert len(step_picture(meshes, [0], [1, 2, 3, 4], offsets, (0.0, 0.0, -1.0), 2.0)[1]) == 8


def test_the_templates_datums_are_on_their_outlines_and_in_their_text(table31_rig):
    """Each template's datum (an edge or a corner) lies on the template as meshed; the text states its
    figures; the drawing marks it in red; the dome's datum corner stands on the plate, z = 0."""
    from rigcad import plots

    rows = {r["template"]: r for r in F.template_datums(table31_rig)}
    assert set(rows) == {"dome_template", "paraboloid_template"}
    for name, row in rows.items():
        mesh = np.asarray(table31_rig.mesh(table31_rig.recipes[name]).vertices)
        xz = mesh[:, [0, 2]]
        for p in row["datum_mm"]:  # on the solid: a vertex within the mesher's chord of the datum point
            assert float(np.min(np.hypot(*(xz - np.asarray(p)).T))) < 0.05, (name, p)
        text = F.template_text(row)
        assert f"z = {row['datum_z_mm']:.1f} mm" in text
        png = plots.template_drawing(row)
        from PIL import Image
        import io

        img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
        red = (img[..., 0] > 180) & (img[..., 1] < 90) & (img[..., 2] < 90)
        assert red.sum() > 50, f"{name}: no datum drawn in red"
    dome = rows["dome_template"]
    assert dome["datum"] == "corner" and abs(dome["datum_z_mm"]) < 1e-9  # on the plate's top
    assert f"{dome['datum_r_mm']:.1f} mm from the axis" in F.template_text(dome)
    # the paraboloid's datum is on the paraboloid: its feet in the plane of its rim (the top edge it had before
    # hung in the air 15 mm over the vertex, level with nothing on the rig)
    para = rows["paraboloid_template"]
    assert para["datum"] == "rim" and len(para["datum_mm"]) == 2
    (x0, z0), (x1, z1) = para["datum_mm"]
    assert abs(x0 + x1) < 1e-9 and abs(z0 - z1) < 1e-9  # one each side, symmetric about the axis, level
    part = np.asarray(table31_rig.mesh(table31_rig.recipes["paraboloid"]).vertices)
    r = np.hypot(part[:, 0], part[:, 1])
    side = part[r > r.max() - 0.05]  # the paraboloid's outermost vertices: its side up to the rim edge
    # the rim edge (the side's top) lies in the feet's plane: within the coats' total (the print stands
    # behind the design, 0.14 mm) and the mesher's chord
    coats = sum(t for _, t in table31_rig.profile.coating.layers)
    assert abs(side[:, 2].max() - para["datum_z_mm"]) < coats + 0.05, (side[:, 2].max(), para["datum_z_mm"])
    assert f"{2 * para['datum_r_mm']:.1f} mm across" in F.template_text(para)


def test_the_sanding_blocks_faces_are_the_mirrors_surfaces_over_bands_that_cover_them(table31_rig):
    """Bands: each at most BLOCK_LENGTH_MM of arc, neighbours overlapping by BLOCK_OVERLAP_MM at least, the first from the
    meridian's start and the last to its end. Faces: the block's mesh comes no nearer the mirror surface than the
    abrasive's thickness and reaches it (its face); a block slid by its slide stands off by at most BLOCK_SAG_MM."""
    rows = F.sanding_block_set(table31_rig)
    designs = {m: d for part in table31_rig.recipes.values() for m, d in part.mirrors}
    assert {r["mirror"] for r in rows} == set(designs)
    for mirror, design in designs.items():
        mine = [r for r in rows if r["mirror"] == mirror]
        u, s = F._arc(design)
        assert mine[0]["from_mm"] == pytest.approx(0.0, abs=1e-9) and mine[-1]["to_mm"] == pytest.approx(s[-1], abs=1e-6)
        for a, b in zip(mine, mine[1:]):
            assert a["to_mm"] - b["from_mm"] >= F.BLOCK_OVERLAP_MM - 1e-9  # spread evenly: at least the overlap
        assert all(r["length_mm"] <= F.BLOCK_LENGTH_MM + 1e-9 for r in mine)
        # the face against the surface, measured in the meridional plane of each mesh vertex
        dense = design.points(design.sample(20001))
        for r in (mine[0], mine[-1]):
            v = np.asarray(table31_rig.mesh(r["part"]).vertices)
            rz = np.stack([np.hypot(v[:, 0], v[:, 1]), v[:, 2]], axis=1)
            dist = np.array([np.min(np.hypot(*(dense - q).T)) for q in rz[:: max(1, len(rz) // 400)]])
            chord = table31_rig.profile.tessellation.chord_error
            # no material inside the abrasive's room (a mesh's chords cut inside by at most the chord error,
            # the dense sampling adds its spacing, under 0.02 mm here); the face touches that room
            assert dist.min() > F.ABRASIVE_MM - chord - 0.02, (mirror, r["block"], dist.min())
            assert dist.min() < F.ABRASIVE_MM + 0.02, (mirror, r["block"], dist.min())
        for r in mine:
            band = (np.interp(r["from_mm"], s, u), np.interp(r["to_mm"], s, u))
            inside = (u >= band[0] - 1e-12) & (u <= band[1] + 1e-12)
            km, ks = F._curvatures(design, u)
            for sign in (1.0, -1.0):
                t = s[inside] + sign * r["slide_mm"]
                if t.min() >= 0 and t.max() <= s[-1]:
                    assert F.block_gap(km, ks, s, inside, t, r["length_mm"], r["width_mm"]) <= F.BLOCK_SAG_MM + 1e-6
    para = [r for r in rows if r["mirror"] == "paraboloid"]
    assert len(para) == 1 and para[0]["slide_mm"] == 0.0  # the whole meridian: it only turns about the axis


def test_the_slope_tests_light_path_is_the_film_tests_set_up(table31_rig):
    """The lit disc is the film on the plate's top over the bore, lit from below between the film test's
    blocks: the figures are film_setup's, and the bore's slope bound is its radius over twice the dome's reach."""
    from rigcad.manual.calibration import film_setup

    acc, f = F.slope_acceptance(table31_rig), film_setup(table31_rig)
    assert acc["bore_radius_mm"] == f["bore_radius_mm"] > acc["disc_radius_mm"]
    assert acc["block_under_disc_mm"] == f["block_under_disc_mm"]
    assert acc["film_above_bench_mm"] == f["block_under_disc_mm"] + table31_rig.profile.base_plate.thickness
    assert acc["bore_slope_mrad"] == pytest.approx(1e3 * f["bore_radius_mm"] / (2 * acc["dome_farthest_from_o_mm"]))
    assert math.isfinite(acc["dome_slope_tolerance_mrad"])
