"""`rig.show()` and `rigcad watch --ocp` with the real standalone OCP CAD Viewer.

Since ocp_vscode 4.2 the standalone viewer is the `ocp_viewer` package (`python -m ocp_viewer`). It
is a websocket server that relays each model to the browser page it serves and keeps nothing one
could read back, so the test opens that page in a headless chromium (Debian's, through playwright)
and reads what the viewer shows: the navigation tree's nodes (`data-path` /Group/<name>, the colour
dot beside each name, the faces/edges state: a solid has faces, the rays are edges only) and the
same tree as the viewer reports it to any client (`ocp_vscode.status(port)["states"]`, which the page
sends back after it has drawn the model). The viewer runs in a subprocess on a free port with HOME
set to the test's folder (its port registry and config file stay there), and is stopped (SIGINT,
then kill) whatever the test does."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import pytest

from .conftest import CHROMIUM, CHROMIUM_ARGS, closed_port, interruptible

ROOT = Path(__file__).resolve().parents[2]
MARKERS = {"cop_marker", "projector_cop_marker", "camera_cop_marker"}
#: The tree's nodes as the page shows them: path, faces state, edges state, colour of the name's dot.
#: The tree draws only the rows in view, so each row is scrolled into view before it is read.
TREE_JS = """async () => {
    const rows = [];
    for (const path of Array.from(document.querySelectorAll('.tv-tree-node[data-path]'), n => n.dataset.path)) {
        const find = () => document.querySelector(`.tv-tree-node[data-path="${CSS.escape(path)}"]`);
        if (!find().querySelector('.tv-node-label')) {
            find().scrollIntoView();
            await new Promise(done => requestAnimationFrame(() => requestAnimationFrame(done)));
        }
        const node = find(), dot = node.querySelector(':scope > .tv-node-content .tv-node-label span');
        rows.push([path, node.dataset.state0, node.dataset.state1, dot ? dot.getAttribute('style') : null]);
    }
    return rows;
}"""

pytestmark = pytest.mark.slow


class Lines:
    """A subprocess's merged output, collected line by line as it comes."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.proc, self.lines = proc, []
        threading.Thread(target=lambda: self.lines.extend(iter(proc.stdout.readline, "")), daemon=True).start()

    def wait(self, pattern: str, timeout: float = 120, count: int = 1) -> None:
        deadline = time.time() + timeout
        while time.time() < deadline:
            if sum(bool(re.search(pattern, line)) for line in list(self.lines)) >= count:
                return
            assert self.proc.poll() is None, f"exited {self.proc.returncode}: {self.lines}"
            time.sleep(0.05)
        raise AssertionError(f"{count} line(s) matching {pattern!r} not seen; got {self.lines}")


class Drawn:
    """Counts the models the viewer's page has drawn (its console says "showViewer finished")."""

    def __init__(self, page) -> None:
        self.page, self.count = page, 0
        page.on("console", self._saw)

    def _saw(self, message) -> None:
        self.count += message.text.startswith("showViewer finished")

    def wait(self, count: int, timeout: float = 120) -> None:
        deadline = time.time() + timeout
        while self.count < count:
            assert time.time() < deadline, f"the page drew {self.count} model(s), not {count}"
            self.page.wait_for_timeout(100)  # lets playwright deliver the console events


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture
def viewer(tmp_path):
    """`python -m ocp_viewer` on a free loopback port, with a headless chromium showing its page;
    yields (port, the viewer's output lines, the page, Drawn)."""
    if not CHROMIUM.is_file():
        pytest.fail(f"{CHROMIUM} is missing: `make tools` installs Debian's chromium (apt-get)")
    from playwright.sync_api import sync_playwright

    port = closed_port()
    home = tmp_path / "home"
    home.mkdir()
    proc = subprocess.Popen(interruptible("ocp_viewer", "--host", "127.0.0.1", "--port", str(port)),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=tmp_path,
                            env={**os.environ, "HOME": str(home), "PYTHONUNBUFFERED": "1"})
    out = Lines(proc)
    try:
        out.wait(rf"OCP Viewer runs at http://127\.0\.0\.1:{port}", timeout=60)
        with sync_playwright() as p, tempfile.TemporaryDirectory() as profile_dir:
            ctx = p.chromium.launch_persistent_context(profile_dir, executable_path=str(CHROMIUM), headless=True,
                                                       args=CHROMIUM_ARGS, viewport={"width": 1000, "height": 700})
            try:
                page = ctx.new_page()
                drawn = Drawn(page)
                page.goto(f"http://127.0.0.1:{port}/viewer")
                out.wait("Browser as viewer client registered", timeout=60)
                drawn.wait(1)  # the viewer's splash (its logo)
                yield port, out, page, drawn
            finally:
                ctx.close()
    finally:
        _stop(proc)
    assert proc.returncode == 0, out.lines  # stopped by SIGINT, not killed


def _tree(page, names: set[str], timeout: float = 30) -> dict[str, tuple]:
    """The page's tree once every one of ``names`` is in it: name -> (faces, edges, dot style)."""
    deadline = time.time() + timeout
    while True:
        nodes = {path.rsplit("/", 1)[1]: (s0, s1, dot) for path, s0, s1, dot in page.evaluate(TREE_JS)
                 if path.count("/") == 2}
        if names <= set(nodes) or time.time() > deadline:
            return nodes
        time.sleep(0.2)


def _expected(rig) -> dict[str, str]:
    """name -> #rrggbb of the parts the rig shows (in-rig parts and instruments)."""
    return {p.name: "#" + "".join(f"{round(255 * c):02x}" for c in p.color)
            for p in [*rig.recipes.values(), *rig.instruments] if p.in_rig}


def _check_arrived(page, port: int, rig) -> None:
    from ocp_vscode import status

    expected = _expected(rig)
    tree = _tree(page, {*expected, "rays"})
    assert set(tree) == {*expected, "rays"}, sorted(set(tree) ^ {*expected, "rays"})
    assert MARKERS <= set(tree)
    for name, colour in expected.items():
        faces, edges, dot = tree[name]
        assert (faces, edges) == ("1", "1") and dot == f"color:{colour}", (name, tree[name], colour)
    assert tree["rays"][:2] == ("3", "1"), tree["rays"]  # edges only: no faces to show
    # the same tree as the viewer itself reports it to a client (sent back by the page once drawn)
    states = status(port=port)["states"]
    assert {path.rsplit("/", 1)[1] for path in states} == set(tree), states


def test_rig_show_reaches_the_standalone_viewer(viewer):
    from rigcad.rig import load

    port, out, page, drawn = viewer
    rig = load("achutha2006")
    rig.show(port=port, rays=20)
    drawn.wait(2)
    _check_arrived(page, port, rig)


def test_watch_ocp_pushes_each_edit_to_the_standalone_viewer(viewer, tmp_path):
    from rigcad.rig import load

    port, out, page, drawn = viewer
    profile = tmp_path / "rig.yaml"
    profile.write_text("extends: achutha2006\nbeam:\n  width: 6 mm\n", encoding="utf-8")
    watch = subprocess.Popen(interruptible("rigcad", "watch", str(profile), "--port", "0", "--ocp",
                                           "--ocp-port", str(port), "--no-check"), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)})
    said = Lines(watch)
    try:
        said.wait(r"\[1\] rig: rebuilt")
        drawn.wait(2)
        _check_arrived(page, port, load(profile))
        profile.write_text("extends: achutha2006\nbeam:\n  width: 14 mm\n", encoding="utf-8")
        said.wait(r"\[2\] rig: rebuilt")
        drawn.wait(3, timeout=90)
    finally:
        _stop(watch)
    assert watch.returncode == 0 and not any("OCP CAD Viewer" in line or "Traceback" in line
                                             for line in said.lines), said.lines
