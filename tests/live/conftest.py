"""What the live-view tests share: the headless chromium they drive (Debian's, through playwright)
and a loopback port with nothing listening on it."""

from __future__ import annotations

import socket
import sys
from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader", "--disable-background-networking", "--disable-component-update",
                 "--disable-default-apps", "--disable-sync", "--no-first-run"]


def closed_port() -> int:
    """A loopback port nothing listens on now (bound, read, released)."""
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def interruptible(module: str, *args: str) -> list[str]:
    """The argv that runs ``module`` as ``python -m`` does, with Ctrl-C (SIGINT) raising
    KeyboardInterrupt as in a terminal. A child inherits an ignored SIGINT (a background or nohup
    `make test` ignores it) and Python then leaves it ignored, so the SIGINT a test sends to stop a
    serving command would never reach it."""
    code = ("import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
            f"runpy.run_module({module!r}, run_name='__main__', alter_sys=True)")
    return [sys.executable, "-c", code, *args]
