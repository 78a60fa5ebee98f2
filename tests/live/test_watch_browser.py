"""`rigcad watch` end to end, in a real browser (Debian's chromium driven by playwright, as the view
test does): the page loads from the watcher's server and asks nothing of anyone else; editing
beam.width advances the frame counter, changes the beam's pixels and rebuilds nothing but the
parts that read beam.width; an unknown key shows the message with file:line while the old rig
stays; fixing it brings the rig back; Ctrl-C (SIGINT) stops the watcher cleanly and the page says
"disconnected". Playwright's polling evaluates strings, which the page's own policy forbids, so
the browser is told to bypass the policy; the policy header itself is checked on the response and
no request may leave for anywhere but the watcher's server.""" 

from __future__ import annotations

import io
import os
import re
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from .conftest import CHROMIUM, CHROMIUM_ARGS, interruptible

#: Whole commands or the whole rig: `make test-e2e` (and CI) runs these, `make test` does not.
pytestmark = pytest.mark.e2e

BACKGROUND = np.array([0xF4, 0xF4, 0xF4])
#: A pixel is drawn (not background) when its RGB channels differ from it by more than this sum.
PIXEL_DIFF = 30
ROOT = Path(__file__).resolve().parents[2]


class Watch:
    """``rigcad watch`` in a subprocess; its stdout lines collected as they come."""

    def __init__(self, profile: Path, *args: str) -> None:
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        self.proc = subprocess.Popen(interruptible("rigcad", "watch", str(profile), *args),
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                                     cwd=profile.parent)
        self.lines: list[str] = []
        threading.Thread(target=lambda: self.lines.extend(iter(self.proc.stdout.readline, "")), daemon=True).start()

    def wait_line(self, pattern: str, timeout: float = 120) -> str:
        deadline = time.time() + timeout
        while time.time() < deadline:
            for line in list(self.lines):
                if re.search(pattern, line):
                    return line
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise AssertionError(f"no line matching {pattern!r}; got {self.lines}; stderr: "
                             f"{self.proc.stderr.read() if self.proc.poll() is not None else ''}")

    def stop(self) -> tuple[int, str]:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(30)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode, self.proc.stderr.read()


def _drawn(page) -> int:
    """Pixels of the canvas that differ from the background, the panels above it hidden meanwhile."""
    from PIL import Image

    page.evaluate("for (const id of ['panel', 'report']) document.getElementById(id).style.visibility = 'hidden'")
    _next_frame(page)
    shot = np.asarray(Image.open(io.BytesIO(page.locator("canvas").screenshot())).convert("RGB")).astype(int)
    page.evaluate("for (const id of ['panel', 'report']) document.getElementById(id).style.visibility = ''")
    return int((np.abs(shot - BACKGROUND).sum(axis=2) > PIXEL_DIFF).sum())


def _next_frame(page) -> None:
    page.evaluate("() => new Promise(done => requestAnimationFrame(() => requestAnimationFrame(done)))")


def test_edit_error_fix_and_stop_in_chromium(tmp_path):
    if not CHROMIUM.is_file():
        pytest.fail(f"{CHROMIUM} is missing: `make tools` installs Debian's chromium (apt-get)")
    from playwright.sync_api import sync_playwright

    profile = tmp_path / "rig.yaml"
    profile.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    watch = Watch(profile, "--port", "0")
    refused, errors = [], []
    try:
        url = re.search(r"(http://127\.0\.0\.1:\d+/)", watch.wait_line(r"-> http://")).group(1)
        with sync_playwright() as p, tempfile.TemporaryDirectory() as profile_dir:
            ctx = p.chromium.launch_persistent_context(profile_dir, executable_path=str(CHROMIUM), headless=True,
                                                       args=CHROMIUM_ARGS, viewport={"width": 900, "height": 700},
                                                       bypass_csp=True)  # playwright's polling evaluates strings
            try:
                ctx.route("**/*", lambda r: r.continue_() if r.request.url.startswith(url)
                          else (refused.append(r.request.url), r.abort()))
                page = ctx.new_page()
                page.on("pageerror", lambda e: errors.append(str(e)))
                response = page.goto(url)
                csp = response.headers["content-security-policy"]
                assert csp.startswith("default-src 'none'") and "connect-src 'self'" in csp, csp
                page.wait_for_function("window.rigcad && window.rigcad.state.rows !== null", timeout=120_000)
                assert page.evaluate("window.rigcad.webgl")
                _scenario(page, profile, watch)
                code, stderr = watch.stop()
                assert code == 0 and "Traceback" not in stderr, stderr
                assert watch.lines[-1].strip() == "rigcad watch: stopped"
                page.wait_for_function("window.rigcad.state.status === 'disconnected'", timeout=30_000)
                assert "disconnected" in page.inner_text("#status")
            finally:
                ctx.close()
    finally:
        watch.stop()
    assert refused == [], refused
    assert errors == [], errors


def _scenario(page, profile: Path, watch: Watch) -> None:
    names = page.evaluate("window.rigcad.parts()")
    assert "beam" in names and "dome" in names
    for name in [*names, "rays"]:
        if name != "beam":
            page.evaluate(f"window.rigcad.setVisible('{name}', false)")
    _next_frame(page)
    narrow = _drawn(page)
    keys = {n: page.evaluate(f"window.rigcad.key('{n}')") for n in names}
    seq = page.evaluate("window.rigcad.seq()")

    profile.write_text("extends: achutha2006\nbeam:\n  width: 14 mm\n", encoding="utf-8")
    page.wait_for_function(f"window.rigcad.seq() > {seq} && window.rigcad.key('beam') !== '{keys['beam']}'",
                           timeout=60_000)
    _next_frame(page)
    wide = _drawn(page)
    # the beam alone on screen, 6 -> 14 mm wide: its top face more than doubles; 1.3x is far from noise
    assert wide > 1.3 * narrow > 0, (narrow, wide)
    line = watch.wait_line(r"rebuilt rays, 3 part\(s\)")
    assert set(line.split("part(s): ")[1].split(" (")[0].split(", ")) == {"dome", "paraboloid", "beam"}, line
    changed = {n for n in names if page.evaluate(f"window.rigcad.key('{n}')") != keys[n]}
    assert changed == {"dome", "paraboloid", "beam"}  # the parts with beam slots or a clamp: the rest stay
    assert set(page.evaluate("window.rigcad.highlighted()")) == changed

    seq = page.evaluate("window.rigcad.seq()")
    beam_key = page.evaluate("window.rigcad.key('beam')")
    profile.write_text("extends: achutha2006\nbeam:\n  widht: 10 mm\n", encoding="utf-8")
    page.wait_for_function("window.rigcad.state.error !== null", timeout=60_000)
    assert page.is_visible("#error")
    shown = page.inner_text("#error")
    assert f"{profile.name}:3" in shown and "widht" in shown and "last good rig" in shown, shown
    assert page.evaluate("window.rigcad.key('beam')") == beam_key and page.evaluate("window.rigcad.parts()") == names

    profile.write_text("extends: achutha2006\nbeam:\n  width: 10 mm\n", encoding="utf-8")
    page.wait_for_function(f"window.rigcad.state.error === null && window.rigcad.key('beam') !== '{beam_key}'",
                           timeout=60_000)
    assert not page.is_visible("#error")
