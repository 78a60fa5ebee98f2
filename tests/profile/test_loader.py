import pytest

from rigcad.errors import ProfileError
from rigcad.profile.loader import load_raw


def test_marks_point_at_the_defining_line(write_profile):
    path = write_profile("""
        layout:
          cop_to_vertex: 27 cm
          sample_to_rim: 13.5 cm
    """)
    raw = load_raw(path)
    assert raw.marks[("layout", "sample_to_rim")].endswith("p.yaml:3")


def test_extends_overrides_keys_and_keeps_marks(write_profile):
    write_profile("""
        layout:
          cop_to_vertex: 27 cm
          sample_to_rim: 13.5 cm
    """, name="base")
    child = write_profile("""
        extends: base
        layout:
          sample_to_rim: 15 cm
    """, name="child")
    raw = load_raw(child)
    assert raw.data["layout"] == {"cop_to_vertex": "27 cm", "sample_to_rim": "15 cm"}
    assert raw.marks[("layout", "sample_to_rim")].endswith("child.yaml:3")
    assert raw.marks[("layout", "cop_to_vertex")].endswith("base.yaml:2")
    assert raw.name == "child"


def test_extends_cycle_is_refused(write_profile):
    write_profile("extends: b\n", name="a")
    b = write_profile("extends: a\n", name="b")
    with pytest.raises(ProfileError, match="cycle"):
        load_raw(b)


def test_duplicate_key_is_refused_with_its_line(write_profile):
    path = write_profile("""
        layout:
          cop_to_vertex: 27 cm
          cop_to_vertex: 28 cm
    """)
    with pytest.raises(ProfileError, match=r"p\.yaml:3: key 'layout\.cop_to_vertex' is given twice"):
        load_raw(path)


def test_yaml_syntax_error_names_file_and_line(write_profile):
    path = write_profile("layout:\n  cop_to_vertex: [27 cm\n")
    with pytest.raises(ProfileError, match=r"p\.yaml:\d+: YAML syntax"):
        load_raw(path)


def test_missing_profile_lists_known_ones(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "profiles").mkdir()
    (tmp_path / "profiles" / "known.yaml").write_text("{}\n")
    with pytest.raises(ProfileError, match="known"):
        load_raw("unknown")
