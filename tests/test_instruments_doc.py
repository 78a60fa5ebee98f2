"""docs/instruments.md holds to the code: its projector table (width x throw ratio, the fewest
pixels per degree the check's fan measures, the verdict against raycheck.min_px_per_deg) is computed
here on the default rig's geometry, and its printer examples load as printer files."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rigcad.check.criteria import cheap_rows
from rigcad.fab.printers import load_printer
from rigcad.profile import load_profile
from rigcad.rig import Rig

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "instruments.md").read_text()


def _table() -> list[list[str]]:
    head = DOC.index("| projector | width x throw ratio |")
    rows = [ln for ln in DOC[head:].split("\n\n", 1)[0].splitlines()[2:]]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in rows]


def test_the_projector_table_is_what_the_check_measures(tmp_path):
    rows = _table()
    assert len(rows) == 4, rows
    for projector, focal, fewest, judged in rows:
        w, h = (int(v) for v in re.search(r"(\d+) x (\d+)", projector).groups())
        throw = float(re.search(r"throw ([\d.]+)", projector).group(1))
        path = tmp_path / f"p{w}_{str(throw).replace('.', '_')}.yaml"
        path.write_text(f"extends: achutha2006\nprojector:\n  resolution: [{w}, {h}]\n  throw_ratio: {throw}\n")
        rig = Rig.from_profile(load_profile(path))
        row = next(r for r in cheap_rows(rig) if r.key == "raycheck.min_px_per_deg")
        assert focal == f"{w * throw:.0f} px", (projector, focal)
        assert fewest == f"{row.measured:.2f}", (projector, fewest, row.measured)  # as the page rounds it
        assert judged == ("passes" if row.ok else "refused"), (projector, judged, row)


def _yaml_blocks() -> list[str]:
    return re.findall(r"```yaml\n(.*?)```", DOC[DOC.index("## Your printer"):], re.S)


def test_the_creality_example_loads_with_the_installed_bundle(tmp_path):
    from rigcad.fab import vendor as V

    if "Creality" not in V.available_bundles():
        pytest.skip("PrusaSlicer's Creality bundle is not installed (apt-get install prusa-slicer)")
    path = tmp_path / "ender3v2.yaml"
    path.write_text(_yaml_blocks()[0])
    printer = load_printer(path)
    assert printer.model == "Creality Ender-3 V2" and printer.nozzle == 0.4 and printer.layer_height == 0.16
    assert printer.slicer_config.effective()["printer_model"] == "ENDER3V2"


#: What File > Export > Export Config writes, in small: the figures rigcad reads from a configuration.
EXPORTED = """\
bed_shape = 0x0,250x0,250x210,0x210
max_print_height = 220
nozzle_diameter = 0.4
layer_height = 0.15
first_layer_height = 0.2
filament_diameter = 1.75
filament_density = 1.24
filament_type = PLA
printer_model = MK4
temperature = 215
bed_temperature = 60
"""


def test_the_exported_configuration_example_loads(tmp_path):
    text = re.sub(r"(?m)^   ", "", _yaml_blocks()[1])  # the example is indented in its list item
    (tmp_path / "prusa_mk4.ini").write_text(EXPORTED)
    path = tmp_path / "mk4.yaml"
    path.write_text(text)
    printer = load_printer(path)
    assert printer.model == "Original Prusa MK4" and printer.slicer_config.kind == "config"
    assert printer.layer_height == 0.15 and printer.build_volume.z == 220
