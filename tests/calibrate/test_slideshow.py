"""The calibration screen's frames advance with the dome on (rigcad.calibrate.slideshow): one page holds
every frame, byte for byte the kit's PNGs, in capture order, and asks for nothing outside itself; the
displays are named by what to buy (resolution, pitch, density, diagonal from closed forms); the upright
display's stand lets its cable out below the plate."""

from __future__ import annotations

import math
import re

import numpy as np

import rigcad
from rigcad.calibrate import kit
from rigcad.calibrate.patterns import Sequence
from rigcad.calibrate.slideshow import frames_of, slideshow_page


def test_the_slideshow_holds_every_frame_in_capture_order(table31):
    seq = Sequence.from_profile(table31.calibration)
    frames = [(n, kit.pattern_png(seq, n)) for n in seq.names()]
    page = slideshow_page("t", frames, seq.resolution)
    assert frames_of(page) == frames  # the same bytes, in the capture order the page shows them
    text = page.decode()
    assert not re.search(r"""(src|href)\s*=\s*["'](?!data:)""", text), "the page refers to a file or URL"
    assert "default-src 'none'" in text and "fetch(" not in text and "XMLHttpRequest" not in text
    # planted: two frames swapped, the page no longer shows the capture order
    swapped = [frames[1], frames[0], *frames[2:]]
    assert frames_of(slideshow_page("t", swapped, seq.resolution)) != frames


def test_a_display_is_named_by_what_to_buy():
    ipad = kit.display_spec((2266, 1488), 0.0779)
    # 326 ppi and 8.3 inches: the closed forms 25.4 / pitch and the diagonal in pixels x pitch
    assert round(ipad["ppi"]) == 326 and abs(ipad["diagonal_in"] - math.hypot(2266, 1488) * 0.0779 / 25.4) < 1e-12
    assert "iPad mini" in ipad["known_as"] and "8.3-inch" in kit.display_text(ipad)
    assert kit.display_spec((2266, 1488), 0.08)["known_as"] is None  # another pitch is another display
    small = kit.display_spec((240, 320), 0.1275)
    assert "ST7789" in small["known_as"] and abs(small["diagonal_in"] - 2.0) < 0.01  # a 2.0-inch module


def test_the_upright_stand_lets_the_cable_out_below(table31_rig):
    """A vertical line through the channel, from the slot's floor to under the collar, meets no material;
    either side of the channel the slot's floor is solid (the module stands on its two ledges)."""
    p = table31_rig.profile
    part = kit.upright_stand(p)
    mesh = table31_rig.mesh(part)
    room = kit.upright_room(p)
    cal = p.calibration
    floor = -cal.upright_depth - cal.upright_border
    bottom = -p.base_plate.thickness - p.sample_holder.stop_thickness
    x = 0.5 * (room["front_mm"] + room["back_mm"])
    z = np.linspace(bottom + 0.2, floor - 0.2, 40)
    line = np.column_stack([np.full_like(z, x), np.zeros_like(z), z])
    assert not mesh.contains(line).any(), "the cable channel is blocked"
    ledge = 0.5 * (room["cable_half_mm"] + room["half_width_mm"])
    under = np.array([[x, s * ledge, floor - 0.5] for s in (-1, 1)])
    assert mesh.contains(under).all(), "the module's ledges are not there"
    assert room["cable_half_mm"] > 5.0  # room for a display's flat cable (the modules' are 10-20 mm wide)


def test_the_kit_page_says_how_the_frames_advance_and_the_bill_has_what_drives_them(table31_rig):
    from rigcad.manual import calibration as C

    page = kit.manual_page(table31_rig)
    assert "patterns/slideshow.html" in page and "interval timer" in page and "fbi" in page
    items = C.kit_items(table31_rig)
    assert any("raspberry pi" in it.words for it in items)
    assert any("iPad mini" in it.spec for it in items if "tablet" in it.words)
