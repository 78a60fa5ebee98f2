"""``rigcad calibrate PROFILE (--images DIR | --simulate) [--seed N] [--exports DIR]``: decode the
capture, fit the misalignment, write the residual slope map and the corrected pixel -> incidence
map into ``<exports>/<profile>/calibrate/`` (published atomically: a refused capture writes
nothing). ``--kit`` writes the calibration kit instead (rigcad.calibrate.kit); ``--seating A B ...``
measures how the screen settles from calibrations of one rig (rigcad.calibrate.seating)."""

from __future__ import annotations

import argparse
import io
import json
from pathlib import Path


def cmd_calibrate(args: argparse.Namespace) -> int:
    from rigcad.calibrate import model as M
    from rigcad.calibrate.images import check_decoded, check_half_turns, read_capture
    from rigcad.calibrate.upright import Uprights
    from rigcad.calibrate.patterns import Sequence
    from rigcad.calibrate.run import calibrate, compare
    from rigcad.check.scene import analytic_optics
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.progress import stages
    from rigcad.calibrate.kit import write_kit

    if any(getattr(args, k, None) for k in ("gray_card", "gray_card_kit", "gray_card_simulate")):
        return _gray_card(args)
    for flag in ("exposures_ms", "response_exposures_ms", "circle", "design_circle"):
        if getattr(args, flag, None):
            from rigcad.errors import ExportError

            raise ExportError(f"--{flag.replace('_', '-')}: only with --gray-card, --gray-card-simulate or "
                              "--gray-card-kit (the gray card's exposures and projector circle)")
    if _kit_alone(args) and _kit_read_back(args):
        return 0
    rig, runs = _before_any_work(args)
    capture_out = getattr(args, "write_capture", None)
    if runs is not None:
        return _seating(rig, args, runs)
    if getattr(args, "kit", False):
        return _kit(rig, args, write_kit)
    seq = Sequence.from_profile(rig.profile.calibration)
    plan = M.Plan.of(rig.profile)
    ups = Uprights.of(rig.profile)
    folder, images, truth = Path("<simulated>"), None, None
    if not args.simulate:  # a capture that is missing or the wrong size is refused before any work
        folder = Path(args.images)
        window = M.Camera.of(rig).crop
        images = (read_capture(folder, seq, plan.labels, rig.profile.camera.resolution, window=window)
                  + read_capture(folder, ups.seq, ups.labels, rig.profile.camera.resolution,
                                 absent=f"the upright display's (calibration.upright_turns: {len(ups)}); to "
                                        "calibrate without one, set calibration.upright_turns: 0", window=window))
    with stages(3, "calibrate") as step:
        step("tracer")
        optics = analytic_optics(rig)
        if args.simulate:
            step("simulated capture")
            images, truth = _simulated(optics, rig, args, capture_out)
        step("decode, fit, maps")
        core = M.Camera.of(rig).mirrored_core(rig)
        check = None if args.simulate else (
            lambda decoded: [check_decoded(folder, k, seq if c < len(plan) else ups.seq, d, core)
                             for c, (k, d) in enumerate(zip(plan.labels + ups.labels, decoded))]
            + [check_half_turns(folder, plan, decoded[:len(plan)])])
        result = calibrate(optics, rig, images, say=print, check=check)
    _check_heights(result, folder)
    _check_uprights(result, rig.profile, folder)
    report = _report(result, rig)
    extra = None
    if truth is not None:
        from rigcad.calibrate.run import truth_maps

        report["simulation"] = {"seed": args.seed, **compare(optics, rig, result, *truth)}
        extra = truth_maps(optics, rig, result, *truth)
    picture = _picture(rig.name, result, extra)
    out = Path(args.exports) / rig.name / "calibrate"
    with Staging(out, lock=profile_lock(Path(args.exports), rig.name), made_from=profile_digest(rig.profile)) as st:
        st.write_bytes(out / "calibration.json", json_bytes(report))
        st.write_bytes(out / "corrected_map.npz", _npz(result))
        st.write_bytes(out / "maps.png", picture)
        st.commit()
    f = report["fit"]
    print(f"calibrate {rig.name}: fit RMS {f['rms_residual_mm'] * 1e3:.2f} um off the mirrors, "
          f"{f['direct_view_rms_residual_mm'] * 1e3:.2f} um on the screen seen directly, over {f['residuals_used']} "
          f"residuals ({f['direct_view_residuals']} direct); "
          f"dome residual slope RMS {report['residual_slopes']['residual_slope_rms_mrad']:.3f} mrad, worst "
          f"{report['residual_slopes']['residual_slope_worst_mrad']:.3f} mrad; "
          f"{100 * report['unmeasured']['fraction_of_lit']['measured']:.0f} % of the lit pixels measured "
          f"(the rest, and why: calibration.json 'unmeasured'); wrote {out}")
    print(_against_dome_line(report["against_the_dome"]["parameters"]))
    return _print_verdict(report["verdict"], simulated=truth is not None)


def _print_verdict(judged: dict, simulated: bool) -> int:
    """Each criterion's line and the verdict (rigcad.calibrate.kit.verdict); the exit status: 1 when a
    capture (``--images``) fails, 0 when it passes; a simulated capture (``--simulate``, a rehearsal of a rig
    moved within its tolerances) exits 0 either way and says so."""
    for line in judged["lines"]:
        print(f"  {line}")
    if simulated:
        print(f"{judged['line']} (a rehearsal on a simulated rig: --simulate exits 0)")
        return 0
    print(judged["line"])
    return 0 if judged["passed"] else 1


#: Peak memory of ``rigcad calibrate P --simulate`` and ``--images``: fixed bytes plus bytes per camera
#: pixel. Measured (/usr/bin/time -v, one run each, achutha2006 with camera.resolution changed):
#: --simulate 680 x 512 px 657 MiB, 1360 x 1024 px 1,192 MiB, 2040 x 1536 px 2,047 MiB (537 and 515 bytes
#: per pixel between them, 502 MiB at none); --images (the capture --simulate --write-capture wrote)
#: 680 x 512 px 447 MiB, 1360 x 1024 px 843 MiB (398 bytes per pixel, 315 MiB at none). Rounded up:
#: linear in the pixels, as the frames, the camera's window and the decoding are.
SIMULATE_BYTES_PER_PIXEL = 560.0
SIMULATE_FIXED_BYTES = 512.0 * 2 ** 20
IMAGES_BYTES_PER_PIXEL = 448.0
IMAGES_FIXED_BYTES = 384.0 * 2 ** 20


def check_simulation_memory(profile, memory: int | None = None, simulate: bool = True) -> None:
    """Refuse ``--simulate`` (``simulate``; else ``--images``) with a ResourceError naming
    camera.resolution when its estimated peak memory (the constants above, per camera pixel) exceeds
    this machine's (``memory`` bytes: engine.machine_memory by default); the line names the largest
    camera that fits."""
    import math

    from rigcad.engine import ResourceError, machine_memory

    memory = machine_memory() if memory is None else memory
    fixed, per_pixel = ((SIMULATE_FIXED_BYTES, SIMULATE_BYTES_PER_PIXEL) if simulate else
                        (IMAGES_FIXED_BYTES, IMAGES_BYTES_PER_PIXEL))
    width, height = (int(v) for v in profile.camera.resolution)
    need = fixed + per_pixel * width * height
    if need <= memory:
        return
    pixels = max(0.0, (memory - fixed) / per_pixel)
    scale = math.sqrt(pixels / (width * height))
    fit_w, fit_h = int(width * scale), int(height * scale)
    raise ResourceError(f"camera.resolution [{width}, {height}]: calibrate {'--simulate' if simulate else '--images'} "
                        f"would need about {need / 2 ** 30:.3g} GiB of memory, more than this machine's "
                        f"{memory / 2 ** 30:.3g} GiB; the largest camera that fits has {int(pixels):,} px "
                        f"([{fit_w}, {fit_h}] at this aspect)", param="camera.resolution")


def _kit_alone(args: argparse.Namespace) -> bool:
    """``--kit`` with no option that could refuse it after the rig is built (--seating, --laying,
    --write-capture): a kit whose result depends on the profile and rigcad's code alone."""
    return bool(getattr(args, "kit", False)) and not any(getattr(args, k, None) for k in ("seating", "laying",
                                                                                          "write_capture"))


def _kit_key(profile) -> str:
    """The key of the calibration kit (rigcad.export.reuse.stage_key): the resolved profile and rigcad's code."""
    from rigcad.export import reuse

    return reuse.stage_key(profile, "calibrate_kit", {})


def _kit(rig, args: argparse.Namespace, write_kit) -> int:
    """``--kit``: write the kit (``write_kit``: rigcad.calibrate.kit.write_kit), recorded with its key
    (:func:`_kit_key`) when nothing but ``--kit`` was asked, so that the next run reads it back."""
    from rigcad.export import reuse

    out = Path(args.exports) / rig.name / "calibrate_kit"
    with reuse.recording(out, _kit_key(rig.profile) if _kit_alone(args) else None):
        from rigcad.manual.finishing import recipe

        manifest = write_kit(rig, out, say=print, refinish=[row[0] for row in recipe(rig.profile)])
    print(f"calibration kit for {rig.name}: {len(manifest['files'])} files in {out}")
    return 0


def _kit_read_back(args: argparse.Namespace) -> bool:
    """``--kit``: when the kit published in ``<exports>/<profile>/calibrate_kit`` was made from the same
    inputs (:func:`_kit_key`) and is intact, say so and return True, with no rig built and nothing written."""
    from rigcad.errors import ExportError
    from rigcad.export import reuse
    from rigcad.export.atomic import check_exports, profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.export.readback import parse_json
    from rigcad.profile import load_profile

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "calibrate_kit")
    out = Path(args.exports) / profile.name / "calibrate_kit"
    back = reuse.read_back(out, _kit_key(profile), profile_digest(profile), profile_lock(Path(args.exports),
                                                                                         profile.name),
                           read=("manifest.json",))
    try:
        manifest = parse_json(back["manifest.json"], str(out / "manifest.json")) if back is not None else None
    except ExportError:
        return False
    if not isinstance(manifest, dict) or not isinstance(manifest.get("files"), dict):
        return False
    print(f"calibration kit for {profile.name}: {len(manifest['files'])} files in {out} (up to date: the same "
          "profile and code as when it was written; nothing written)")
    return True


def _before_any_work(args: argparse.Namespace):
    """The rig, and ``--seating``'s calibrations (None without it), after every refusal that needs no
    work: --seating's files read first (before the rig is built), --simulate's or --images' memory from the
    profile, a screen or upright display that cannot fit, --laying, --write-capture's folder."""
    from rigcad.calibrate.kit import check_screen_fits, check_upright_fits
    from rigcad.rig import load

    runs = _seating_runs(args.seating) if getattr(args, "seating", None) else None
    if args.simulate or getattr(args, "images", None):  # a camera that cannot fit: one line, before the rig
        from rigcad.profile import load_profile

        check_simulation_memory(load_profile(args.profile), simulate=bool(args.simulate))
    rig = load(args.profile)
    check_screen_fits(rig)  # a screen that cannot lie in the dome is refused before any work
    check_upright_fits(rig.profile)  # nor an upright display that cannot stand in the bore
    _check_laying(getattr(args, "laying", 0), args.simulate)
    if getattr(args, "write_capture", None):
        _check_capture_folder(Path(args.write_capture), args.simulate)
    return rig, runs


def _simulated(optics, rig, args: argparse.Namespace, capture_out: str | None) -> tuple[list, tuple]:
    """``--simulate``'s capture (seeded by ``--seed``), written out with ``--write-capture``, as the
    images to calibrate (float) and the truth to compare with (misalignment, surface, upright placement).
    ``--laying`` k > 0: the same rig and surface, the screens and the upright display placed anew
    and the camera's noise drawn anew (a capture for ``--seating``)."""
    import numpy as np

    from rigcad.calibrate import model as M, simulate as S
    from rigcad.calibrate.patterns import Sequence
    from rigcad.calibrate.upright import Uprights, random_placement

    plan = M.Plan.of(rig.profile)
    rng = np.random.default_rng(args.seed)
    laying = getattr(args, "laying", 0)
    theta = S.random_misalignment(rig, plan, rng, laying)
    placement = random_placement(rig.profile, rng)
    surface = S.planted_surface(rig, rng)
    noise = np.random.default_rng([args.seed, laying]) if laying else rng
    images = S.render(optics, rig, theta, surface, M.Camera.of(rig), Sequence.from_profile(rig.profile.calibration),
                      plan, noise, placement)
    if capture_out:
        _write_capture(Path(capture_out), plan.labels + Uprights.of(rig.profile).labels, images, args.profile)
    return S.as_read(M.Camera.of(rig), images), (theta, surface, placement)


def _seating(rig, args: argparse.Namespace, runs: list) -> int:
    """``--seating``: how the screen settles, from calibration.json files of one rig
    (rigcad.calibrate.seating), into ``<exports>/<profile>/calibrate_seating/seating.json``."""
    from rigcad.calibrate.images import CaptureError
    from rigcad.calibrate.seating import line, measure
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest

    result = measure(runs, rig.profile)
    out = Path(args.exports) / rig.name / "calibrate_seating"
    with Staging(out, lock=profile_lock(Path(args.exports), rig.name), made_from=profile_digest(rig.profile)) as st:
        st.write_bytes(out / "seating.json", json_bytes(result))
        st.commit()
    print(f"{line(result)}; wrote {out}")
    return 0


#: The largest calibration.json --seating reads: rigcad's own are ~83 KB (achutha2006, 4 captures and
#: 3 upright ones); 4 MiB leaves room for fifty times as many captures.
SEATING_MAX_BYTES = 4 << 20


def _seating_runs(given: list[str]) -> list[tuple[str, object]]:
    """Each calibration.json ``--seating`` names (a file, or the calibrate/ folder holding one), read
    as data (rigcad.export.readback: a regular file of at most SEATING_MAX_BYTES, strict JSON); one file
    named twice, or two files with the same bytes, is refused: it would measure a seating of 0."""
    import hashlib

    from rigcad.calibrate.images import CaptureError
    from rigcad.export.readback import read_file, parse_json, shown

    runs, seen = [], {}
    for name in given:
        path = Path(name) / "calibration.json" if Path(name).is_dir() else Path(name)
        data, st = read_file(path, "a calibration.json", SEATING_MAX_BYTES, CaptureError,
                             missing="--seating reads the calibration.json of each calibration")
        for key in ((st.st_dev, st.st_ino), hashlib.sha256(data).hexdigest()):
            if key in seen:
                raise CaptureError(f"{shown(path)}: the same calibration as {seen[key]} "
                                   f"({'the same file' if isinstance(key, tuple) else 'the same bytes'}): give "
                                   "calibrations of separate layings, each once")
            seen[key] = shown(path)
        runs.append((str(path), parse_json(data, shown(path), CaptureError)))
    return runs


def _against_dome_line(params: dict) -> str:
    """One line: the paraboloid's and the camera's placement against the dome, with standard errors."""
    def part(c: str) -> str:
        v = lambda k: f"{params[f'{c}_{k}']['value']:+.3f} ± {params[f'{c}_{k}']['standard_error']:.3f}"  # noqa: E731
        return (f"{c} off by x {v('dx_mm')}, y {v('dy_mm')}, z {v('dz_mm')} mm, "
                f"tilted x {v('tilt_x_deg')}, y {v('tilt_y_deg')} deg")
    return f"against the dome's axis: {part('paraboloid')}; {part('camera')}"


def _check_laying(laying: int, simulate: bool) -> None:
    """``--laying``: with ``--simulate`` only, and 0 (the seed's own capture) or more."""
    from rigcad.errors import ExportError

    if laying and not simulate:
        raise ExportError(f"--laying {laying}: only with --simulate (it lays the simulated screens anew)")
    if laying < 0:
        raise ExportError(f"--laying {laying}: a count of layings, 0 (the seed's own capture) or more")


def _check_capture_folder(folder: Path, simulate: bool) -> None:
    """``--write-capture``'s folder: with ``--simulate`` only, and new or empty (a capture is one
    run's images: no frame of another may stay beside them)."""
    from rigcad.errors import ExportError

    if not simulate:
        raise ExportError(f"--write-capture {folder}: only with --simulate (it writes the simulated capture)")
    from rigcad.export.atomic import refuse_links

    refuse_links(folder, folder.parent)  # a link there is refused now, not after the simulation's work
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise ExportError(f"--write-capture {folder}: it exists and is not an empty folder; name a new or empty one")


def _write_capture(folder: Path, labels: tuple[str, ...], images: list, profile: str) -> None:
    """The simulated capture's images (per capture ``labels``: the plan's, then the upright display's;
    frame name -> uint8 image) as the PNG files ``--images`` reads
    (rigcad.calibrate.images.capture_path), published at once."""
    from rigcad.calibrate.images import capture_path
    from rigcad.export.atomic import Staging
    from rigcad.export.png import gray_png

    with Staging(folder) as st:
        for label, frames in zip(labels, images):
            for name, im in frames.items():
                st.write_bytes(capture_path(folder, label, name), gray_png(im))
        st.commit()
    print(f"wrote the simulated capture: {sum(len(f) for f in images)} images in {folder} "
          f"(rigcad calibrate {profile} --images {folder} reads them)")


#: A fitted screen height further than this (mm) from its spacer's is a height the images contradict.
HEIGHT_TOLERANCE_MM = 1.0


def _check_heights(result, folder: Path) -> None:
    from rigcad.calibrate import model as M
    from rigcad.calibrate.images import CaptureError, capture_path

    plan = result.plan
    for k, label in enumerate(plan.labels):
        dz = float(result.fit.theta[M.screen_index(k)])
        if abs(dz) > HEIGHT_TOLERANCE_MM:
            raise CaptureError(f"{capture_path(folder, label, 'white')}: the images put the screen {dz:+.2f} mm from "
                               f"its spacer's height ({plan.heights[k]:g} mm above O): wrong spacer or order")


#: An upright capture placed further than this many of its tolerances from its nominal pose
#: (upright.placement_scale) is one the images contradict: the stand at another turn's mark, or the
#: display the wrong way round.
UPRIGHT_TOLERANCES = 5.0


def _check_uprights(result, profile, folder: Path) -> None:
    """An upright capture that could not be placed, or that the images place far from its mark."""
    import numpy as np

    from rigcad.calibrate import model as M
    from rigcad.calibrate.images import CaptureError, capture_path
    from rigcad.calibrate.upright import MIN_REFERENCE_PIXELS, placement_scale

    scale = placement_scale(profile)
    for label, pl in zip(result.uprights.labels, result.placed):
        where = capture_path(folder, label, "white")
        if not pl.placed:
            raise CaptureError(f"{where}: the upright display decodes at {pl.pixels} of the pixels the flat captures "
                               f"measured, under the {MIN_REFERENCE_PIXELS} that place it: is it on, facing the dome, "
                               "in the stand at its mark?")
        worst = int(np.argmax(np.abs(pl.placement) / scale))
        if abs(pl.placement[worst]) > UPRIGHT_TOLERANCES * scale[worst]:
            raise CaptureError(f"{where}: the images place the upright display {abs(pl.placement[worst]) / scale[worst]:.0f} "
                               f"tolerances from its mark ({M.SCREEN_KEYS[worst]}): wrong turn, or captures out of order")


def _report(result, rig) -> dict:
    from rigcad.calibrate import maps
    from rigcad.calibrate import model as M
    from rigcad.calibrate.fit import against_dome, in_report_units
    from rigcad.calibrate.kit import verdict

    refit = result.map_fit.as_dict()
    report = {"fit": result.fit.as_dict(),
            "against_the_dome": {"about": "the paraboloid's and the camera's offsets (their pivots') and tilts against "
                                          "the dome's axis (model.in_dome_frame): what the images fix apart from the "
                                          "rig's tilt over the sample plane, which only the priors fix; the parameters "
                                          "under 'fit' are in the sample frame (docs/calibrate.md)",
                                 "parameters": in_report_units(M.DOME_FRAME_NAMES, *against_dome(rig, result.fit)),
                                 "screens": _screens_report(rig, result)},
            "residual_slopes": result.slope_figures(),
            "map_model": {"about": "the corrected map's model: refit from the fit above with each pixel's dome-slope "
                                   "residual component down-weighted (docs/calibrate.md)",
                          "parameters": refit["parameters"], "rms_residual_mm": refit["rms_residual_mm"]},
            "residual_attribution": "the dome (sanded by hand); a paraboloid slope error at the paired point, "
                                    "and low-order figure errors that a fitted tilt or offset mimics, are not "
                                    "separable from it",
            "unmeasured": {"about": "why lit camera pixels (the fitted model's ray reaches the sample) have no "
                                    "measured direction, each pixel counted under the first cause that applies; "
                                    "corrected_map.npz's 'cause' shows where",
                           "fraction_of_lit": maps.cause_fractions(result.causes), "causes": maps.CAUSE_NOTES},
            "decoding": [d.stats() for d in result.decoded + result.upright_decoded],
            "captures": list(result.plan.labels + result.uprights.labels),
            "upright_display": _uprights_report(result),
            "screen_heights_mm": result.plan.heights.tolist(),
            "timings_s": result.timings_s, "camera_window": {"row0": result.cam.row0, "col0": result.cam.col0,
                                                             "shape": list(result.cam.shape)}}
    report["verdict"] = verdict(rig, report)  # judged before anything is written: it goes into the report
    return report


def _screens_report(rig, result) -> dict:
    """Each flat capture's screen tilt against the dome, by label: what ``--seating`` compares
    between calibrations of the same rig (rigcad.calibrate.seating)."""
    from rigcad.calibrate.fit import in_report_units, screens_against_dome

    tilts, se = screens_against_dome(rig, result.plan, result.fit)
    return {label: in_report_units(("tilt_x_rad", "tilt_y_rad"), t, e)
            for label, t, e in zip(result.plan.labels, tilts, se)}


def _uprights_report(result) -> dict:
    """Each upright capture's fitted placement (in the display's own frame) and its resection."""
    from rigcad.calibrate import model as M
    from rigcad.calibrate.fit import in_report_units

    names = [f"{k}" for k in M.SCREEN_KEYS]
    return {"about": "the upright display's captures (rigcad.calibrate.upright): each placement from its nominal pose, "
                     "in the display's frame (dz along its normal, tilts about its width and height, du sideways, dv "
                     "up, its turn about its normal), fitted against the rays the flat captures measured",
            "captures": {label: {"parameters": in_report_units(names, pl.placement, pl.standard_error),
                                 "rms_residual_mm": pl.rms_mm, "reference_pixels": pl.pixels, "outliers_dropped": pl.outliers}
                         for label, pl in zip(result.uprights.labels, result.placed)}}


def _picture(name: str, result, extra) -> bytes:
    """maps.png: decoded phase, residual slopes (and, simulated, the planted ones and both maps' errors)."""
    import numpy as np

    from rigcad import plots
    from rigcad.calibrate import maps

    shape = result.cam.shape
    phase = result.decoded[0].axes["x"].fringes[-1].phase
    phase = np.where(result.decoded[0].valid, phase, np.nan)
    slope = (np.linalg.norm(result.slopes, axis=1) * 1e3).reshape(shape)
    causes = {"causes": result.causes.reshape(shape), "cause_names": maps.CAUSES}
    if extra is None:
        return plots.calibration_maps(phase, slope, None, None, None, f"{name}: calibration", **causes)
    return plots.calibration_maps(phase, slope, extra["planted_slope_mrad"].reshape(shape),
                                  extra["corrected_error_deg"].reshape(shape), extra["design_error_deg"].reshape(shape),
                                  f"{name}: simulated calibration", **causes)


def _npz(result) -> bytes:
    import numpy as np

    from rigcad.calibrate import maps

    buf = io.BytesIO()
    c = result.corrected
    shape = result.cam.shape + (3,)
    np.savez_compressed(buf, direction=c["direction"].reshape(shape), uncertainty_rad=c["uncertainty_rad"].reshape(
        result.cam.shape), source=c["source"].reshape(result.cam.shape), design=result.design.reshape(shape),
        row0=result.cam.row0, col0=result.cam.col0, resolution=np.array(result.cam.resolution),
        residual_slope=result.slopes.reshape(shape), cause=result.causes.reshape(result.cam.shape),
        measurement_weight=c["measurement_weight"].reshape(result.cam.shape), about=json.dumps(
            {"frame": "mm, O at the origin, +z up; unit directions from O towards the light",
             "source": "0 none, 1 measured, 2 filled, 3 model only",
             "measurement_weight": "the share of the measured residual the map kept (maps.corrected_map)",
             "cause": "-1 the model's ray is lost; " + ", ".join(f"{k} {n}" for k, n in enumerate(maps.CAUSES))}))
    return buf.getvalue()


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``calibrate`` to rigcad's subcommands."""
    from rigcad.arguments import profile_command

    p = profile_command(
        subparsers, "calibrate", cmd_calibrate,
        help="deflectometric calibration of the as-built rig (a screen at the sample)",
        description="Decode a capture of the calibration screen at two or more spacer heights (images "
                    "h<spacer>_<frame>.png|tif, h<spacer>r_<frame> for the half turn, u<turn>_<frame> for the upright "
                    "display, docs/calibrate.md), fit "
                    "the rig's misalignment with its own tracer, map the dome's residual slopes and write exports/<profile>/calibrate/: "
                    "calibration.json, corrected_map.npz (read by rigcad basis --simulate), maps.png. "
                    "--simulate renders a seeded capture of a moved rig with a planted dome error instead and "
                    "compares; --kit writes the screen patterns, the spacers and the manual's page; --seating "
                    "measures how the screen settles, from the calibration.json of repeated calibrations. "
                    "--images judges the rig and prints one line per criterion, PASS or FAIL with its figure against its "
                    "bound (each placement against the dome within its tolerancing key by two standard errors; the "
                    "dome's residual slope p99 within the optical acceptance test's slope), then the verdict, also "
                    "written into calibration.json's 'verdict'; it exits 1 on FAIL (the outputs are still written: "
                    "the manual's 'When it fails' says what to turn or redo), 0 on PASS; --simulate prints the "
                    "rehearsal's verdict and exits 0. "
                    "--gray-card DIR is the reflectance calibration of thesis 4.1.2 (an 18 % gray card: the camera's "
                    "response curve, the scale factors, PASS or FAIL) into exports/<profile>/calibrate_graycard/; "
                    "--gray-card-kit writes its projector images and capture plan, --gray-card-simulate rehearses it.")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--images", help="folder of captured camera images (h<spacer>_<frame>.png|tif, "
                     "h<spacer>r_<frame>, u<turn>_<frame>); prints PASS or FAIL per criterion and exits 1 on FAIL")
    src.add_argument("--simulate", action="store_true", help="render a seeded simulated capture and calibrate it")
    src.add_argument("--kit", action="store_true", help="write the calibration kit: screen patterns, spacers "
                     "(STL, STEP, manifest), the manual's page, into <exports>/<profile>/calibrate_kit")
    src.add_argument("--seating", nargs="+", metavar="JSON", help="how the screen settles on its spacer, from the "
                     "calibration.json (or the calibrate/ folder holding it) of two or more calibrations of one rig left "
                     "as it is, the screen laid anew for each: the value for calibration.screen_seating, into "
                     "<exports>/<profile>/calibrate_seating")
    src.add_argument("--gray-card", metavar="DIR", help="the reflectance calibration (thesis 4.1.2): captures of the "
                     "18 %% gray card (white_<ms>ms, z_<l>_<m>_<pos|neg>_<ms>ms .png|tif): the camera's response curve, "
                     "the scale factors and PASS or FAIL, into <exports>/<profile>/calibrate_graycard")
    src.add_argument("--gray-card-kit", action="store_true", help="write the gray card's projector images and "
                     "capture plan into <exports>/<profile>/calibrate_graycard_kit")
    src.add_argument("--gray-card-simulate", action="store_true", help="render a seeded simulated gray card capture "
                     "(a planted response curve, card and throughputs) and calibrate from it")
    p.add_argument("--exposures-ms", nargs="+", type=float, metavar="MS", default=None,
                   help="with --gray-card*: the basis frames' exposures (default 62.5 125 250, thesis Figure 4.4)")
    p.add_argument("--response-exposures-ms", nargs="+", type=float, metavar="MS", default=None,
                   help="with --gray-card*: the white field's bracket for the response curve "
                        "(default 7.8125 15.625 31.25 62.5 125 250 500)")
    p.add_argument("--circle", type=float, nargs=3, metavar=("CX", "CY", "R"),
                   help="with --gray-card*: the calibration circle as measured (manual section 6, "
                        "calibration/circle.html), its centre and radius in projector pixels from the image's top-left "
                        "corner, as rigcad basis takes it (default: exports/<profile>/calibrate/circle.json when there, "
                        "else the design's)")
    p.add_argument("--design-circle", action="store_true",
                   help="with --gray-card*: ignore the calibrate/circle.json found beside: the design's circle")
    p.add_argument("--seed", type=int, default=2006, help="seed of the simulated misalignment and noise")
    p.add_argument("--laying", type=int, default=0, metavar="K", help="with --simulate: the screens laid anew the "
                   "K-th time on --seed's rig (its misalignment, surface, spacers and wedges kept; the hand's "
                   "placement, the seating and the noise drawn anew): captures for --seating")
    p.add_argument("--write-capture", metavar="DIR", help="with --simulate: also write the simulated camera "
                   "images into DIR (new or empty), named as --images reads them: a capture to rehearse on")
    return p


def _gray_card(args: argparse.Namespace) -> int:
    """``--gray-card DIR``, ``--gray-card-simulate``, ``--gray-card-kit``: the reflectance calibration
    (rigcad.calibrate.graycard) into ``<exports>/<profile>/calibrate_graycard/`` (graycard.json,
    scale_factors.npz; published together, on PASS and on FAIL, which exits 1), or its kit into
    ``calibrate_graycard_kit/``. Every refusal comes before anything is written."""
    import dataclasses

    import numpy as np

    from rigcad.basis.card_light import card_light
    from rigcad.calibrate import graycard as G
    from rigcad.errors import ExportError
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.rig import load

    plan = G.Plan(exposures_ms=tuple(args.exposures_ms or G.EXPOSURES_MS),
                  response_exposures_ms=tuple(args.response_exposures_ms or G.RESPONSE_EXPOSURES_MS))
    for flag, bad in (("--laying", getattr(args, "laying", 0)), ("--seating", getattr(args, "seating", None))):
        if bad:
            raise ExportError(f"{flag}: not with the gray card (it belongs to the deflectometric calibration)")
    capture_out = getattr(args, "write_capture", None)
    if capture_out:
        if not args.gray_card_simulate:
            from rigcad.export.readback import shown

            raise ExportError(f"--write-capture {shown(capture_out)}: only with --simulate or --gray-card-simulate (it "
                              "writes the simulated capture)")
        _check_capture_folder(Path(capture_out), True)
    if args.gray_card:
        plan = plan.with_turned(Path(args.gray_card))  # the half turn's frames when the folder holds any
        G.check_present(Path(args.gray_card), plan)  # a missing capture: one line before the rig is built
    else:
        plan = dataclasses.replace(plan, turned=True)  # the kit asks for it; the simulation rehearses it
    rig = load(args.profile)
    circle = gray_card_circle(rig, args)
    light = card_light(rig, plan.order, circle=circle)
    print(f"  projector images drawn for {_circle_words(circle)}")
    if args.gray_card_kit:
        return _gray_card_kit(rig, plan, light, Path(args.exports), circle)
    view = G.view_of(rig)
    truth = None
    if args.gray_card_simulate:
        truth = G.planted(view, light)
        images = G.render(plan, view, light, truth, np.random.default_rng(args.seed))
        if capture_out:
            _write_gray_capture(Path(capture_out), plan, view, images, args.profile)
        capture = G.as_read(plan, images)
    else:
        capture = G.read(Path(args.gray_card), plan, view)
    result = G.analyse(plan, capture, view, light)
    report = {"profile": rig.name, "source": "simulated" if truth else str(args.gray_card),
              "projector_circle": _circle_record(circle), **result.report}
    if truth is not None:
        report["simulation"] = {"seed": args.seed, "planted": "gamma 2.2 camera, 18 % card lying flat, captured again "
                                "turned a half turn, the camera side falling 20 % to grazing, the light 15 % "
                                "(graycard.planted)",
                                **G.compare(result, truth, view, light)}
    out = Path(args.exports) / rig.name / "calibrate_graycard"
    with Staging(out, lock=profile_lock(Path(args.exports), rig.name), made_from=profile_digest(rig.profile)) as st:
        st.write_bytes(out / "graycard.json", json_bytes(report))
        st.write_bytes(out / "scale_factors.npz", _gray_npz(result, view, light))
        st.commit()
    print(G.summary(result))
    print(f"wrote {out}")
    return 0 if result.passed else 1


def _gray_npz(result, view, light) -> bytes:
    """scale_factors.npz: the camera side's scale factor per window pixel, the light side's per lit
    projector pixel and as zonal coefficients, and the response curve."""
    import numpy as np

    cam = view.cam
    buf = io.BytesIO()
    np.savez_compressed(
        buf, camera_scale=result.camera_scale, row0=cam.row0, col0=cam.col0, resolution=np.array(cam.resolution),
        light_throughput=result.fit.light_g, projector_row=light.row, projector_col=light.col,
        light_zonal_coefficients=result.fit.b, alpha_rad=light.alpha_rad,
        response_knots=result.response.knots, response_log_exposure=result.response.log_radiance,
        response_toe=result.response.toe, about=json.dumps({
            "camera_scale": "1 / t per camera window pixel (NaN off the card's pixels): divide a capture's radiance by "
                            "t, i.e. multiply by this",
            "light_throughput": "kappa g per lit projector pixel (radiance per second per projector level per unit "
                                "f cos theta per sr): eq. 4.2's lambda = 1 / light_throughput "
                                "(rigcad.calibrate.graycard.calibrated applies both)",
            "light_zonal_coefficients": "kappa g in the zonal basis (order 2, zone alpha_rad..pi/2)",
            "response": "log linear exposure at the knots (fractions of full scale), linear to 0 below response_toe"}))
    return buf.getvalue()


def _write_gray_capture(folder: Path, plan, view, images: dict, profile: str) -> None:
    """The simulated gray card capture as the full-frame PNG files ``--gray-card`` reads, at once."""
    from rigcad.calibrate import graycard as G
    from rigcad.export.atomic import Staging
    from rigcad.export.png import gray_png

    with Staging(folder) as st:
        for (frame, ms), im in images.items():
            e = (plan.response_exposures_ms if frame == G.WHITE else plan.exposures_ms).index(ms)
            st.write_bytes(plan.path(folder, frame, e), gray_png(G.full_frame(view, im)))
        st.commit()
    print(f"wrote the simulated gray card capture: {len(images)} images in {folder} (rigcad calibrate {profile} "
          f"--gray-card {folder} reads them)")


def gray_card_circle(rig, args: argparse.Namespace):
    """The calibration circle the gray card's projector images are drawn for, as ``rigcad basis``
    reads it (rigcad.basis.measured): ``--circle CX CY R``, else ``<exports>/<profile>/calibrate/circle.json``
    when there (not with ``--design-circle``), else None (the design's circle)."""
    from rigcad.basis.measured import CIRCLE_JSON, check_circle, read_circle

    given = getattr(args, "circle", None)
    if given is not None:
        return check_circle(rig, given[:2], given[2], "--circle")
    path = Path(args.exports) / rig.name / CIRCLE_JSON
    if not getattr(args, "design_circle", False) and path.exists():
        return read_circle(rig, path)
    return None


def _circle_words(circle) -> str:
    """Which circle, in words, for the command's output."""
    if circle is None:
        return "the design's circle (no --circle, no calibrate/circle.json)"
    return (f"the measured circle ({circle.radius_px:.1f} px about ({circle.centre_px[0]:g}, {circle.centre_px[1]:g}), "
            f"{circle.source})")


def _circle_record(circle) -> dict:
    """Which circle, for graycard.json and capture_plan.json (px from the image's top-left corner)."""
    if circle is None:
        return {"source": "the design's"}
    return {"centre_px_from_top_left": list(circle.centre_px), "radius_px": circle.radius_px,
            "source": str(circle.source)}


def _gray_card_kit(rig, plan, light, exports: Path, circle=None) -> int:
    """The gray card's kit: the projector images (white.png, z_<l>_<m>_<pos|neg>.png), capture_plan.json
    (every file to capture) and procedure.md, into ``<exports>/<profile>/calibrate_graycard_kit/``."""
    from rigcad.calibrate import graycard as G
    from rigcad.export.atomic import Staging, json_bytes, profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.export.png import gray_png

    out = exports / rig.name / "calibrate_graycard_kit"
    files = plan.files()
    capture = {"about": "show each projector image, capture it at each of its exposures (gain fixed, automatic "
                        "exposure off) into one folder; then rigcad calibrate PROFILE --gray-card FOLDER",
               "projector_images": [f"projector/{f}.png" for f in (G.WHITE,) + plan.frames()],
               "captures": [{"show": f"projector/{f.removeprefix(G.TURNED)}.png", "exposure_ms": ms,
                             "file": plan.path(Path("."), f, (plan.response_exposures_ms if f == G.WHITE
                                                              else plan.exposures_ms).index(ms)).name,
                             **({"card": "turned a half turn in the holder"} if f.startswith(G.TURNED) else {})}
                            for f, ms in files],
               "projector_circle": _circle_record(circle)}
    with Staging(out, lock=profile_lock(exports, rig.name), carry=lambda rel: False,
                 made_from=profile_digest(rig.profile)) as st:
        for f in (G.WHITE,) + plan.frames():
            st.write_bytes(out / "projector" / f"{f}.png", gray_png(light.image(f)))
        st.write_bytes(out / "capture_plan.json", json_bytes(capture))
        st.write_bytes(out / "procedure.md", (f"# The gray card (thesis 4.1.2)\n\n{G.manual_text(rig)}\n").encode())
        st.commit()
    print(f"gray card kit for {rig.name}: {len(plan.frames()) + 1} projector images, {len(files)} captures to take; "
          f"wrote {out}")
    return 0
