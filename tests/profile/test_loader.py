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


def test_shipped_profile_loads_by_name_from_any_folder(tmp_path, monkeypatch):
    """The packaged profiles are on the search path: no repository checkout needed; they are named
    the same wherever rigcad is installed (outputs must not depend on the install folder)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("RIGCAD_PROFILES", raising=False)
    raw = load_raw("achutha2006")
    assert str(raw.sources[0]) == "profiles/achutha2006.yaml"  # the file to edit, as the repository has it
    assert raw.marks[("layout", "cop_to_vertex")].startswith("profiles/achutha2006.yaml:")


def test_extends_a_shipped_profile_by_name_from_elsewhere(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.yaml").write_text("extends: achutha2006\nlayout:\n  cop_to_vertex: 30 cm\n")
    raw = load_raw(tmp_path / "mine.yaml")
    assert raw.data["layout"]["cop_to_vertex"] == "30 cm"
    assert raw.data["layout"]["sample_to_rim"] == "13.5 cm"  # from the shipped parent
    assert len(raw.sources) == 2


def test_env_folder_is_searched_before_the_package(tmp_path, monkeypatch):
    lab = tmp_path / "lab"
    lab.mkdir()
    (lab / "achutha2006.yaml").write_text("description: the lab's own copy\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RIGCAD_PROFILES", str(lab))
    raw = load_raw("achutha2006")
    assert raw.data == {"description": "the lab's own copy"}


def test_missing_name_says_where_it_looked(tmp_path, monkeypatch):
    lab = tmp_path / "lab"
    lab.mkdir()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RIGCAD_PROFILES", str(lab))
    with pytest.raises(ProfileError) as err:
        load_raw("nope")
    msg = str(err.value)
    assert "lab/ (none)" in msg and "RIGCAD_PROFILES" in msg
    assert "profiles/ (shipped with rigcad: achutha2006" in msg
    # the working folder has no profiles/: it is not listed, or it would read as a second "profiles/"
    assert msg.count("profiles/") == 1, msg
    assert "did you mean" not in msg  # nothing close to "nope"


def test_a_mistyped_name_gets_the_closest_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ProfileError) as err:
        load_raw("achuta2006")
    assert str(err.value).startswith("no profile 'achuta2006' (did you mean 'achutha2006'?): looked for ")
