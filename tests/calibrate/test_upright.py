"""The upright display (rigcad.calibrate.upright): where it stands, what it sees, its resection
against rays of known direction, and its decoded points against the tracer's own truth."""

import math

import numpy as np
import pytest
from scipy.ndimage import binary_erosion

from rigcad.calibrate import model as M, simulate as S, upright as U
from rigcad.calibrate.decode import Decoded, decode
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import on_screen, screen_pose
from rigcad.profile.schema import load_profile
from rigcad.rig import Rig

#: The small camera of test_simulate_fit (340 x 256 px), with four upright captures.
SMALL = ("extends: achutha2006\ncamera:\n  resolution: [340, 256]\ncalibration:\n  sim_blur: 0.3\n"
         "  spacer_heights: [2 mm, 9 mm]\n  half_turn: highest\n  upright_turns: 4\n")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    from rigcad.check.scene import analytic_optics

    path = tmp_path_factory.mktemp("upright") / "small.yaml"
    path.write_text(SMALL)
    rig = Rig.from_profile(load_profile(path))
    return dict(rig=rig, optics=analytic_optics(rig), cam=M.Camera.of(rig), ups=U.Uprights.of(rig.profile))


def test_each_capture_stands_on_edge_facing_the_dome(small):
    """Turn j's display: its face 7 mm from the axis towards azimuth 90 j deg, its normal level and
    pointing out (towards the dome it sees), its width level, its active area from 1 mm under the
    sample plane up: closed forms of the profile's keys."""
    cal, ups = small["rig"].profile.calibration, small["ups"]
    assert ups.labels == ("u0", "u1", "u2", "u3")
    height = cal.upright_resolution[1] * cal.upright_pitch
    for j, pose in enumerate(ups.nominal):
        psi = math.radians(90 * j)
        normal = pose.rotation[:, 2]
        assert normal == pytest.approx([math.cos(psi), math.sin(psi), 0.0], abs=1e-12)
        assert pose.rotation[:, 1] == pytest.approx([0.0, 0.0, 1.0])  # the display's v is up
        assert np.linalg.det(pose.rotation) == pytest.approx(1.0)
        bottom = pose.globalize_points(np.array([[0.0, -height / 2, 0.0]]))[0]
        assert bottom @ normal == pytest.approx(7.0) and bottom[2] == pytest.approx(-1.0)


def test_it_meets_the_grazing_rays_face_on_where_a_flat_screen_cannot(small):
    """The design rig's rays that reach the sample at 80-89 deg of incidence: every one meets some
    capture's display on its face, within its active area, and a neighbouring pixel's ray meets it
    under 2 mm away on this small camera (4 x the profile's pixels); past 87 deg they come off
    the dome under the lower flat screen's surface (the tablet's, 7 mm up)."""
    rig, cam, ups = small["rig"], small["cam"], small["ups"]
    tr = M.trace_camera(small["optics"], rig, cam.x_px, cam.y_px, cam.design)
    inc = np.degrees(np.arccos(np.clip(-tr.v[:, 2], -1, 1)))
    grazing = tr.ok & (inc > 80) & (inc < 89)
    assert grazing.sum() > 300
    w, h = (n * rig.profile.calibration.upright_pitch for n in rig.profile.calibration.upright_resolution)
    met, best = np.zeros(len(inc), bool), np.full(len(inc), np.inf)
    for pose in ups.nominal:
        su, sv = tr.screen(pose)
        face = tr.ok & (tr.v @ pose.rotation[:, 2] < 0) & (np.abs(su) < w / 2) & (np.abs(sv) < h / 2)
        met |= face
        step = np.max([np.hypot(*(np.gradient(a.reshape(cam.shape), axis=ax) for a in (su, sv))) for ax in (0, 1)],
                      axis=0).ravel()  # NaN next to a pixel whose ray is lost (the rim)
        best = np.where(face & np.isfinite(step), np.minimum(best, step), best)
    assert np.all(met[grazing])
    stepped = grazing & np.isfinite(best) & (inc < 88)  # at the rim a neighbour sees past the paraboloid
    assert stepped.sum() > 0.8 * grazing.sum()
    assert np.percentile(best[stepped], 95) < 2.0, np.percentile(best[stepped], [50, 95])
    lowest = M.screens(M.Plan.of(rig.profile), np.zeros(len(M.RIG_NAMES) + 6 * 3))[0]
    assert float(lowest.translation[2]) == pytest.approx(7.0)
    # from ~87 deg their dome points lie under the flat screen's surface: no flat screen meets them
    assert np.all(tr.p2[grazing & (inc > 87), 2] < 7.0) and np.sum(grazing & (inc > 87)) > 100


def _synthetic(small, planted: np.ndarray, k: int):
    """Capture ``k``'s decoding as the design rig's exact rays meet its display placed by ``planted``."""
    rig, cam, ups = small["rig"], small["cam"], small["ups"]
    tr = M.trace_camera(small["optics"], rig, cam.x_px, cam.y_px, cam.design)
    pose = U.compose(ups.nominal[k], screen_pose(*planted))
    su, sv = on_screen(pose, np.nan_to_num(tr.p2), np.nan_to_num(tr.v, nan=1.0))
    w, h = ups.seq.resolution[0] * ups.seq.pitch, ups.seq.resolution[1] * ups.seq.pitch
    valid = (tr.ok & (np.nan_to_num(tr.v) @ pose.rotation[:, 2] < 0) & (np.abs(su) < w / 2)
             & (np.abs(sv) < h / 2)).reshape(cam.shape)
    d = Decoded(np.where(valid, su.reshape(cam.shape), np.nan), np.where(valid, sv.reshape(cam.shape), np.nan),
                valid, valid, {})
    return tr, d


def test_the_resection_finds_a_planted_placement(small):
    """Rays of known direction (the design's, exact) and the points where they meet a display placed
    off its nominal pose by a planted placement: :func:`upright.place` gives the placement back to
    a nanometre and a microradian, whichever the capture. (With the pose composed the other way
    round, the nominal pose after the placement, the error is the planted tilt times the 8 mm
    offset and more: it fails.)"""
    planted = np.array([0.15, math.radians(1.2), math.radians(-0.7), 0.6, -0.15, math.radians(0.8)])
    for k in range(4):
        tr, d = _synthetic(small, planted, k)
        got = U.place(small["ups"].nominal[k], U.placement_scale(small["rig"].profile), d, tr, -tr.v,
                      small["cam"].shape)
        assert got.placed and got.pixels > U.MIN_REFERENCE_PIXELS
        assert np.allclose(got.placement, planted, atol=1e-6), (k, got.placement - planted)
        assert got.rms_mm < 1e-6


def test_too_few_reference_pixels_leave_a_capture_unplaced(small):
    """A display that shares too few pixels with the flat captures' measured rays is not placed."""
    tr, d = _synthetic(small, np.zeros(6), 0)
    measured = np.full_like(tr.v, np.nan)
    measured[: U.MIN_REFERENCE_PIXELS // 2] = -tr.v[: U.MIN_REFERENCE_PIXELS // 2]
    got = U.place(small["ups"].nominal[0], U.placement_scale(small["rig"].profile), d, tr, measured, small["cam"].shape)
    assert not got.placed and np.all(np.isnan(got.placement))


def test_decoded_points_on_the_upright_display_match_the_tracer(small):
    """The simulated upright captures (a seeded misalignment, surface error and placement), decoded,
    against the true rays' points on the true displays: the decoded point is the centre ray's to well
    under a period (16 px = 2.04 mm). Measured: median 0.073 mm, p99 0.41 mm; this camera's pixels are
    4 x the profile's, and so are their footprints (the full-size bench's resections leave ~30 um RMS)."""
    rig, cam, ups = small["rig"], small["cam"], small["ups"]
    plan = M.Plan.of(rig.profile)
    rng = np.random.default_rng(3)
    theta = S.random_misalignment(rig, plan, rng)
    placement = U.random_placement(rig.profile, rng)
    surface = S.planted_surface(rig, rng)
    images = S.render(small["optics"], rig, theta, surface, cam, Sequence.from_profile(rig.profile.calibration),
                      plan, rng, placement)
    assert len(images) == len(plan) + 4
    true_rig = M.moved(rig, theta)
    tr = S.with_surface(true_rig, surface, M.trace_camera(small["optics"], true_rig, cam.x_px, cam.y_px, cam.design))
    for frames, pose in zip(images[len(plan):], ups.poses(placement)):
        d = decode(ups.seq, {n: cam.crop(im) / 255.0 for n, im in frames.items()}, 0.1)
        su, sv = tr.screen(pose)
        err = np.hypot(d.u.ravel() - su, d.v.ravel() - sv)
        inner = binary_erosion(d.valid, iterations=2).ravel() & np.isfinite(err) & tr.ok
        assert inner.sum() > 300
        assert np.median(err[inner]) < 0.15 and np.percentile(err[inner], 99) < 0.8, (
            np.median(err[inner]), np.percentile(err[inner], 99))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """``rigcad calibrate --simulate --write-capture`` on the small camera with the upright display
    (every 4th row and column fitted: the command's tests need no accuracy): the capture's files
    and the simulated run's exports."""
    import argparse

    from rigcad.cli.calibrate import cmd_calibrate

    root = tmp_path_factory.mktemp("upright_capture")
    profile = root / "small.yaml"
    profile.write_text(SMALL + "  fit_stride: 4\n")
    args = argparse.Namespace(profile=str(profile), images=None, simulate=True, kit=False, seed=3,
                              exports=str(root / "simulated"), write_capture=str(root / "capture"))
    assert cmd_calibrate(args) == 0
    return dict(profile=profile, folder=root / "capture", simulated=root / "simulated" / "small" / "calibrate")


def _from_files(tmp_path, written, spoil=None):
    import argparse
    import shutil

    from rigcad.cli.calibrate import cmd_calibrate

    folder = tmp_path / "capture"
    shutil.copytree(written["folder"], folder)
    if spoil:
        spoil(folder)
    args = argparse.Namespace(profile=str(written["profile"]), images=str(folder), simulate=False, seed=0,
                              exports=str(tmp_path / "exports"))
    return cmd_calibrate(args)


def test_the_upright_captures_go_through_their_files(tmp_path, written):
    """The simulated capture written out (u0-u3 beside the flat captures' files) and calibrated from
    its files gives the simulated run's corrected map, byte for byte; the report places each upright
    capture, near what was planted (the small camera's rays: within a tenth of a millimetre and
    half a degree here), and measures nearly every lit pixel (the flat captures alone: ~86 %)."""
    import json

    assert sorted({p.name.split("_")[0] for p in written["folder"].iterdir()}) == ["h0", "h1", "h1r", "u0", "u1", "u2",
                                                                                  "u3"]
    code = _from_files(tmp_path, written)
    out = tmp_path / "exports" / "small" / "calibrate"
    # written on PASS and on FAIL alike; the exit status is the verdict's (tests/calibrate/test_verdict.py)
    assert code == (0 if json.loads((out / "calibration.json").read_text())["verdict"]["passed"] else 1)
    assert (out / "corrected_map.npz").read_bytes() == (written["simulated"] / "corrected_map.npz").read_bytes()
    report = json.loads((written["simulated"] / "calibration.json").read_text())
    assert report["captures"][-4:] == ["u0", "u1", "u2", "u3"]
    placed = report["simulation"]["upright_placement"]
    assert placed["captures_placed"] == 4
    assert max(placed[k] for k in ("dz_mm", "du_mm", "dv_mm")) < 0.2
    assert max(placed[k] for k in ("tilt_x_rad", "tilt_y_rad", "turn_rad")) < math.radians(0.5)
    assert report["unmeasured"]["fraction_of_lit"]["measured"] > 0.95


@pytest.mark.parametrize("spoil, words", [
    (lambda f: (f / "u2_y_p16_s1.png").unlink(), ("u2_y_p16_s1.png", "missing", "u<turn>_ for the upright display")),
    (lambda f: [p.unlink() for p in f.glob("u*_*.png")],
     ("u0_white.png", "missing, and every other frame of capture u0", "set calibration.upright_turns: 0")),
    (lambda f: [(f / p.name).rename(f / p.name.replace("u1_", "t_")) for p in f.glob("u1_*.png")]
     + [(f / p.name).rename(f / p.name.replace("u3_", "u1_")) for p in f.glob("u3_*.png")]
     + [(f / p.name).rename(f / p.name.replace("t_", "u3_")) for p in f.glob("t_*.png")],
     ("u1_white.png", "tolerances from its mark", "wrong turn")),
])
def test_a_bad_upright_capture_is_refused_with_one_line_naming_the_file(tmp_path, written, spoil, words):
    """A missing frame (before any work), no upright capture at all (a lab without the display is told
    how to calibrate without it), and the stand's turns 1 and 3 swapped: the images put the display
    far from u1's mark. Nothing is written."""
    from rigcad.calibrate.images import CaptureError

    with pytest.raises(CaptureError) as info:
        _from_files(tmp_path, written, spoil)
    msg = str(info.value)
    assert "\n" not in msg and all(w in msg for w in words), msg
    assert not (tmp_path / "exports" / "small" / "calibrate").exists()


def test_the_kit_has_the_upright_display_its_patterns_and_its_stand(tmp_path, small):
    """The kit with the upright display: its patterns at its own size, its stand (STL and STEP, its
    B-rep re-imported) on the page. Sampled in the stand's STL (trimesh's inside test): the module's
    box, its face at the offset and its lower edge on the slot's floor, is clear of the stand, the
    floor under it and the back behind it are solid, and the whole stand passes the holder's bore."""
    import trimesh
    from PIL import Image

    from rigcad.calibrate.kit import SLOT_CLEARANCE_MM, write_kit

    rig = small["rig"]
    cal = rig.profile.calibration
    manifest = write_kit(rig, tmp_path / "kit")
    with Image.open(tmp_path / "kit" / "patterns_upright" / "x_p16_s0.png") as im:
        assert im.size == tuple(cal.upright_resolution)
    stand = manifest["parts"]["calibration_upright_stand"]
    assert stand["step_reimport"]["solids"] == 1 and stand["volume_mm3"] > 0
    mesh = trimesh.load(tmp_path / "kit" / "stl" / "calibration_upright_stand.stl")
    assert mesh.is_watertight and mesh.volume == pytest.approx(stand["volume_mm3"], rel=2e-3)
    c, t, half = cal.upright_offset, cal.upright_thickness, cal.upright_resolution[0] * cal.upright_pitch / 2
    floor = -cal.upright_depth - cal.upright_border
    g = np.linspace(0.05, 0.95, 7)
    xs, ys, zs = np.meshgrid(c - t + g * t, (g - 0.5) * 2 * (half + cal.upright_border), floor + g * 12.0)
    module = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    assert not mesh.contains(module).any()
    from rigcad.calibrate.kit import upright_room

    # the module stands on the slot's floor either side of the cable channel (its flat cable runs down it)
    under = module[np.abs(module[:, 1]) > upright_room(rig.profile)["cable_half_mm"]].copy()
    under[:, 2] = floor - 0.5
    behind = module.copy()
    behind[:, 0] = c - t - SLOT_CLEARANCE_MM - 1.0
    behind[:, 2] = np.clip(behind[:, 2], 0.5, 11.0)
    assert mesh.contains(under).all() and mesh.contains(behind).all()
    _notches_turn_the_stand_to_its_captures(rig.profile, mesh)
    above_plate = mesh.vertices[mesh.vertices[:, 2] > -rig.profile.base_plate.thickness + 1e-6]
    assert np.hypot(above_plate[:, 0], above_plate[:, 1]).max() <= rig.profile.sample_holder.radius + 1e-6
    page = (tmp_path / "kit" / "calibration.md").read_text()
    assert "`stl/calibration_upright_stand.stl`" in page and "files `u3_<frame>.png`" in page
    # the rule _notches_turn_the_stand_to_its_captures follows, as the page tells it
    assert "the 3rd notch counter-clockwise from the wide one, seen from below, at the groove" in page
    assert "set their exposure on that image" in page


def _notches_turn_the_stand_to_its_captures(profile, mesh):
    """Found in the stand's STL: the gaps in its collar's rim, sampled every 0.05 deg just inside it.
    Turned so that its j-th notch (counting counter-clockwise seen from below, from the wide one)
    faces the base plate's groove (+x), the stand's slot faces where the fit expects capture u<j>
    (Uprights.of): the page's steps, the stand and the fit agree."""
    from rigcad.calibrate.upright import Uprights

    h, t = profile.sample_holder, profile.base_plate.thickness
    a = np.radians(np.arange(0.0, 360.0, 0.05))
    r, z = h.stop_radius - 0.3, -t - h.stop_thickness / 2
    solid = mesh.contains(np.stack([r * np.cos(a), r * np.sin(a), np.full_like(a, z)], axis=1))
    start = np.flatnonzero(solid)[0]  # walk the rim from a solid sample: every gap is whole
    gaps, width = [], 0
    for i in range(start, start + len(a) + 1):
        if not solid[i % len(a)]:
            width += 1
        elif width:
            gaps.append(((i - width / 2 - 0.5) * 0.05 % 360.0, width))
            width = 0
    turns = profile.calibration.upright_turns
    assert len(gaps) == turns, gaps
    wide = max(gaps, key=lambda g: g[1])
    assert all(wide[1] > 1.5 * g[1] for g in gaps if g is not wide)
    # seen from below, counter-clockwise is seen from above clockwise: decreasing azimuth
    order = sorted(gaps, key=lambda g: (wide[0] - g[0]) % 360.0)
    nominal = Uprights.of(profile).nominal
    for j, (azimuth, _) in enumerate(order):
        turn = -azimuth  # the stand turned to bring this notch to +x: the slot's face, +x as drawn, turns with it
        face = np.radians(turn)
        assert np.allclose(nominal[j].rotation[:, 2], [np.cos(face), np.sin(face), 0.0], atol=2e-3), (j, azimuth)


def test_a_display_too_wide_for_the_bore_is_refused_naming_its_key(tmp_path):
    from rigcad.calibrate.kit import check_upright_fits
    from rigcad.errors import ProfileError

    path = tmp_path / "wide.yaml"
    path.write_text("extends: achutha2006\ncalibration:\n  upright_offset: 12 mm\n")
    with pytest.raises(ProfileError) as e:
        check_upright_fits(load_profile(path))
    assert e.value.message.startswith("calibration.upright_offset 12 mm: the upright display's module (34.6 mm wide")
    assert "keeps 19.0 mm" in e.value.message and e.value.where.endswith("wide.yaml:3")
    path.write_text("extends: achutha2006\ncalibration:\n  upright_offset: 7 mm\n")
    assert check_upright_fits(load_profile(path))["fits"]
