"""Tolerancing at scale: the seeded Monte Carlo of perturbed rigs on rigcad.engine
(joblib loky by default, Dask with a scheduler), the sensitivity ranking, inverse limits by
bisection on the analytic tracer, and parameter sweeps of whole designs.

Modules: ``params`` (the toleranced parameters: which component, which degree of freedom, unit,
profile key), ``montecarlo`` (the rank correlations of the
parameters with the figures; the Monte Carlo itself is rigcad.check.montecarlo, shared with the
ray check), ``limits`` (one-at-a-time sensitivity and inverse limits), ``sweep``
(designs over a parameter range), ``report`` (Parquet, CSV, JSON, tolerance.md and the figures
from rigcad.plots); the commands ``rigcad tolerance`` and ``rigcad sweep`` are rigcad.cli.tolerance
and rigcad.cli.sweep.

Frame and units as everywhere: mm, radians, O at the origin, +z up; every written number names its
unit in its key or column header.
"""
