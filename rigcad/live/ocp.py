"""The rig in an OCP CAD Viewer (``ocp_vscode``, the viewer build123d's documentation points to):
the in-rig parts as named, coloured exact solids (``parts._kernel.part_solid``, built once per
recipe content and kept), the traced rays as one compound of polylines and the centre-of-
projection markers (instruments named ``*_marker``), sent to a viewer already running on a port.

``ocp_vscode`` is the optional ``rigcad[ocp]`` extra. When it is missing, or no viewer listens on
the port, :func:`connect` says so in one line (how to start a viewer) and returns None; the
watcher then shows the browser view only. ``ocp_vscode`` 4.2 no longer starts a standalone viewer
itself (``python -m ocp_vscode`` says it moved to the ``ocp_viewer`` package, also in the extra), so
the line names ``python -m ocp_viewer --port P`` and the VS Code extension.
"""

from __future__ import annotations

from rigcad.errors import RigcadError

#: The port OCP CAD Viewer listens on by default (ocp_vscode's DEFAULT_PORT).
DEFAULT_PORT = 3939


def start_hint(port: int) -> str:
    """How to start a viewer on ``port``, for the one line said when none runs."""
    return (f"run `python -m ocp_viewer --port {port}` (the standalone viewer, in rigcad[ocp]; `python -m ocp_vscode` "
            "no longer starts one) or open the OCP CAD Viewer extension in VS Code")


class ViewerError(RigcadError):
    """No OCP CAD Viewer to show the rig in (none running, or ocp_vscode not installed)."""


def viewer_missing(port: int = DEFAULT_PORT, host: str = "127.0.0.1") -> str | None:
    """Why the rig cannot be shown in an OCP CAD Viewer on ``host:port`` (one line), or None."""
    try:
        from ocp_vscode.comms import port_check
    except ImportError:
        return "ocp_vscode is not installed (pip install 'rigcad[ocp]')"
    if not port_check(int(port), host):
        return f"no OCP CAD Viewer on {host}:{port}: {start_hint(port)}"
    return None


class OcpPush:
    """Pushes a rig to the viewer on ``port``; each part's solid is built once per recipe content."""

    def __init__(self, port: int = DEFAULT_PORT, host: str = "127.0.0.1") -> None:
        self.port, self.host = int(port), host
        self._solids: dict[str, object] = {}
        self.pushed = 0

    def objects(self, rig, rays: dict | None) -> tuple[list, list[str], list[str]]:
        """(shapes, names, colours) of ``rig``: its in-rig parts and instruments, and the rays."""
        from rigcad.manual.assembly import hex_color
        from rigcad.parts import _kernel as K

        shapes, names, colours, used = [], [], [], set()
        tol = rig.profile.tessellation.fit_tolerance
        for part in [*rig.recipes.values(), *rig.instruments]:
            if not part.in_rig:
                continue
            key = part.content_hash()
            if key not in self._solids:
                self._solids[key] = K.part_solid(part, tol, K.FitReport(), rig.profile)
            used.add(key)
            shapes.append(self._solids[key])
            names.append(part.name)
            colours.append(hex_color(part.color))
        for stale in [k for k in self._solids if k not in used]:
            del self._solids[stale]
        if rays is not None and len(rays["lines"]):
            shapes.append(K.polylines(rays["lines"]))
            names.append("rays")
            colours.append("#ffb000")
        return shapes, names, colours

    def push(self, rig, rays: dict | None) -> None:
        """Show ``rig`` (and ``rays``, manual.view.traced_rays) in the viewer; ViewerError when it
        has gone away."""
        missing = viewer_missing(self.port, self.host)
        if missing is not None:
            raise ViewerError(missing)
        import warnings

        from ocp_vscode import show

        shapes, names, colours = self.objects(rig, rays)
        with warnings.catch_warnings():  # the camera is kept on purpose: the user's view survives an edit
            warnings.simplefilter("ignore")
            show(*shapes, names=names, colors=colours, port=self.port, progress="")
        self.pushed += 1


def connect(port: int = DEFAULT_PORT, host: str = "127.0.0.1", say=print) -> OcpPush | None:
    """An OcpPush when a viewer runs on ``host:port``; else one line said and None."""
    missing = viewer_missing(port, host)
    if missing is not None:
        say(f"rigcad watch: {missing}; showing the browser view")
        return None
    return OcpPush(port, host)


def show(rig, port: int = DEFAULT_PORT, rays: int | None = None) -> OcpPush:
    """Push ``rig`` to the OCP CAD Viewer on ``port`` (``rays`` traced rays, default as many as
    ``rigcad view`` draws); ViewerError (one line, how to start a viewer) when none runs."""
    from rigcad.manual.view import VIEW_RAYS, traced_rays

    missing = viewer_missing(port)
    if missing is not None:
        raise ViewerError(missing)
    push = OcpPush(port)
    push.push(rig, traced_rays(rig, VIEW_RAYS if rays is None else rays))
    return push


__all__ = ["DEFAULT_PORT", "OcpPush", "ViewerError", "connect", "show", "start_hint", "viewer_missing"]
