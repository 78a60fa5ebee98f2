"""Where the time of the mesh reading goes (issue 12): the compiled passes (rigcad.check.meshtrace)
against the numpy passes they replaced (trace3d._trace, ``vectorised=True``), on the same rays
and Embree scenes, each stage timed with perf_counter: Embree's own calls (EmbreeMesh.raw), each
compiled pass, and for the numpy path its float64 refinement (_kernels.refine_mesh_hits) and the
rest of its glue. Prints one line per reading (the median over REPEATS traces, seconds); writes
nothing. Timings vary run to run (a shared machine); never asserted.

Run from the repository root: ``.venv/bin/python bench/meshglue.py [--rays N] [--exports DIR]``
(the exports of ``rigcad stl <profile> --exports DIR``; without them the meshes are built from
the profile at its tessellation tolerances).
"""

from __future__ import annotations

import argparse
import os
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from rigcad.check import _kernels, _mesh_kernels, rays
from rigcad.check.scene import mesh_optics, mirror_meshes, share_scenes
from rigcad.check.sources import annulus_rays
from rigcad.check.trace3d import trace
from rigcad.profile import load_profile
from rigcad.rig import Rig

REPEATS = 3


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--exports", default="exports")
    args = ap.parse_args()
    rig = Rig.from_profile(load_profile(args.profile))
    base = mesh_optics(mirror_meshes(rig, Path(args.exports)), "smooth")
    src = annulus_rays(rig.incidence, args.rays, 1)
    spent = defaultdict(float)

    def timed(name, fn):
        def wrapper(*a, **k):
            t0 = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                spent[name] += time.perf_counter() - t0
        return wrapper

    # stage timers around the functions both paths call (restored below)
    saved = {}
    for mod, name, label in ((rays.EmbreeMesh, "raw", "embree"), (_kernels, "refine_mesh_hits", "refine"),
                             *((_mesh_kernels, k, k) for k in ("source_casts", "after_paraboloid", "after_dome",
                                                                "after_return"))):
        saved[(mod, name)] = getattr(mod, name)
        setattr(mod, name, timed(label, getattr(mod, name)))
    try:
        print(f"{args.rays} rays, profile {args.profile}, load {os.getloadavg()[0]:.1f}; seconds, median of {REPEATS}")
        for mode in ("smooth", "mesh"):
            optics = share_scenes(base, mode)
            for vectorised in (False, True):
                trace(optics, src.origins[:1000], src.dirs[:1000], vectorised=vectorised)  # compile / warm up
                runs = []
                for _ in range(REPEATS):
                    spent.clear()
                    t0 = time.perf_counter()
                    tr = trace(optics, src.origins, src.dirs, vectorised=vectorised)
                    total = time.perf_counter() - t0
                    runs.append(dict(spent, total=total, glue=total - spent["embree"]))
                keys = sorted({k for r in runs for k in r}, key=lambda k: (k in ("total", "glue"), k))
                med = {k: float(np.median([r.get(k, 0.0) for r in runs])) for k in keys}
                print(f"{mode:6s} {next(iter(tr.kernels)):13s} " + ", ".join(f"{k} {v:.3f}" for k, v in med.items())
                      + f"; embree / total {med['embree'] / med['total']:.2f}")
    finally:
        for (mod, name), fn in saved.items():
            setattr(mod, name, fn)


if __name__ == "__main__":
    main()
