"""Write the design stage's outputs: design.json, dome_profile.csv, rays.png, incidence.png."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from rigcad.export.atomic import write_bytes
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


def write_design(design: Design, out_dir: Path) -> list[Path]:
    """Write the design files into ``out_dir``, each atomically; returns the paths."""
    return [write_bytes(out_dir / name, data) for name, data in design_files(design).items()]


def _design_json(design: Design) -> bytes:
    from rigcad.export.atomic import json_bytes

    report = dict(design.report)
    report["files"] = {
        "dome_profile.csv": "dome profile table, one row per dome point (units in the header)",
        "rays.png": "ray diagram in the meridional plane (thesis Figure 3.6)",
        "incidence.png": "incidence angle and projector pixel against the paraboloid radius",
    }
    return json_bytes(report)


__all__ = ["design_files", "table_csv", "write_design"]
