"""The live view's server: a small HTTP server on 127.0.0.1 that serves two things, its page (``/``)
and a stream of server-sent events (``/events``), from memory. No route reads a file, so no path
can reach one: anything but those two exact paths is a 404, whatever it encodes. A request whose
``Host`` header is not this server's own address (a DNS-rebinding page that resolved its name to
127.0.0.1) is refused with 403; methods other than GET and HEAD with 405 (every one, whatever its
name). A client that disconnects early is silent: no traceback on the watcher's terminal.

:class:`Hub` holds what a newly connected page needs (every part's mesh, the rays, the rows) and
the recent deltas; :func:`frame_message` turns a :class:`rigcad.live.session.Frame` into the JSON
a page applies. Python's standard library only (http.server), threads: one per connection.
"""

from __future__ import annotations

import errno
import json
import socket
import threading
import time
from collections import deque
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import numpy as np

from rigcad.errors import RigcadError

#: Address the server binds by default: this machine only.
DEFAULT_HOST = "127.0.0.1"
#: Port tried first; when it is taken, the next ones (up to PORT_TRIES in all).
DEFAULT_PORT = 8765
PORT_TRIES = 50
#: Seconds between keep-alive comments on an idle event stream (a proxy or browser drops silent ones).
KEEPALIVE_S = 15.0
#: Deltas kept for pages that are a few frames behind; further behind, they get the whole state again.
HISTORY = 8


class ServerError(RigcadError):
    """The live view's server could not start (no free port, an address that cannot be bound)."""


def _rays_message(rays: dict | None) -> dict | None:
    """The rays as line segments with their colours (manual.view.ray_segments), float32 base64."""
    if rays is None:
        return None
    from rigcad.manual.view import b64, ray_segments

    seg, colours = ray_segments(rays)
    return {"key": rays.get("key"), "positions": b64(seg, "<f4"), "colors": b64(colours, "<f4"),
            "count": int(len(rays["lines"])), "traced": int(rays["traced"])}


def _finite(value):
    """``value`` with every NaN or infinity (a check row that measured nothing) as None: JSON has none."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def mesh_message(mesh) -> dict:
    """A part's picture mesh (assembly.PartMesh) for the page: base64 float32 positions, uint32 indices."""
    from rigcad.manual.view import b64

    return {"positions": b64(mesh.vertices, "<f4"), "indices": b64(mesh.faces, "<u4")}


def frame_message(frame, meshes_for, rays: bool, encode=mesh_message) -> dict:
    """The JSON-ready message of ``frame``: every part's description, the meshes of the parts in
    ``meshes_for`` (``encode``: mesh_message or a cache of it), the rays when ``rays``, figures with
    their change, rows, timings and the error."""
    from rigcad.live.session import HEADLINE
    from rigcad.manual.assembly import SEE_THROUGH_OPACITY, encloses, hex_color

    see_through = encloses(frame.parts) if frame.parts else set()
    parts, meshes = [], {}
    for m in frame.parts:
        parts.append({"name": m.name, "key": frame.keys.get(m.name), "color": hex_color(m.color), "quantity": m.quantity,
                      "description": m.description, "opacity": SEE_THROUGH_OPACITY if m.name in see_through else 1.0})
        if m.name in meshes_for:
            meshes[m.name] = encode(m)
    figures = [{"key": k, "label": label, "unit": unit, "value": frame.figures.get(k), "delta": frame.deltas.get(k)}
               for k, (label, unit, _) in HEADLINE.items() if k in frame.figures]
    return {"seq": frame.seq, "profile": frame.profile, "error": frame.error, "parts": parts, "meshes": meshes,
            "changed": list(frame.changed), "moved": list(frame.moved), "removed": list(frame.removed),
            "rays": _rays_message(frame.rays) if rays else None, "figures": _finite(figures),
            "rows": _finite(frame.rows),
            "check_pending": frame.check_pending, "timings": _finite(frame.timings),
            "printers": {n: {k: v for k, v in p.items() if k != "key"} for n, p in frame.printers.items()}}


class Hub:
    """The frames a page is sent: the whole state for a page that connects (or fell behind), the
    deltas for pages that keep up. Thread-safe; :meth:`close` ends every stream with a ``bye``."""

    def __init__(self) -> None:
        self._cond = threading.Condition()
        self._full: tuple[int, str] | None = None
        self._deltas: deque[tuple[int, str]] = deque(maxlen=HISTORY)
        self._id = 0
        self.closed = False
        self.streams = 0
        self._rays_key = None
        self._encoded: dict[str, dict] = {}

    def publish(self, frame) -> float:
        """Make ``frame`` the current state and wake the streams; returns the seconds it took."""
        t0 = time.perf_counter()
        everything = {m.name for m in frame.parts}
        encoded = {}

        def encode(mesh) -> dict:  # each part's mesh encoded once while its key stays the same
            key = frame.keys.get(mesh.name)
            encoded[key] = self._encoded.get(key) or mesh_message(mesh)
            return encoded[key]

        full = json.dumps(frame_message(frame, everything, True, encode), separators=(",", ":"), allow_nan=False)
        delta = json.dumps(frame_message(frame, set(frame.changed), self._rays_changed(frame), encode),
                           separators=(",", ":"), allow_nan=False)
        self._encoded = encoded
        with self._cond:
            self._id += 1
            self._full = (self._id, full)
            self._deltas.append((self._id, delta))
            self._cond.notify_all()
        return time.perf_counter() - t0

    def _rays_changed(self, frame) -> bool:
        key = frame.rays.get("key") if frame.rays else None
        changed = key != self._rays_key
        self._rays_key = key
        return changed

    def close(self, timeout: float = 2.0) -> None:
        """End every stream (each sends ``bye``); wait up to ``timeout`` s for them to have sent it."""
        with self._cond:
            self.closed = True
            self._cond.notify_all()
            self._cond.wait_for(lambda: self.streams == 0, timeout)

    def opened(self, delta: int) -> None:
        """Count a stream opening (+1) or ending (-1)."""
        with self._cond:
            self.streams += delta
            self._cond.notify_all()

    def next_after(self, last: int, timeout: float) -> tuple[int, str] | None:
        """The message a stream that has sent up to id ``last`` sends next (the whole state when it
        has sent nothing or fell behind), or None after ``timeout`` s or once closed."""
        with self._cond:
            if not self._cond.wait_for(lambda: self.closed or (self._full is not None and self._full[0] > last),
                                       timeout):
                return None
            if self.closed:
                return None
            ids = [i for i, _ in self._deltas]
            if last == 0 or not ids or ids[0] > last + 1:
                return self._full
            return next((i, d) for i, d in self._deltas if i == last + 1)


class _Handler(BaseHTTPRequestHandler):
    server_version = "rigcad-watch"
    sys_version = ""
    protocol_version = "HTTP/1.1"

    def log_message(self, format, *args) -> None:  # quiet: the terminal is the watcher's
        pass

    def _refuse(self, code: int, text: str) -> None:
        body = f"{code} {text}\n".encode()
        self.send_response(code)
        self.send_header("Content-Type", "text/plain; charset=utf-8")
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Connection", "close")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)
        self.close_connection = True

    def _host_ok(self) -> bool:
        return self.headers.get("Host", "").strip().lower() in self.server.allowed_hosts

    def do_GET(self) -> None:
        if not self._host_ok():
            return self._refuse(403, "Forbidden: foreign Host header")
        if self.path == "/":
            return self._page()
        if self.path == "/events":
            return self._events()
        return self._refuse(404, "Not Found")

    def do_HEAD(self) -> None:
        self.do_GET()

    def _other(self) -> None:
        if not self._host_ok():
            return self._refuse(403, "Forbidden: foreign Host header")
        self._refuse(405, "Method Not Allowed")

    do_POST = do_PUT = do_DELETE = do_PATCH = do_OPTIONS = _other

    def __getattr__(self, name: str):
        """Every other method (TRACE, CONNECT, PROPFIND, a lowercase ``get``: methods are case-sensitive)
        is refused as the ones above, 405, where http.server would answer 501 with an HTML page."""
        if name.startswith("do_"):
            return self._other
        raise AttributeError(name)

    def _headers(self, kind: str, length: int | None) -> None:
        from rigcad.live.page import CSP

        self.send_response(200)
        self.send_header("Content-Type", kind)
        if length is not None:
            self.send_header("Content-Length", str(length))
        self.send_header("Content-Security-Policy", CSP)
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Cache-Control", "no-store")
        self.end_headers()

    def _page(self) -> None:
        body = self.server.page
        self._headers("text/html; charset=utf-8", len(body))
        if self.command != "HEAD":
            self.wfile.write(body)

    def _events(self) -> None:
        self._headers("text/event-stream", None)
        self.close_connection = True
        if self.command == "HEAD":
            return
        hub, last = self.server.hub, 0
        hub.opened(+1)
        try:
            while True:
                item = hub.next_after(last, KEEPALIVE_S)
                if item is None:
                    if hub.closed:
                        self.wfile.write(b"event: bye\ndata: stopped\n\n")
                        self.wfile.flush()
                        return
                    self.wfile.write(b": keep-alive\n\n")
                else:
                    last, data = item
                    self.wfile.write(f"id: {last}\nevent: frame\ndata: {data}\n\n".encode())
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError):  # the page went away
            return
        finally:
            hub.opened(-1)


class LiveServer(ThreadingHTTPServer):
    """The server: ``hub`` (the frames), ``page`` (bytes), ``allowed_hosts`` (Host header values)."""

    daemon_threads = True
    allow_reuse_address = False  # a port in use must be found in use, not shared

    def __init__(self, address, hub: Hub, page: bytes) -> None:
        super().__init__(address, _Handler)
        self.hub, self.page = hub, page
        host, port = self.server_address[:2]
        names = {host, "127.0.0.1", "localhost"} if host in ("127.0.0.1", "localhost") else {host}
        self.allowed_hosts = {f"{n}:{port}".lower() for n in names}
        if host in ("::1",):
            self.allowed_hosts |= {f"[::1]:{port}", f"localhost:{port}"}

    def handle_error(self, request, client_address) -> None:
        """A client that goes away (closes early, resets, times out) is an ordinary disconnect: silent.
        Anything else is one line on stderr, not socketserver's traceback."""
        import sys

        err = sys.exc_info()[1]
        if isinstance(err, (ConnectionError, TimeoutError)):
            return
        print(f"rigcad watch: a request from {client_address[0]} failed: {type(err).__name__}: {err}"[:300],
              file=sys.stderr, flush=True)

    @property
    def url(self) -> str:
        host, port = self.server_address[:2]
        return f"http://{host}:{port}/"


def start(hub: Hub, page: bytes, host: str = DEFAULT_HOST, port: int = DEFAULT_PORT, say=print) -> LiveServer:
    """The server on ``host``, on ``port`` or (one line said) the next free one, serving in a
    daemon thread. ``port`` 0: any free port."""
    last_error = None
    for candidate in range(port, port + PORT_TRIES) if port else [0]:
        try:
            server = LiveServer((host, candidate), hub, page)
        except (OSError, UnicodeError) as err:
            if getattr(err, "errno", None) != errno.EADDRINUSE:
                reason = getattr(err, "strerror", None) or str(err)
                resolver = isinstance(err, (UnicodeError, socket.gaierror))  # the name, not the port
                raise ServerError(f"cannot serve the live view on {host}:{candidate}: {reason}; "
                                  "give another --host or --port", param="--host" if resolver else "--port") from err
            last_error = err
            continue
        if candidate != port and port:
            say(f"rigcad watch: port {port} is in use; serving on {server.server_address[1]}")
        threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.2}, daemon=True,
                         name="rigcad-live-server").start()
        return server
    raise ServerError(f"ports {port}..{port + PORT_TRIES - 1} on {host} are all in use ({last_error}); "
                      "give a free one with --port", param="--port")


__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "Hub", "LiveServer", "ServerError", "frame_message", "start"]
