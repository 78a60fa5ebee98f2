"""rigcad's version: a leaf module that imports nothing, so any module can read it without importing
the package's public names first (``from rigcad._version import __version__``)."""

__version__ = "0.1.0"
