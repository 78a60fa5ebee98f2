"""A printer whose material rigcad has no strength figures for is refused naming the printer file's
`material:` key and where it stands (or the file, when the key is missing): the newcomer's X1C
file had no `material:`, and `rigcad manual` said only "material 'unspecified'"."""

import pytest

from rigcad.errors import FabricationError
from rigcad.fab import loads as L
from rigcad.fab.printers import load_printer

X1C = """description: Bambu Lab X1 Carbon, PLA
model: Bambu Lab X1 Carbon
process: fdm
build_volume: {x: 256 mm, y: 256 mm, z: 256 mm}
slicer: prusa-slicer
layer_height: 0.2 mm
nozzle: 0.4 mm
filament_diameter: 1.75 mm
material_density_g_cm3: 1.24
"""


def test_a_missing_material_names_the_key_and_the_file(tmp_path):
    path = tmp_path / "x1c.yaml"
    path.write_text(X1C)
    with pytest.raises(FabricationError) as err:
        L.material(load_printer(path))
    msg = str(err.value)
    assert "'unspecified'" in msg and "`material:` key (one of PLA, ABS" in msg and "x1c.yaml" in msg, msg
    path.write_text(X1C + "material: PETG\n")  # stated, but unknown: its own line is named
    with pytest.raises(FabricationError, match=r"'PETG'.*`material:` key.*x1c.yaml:10"):
        L.material(load_printer(path))
    path.write_text(X1C + "material: PLA\n")
    assert L.material(load_printer(path)).name == "PLA"
