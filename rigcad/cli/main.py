"""rigcad's command line: thin. Parses arguments, calls the stages, prints. A RigcadError becomes
one readable line on stderr and a non-zero exit code; a traceback is a bug.

Each command is a module of this package with ``register(subparsers)`` (its arguments, its
``func``); :data:`COMMANDS` lists them in the order ``rigcad --help`` shows them. A command module
imports only light things at its top (argparse, units, the argument types): building the parser,
which every command and ``--help`` do first, loads no numpy, integrator, CAD kernel or plotting
library; each ``cmd_*`` imports what it uses when it runs."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from rigcad._version import __version__
from rigcad.cli import (basis, build, calibrate, check, design, fab, manual, optimize, profile, stl, sweep, tolerance,
                        view, watch)
from rigcad.errors import RigcadError, one_line

#: numpy's switch for asking Linux to back its large arrays with transparent huge pages (numpy's
#: default: on). Where the kernel's THP ``defrag`` setting is ``madvise`` (its default since Linux
#: 4.6), a fault in memory so marked can stall on compaction instead of taking small pages (numpy
#: gh-31590), and the marks stay on the heap after the array is freed. rigcad allocates and frees
#: many large temporaries: a fifth to a third of ``rigcad calibrate --simulate``'s CPU time was the
#: kernel's (bench/hugepages.py).
NUMPY_HUGEPAGE_VARIABLE = "NUMPY_MADVISE_HUGEPAGE"

#: The commands, in the order of ``rigcad --help``: each a module with ``register(subparsers)``.
COMMANDS = (profile, design, build, stl, check, fab, basis, calibrate, optimize, view, watch, manual, tolerance, sweep)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rigcad",
        description="CAD and fabrication toolchain for the image-based BRDF acquisition rig "
                    "(Achutha 2006): YAML profile -> optical design -> parts -> exports.",
        epilog="Profiles are looked up by name under profiles/ or given as a path. Lengths and angles "
               "in profiles carry units: '13.5 cm', '11 in', '5.5 mil', '20 deg'.")
    parser.add_argument("--version", action="version", version=f"rigcad {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in COMMANDS:
        command.register(sub)
    return parser


def _error_line(message: object) -> str:
    """``rigcad: error: <message>`` on one line: a newline or other control character that a name,
    a path or a value brought into the message is shown escaped (``\\n``), never printed."""
    return f"rigcad: error: {one_line(message)}"


def process_defaults() -> None:
    """rigcad's defaults for this process and the workers it starts, set before numpy is imported
    (numpy reads :data:`NUMPY_HUGEPAGE_VARIABLE` once, at import): huge-page advice off. A value the
    user set wins. (The Makefile sets the same for the tests, benchmarks and docs.)"""
    os.environ.setdefault(NUMPY_HUGEPAGE_VARIABLE, "0")


def main(argv: list[str] | None = None) -> int:
    process_defaults()  # before anything imports numpy
    args = build_parser().parse_args(argv)  # --help and a bad argument end here: no engine, no numpy
    from rigcad.engine import run_temp_dir

    try:
        with run_temp_dir():
            return args.func(args)
    except RigcadError as err:
        print(_error_line(err), file=sys.stderr)
        return err.exit_code
    except BrokenPipeError:  # output piped into head & co.
        return 0
    except OSError as err:  # an I/O failure outside the writers' own guards: still one line
        from rigcad.export.atomic import write_error

        failure = write_error(Path(err.filename or "."), err)
        print(_error_line(failure), file=sys.stderr)
        return failure.exit_code
    except KeyboardInterrupt:
        print("rigcad: interrupted", file=sys.stderr)
        return 130
    except MemoryError as err:  # an allocation the estimates before it did not foresee
        print(_error_line(f"out of memory{': ' + str(err) if str(err) else ''}; ask for fewer rays, builds or "
                          "samples, or run on a machine with more memory"), file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
