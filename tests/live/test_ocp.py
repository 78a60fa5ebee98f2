"""`rigcad watch --ocp` and `rig.show()` with OCP CAD Viewer.

Without a viewer: one line that says how to start one, no traceback, and the browser view runs on.
With one: a minimal viewer of the test's own speaking the viewer's websocket protocol
(ocp_viewer_core.websocket: ``C:`` commands answered with JSON, ``B:`` answered with an ack, ``D:``
the model) reads the model as sent (each part's name, colour and kind: solid, or edges for the
rays). The real standalone viewer (`python -m ocp_viewer`) is tested in test_ocp_viewer.py."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest

from .conftest import closed_port, interruptible

ROOT = Path(__file__).resolve().parents[2]


def test_ocp_without_a_viewer_says_one_line_and_the_browser_view_runs(tmp_path):
    profile = tmp_path / "rig.yaml"
    profile.write_text("extends: achutha2006\n", encoding="utf-8")
    port = closed_port()
    proc = subprocess.Popen(interruptible("rigcad", "watch", str(profile), "--port", "0", "--ocp",
                                          "--ocp-port", str(port), "--no-check"), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": str(ROOT)}, cwd=tmp_path)
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(iter(proc.stdout.readline, "")), daemon=True).start()
    try:
        deadline = time.time() + 120
        while not any(re.match(r"\[1\] rig: rebuilt", line) for line in lines) and time.time() < deadline:
            assert proc.poll() is None, proc.stderr.read()
            time.sleep(0.05)
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(30)
    stderr = proc.stderr.read()
    said = [line for line in lines if "OCP CAD Viewer" in line]
    assert len(said) == 1 and f":{port}" in said[0] and f"python -m ocp_viewer --port {port}" in said[0], lines
    assert "browser view" in said[0]
    assert any(re.match(r"\[1\] rig: rebuilt", line) for line in lines), lines
    assert proc.returncode == 0 and "Traceback" not in stderr, stderr
    assert not (tmp_path / "exports").exists()  # without --write nothing is published


def test_rig_show_without_a_viewer_is_one_clear_error():
    from rigcad.live.ocp import ViewerError
    from rigcad.rig import load

    port = closed_port()
    hint = f"no OCP CAD Viewer on 127.0.0.1:{port}: .*python -m ocp_viewer --port {port}"
    with pytest.raises(ViewerError, match=hint):
        load("achutha2006").show(port=port)


@pytest.mark.slow
def test_the_parts_arrive_at_a_viewer():
    from websockets.sync.server import serve

    models = []

    def viewer(ws):
        for message in ws:
            data = message if isinstance(message, bytes) else message.encode()
            if data[:2] == b"C:":
                ws.send(json.dumps({}))
            elif data[:2] == b"B:":
                ws.send(json.dumps({"ok": True}))
            elif data[:2] == b"D:":
                models.append(json.loads(data[2:]))

    server = serve(viewer, "127.0.0.1", 0, max_size=None)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        from rigcad.rig import load

        rig = load("achutha2006")
        rig.show(port=server.socket.getsockname()[1], rays=20)
    finally:
        server.shutdown()
    assert len(models) == 1
    shown = {p["name"]: p for p in models[0]["data"]["shapes"]["parts"]}
    expected = [p for p in [*rig.recipes.values(), *rig.instruments] if p.in_rig]
    for part in expected:
        colour = "#" + "".join(f"{round(255 * c):02x}" for c in part.color)
        assert shown[part.name]["color"] == colour and shown[part.name]["subtype"] == "solid", part.name
    assert {"cop_marker", "projector_cop_marker", "camera_cop_marker"} <= set(shown)
    assert shown["rays"]["type"] == "edges"
