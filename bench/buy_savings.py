"""Print hours saved by buying the tower's structural parts (the profile's ``buy``): the fab
stage's estimate model (rigcad.fab.estimate, fitted to PrusaSlicer) run on the printed column and
shelf, against the same rig with an extrusion and an aluminium plate (not printed: no pieces).
Writes bench/results/buy_savings.json (deterministic but for the ``run`` section).

    .venv/bin/python bench/buy_savings.py [--printer prusa_mk3s] [--profile achutha2006]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import arguments, run_info  # noqa: E402

from rigcad.export.atomic import write_json  # noqa: E402
from rigcad.fab.printers import load_printer  # noqa: E402
from rigcad.fab.stage import run_fab  # noqa: E402
from rigcad.profile.loader import load_raw  # noqa: E402
from rigcad.profile.schema import validate  # noqa: E402
from rigcad.rig import Rig  # noqa: E402

PARTS = ["tower_column", "tower_shelf"]


def _rig(profile: str, buy: dict | None) -> Rig:
    raw = load_raw(profile)
    if buy:
        raw.data["buy"] = dict(buy)  # the same profile with its buy section replaced
    return Rig.from_profile(validate(raw))


def _hours(rig: Rig, printer) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        report = run_fab(rig, printer, Path(tmp), parts=PARTS).report
    out = {}
    for name in PARTS:
        e = report["parts"][name]
        if e.get("process") == "bought":
            out[name] = {"bought": e["stock"], "print_time_h": 0.0}
            continue
        pcs = e["pieces"]
        out[name] = {"print_time_h": sum(pc["estimate"]["print_time_s"] for pc in pcs) / 3600.0,
                     "material_g": sum(pc["estimate"]["material_g"] for pc in pcs),
                     "pieces": len(pcs)}
    return out


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--printer", default="prusa_mk3s")
    ap.add_argument("--profile", default="achutha2006")
    args = ap.parse_args()
    printer = load_printer(args.printer)
    printed = _hours(_rig(args.profile, {"column": "print", "shelf": "print"}), printer)
    bought = _hours(_rig(args.profile, {"column": "extrusion_40x40", "shelf": "aluminium_plate"}), printer)
    saved = {n: printed[n]["print_time_h"] - bought[n]["print_time_h"] for n in PARTS}
    result = {"profile": args.profile, "printer": args.printer,
              "method": "rigcad.fab.estimate (the fab stage's model fitted to PrusaSlicer); no slicer run",
              "printed": printed, "bought": bought, "print_hours_saved_h": saved,
              "print_hours_saved_total_h": sum(saved.values()), "run": run_info()}
    path = write_json(args.out / "buy_savings.json", result)
    print(f"{path}: {result['print_hours_saved_total_h']:.1f} h saved "
          + ", ".join(f"{n} {h:.1f} h" for n, h in saved.items()))


if __name__ == "__main__":
    main()
