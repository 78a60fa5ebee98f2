"""``rigcad basis PROFILE [--order N] [--exports DIR] [--alpha-deg A] [--lowdin] [--simulate]
[--circle CX CY R] [--calibration PATH] [--as-designed]``: the projector images of the zonal basis,
their Gram matrices and (``--simulate``) the simulated acquisition on the rig, from the command line;
drawn for the rig as measured when the calibration circle or ``rigcad calibrate``'s fit is given or
found beside (rigcad.basis.measured)."""

from __future__ import annotations

import argparse
import math
import time


def _order(text: str):
    """The order as an int when it reads as one, else the text (refused with one line by check_basis_order)."""
    try:
        return int(text)
    except ValueError:
        return text


#: Peak memory of ``rigcad basis`` (images, lat-long maps, Gram matrices; --simulate's own not counted):
#: fixed bytes, bytes per projector pixel and per pixel and function ((order + 1)^2 functions).
#: Measured (/usr/bin/time -v, one run each): 1024 x 768 px: order 0 256 MiB, order 4 346 MiB, order 8
#: 558 MiB; 2048 x 1536 px: order 0 290 MiB, order 4 557 MiB; 16384 x 16384 px, order 0: 3,418 MiB.
#: That is 12-15 bytes per pixel and 3-5 per pixel and function; the estimate rounds up to 16 and 8.
BASIS_FIXED_BYTES = 256.0 * 2 ** 20
BASIS_BYTES_PER_PIXEL = 16.0
BASIS_BYTES_PER_PIXEL_FUNCTION = 8.0


def check_basis_memory(resolution, order: int, memory: int | None = None) -> None:
    """Refuse a basis of ``order`` for a projector of ``resolution`` (width, height) px when its
    estimated peak memory exceeds this machine's (``memory`` bytes; engine.machine_memory by default):
    one line naming the largest order that fits, or the largest projector when no order does."""
    import math

    from rigcad.engine import ResourceError, machine_memory

    memory = machine_memory() if memory is None else memory
    width, height = (int(v) for v in resolution)
    pixels = width * height

    def need(functions: int) -> float:
        return BASIS_FIXED_BYTES + pixels * (BASIS_BYTES_PER_PIXEL + BASIS_BYTES_PER_PIXEL_FUNCTION * functions)

    if need((order + 1) ** 2) <= memory:
        return
    functions = ((memory - BASIS_FIXED_BYTES) / pixels - BASIS_BYTES_PER_PIXEL) / BASIS_BYTES_PER_PIXEL_FUNCTION
    head = (f"projector.resolution [{width}, {height}] with --order {order}: the basis would need about "
            f"{need((order + 1) ** 2) / 2 ** 30:.3g} GiB of memory, more than this machine's {memory / 2 ** 30:.3g} GiB")
    if functions >= 1:
        raise ResourceError(f"{head}; the largest order that fits is {math.isqrt(int(functions)) - 1}", param="--order")
    largest = max(0.0, (memory - BASIS_FIXED_BYTES) / (BASIS_BYTES_PER_PIXEL + BASIS_BYTES_PER_PIXEL_FUNCTION))
    raise ResourceError(f"{head}; even order 0 does not fit: the largest projector that fits has {int(largest):,} px",
                        param="projector.resolution")


def cmd_basis(args: argparse.Namespace) -> int:
    from rigcad import api
    from rigcad.basis.acquire import simulate_on_rig, simulation_steps, stage_simulation
    from rigcad.basis.projector import BASIS_STEPS, check_basis_order, write_basis
    from rigcad.export.manifest import profile_digest
    from rigcad.progress import stages
    from rigcad.rig import load

    order = check_basis_order(_order(args.order))  # before any work: a bad order is one line, nothing written
    alpha = None if args.alpha_deg is None else math.radians(args.alpha_deg)
    from rigcad.export.atomic import check_exports
    from rigcad.profile import load_profile

    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "basis")  # a planted link or lock: one line now, not after the work
    check_basis_memory(profile.projector.resolution, order)  # a basis no memory here holds: one line, no work
    if args.simulate:  # before the images: a stride that samples no 2 x 2 camera pixels is refused now
        largest = min(profile.camera.resolution) // 2
        if args.camera_stride_px > largest:
            from rigcad.errors import BasisError

            raise BasisError(f"--camera-stride-px {args.camera_stride_px}: the {profile.camera.resolution[0]} x "
                             f"{profile.camera.resolution[1]} px camera would be sampled at fewer than 2 x 2 pixels; "
                             f"valid: 1..{largest}")
    corrected = None
    if args.simulate:  # read before any work: a map that is not one is refused in one line, never replaced
        from rigcad.calibrate import load_corrected_map

        corrected = load_corrected_map(args.exports, profile.name, tuple(profile.camera.resolution))
    rig = load(profile)
    from rigcad.basis.measured import load_measured

    measured = load_measured(rig, args.exports, args.circle, args.calibration, args.as_designed)
    _print_measured(measured)
    # written under the one lock of everything under exports/<profile>: a design or build publishing
    # the whole folder meanwhile waits, instead of deleting this run's staging folder
    out = api.default_folder(rig.name, "basis", root=args.exports)
    total = BASIS_STEPS + (order + 1) ** 2 + 1 + (simulation_steps() if args.simulate else 0)
    t0 = time.perf_counter()
    with stages(total, f"basis {rig.name}") as step:
        basis = api.basis(rig, order, alpha, progress=step, measured=measured)
        sim, t_sim = None, time.perf_counter()
        if args.simulate:  # simulated first: the images and the simulation are one run's, published together
            print("  camera exitant directions: " + (f"the corrected map {corrected.path}" if corrected else
                                                     "the design map (no corrected map: rigcad calibrate)"))
            sim = simulate_on_rig(rig, order, basis=basis, camera_stride_px=args.camera_stride_px, progress=step,
                                  corrected=corrected)
        t_sim = time.perf_counter() - t_sim
        paths = write_basis(basis, out, lowdin_images=args.lowdin, progress=step,
                            lock=api.writer_lock(out, rig.name, ("basis",)), made_from=profile_digest(rig.profile),
                            also=None if sim is None else lambda st, folder: stage_simulation(sim, st, folder))
    _print_basis(rig, basis, order)
    print(f"  {len(paths)} files in {out}/ ({time.perf_counter() - t0:.1f} s)")
    if sim is not None:
        _print_simulation(sim, t_sim)
    return 0


def _print_measured(measured) -> None:
    """Which measurements the images are drawn for (rigcad.basis.measured), one line."""
    c, fit = measured.circle, measured.fit_source
    circle = (f"the measured circle ({c.radius_px:.1f} px about ({c.centre_px[0]:g}, {c.centre_px[1]:g}), "
              f"{c.source})" if c else "the design's circle (no --circle, no calibrate/circle.json)")
    rig = f"the calibrated rig ({fit})" if fit else "the rig as designed (no calibrate/calibration.json)"
    print(f"  projector images drawn for {circle} on {rig}")


def _print_basis(rig, basis, order: int) -> None:
    """The basis's summary: zone, lit pixels, solid angles and the Gram matrices' deviations."""
    rep = basis.report
    z, px, sa = rep["zone"], rep["projector"], rep["solid_angle"]
    print(f"{rig.name}: zonal basis to order {order} ({rep['functions']} functions) over "
          f"{z['alpha_deg']:.3f}..{z['beta_deg']:.0f} deg; {px['pixels_lit']} lit projector pixels "
          f"({px['lit_fraction_of_zone']:.1%} of the zone's solid angle), pitch {px['pitch_deg']:.2f} deg")
    print(f"  pixel solid angles: {sa['pixel_sum_sr']:.6f} sr against 2 pi (cos alpha - cos beta) = "
          f"{sa['zone_closed_form_sr']:.6f} sr (relative {sa['relative_error']:+.2e}; edge bound "
          f"{sa['edge_bound_sr']:.3g} sr)")
    print("  Gram matrix over the lit pixels, largest |G - I|: order  analytic  8-bit  16-bit  "
          "no occluders  Loewdin 8-bit (deviation)")
    for key, g in rep["gram"].items():
        if key.startswith("order_"):
            print(f"    {key[6:]:>5}  {g['analytic']['max_abs']:.2e}  {g['analytic_8bit']['max_abs']:.2e}  "
                  f"{g['analytic_16bit']['max_abs']:.2e}  {g['analytic_without_occluders']['max_abs']:.2e}      "
                  f"{g['lowdin_8bit']['max_abs']:.2e} ({g['lowdin_deviation_from_analytic']['max']:.3f})")


def _print_simulation(sim, seconds: float) -> None:
    """The simulated acquisition's table: coefficient errors per model and order, moved rigs, gray card."""
    r = sim.report
    print(f"  simulated acquisition ({r['camera']['exitant_directions']} exitant directions, {r['bits']}-bit "
          f"images; relative L2 of the zonal coefficients; {seconds:.1f} s):")
    print("    model          order  lit zone (none)  zone (none)  zone (gram)   " +
          "  ".join(f"moved {i}: lit zone (none)" for i in range(1, len(r["rigs"]))))
    for name in r["models"]:
        for o in r["orders"]:
            cells = []
            for rv in r["rigs"].values():
                f = rv["models"][name][f"order_{o}"]
                cells.append(f)
            a = cells[0]
            print(f"    {name:<14} {o:>5}  {a['coefficients_vs_lit_zone_rel_l2']['none']:15.2e}  "
                  f"{a['coefficients_vs_zone_rel_l2']['none']:11.2e}  {a['coefficients_vs_zone_rel_l2']['gram']:11.2e}   "
                  + "  ".join(f"{c['coefficients_vs_lit_zone_rel_l2']['none']:24.2e}" for c in cells[1:]))
    for i, (key, rv) in enumerate(r["rigs"].items()):
        if i:
            print(f"    moved {i}: {rv['rig']}")
    for rv in r["rigs"].values():
        card = rv["gray_card_order_1"]
        print(f"    gray card (4.1.2, orders 0-1), {rv['rig']}: albedo error {card['gram']['albedo_max_rel_error']:.2e} "
              f"(Gram), {card['none']['albedo_max_rel_error']:.2e} (none)")


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``basis`` to rigcad's subcommands."""
    from rigcad.basis import CAMERA_STRIDE_PX
    from rigcad.arguments import positive_int, profile_command

    p = profile_command(
        subparsers, "basis", cmd_basis,
        help="zonal basis images for the projector, Gram matrices, simulated acquisition",
        description="Compute the zonal basis functions (thesis 3.3) at every projector pixel's incidence "
                    "direction (the rig's own map; pixels that do not reach the sample black), preprocess them as "
                    "thesis 4.2.1 (one scale, positive and negative parts, 8 and 16 bit) and write "
                    "exports/<profile>/basis/: projector/{8bit,16bit}/*.png, the latitude-longitude maps "
                    "latlong/, contact_sheet.png, latlong_sheet.png and basis.json (solid-angle check, Gram "
                    "matrices over the lit pixels, the re-orthonormalised set). --simulate adds the thesis's "
                    "basis validation (3.3.1) on the rig as designed and moved within its tolerances: "
                    "simulation.json and simulation.png.")
    p.add_argument("--order", default="6", help="largest l, 0..12 (default 6: thesis 3.3.1, specular materials)")
    p.add_argument("--alpha-deg", type=float, help="the zone's lower edge in degrees (default: the rig's occlusion "
                                                   "limit, its lowest measurable incidence angle)")
    p.add_argument("--lowdin", action="store_true", help="also write the re-orthonormalised (Loewdin) images")
    p.add_argument("--simulate", action="store_true", help="simulated acquisition: five analytic BRDFs, the rig "
                                                           "as designed and moved by its tolerances")
    p.add_argument("--circle", type=float, nargs=3, metavar=("CX", "CY", "R"),
                   help="the calibration circle as measured (manual section 6, calibration/circle.html): its centre "
                        "and radius in projector pixels from the image's top-left corner (default: "
                        "exports/<profile>/calibrate/circle.json when there, else the design's)")
    p.add_argument("--calibration", metavar="PATH",
                   help="rigcad calibrate's calibration.json (or its folder): the images are drawn on the rig as "
                        "fitted (default: exports/<profile>/calibrate/calibration.json when there)")
    p.add_argument("--as-designed", action="store_true",
                   help="ignore the circle.json and calibration.json found beside: draw the rig as designed")
    p.add_argument("--camera-stride-px", type=positive_int, default=CAMERA_STRIDE_PX,
                   help=f"simulate every N-th camera pixel in both directions (default {CAMERA_STRIDE_PX}: ~50 "
                        "exitant directions)")
    return p
