"""The Monte Carlo of perturbed rigs at scale: ``rigcad tolerance``'s view of the one Monte Carlo,
rigcad.check.montecarlo (sample i's build from SeedSequence child i of ``tolerancing.seed``, the
same pinhole rays for every sample, on rigcad.engine: bit-identical for any worker count, batching
or engine; the ray check runs the same on a small sample). Here: what only the tolerance report
adds, the rank correlations of the parameters with the figures.
"""

from __future__ import annotations

import numpy as np


def rank_correlations(columns: dict) -> dict:
    """Spearman rank correlation of each parameter's magnitude in the samples (lateral offset
    |(dx, dy)|, |dz|, tilt) with the sample's spot and mirror angle error. Tied values share their
    mean rank: a parameter toleranced at 0 (every sample's magnitude 0) correlates with nothing."""
    from scipy.stats import rankdata

    from rigcad.tolerance.params import PARAMETERS

    def ranks(v):
        return rankdata(v, method="average")

    out = {}
    figs = {k: ranks(columns[k]) for k in ("max_spot_radius_mm", "max_mirror_angle_error_rad")}
    for p in PARAMETERS:
        c = p.component
        mag = {"offset": np.hypot(columns[f"{c}_dx_mm"], columns[f"{c}_dy_mm"]),
               "height": np.abs(columns[f"{c}_dz_mm"]), "tilt": columns[f"{c}_tilt_rad"]}[p.kind]
        r = ranks(mag)
        out[p.name] = {}
        for k, fr in figs.items():
            if np.ptp(r) == 0 or np.ptp(fr) == 0:
                out[p.name][k] = 0.0
            else:
                out[p.name][k] = float(np.corrcoef(r, fr)[0, 1])
    return out
