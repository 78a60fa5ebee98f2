"""Basis illumination on the default rig (issue 16): run time of the projector images, their files and
the whole simulated acquisition (thesis 3.3.1) at order 6, with the figures they produce.

Run from the repository root: ``.venv/bin/python bench/basis.py [--out DIR] [--quick]``. Writes
bench/results/basis.json and basis.png.

Stages, timed in one process after the Rig is loaded (what ``rigcad basis achutha2006 --order 6
--simulate`` runs): the projector pixels traced and the images, Gram matrices and lat-long maps
(``projector_basis``); writing the PNGs, sheets and basis.json (``write_basis``, into a temporary
folder); the simulation (``simulate_on_rig``: eq. 4.3 by quadrature over the zone and over its lit
part, the rig as designed and with the paraboloid and the dome moved by their tolerances, the
lobe-width study). The issue's target: the whole simulation at order 6 under a minute on this
machine. Errors are exact (deterministic); timings (keys ending in ``_s``) depend on the load
recorded in ``run``. Not asserted.
"""

from __future__ import annotations

import tempfile
import time

import numpy as np
from _common import arguments, png, pyplot, run_info

import rigcad
from rigcad.basis.acquire import simulate_on_rig
from rigcad.basis.projector import projector_basis, write_basis
from rigcad.export.atomic import write_bytes, write_json

PROFILE = "achutha2006"
ORDER = 6


class Stopwatch:
    """A progress callback that records the time since the last call under each label."""

    def __init__(self) -> None:
        self.t = time.perf_counter()
        self.laps: dict[str, float] = {}

    def __call__(self, label: str) -> None:
        now = time.perf_counter()
        self.laps[label] = self.laps.get(label, 0.0) + now - self.t
        self.t = now


def main() -> None:
    ap = arguments(__doc__)
    args = ap.parse_args()
    order, stride = (2, 120) if args.quick else (ORDER, 32)
    run = run_info()
    t0 = time.perf_counter()
    rig = rigcad.load(PROFILE)
    rig.design  # the 2D design (its table is the light paths' truth); not part of the basis stages
    load_s = time.perf_counter() - t0

    sw = Stopwatch()
    t0 = time.perf_counter()
    basis = projector_basis(rig, order, progress=sw)
    basis_s = time.perf_counter() - t0
    basis_laps = dict(sw.laps)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        paths = write_basis(basis, tmp)
        write_s = time.perf_counter() - t0
        files, megabytes = len(paths), sum(p.stat().st_size for p in paths) / 1e6
    sw = Stopwatch()
    t0 = time.perf_counter()
    sim = simulate_on_rig(rig, order, basis=basis, camera_stride_px=stride, lobe_study=not args.quick, progress=sw)
    simulate_s = time.perf_counter() - t0
    rep, srep = basis.report, sim.report

    gram = {k: {"analytic_8bit_max_abs": v["analytic_8bit"]["max_abs"],
                "analytic_without_occluders_max_abs": v["analytic_without_occluders"]["max_abs"],
                "lowdin_8bit_max_abs": v["lowdin_8bit"]["max_abs"],
                "lowdin_deviation_max": v["lowdin_deviation_from_analytic"]["max"]}
            for k, v in rep["gram"].items() if k.startswith("order_")}
    errors = {}
    for rk, rv in srep["rigs"].items():
        errors[rk] = {"rig": rv["rig"], "geometry": rv.get("geometry"),
                      "gray_card_albedo_rel_error_gram": rv["gray_card_order_1"]["gram"]["albedo_max_rel_error"],
                      "models": {n: {o: {"lit_zone_none": v["coefficients_vs_lit_zone_rel_l2"]["none"],
                                         "zone_none": v["coefficients_vs_zone_rel_l2"]["none"],
                                         "zone_gram": v["coefficients_vs_zone_rel_l2"]["gram"],
                                         "slice_gram": v["gram"]["slice_rel_l2"],
                                         "cap_gram": v["gram"]["cap_rel_l2"]}
                                     for o, v in m.items()} for n, m in rv["models"].items()}}
    result = {
        "run": run,
        "profile": PROFILE, "order": order, "quick": args.quick,
        "target": "the whole simulation for order 6 on the default profile under a minute (issue 16)",
        "timings_s": {"load_and_design_s": load_s, "projector_basis_s": basis_s, "projector_basis_stages_s": basis_laps,
                      "write_basis_s": write_s, "simulate_s": simulate_s, "simulate_stages_s": dict(sw.laps),
                      "basis_plus_simulation_s": basis_s + simulate_s},
        "files": {"count": files, "megabytes": megabytes},
        "zone": rep["zone"], "solid_angle": rep["solid_angle"],
        "projector": {k: rep["projector"][k] for k in ("pixels_lit", "lit_fraction_of_zone", "pitch_deg")},
        "gram": gram,
        "camera_exitant_directions": srep["camera"]["exitant_directions"],
        "reference_error_estimate": srep["reference"],
        "errors_rel_l2": errors,
        "lobe_width_study": srep["lobe_width_study"]["rows"],
    }
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "basis.json", result))

    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.4))
    stages = {**{f"basis: {k}": v for k, v in basis_laps.items()}, "write files": write_s,
              **{f"simulate: {k}": v for k, v in sw.laps.items()}}
    a.barh(np.arange(len(stages)), list(stages.values()), color="tab:blue")
    a.set_yticks(np.arange(len(stages)))
    a.set_yticklabels(list(stages), fontsize=7)
    a.invert_yaxis()
    a.set_xlabel("seconds (one run; load average %.1f)" % run["loadavg_1min"])
    a.set_title(f"{PROFILE}, order {order}: basis {basis_s:.1f} s, files {write_s:.1f} s, "
                f"simulation {simulate_s:.1f} s", fontsize=9)
    a.grid(True, axis="x", alpha=0.3)
    names = list(srep["models"])
    for ri, (rk, rv) in enumerate(srep["rigs"].items()):
        y = [rv["models"][n][f"order_{order}"]["coefficients_vs_lit_zone_rel_l2"]["none"] for n in names]
        b.semilogy(np.arange(len(names)) + 0.15 * (ri - 1), y, "o", label=rv["rig"])
    b.axhline(0.01, color="0.4", ls="--", lw=0.8)
    b.set_xticks(np.arange(len(names)))
    b.set_xticklabels(names, fontsize=8, rotation=15)
    b.set_ylabel(f"relative L2 error, order {order} coefficients")
    b.set_title("against eq. 4.3 over the lit zone (no correction, 8 bit)", fontsize=9)
    b.legend(fontsize=7)
    b.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    print(write_bytes(args.out / "basis.png", png(fig)))
    print(f"basis {basis_s:.1f} s, files {write_s:.1f} s ({files} files, {megabytes:.1f} MB), "
          f"simulation {simulate_s:.1f} s")


if __name__ == "__main__":
    main()
