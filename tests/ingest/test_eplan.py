"""EPLAN device tags and pin references, and the decimal parser of text cells."""

from __future__ import annotations

import random
import re
from decimal import Decimal

import pytest

from cadkg.ingest.eplan.labels import PinRef, PinSyntaxError, normalize_label, parse_pin_ref
from cadkg.ingest.text import Row, iter_rows, parse_decimal


@pytest.mark.parametrize(
    ("raw", "component", "pin", "level", "key"),
    [
        ("-F1500.1:14", "F1500.1", "14", None, "F1500.1:14"),
        ("=-F1500.1:1", "F1500.1", "1", None, "F1500.1:1"),
        ("-X1600:2:a", "X1600", "2", "a", "X1600:2:a"),
        ("-X0030.1:1L+.2:a2", "X0030.1", "1L+.2", "a2", "X0030.1:1L+.2:a2"),
        ("=A1+ST1-K3:13", "K3", "13", None, "K3:13"),
        ("F1500.1:14", "F1500.1", "14", None, "F1500.1:14"),
        ("=-T0020.1:+", "T0020.1", "+", None, "T0020.1:+"),
        ("=-T0020.1:-", "T0020.1", "-", None, "T0020.1:-"),
        ("  -Q1500.1:A2  ", "Q1500.1", "A2", None, "Q1500.1:A2"),
    ],
)
def test_good_pin_refs(raw: str, component: str, pin: str, level: str | None, key: str) -> None:
    ref = parse_pin_ref(raw)
    assert ref == PinRef(component=component, pin=pin, level=level, raw=raw.strip())
    assert ref.key == key


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        ("F1500.1-14", "no ':' between device and pin"),
        (":14", "no device tag before ':'"),
        ("-:14", "no device tag before ':'"),
        ("-F1:", "empty part or white space inside the reference"),
        ("-F1:1:", "empty part or white space inside the reference"),
        ("-F1:1:a:b", "more than DEVICE:PIN:LEVEL"),
        ("-F 1:1", "empty part or white space inside the reference"),
        ("-F1:1 2", "empty part or white space inside the reference"),
        ("", "no ':' between device and pin"),
        ("   ", "no ':' between device and pin"),
    ],
)
def test_bad_pin_refs(raw: str, message: str) -> None:
    with pytest.raises(PinSyntaxError, match=message):
        parse_pin_ref(raw)


def test_pin_syntax_error_is_a_value_error() -> None:
    assert issubclass(PinSyntaxError, ValueError)


@pytest.mark.parametrize(
    ("raw", "label"),
    [
        ("=-F1500.1", "F1500.1"),
        ("-F1500.1", "F1500.1"),
        ("F1500.1", "F1500.1"),
        ("=A1+ST1-K3", "K3"),
        ("=A1-K3", "K3"),
        ("+ST1-K3", "K3"),
        ("=-U3", "U3"),
        ("  -T0020.1 ", "T0020.1"),
        ("-X1-2", "X1-2"),
        ("=A1+ST1-K3-1", "K3-1"),
        ("", ""),
    ],
)
def test_normalize_label(raw: str, label: str) -> None:
    assert normalize_label(raw) == label


@pytest.mark.parametrize(
    ("text", "number", "unit"),
    [
        ("1,5 mm²", "1.5", "mm²"),
        ("0,75 mm²", "0.75", "mm²"),
        ("2,5 mm²", "2.5", "mm²"),
        ("2,5mm2", "2.5", "mm2"),
        ("1 mm²", "1", "mm²"),
        ("0,474 m", "0.474", "m"),
        ("746 mm", "746", "mm"),
        ("746", "746", ""),
        ("0.75", "0.75", ""),
        ("1.234,5", "1234.5", ""),
        ("1,234.5", "1234.5", ""),
        ("1.234.567,89", "1234567.89", ""),
        ("  1,5\u00a0mm²  ", "1.5", "mm²"),
        ("-0,5", "-0.5", ""),
    ],
)
def test_parse_decimal(text: str, number: str, unit: str) -> None:
    value, found_unit = parse_decimal(text)
    assert isinstance(value, Decimal)
    assert value == Decimal(number)
    assert str(value) == number
    assert found_unit == unit


@pytest.mark.parametrize(
    "text", ["abc", "nan", "NaN", "inf", "-Infinity", "", "  ", "mm²", "m", "1,5 cm", "1 2"]
)
def test_parse_decimal_rejects(text: str) -> None:
    with pytest.raises(ValueError):
        parse_decimal(text)


def test_iter_rows_reports_the_start_line_of_multi_line_records() -> None:
    text = 'a\tb\n"x\ny"\tz\n\nlast\tq\r\n'
    assert list(iter_rows(text, "\t")) == [
        Row(1, ("a", "b")),
        Row(2, ("x\ny", "z")),
        Row(4, ()),
        Row(5, ("last", "q")),
    ]
    assert Row(4, ()).is_blank
    assert Row(5, (" q ",)).cell(0) == "q"
    assert Row(5, ("q",)).cell(3) == ""


def _checked_parse(raw: str) -> PinRef | str:
    """The reference as the step-by-step checks read it, without the one-match shortcut."""
    from cadkg.ingest.eplan import labels as eplan

    saved = eplan._PLAIN_REF
    eplan._PLAIN_REF = re.compile(r"(?!)")  # never matches
    try:
        return parse_pin_ref(raw)
    except PinSyntaxError as err:
        return str(err)
    finally:
        eplan._PLAIN_REF = saved


def test_one_match_shortcut_reads_every_reference_as_the_checks_do() -> None:
    # Random references over the characters that matter to the syntax: the shortcut must
    # give the same parts, or leave the reference to the checks, never differ.
    rng = random.Random(7)
    alphabet = "=+-:; \t" + "FX1.a" * 4
    for _ in range(20000):
        raw = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 12)))
        try:
            fast: PinRef | str = parse_pin_ref(raw)
        except PinSyntaxError as err:
            fast = str(err)
        assert fast == _checked_parse(raw), raw
    assert parse_pin_ref("=-X0030.1:1L+.2:a2") == _checked_parse("=-X0030.1:1L+.2:a2")
