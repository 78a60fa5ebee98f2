"""`rigcad watch` says each frame once: no "rebuilt nothing" right after it starts, and a profile
that stops reading (a YAML syntax error, whose extends: chain can no longer be read) one error
line, not two. Both came from the same fault: the files' signature taken before a rebuild was
compared with one over the files the rebuild found, a different set, so the loop's first quiet
check saw a change that no one made."""

from __future__ import annotations

import threading
import time

import pytest

from rigcad.live.server import Hub
from rigcad.live.session import LiveSession
from rigcad.live.watch import RUST_TIMEOUT_MS, Watcher

#: How long the loop is left alone to show a spurious frame: the loop compares the files'
#: signature at each quiet RUST_TIMEOUT_MS, so the first such check (where the fault showed) comes
#: within one; four leave room for a loaded machine.
QUIET_S = 4 * RUST_TIMEOUT_MS / 1000


def _wait(condition, what: str, timeout: float = 90) -> None:
    deadline = time.time() + timeout
    while not condition():
        assert time.time() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


@pytest.fixture
def loop(tmp_path):
    path = tmp_path / "lab.yaml"
    path.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    lines: list[str] = []
    watcher = Watcher(LiveSession(path, check=False), Hub(), say=lines.append)
    stop = threading.Event()
    thread = threading.Thread(target=watcher.run, args=(stop,), daemon=True)
    thread.start()
    _wait(lambda: len(watcher.frames) >= 1, "the first build")
    yield watcher, path, lines
    stop.set()
    thread.join(10)
    assert not thread.is_alive()


def test_no_frame_without_an_edit_after_the_start(loop):
    watcher, _, lines = loop
    time.sleep(QUIET_S)
    assert len(lines) == 1, lines  # the first build only: no "rebuilt nothing"


def test_a_syntax_error_is_said_once(loop):
    watcher, path, lines = loop
    time.sleep(QUIET_S)
    path.write_text("extends: achutha2006\nbeam: {width: 6 mm\n", encoding="utf-8")
    _wait(lambda: any("error:" in line for line in lines), "the error frame")
    time.sleep(QUIET_S)
    errors = [line for line in lines if "error:" in line]
    assert len(errors) == 1, lines
    assert "YAML syntax" in errors[0] and "lab.yaml:" in errors[0], errors
    # mended, it rebuilds once more, and says so once
    path.write_text("extends: achutha2006\nbeam:\n  width: 7 mm\n", encoding="utf-8")
    _wait(lambda: len(lines) >= 3, "the mended frame")
    time.sleep(QUIET_S)
    assert len(lines) == 3 and "error:" not in lines[2], lines
