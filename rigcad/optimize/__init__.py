"""Inverse design (``rigcad optimize``): the profile's ``optimize:`` section (spec), one design
evaluated in milliseconds (fast, printfit, problem), the seeded search on rigcad.engine (search)
and its outputs (run); the command is rigcad.cli.optimize. See docs/optimize.md."""
