"""The sample holder's shop drawing (rigcad.manual.drawings, drawn by rigcad.plots.turned_part_drawing):
the dimensions its SVG states, read back as text, are the part's own (its mesh, an independent reader
of the recipe) with the fit's ISO 286 zone; the PNG and SVG are deterministic."""

from __future__ import annotations

import re

import numpy as np
import pytest

from rigcad.manual import drawings as D

#: ISO 286-2, shafts over 30 up to 50 mm: f's fundamental deviation -25 um, IT7 25 um: f7 = -0.025/-0.050 mm.
F7_40 = (-0.050, -0.025)


def svg_texts(svg: bytes) -> list[str]:
    """Every <text> element's content (matplotlib writes one per label with svg.fonttype none)."""
    return [t.replace("&apos;", "'") for t in re.findall(r"<text[^>]*>([^<]*)</text>", svg.decode("utf-8"))]


def _mesh_figures(rig) -> dict:
    """The holder's sizes from its mesh: overall length, collar diameter, the body's diameter and length
    (the vertices on its top face), the collar's thickness (the shoulder: where the radius steps)."""
    m = rig.mesh("sample_holder")
    v = m.vertices
    r = np.hypot(v[:, 0], v[:, 1])
    z0, z1 = v[:, 2].min(), v[:, 2].max()
    body_r = r[np.isclose(v[:, 2], z1, atol=1e-6)].max()
    shoulder = v[np.isclose(r, r.max(), atol=1e-3), 2].max()  # the collar's top, where the radius steps down
    return {"overall": z1 - z0, "collar_d": 2 * r.max(), "body_d": 2 * body_r, "body_len": z1 - shoulder,
            "collar_t": shoulder - z0}


def test_the_drawing_states_the_holders_own_dimensions_and_fit(table31_rig):
    files = D.drawings(table31_rig)
    texts = svg_texts(files["drawings/sample_holder.svg"])
    got = _mesh_figures(table31_rig)
    # the body: its diameter with the f7 zone, as a machinist reads it (upper/lower deviation)
    (body,) = [t for t in texts if re.fullmatch(r"Ø[\d.]+ f7 \([-+][\d.]+/[-+][\d.]+\)", t)]
    d, hi, lo = re.fullmatch(r"Ø([\d.]+) f7 \(([-+][\d.]+)/([-+][\d.]+)\)", body).groups()
    # the mesh's polygon lies inside the circle, by its chord error (0.018 mm at most)
    assert float(d) == pytest.approx(got["body_d"], abs=0.04), (body, got)
    assert (float(lo), float(hi)) == F7_40
    # the collar's diameter, and the three lengths, as plain figures
    (collar,) = [t for t in texts if re.fullmatch(r"Ø[\d.]+", t)]
    assert float(collar[1:]) == pytest.approx(got["collar_d"], abs=0.04)
    lengths = sorted(float(t) for t in texts if re.fullmatch(r"[\d.]+", t))
    expected = sorted([got["collar_t"], got["body_len"], got["overall"]])
    assert lengths == pytest.approx(expected, abs=1e-6), (lengths, expected)  # flat faces: exact in the mesh
    notes = " ".join(texts)
    assert "40 H7/f7 (sliding: clearance 0.025-0.075" in notes and D.GENERAL_TOLERANCE in notes
    assert "10 mm" in texts, "the scale bar's label"


def test_the_drawing_follows_the_profile(write_profile, table31_text):
    """A 30 mm holder is drawn 30 f7 with its own zone (ISO 286-2, 18-30 mm: f -20 um, IT7 21 um)."""
    import rigcad

    rig = rigcad.load(write_profile(table31_text + "sample_holder:\n  radius: 15 mm\n  stop_radius: 22 mm\n",
                                    "small_holder"))
    texts = svg_texts(D.drawings(rig)["drawings/sample_holder.svg"])
    assert "Ø30 f7 (-0.020/-0.041)" in texts and "Ø44" in texts, texts


def test_the_drawing_is_deterministic(table31_rig):
    assert D.drawings(table31_rig) == D.drawings(table31_rig)
