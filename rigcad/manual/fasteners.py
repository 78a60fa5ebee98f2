"""The fasteners the assembly steps fit (rigcad.manual.plan, rigcad.manual.tower_joints): ISO 4762
socket-head screws (head diameter 1.5 d, height d) with the hex tools that drive them (ISO 2936
screwdriver or L key) and the open-end spanner (DIN 3110) that holds a nut. Frame: mm, rig frame.
"""

from __future__ import annotations

import numpy as np

from rigcad.manual.assembly_check import Fastener, Tool
from rigcad.parts.tower import NUT_AF as _NUT_AF

DOWN, UP = (0.0, 0.0, -1.0), (0.0, 0.0, 1.0)
#: Hex key (mm across flats, ISO 4762 socket) per thread; 1/4-20 and 3/8-16 socket heads take 3/16 in and 5/16 in.
HEX_KEY = {"M2": 1.5, "M2.5": 2.0, "M3": 2.5, "M4": 3.0, "M5": 4.0, "M6": 5.0, "M8": 6.0, "M10": 8.0, "M12": 10.0,
           "1/4-20 UNC": 4.7625, "3/8-16 UNC": 7.9375}
#: Nut width across flats (mm, ISO 4032) per metric thread: the open-end spanner's size (the parts' table).
NUT_AF = _NUT_AF
#: The hex screwdriver's blade (mm): a hand needs this much straight room above a head.
DRIVER_BLADE_MM = 100.0
#: The open-end spanner's reach (mm, DIN 3110 for M3-M6 nuts: 90-120 mm long).
SPANNER_MM = 80.0
#: ISO 2936 hex keys: key (mm across flats) -> long arm, short arm (mm).
L_KEY = {1.5: (45.0, 14.0), 2.0: (50.0, 16.0), 2.5: (56.0, 18.0), 3.0: (63.0, 20.0), 4.0: (70.0, 25.0),
         4.7625: (80.0, 28.0), 5.0: (80.0, 28.0), 6.0: (90.0, 32.0), 7.9375: (100.0, 36.0), 8.0: (100.0, 36.0),
         10.0: (112.0, 40.0)}


def driver(thread: str, out_dir=(1.0, 0.0, 0.0), key: float | None = None) -> tuple[Tool, ...]:
    """A hex screwdriver with a DRIVER_BLADE_MM blade; else an L hex key (ISO 2936) with its short
    arm in the socket and its long arm out along ``out_dir`` (away from the rig's axis). ``key``:
    the socket's size (mm) when it is not the cap screw's (HEX_KEY), as in a countersunk head."""
    key = HEX_KEY[thread] if key is None else key
    r = key / np.sqrt(3.0) + 0.5  # the key's corners, and a little play for the hand
    long, short = L_KEY[key]
    return (Tool(f"{key:g} mm hex screwdriver (ISO 2936 hex), {DRIVER_BLADE_MM:g} mm blade", DRIVER_BLADE_MM, r),
            Tool(f"{key:g} mm L hex key (ISO 2936, {long:g} x {short:g} mm), short arm in", short, r, long,
                 tuple(float(v) for v in out_dir)))


def spanner(thread: str, nut_height: float) -> Tool:
    # its jaws are about as thick as the nut is high: a cylinder of that diameter along its way out
    return Tool(f"{NUT_AF[thread]:g} mm open-end spanner (DIN 3110)", SPANNER_MM, nut_height / 2 + 0.5)


def metric(thread: str):
    """The thread's row of rigcad.manual.bom.METRIC (thread, clearance hole, pitch, nut height, washer)."""
    from rigcad.manual.bom import METRIC

    return next(r for r in METRIC if r[0] == thread)


def socket_head(item: str, head, axis, length: float, d: float, thread: str, **kw) -> Fastener:
    """An ISO 4762 socket-head screw of diameter ``d`` (mm), head's bearing face at ``head``, with its
    hex tools (the L key's long arm out, away from the rig's axis)."""
    h = np.array([head[0], head[1], 0.0])
    out = tuple(h / np.linalg.norm(h)) if np.linalg.norm(h) > 1e-9 else (1.0, 0.0, 0.0)
    if abs(np.dot(out, axis)) > 0.9:
        out = (0.0, 0.0, -1.0)
    return Fastener(item, tuple(float(v) for v in head), axis, float(length), d / 2, 0.75 * d, d,
                    driver(thread, out), **kw)


__all__ = ["DOWN", "DRIVER_BLADE_MM", "HEX_KEY", "L_KEY", "NUT_AF", "SPANNER_MM", "UP", "driver", "metric", "socket_head",
           "spanner"]
