"""The assembled rig: no part cuts into another, and only the beam and the paraboloid's mount
stand between the dome and the sample."""

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from rigcad.optics.design import profile_table
from rigcad.parts import _kernel as K
from rigcad.parts.occlusion import blocked_solid_angle
from rigcad.profile import load_profile
from rigcad.rig import Rig

ROOT = Path(__file__).resolve().parents[2]
RIG = ["dome", "paraboloid", "beam", "base_plate", "sample_holder"]


@pytest.fixture(scope="module")
def rig():
    r = Rig.from_profile(load_profile(ROOT / "profiles/achutha2006.yaml"))
    shapes = {n: K.single_solid(K.build(r.recipe(n).solid, 1e-4, K.FitReport())) for n in RIG}
    return r, shapes


@pytest.mark.parametrize("a, b", list(itertools.combinations(RIG, 2)))
def test_no_interference_between_rig_parts(rig, a, b):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    shapes = rig[1]
    common = BRepAlgoAPI_Common(shapes[a], shapes[b]).Shape()
    # intended contacts (flange on plate, beam on its slot floor, clamp on the beam, collar under
    # the plate) share faces only: zero volume. 1e-6 mm^3 is far below any real overlap.
    assert K.volume(common) < 1e-6, (a, b, K.volume(common))


def test_only_beam_and_mount_stand_between_dome_and_sample(rig, default_exports):
    r = rig[0]
    geo = r.geometry
    # the parts' STLs as `rigcad stl achutha2006` wrote them (the session's shared exports)
    meshes = {n: trimesh.load(default_exports.out / "stl" / f"{n}.stl") for n in RIG}
    rng = np.random.default_rng(11)
    n = 20000
    theta = np.arccos(rng.uniform(0.0, math.cos(geo.occlusion_theta + math.radians(0.5)), n))
    phi = rng.uniform(0, 2 * math.pi, n)
    dirs = np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    origins = np.tile([0.0, 0.0, 1e-3], (n, 1))  # just above the sample surface
    first = np.full(n, np.inf)
    who = np.full(n, "", dtype=object)
    for name, mesh in meshes.items():
        loc, ray, _ = mesh.ray.intersects_location(origins, dirs, multiple_hits=False)
        dist = np.linalg.norm(loc - origins[ray], axis=1)
        closer = dist < first[ray]
        first[ray[closer]] = dist[closer]
        who[ray[closer]] = name
    hit = set(who[np.isfinite(first)])
    assert hit <= {"dome", "beam", "paraboloid"}, hit
    # The dome encloses the zone except for the slots' clearance gaps beside and above the beam,
    # which are real openings: misses may only lie in the beam's azimuth, and be rare.
    miss = ~np.isfinite(first)
    assert np.all(np.abs(np.sin(phi[miss])) < 0.05), np.degrees(phi[miss])
    assert miss.mean() < 1e-3
    # the blocked fraction seen by rays agrees with the analytic occlusion report (2 sigma of 20k samples)
    frac_rays = np.mean(who != "dome")
    report = blocked_solid_angle(r.occluders, profile_table(geo, r.dome))
    rays_only_return = report["blocked_fraction"]  # report counts P->D too: an upper bound
    assert frac_rays <= rays_only_return + 2 * math.sqrt(frac_rays * (1 - frac_rays) / n)
    assert frac_rays > 0.01  # the beam does hide a strip


def test_coated_mirrors_lie_on_the_design_surfaces(rig):
    """Measured on the exact B-rep: points of the design surface moved behind by the coating are
    on the printed solid's boundary (<= 1 um), and the design points sit one coating thickness off it."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepClass3d import BRepClass3d
    from OCP.gp import gp_Pnt

    r, shapes = rig
    layout = r.layout
    coat = layout.coating
    assert coat == pytest.approx(5.5 * 0.0254)  # the thesis's 5.5 mil default stack
    for name, design in (("dome", layout.design_dome), ("paraboloid", layout.design_paraboloid)):
        shell = BRepClass3d.OuterShell_s(shapes[name])
        u = np.linspace(*design.u_range, 41)[1:-1]
        rng = np.random.default_rng(5)
        for (r, z), nrm, phi in zip(design.points(u), design.normals(u), rng.uniform(0, 2 * math.pi, len(u))):
            if name == "dome" and layout.beam_z[0] - 5 < z < layout.beam_z[1] + 5:
                continue  # the beam slots remove the wall there at phi ~ 0, pi
            for depth, expected in ((coat, 0.0), (0.0, coat)):
                rr, zz = r - depth * nrm[0], z - depth * nrm[1]
                p = gp_Pnt(rr * math.cos(phi), rr * math.sin(phi), zz)
                dist = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(p).Vertex(), shell)
                assert abs(dist.Value() - expected) <= 1e-3, (name, r, z, depth, dist.Value())  # 1 um


def test_instrument_boxes_say_who_set_their_size(tmp_path):
    """The rig's instrument boxes name where their size came from (rigcad.profile.instruments.size_origin):
    assumed by default, the instrument file a profile names, or the profile itself."""
    import rigcad
    from rigcad.manual.assembly import picture_meshes

    path = tmp_path / "lab.yaml"
    path.write_text("extends: achutha2006\ncamera:\n  model: basler_ace_u_aca2040_55uc\nprojector:\n"
                    "  lens_diameter: 40 mm\n  lens_length: 25 mm\n", encoding="utf-8")
    by = {m.name: m.description for m in picture_meshes(rigcad.load(path))}
    assert by["camera_body"].endswith("(size from basler_ace_u_aca2040_55uc)")
    assert by["projector_lens"].endswith("(size set in the profile)")
    assert by["camera_lens"].endswith("(assumed size)")
