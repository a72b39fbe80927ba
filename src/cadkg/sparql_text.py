"""SPARQL text: a query's form, and parameters bound as a ``VALUES`` block opening its WHERE group.

Values are never pasted into a query: each becomes a term that pyoxigraph writes
(quotes, backslashes and line breaks escaped). The block goes first in the outermost group
rather than being substituted at evaluation: pyoxigraph plans a query before it sees
substituted values, so it would join from any pattern, while a one-row ``VALUES`` is where
its planner starts. Local and remote stores bind the same way.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from datetime import date, datetime
from decimal import Decimal
from functools import lru_cache
from typing import Any

import pyoxigraph as ox

from cadkg.errors import QueryError

__all__ = [
    "bind_values",
    "query_form",
    "string_end",
    "syntax_error_message",
    "term_value",
    "to_term",
    "values_clause",
]

_XSD = "http://www.w3.org/2001/XMLSchema#"
# Comments, whitespace, PREFIX and BASE declarations before the query form keyword.
_PROLOGUE = re.compile(r"(?:\s+|#[^\n]*(?:\n|$)|PREFIX\s+[^\s:]*:\s*<[^>]*>|BASE\s*<[^>]*>)*", re.IGNORECASE)
_FORM = re.compile(r"(SELECT|ASK|CONSTRUCT|DESCRIBE)\b", re.IGNORECASE)
_IRIREF = re.compile(r'<[^<>"{}|^`\\\x00-\x20]*>')
_WORD = re.compile(r"[A-Za-z_][\w-]*")
# What oxigraph's SPARQL parser says: "error at LINE:COLUMN: expected one of A, B, ...".
_PARSER_ERROR = re.compile(r"error at (\d+):(\d+)(?::\s*(.*))?", re.DOTALL)
_MAX_EXPECTED = 12


def to_term(value: Any) -> ox.NamedNode | ox.Literal:
    """A Python value as an RDF term for binding: strings are literals, IRIs must be NamedNode."""
    if isinstance(value, ox.NamedNode | ox.Literal):
        return value
    if isinstance(value, bool):
        return ox.Literal(str(value).lower(), datatype=ox.NamedNode(_XSD + "boolean"))
    if isinstance(value, int):
        return ox.Literal(str(value), datatype=ox.NamedNode(_XSD + "integer"))
    if isinstance(value, Decimal):
        return ox.Literal(format(value, "f"), datatype=ox.NamedNode(_XSD + "decimal"))
    if isinstance(value, float):
        return ox.Literal(repr(value), datatype=ox.NamedNode(_XSD + "double"))
    if isinstance(value, str):
        return ox.Literal(value)
    raise QueryError(f"cannot bind a value of type {type(value).__name__}")


def _boolean(text: str) -> bool:
    return text in ("true", "1")


# Lexical form -> Python value per datatype; rows of big SELECTs go through here,
# so it is one dict lookup per literal.
_LITERAL_VALUE: dict[str, Any] = {
    _XSD + "integer": int,
    _XSD + "int": int,
    _XSD + "long": int,
    _XSD + "decimal": Decimal,
    _XSD + "double": float,
    _XSD + "float": float,
    _XSD + "boolean": _boolean,
    _XSD + "dateTime": datetime.fromisoformat,
    _XSD + "date": date.fromisoformat,
}


def term_value(term: Any) -> Any:
    """A pyoxigraph term as a Python value: IRIs as strings, typed literals converted."""
    kind = type(term)
    if kind is ox.Literal:
        convert = _LITERAL_VALUE.get(term.datatype.value)
        if convert is None:
            return term.value
        try:
            return convert(term.value)
        except (ValueError, ArithmeticError):
            return term.value
    if kind is ox.NamedNode:
        return term.value
    if term is None:
        return None
    if kind is ox.BlankNode:
        return f"_:{term.value}"
    return str(term)


def query_form(sparql: str) -> str:
    """The form of a query: ``SELECT``, ``ASK``, ``CONSTRUCT`` or ``DESCRIBE``.

    Raises
    ------
    QueryError
        When the text does not start (after its prologue) with one of them.
    """
    start = _PROLOGUE.match(sparql)
    match = _FORM.match(sparql, start.end() if start else 0)
    if match is None:
        raise QueryError("not a SPARQL query: expected SELECT, ASK, CONSTRUCT or DESCRIBE after the prefixes")
    return match.group(1).upper()


def values_clause(bindings: Mapping[str, Any]) -> str:
    """A ``VALUES`` block binding each name to its value as an escaped SPARQL term.

    Strings become literals, numbers typed literals, :class:`pyoxigraph.NamedNode` IRIs;
    pyoxigraph writes each term (quotes, backslashes and line breaks escaped), so no value
    can end the block or add to the query.

    >>> values_clause({"label": 'F1"} ; DROP ALL'})
    'VALUES (?label) { ("F1\\\\"} ; DROP ALL") }'

    Raises
    ------
    QueryError
        On a name that is not a SPARQL variable name or a value that cannot be bound.
    """
    if not bindings:
        return ""
    names = []
    for name in bindings:
        try:
            names.append(str(ox.Variable(name)))
        except ValueError:
            raise QueryError(f"{name!r} is not a SPARQL variable name") from None
    row = " ".join(str(to_term(value)) for value in bindings.values())
    return f"VALUES ({' '.join(names)}) {{ ({row}) }}"


@lru_cache(maxsize=256)
def _where_group(sparql: str, form: str) -> int | None:
    """Where the query's WHERE group opens (the index of its ``{``), or None when it has none.

    Cached: services and named queries run the same few texts over and over, and scanning
    one costs as much as answering it.

    A small scanner: comments, strings and IRIs are skipped, so a ``{`` inside them does
    not count; braces and parentheses are counted to find the outermost groups.
    """
    braces = parens = 0
    last_word = ""
    tops: list[tuple[int, str]] = []  # outermost groups: where they open, the word before
    i, n = 0, len(sparql)
    while i < n:
        c = sparql[i]
        if c == "#":
            end = sparql.find("\n", i)
            i = n if end < 0 else end + 1
            continue
        if c in "\"'":
            i = string_end(sparql, i)
            continue
        if c == "<":
            match = _IRIREF.match(sparql, i)
            if match:
                i = match.end()
                continue
        if c == "{":
            if braces == 0 and parens == 0:
                tops.append((i, last_word))
            braces += 1
        elif c == "}":
            braces -= 1
        elif c == "(":
            parens += 1
        elif c == ")":
            parens -= 1
        elif c in "?$":  # a variable, never a keyword
            match = _WORD.match(sparql, i + 1)
            i = match.end() if match else i + 1
            continue
        elif c.isalpha() and braces == 0:
            match = _WORD.match(sparql, i)
            assert match is not None
            last_word = match.group(0).upper()
            i = match.end()
            continue
        i += 1
    if not tops:
        return None
    if form == "CONSTRUCT" and tops[0][1] != "WHERE":
        # CONSTRUCT { template } WHERE? { pattern }: the second group.
        return tops[1][0] if len(tops) > 1 else None
    return tops[0][0]


def string_end(text: str, start: int) -> int:
    """The index just after the SPARQL string literal opening at ``start`` (any of its four quotes)."""
    quote = text[start]
    if text.startswith(quote * 3, start):
        end = start + 3
        while True:
            end = text.find(quote * 3, end)
            if end < 0:
                return len(text)
            if not _escaped(text, end):
                return end + 3
            end += 1
    end = start + 1
    while end < len(text) and text[end] != quote:
        end += 2 if text[end] == "\\" else 1
    return end + 1


def _escaped(text: str, index: int) -> bool:
    backslashes = 0
    while index - backslashes - 1 >= 0 and text[index - backslashes - 1] == "\\":
        backslashes += 1
    return backslashes % 2 == 1


def bind_values(sparql: str, bindings: Mapping[str, Any]) -> str:
    """``sparql`` with its parameters bound by a ``VALUES`` block opening its WHERE group.

    The block goes first in the outermost group, where the parameters join the pattern and the
    planner starts from them; a query without a group gets it after its end (the SPARQL grammar's
    trailing ``VALUES``, which some stores, Virtuoso among them, evaluate wrongly around
    sub-selects). No bindings: the text is returned unchanged.

    Raises
    ------
    QueryError
        As :func:`values_clause`, or when the text is not a query.
    """
    if not bindings:
        return sparql
    block = values_clause(bindings)
    where = _where_group(sparql, query_form(sparql))
    if where is None:
        return f"{sparql}\n{block}"
    # On the line of the brace, so a syntax error still names the line of the query as written.
    return f"{sparql[: where + 1]} {block} {sparql[where + 1 :]}"


def syntax_error_message(err: SyntaxError | str, text: str, prefixes: Iterable[str] = ()) -> str:
    """One line for a SPARQL parse error of ``text``: where, what is there, what would do.

    ``prefixes`` are those the store declares itself, named when an undeclared one is used.

    The parser lists every token it would accept, character classes included; the words and
    punctuation are kept, the classes (which only say "a name or a number") dropped.
    """
    message = str(err)
    match = _PARSER_ERROR.match(message)
    if match is None:
        return f"SPARQL syntax error: {message}"
    line, column = int(match.group(1)), int(match.group(2))
    expected = _expected(match.group(3) or "", sorted(prefixes))
    return f"SPARQL syntax error at line {line}, column {column} (found {_found_at(text, line, column)}" + (
        f", expected {expected})" if expected else ")"
    )


def _found_at(text: str, line: int, column: int) -> str:
    lines = text.split("\n")
    rest = "\n".join([lines[line - 1][column - 1 :], *lines[line:]]) if line <= len(lines) else ""
    words = rest.split()
    return repr(words[0][:40]) if words else "the end of the query"


def _expected(detail: str, prefixes: list[str]) -> str:
    detail = detail.strip()
    if not detail.startswith("expected one of "):
        return detail.removeprefix("expected ")
    items = [item.strip() for item in detail.removeprefix("expected one of ").split(", ")]
    if "Prefix not found" in items:
        declared = f" or one of {', '.join(prefixes)}" if prefixes else ""
        return f"a prefix declared with PREFIX name: <iri>{declared}"
    kept = [item for item in items if item and not item.startswith("[")]
    if len(kept) > _MAX_EXPECTED:
        kept = [*kept[:_MAX_EXPECTED], "…"]
    return "one of " + ", ".join(kept) if kept else ""
