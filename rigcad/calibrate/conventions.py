"""The capture conventions a lab's capture script needs, read from the code that uses them, so that
the page (docs/calibrate.md, "Capture conventions") and the kit's figure cannot drift from it:
the camera image's axes, pixel centres, intrinsics and window; the screen's axes and origin at
each turn, its pixel centres, the patterns and the Gray code's polarity; the tilts' axes and sign.

:func:`facts` gathers them as plain data (tests/calibrate/test_conventions.py holds the page's
statements to it); :func:`figure` draws them (PNG bytes), computing nothing of its own."""

from __future__ import annotations

import math

import numpy as np

from rigcad.calibrate import model as M
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.raxel import screen_pose, to_global

#: The rig frame's axes by name, for reading a direction back as the axis it lies along.
_AXES = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0), "+z": (0, 0, 1), "-z": (0, 0, -1)}


def _axis_name(v) -> str:
    """The rig axis a direction (3,) lies along (within a degree), or ValueError."""
    v = np.asarray(v, float) / np.linalg.norm(v)
    for name, a in _AXES.items():
        if float(np.dot(v, a)) > math.cos(math.radians(1.0)):
            return name
    raise ValueError(f"{v} lies along no axis of the rig frame")


def facts(rig) -> dict:
    """The conventions as the code applies them (module docstring), on ``rig``'s profile."""
    from rigcad.check.sources import pixel_rays

    cam = M.Camera.of(rig)
    width, height = cam.resolution
    f = float(cam.design.focal_px)
    # where the aligned camera's ray through a pixel right of / below the centre lands: the image's
    # column and row axes in the rig frame (the camera looks down, -z)
    rays = pixel_rays(cam.design, np.array([100.0, 0.0]), np.array([0.0, -100.0]))
    column_axis = _axis_name(rays.dirs[0] - rays.dirs[0] @ np.array([0, 0, 1.0]) * np.array([0, 0, 1.0]))
    row_axis = _axis_name(rays.dirs[1] - rays.dirs[1] @ np.array([0, 0, 1.0]) * np.array([0, 0, 1.0]))
    seq = Sequence.from_profile(rig.profile.calibration)
    sw, sh = seq.resolution
    first = (float(seq.to_mm("x", np.array(0.5))), float(seq.to_mm("y", np.array(0.5))))
    screen = {}
    for label, turn in (("turn 0", 0.0), ("half turn", math.pi)):
        pose = screen_pose(0.0, turn=turn)
        screen[label] = {"u": _axis_name(pose.rotation[:, 0]), "v": _axis_name(pose.rotation[:, 1]),
                         "du": _axis_name(screen_pose(0.0, du=1.0, turn=turn).translation),
                         "dv": _axis_name(screen_pose(0.0, dv=1.0, turn=turn).translation)}
    # a small tilt about x and about y: which side of a part rises
    lift_x = to_global(screen_pose(0.0, tilt_x=1e-3), np.array(0.0), np.array(1.0))[2]
    lift_y = to_global(screen_pose(0.0, tilt_y=1e-3), np.array(1.0), np.array(0.0))[2]
    g = np.arange(8)
    return {
        "camera": {"resolution_px": [width, height], "focal_px": f, "principal_point_px": list(cam.principal_point),
                   "pixel_centre": ("x = col + 0.5 - W / 2, y = H / 2 - row - 0.5"
                                    if tuple(cam.principal_point) == (width / 2, height / 2)
                                    else "x = col + 0.5 - c_x, y = c_y - row - 0.5 (c: the principal point)"),
                   "first_pixel_centre_px": [float(cam.x_px[0] - cam.col0), float(cam.y_px[0] + cam.row0)],
                   "column_axis": column_axis, "row_axis": row_axis,
                   "window": {"row0": cam.row0, "col0": cam.col0, "rows": cam.shape[0], "cols": cam.shape[1]}},
        "screen": {"resolution_px": [sw, sh], "pitch_mm": seq.pitch,
                   "size_mm": [sw * seq.pitch, sh * seq.pitch], "first_pixel_centre_mm": list(first),
                   "pixel_centre": "c = index + 0.5", **screen},
        "gray": {"stripe_px": seq.stripe, "bits": seq.gray_bits, "codes_of_stripes_0_7": (g ^ (g >> 1)).tolist(),
                 "white_is": 1},
        "tilt": {"tilt_x_lifts": "+y" if lift_x > 0 else "-y", "tilt_y_lifts": "+x" if lift_y > 0 else "-x"},
    }


def figure(data: dict) -> bytes:
    """The conventions of :func:`facts` drawn: the camera image, the screen at turn 0 and at the half
    turn, and the tilts' sign (PNG bytes)."""
    import matplotlib.pyplot as plt

    from rigcad.plots import _png

    fig, axes = plt.subplots(1, 4, figsize=(15, 4.2))
    _camera_panel(axes[0], data["camera"])
    for ax, label in ((axes[1], "turn 0"), (axes[2], "half turn")):
        _screen_panel(ax, data["screen"], label)
    _tilt_panel(axes[3], data)
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    return _png(fig, dpi=90)


_ARROW = dict(arrowstyle="->", lw=1.6)


def _frame_arrows(ax, origin, length, labels, color) -> None:
    for (dx, dy), text in zip(((length, 0), (0, length)), labels):
        ax.annotate("", (origin[0] + dx, origin[1] + dy), origin, arrowprops={**_ARROW, "color": color})
        ax.text(origin[0] + 1.25 * dx, origin[1] + 1.25 * dy, text, color=color, ha="center", va="center")


def _camera_panel(ax, cam: dict) -> None:
    """The camera image, drawn as a file shows it (row 0 at the top)."""
    import matplotlib.pyplot as plt

    w, h = cam["resolution_px"]
    win = cam["window"]
    ax.add_patch(plt.Rectangle((0, 0), w, h, fill=False, lw=1.2))
    ax.add_patch(plt.Rectangle((win["col0"], win["row0"]), win["cols"], win["rows"], fill=False, ls="--", color="C2"))
    ax.text(win["col0"], win["row0"] - 18, f"window: rows {win['row0']}-{win['row0'] + win['rows'] - 1}, "
            f"cols {win['col0']}-{win['col0'] + win['cols'] - 1}", color="C2", fontsize=8)
    cx, cy = cam["principal_point_px"]
    ax.plot([cx], [cy], "+", color="C3", ms=12)
    ax.text(cx + 40, cy + 90, f"principal point\n({cx:g}, {cy:g}) px\nf = {cam['focal_px']:.0f} px",
            color="C3", fontsize=8)
    _frame_arrows(ax, (40, 60), 200, ("column", "row"), "k")
    up = "+y" if cam["row_axis"] == "-y" else "-y"
    ax.annotate("", (300, h - 60), (60, h - 60), arrowprops={**_ARROW, "color": "C0"})
    ax.annotate("", (60, h - 300), (60, h - 60), arrowprops={**_ARROW, "color": "C0"})
    ax.text(320, h - 60, f"rig {cam['column_axis']}", color="C0", va="center")
    ax.text(60, h - 340, f"rig {up}", color="C0", ha="center")
    ax.text(0, -20, "pixel (row 0, col 0) at top left, its centre at (0.5, 0.5)", fontsize=8)
    ax.set_xlim(-40, w + 40)
    ax.set_ylim(h + 40, -60)
    ax.set_aspect("equal")
    ax.set_title("camera image as stored (the camera looks down)", fontsize=10)


def _screen_panel(ax, scr: dict, label: str) -> None:
    """The screen seen from above at one turn (``label``: 'turn 0' or 'half turn')."""
    import matplotlib.pyplot as plt

    sw, sh = scr["size_mm"]
    s = scr[label]
    flip = -1.0 if s["u"] == "-x" else 1.0
    ax.add_patch(plt.Rectangle((-sw / 2, -sh / 2), sw, sh, fill=False, lw=1.2))
    corner = (flip * -sw / 2, flip * sh / 2)  # pixel (0, 0): u = -W/2, v = +H/2
    ax.plot(*corner, "s", color="C3", ms=7)
    ax.text(corner[0] + flip * 6, corner[1] - flip * 10, "pixel (0, 0)", color="C3", fontsize=8,
            ha="left" if flip > 0 else "right")
    ax.annotate("", (flip * 45, 0), (0, 0), arrowprops={**_ARROW, "color": "k"})
    ax.annotate("", (0, flip * 45), (0, 0), arrowprops={**_ARROW, "color": "k"})
    ax.text(flip * 55, 0, "u (columns)", ha="center", va="center")
    ax.text(flip * 4, flip * 45, "v (rows run -v)", ha="left" if flip > 0 else "right", va="center")
    _frame_arrows(ax, (-sw / 2 + 8, -sh / 2 - 22), 30, ("rig +x", "rig +y"), "C0")
    ax.text(sw / 2 - 2, -sh / 2 - 22, f"du along rig {s['du']}, dv along rig {s['dv']}", color="C0",
            ha="right", fontsize=8)
    ax.plot([0], [0], "o", color="C1")
    ax.text(-flip * 4, -flip * 10, "(u, v) = (0, 0)\non the axis", color="C1", fontsize=8,
            ha="right" if flip > 0 else "left", va="center")
    ax.set_xlim(-sw / 2 - 15, sw / 2 + 15)
    ax.set_ylim(-sh / 2 - 40, sh / 2 + 15)
    ax.set_aspect("equal")
    ax.set_title(f"screen from above, {label}: u = rig {s['u']}, v = rig {s['v']}", fontsize=10)


def _tilt_panel(ax, data: dict) -> None:
    """The tilts' sign (side view along -x: +y to the right), and the Gray code's form."""
    ax.plot([-1, 1], [0, 0], color="0.6", lw=1)
    t = 0.25 if data["tilt"]["tilt_x_lifts"] == "+y" else -0.25
    ax.plot([-math.cos(t), math.cos(t)], [-math.sin(t), math.sin(t)], color="k", lw=2)
    ax.text(1.02, 0, "rig +y", color="C0", va="center", fontsize=8)
    ax.text(0, 0.45, f"tilt_x > 0 lifts the {data['tilt']['tilt_x_lifts']} side (drawn),\n"
                     f"tilt_y > 0 lifts the {data['tilt']['tilt_y_lifts']} side:\n"
                     "one rotation, vector (tilt_x, tilt_y, 0) rad,\nright-handed, about the part's pivot",
            ha="center", fontsize=8)
    g = data["gray"]
    ax.text(0, -0.75, f"Gray stripe k = floor(c / {g['stripe_px']:g}), c = index + 0.5\n"
                      f"shows k XOR (k >> 1), most significant bit first,\nwhite = 1: stripes 0-7 -> "
                      f"{', '.join(str(c) for c in g['codes_of_stripes_0_7'])}", ha="center", fontsize=8)
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(-1.1, 1.1)
    ax.set_title("tilts (side view) and the Gray code", fontsize=10)
