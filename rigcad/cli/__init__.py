"""rigcad's command line, the top floor: :mod:`rigcad.cli.main` (the parser, ``main``, the one-line
error) and one module per command, each with ``register(subparsers)``. Nothing below imports it."""

from rigcad.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
