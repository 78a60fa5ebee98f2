"""The newcomer's hardware (tests/cli/newcomer/: a 2448 x 2048 camera of 3.45 um pixels with a 12 mm
lens, a 1280 x 720 DLP pico projector, a Bambu Lab X1 Carbon with no PrusaSlicer presets, the
Creality Ender-3 by its preset name) from `design` to `manual`, as a user runs it: each stage either
succeeds or refuses early, in one line naming the key to change, writing nothing of its own. A stage
that refuses what `design` passed refuses late: that fails here."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

from rigcad.cli import main

pytestmark = [pytest.mark.e2e, pytest.mark.slow]  # stl, check, two fabs and the manual: minutes

NEWCOMER = Path(__file__).parent / "newcomer"
ENDER = "Creality Ender-3 (0.4 mm nozzle)"
KEY = re.compile(r"\b(projector|camera|tower|beam_splitter|adjusters|alignment_pin|layout|paraboloid|dome_shell|"
                 r"raycheck|targets|tolerancing|slicer|lens|datum|base_plate|sample_holder)\.[a-z_]+")


def _run(*args) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("RIGCAD_PROFILES", str(NEWCOMER))
        yield tmp_path_factory.mktemp("newcomer")


def _ok_or_early(code: int, err: str, folder: Path) -> None:
    """Success, or one error line naming a key with nothing written in the stage's own folder."""
    if code == 0:
        return
    lines = [line for line in err.splitlines() if line.startswith("rigcad: error:")]
    assert code == 1 and lines and KEY.search(err), err
    assert not folder.exists() or not any(folder.iterdir()), f"{folder} written by a refused stage"


def test_design_passes_the_newcomers_rig(exports):
    code, out, err = _run("design", "mylab", "--exports", str(exports))
    assert code == 0, err
    assert "390 px across, 19% of the 2048 px short side" in out  # the 12 mm lens's fill


def test_stl_builds_what_design_passed(exports):
    """The pico's low body (projector.pupil_height 20 mm) raises the shelf, and the splitter holder on
    it, to the plate's lowest edge: the assembly gate must still find the plate a way in (the holder's
    +y spring bolt behind the plate, its flange notched: tests/parts/test_tower_low_projector.py)."""
    code, _, err = _run("stl", "mylab", "--exports", str(exports))
    assert code == 0, err  # design passed it: a refusal here is late


def test_check_passes_or_names_a_key(exports):
    code, _, err = _run("check", "mylab", "--exports", str(exports))
    _ok_or_early(code, err, exports / "mylab" / "check")


def test_the_x1c_without_presets_gets_no_gcode_but_its_pieces(exports):
    folder = exports / "mylab" / "fab" / "bambu_x1c"
    code, _, err = _run("fab", "mylab", "--printer", "bambu_x1c", "--gcode", "--exports", str(exports))
    assert code != 0 and "has no PrusaSlicer presets" in err and "bed at 0 C" in err, err
    assert not folder.exists()
    code, _, err = _run("fab", "mylab", "--printer", "bambu_x1c", "--exports", str(exports))
    _ok_or_early(code, err, folder)


def test_the_ender3_by_its_preset_name(exports):
    code, _, err = _run("fab", "mylab", "--printer", ENDER, "--exports", str(exports))
    _ok_or_early(code, err, exports / "mylab" / "fab" / "creality_ender_3_0_4_mm_nozzle")


def test_manual_on_the_x1c(exports):
    code, _, err = _run("manual", "mylab", "--printer", "bambu_x1c", "--exports", str(exports))
    _ok_or_early(code, err, exports / "mylab" / "manual" / "bambu_x1c")
