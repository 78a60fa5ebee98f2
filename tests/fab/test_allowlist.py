"""rigcad.fab.allowlist against the installed PrusaSlicer 2.5 and the vendor bundles it ships:
every setting classified, no shipped preset refused, out-of-range and non-print settings in a
printer file's overrides refused with their file:line and why."""

from __future__ import annotations

import json

import pytest

from rigcad.errors import ProfileError
from rigcad.fab import allowlist as A
from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer

from .test_vendor import line_of, needs_bundle, needs_slicer, printer_yaml, slicer_section


@needs_slicer
def test_every_prusaslicer_setting_is_classified():
    """Each key the installed PrusaSlicer knows is either allowed or refused with a reason, so a
    new slicer version's setting is a decision, not a silent pass."""
    unclassified = sorted(k for k in V.slicer_keys() if k not in A.ALLOWED_KEYS and k not in A.REFUSED)
    assert unclassified == []


@needs_bundle
def test_every_installed_vendor_preset_passes_the_allow_list():
    """The ranges and checks refuse no preset PrusaSlicer ships (1,393 presets in the 18 bundles
    of Debian's prusa-slicer 2.5.0)."""
    n = 0
    for path in V.available_bundles().values():
        b = V.load_bundle(path)
        for g in ("print", "printer", "filament"):
            for name in b.presets(g):
                flat = {k: v for k, v in b.flatten(g, name).items() if k not in V.BUNDLE_ONLY}
                kept = A.filter_preset(flat, lambda k, b=b, g=g, name=name: b.where_set(g, name, k))
                assert "post_process" not in kept and "output_filename_format" not in kept
                n += 1
    assert n > 100  # the bundles were read, not skipped


@needs_bundle
@pytest.mark.parametrize("key, value, expect", [
    ("temperature", 2150, r"2150 degC is outside 0..500 degC"),
    ("bed_temperature", -5, r"-5 degC is outside 0..200"),
    ("perimeters", 100000, r"100000 is outside 0..1000"),
    ("start_gcode", "M104 S2900", r"'M104 S2900' sets 2900 degC, outside 0..500"),
    ("threads", 64, r"refused: sets how this machine runs PrusaSlicer"),
    ("print_host", "evil.example", r"refused: names a print host"),
    ("bed_custom_texture", "/etc/passwd", r"refused: names a file"),
    ("gcode_substitutions", "M104\\nM104 S290", r"refused: rewrites the finished G-code"),
])
def test_overrides_out_of_range_or_not_shaping_the_print_are_refused(tmp_path, key, value, expect):
    path = printer_yaml(tmp_path, slicer_section(overrides=f"    {key}: {json.dumps(value)}\n"))
    line = line_of(path, f"    {key}:")
    with pytest.raises(ProfileError, match=rf"mk3s.yaml:{line}: slicer.overrides.{key}: {expect}"):
        load_printer(path)
