"""Progress on stderr for the commands: a bar of named stages and a counting bar (tqdm, silent when
stderr is not a terminal). A ground-floor leaf: every command's module imports it, it imports no
other part of rigcad."""

from __future__ import annotations

import sys
from contextlib import contextmanager

#: Set (to anything) to have every progress step also printed as a line ``rigcad-event: <label>``
#: on stderr: a machine-readable trace of where a run is (the fault tests kill runs at these).
EVENTS_ENV = "RIGCAD_EVENTS"


@contextmanager
def stages(total: int, desc: str):
    """A progress bar of ``total`` stages on stderr when it is a terminal (tqdm); silent otherwise.
    Yields ``step(label)``, called once a stage is done."""
    import os

    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="stage", disable=None, leave=False, file=sys.stderr)
    events = bool(os.environ.get(EVENTS_ENV))

    def step(label: str) -> None:
        bar.set_postfix_str(label)
        bar.update(1)
        if events:
            print(f"rigcad-event: {label}", file=sys.stderr, flush=True)

    try:
        yield step
    finally:
        bar.close()


@contextmanager
def progress_bar(total: int, desc: str, unit: str):
    """A counting progress bar on stderr (tqdm: count, rate in ``unit``/s, ETA), refreshed at
    least once a second while it advances; silent when stderr is not a terminal. Yields
    ``update(done)`` taking the absolute count (engine callbacks pass totals, not increments)."""
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit=unit, disable=None, leave=False, file=sys.stderr,
               mininterval=0.25, maxinterval=1.0, smoothing=0.1)

    def update(done: int) -> None:
        bar.update(done - bar.n)

    try:
        yield update
    finally:
        bar.close()
