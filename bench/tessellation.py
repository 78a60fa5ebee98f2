"""Tessellation: each mesh tolerance against triangles, file size, build time and the error it
causes, measured against the exact geometry (issue 7, table b).

Run from the repository root: ``.venv/bin/python bench/tessellation.py [--rays N]``. Writes
bench/results/tessellation.json and tessellation.png. Two sweeps:

1. printable STL, ``tessellation.chord_error`` (default 0.018 mm): every part meshed by
   rigcad.export.mesh.build (manifold3d) as ``rigcad build`` does; per chord error, per part and
   in total: triangles, STL bytes, mesh time (manifold3d build + arrays), STL and 3MF
   serialisation times; and errors against truth: on the mirror surfaces (dome, paraboloid) the
   measured chord error and facet-normal error (the angular criterion, measured after meshing:
   the STL tolerance has no angular term) against the exact printed meridian, as ``rigcad build``
   measures them; for every part the volume against the OpenCascade B-rep's.
2. mirror meshes of the ray checker, ``tessellation.mirror_chord_error`` (1 um) and
   ``mirror_normal_error`` (0.01 rad): rigcad.export.mirror_mesh.mirror_mesh for both mirrors at a
   chord sweep (normal error fixed at the default) and a normal sweep (chord fixed at the default);
   per row: triangles, PLY bytes, mesh time, Embree BVH build time, trace time, and the ray
   checker's own figures (rigcad.check.raycheck.reading) over the same seeded pinhole rays:
   mesh-minus-exact arrival angle (max, rms) and spot radius, for the smooth (vertex-normal) and
   facet (STL-literal) readings; exact = the analytic float64 tracer on the same rays.

Timings (``*_s``) are best of REPEATS for the STL sweep, one run for the mirror sweep. Not asserted.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from _common import arguments, png, pyplot, run_info, timed

from rigcad.check.raycheck import reading
from rigcad.check import rays as R
from rigcad.check.scene import (RigMeshes, _occluder_meshes, analytic_optics, mesh_optics,
                                share_scenes)
from rigcad.check.sources import annulus_rays
from rigcad.check.trace3d import trace
from rigcad.export import mesh as M
from rigcad.export.atomic import write_bytes, write_json
from rigcad.export.build import _coating, _stl_mirror_errors
from rigcad.export.mirror_mesh import mirror_mesh
from rigcad.parts import PARTS
from rigcad.rig import Rig
from rigcad.profile import load_profile

STL_CHORDS_MM = (0.3, 0.1, 0.05, 0.018, 0.01, 0.005)
REPEATS = 3
#: (sweep, chord mm, normal rad); None = the profile's value.
MIRROR_ROWS = tuple(("chord", c, None) for c in (0.03, 0.01, 0.003, 0.001, 0.0003)) + tuple(
    ("normal", None, n) for n in (0.1, 0.03, 0.01, 0.003))
RAYS = 100_000
SEED = 2006


def exact_volumes(profile, layout) -> dict[str, float]:
    """mm^3 of every part's OpenCascade B-rep (what the STEP holds): the volume ground truth."""
    from rigcad.parts import _kernel as K

    return {name: K.volume(K.single_solid(K.build(make(profile, layout).solid, profile.tessellation.fit_tolerance,
                                                  K.FitReport())))
            for name, make in PARTS.items()}


def stl_row(profile, layout, chord: float, volumes: dict, repeats: int, scratch: Path) -> dict:
    parts = {}
    for name, make in PARTS.items():
        part = make(profile, layout)
        mesh_s, _, man = timed(lambda: M.mesh_arrays(M.build(part.solid, chord)), repeats)
        v, f = man
        stl_s, _, stl = timed(lambda: M.stl_bytes(v, f, name), repeats)
        writer = M.threemf_writer(v, f, name)
        tmf_s, _, _ = timed(lambda: writer(scratch / f"{name}.3mf"), 1)
        vol = M.mesh_volume(v, f)
        row = {"triangles": int(len(f)), "stl_bytes": len(stl), "threemf_bytes": (scratch / f"{name}.3mf").stat().st_size,
               "volume_rel_error": (vol - volumes[name]) / volumes[name],
               "mesh_s": mesh_s, "stl_serialise_s": stl_s, "threemf_write_s": tmf_s}
        for mirror, meridian in part.mirrors:
            t0 = time.perf_counter()
            e = _stl_mirror_errors(v, f, meridian.behind(_coating(profile)))
            row[f"{mirror}_mirror"] = {"facets": e["facets"], "measured_chord_error_mm": e["chord_error_mm"],
                                       "measured_facet_normal_error_rad": e["facet_normal_error_rad"],
                                       "measure_s": time.perf_counter() - t0}
        parts[name] = row
    total = {k: sum(p[k] for p in parts.values()) for k in ("triangles", "stl_bytes", "threemf_bytes", "mesh_s",
                                                             "stl_serialise_s", "threemf_write_s")}
    total["max_abs_volume_rel_error"] = max(abs(p["volume_rel_error"]) for p in parts.values())
    return {"chord_error_mm": chord, "total": total, "parts": parts}


def mirror_row(rig, design, rays, exact, sweep: str, chord, normal) -> dict:
    """One mirror-tessellation row: both mirrors meshed as rigcad.check.scene.mirror_meshes does
    without exports (occluders from the layout), traced in the smooth and facet readings."""
    tess = rig.profile.tessellation
    c = tess.mirror_chord_error if chord is None else chord
    n = tess.mirror_normal_error if normal is None else normal
    mirrors, ply_bytes, mesh_s = {}, {}, {}
    for name, meridian in (("paraboloid", rig.layout.design_paraboloid), ("dome", rig.layout.design_dome)):
        t0 = time.perf_counter()
        mm = mirror_mesh(meridian, name, c, n)
        mesh_s[name] = time.perf_counter() - t0
        ply_bytes[name] = mm.report["bytes"]
        mirrors[name] = R.TriMesh(name, mm.vertices, mm.faces, mm.normals, meridian, source="mirror_mesh()")
        del mm
    mount, beam = _occluder_meshes(rig)
    meshes = RigMeshes(mirrors["paraboloid"], mirrors["dome"], mount, beam, {"chord_error_mm": c, "normal_error_rad": n})
    base = mesh_optics(meshes, "smooth")
    bvh_s = base.paraboloid.build_s + base.dome.build_s + base.beam.build_s
    ddirs = design.direction(rays.chief)
    row = {"sweep": sweep, "chord_error_mm": c, "normal_error_rad": n,
           "triangles": {k: len(v.faces) for k, v in mirrors.items()}, "ply_bytes": ply_bytes,
           "mesh_s": mesh_s, "embree_bvh_build_s": bvh_s, "readings": {}}
    for name in ("smooth", "mesh"):
        t0 = time.perf_counter()
        tr = trace(share_scenes(base, name), rays.origins, rays.dirs)
        trace_s = time.perf_counter() - t0
        r = reading(tr, ddirs, exact, rays.chief)
        row["readings"][name] = {
            "mesh_minus_exact_angle_rad": r["mesh_minus_exact_angle_rad"],
            "mesh_minus_exact_spot_max_mm": r["mesh_minus_exact_spot_mm"]["max"],
            "max_spot_radius_mm": r["max_spot_radius_mm"], "rms_spot_radius_mm": r["rms_spot_radius_mm"],
            "status_agreement_with_exact": r["status_agreement_with_exact"], "trace_s": trace_s}
    return row


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--profile", default="achutha2006")
    ap.add_argument("--rays", type=int, default=RAYS)
    args = ap.parse_args()
    chords = (0.3, 0.05) if args.quick else STL_CHORDS_MM
    mirror_rows = (("chord", 0.03, None), ("normal", None, 0.1)) if args.quick else MIRROR_ROWS
    n_rays = 2_000 if args.quick else args.rays
    repeats = 1 if args.quick else REPEATS
    run = run_info()
    profile = load_profile(args.profile)
    rig = Rig.from_profile(profile)
    layout = rig.layout
    volumes = exact_volumes(profile, layout)
    result = {"profile": profile.name, "default_chord_error_mm": profile.tessellation.chord_error,
              "default_mirror_chord_error_mm": profile.tessellation.mirror_chord_error,
              "default_mirror_normal_error_rad": profile.tessellation.mirror_normal_error,
              "exact_volumes_mm3": volumes, "stl": [], "mirrors": {"rays": n_rays, "seed": SEED, "rows": []},
              "run": run}
    with tempfile.TemporaryDirectory() as scratch:
        for chord in chords:
            row = stl_row(profile, layout, chord, volumes, repeats, Path(scratch))
            result["stl"].append(row)
            d, p, t = row["parts"]["dome"]["dome_mirror"], row["parts"]["paraboloid"]["paraboloid_mirror"], row["total"]
            print(f"STL {chord:6.3f} mm: {t['triangles']:>8} tri, {t['stl_bytes'] / 1e6:7.2f} MB, mesh {t['mesh_s']:.3f} s, "
                  f"3MF {t['threemf_write_s']:.2f} s; dome chord {d['measured_chord_error_mm']:.4f} mm normal "
                  f"{d['measured_facet_normal_error_rad']:.4f} rad; paraboloid normal {p['measured_facet_normal_error_rad']:.4f}"
                  f" rad; max |dV/V| {t['max_abs_volume_rel_error']:.2e}", flush=True)
    design = rig.incidence
    rays = annulus_rays(design, n_rays, SEED)
    exact = trace(analytic_optics(rig), rays.origins, rays.dirs)
    for sweep, chord, normal in mirror_rows:
        row = mirror_row(rig, design, rays, exact, sweep, chord, normal)
        result["mirrors"]["rows"].append(row)
        s, m = row["readings"]["smooth"], row["readings"]["mesh"]
        print(f"mirrors {row['chord_error_mm']:g} mm / {row['normal_error_rad']:g} rad: "
              f"{sum(row['triangles'].values()):>8} tri, mesh {sum(row['mesh_s'].values()):.2f} s, BVH {row['embree_bvh_build_s']:.2f} s; "
              f"smooth angle max {s['mesh_minus_exact_angle_rad']['max']:.2e} rad, spot max {s['max_spot_radius_mm']:.2e} mm; "
              f"facet angle max {m['mesh_minus_exact_angle_rad']['max']:.2e} rad, spot max {m['max_spot_radius_mm']:.2e} mm",
              flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    print(write_json(args.out / "tessellation.json", result))
    write_bytes(args.out / "tessellation.png", plot(result))


def plot(result: dict) -> bytes:
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8))
    stl = result["stl"]
    chords = [r["chord_error_mm"] for r in stl]
    ax = axes[0]
    for mirror, part in (("dome", "dome"), ("paraboloid", "paraboloid")):
        ax.loglog(chords, [r["parts"][part][f"{mirror}_mirror"]["measured_chord_error_mm"] for r in stl], "o-",
                  label=f"{mirror}: measured chord error (mm)")
        ax.loglog(chords, [r["parts"][part][f"{mirror}_mirror"]["measured_facet_normal_error_rad"] for r in stl], "s--",
                  label=f"{mirror}: measured facet-normal error (rad)")
    ax.loglog(chords, [r["total"]["max_abs_volume_rel_error"] for r in stl], "^:", label="max |volume error| / volume")
    ax.loglog(chords, chords, "k-", lw=0.6, label="declared chord error")
    ax.invert_xaxis()
    ax.set_xlabel("tessellation.chord_error (mm)")
    ax.set_title("printable STL: errors against the exact surfaces and B-rep volumes", fontsize=9)
    ax2 = axes[1]
    tri = [r["total"]["triangles"] for r in stl]
    ax2.loglog(tri, [r["total"]["mesh_s"] for r in stl], "o-", label="manifold3d mesh (all parts)")
    ax2.loglog(tri, [r["total"]["stl_serialise_s"] for r in stl], "s-", label="STL bytes")
    ax2.loglog(tri, [r["total"]["threemf_write_s"] for r in stl], "^-", label="3MF write (lib3mf)")
    ax2.loglog(tri, [r["total"]["stl_bytes"] / 1e9 for r in stl], "k:", label="STL size (GB)")
    for r in stl:
        ax2.annotate(f"{r['chord_error_mm']:g}", (r["total"]["triangles"], r["total"]["mesh_s"]), fontsize=7)
    ax2.set_xlabel("triangles, all 12 parts")
    ax2.set_ylabel("seconds (this machine)")
    ax2.set_title("printable STL: cost (labels: chord error mm)", fontsize=9)
    ax3 = axes[2]
    for sweep, mark in (("chord", "o"), ("normal", "s")):
        rows = [r for r in result["mirrors"]["rows"] if r["sweep"] == sweep]
        t = [sum(r["triangles"].values()) for r in rows]
        for rd, style in (("smooth", "-"), ("mesh", "--")):
            ax3.loglog(t, [r["readings"][rd]["mesh_minus_exact_angle_rad"]["max"] for r in rows], mark + style,
                       label=f"{sweep} sweep, {'facet' if rd == 'mesh' else rd} reading")
        for r in rows:
            lab = f"{r['chord_error_mm']:g}" if sweep == "chord" else f"{r['normal_error_rad']:g}"
            ax3.annotate(lab, (sum(r["triangles"].values()), r["readings"]["smooth"]["mesh_minus_exact_angle_rad"]["max"]),
                         fontsize=7)
    ax3.set_xlabel("mirror triangles (paraboloid + dome)")
    ax3.set_ylabel("max mesh-minus-exact arrival angle (rad)")
    ax3.set_title("ray checker mirror meshes (labels: chord mm / normal rad)", fontsize=9)
    for a in axes:
        a.grid(True, which="both", lw=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    return png(fig)


if __name__ == "__main__":
    main()
