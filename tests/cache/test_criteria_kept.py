"""The ray check's cheap criteria kept beside the export (rigcad.check.criteria.judged_rows): judged
once per profile and code, read back by the next command with no rig built (the dome integrated and
the pixel fan traced: what kept `rigcad stl` and `fab` run again over 1 s); a changed profile key,
a changed code, a deleted or edited kept file, or a moved rig judges them anew. The rig's building is
counted at its one door (rigcad.rig.Rig.from_profile) and the rows' making at cheap_rows."""

from __future__ import annotations

import json

import pytest

from rigcad.check import criteria
from rigcad.export import reuse
from rigcad.profile import load_profile
from rigcad.rig import Rig

#: A key of the default rig the cheap rows judge (the projector's fewest pixels per degree, 1.01 on
#: Table 3.1): asked for 1.2, the same rig fails it.
STRICT = "extends: achutha2006\nraycheck:\n  min_px_per_deg: 1.2\n"
LOOSE = "extends: achutha2006\n"


@pytest.fixture
def counted(monkeypatch):
    """Count the rigs built and the cheap rows made from now on."""
    calls = {"rigs": 0, "rows": 0}
    real_rig, real_rows = Rig.from_profile.__func__, criteria.cheap_rows

    def rig(cls, *args, **kwargs):
        calls["rigs"] += 1
        return real_rig(cls, *args, **kwargs)

    def rows(*args, **kwargs):
        calls["rows"] += 1
        return real_rows(*args, **kwargs)

    monkeypatch.setattr(Rig, "from_profile", classmethod(rig))
    monkeypatch.setattr(criteria, "cheap_rows", rows)
    return calls


def test_kept_rows_are_read_back_with_no_rig_and_the_same_verdict(write_profile, tmp_path, counted):
    profile = load_profile(write_profile(STRICT, "newcomer"))
    first = criteria.judge(profile, tmp_path)
    assert counted == {"rigs": 1, "rows": 1}  # the rig built once, for the rows
    assert (tmp_path / "newcomer" / criteria.KEPT_FILE).is_file()
    again = criteria.judge(profile, tmp_path)
    assert counted == {"rigs": 1, "rows": 1}, counted  # read back: no rig, no rows made
    assert again == first and not again.ok and again.refusals[0].startswith("raycheck.min_px_per_deg"), again
    live = criteria.judge(Rig.from_profile(profile), tmp_path / "elsewhere")  # made afresh in another folder
    assert live == first  # what is kept prints as what is made: the same lines, to the character


def test_a_changed_profile_key_judges_anew(write_profile, tmp_path, counted):
    strict = criteria.judge(load_profile(write_profile(STRICT, "newcomer")), tmp_path)
    loose = criteria.judge(load_profile(write_profile(LOOSE, "newcomer")), tmp_path)  # same name, one key less
    assert counted["rows"] == 2 and not strict.ok and loose.ok, (strict, loose)


def test_changed_code_judges_anew(write_profile, tmp_path, counted, monkeypatch):
    profile = load_profile(write_profile(STRICT, "newcomer"))
    criteria.judge(profile, tmp_path)
    monkeypatch.setattr(reuse, "running_code", lambda: "another version of rigcad")
    criteria.judge(profile, tmp_path)
    assert counted["rows"] == 2


@pytest.mark.parametrize("damage", ["deleted", "edited", "not json"])
def test_a_deleted_or_edited_kept_file_judges_anew(write_profile, tmp_path, counted, damage):
    profile = load_profile(write_profile(STRICT, "newcomer"))
    first = criteria.judge(profile, tmp_path)
    path = tmp_path / "newcomer" / criteria.KEPT_FILE
    if damage == "deleted":
        path.unlink()
    elif damage == "edited":  # the failed row turned to a pass, its key intact
        doc = json.loads(path.read_text())
        for row in doc["rows"]:
            row["ok"] = True
        path.write_text(json.dumps(doc))
    else:
        path.write_text("{")
    again = criteria.judge(profile, tmp_path)
    assert counted["rows"] == 2 and again == first, (counted, again)


def test_a_moved_rig_is_judged_as_it_stands_and_never_kept(write_profile, tmp_path, counted):
    """The kept rows are the rig as designed: a rig with a component moved (its projector's pose
    enters the pixel fan) makes its own rows and keeps nothing."""
    rig = Rig.from_profile(load_profile(write_profile(STRICT, "newcomer")))
    criteria.judge(rig, tmp_path)  # as designed: kept
    moved = rig.moved("projector", offset=(0.0, 0.0, 0.5))
    before = (tmp_path / "newcomer" / criteria.KEPT_FILE).read_bytes()
    criteria.judge(moved, tmp_path)
    assert counted["rows"] == 2  # not read from the designed rig's rows
    assert (tmp_path / "newcomer" / criteria.KEPT_FILE).read_bytes() == before  # nor written over them
