"""The acquisition simulation reads the camera's exitant directions from a corrected map when one
exists (rigcad calibrate writes it), else from the design map."""

import io

import numpy as np

from rigcad.basis.acquire import camera_view
from rigcad.basis.projector import zone_of
from rigcad.calibrate import CORRECTED_MAP, load_corrected_map


def test_camera_view_reads_the_corrected_map(table31_rig, tmp_path):
    rig = table31_rig
    zone = zone_of(rig)
    design = camera_view(rig, zone, 16)
    assert load_corrected_map(tmp_path, rig.name) is None
    # a map over the left half of the window only, all pointing straight up
    rows, cols = design.pixels.row[design.keep], design.pixels.col[design.keep]
    row0, col0 = int(rows.min()), int(cols.min())
    h, w = int(rows.max()) - row0 + 1, int(cols.max()) - col0 + 1
    direction = np.full((h, w, 3), np.nan)
    direction[:, : w // 2] = (0.0, 0.0, 1.0)
    path = tmp_path / rig.name / CORRECTED_MAP
    path.parent.mkdir(parents=True)
    buf = io.BytesIO()
    np.savez(buf, direction=direction, row0=row0, col0=col0)
    path.write_bytes(buf.getvalue())
    corrected = load_corrected_map(tmp_path, rig.name)
    got = camera_view(rig, zone, 16, corrected=corrected).wo
    left = cols - col0 < w // 2
    assert left.any() and (~left).any()
    assert np.array_equal(got[left], np.tile([0.0, 0.0, 1.0], (left.sum(), 1)))
    assert np.array_equal(got[~left], design.wo[~left])
