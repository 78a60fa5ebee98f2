"""Files of a tolerance run, published together (rigcad.export.atomic.Staging) into
``exports/<profile>/tolerance/``:

* ``samples.parquet``, ``samples.csv`` - one row per sample: every perturbation (mm, rad) and
  every figure, per light path and the worse of the two, and whether it met the targets;
* ``summary.json`` - the yield and the distribution of each figure, the sensitivity ranking and
  the inverse limits; the same bytes for any worker count or engine;
* ``tolerance.md`` with ``histograms.png`` and ``sensitivity.png`` (rigcad.plots);
* ``run.json`` - engine, workers and wall times: the one file that differs run to run.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from rigcad.check.montecarlo import PATH_FIGURES, meets
from rigcad.units import DEG


def table_bytes(columns: dict, tol) -> tuple[bytes, bytes]:
    """(Parquet, CSV) bytes of the per-sample table, with a ``meets_targets`` column."""
    import pyarrow as pa
    import pyarrow.csv as pcsv
    import pyarrow.parquet as pq

    cols = dict(columns)
    cols["meets_targets"] = meets(columns, tol)
    table = pa.table({k: pa.array(np.asarray(v)) for k, v in cols.items()})
    pbuf = io.BytesIO()
    pq.write_table(table, pbuf, compression="zstd")
    cbuf = io.BytesIO()
    pcsv.write_csv(table, cbuf)
    return pbuf.getvalue(), cbuf.getvalue()


def _fmt(v: float, unit: str) -> str:
    if unit == "rad":
        return f"{v / DEG:.4g} deg"
    return f"{v:.4g} mm"


def markdown(profile, summary: dict, limits: list[dict] | None, correlations: dict | None) -> str:
    """tolerance.md: the yield, the figures' distributions, the ranking and the inverse limits."""
    tol = profile.tolerancing
    lines = [f"# Tolerance report: {profile.name}", "",
             f"{summary['samples']} random builds (seed {summary['seed']}), {summary['rays_per_path']} rays per light "
             f"path (projector and camera; the worse counts). {summary['distribution']}.", "",
             f"**Yield: {summary['yield']:.2%}** of builds meet both targets (spot radius <= "
             f"{tol.max_spot_radius:g} mm, calibrated angle error <= {tol.max_angle_error / DEG:g} deg); "
             f"required {tol.min_yield:.0%} (`tolerancing.min_yield`): "
             f"{'met' if summary['yield'] >= tol.min_yield else 'NOT met'}.", "",
             "| figure | mean | p50 | p90 | p99 | max |", "|---|---|---|---|---|---|"]
    for k in PATH_FIGURES:
        s = summary["figures"][k]
        if k == "max_angle_error_rad":
            name, conv = "max_pixel_angle_error, uncalibrated (deg)", 1 / DEG
        elif k.endswith("_rad"):
            name, conv = k[:-4] + ", calibrated (deg)", 1 / DEG
        else:
            name, conv = k, 1.0
        lines.append(f"| {name} | " + " | ".join(f"{s[q] * conv:.4g}" for q in ("mean", "p50", "p90", "p99", "max")) + " |")
    lines += ["", "![histograms](histograms.png)", ""]
    if limits:
        lines += ["## Sensitivity and inverse limits", "",
                  "Each parameter alone at its tolerance (worst of two directions), the share of each target it "
                  "uses, and its inverse limit: the largest move keeping the calibrated angle error within "
                  f"{tol.max_angle_error / DEG:g} deg (and the spot within {tol.max_spot_radius:g} mm), by bisection "
                  "on the analytic tracer.", "",
                  "| rank | parameter | tolerance | spot used | angle used | angle limit | spot limit | "
                  "MC rank corr. (spot, angle) |", "|---|---|---|---|---|---|---|---|"]
        for r in limits:
            u = r["unit"]
            lim = _fmt(r[f"limit_{u}"], u) + ("" if r["limit_found"] else " (none below the search cap)")
            slim = _fmt(r[f"spot_limit_{u}"], u) + ("" if r["spot_limit_found"] else " (none below cap)")
            corr = correlations.get(r["parameter"], {}) if correlations else {}
            cs = (f"{corr.get('max_spot_radius_mm', 0):+.2f}, {corr.get('max_mirror_angle_error_rad', 0):+.2f}"
                  if corr else "-")
            lines.append(f"| {r['rank']} | `{r['profile_key']}` | {_fmt(r[f'tolerance_{u}'], u)} | "
                         f"{r['spot_budget_used']:.1%} | {r['angle_budget_used']:.1%} | {lim} | {slim} | {cs} |")
        lines += ["", "![sensitivity](sensitivity.png)", ""]
    return "\n".join(lines) + "\n"


def write_tolerance(out_dir: Path, profile, mc, limits, correlations, run_info: dict, lock=None) -> list[Path]:
    """Write the files of the module docstring into ``out_dir`` (all or nothing); returns the paths."""
    from rigcad import plots
    from rigcad.export.atomic import Staging, json_bytes

    out_dir = Path(out_dir)
    parquet, csv = table_bytes(mc.columns, profile.tolerancing)
    summary = dict(mc.summary)
    summary["sensitivity_and_limits"] = limits
    summary["rank_correlations"] = correlations
    files = {"samples.parquet": parquet, "samples.csv": csv, "summary.json": json_bytes(summary),
             "tolerance.md": markdown(profile, mc.summary, limits, correlations).encode(),
             "histograms.png": plots.tolerance_histograms(profile, mc.columns, mc.summary),
             "run.json": json_bytes(run_info)}
    if limits:
        files["sensitivity.png"] = plots.tolerance_sensitivity(profile, limits)
    from rigcad.export.manifest import profile_digest

    with Staging(out_dir, lock, carry=lambda rel: False,  # the run owns the whole folder
                 made_from=profile_digest(profile)) as stage:
        for name, data in files.items():
            stage.write_bytes(out_dir / name, data)
        return stage.commit()
