"""The optimize: section is validated like the rest of a profile: one line naming the key, its
file:line and what would be valid."""

from __future__ import annotations

import pytest

from rigcad.errors import ProfileError
from rigcad.optimize.run import load_problem

GOOD = """
optimize:
  parameters:
    layout.cop_to_vertex: [20 cm, 45 cm]
  objectives:
    theta_min: minimize
"""


def test_a_good_section_reads_with_units(write_profile):
    pb = load_problem(write_profile("good", GOOD))
    (p,) = pb.spec.parameters
    assert (p.key, p.lo, p.hi, p.base) == ("layout.cop_to_vertex", 200.0, 450.0, 270.0)  # mm
    assert pb.spec.objectives == (("theta_min", "minimize"),)


@pytest.mark.parametrize("text, match", [
    (GOOD.replace("[20 cm, 45 cm]", "[20, 45]"), r"good.yaml:5: optimize.parameters.layout.cop_to_vertex: .*unit"),
    (GOOD.replace("theta_min: minimize", "theta_low: minimize"), r"good.yaml:7: .*unknown objective.*did you mean 'theta_min'"),
    (GOOD.replace("theta_min: minimize", "theta_min: smaller"), r"good.yaml:7: .*one of minimize, maximize"),
    (GOOD.replace("layout.cop_to_vertex", "layout.cop_to_vertx"), r"good.yaml:5: .*not a free parameter.*did you mean"),
    (GOOD.replace("layout.cop_to_vertex", "paraboloid.focal_length"), r"does not set paraboloid.focal_length"),
    (GOOD.replace("[20 cm, 45 cm]", "[45 cm, 20 cm]"), r"low < high"),
    (GOOD + "  constraints:\n    max_pieces: 4\n", r"max_pieces needs optimize.constraints.printer"),
    (GOOD + "  constraints:\n    printer: no_such_printer\n", r"no_such_printer"),
    (GOOD + "  evaluations: 5\n", r"optimize.evaluations: expected a whole number 10"),
    (GOOD + "  sed: 3\n", r"unknown key optimize.sed.*did you mean 'seed'"),
])
def test_bad_sections_are_refused_naming_key_and_line(write_profile, text, match):
    with pytest.raises(ProfileError, match=match):
        load_problem(write_profile("good", text))


def test_a_profile_without_the_section_says_where_to_look(write_profile):
    with pytest.raises(ProfileError, match="no 'optimize:' section.*achutha2006_optimize.yaml"):
        load_problem(write_profile("plain", "description: no search here\n"))


def test_other_commands_accept_the_section(write_profile):
    from rigcad.profile import load_profile

    assert load_profile(write_profile("good", GOOD)).layout.cop_to_vertex == 270.0


def test_command_line_overrides_are_checked(write_profile):
    with pytest.raises(ProfileError, match=r"--evaluations 5: expected a whole number 10"):
        load_problem(write_profile("good", GOOD), {"evaluations": 5})
