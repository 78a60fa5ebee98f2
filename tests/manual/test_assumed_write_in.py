"""The manual's measure-first table sends an assumed instrument size to the instrument file the profile
chose (where the lab writes the figure it measures), not to the profile's section line; a size the
profile sets keeps its file:line."""

import textwrap

import rigcad
from rigcad.manual.document import assumed_sizes


def test_an_assumed_projector_size_goes_to_the_instrument_file(tmp_path):
    (tmp_path / "instruments").mkdir()
    (tmp_path / "instruments" / "lab_dlp.yaml").write_text(textwrap.dedent("""\
        kind: projector
        title: a lab's DLP projector
        resolution: [1920, 1080]
        throw_ratio: 1.64
        lens_offset: 0
        """), encoding="utf-8")
    path = tmp_path / "lab.yaml"
    path.write_text("extends: achutha2006\nprojector:\n  model: lab_dlp\n  body_depth: 240 mm\n", encoding="utf-8")
    rows = {r["key"]: r["set_in"] for r in assumed_sizes(rigcad.load(path).profile)}
    assert rows["projector.body_width"].endswith("instruments/lab_dlp.yaml"), rows["projector.body_width"]
    assert not any(v.endswith("lab.yaml:2") for v in rows.values()), rows  # never the section's line
