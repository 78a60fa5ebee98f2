"""A printer file names the files rigcad reads for it (``slicer.vendor_bundle``) and the command
line names the printer file (``--printer``): neither reaches a file outside the profile folders,
the printer file's own folder and the installed PrusaSlicer bundles. A refused file is never
opened, so its content is never quoted in the error nor copied into the exports. (On the code
before this check: /etc/passwd's and /etc/shadow's first lines were quoted, /proc/self/environ
was accepted as a configuration.)"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from rigcad.errors import ProfileError
from rigcad.fab import vendor as V
from rigcad.fab.printers import load_printer

from .test_vendor import line_of, needs_bundle, printer_yaml

_opened: list[str] = []
_watching = False


def _audit(event: str, args) -> None:
    if _watching and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        _opened.append(os.path.realpath(os.fsdecode(args[0])))


sys.addaudithook(_audit)


def refusal(spec) -> tuple[str, list[str]]:
    """Load a printer (a path, or a printer file); the refusal's text and every file opened."""
    global _watching
    _opened.clear()
    _watching = True
    try:
        with pytest.raises(ProfileError) as err:
            load_printer(spec)
    finally:
        _watching = False
    return str(err.value), list(_opened)


def first_line(path: str) -> str:
    """The start of a system file's first line (what the old errors quoted); NUL-separated for environ."""
    data = Path(path).read_bytes()
    return data.split(b"\n")[0].split(b"\0")[0].decode("utf-8", "replace")[:24]


SYSTEM_FILES = ["/etc/passwd", "/etc/shadow", "/proc/self/environ"]


@pytest.mark.parametrize("target", SYSTEM_FILES + ["../../../../../../../../etc/passwd", "link"])
def test_vendor_bundle_reads_no_file_outside(tmp_path, target):
    if target == "link":  # a .ini beside the printer file that leads to /etc/passwd
        (tmp_path / "mine.ini").symlink_to("/etc/passwd")
        target, real = "mine.ini", "/etc/passwd"
    else:
        real = os.path.realpath(tmp_path / target) if not target.startswith("/") else target
    if not os.access(real, os.R_OK):
        pytest.skip(f"{real} is not readable here, so there is nothing to leak")
    path = printer_yaml(tmp_path, f"slicer:\n  vendor_bundle: {target}\n")
    msg, opened = refusal(path)
    assert f"mk3s.yaml:{line_of(path, 'vendor_bundle')}: slicer.vendor_bundle" in msg
    assert first_line(real) not in msg, "the refused file's content was quoted"
    assert os.path.realpath(real) not in opened, "the refused file was opened"
    assert "\n" not in msg


@pytest.mark.parametrize("target", SYSTEM_FILES)
def test_printer_reads_no_system_file(target):
    if not os.access(target, os.R_OK):
        pytest.skip(f"{target} is not readable here")
    msg, opened = refusal(target)
    assert first_line(target) not in msg and "root" not in msg.replace(target, ""), msg
    assert target not in opened
    assert "not read" in msg


def test_a_printer_file_linked_to_a_system_file_is_not_read(tmp_path):
    link = tmp_path / "printer.yaml"
    link.symlink_to("/etc/shadow")
    msg, opened = refusal(link)
    assert "/etc/shadow" not in opened and "not read" in msg and first_line("/etc/shadow") not in msg


@needs_bundle
def test_allowed_places_still_work(tmp_path, monkeypatch):
    """A .ini on the profile search path ($RIGCAD_PROFILES) by absolute path, and an installed
    bundle by its path, are read as before."""
    shipped = V.find_bundle("PrusaResearch")
    mk3s = load_printer("prusa_mk3s").slicer_config
    eff = mk3s.effective()
    lab = tmp_path / "lab"
    lab.mkdir()
    (lab / "mk3s.ini").write_text("".join(f"{k} = {v}\n" for k, v in sorted(eff.items())))
    monkeypatch.setenv("RIGCAD_PROFILES", str(lab))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    p = load_printer(printer_yaml(elsewhere, f"slicer:\n  vendor_bundle: {lab / 'mk3s.ini'}\n"))
    assert p.slicer_config.kind == "config" and p.slicer_config.effective() == eff
    section = ("slicer:\n  vendor_bundle: {}\n  printer_preset: Original Prusa i3 MK3S & MK3S+\n"
               "  print_preset: 0.15mm QUALITY @MK3\n  filament_preset: Prusament PLA\n")
    p = load_printer(printer_yaml(elsewhere, section.format(shipped)))
    assert p.slicer_config.settings == mk3s.settings  # the same presets (without the shipped file's overrides)
    monkeypatch.delenv("RIGCAD_PROFILES")
    msg, _ = refusal(printer_yaml(elsewhere, f"slicer:\n  vendor_bundle: {lab / 'mk3s.ini'}\n"))
    assert "leads outside the printer file's folder and the profile search path" in msg


@pytest.mark.parametrize("first_line", ["DECOY-SECRET-not-for-the-exports: 1", "root:x:0:0:root:/root:/bin/bash: 1",
                                        "AKIA0123456789SECRET/xyz: 1"])
def test_a_yaml_file_that_is_not_a_printer_is_refused_without_quoting_it(tmp_path, first_line):
    """--printer names a YAML file that is not a printer (a credentials or notes file): the error says
    where it is and what would be valid, never what its first key says."""
    path = tmp_path / "notes.yaml"
    path.write_text(first_line + "\n")
    with pytest.raises(ProfileError) as err:
        load_printer(path)
    secret = first_line.rsplit(":", 1)[0]
    assert secret not in str(err.value) and "not shown" in str(err.value) and "notes.yaml:1" in str(err.value)


def test_a_mistyped_printer_key_is_still_named(tmp_path):
    path = tmp_path / "typo.yaml"
    path.write_text("layer_heigth: 0.2 mm\n")
    with pytest.raises(ProfileError, match=r"unknown printer key 'layer_heigth' \(did you mean 'layer_height'\?\)"):
        load_printer(path)
