"""The live view's server serves its page and its event stream and nothing else: hostile paths
(traversal, percent-encoded and double-encoded variants, absolute and backslash forms) get a 4xx and
no file is opened while they are answered (an audit hook watches every open, as the hostile-profile
tests do); a foreign Host header (DNS rebinding) gets 403; a port in use gets one line and the next
free port; the stream sends the whole state first, then only the parts that changed."""

from __future__ import annotations

import http.client
import os
import socket
import sys
import threading

import numpy as np
import pytest

from rigcad.live.server import Hub, start
from rigcad.live.session import Frame
from rigcad.manual.assembly import PartMesh

_opened: list[str] = []
_watching = threading.Event()


def _audit(event: str, args) -> None:
    if _watching.is_set() and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        _opened.append(os.fsdecode(args[0]))


sys.addaudithook(_audit)


def _part(name: str, size: float) -> PartMesh:
    v = np.array([[0, 0, 0], [size, 0, 0], [0, size, 0], [0, 0, size]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return PartMesh(name, v, f, (0.5, 0.5, 0.5), name, 1, np.zeros(3))


def _frame(seq: int, sizes: dict[str, float], changed) -> Frame:
    parts = [_part(n, s) for n, s in sizes.items()]
    return Frame(seq, "test", parts, {n: f"{n}-{s}" for n, s in sizes.items()}, tuple(changed), (), (), None,
                 {"theta_min_deg": 7.0}, {}, [{"check": "c", "measured": float("nan"), "ok": False}], False, {}, ())


@pytest.fixture
def server():
    hub = Hub()
    srv = start(hub, b"<!DOCTYPE html><title>page</title>", port=0, say=lambda line: None)
    hub.publish(_frame(1, {"a": 1.0, "b": 2.0}, ["a", "b"]))
    yield srv
    hub.close(timeout=1.0)
    srv.shutdown()
    srv.server_close()


def _raw(srv, request: bytes) -> tuple[int, bytes]:
    """Send ``request`` as bytes (no client library normalises the path) and read the answer."""
    with socket.create_connection(srv.server_address[:2], timeout=5) as s:
        s.sendall(request)
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    return int(data.split(b" ", 2)[1]), data


HOSTILE = ["/../../etc/passwd", "/..%2f..%2fetc%2fpasswd", "/%2e%2e/%2e%2e/etc/passwd", "/%252e%252e%252fetc%252fpasswd",
           "//etc/passwd", "/etc/passwd", "/..\\..\\etc\\passwd", "/./", "/events/../../etc/passwd", "/index.html",
           "/?file=/etc/passwd", "/%00", "/events%00", "http://127.0.0.1/etc/passwd", "*"]


@pytest.mark.parametrize("path", HOSTILE)
def test_hostile_paths_get_4xx_and_open_nothing(server, path):
    port = server.server_address[1]
    _opened.clear()
    _watching.set()
    try:
        code, body = _raw(server, f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
    finally:
        _watching.clear()
    assert 400 <= code < 500, (path, code)
    assert b"root:" not in body
    assert _opened == [], f"{path}: opened {_opened}"


@pytest.mark.parametrize("host", ["evil.example:{port}", "127.0.0.1.evil.example", "localhost", "", "127.0.0.1:1"])
def test_a_foreign_host_header_is_refused(server, host):
    port = server.server_address[1]
    header = f"Host: {host.format(port=port)}\r\n" if host else ""
    for path in ("/", "/events"):
        code, _ = _raw(server, f"GET {path} HTTP/1.1\r\n{header}Connection: close\r\n\r\n".encode())
        assert code == 403, (host, path, code)


def test_own_host_names_are_served(server):
    port = server.server_address[1]
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"LOCALHOST:{port}"):
        code, body = _raw(server, f"GET / HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
        assert code == 200 and b"<title>page</title>" in body
        assert b"Content-Security-Policy: default-src 'none'" in body


def test_other_methods_are_refused(server):
    port = server.server_address[1]
    code, _ = _raw(server, f"POST / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
                   .encode())
    assert code == 405


@pytest.mark.parametrize("method", ["PUT", "DELETE", "TRACE", "CONNECT", "PROPFIND", "get", "Head", "M-SEARCH", "BREW"])
def test_every_unsupported_method_gets_405_as_plain_text(server, method):
    """Methods are case-sensitive: a lowercase ``get`` is not GET. http.server answers a method it has
    no handler for with 501 and an HTML page; the docs say 405."""
    port = server.server_address[1]
    code, data = _raw(server, f"{method} / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
    assert code == 405, (method, data[:200])
    assert b"text/plain" in data and b"<html" not in data.lower()


def test_clients_that_go_away_early_leave_no_traceback(server, capfd):
    """A page closed mid-request (reset, or the request half sent) or mid-stream: ordinary
    disconnects, nothing on the terminal (1,506 tracebacks in one run of watch before)."""
    import struct
    import time

    port = server.server_address[1]
    for request in (b"GET / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n" % port, b"GET /events HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % port,
                    b"GE"):
        for _ in range(20):
            s = socket.create_connection(server.server_address[:2], timeout=5)
            s.sendall(request)
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # close with a reset
            s.close()
    time.sleep(0.5)  # the handler threads meet the resets
    out, err = capfd.readouterr()
    assert "Traceback" not in err and "Error" not in err, err[-2000:]


def test_a_port_in_use_gets_one_line_and_the_next_free_port():
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    port = taken.getsockname()[1]
    said = []
    hub = Hub()
    try:
        srv = start(hub, b"x", port=port, say=said.append)
        try:
            assert srv.server_address[1] > port
            assert len(said) == 1 and f"port {port} is in use" in said[0] and str(srv.server_address[1]) in said[0]
        finally:
            srv.shutdown()
            srv.server_close()
    finally:
        taken.close()


def _events(srv, count: int) -> list[dict]:
    import json

    conn = http.client.HTTPConnection(*srv.server_address[:2], timeout=10)
    conn.request("GET", "/events", headers={"Host": f"127.0.0.1:{srv.server_address[1]}"})
    resp = conn.getresponse()
    assert resp.status == 200 and resp.getheader("Content-Type") == "text/event-stream"
    out = []
    while len(out) < count:
        line = resp.fp.readline().decode()
        if line.startswith("data: "):
            out.append(json.loads(line[6:]))
    conn.close()
    return out


def test_the_stream_sends_the_whole_state_then_only_what_changed(server):
    got = []
    reader = threading.Thread(target=lambda: got.extend(_events(server, 2)))
    reader.start()
    import time

    deadline = time.time() + 10
    while server.hub.streams == 0 and time.time() < deadline:
        time.sleep(0.01)
    server.hub.publish(_frame(2, {"a": 1.0, "b": 3.0}, ["b"]))
    reader.join(10)
    first, second = got
    assert sorted(first["meshes"]) == ["a", "b"] and [p["name"] for p in first["parts"]] == ["a", "b"]
    assert list(second["meshes"]) == ["b"] and second["changed"] == ["b"]
    assert first["rows"][0]["measured"] is None  # NaN travels as null: JSON has no NaN
