"""The live session rebuilds only what an edit touches, and what it rebuilds equals a rig built
from scratch (the non-incremental path: Rig.from_profile, run_design, picture_meshes, run_raycheck):
an edit of beam.width re-meshes exactly the in-rig parts whose recipes declare that they read
beam.width (Part.shaped_by, the parts' own statement, not the session's keys), integrates no dome
and traces no design; an edit of layout.cop_to_vertex does both; an unknown key gives file:line
and keeps the last good rig; fixing it brings the new rig back; the extends: chain is watched."""

from __future__ import annotations

import numpy as np
import pytest

from rigcad.live.session import LiveSession, check_rows, headline

BASE = "extends: achutha2006\n"


def _write(path, body: str) -> None:
    path.write_text(BASE + body, encoding="utf-8")


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    folder = tmp_path_factory.mktemp("live")
    path = folder / "rig.yaml"
    _write(path, "beam:\n  width: 6 mm\n")
    session = LiveSession(path)
    first = session.update()
    assert first.error is None, first.error
    assert session.finish_check() is not None
    return session, path


def _from_scratch(path):
    from rigcad.profile import load_profile
    from rigcad.rig import Rig

    return Rig.from_profile(load_profile(path))


def test_first_frame_builds_everything_and_watches_the_extends_chain(live):
    session, path = live
    names = [f.name for f in session.files]
    assert names[:2] == ["rig.yaml", "achutha2006.yaml"], names  # the profile, then what it extends
    # and the instrument files it names: an edit of its camera's file rebuilds as an edit of the profile
    assert {"benq_pb6210.yaml", "prosilica_ec1350c.yaml"} <= set(names), names
    assert session.builds["dome"] == 1 and session.builds["design"] == 1 and session.builds["check"] == 1
    assert len(session.good.parts) == len(session.good.keys) > 10


def test_beam_width_rebuilds_only_the_parts_that_read_it(live):
    session, path = live
    before = session.builds.copy()
    _write(path, "beam:\n  width: 9 mm\n")
    frame = session.update()
    assert frame.error is None, frame.error
    rig = _from_scratch(path)
    readers = {p.name for p in [*rig.recipes.values(), *rig.instruments] if p.in_rig and "beam.width" in p.shaped_by}
    assert "beam" in readers and len(readers) < len(frame.keys) / 3  # the test means something: a few parts
    meshed = {k[5:] for k in session.builds if k.startswith("mesh:") and session.builds[k] > before[k]}
    assert meshed == readers, f"re-meshed {sorted(meshed)}; the parts that read beam.width: {sorted(readers)}"
    assert set(frame.changed) == readers
    assert "beam" in frame.moved  # its box got wider
    assert session.builds["dome"] == before["dome"] and session.builds["design"] == before["design"]
    assert frame.check_pending, "the occluding beam is an input of the check"
    done = session.finish_check()
    assert session.builds["check"] == before["check"] + 1
    # the incremental result is the from-scratch result: rows, figures, the beam's mesh
    assert done.rows == check_rows(rig)
    assert frame.figures == headline(rig.design.report)
    beam = next(m for m in frame.parts if m.name == "beam")
    from rigcad.export.mesh import PICTURE_CHORD_ERROR

    fresh = rig.mesh("beam", PICTURE_CHORD_ERROR)
    assert np.array_equal(beam.vertices, fresh.vertices) and np.array_equal(beam.faces, fresh.faces)
    assert np.ptp(beam.vertices[:, 1]) == pytest.approx(9.0, abs=1e-9)  # 9 mm across (y), as written


def test_a_save_without_a_change_rebuilds_nothing(live):
    session, path = live
    path.write_text(path.read_text())
    before = session.builds.copy()
    frame = session.update()
    assert frame.changed == () and frame.ran == () and not frame.check_pending
    assert session.builds == before
    assert len(session._mesh_cache) == len(frame.keys)  # meshes of parts no longer in use are dropped


def test_the_design_carried_over_equals_a_fresh_one(live):
    """A key that ignored a design input would carry a stale design over: the report must equal a
    fresh run_design's, profile entry included."""
    session, path = live
    _write(path, "beam:\n  width: 9 mm\n  height: 12 mm\n")
    frame = session.update()
    assert "design" not in frame.ran
    assert session.good.rig.design.report == _from_scratch(path).design.report


def test_a_design_input_alone_retraces_the_design_not_the_dome(live):
    """targets.* is read by the design, not by the dome or the parts: the design is traced again
    (its report then equals a fresh one) and nothing else is."""
    session, path = live
    before = session.builds.copy()
    _write(path, "beam:\n  width: 9 mm\n  height: 12 mm\ntargets:\n  theta_min: 10 deg\n")
    frame = session.update()
    assert frame.error is None, frame.error
    assert session.builds["design"] == before["design"] + 1 and session.builds["dome"] == before["dome"]
    assert frame.changed == ()
    assert session.good.rig.design.report == _from_scratch(path).design.report


def test_unknown_key_keeps_the_last_good_rig_and_a_fix_brings_the_new_one(live):
    session, path = live
    good = session.good
    _write(path, "beam:\n  widht: 7 mm\n")
    frame = session.update()
    assert frame.error is not None and f"{path.name}:3" in frame.error and "widht" in frame.error
    assert session.good is good and frame.keys == good.keys and frame.changed == ()
    _write(path, "beam:\n  width: 7 mm\n")
    fixed = session.update()
    assert fixed.error is None and "beam" in fixed.changed
    assert np.ptp(next(m for m in fixed.parts if m.name == "beam").vertices[:, 1]) == pytest.approx(7.0, abs=1e-9)


def test_cop_to_vertex_integrates_the_dome_and_traces_the_design(live):
    session, path = live
    before, previous = session.builds.copy(), dict(session.good.figures)
    _write(path, "beam:\n  width: 7 mm\nlayout:\n  cop_to_vertex: 28 cm\n")
    frame = session.update()
    assert frame.error is None, frame.error
    assert session.builds["dome"] == before["dome"] + 1 and session.builds["design"] == before["design"] + 1
    # the dome follows the COP; the paraboloid's recipe (its size, the clamp) does not, so it stays
    assert "dome" in frame.changed and "paraboloid" not in frame.changed
    rig = _from_scratch(path)
    assert np.array_equal(session.good.rig.dome.points, rig.dome.points)
    fresh = headline(rig.design.report)
    assert frame.figures == fresh
    for key, value in fresh.items():  # the change since the last good state, figure by figure
        assert frame.deltas[key] == value - previous[key]
    assert frame.deltas["mirror_width_mm"] > 0  # a longer throw widens the dome mirror


PRINTER = """description: a test printer
process: fdm
build_volume: {x: 250 mm, y: 210 mm, z: 210 mm}
bed_margin: 1 mm
layer_height: 0.15 mm
first_layer_height: 0.2 mm
nozzle: 0.4 mm
filament_diameter: 1.75 mm
material: PLA
material_density_g_cm3: 1.24
deposition_rate_mm3_s: 8.0
layer_time_s: 1.0
slicer: none
alignment_pin: {diameter: 1.75 mm, clearance: 0.15 mm, depth: 6 mm}
"""


def test_printer_files_are_watched_and_fits_reported(tmp_path):
    path = tmp_path / "rig.yaml"
    _write(path, "")
    (tmp_path / "base_printer.yaml").write_text(PRINTER, encoding="utf-8")
    printer = tmp_path / "tiny.yaml"
    printer.write_text("extends: base_printer\nbuild_volume: {x: 60 mm, y: 60 mm, z: 60 mm}\n", encoding="utf-8")
    session = LiveSession(path, check=False, printers=(str(printer),))
    frame = session.update()
    assert frame.error is None, frame.error
    assert printer.resolve() in session.files and (tmp_path / "base_printer.yaml").resolve() in session.files
    fit = frame.printers["tiny"]
    # the dome mirror is ~270 mm across: it cannot fit 60 mm; the ~40 mm sample holder can
    assert "dome" in fit["split"] and "sample_holder" not in fit["split"] and "sample_holder" in frame.keys, fit
    printer.write_text("extends: base_printer\n", encoding="utf-8")  # the full 250 x 210 x 210 mm bed
    again = session.update()
    assert len(again.printers["tiny"]["split"]) < len(fit["split"])
    assert "mesh:dome" not in again.ran  # a printer edit re-meshes nothing
