"""A fab run's published result, read back without doing the work again and without the fab
stage's heavy imports (meshing, slicing, figures): the run's key and the reading back, for
rigcad.fab.stage (which publishes) and for a command that asks before it builds a rig
(rigcad.api.fab_published). The key: rigcad.export.reuse.stage_key with the printer's resolved
settings and the run's options; the record and its checks: rigcad.export.reuse.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from rigcad.export import reuse
from rigcad.errors import ExportError
from rigcad.export.manifest import profile_digest
from rigcad.export.readback import parse_json
from rigcad.fab.printers import Printer


@dataclass
class FabResult:
    report: dict
    written: list[Path]
    timings_s: dict[str, float] = field(default_factory=dict)
    slicer_s: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    #: True when the result was read back from an earlier run's published folder (nothing recomputed).
    reused: bool = False


def inputs_key(profile, printer: Printer, gcode: bool, parts: list[str] | None) -> str:
    """The key of a fab run's result for the rig of ``profile`` as designed (rigcad.export.reuse.
    stage_key): the resolved profile and rigcad's code, the printer's resolved settings (its file,
    what it inherits, its slicer presets and overrides), the parts, and with ``gcode`` the slicer
    program found (path, size, time: a new PrusaSlicer slices anew). ``parts``: the names asked
    for (None or empty: all; the code hashed in the key fixes what all are)."""
    inputs = {"printer": printer.describe(), "slicer_unavailable": printer.slicer_unavailable,
              "slicer_settings": printer.slicer_config.effective() if printer.slicer_config else None,
              "gcode": bool(gcode), "parts": sorted(set(parts)) if parts else "all"}
    if gcode and printer.slicer == "prusa-slicer":
        from rigcad.fab import slicer

        exe = slicer.find_slicer()
        st = os.stat(exe) if exe else None
        inputs["slicer_program"] = [exe, st.st_size, st.st_mtime_ns] if st else None
    return reuse.stage_key(profile, "fab", inputs)


def read_back(profile, printer: Printer, out: Path, *, gcode: bool = False, parts: list[str] | None = None,
              progress=None, lock: Path | None = None) -> FabResult | None:
    """The fab run of the rig of ``profile`` as designed published in ``out`` from the same inputs
    (:func:`inputs_key`) and intact (rigcad.export.reuse.read_back), read back with nothing
    recomputed and no rig built: its report, ``reused`` set; ``progress`` called once per part as a
    run would. None when there is none: run the stage (:func:`run_fab`)."""
    t0 = time.perf_counter()
    out = Path(out)
    key = inputs_key(profile, printer, gcode, parts)
    lock = lock if lock is not None else out.parent / f".{out.name}.lock"  # Staging's own default
    back = reuse.read_back(out, key, profile_digest(profile), lock, read=("fab.json",))
    if back is None:
        return None
    try:
        report = parse_json(back["fab.json"], str(out / "fab.json"))
    except ExportError:  # not a report rigcad could have written: run the stage
        return None
    if not isinstance(report, dict) or not isinstance(report.get("parts"), dict):
        return None
    for name in report["parts"]:
        (progress or (lambda msg: None))(name)
    return FabResult(report, [], {"read_back": time.perf_counter() - t0}, reused=True)
