"""``rigcad check PROFILE``: the 3D ray check from the command line (wired by rigcad.cli)."""

from __future__ import annotations

import argparse
import sys
from contextlib import contextmanager
from pathlib import Path

from rigcad.units import DEG


@contextmanager
def _rays_bar(desc: str):
    """A progress bar of rays traced (count and rays/s; the stage as its postfix) on stderr when it
    is a terminal (tqdm). Yields (add(n), stage(label))."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="ray", unit_scale=True, disable=None, leave=False, file=sys.stderr,
               mininterval=0.25, maxinterval=1.0)
    try:
        yield bar.update, bar.set_postfix_str
    finally:
        bar.close()


def cmd_check(args: argparse.Namespace) -> int:
    from rigcad.check.raycheck import run_raycheck, write_raycheck
    from rigcad.check.tolerances import raise_if_failed, table
    from rigcad.export.atomic import profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.rig import load

    rig = load(args.profile)
    profile = rig.profile
    from rigcad.check.trace3d import counting

    exports = Path(args.exports)
    mirrors = exports / profile.name / "mirrors"
    missing = [n for n in ("paraboloid", "dome") if not (mirrors / f"{n}.ply").is_file()]
    if missing and (args.mode or profile.raycheck.mode) != "analytic":
        print(f"note: no exported {' and '.join(missing)} mesh in {mirrors}/ (run `rigcad stl {args.profile}`): "
              "meshing the mirrors from the profile", file=sys.stderr)
    with _rays_bar(f"check {profile.name}") as (bar, stage):
        def step(label: str) -> None:
            stage(label)
            if args.verbose:
                print(f"  {label} ...", file=sys.stderr)

        with counting(bar):
            result = run_raycheck(rig, exports=exports, rays=args.rays, mode=args.mode,
                                  monte_carlo=not args.no_monte_carlo, builds=args.builds, progress=step)
    paths = write_raycheck(result, exports / profile.name / "check", profile_lock(exports, profile.name),
                           made_from=profile_digest(profile))
    rep = result.report
    main = rep["readings"][rep["mode"]]
    print(f"{profile.name}: mode {rep['mode']}, {rep['rays']} rays, backend {rep['backend']}")
    print(f"  spot radius max {main['max_spot_radius_mm']:.3g} mm (rms {main['rms_spot_radius_mm']:.3g}), "
          f"angle error max {main['max_angle_error_rad'] / DEG:.3g} deg, theta {main['theta_min_deg']:.2f}.."
          f"{main['theta_max_deg']:.2f} deg, lost {main['lost_fraction']:.2%}")
    meshed = sorted(n for n, src in (rep["meshes"] or {}).get("sources", {}).items() if not src.startswith(str(exports)))
    if meshed and not missing:
        print(f"  note: meshed from the profile, not the exports: {', '.join(meshed)}", file=sys.stderr)
    print(table(result.rows))
    for p in paths:
        print(f"  wrote {p}")
    raise_if_failed(result.rows, profile.name)
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``check`` to rigcad's subcommands."""
    p = subparsers.add_parser(
        "check", help="3D ray check: trace the mirror meshes, compare with the exact surfaces and the targets",
        description="Trace rays from the COP through the mirror meshes (Embree; exported PLYs when present, "
                    "else meshed from the profile), the exact surfaces and the occluders; write "
                    "exports/<profile>/check/{raycheck.json, spot.png, theta_map.png}; exit 1 with a table when "
                    "a tolerance declared in the profile (raycheck.*, tolerancing.*) is not met.")
    p.add_argument("profile", help="profile name (under profiles/) or path")
    p.add_argument("--exports", default="exports", help="exports root (default: exports)")
    p.add_argument("--rays", type=int, help="pinhole rays (default: raycheck.rays)")
    p.add_argument("--mode", choices=("mesh", "smooth", "analytic"), help="reading checked (default: raycheck.mode)")
    p.add_argument("--builds", type=int, help="Monte Carlo builds (default: tolerancing.builds)")
    p.add_argument("--no-monte-carlo", action="store_true", help="skip the Monte Carlo tolerance analysis")
    p.add_argument("-v", "--verbose", action="store_true", help="print stages on stderr")
    p.set_defaults(func=cmd_check)
    return p
