"""The newcomer's hardware (tests/cli/newcomer/: a 720p DLP pico projector on three M3 case screws, a
2448 x 2048 camera with the 12 mm lens) as `rigcad design` judges it before any solid: the projector's
screws that `stl`'s bill used to refuse late ("check projector.mount_depth", whatever the cause) are
refused by design, naming the key and the value that passes."""

from __future__ import annotations

from pathlib import Path

import pytest

NEWCOMER = Path(__file__).parent / "newcomer"


@pytest.fixture
def refusals(tmp_path, monkeypatch):
    """The early refusals (rigcad.manual.gate.early_refusals) of mylab with ``extra`` YAML added."""
    monkeypatch.setenv("RIGCAD_PROFILES", str(NEWCOMER))
    from rigcad.manual.gate import early_refusals
    from rigcad.profile import load_profile
    from rigcad.rig import load

    def run(extra: str) -> list[str]:
        path = tmp_path / "lab.yaml"
        path.write_text("extends: mylab\n" + extra)
        return [r.line() for r in early_refusals(load(load_profile(str(path))))]

    return run


def test_the_fixture_passes_design(refusals):
    assert refusals("") == []


def test_a_stack_too_thick_for_the_longest_screw_names_the_travel(refusals):
    """At the default 6 mm of travel across, 12 shims a stack: 25.35 mm through, and the longest M3
    screw sold (30 mm) does not reach 5 mm into the socket; 5 mm of travel (10 shims) passes."""
    lines = refusals("tower:\n  travel_across: 6 mm\n")
    assert len(lines) == 1, lines
    assert lines[0].startswith("the tower's hardware: ") and "lab.yaml:3" in lines[0]
    assert "longest stocked M3 screw (30 mm)" in lines[0] and "stack of 12 shims" in lines[0]
    assert "valid: tower.travel_across at most 5 mm (10 shims a stack)" in lines[0]
    assert "projector.mount_thread" in lines[0]


def test_a_shallow_socket_names_the_depth_that_passes(refusals):
    """A 4 mm deep thread: every screw that reaches 5 mm into it bottoms out; the refusal names the
    shallowest socket every stack's screw fits (5.2 mm, extra washers taking up the rest) and passes there."""
    lines = refusals("projector:\n  mount_depth: 4 mm\n")
    assert len(lines) == 1, lines
    assert "lab.yaml:3" in lines[0] and "valid: projector.mount_depth at least 5.2 mm" in lines[0]
    assert refusals("projector:\n  mount_depth: 5.2 mm\n") == []
    assert refusals("projector:\n  mount_depth: 5.1 mm\n") != []
