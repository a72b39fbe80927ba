"""The rules file: its shape checked with one line naming the file, and the first tool serving
a class chosen."""

from __future__ import annotations

import pytest

from cadkg.plan.rules import RulesError, parse_rules


def test_the_first_tool_serving_a_class_is_chosen() -> None:
    rules = parse_rules(
        '[robot]\nzones = ["Q"]\n[[tool]]\nname = "a"\nserves = ["X"]\n'
        '[[tool]]\nname = "b"\nserves = ["X", "Y"]\n',
        "robot.toml",
    )
    assert (rules.tool_for("X"), rules.tool_for("Y"), rules.tool_for("Z")) == ("a", "b", None)
    assert rules.names("zones") == ("Q",) and rules.number("clearance_m", 0.004) == 0.004


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[robot\n", "robot.toml: "),
        ("[cell]\n", "unknown table [cell]"),
        ("robot = 3\n", "'robot' must be a table"),
        ('[[tool]]\nserves = ["X"]\n', "[[tool]] number 1 has no name"),
        ('[[tool]]\nname = "a"\nserves = "X"\n', "[[tool]] a: serves must be a list of strings"),
    ],
)
def test_a_malformed_file_is_one_line_naming_it(text: str, words: str) -> None:
    with pytest.raises(RulesError) as raised:
        parse_rules(text, "robot.toml")
    assert words in str(raised.value) and str(raised.value).startswith("robot.toml: ")
    assert "\n" not in str(raised.value)


def test_a_setting_of_the_wrong_type_names_its_key() -> None:
    rules = parse_rules('[robot]\nzones = "Q"\nmissing_pin_data = "maybe"\n', "robot.toml")
    with pytest.raises(RulesError, match=r"\[robot\] zones must be a list of strings"):
        rules.names("zones")
    with pytest.raises(RulesError, match=r"missing_pin_data must be one of robot, human"):
        rules.choice("missing_pin_data", "robot", ("robot", "human"))
