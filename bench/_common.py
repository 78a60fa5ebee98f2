"""Helpers shared by the bench scripts added for issue 7 (tessellation, ray_count, float32, make_stl):
where results go, what the machine was doing, figures as deterministic PNG bytes.

Conventions of every bench JSON: units in the keys; everything is deterministic except timings
(keys ending in ``_s``, and everything under such a key) and the ``run`` section (load average,
CPU count: what the machine was doing while the timings were taken).
"""

from __future__ import annotations

import argparse
import io
import math
import os
import platform
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"


def reaped(cmd: list[str], cwd: Path = ROOT, env: dict | None = None) -> dict:
    """Run ``cmd`` as a child and reap it with os.wait4, which gives that child's own resource usage:
    wall time (s), user and system CPU time (s), peak RSS (``ru_maxrss``, KiB on Linux), the exit code
    and its output (stdout and stderr, through a temporary file)."""
    with tempfile.TemporaryFile() as log:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=log, stderr=subprocess.STDOUT)
        _, status, ru = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
        log.seek(0)
        text = log.read().decode(errors="replace")
    return {"wall_s": wall, "user_s": ru.ru_utime, "system_s": ru.ru_stime, "peak_rss_kb": ru.ru_maxrss,
            "exit_code": proc.returncode, "output": text}


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo's first ``model name``; platform.processor() elsewhere):
    a ratio of two codes' times depends on it (Embree and the compiled kernels do not gain alike
    from one CPU to another), and a virtual machine may be moved to another host's CPU."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def run_info() -> dict:
    """The machine and its load when called (os.getloadavg: 1, 5, 15 minute run-queue averages)."""
    one, five, fifteen = os.getloadavg()
    return {"cpus": os.cpu_count(), "cpu_model": cpu_model(), "machine": platform.machine(),
            "python": platform.python_version(),
            "loadavg_1min": round(one, 2), "loadavg_5min": round(five, 2), "loadavg_15min": round(fifteen, 2),
            "note": "timings (keys ending in _s) were taken with this much other load on the machine"}


def arguments(doc: str) -> argparse.ArgumentParser:
    """The options every new bench script takes: ``--out`` (results folder) and ``--quick`` (a
    seconds-long run for the smoke test; its numbers are not the benchmark)."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=RESULTS, help="results folder (default: bench/results)")
    ap.add_argument("--quick", action="store_true", help="tiny run for the smoke test (numbers not meaningful)")
    return ap


def png(fig) -> bytes:
    """The figure as PNG bytes without the Software/date metadata (same bytes for the same plot)."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def timed(fn, repeats: int = 1):
    """(min seconds, median seconds, result of the last call) of ``repeats`` calls of ``fn``."""
    times, out = [], None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[0], times[len(times) // 2], out


def loglog_slope(x, y) -> float | None:
    """Least-squares slope of log y against log x over the finite, positive points (None if < 2)."""
    pts = [(math.log(a), math.log(b)) for a, b in zip(x, y) if a and b and a > 0 and b > 0
           and math.isfinite(a) and math.isfinite(b)]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx else None
