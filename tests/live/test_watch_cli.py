"""`rigcad watch` from the command line: what no edit can mend (a profile or printer that is
nowhere, an empty --host that would serve every interface, with --write an exports root that is a
file) is one line and a non-zero exit before anything is served; `--write` publishes the exports
after each good rebuild through `rig.export` (the atomic publication and part cache of `rigcad stl`), so a second edit rebuilds
only the parts it changed."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from .conftest import interruptible

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("argv, named", [
    (["no_such_rig"], "no_such_rig"),
    (["achutha2006", "--printer", "no_such_printer"], "no_such_printer"),
    (["achutha2006", "--host", ""], "--host"),
    (["achutha2006", "--write", "--exports", "a_file"], "a_file"),
], ids=["missing profile", "missing printer", "empty host (every interface)", "exports is a file"])
def test_what_no_edit_can_mend_is_one_line_before_serving(tmp_path, argv, named):
    (tmp_path / "a_file").write_text("not a folder")
    run = subprocess.run([sys.executable, "-m", "rigcad", "watch", *argv, "--port", "0"],
                         capture_output=True, text=True, timeout=120, cwd=tmp_path,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert run.returncode != 0 and "->" not in run.stdout, run.stdout
    errors = [line for line in run.stderr.splitlines() if "error: " in line]  # argparse's usage lines aside
    assert len(errors) == 1 and named in errors[0] and "Traceback" not in run.stderr, run.stderr


@pytest.mark.slow
def test_write_publishes_the_exports_and_rebuilds_only_what_changed(tmp_path):
    profile = tmp_path / "rig.yaml"
    profile.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    exports = tmp_path / "out"
    proc = subprocess.Popen(interruptible("rigcad", "watch", str(profile), "--port", "0", "--write",
                                          "--no-check", "--exports", str(exports)), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)})
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(iter(proc.stdout.readline, "")), daemon=True).start()

    def wrote(count: int) -> list[str]:
        deadline = time.time() + 900
        while len([t for t in lines if "  wrote " in t]) < count and time.time() < deadline:
            assert proc.poll() is None, proc.stderr.read()
            time.sleep(0.1)
        return [t for t in lines if "  wrote " in t]

    try:
        first = wrote(1)[0]
        manifest = json.loads((exports / "rig" / "manifest.json").read_text())
        assert manifest["profile"]["name"] == "rig" and "beam" in manifest["parts"]
        profile.write_text("extends: achutha2006\nbeam:\n  width: 8 mm\n", encoding="utf-8")
        second = wrote(2)[1]
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(60)
    assert re.search(r"wrote .*/rig/: \d+ part\(s\) built, 0 unchanged", first), first
    # the beam, the dome and the paraboloid read beam.width (their slots, their clamp); so does the
    # camera cross that hangs from the beam: the rest of the 17 parts are reused from the first write
    built, reused = map(int, re.search(r"(\d+) part\(s\) built, (\d+) unchanged", second).groups())
    assert 3 <= built <= 4 and built + reused == len(manifest["parts"]), second
    assert proc.returncode == 0
