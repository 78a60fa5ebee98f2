"""The stages run on a rig, as the Python API and the command line run them: ``export``, ``check``,
``basis`` and ``fab`` (with ``write_check``, ``write_basis`` and ``write_simulation`` for the
results computed in memory). The one home of what every caller must agree on:

- the folder each writes by default: ``exports/<profile>`` for the parts and the design files,
  ``.../check``, ``.../basis`` and ``.../fab/<printer>`` (:func:`default_folder`);
- the lock its writer holds while it publishes (:func:`writer_lock`): under
  ``exports/<profile>`` the profile's one lock, ``exports/.<profile>.lock``, so that two commands
  writing into one profile's folder wait for each other instead of replacing each other's files;
- the key its results are known by: the manifest's inputs key (the resolved profile and rigcad's
  code) for a whole export, which an up-to-date ``rigcad stl`` compares
  (:func:`export_up_to_date`); the profile's SHA-256 (``made_from``) recorded beside a result
  folder, so that a later export of another profile removes the results it no longer matches.

- a fab run's key (rigcad.fab.published.inputs_key: the stl manifest's inputs with the printer's
  resolved settings and the options): a run publishing it records it, and a later run with the
  same key reads the folder back while it is intact, with no rig built (:func:`fab_published`).

``Rig.export``, ``Rig.check``, ``Rig.basis`` and ``Rig.fab`` call these, and so does every command.
This module imports the stages when an operation runs: importing it costs nothing (an up-to-date
``rigcad stl`` reads it).
"""

from __future__ import annotations

from pathlib import Path

#: The output root of the command line and of the API's defaults (``--exports``).
EXPORTS = "exports"


def default_folder(profile: str, *inside: str, root: str | Path = EXPORTS) -> Path:
    """``<root>/<profile>/<inside...>``: where a stage writes a profile's results by default
    (``inside`` empty for the export, ``("check",)``, ``("basis",)``, ``("fab", printer)``)."""
    return Path(root, profile, *inside)


def writer_lock(folder: str | Path, profile: str, inside: tuple[str, ...] = ()) -> Path:
    """The lock a writer into ``folder`` holds while it publishes. ``inside``: where the writer's
    folder lies in ``<root>/<profile>`` (``()`` for that folder itself, ``("fab", printer)`` for a
    fab run). When ``folder`` is ``<root>/<profile>/<inside...>``: the profile's one lock
    (export.atomic.profile_lock(root, profile), what every command writing there holds); anywhere
    else: a lock of its own beside the folder."""
    from rigcad.export.atomic import profile_lock

    folder = Path(folder)
    tail = (profile, *inside)
    if folder.parts[-len(tail):] == tail:
        return profile_lock(folder.parents[len(inside)], profile)
    return profile_lock(folder.parent, folder.name)


def export_up_to_date(profile, folder: str | Path) -> bool:
    """True when ``folder`` holds the export of ``profile`` (a loaded Profile) by this code, intact
    (the manifest's inputs key and every file it lists), with no result folder beside it made from
    another profile (an export would remove those). A killed run's leftovers beside an up-to-date
    folder are removed (under the folder's lock, taken only when there is something to remove)."""
    from rigcad.export.atomic import stale_results, tidy
    from rigcad.export.manifest import inputs_key, profile_digest, up_to_date

    folder = Path(folder)
    if not up_to_date(folder, inputs_key(profile)) or stale_results(folder, profile_digest(profile)):
        return False
    tidy(folder, writer_lock(folder, profile.name))
    return True


def export(rig, folder: str | Path | None = None, parts: list[str] | None = None, progress=None):
    """Write the design files and the parts (STEP, STL, 3MF, PLY mirrors, renders, rig.step,
    manifest.json) into ``folder`` (default ``exports/<profile>``), all published together under
    :func:`writer_lock`; the manifest records the inputs key when the whole rig as designed is
    exported. Returns the build's :class:`rigcad.export.build.BuildResult`."""
    from rigcad.export.build import build_rig
    from rigcad.export.design import design_files
    from rigcad.export.manifest import inputs_key
    from rigcad.optics.frames import Misalignment

    out = Path(folder) if folder is not None else default_folder(rig.name)
    key = inputs_key(rig.profile) if parts is None and rig.misalignment == Misalignment.none() else None
    return build_rig(rig, out, parts, progress=progress, design=design_files(rig.design), inputs_key=key,
                     lock=writer_lock(out, rig.name))


def check(rig, rays: int | None = None, mode: str | None = None, exports: str | Path | None = None, **options):
    """The 3D ray check (``rigcad.check.raycheck.run_raycheck``), in memory: returns a RayCheck whose
    ``report`` holds every figure and ``rows`` the declared tolerances with pass/fail. ``exports``:
    the root whose ``<profile>/mirrors/*.ply`` are traced (default: meshed from the profile)."""
    from rigcad.check.raycheck import run_raycheck

    return run_raycheck(rig, exports=Path(exports) if exports is not None else None, rays=rays, mode=mode,
                        **options)


def write_check(rig, result, folder: str | Path | None = None) -> list[Path]:
    """Write a check of ``rig`` (raycheck.json, spot.png, theta_map.png) into ``folder`` (default
    ``exports/<profile>/check``) under :func:`writer_lock`, made from the rig's profile."""
    from rigcad.check.raycheck import write_raycheck
    from rigcad.export.manifest import profile_digest

    out = Path(folder) if folder is not None else default_folder(rig.name, "check")
    return write_raycheck(result, out, writer_lock(out, rig.name, ("check",)), made_from=profile_digest(rig.profile))


def basis(rig, order: int = 6, alpha: float | None = None, progress=None, measured=None):
    """The zonal basis up to ``order`` as ``rig``'s projector shows it (thesis 3.3, 4.2.1): images,
    Gram matrices over the lit pixels, latitude-longitude maps; ``alpha`` rad the zone's lower
    edge (default: the occlusion limit); ``measured``: the rig as calibrated
    (rigcad.basis.measured.load_measured). See :func:`rigcad.basis.projector.projector_basis`."""
    from rigcad.basis.projector import projector_basis

    return projector_basis(rig, order, alpha_rad=alpha, progress=progress, measured=measured)


def write_basis(rig, result, folder: str | Path | None = None, lowdin_images: bool = False,
                progress=None) -> list[Path]:
    """Write a basis of ``rig`` (:func:`rigcad.basis.projector.write_basis`) into ``folder`` (default
    ``exports/<profile>/basis``) under :func:`writer_lock`, made from the rig's profile."""
    from rigcad.basis.projector import write_basis as write
    from rigcad.export.manifest import profile_digest

    out = Path(folder) if folder is not None else default_folder(rig.name, "basis")
    return write(result, out, lowdin_images=lowdin_images, progress=progress,
                 lock=writer_lock(out, rig.name, ("basis",)), made_from=profile_digest(rig.profile))


def write_simulation(rig, sim, folder: str | Path | None = None) -> list[Path]:
    """Write a simulated acquisition on ``rig`` (simulation.json, simulation.png) beside its basis,
    into ``folder`` (default ``exports/<profile>/basis``), as :func:`write_basis`."""
    from rigcad.basis.acquire import write_simulation as write
    from rigcad.export.manifest import profile_digest

    out = Path(folder) if folder is not None else default_folder(rig.name, "basis")
    return write(sim, out, writer_lock(out, rig.name, ("basis",)), profile_digest(rig.profile))


def fab(rig, printer, folder: str | Path | None = None, gcode: bool = False, parts: list[str] | None = None,
        progress=None, workers: int | None = None, slicing=None):
    """Fabrication for ``printer`` (a name on the profile search path, a path, or a Printer):
    fit, split, orient, slice, report into ``folder`` (default ``exports/<profile>/fab/<printer>``),
    published under :func:`writer_lock`. ``workers``/``slicing``: see
    :func:`rigcad.fab.stage.run_fab`."""
    from rigcad.fab.printers import Printer, load_printer
    from rigcad.fab.stage import run_fab

    p = printer if isinstance(printer, Printer) else load_printer(printer)
    out = Path(folder) if folder is not None else default_folder(rig.name, "fab", p.name)
    return run_fab(rig, p, out, gcode=gcode, parts=parts, progress=progress, workers=workers,
                   lock=writer_lock(out, rig.name, ("fab", p.name)), slicing=slicing)


def fab_published(profile, printer, folder: str | Path | None = None, gcode: bool = False,
                  parts: list[str] | None = None, progress=None):
    """The fab run for ``printer`` (as :func:`fab` takes it) of the rig of ``profile`` (a loaded
    Profile) as designed, read back from ``folder`` (default ``exports/<profile>/fab/<printer>``)
    under :func:`writer_lock` when an earlier run, of whichever command, published it from the
    same inputs and it is intact (:func:`rigcad.fab.published.read_back`); None otherwise. Builds no
    rig: a command asks this first and builds the rig only when there is work (:func:`fab` reads
    back the same way on its own)."""
    from rigcad.fab.printers import Printer, load_printer
    from rigcad.fab.published import read_back

    p = printer if isinstance(printer, Printer) else load_printer(printer)
    out = Path(folder) if folder is not None else default_folder(profile.name, "fab", p.name)
    return read_back(profile, p, out, gcode=gcode, parts=parts, progress=progress,
                     lock=writer_lock(out, profile.name, ("fab", p.name)))


def manual_key(profile, printer, root: str | Path, gcode: bool) -> str:
    """The key of a manual for ``printer`` (a loaded Printer) of the rig of ``profile`` as designed, into
    ``<root>/<profile>/manual/<printer>`` (rigcad.export.reuse.stage_key): the resolved profile and rigcad's
    code, the printer's resolved settings and ``gcode``, and what the manual follows from the earlier
    stages: the record of the fab run published in ``fab/<printer>`` (its inputs' key and every file's
    SHA-256, rigcad.export.reuse) and the ray check written in ``check`` (raycheck.json and the profile it
    records: the criteria the manual is judged by). A changed fab run or check changes the key."""
    from rigcad.export import reuse
    from rigcad.export.atomic import made_from_path

    fab_folder = default_folder(profile.name, "fab", printer.name, root=root)
    check_folder = default_folder(profile.name, "check", root=root)
    reads = {"fab": fab_folder / reuse.RECORD, "check": check_folder / "raycheck.json",
             "check_made_from": made_from_path(check_folder)}
    return reuse.stage_key(profile, "manual", {"printer": printer.describe(), "gcode": bool(gcode),
                                               "reads": reuse.input_files(reads)})


def manual_published(profile, printer, root: str | Path, gcode: bool = False) -> dict | None:
    """The manual for ``printer`` (a loaded Printer) of the rig of ``profile`` (a loaded Profile) as
    designed, published in ``<root>/<profile>/manual/<printer>`` by an earlier run from the same inputs
    (:func:`manual_key`) and intact, while the fab run it follows is still published and intact
    (:func:`fab_published`: the sliced run first, as the manual keeps it): the record's ``summary``
    with ``files`` (the paths), read under :func:`writer_lock`; None otherwise. Builds no rig."""
    import json

    from rigcad.export import reuse
    from rigcad.export.manifest import profile_digest

    fab_folder = default_folder(profile.name, "fab", printer.name, root=root)
    if fab_published(profile, printer, fab_folder, gcode=True) is None and \
            (gcode or fab_published(profile, printer, fab_folder, gcode=False) is None):
        return None
    out = default_folder(profile.name, "manual", printer.name, root=root)
    back = reuse.read_back(out, manual_key(profile, printer, root, gcode), profile_digest(profile),
                           writer_lock(out, profile.name, ("manual", printer.name)), read=(reuse.RECORD,))
    if back is None:
        return None
    rec = json.loads(back[reuse.RECORD])
    summary = rec.get("summary") if isinstance(rec.get("summary"), dict) else {}
    return {**summary, "files": [out / rel for rel in sorted(rec["files"])]}
