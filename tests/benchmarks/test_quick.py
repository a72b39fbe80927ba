"""benchmarks/quick.py: a benchmark's ``--quick`` is its own options' values, shown by ``--help``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from quick import add_quick, parse


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser()
    parser.add_argument("--wires", type=int, default=10_000)
    parser.add_argument("--baseline-calls", type=int, default=200)
    add_quick(parser, wires=300, baseline_calls=20)
    return parser


def test_quick_sets_its_values_over_the_given_ones() -> None:
    assert vars(parse(_parser(), ["--wires", "5", "--quick"])) | {"quick": None} == {
        "wires": 300,
        "baseline_calls": 20,
        "quick": None,
    }


def test_without_quick_the_options_are_as_given() -> None:
    args = parse(_parser(), ["--wires", "5"])
    assert (args.wires, args.baseline_calls, args.quick) == (5, 200, None)


def test_the_help_shows_the_settings_as_options() -> None:
    assert "a smoke test: --wires 300 --baseline-calls 20" in " ".join(_parser().format_help().split())


def test_a_setting_the_benchmark_has_no_option_for_is_refused() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--wires", type=int)
    add_quick(parser, wires=300, runs=1)
    with pytest.raises(ValueError, match="'runs'"):
        parse(parser, ["--quick"])
