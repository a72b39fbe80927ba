"""The statements of the harness text description: one per line, checked against the grammar,
and the values they hold (names, lengths, sections, cavity lists)."""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import small_integer

__all__ = ["EXPECTED", "FILE_FORMAT", "GRAMMAR", "Statement", "StatementReader", "split_words"]

FILE_FORMAT = "cadkg harness text 1"
EXPECTED = (
    "a harness description: a first statement 'harness NAME', then connector, node, segment, wire ... lines"
)
_NAME = re.compile(r"^[^\s:,=#\"']+$")
_CAVITY = re.compile(r"^[^\s,=#\"']+$")
_LENGTH = re.compile(r"^(?P<number>\d+(?:\.\d*)?|\.\d+)(?P<unit>mm|cm|m)$")
_COORDINATE = re.compile(r"^(?P<number>[+-]?(?:\d+(?:\.\d*)?|\.\d+))(?P<unit>mm|cm|m)$")
_SECTION = re.compile(r"^(?P<number>\d+(?:\.\d*)?|\.\d+)(?:mm2|mm²)?$")
_RANGE = re.compile(r"^(?P<first>\d+)-(?P<last>\d+)$")
_METRES = {"mm": Decimal("0.001"), "cm": Decimal("0.01"), "m": Decimal(1)}
# Cavities of one connector: the largest connectors have a few hundred.
_MAX_CAVITIES = 1000
# Statement → (number of positional words after the keyword, required keys, optional keys).
GRAMMAR: dict[str, tuple[tuple[str, ...], frozenset[str], frozenset[str]]] = {
    "harness": (("name",), frozenset(), frozenset({"description"})),
    "connector": (("name",), frozenset({"cavities"}), frozenset({"at", "description", "position"})),
    "node": (("name",), frozenset(), frozenset({"position"})),
    "segment": (("name", "from-node", "to-node"), frozenset({"length"}), frozenset({"diameter", "section"})),
    "wire": (
        ("name", "from connector:cavity", "to connector:cavity"),
        frozenset(),
        frozenset({"section", "colour", "length", "diameter", "route", "cable", "signal"}),
    ),
    "cable": (("name",), frozenset(), frozenset({"length", "diameter"})),
    "fixing": (("name",), frozenset({"on"}), frozenset({"description"})),
    "protection": (("name",), frozenset({"on"}), frozenset({"length", "description"})),
}


_BLANKS = " \t\r\n"
_GAP = re.compile(r"[ \t\r\n]*")
_PLAIN = re.compile(r"[^ \t\r\n#'\"\\]+")
_DOUBLE_QUOTED = re.compile(r'[^"\\]+')


def split_words(line: str) -> list[str]:
    """The words of ``line`` as ``shlex`` splits them in POSIX mode on blanks, ``#`` starting a
    comment: quotes join, ``\\`` escapes (in double quotes only a quote or a backslash).

    shlex grows each word a character at a time, which takes time with the square of a word's
    length; this takes each run of plain characters at once, in time linear in the line.

    Raises
    ------
    ValueError
        ``No closing quotation`` or ``No escaped character``, as shlex does.
    """
    words: list[str] = []
    at, end = 0, len(line)
    while True:
        gap = _GAP.match(line, at)
        assert gap is not None  # it matches the empty string
        at = gap.end()
        if at == end:
            return words
        parts: list[str] = []
        started = False
        while at < end and line[at] not in _BLANKS:
            char = line[at]
            if char == "#":  # the rest of the line is a comment, and it ends a word
                at = end if (newline := line.find("\n", at)) < 0 else newline + 1
                break
            started = True
            if char == "'":
                close = line.find("'", at + 1)
                if close < 0:
                    raise ValueError("No closing quotation")
                parts.append(line[at + 1 : close])
                at = close + 1
            elif char == '"':
                at = _double_quoted(line, at + 1, parts)
            elif char == "\\":
                if at + 1 == end:
                    raise ValueError("No escaped character")
                parts.append(line[at + 1])
                at += 2
            else:
                plain = _PLAIN.match(line, at)
                assert plain is not None  # line[at] is none of the characters it stops at
                parts.append(plain.group())
                at = plain.end()
        if started:
            words.append("".join(parts))


def _double_quoted(line: str, at: int, parts: list[str]) -> int:
    """Where the double-quoted text from ``at`` ends (after its quote), its text put in ``parts``."""
    while True:
        run = _DOUBLE_QUOTED.match(line, at)
        if run is not None:
            parts.append(run.group())
            at = run.end()
        if at == len(line):
            raise ValueError("No closing quotation")
        if line[at] == '"':
            return at + 1
        if at + 1 == len(line):  # a backslash last
            raise ValueError("No escaped character")
        escaped = line[at + 1]
        parts.append(escaped if escaped in '"\\' else "\\" + escaped)
        at += 2


@dataclass
class Statement:
    """One statement: its keyword, positional words, ``key=value`` options and line."""

    keyword: str
    words: list[str]
    options: dict[str, str]
    line: int


class StatementReader:
    """Reads statements and their values, with errors located at their line."""

    def __init__(self, path: str | Path) -> None:
        self.path = path

    def error(
        self, reason: str, line: int, found: object | None = None, expected: str | None = None
    ) -> IngestError:
        return IngestError(self.path, reason, line=line, found=found, expected=expected)

    # -- statements ---------------------------------------------------------------------------------
    def statement(self, raw: str, line: int) -> Statement | None:
        try:
            tokens = split_words(raw.rstrip("\r"))
        except ValueError as err:
            raise self.error(
                f"cannot split the line into words: {err}", line, expected="closed quotes"
            ) from None
        if not tokens:
            return None
        keyword, rest = tokens[0], tokens[1:]
        if keyword not in GRAMMAR:
            raise self.error("unknown statement", line, found=keyword, expected=" | ".join(GRAMMAR))
        positional, required, optional = GRAMMAR[keyword]
        words = [w for w in rest if "=" not in w]
        options: dict[str, str] = {}
        for token in rest:
            key, sep, value = token.partition("=")
            if not sep:
                continue
            if key not in required | optional:
                known = ", ".join(sorted(required | optional)) or "none"
                raise self.error(f"unknown key of '{keyword}'", line, found=key, expected=f"one of: {known}")
            if key in options:
                raise self.error(f"key given twice in '{keyword}'", line, found=key, expected="each key once")
            if not value:
                raise self.error(f"empty value of {key}=", line, expected=f"{key}=VALUE")
            options[key] = value
        if len(words) != len(positional):
            raise self.error(
                f"'{keyword}' takes {len(positional)} word(s) before its options",
                line,
                found=" ".join(words) or "none",
                expected=f"{keyword} {' '.join(p.upper() for p in positional)}",
            )
        missing = sorted(required - set(options))
        if missing:
            raise self.error(f"'{keyword}' needs {missing[0]}=", line, expected=f"{missing[0]}=VALUE")
        if not _NAME.match(words[0]):
            raise self.error(
                f"malformed {keyword} name",
                line,
                found=words[0],
                expected="a name without blanks, : , = # or quotes",
            )
        return Statement(keyword, words, options, line)

    def length(self, s: Statement, key: str) -> Decimal | None:
        raw = s.options.get(key)
        if raw is None:
            return None
        match = _LENGTH.match(raw)
        if match is None or Decimal(match["number"]) == 0:
            raise self.error(
                f"malformed {key}",
                s.line,
                found=raw,
                expected="a positive number with mm, cm or m, e.g. 250mm",
            )
        return Decimal(match["number"]) * _METRES[match["unit"]]

    def position(self, s: Statement) -> tuple[float, float, float]:
        """``position=X,Y,Z``: each with its unit, metres in REP 103 axes (x forward, y left, z up)."""
        raw = s.options["position"]
        matches = [_COORDINATE.match(part) for part in raw.split(",")]
        if len(matches) != 3 or any(m is None for m in matches):
            raise self.error(
                "malformed position",
                s.line,
                found=raw,
                expected="x,y,z each with mm, cm or m, e.g. 1200mm,-350mm,400mm",
            )
        x, y, z = (float(Decimal(m["number"]) * _METRES[m["unit"]]) for m in matches if m is not None)
        return (x, y, z)

    def section(self, s: Statement) -> Decimal | None:
        raw = s.options.get("section")
        if raw is None:
            return None
        match = _SECTION.match(raw)
        try:
            value = Decimal(match["number"]) if match else Decimal(0)
        except InvalidOperation:
            value = Decimal(0)
        if value <= 0:
            raise self.error(
                "malformed section",
                s.line,
                found=raw,
                expected="a positive number of mm², e.g. 0.35 or 0.35mm2",
            )
        return value

    def names(self, s: Statement, key: str) -> list[str]:
        names = s.options.get(key, "").split(",") if key in s.options else []
        for name in names:
            if not _NAME.match(name):
                raise self.error(
                    f"malformed name in {key}=",
                    s.line,
                    found=name or "an empty name",
                    expected="names separated by commas",
                )
        return names

    def cavities(self, s: Statement) -> tuple[str, ...]:
        names: list[str] = []
        for item in s.options["cavities"].split(","):
            match = _RANGE.match(item)
            if match:
                first, last = small_integer(match["first"]), small_integer(match["last"])
                if first is None or last is None or not 0 <= last - first < _MAX_CAVITIES:
                    raise self.error(
                        "bad cavity range",
                        s.line,
                        found=item,
                        expected=f"FIRST-LAST with FIRST <= LAST, at most {_MAX_CAVITIES}",
                    )
                names.extend(str(n) for n in range(first, last + 1))
            elif _CAVITY.match(item):
                names.append(item)
            else:
                raise self.error(
                    "malformed cavity list",
                    s.line,
                    found=item or "an empty name",
                    expected="names or ranges like 1-4, separated by commas",
                )
            if len(names) > _MAX_CAVITIES:
                raise self.error(
                    "too many cavities", s.line, found=len(names), expected=f"at most {_MAX_CAVITIES}"
                )
        twice = sorted(n for n, count in Counter(names).items() if count > 1)
        if twice:
            raise self.error("cavity listed twice", s.line, found=twice[0], expected="each cavity once")
        return tuple(names)

    # -- checks and records ---------------------------------------------------------------------------
