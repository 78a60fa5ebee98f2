"""Write the design stage's outputs: design.json, dome_profile.csv, rays.png, incidence.png."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from rigcad.export.atomic import Staging, json_bytes
from rigcad.export.manifest import profile_digest, sha256_hex
from rigcad.export.readback import own_json
from rigcad.optics.design import Design


def table_csv(table: dict[str, np.ndarray]) -> bytes:
    """The profile table as CSV (header with units, 12 significant digits, empty for undefined)."""
    names = list(table)
    cols = [np.asarray(table[n], dtype=float) for n in names]
    out = io.StringIO()
    out.write(",".join(names) + "\n")
    for row in zip(*cols):
        out.write(",".join("" if not np.isfinite(v) else f"{v:.12g}" for v in row) + "\n")
    return out.getvalue().encode()


def design_files(design: Design) -> dict[str, bytes]:
    """The design stage's files, rendered in memory: name -> bytes."""
    from rigcad import plots

    return {
        "design.json": _design_json(design),
        "dome_profile.csv": table_csv(design.table),
        "rays.png": plots.ray_diagram(design),
        "incidence.png": plots.incidence_plot(design),
    }


def write_design(design: Design, out_dir: Path, lock: Path | None = None) -> list[Path]:
    """Write the design files into ``out_dir``, published together with the folder's other files
    carried over (export.atomic.Staging, under ``lock``); returns the paths."""
    files = design_files(design)
    # results (check/, fab/<printer>/, ...) made from another profile are not carried over
    with Staging(out_dir, lock, results_of=profile_digest(design.profile)) as stage:
        for name, data in files.items():
            stage.write_bytes(out_dir / name, data)
        manifest = out_dir / "manifest.json"
        if manifest.is_file():  # the build's manifest vouches for these files: keep it truthful
            m = own_json(manifest)  # read as data: None when it is not one rigcad wrote
            shas = {name: sha256_hex(data) for name, data in files.items()}
            if isinstance(m, dict) and (m.get("design_files") != shas or stage.stale):
                if m.get("design_files") != shas:
                    m["design_files"] = shas
                    m["inputs_key"] = None  # the parts may no longer match this design: `rigcad stl` rebuilds
                m["stale_results_removed"] = stage.stale_report()
                stage.write_bytes(manifest, json_bytes(m))
        return stage.commit()


def _design_json(design: Design) -> bytes:
    report = dict(design.report)
    report["files"] = {
        "dome_profile.csv": "dome profile table, one row per dome point (units in the header)",
        "rays.png": "ray diagram in the meridional plane (thesis Figure 3.6)",
        "incidence.png": "incidence angle and projector pixel against the paraboloid radius",
    }
    return json_bytes(report)


__all__ = ["design_files", "table_csv", "write_design"]
