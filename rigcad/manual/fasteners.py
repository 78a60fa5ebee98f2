"""The fasteners the assembly steps fit (rigcad.manual.plan, rigcad.manual.tower_joints): ISO 4762
socket-head screws (head diameter 1.5 d, height d) with the hex tools that drive them (ISO 2936
screwdriver or L key) and the open-end spanner (DIN 3110) that holds a nut. Frame: mm, rig frame.
"""

from __future__ import annotations

import numpy as np

from rigcad.manual.assembly_check import Fastener, Tool
from rigcad.standards import DRIVER_BLADE_MM, HEX_KEYS, SPANNER_MM, THREADS

DOWN, UP = (0.0, 0.0, -1.0), (0.0, 0.0, 1.0)


def driver(thread: str, out_dir=(1.0, 0.0, 0.0), key: float | None = None) -> tuple[Tool, ...]:
    """A hex screwdriver with a DRIVER_BLADE_MM blade; else an L hex key (ISO 2936) with its short
    arm in the socket and its long arm out along ``out_dir`` (away from the rig's axis). ``key``:
    the socket's size (mm) when it is not the cap screw's (HEX_KEY), as in a countersunk head."""
    key = THREADS[thread].hex_key if key is None else key
    r = HEX_KEYS[key].room  # the key's corners, and a little play for the hand
    long, short = HEX_KEYS[key].long_arm, HEX_KEYS[key].short_arm
    return (Tool(f"{key:g} mm hex screwdriver (ISO 2936 hex), {DRIVER_BLADE_MM:g} mm blade", DRIVER_BLADE_MM, r),
            Tool(f"{key:g} mm L hex key (ISO 2936, {long:g} x {short:g} mm), short arm in", short, r, long,
                 tuple(float(v) for v in out_dir)))


def spanner(thread: str, nut_height: float) -> Tool:
    # its jaws are about as thick as the nut is high: a cylinder of that diameter along its way out
    return Tool(f"{THREADS[thread].nut_af:g} mm open-end spanner (DIN 3110)", SPANNER_MM, nut_height / 2 + 0.5)


def socket_head(item: str, head, axis, length: float, thread: str, **kw) -> Fastener:
    """An ISO 4762 socket-head screw of ``thread`` (its head's size from rigcad.standards), head's
    bearing face at ``head``, with its hex tools (the L key's long arm out, away from the rig's axis)."""
    h = np.array([head[0], head[1], 0.0])
    out = tuple(h / np.linalg.norm(h)) if np.linalg.norm(h) > 1e-9 else (1.0, 0.0, 0.0)
    if abs(np.dot(out, axis)) > 0.9:
        out = (0.0, 0.0, -1.0)
    th = THREADS[thread]
    return Fastener(item, tuple(float(v) for v in head), axis, float(length), th.major / 2, th.head_diameter / 2,
                    th.head_height, driver(thread, out), **kw)


__all__ = ["DOWN", "UP", "driver", "socket_head", "spanner"]
