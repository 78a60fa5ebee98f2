"""Mirror meshes: declared chord error against triangle count, build time, measured errors, PLY size.

Run from the repository root: ``.venv/bin/python bench/mirror_mesh.py``. Writes
bench/results/mirror_mesh.json and bench/results/mirror_mesh.png. Everything in them is
deterministic except the timings (keys ending in ``_s``, and the PNG's time panel).

Tie between the two declared bounds: facet-normal error (rad) = chord error (mm) x 1 rad/mm, the
same number (0.001 mm with 0.001 rad, the pair the ray checker asked about). On a meridian of
curvature k a facet sized for chord error e has a normal error of about sqrt(2 k e), so with this
tie the normal bound sets the density once e < 2 k: below ~0.017 mm for the dome (k <= 0.0083/mm),
and at every row for the paraboloid near its vertex (k = 0.168/mm). The ``binding`` column says
which bound set it.

Timings: ``build_first_s`` is the first build of each row in this process, ``build_s`` the best of
REPEATS builds (the first build of a large mesh also pays the kernel's first touch of its memory);
``write_s`` is one atomic PLY write to a temporary folder. Not asserted anywhere.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from rigcad.export.atomic import write_bytes, write_json
from rigcad.export.mirror_mesh import mirror_mesh, write_ply
from rigcad.optics.dome import build_dome
from rigcad.optics.surfaces import dome_meridian, paraboloid_meridian
from rigcad.profile import derive, load_profile

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "profiles" / "achutha2006.yaml"
RESULTS = ROOT / "bench" / "results"
CHORD_ERRORS_MM = (0.1, 0.03, 0.01, 0.003, 0.001)
NORMAL_PER_CHORD_RAD_PER_MM = 1.0
REPEATS = 3


def run_row(meridian, name: str, chord: float, normal: float, scratch: Path) -> dict:
    times = []
    for _ in range(REPEATS):
        mesh = None  # free the previous build first: the largest mesh holds ~0.6 GB of arrays
        t0 = time.perf_counter()
        mesh = mirror_mesh(meridian, name, chord, normal)
        times.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    path = write_ply(scratch / f"{name}.ply", mesh)
    write_s = time.perf_counter() - t0
    size = path.stat().st_size
    path.unlink()
    rep = mesh.report
    if size != rep["bytes"]:
        raise SystemExit(f"{name} {chord} mm: PLY is {size} bytes, the report says {rep['bytes']}")
    return {
        "chord_error_mm": chord,
        "facet_normal_error_rad": normal,
        "triangles": rep["triangles"],
        "vertices": rep["vertices"],
        "rings": rep["rings"],
        "sectors": rep["sectors"],
        "measured_chord_error_mm": rep["measured_chord_error_mm"],
        "measured_facet_normal_error_rad": rep["measured_facet_normal_error_rad"],
        "model_chord_error_mm": rep["model_chord_error_mm"],
        "model_facet_normal_error_rad": rep["model_facet_normal_error_rad"],
        "hausdorff_mm": rep["hausdorff_mm"],
        "binding": rep["binding"],
        "builds": rep["builds"],
        "ply_bytes": rep["bytes"],
        "build_first_s": times[0],
        "build_s": min(times),
        "write_s": write_s,
    }


def table(name: str, rows: list[dict]) -> str:
    head = (f"{name}\n{'chord mm':>9} {'normal rad':>10} {'triangles':>10} {'rings x sectors':>16} {'build s':>8} "
            f"{'(first)':>8} {'meas chord mm':>13} {'meas normal rad':>15} {'binding':>12} {'hausdorff mm':>12} "
            f"{'PLY MB':>8} {'write s':>8}")
    lines = [head]
    for r in rows:
        lines.append(
            f"{r['chord_error_mm']:>9g} {r['facet_normal_error_rad']:>10g} {r['triangles']:>10d} "
            f"{r['rings']:>7d} x {r['sectors']:<6d} {r['build_s']:>8.3f} {r['build_first_s']:>8.3f} "
            f"{r['measured_chord_error_mm']:>13.4g} {r['measured_facet_normal_error_rad']:>15.4g} {r['binding']:>12} "
            f"{r['hausdorff_mm']:>12.4g} {r['ply_bytes'] / 1e6:>8.2f} {r['write_s']:>8.3f}")
    return "\n".join(lines)


def plot(results: dict) -> bytes:
    """Log-log: measured chord and facet-normal errors and build time against triangles."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    colours = {"dome": "tab:blue", "paraboloid": "tab:orange"}
    for name, rows in results["mirrors"].items():
        tri = np.array([r["triangles"] for r in rows])
        c = colours[name]
        for ax, meas, decl in ((axes[0], "measured_chord_error_mm", "chord_error_mm"),
                               (axes[1], "measured_facet_normal_error_rad", "facet_normal_error_rad")):
            ax.loglog(tri, [r[meas] for r in rows], "o-", color=c, label=f"{name}: measured")
            ax.loglog(tri, [r[decl] for r in rows], "--", color=c, lw=0.8, label=f"{name}: declared")
        axes[2].loglog(tri, [r["build_s"] for r in rows], "o-", color=c, label=f"{name}: best of {REPEATS}")
        axes[2].loglog(tri, [r["build_first_s"] for r in rows], "x:", color=c, label=f"{name}: first build")
    axes[0].set_ylabel("chord error (mm)")
    axes[1].set_ylabel("facet-normal error (rad)")
    axes[2].set_ylabel("build time (s), this machine")
    for ax, title in zip(axes, ("chord error", "facet-normal error", "build time (mirror_mesh, incl. checks)")):
        ax.set_xlabel("triangles")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("rigcad mirror meshes (normal error rad = chord error mm x 1 rad/mm)", fontsize=11)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=RESULTS, help="results folder (default: bench/results)")
    out = ap.parse_args().out
    geo = derive(load_profile(PROFILE))
    meridians = {
        "dome": dome_meridian(build_dome(geo, "dop853", tolerance=1e-9, rows=2001)),
        "paraboloid": paraboloid_meridian(geo),
    }
    results = {
        "profile": str(PROFILE.relative_to(ROOT)),
        "dome_meridian": "build_dome dop853, tolerance 1e-9 mm, 2001 rows, quintic spline (dome_meridian)",
        "normal_error_tie": "facet_normal_error_rad = chord_error_mm x 1 rad/mm",
        "timings": f"build_s best of {REPEATS}, build_first_s first build in the process, write_s one PLY write",
        "mirrors": {},
    }
    with tempfile.TemporaryDirectory() as scratch:
        for name, meridian in meridians.items():
            rows = [run_row(meridian, name, c, c * NORMAL_PER_CHORD_RAD_PER_MM, Path(scratch))
                    for c in CHORD_ERRORS_MM]
            results["mirrors"][name] = rows
            print(table(name, rows), flush=True)
    print(write_json(out / "mirror_mesh.json", results))
    print(write_bytes(out / "mirror_mesh.png", plot(results)))


if __name__ == "__main__":
    main()
