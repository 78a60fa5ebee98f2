"""The ray check's criteria judged before a rig is printed (``rigcad stl``, ``fab``, ``manual``).

Two kinds:

- the criteria the check decides without tracing its rays (:func:`cheap_rows`): the design's theta
  range against ``targets.theta_min/theta_max`` (the 2D design's exact range, the figure `rigcad
  design` reports), the projector's fewest pixels per degree of theta (the check's own fan of
  pixels, traced on the exact surfaces: some 2,000 rays, ~10 ms) and the camera's rows (closed
  forms on its lens). Each is the same :class:`rigcad.check.tolerances.Row` the full check writes,
  built by the same function, so the two cannot disagree on the aligned rig.
- the criteria that need the full trace (spot radius, angle errors, rays lost, the tower's
  clearance, the Monte Carlo yield): read from the last ``rigcad check`` written for the same
  profile (``exports/<profile>/check/raycheck.json``, made from the same resolved profile), or
  said plainly to be unjudged when there is none (:func:`written_check`).

The cheap rows of the rig as designed are kept beside the export (:data:`KEPT_FILE`, keyed by the
resolved profile and rigcad's code: rigcad.export.reuse.stage_key), so that a command run again
with nothing changed judges them without building the rig (the dome integrated, the fan traced:
about 1.6 s of CPU on the default rig); a changed profile key or code makes them again.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from rigcad.check.tolerances import Row, camera_rows, px_per_deg_row, theta_range_rows

#: What the full check judges that :func:`cheap_rows` does not, for the note when no check was written.
TRACED_CRITERIA = "spot radius, angle errors, rays lost, the tower's clearance, the Monte Carlo yield"


def cheap_rows(rig) -> list[Row]:
    """The check's rows that need no trace of its rays (module docstring), for ``rig`` as it stands."""
    from rigcad.check.raycheck import pixels_per_degree
    from rigcad.check.scene import analytic_optics
    from rigcad.optics.camera import camera_model

    profile = rig.profile
    rows = theta_range_rows(profile, rig.design.report["measurable_range"])
    fan = pixels_per_degree(analytic_optics(rig), rig.incidence, pose=rig.pose("projector"))
    rows.append(px_per_deg_row(profile, fan["summary"]["px_per_deg_min"]))
    if not rig.geometry.cop_at_infinity:
        rows += camera_rows(profile, camera_model(profile, rig.geometry).as_dict())
    return rows


@dataclass(frozen=True)
class WrittenCheck:
    """The last ``rigcad check`` of a profile: ``state`` is "passed", "failed", "none" (no result
    written), "other" (written from another version of the profile) or "unreadable"; ``failed``
    its failed rows as raycheck.json records them (dicts of Row.as_dict)."""

    state: str
    path: Path
    failed: list = field(default_factory=list)


def written_check(exports: str | Path, profile) -> WrittenCheck:
    """The ``rigcad check`` result written under ``exports`` for ``profile`` (a loaded Profile),
    judged only when its folder records the same resolved profile (export.atomic.read_made_from)."""
    from rigcad.export.atomic import read_made_from
    from rigcad.export.manifest import profile_digest
    from rigcad.export.readback import own_json

    folder = Path(exports) / profile.name / "check"
    path = folder / "raycheck.json"
    if not path.is_file():
        return WrittenCheck("none", path)
    if read_made_from(folder) != profile_digest(profile):
        return WrittenCheck("other", path)
    report = own_json(path)
    checks = report.get("checks") if isinstance(report, dict) else None
    if not isinstance(checks, list) or not all(isinstance(c, dict) and "ok" in c for c in checks):
        return WrittenCheck("unreadable", path)
    failed = [c for c in checks if not c["ok"]]
    return WrittenCheck("failed" if failed else "passed", path, failed)


def row_line(row: Row) -> str:
    """One failed row on one line: the key, its file:line, the figure against its limit, the way out."""
    return line_of(row.as_dict())


def line_of(c: dict) -> str:
    """One failed row (Row.as_dict, as raycheck.json records it) on one line."""
    unit = f" {c['unit']}" if c.get("unit") else ""
    return (f"{c['profile_key']} ({c.get('where') or 'default'}): {c['check']} {c['measured']:.4g}{unit} not "
            f"{c['relation']} {c['limit']:.4g}{unit}" + (f"; {c['hint']}" if c.get("hint") else ""))


@dataclass(frozen=True)
class Verdict:
    """What :func:`judge` found: ``refusals`` one line each (the cheap rows failed, then the written
    check's failed rows not already among them), ``notes`` what was not judged and why."""

    refusals: list[str]
    notes: list[str]

    @property
    def ok(self) -> bool:
        return not self.refusals


#: The cheap rows kept for the rig as designed, in exports/<profile>/: ``{"key", "rows"}``.
KEPT_FILE = "criteria.json"


def _kept_key(profile) -> str:
    from rigcad.export import reuse

    return reuse.stage_key(profile, "criteria", {})


def kept_rows(exports: str | Path, profile) -> list[dict] | None:
    """The cheap rows (Row.as_dict) kept under ``exports`` for the rig of ``profile`` as designed, when
    this profile and code made them; None otherwise (missing, not a plain file, unreadable, made from
    another profile or code: they are made anew). Read as rigcad reads back its own files."""
    from rigcad.export.readback import own_json

    doc = own_json(Path(exports) / profile.name / KEPT_FILE)
    if not isinstance(doc, dict) or doc.get("key") != _kept_key(profile):
        return None
    rows = doc.get("rows")
    if not isinstance(rows, list) or not all(map(_row_like, rows)) or doc.get("rows_sha256") != _rows_digest(rows):
        return None  # an edited row is made anew, not trusted
    return rows


def _rows_digest(rows: list) -> str:
    from rigcad.export.atomic import json_bytes
    from rigcad.export.manifest import sha256_hex

    return sha256_hex(json_bytes(rows))


def _row_like(r) -> bool:
    """A kept row :func:`line_of` can print: its figures numbers (a NaN figure was kept as null: made anew)."""
    return (isinstance(r, dict) and isinstance(r.get("ok"), bool) and isinstance(r.get("check"), str)
            and all(f in r for f in ("profile_key", "relation", "unit", "where"))
            and all(isinstance(r.get(f), (int, float)) and not isinstance(r.get(f), bool) for f in ("measured", "limit")))


def judged_rows(rig, exports: str | Path) -> list[dict]:
    """The cheap rows (Row.as_dict) of ``rig`` (a Rig, or a loaded Profile for its rig as designed):
    for the rig as designed, the rows kept under ``exports`` (:func:`kept_rows`) when there are any,
    else made (the rig built from a Profile only then) and kept, atomically, for the next command."""
    from rigcad.optics.frames import Misalignment
    from rigcad.profile.schema import Profile

    profile = rig if isinstance(rig, Profile) else rig.profile
    designed = isinstance(rig, Profile) or rig.misalignment == Misalignment.none()
    kept = kept_rows(exports, profile) if designed else None
    if kept is not None:
        return kept
    if isinstance(rig, Profile):
        from rigcad.rig import Rig

        rig = Rig.from_profile(profile)
    rows = [r.as_dict() for r in cheap_rows(rig)]
    if designed:
        from rigcad.export.atomic import write_json

        path = Path(exports) / profile.name / KEPT_FILE
        path.parent.mkdir(parents=True, exist_ok=True)
        write_json(path, {"key": _kept_key(profile), "rows": rows, "rows_sha256": _rows_digest(rows)})
    return rows


def judge(rig, exports: str | Path) -> Verdict:
    """The criteria of the ray check a rig must meet before it is printed (module docstring). ``rig``:
    a Rig, or a loaded Profile (its rig as designed, built only when no cheap rows are kept for it)."""
    from rigcad.export.readback import shown
    from rigcad.profile.schema import Profile

    profile = rig if isinstance(rig, Profile) else rig.profile
    cheap = judged_rows(rig, exports)
    refusals = [line_of(r) for r in cheap if not r["ok"]]
    names = {r["check"] for r in cheap}
    written = written_check(exports, profile)
    where = shown(written.path)
    notes = []
    if written.state == "failed":
        refusals += [f"{line_of(c)} (rigcad check, {where})" for c in written.failed if c.get("check") not in names]
    elif written.state != "passed":
        why = {"none": "no `rigcad check` result for it", "other": f"the `rigcad check` result in {where} was made "
               "from another version of the profile, so it is not read",
               "unreadable": f"the `rigcad check` result {where} cannot be read"}[written.state]
        notes.append(f"{rig.name}: {why}: the criteria that need the check's full trace ({TRACED_CRITERIA}) are not "
                     f"judged; run `rigcad check {rig.name}` before printing")
    return Verdict(refusals, notes)
