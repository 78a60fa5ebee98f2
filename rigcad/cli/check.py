"""``rigcad check PROFILE``: the 3D ray check from the command line."""

from __future__ import annotations

import argparse
import json
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


#: Peak memory of a check per pinhole ray (bytes): at most 1.5 kB measured (peak RSS 0.40 GB at
#: 20,000 rays, 1.91 GB at 1,000,000, 4.03 GB at 3,000,000, smooth mode: /usr/bin/time -f %M
#: rigcad check achutha2006 --rays N --no-monte-carlo), with a third more for the other modes.
CHECK_BYTES_PER_RAY = 2000
#: Memory of a check before its rays (bytes): the interpreter, the kernels, the mirror meshes (0.40 GB
#: measured at 20,000 rays).
CHECK_FIXED_BYTES = 600e6
#: Per Monte Carlo build kept for the report (bytes): four figures as Python floats, their arrays
#: and JSON text (~300 bytes), doubled.
CHECK_BYTES_PER_BUILD = 600


def checked_counts(profile, rays: int | None, builds: int | None) -> None:
    """Refuse, before any work, ``--rays``/``--builds`` outside their profile keys' ranges
    (raycheck.rays, tolerancing.builds) or beyond this machine's memory."""
    from rigcad.engine import ResourceError, require_memory
    from rigcad.profile.schema import bound, check_override

    n_rays = profile.raycheck.rays if rays is None else rays
    try:  # memory first: its message names the largest count this machine can take
        require_memory("--rays" if rays is not None else "raycheck.rays", n_rays, CHECK_BYTES_PER_RAY,
                       CHECK_FIXED_BYTES, "tracing the check's rays", most=bound("raycheck", "rays"))
        if builds is not None:
            per_build = max(n_rays, profile.tolerancing.rays) * CHECK_BYTES_PER_RAY + CHECK_FIXED_BYTES
            require_memory("--builds", builds, CHECK_BYTES_PER_BUILD, per_build, "keeping every build's figures",
                           most=bound("tolerancing", "builds"))
    except ResourceError as err:
        raise err.located(profile.marks) from None
    if rays is not None:
        check_override("raycheck", "rays", rays, "--rays")
    if builds is not None:
        check_override("tolerancing", "builds", builds, "--builds")


def check_key(profile, args: argparse.Namespace, exports: Path) -> str:
    """The key of a check's result (rigcad.export.reuse.stage_key): the resolved profile and
    rigcad's code, the command's options, and the SHA-256 of each exported file the check traces
    (the mirrors' PLYs, the paraboloid's and the beam's STLs as occluders; None when absent)."""
    from rigcad.export import reuse

    root = Path(exports) / profile.name
    reads = {f"mirrors/{n}.ply": root / "mirrors" / f"{n}.ply" for n in ("paraboloid", "dome")}
    reads.update({f"stl/{n}.stl": root / "stl" / f"{n}.stl" for n in ("paraboloid", "beam")})
    return reuse.stage_key(profile, "check", {"rays": args.rays, "mode": args.mode, "builds": args.builds,
                                              "monte_carlo": not args.no_monte_carlo,
                                              "reads": reuse.input_files(reads)})


def _read_back(profile, args: argparse.Namespace, exports: Path, key: str):
    """The check published in ``exports/<profile>/check`` from the same inputs (:func:`check_key`)
    and intact: its report and rows, with nothing traced; None otherwise."""
    from rigcad import api
    from rigcad.check.tolerances import Row
    from rigcad.errors import ExportError
    from rigcad.export import reuse
    from rigcad.export.manifest import profile_digest
    from rigcad.export.readback import parse_json

    out = api.default_folder(profile.name, "check", root=exports)
    back = reuse.read_back(out, key, profile_digest(profile), api.writer_lock(out, profile.name, ("check",)),
                           read=("raycheck.json", reuse.RECORD))
    if back is None:
        return None
    try:
        rep = parse_json(back["raycheck.json"], str(out / "raycheck.json"))
        rows = [Row(c["check"], c["profile_key"], c["measured"], c["limit"], c["relation"], c["unit"], c["where"],
                    c.get("hint", "")) for c in rep["checks"]]
        rep["readings"][rep["mode"]]["max_spot_radius_mm"]
    except (ExportError, KeyError, TypeError, IndexError):  # not a report rigcad could have written: check again
        return None
    return rep, rows, [out / rel for rel in sorted(json.loads(back[reuse.RECORD])["files"])]


def cmd_check(args: argparse.Namespace) -> int:
    from rigcad import api
    from rigcad.check.tolerances import raise_if_failed, table
    from rigcad.export import reuse
    from rigcad.export.atomic import check_exports
    from rigcad.profile import load_profile
    from rigcad.rig import load

    profile = load_profile(args.profile)
    checked_counts(profile, args.rays, args.builds)
    check_exports(args.exports, profile.name, "check")  # a planted link or lock: one line now, not after the work
    exports = Path(args.exports)
    mirrors = api.default_folder(profile.name, "mirrors", root=exports)
    missing = [n for n in ("paraboloid", "dome") if not (mirrors / f"{n}.ply").is_file()]
    if missing and (args.mode or profile.raycheck.mode) != "analytic":
        print(f"note: no exported {' and '.join(missing)} mesh in {mirrors}/ (run `rigcad stl {args.profile}`): "
              "meshing the mirrors from the profile", file=sys.stderr)
    key = check_key(profile, args, exports)
    back = _read_back(profile, args, exports, key)
    if back is not None:  # published from the same inputs and intact: nothing traced, nothing written
        rep, rows, paths = back
        if args.verbose:
            print(f"  read back {api.default_folder(profile.name, 'check', root=exports)}/ (nothing changed since "
                  "it was written)", file=sys.stderr)
    else:
        from rigcad.check.trace3d import counting

        rig = load(profile)
        with _rays_bar(f"check {profile.name}") as (bar, stage):
            def step(label: str) -> None:
                stage(label)
                if args.verbose:
                    print(f"  {label} ...", file=sys.stderr)

            with counting(bar):
                result = api.check(rig, args.rays, args.mode, exports, monte_carlo=not args.no_monte_carlo,
                                   builds=args.builds, progress=step)
        out = api.default_folder(profile.name, "check", root=exports)
        with reuse.recording(out, key if rig.profile is profile else None):
            paths = api.write_check(rig, result, out)
        rep, rows = result.report, result.rows
        if args.verbose:  # the run's times: not in raycheck.json, which is the same bytes on every run
            for stage, seconds in result.timings_s.items():
                print(f"  time {stage}: {seconds:.2f} s", file=sys.stderr)
    main = rep["readings"][rep["mode"]]
    print(f"{profile.name}: mode {rep['mode']}, {rep['rays']} rays, backend {rep['backend']}")
    print(f"  spot radius max {main['max_spot_radius_mm']:.3g} mm (rms {main['rms_spot_radius_mm']:.3g}), "
          f"angle error max {main['max_angle_error_rad'] / DEG:.3g} deg, theta {main['theta_min_deg']:.2f}.."
          f"{main['theta_max_deg']:.2f} deg, lost {main['lost_fraction']:.2%}")
    meshed = sorted(n for n, src in (rep["meshes"] or {}).get("sources", {}).items() if not src.startswith(str(exports)))
    if meshed and not missing:
        print(f"  note: meshed from the profile, not the exports: {', '.join(meshed)}", file=sys.stderr)
    print(table(rows))
    for p in paths:
        print(f"  wrote {p}" if back is None else f"  up to date {p}")
    raise_if_failed(rows, profile.name)
    return 0


def criteria_refusal(rig, exports, command: str, written: bool = False):
    """Judge ``rig`` (a Rig, or a loaded Profile: its rig as designed, built only when the criteria's
    cheap rows are not kept for it) by the ray check's criteria before it is printed (rigcad.check.criteria.judge):
    when it fails one, print one line per failed criterion (its key, file:line, the figure and the
    value that would pass) under one 'rigcad: error:' line saying what ``command`` did (``written``:
    its files are written for inspection only). Returns the verdict (``.ok``; ``.notes``, what was not
    judged, for :func:`criteria_notes` once the command's work is done)."""
    from rigcad.check.criteria import judge
    from rigcad.errors import one_line

    verdict = judge(rig, exports)
    if not verdict.ok:
        what = ("its files are written for inspection only: do not print them" if written
                else "nothing is written for printing")
        print(f"rigcad: error: {rig.name}: the rig fails {len(verdict.refusals)} of the ray check's criteria, each "
              f"below; `rigcad {command}` refuses it ({what})", file=sys.stderr)
        for line in verdict.refusals:
            print(f"  {one_line(line)}", file=sys.stderr)
    return verdict


def criteria_notes(verdict) -> None:
    """Print what the ray check's criteria left unjudged (no `rigcad check` written for the profile)."""
    from rigcad.errors import one_line

    for note in verdict.notes:
        print(f"note: {one_line(note)}", file=sys.stderr)


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``check`` to rigcad's subcommands."""
    from rigcad.arguments import positive_int, profile_command

    p = profile_command(
        subparsers, "check", cmd_check,
        help="3D ray check: trace the mirror meshes, compare with the exact surfaces and the targets",
        description="Trace rays from the COP through the mirror meshes (Embree; exported PLYs when present, "
                    "else meshed from the profile), the exact surfaces and the occluders; write "
                    "exports/<profile>/check/{raycheck.json, spot.png, theta_map.png}; exit 1 with a table when "
                    "a tolerance declared in the profile (raycheck.*, tolerancing.*) is not met.")
    p.add_argument("--rays", type=positive_int, help="pinhole rays (default: raycheck.rays)")
    p.add_argument("--mode", choices=("mesh", "smooth", "analytic"), help="reading checked (default: raycheck.mode)")
    p.add_argument("--builds", type=positive_int, help="Monte Carlo builds (default: tolerancing.builds)")
    p.add_argument("--no-monte-carlo", action="store_true", help="skip the Monte Carlo tolerance analysis")
    p.add_argument("-v", "--verbose", action="store_true", help="print stages and their times on stderr")
    return p
