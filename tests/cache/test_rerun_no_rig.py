"""``rigcad stl`` and ``rigcad fab`` run again with nothing changed build no rig: the ray check's
cheap criteria are read from what the first run kept (rigcad.check.criteria.judged_rows), the export,
the assembly verdict and the fab run from their published records. The rig's building is counted at
its one door (rigcad.rig.Rig.from_profile). The fast tests stand the published export and fab run in
with what their own read-backs return when intact (tests/export, tests/fab/test_stage_reuse.py and
tests/cache/test_command_readback.py test those); the e2e test runs fab itself."""

from __future__ import annotations

import pytest

from rigcad import api
from rigcad.check import criteria
from rigcad.manual import gate
from rigcad.rig import Rig
from tests.cache.test_command_readback import run_cli


@pytest.fixture
def rigs(monkeypatch) -> dict:
    calls = {"n": 0}
    real = Rig.from_profile.__func__

    def counted(cls, *args, **kwargs):
        calls["n"] += 1
        return real(cls, *args, **kwargs)

    monkeypatch.setattr(Rig, "from_profile", classmethod(counted))
    return calls


def test_stl_up_to_date_builds_no_rig_once_the_criteria_are_kept(tmp_path, monkeypatch, rigs):
    monkeypatch.setattr(api, "export_up_to_date", lambda profile, folder: True)
    monkeypatch.setattr(gate, "read_verdict", lambda root, profile: gate.Verdict(profile.name, order=("a",)))
    ex = str(tmp_path / "exports")
    code, out, err = run_cli("stl", "achutha2006", "--exports", ex)
    assert code == 0 and "up to date" in out and rigs["n"] == 1, (out, err)  # the criteria judged: one rig
    again = run_cli("stl", "achutha2006", "--exports", ex)
    assert again == (code, out, err) and rigs["n"] == 1  # the same words, no rig
    (tmp_path / "exports" / "achutha2006" / criteria.KEPT_FILE).unlink()
    assert run_cli("stl", "achutha2006", "--exports", ex) == (code, out, err) and rigs["n"] == 2


def test_fab_read_back_builds_no_rig_once_the_criteria_are_kept(tmp_path, monkeypatch, rigs):
    from rigcad.fab.published import FabResult

    report = {"totals": {"pieces": 0}, "parts": {}}
    monkeypatch.setattr(gate, "kept_gate", lambda root, profile: True)
    monkeypatch.setattr(api, "fab_published", lambda *a, **k: FabResult(report, [], reused=True))
    ex = str(tmp_path / "exports")
    first = run_cli("fab", "achutha2006", "--printer", "prusa_mk3s", "--exports", ex)
    assert first[0] == 0 and rigs["n"] == 1, first  # the criteria judged: one rig
    assert run_cli("fab", "achutha2006", "--printer", "prusa_mk3s", "--exports", ex) == first and rigs["n"] == 1


@pytest.mark.e2e  # the assembly gate on the whole rig and fab of the beam: ~30 s
def test_fab_again_reads_back_with_no_rig(tmp_path, rigs):
    ex = str(tmp_path / "exports")
    args = ("fab", "achutha2006", "--printer", "prusa_mk3s", "--parts", "beam", "--exports", ex)
    code, out, err = run_cli(*args)
    assert code == 0 and rigs["n"] >= 1, err[-2000:]
    built = rigs["n"]
    again = run_cli(*args)
    assert again[0] == 0 and again[1] == out and rigs["n"] == built, (rigs, again[2][-2000:])  # no rig built
