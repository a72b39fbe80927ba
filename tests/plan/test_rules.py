"""The rules file: its shape checked with one line naming the file, and the first tool serving
a class chosen."""

from __future__ import annotations

import re
import tomllib
from collections.abc import Iterator
from importlib import resources

import pytest

import cadkg.registry as registry
from cadkg.plan.rules import RulesError, check_settings, load_rules, parse_rules
from cadkg.usecase import Planner
from tests.conftest import ROOT

# A setting read as rules.number("key", ...), rules.names("key"), rules.choice("key", ...),
# rules.robot.get("key") or "key" in rules.robot.
_READ = re.compile(r'rules\.(?:number|names|choice|robot\.get)\(\s*"(\w+)"|"(\w+)" in rules\.robot')


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


def _planners() -> Iterator[tuple[str, Planner]]:
    for case in registry.use_cases():
        if case.planner is not None:
            yield case.name, case.planner


def _misspellings(key: str) -> list[str]:
    """Typos a person makes: a letter dropped, the unit left off, a dash, capitals, a suffix."""
    variants = {key[:-1], key[1:], key.replace("_", "-"), key.upper(), key + "s", key.split("_")[0]}
    variants |= {key.rsplit("_", 1)[0]} if "_" in key else set()
    return sorted(variants - {key})


def test_every_use_cases_default_rules_use_only_its_settings() -> None:
    planners = list(_planners())
    assert {name for name, _ in planners} >= {"iema", "elvez"}
    for name, planner in planners:
        rules = load_rules(planner.rules, f"the {name} default rules")
        assert check_settings(rules, planner.settings) is rules


def test_every_setting_the_planner_reads_is_declared() -> None:
    for name, planner in _planners():
        folder = ROOT / "src" / "cadkg" / "usecases" / name
        read = {a or b for path in folder.glob("plan*.py") for a, b in _READ.findall(path.read_text())}
        assert read <= planner.settings, f"{name} reads undeclared settings {read - planner.settings}"
        if planner.settings:
            assert read, f"{name} declares settings but none is read where looked for"


def test_every_misspelt_setting_is_refused_naming_it() -> None:
    for name, planner in _planners():
        for key in sorted(planner.settings):
            for typo in _misspellings(key):
                if typo in planner.settings:
                    continue
                rules = parse_rules(f"[robot]\n{typo} = 1\n", "robot.toml")
                with pytest.raises(RulesError) as raised:
                    check_settings(rules, planner.settings)
                assert f"unknown key [robot] {typo};" in str(raised.value), (name, typo)


def test_every_declared_setting_is_accepted() -> None:
    for _, planner in _planners():
        text = "[robot]\n" + "".join(f"{key} = 1\n" for key in sorted(planner.settings))
        rules = parse_rules(text, "robot.toml")
        assert check_settings(rules, planner.settings).robot.keys() == planner.settings


def test_a_tool_with_an_unknown_key_is_refused() -> None:
    with pytest.raises(RulesError, match=r"\[\[tool\]\] number 1: unknown key 'serve'"):
        parse_rules('[[tool]]\nname = "a"\nserve = ["X"]\n', "robot.toml")


def test_the_iema_default_file_documents_every_setting() -> None:
    text = resources.files("cadkg.usecases.iema").joinpath("plan-rules.toml").read_text()
    planner = registry.use_case("iema").planner
    assert planner is not None and tomllib.loads(text)["robot"]
    for key in planner.settings:
        assert re.search(rf"^#? ?{key} = |\b{key} = ", text, flags=re.M), key
