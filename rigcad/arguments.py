"""argparse types shared by the commands' parsers: each refuses a bad value on one line, before
any work. A ground-floor leaf: it imports no other part of rigcad."""

from __future__ import annotations

import argparse
import math


def positive_int(text: str) -> int:
    """An argparse type: a whole number >= 1, written plainly or as ``1e6``; anything else is
    refused by argparse on one line, before any work."""
    try:
        value = int(text)
    except ValueError:
        try:
            f = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
        if not (math.isfinite(f) and f == int(f)):
            raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
        value = int(f)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return value


def worker_count(text: str) -> int:
    """An argparse type: a worker count, 0 for every core, else >= 1 (clamped to the cores by
    rigcad.engine.Engine unless a remote Dask scheduler runs the tasks)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0 (0: every core), got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0 (0: every core), got {text!r}")
    return value


def port_number(text: str) -> int:
    """An argparse type: a TCP port, 1..65535, or 0 for any free port."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port 0..65535 (0: any free port), got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port 0..65535 (0: any free port), got {text!r}")
    return value


def host_address(text: str) -> str:
    """An argparse type: the address a server listens on, a host name or an IP address; not empty
    (an empty one would listen on every interface) and of printable ASCII (a name the resolver can
    take)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("expected an address such as 127.0.0.1 or localhost, got an empty one (an "
                                         "empty address would serve every network interface; say 0.0.0.0 to mean it)")
    if not (text.isascii() and text.isprintable()) or any(c.isspace() for c in text):
        raise argparse.ArgumentTypeError(f"expected an address such as 127.0.0.1 or localhost, got {ascii(text)[:80]}")
    return text


def exports_root(text: str) -> str:
    """An argparse type: an output root, not empty (an empty one would write into the current folder)
    and without control or formatting characters (a newline or a right-to-left override in a folder
    name breaks every line that names it)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("expected a folder, got an empty path (the default is 'exports')")
    if not text.isprintable():
        raise argparse.ArgumentTypeError(f"expected a folder name of printable characters, got {ascii(text)[:80]}")
    return text


#: What every command that reads a profile says of its first argument.
PROFILE_HELP = "profile name (under profiles/) or path"


def profile_command(subparsers, name: str, func, *, profile_help: str = PROFILE_HELP, exports: bool = True,
                    **parser_options) -> argparse.ArgumentParser:
    """A command ``name`` that reads a profile (its first argument) and writes under ``--exports``
    (an :func:`exports_root`, default ``exports``; ``exports=False`` for one that writes nothing),
    run by ``func(args)``. ``parser_options``: ``help``, ``description``, ``epilog`` of its parser."""
    p = subparsers.add_parser(name, **parser_options)
    p.add_argument("profile", help=profile_help)
    if exports:
        p.add_argument("--exports", default="exports", type=exports_root, help="output root (default: exports)")
    p.set_defaults(func=func)
    return p
