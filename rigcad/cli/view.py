"""``rigcad view PROFILE``: the assembled rig in 3D, one self-contained HTML file."""

from __future__ import annotations

import argparse
from pathlib import Path


#: Most rays ``rigcad view`` draws: the page carries each ray's segments inline (~100 bytes of
#: base64 a ray) and a browser draws them all at once; 100,000 rays is ~10 MB of page and already
#: a solid colour over the dome (the default 300 shows the fan).
VIEW_MAX_RAYS = 100_000


def cmd_view(args: argparse.Namespace) -> int:
    from rigcad.progress import stages
    from rigcad.errors import ProfileError
    from rigcad.export import reuse
    from rigcad.export.atomic import check_exports, profile_lock
    from rigcad.export.manifest import profile_digest
    from rigcad.manual.view import write_view
    from rigcad.profile import load_profile
    from rigcad.rig import load

    if args.rays > VIEW_MAX_RAYS:
        raise ProfileError(f"--rays {args.rays}: the page draws at most {VIEW_MAX_RAYS} rays (each travels inside the "
                           f"HTML file and is drawn at once); valid: 1..{VIEW_MAX_RAYS}", param="--rays")
    profile = load_profile(args.profile)
    check_exports(args.exports, profile.name, "view")  # a planted link or lock: one line now, not after the work
    out = Path(args.exports) / profile.name / "view"
    lock = profile_lock(args.exports, profile.name)
    key = reuse.stage_key(profile, "view", {"rays": args.rays, "glb": bool(args.glb)})
    back = reuse.read_back(out, key, profile_digest(profile), lock)
    if back is not None:  # published from the same inputs and intact: nothing drawn, nothing written
        print(f"{profile.name}: 3D view up to date in {out}/ (the same profile, options and code as when it was "
              "written; nothing written)")
        return 0
    with stages(5, "view") as step:
        rig = load(profile)
        step("dome integrated")
        with reuse.recording(out, key):
            r = write_view(rig, out, lock, progress=step, rays=args.rays, glb=args.glb)
    print(f"{rig.name}: 3D view of {len(r['parts'])} part(s) ({', '.join(r['parts'])}), {r['triangles']} triangles, "
          f"{r['rays']} of {r['rays_traced']} rays reach the sample")
    print(f"  wrote {r['html']} ({r['html_bytes'] / 1e6:.2f} MB, self-contained: open it in a browser, offline)")
    print(f"  wrote {r['png']}")
    if args.glb:
        print(f"  wrote {r['glb']} (binary glTF 2.0: a named node per part, the rays as lines; metres, +Y up)")
    return 0


def register(subparsers) -> None:
    """Add ``view`` to rigcad's subcommands."""
    from rigcad.arguments import positive_int, profile_command

    p = profile_command(
        subparsers, "view", cmd_view,
        help="the assembled rig in 3D: one self-contained HTML file (three.js inline, no network)",
        description="Write exports/<profile>/view/rig.html: the assembled rig (parts toggled by name), a few hundred "
                    "rays traced through the exact surfaces and coloured by incidence angle, an exploded view; one "
                    "file with three.js and the geometry inside, nothing loaded from the network. Also "
                    "exports/<profile>/view/rig.png, a picture of the assembled rig.")
    p.add_argument("--rays", type=positive_int, default=300, help="rays traced from the COP (default: 300)")
    p.add_argument("--glb", action="store_true", help="also write rig.glb: the assembled rig as one binary glTF 2.0 "
                                                      "(metres, +Y up; named nodes and materials, normals, the rays "
                                                      "as lines) for Blender, YACV or any glTF viewer")
