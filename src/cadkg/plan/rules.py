"""The rules file: what the cell's robot can do, in TOML.

::

    [robot]                    # settings the use case's tasks read (see docs/plan.md)
    zones = ["Q", "QE"]
    clearance_m = 0.004

    [[tool]]                   # a tool, and the task classes it serves
    name = "screwdriver"
    serves = ["PUNTALINO_vite", "CAPICORDA_vite"]

    [time]                     # the time model (cadkg.plan.times), every key optional
    person_task_s = 240

Every use case ships a default (``plan-rules.toml`` in its folder); a manifest names its own
with ``[plan] rules = "FILE"``, and ``cadkg plan --rules FILE`` overrides both. What a task
class is (a wire end's termination, an operation's code) is the use case's to say.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

from cadkg.errors import CadkgError
from cadkg.plan.times import CLASS_TABLES, NUMBERS, TIME_KEYS

__all__ = ["Rules", "RulesError", "Tool", "check_settings", "load_rules", "parse_rules"]


class RulesError(CadkgError):
    """A rules file that is not TOML or not of the expected shape (names the file and key)."""


@dataclass(frozen=True, slots=True)
class Tool:
    name: str
    serves: tuple[str, ...]


@dataclass(frozen=True)
class Rules:
    """``robot`` holds the ``[robot]`` settings; ``tools`` the ``[[tool]]`` entries in file order;
    ``time`` the ``[time]`` values the file gives, checked."""

    source: str
    robot: dict[str, Any] = field(default_factory=dict)
    tools: tuple[Tool, ...] = ()
    time: dict[str, Any] = field(default_factory=dict)
    # Task class → the first tool serving it: asked twice per wire.
    _serving: dict[str, str] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        serving: dict[str, str] = {}
        for tool in self.tools:
            for task_class in tool.serves:
                serving.setdefault(task_class, tool.name)
        object.__setattr__(self, "_serving", serving)

    def tool_for(self, task_class: str) -> str | None:
        """The first tool serving ``task_class``; None when no tool does."""
        return self._serving.get(task_class)

    def number(self, key: str, default: float) -> float:
        value = self.robot.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int | float) or value < 0:
            raise RulesError(f"{self.source}: [robot] {key} must be a non-negative number, not {value!r}")
        return float(value)

    def names(self, key: str, default: Sequence[str] = ()) -> tuple[str, ...]:
        value = self.robot.get(key, list(default))
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise RulesError(f"{self.source}: [robot] {key} must be a list of strings, not {value!r}")
        return tuple(value)

    def choice(self, key: str, default: str, allowed: Sequence[str]) -> str:
        value = self.robot.get(key, default)
        if value not in allowed:
            raise RulesError(
                f"{self.source}: [robot] {key} must be one of {', '.join(allowed)}, not {value!r}"
            )
        return str(value)


def parse_rules(text: str, source: str) -> Rules:
    """Rules from TOML ``text``; ``source`` names it in errors and reasons.

    Raises
    ------
    RulesError
        On a TOML syntax error (with its line) or an entry of the wrong shape.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise RulesError(f"{source}: {err}") from None
    unknown = sorted(set(data) - {"robot", "tool", "time"})
    if unknown:
        raise RulesError(f"{source}: unknown table [{unknown[0]}]; expected [robot], [[tool]] and [time]")
    robot = data.get("robot", {})
    if not isinstance(robot, dict):
        raise RulesError(f"{source}: 'robot' must be a table [robot]")
    tools = []
    entries = data.get("tool", [])
    if not isinstance(entries, list):
        raise RulesError(f"{source}: 'tool' must be an array of tables [[tool]]")
    for n, entry in enumerate(entries, 1):
        if not isinstance(entry, dict):
            raise RulesError(f"{source}: [[tool]] number {n} must be a table")
        extra = sorted(set(entry) - {"name", "serves"})
        if extra:
            raise RulesError(
                f"{source}: [[tool]] number {n}: unknown key {extra[0]!r}; expected name and serves"
            )
        name, serves = entry.get("name"), entry.get("serves", [])
        if not isinstance(name, str) or not name:
            raise RulesError(f'{source}: [[tool]] number {n} has no name = "..."')
        if not isinstance(serves, list) or not all(isinstance(s, str) for s in serves):
            raise RulesError(f"{source}: [[tool]] {name}: serves must be a list of strings")
        tools.append(Tool(name, tuple(serves)))
    return Rules(source, robot, tuple(tools), _time(data.get("time", {}), source))


def _seconds(value: Any, where: str, *, positive: bool = False) -> float:
    # bool is an int to Python: a time of `true` is a mistake, not 1 s.
    number = not isinstance(value, bool) and isinstance(value, int | float) and math.isfinite(value)
    if not number or value < 0 or (positive and value == 0):
        kind = "a positive number" if positive else "a non-negative number"
        raise RulesError(f"{where} must be {kind}, not {value!r}")
    return float(value)


def _time(table: Any, source: str) -> dict[str, Any]:
    """The ``[time]`` values the file gives, checked: each names the file and key when wrong."""
    if not isinstance(table, dict):
        raise RulesError(f"{source}: 'time' must be a table [time]")
    values: dict[str, Any] = {}
    for key, value in table.items():
        where = f"{source}: [time] {key}"
        if key in NUMBERS:
            values[key] = _seconds(value, where, positive=key == "robot_speed_m_s")
        elif key in CLASS_TABLES:
            if not isinstance(value, dict):
                raise RulesError(f"{where} must be a table [time.{key}] of task classes and seconds")
            values[key] = {
                str(name): _seconds(seconds, f"{source}: [time.{key}] {name}")
                for name, seconds in value.items()
            }
        elif key == "balance":
            if not isinstance(value, bool):
                raise RulesError(f"{where} must be true or false, not {value!r}")
            values[key] = value
        else:
            expected = ", ".join(sorted(TIME_KEYS))
            raise RulesError(f"{source}: unknown key [time] {key}; expected one of: {expected}")
    return values


def check_settings(rules: Rules, known: frozenset[str]) -> Rules:
    """``rules`` when every ``[robot]`` key is one of ``known`` (the use case's settings).

    Raises
    ------
    RulesError
        Naming the first unknown key and the keys there are.
    """
    unknown = sorted(set(rules.robot) - known)
    if unknown:
        expected = ", ".join(sorted(known)) or "none"
        raise RulesError(f"{rules.source}: unknown key [robot] {unknown[0]}; expected one of: {expected}")
    return rules


def load_rules(path: Path | Traversable, name: str | None = None) -> Rules:
    """Read a rules file (see :func:`parse_rules`); ``name`` says what it is in reasons.

    Raises
    ------
    RulesError
        When the file cannot be read or is malformed.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise RulesError(f"{path}: cannot read the rules file ({err})") from None
    return parse_rules(text, name or str(path))
