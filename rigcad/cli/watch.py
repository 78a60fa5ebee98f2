"""``rigcad watch PROFILE``: the live edit loop (rigcad.live) with its view served on 127.0.0.1."""

from __future__ import annotations

import argparse
from pathlib import Path


def cmd_watch(args: argparse.Namespace) -> int:
    _refuse_at_start(args)
    from rigcad.live.page import live_html
    from rigcad.live.server import Hub, start
    from rigcad.live.session import LiveSession
    from rigcad.live.watch import Watcher

    session = LiveSession(args.profile, check=not args.no_check, printers=tuple(args.printer or ()))
    hub = Hub()
    server = start(hub, live_html(f"{Path(args.profile).stem}: rigcad watch"), args.host, args.port)
    try:
        ocp = None
        if args.ocp:
            from rigcad.live.ocp import connect

            ocp = connect(args.ocp_port)
        try:
            print(f"rigcad watch: {args.profile} -> {server.url} (open it in a browser; Ctrl-C stops)", flush=True)
            Watcher(session, hub, say=lambda line: print(line, flush=True),
                    write=Path(args.exports) if args.write else None, ocp=ocp).run()
        except KeyboardInterrupt:
            pass
    finally:
        hub.close()
        server.shutdown()
        server.server_close()
    print("rigcad watch: stopped", flush=True)
    return 0


def _refuse_at_start(args: argparse.Namespace) -> None:
    """One line now, before anything is served, for what no edit can mend: a profile or printer that
    is nowhere (one with an error is served, with the error shown, and watched till it is fixed) and,
    with --write, an exports root rigcad could never publish into."""
    from rigcad.fab.printers import printer_path
    from rigcad.profile.loader import resolve_profile_path

    resolve_profile_path(args.profile)
    for spec in args.printer or ():
        printer_path(spec)
    if args.write:
        from rigcad.export.atomic import check_exports_root

        check_exports_root(args.exports)


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``watch`` to rigcad's subcommands."""
    from rigcad.arguments import host_address, port_number, profile_command

    p = profile_command(
        subparsers, "watch", cmd_watch,
        help="edit the YAML, see the rig: a live 3D view rebuilt on every save",
        description="Watch the profile, every file its extends: chain reads and the printer files given, and on "
                    "each save rebuild only what the change touches (the parts whose recipe changed; the dome, "
                    "design and check only when their inputs did), re-run the design-level check rows on the "
                    "analytic tracer and push the result to a live view in the browser (served on 127.0.0.1). "
                    "A profile with an error shows it, with file:line, and keeps the last good rig. Ctrl-C stops.",
        epilog="By default nothing under the exports changes; --write publishes them after each good rebuild, "
               "as `rigcad stl` does. --ocp also shows the rig in a running OCP CAD Viewer. See docs/watch.md.")
    p.add_argument("--host", default="127.0.0.1", type=host_address,
                   help="address the live view is served on (default: 127.0.0.1, this machine only)")
    p.add_argument("--port", type=port_number, default=8765,
                   help="port of the live view (default 8765; taken: the next free one; 0: any free port)")
    p.add_argument("--printer", action="append", metavar="NAME",
                   help="a printer (name under printers/ or path) whose files are watched too; the view lists the "
                        "printed parts that must be split for it (repeatable)")
    p.add_argument("--no-check", action="store_true", help="skip the check rows (parts and design only)")
    p.add_argument("--write", action="store_true", help="also publish <exports>/<profile>/ after each good rebuild")
    p.add_argument("--ocp", action="store_true", help="also push the parts, rays and COP markers to a running OCP CAD "
                                                      "Viewer (rigcad[ocp]; start one with `python -m ocp_viewer`)")
    p.add_argument("--ocp-port", type=port_number, default=3939, help="the OCP CAD Viewer's port (default 3939)")
    return p


__all__ = ["cmd_watch", "register"]
