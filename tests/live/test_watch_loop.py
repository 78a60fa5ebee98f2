"""The watch loop sees every way an editor saves: in place, by writing a new file and renaming it
over the old one (most editors, atomically), and by moving the old file away first (vim's
backup); a burst of writes is one rebuild; an edit of a file the profile extends rebuilds, and
when the extends: chain changes the loop watches the new parent."""

from __future__ import annotations

import os
import threading
import time

import pytest

from rigcad.live.server import Hub
from rigcad.live.session import LiveSession
from rigcad.live.watch import STEP_MS, Watcher


@pytest.fixture
def loop(tmp_path):
    path = tmp_path / "rig.yaml"
    path.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    watcher = Watcher(LiveSession(path, check=False), Hub(), say=lambda line: None)
    stop = threading.Event()
    thread = threading.Thread(target=watcher.run, args=(stop,), daemon=True)
    thread.start()
    _wait(lambda: len(watcher.frames) >= 1, "the first build")
    time.sleep(0.3)  # the watch is armed once the first build has been published
    yield watcher, path
    stop.set()
    thread.join(10)
    assert not thread.is_alive()


def _wait(condition, what: str, timeout: float = 60) -> None:
    deadline = time.time() + timeout
    while not condition():
        assert time.time() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def _beam(watcher) -> float:
    beam = next(m for m in watcher.session.good.parts if m.name == "beam")
    return float(beam.vertices[:, 1].max() - beam.vertices[:, 1].min())


def test_saves_in_place_by_rename_and_by_backup_each_rebuild(loop):
    watcher, path = loop
    for width, save in ((7, "in place"), (8, "rename"), (9, "backup")):
        before = len(watcher.frames)
        text = f"extends: achutha2006\nbeam:\n  width: {width} mm\n"
        if save == "in place":
            path.write_text(text, encoding="utf-8")
        elif save == "rename":  # a new file beside it, renamed over it
            tmp = path.with_name(".rig.yaml.swp-new")
            tmp.write_text(text, encoding="utf-8")
            os.replace(tmp, path)
        else:  # the old file moved away, a new one written, the backup removed
            backup = path.with_name("rig.yaml~")
            os.replace(path, backup)
            path.write_text(text, encoding="utf-8")
            backup.unlink()
        _wait(lambda: len(watcher.frames) > before and abs(_beam(watcher) - width) < 1e-9, f"{save} save")


def test_a_burst_of_writes_is_one_rebuild(loop):
    watcher, path = loop
    before = len(watcher.frames)
    t0 = time.perf_counter()
    for width in (7.1, 7.2, 7.3, 7.4, 7.5):  # an editor writing in chunks, back to back
        path.write_text(f"extends: achutha2006\nbeam:\n  width: {width} mm\n", encoding="utf-8")
    span = time.perf_counter() - t0
    _wait(lambda: len(watcher.frames) > before and abs(_beam(watcher) - 7.5) < 1e-9, "the last write")
    time.sleep(1.0)  # anything the burst would still trigger
    rebuilds = len(watcher.frames) - before
    if span < STEP_MS / 1000:  # the writes came closer together than the quiet time that ends a burst
        assert rebuilds == 1, watcher.frames[before:]
    else:  # a loaded machine spread the writes out (measured span in the message): still grouped
        assert rebuilds < 5, (span, watcher.frames[before:])


def test_the_extends_chain_is_followed(loop):
    watcher, path = loop
    parent = path.with_name("parent.yaml")
    parent.write_text("extends: achutha2006\nbeam:\n  width: 10 mm\n", encoding="utf-8")
    path.write_text("extends: parent\n", encoding="utf-8")
    _wait(lambda: abs(_beam(watcher) - 10) < 1e-9, "the new parent")
    assert parent.resolve() in watcher.session.files
    # written at once, maybe before the watch has restarted on the new chain: still seen
    parent.write_text("extends: achutha2006\nbeam:\n  width: 11 mm\n", encoding="utf-8")  # only the parent changes
    _wait(lambda: abs(_beam(watcher) - 11) < 1e-9, "an edit of the parent")


def test_a_refused_write_is_one_line_and_the_watch_goes_on(tmp_path):
    """--write into an exports folder where the profile's folder is a planted symbolic link: the
    publication refuses (export.atomic), the watcher says so in one line and keeps the rig."""
    path = tmp_path / "rig.yaml"
    path.write_text("extends: achutha2006\n", encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "elsewhere").mkdir()
    (out / "rig").symlink_to(tmp_path / "elsewhere")
    lines: list[str] = []
    watcher = Watcher(LiveSession(path, check=False), Hub(), say=lines.append, write=out)
    watcher.rebuild()
    refused = [line for line in lines if line.startswith("  not written: ")]
    assert len(refused) == 1 and "link" in refused[0], lines
    assert watcher.session.good is not None and list((tmp_path / "elsewhere").iterdir()) == []


@pytest.fixture
def named_loop(tmp_path, monkeypatch):
    """The loop on a profile named (``w1``, found in ./profiles), as `rigcad watch w1` runs it."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "profiles" / "w1.yaml"
    path.parent.mkdir()
    path.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    watcher = Watcher(LiveSession("w1", check=False), Hub(), say=lambda line: None)
    stop = threading.Event()
    thread = threading.Thread(target=watcher.run, args=(stop,), daemon=True)
    thread.start()
    _wait(lambda: len(watcher.frames) >= 1, "the first build")
    time.sleep(0.3)
    yield watcher, path
    stop.set()
    thread.join(10)
    assert not thread.is_alive()


@pytest.mark.parametrize("which", ["named", "path"])
def test_a_link_renamed_over_the_profile_is_read_and_the_real_file_back_is_seen(request, tmp_path, which):
    """``ln -s elsewhere/other.yaml .l && mv -Tf .l w1.yaml``: the link is read as data (its rig
    shown); a link to a file that is no profile is an error frame that quotes nothing of it; the real
    file renamed back over the link brings a frame (the watch stays on the profile's own path)."""
    watcher, path = request.getfixturevalue("named_loop" if which == "named" else "loop")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "other.yaml").write_text("extends: achutha2006\nbeam:\n  width: 12 mm\n", encoding="utf-8")
    (elsewhere / "secret.yaml").write_text("root:x:0:0:root:/root:/bin/bash\n", encoding="utf-8")
    for target, width in ((elsewhere / "other.yaml", 12), (None, 13), (elsewhere / "secret.yaml", None), (None, 13)):
        time.sleep(1.5)  # a user's pause: the watch has settled on the files the last frame read
        before = len(watcher.frames)
        if target is None:  # the real file, saved by rename over the link
            real = path.with_name(".profile.new")
            real.write_text("extends: achutha2006\nbeam:\n  width: 13 mm\n", encoding="utf-8")
            os.replace(real, path)
        else:
            link = path.with_name(".l")
            link.unlink(missing_ok=True)
            link.symlink_to(target)
            os.replace(link, path)
        if width is None:
            _wait(lambda: len(watcher.frames) > before and watcher.frames[-1]["error"], "the error frame", timeout=20)
            assert "root:x" not in watcher.frames[-1]["error"]
        else:
            _wait(lambda: len(watcher.frames) > before and abs(_beam(watcher) - width) < 1e-9, f"width {width}",
                  timeout=20)
    assert not path.is_symlink()
