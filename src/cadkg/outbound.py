"""What a SPARQL text would make the engine fetch, and the policy that refuses it.

pyoxigraph evaluates ``SERVICE <url> { ... }`` by sending the pattern to ``url``, and an update's
``LOAD <url>`` by downloading it: a query typed into a served page would make the server reach
any address (server-side request forgery). cadkg makes no outbound request unless the endpoint
is named in an allow-list (``--allow-service URL``, :attr:`cadkg.store.GraphStore.allowed_services`).

The check reads the text as pyoxigraph's parser does, not as a substring: comments (ended by a
line feed or a carriage return), strings, IRIs, variables, prefixed names and language tags are
whole tokens, so ``# SERVICE``, ``"SERVICE"``, ``?service`` or ``ex:service`` are not the
keyword, while ``service``, ``Service``, ``SERVICE SILENT ?e`` are, and so are the forms
pyoxigraph reads with nothing after the keyword (``SERVICEex:x``, ``SERVICE:x``,
``SERVICESILENT<iri>``, ``LOADex:x``). pyoxigraph exposes no query algebra; the tests hold this
recogniser against pyoxigraph itself on generated variants (``tests/security``), and against
rdflib's algebra wherever rdflib parses. SPARQL keywords cannot be escaped (pyoxigraph refuses
``\\u0053ERVICE``), so a text without the letters ``service`` or ``load`` in any case is passed
at once; IRIs are compared after their ``\\u`` escapes, prefixes and ``BASE`` are applied, as
pyoxigraph would resolve them.

This is the first, friendly refusal. What makes the promise hold is that queries from outside
are evaluated where there is no network (:mod:`cadkg.limited`).
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass
from urllib.parse import urljoin, urlsplit

from cadkg.errors import QueryError
from cadkg.sparql_text import string_end

__all__ = ["Outbound", "check_outbound", "outbound_requests"]

_CANDIDATE = re.compile(r"service|load", re.IGNORECASE)
_IRI = re.compile(r'<((?:[^<>"{}|^`\\\x00-\x20]|\\u[0-9A-Fa-f]{4}|\\U[0-9A-Fa-f]{8})*)>')
_ESCAPE = re.compile(r"\\u([0-9A-Fa-f]{4})|\\U([0-9A-Fa-f]{8})")
# A name: keyword, prefixed name or blank node label, up to SPARQL's punctuation. It starts with
# a letter, ``_`` or ``:`` (a digit starts a number, a dot ends a triple).
_NAME = re.compile(r"""(?:[^\W\d]|:)[^\s{}()\[\];,<>"'#?$@!=*/+|^&]*""")
_NUMBER = re.compile(r"[0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?")
_VARIABLE = re.compile(r"[?$][\w\u00b7\u0300-\u036f\u203f-\u2040]*")
_LANGUAGE = re.compile(r"@[A-Za-z]+(?:-[A-Za-z0-9]+)*")
_LINE_END = re.compile(r"[\r\n]")
# Keywords pyoxigraph reads with nothing between them and what follows (``SERVICEex:x``,
# ``LOADSILENT<iri>``, ``PREFIX:<iri>``): a name may start with one.
_GLUED = ("SERVICE", "LOAD", "PREFIX")
_KEYWORDS = {"SERVICE", "LOAD"}


@dataclass(frozen=True)
class Outbound:
    """One request a text asks for: ``SERVICE`` or ``LOAD``, and the IRI it would reach
    (``None`` when it is a variable or cannot be resolved before the query runs)."""

    keyword: str
    target: str | None
    written: str

    def __str__(self) -> str:
        return f"{self.keyword} {self.written}"


def _tokens(text: str) -> Iterator[tuple[str, str]]:
    """(kind, value) of SPARQL's tokens: ``iri`` (unescaped), ``name``, ``var``, ``punct``;
    comments (to a line feed or a carriage return, as pyoxigraph ends them), strings, numbers
    and language tags are skipped."""
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c.isspace():
            i += 1
        elif c == "#":
            end = _LINE_END.search(text, i)
            i = n if end is None else end.end()
        elif c in "\"'":
            i = string_end(text, i)
        elif c == "<" and (iri := _IRI.match(text, i)):
            yield "iri", _ESCAPE.sub(lambda m: chr(int(m.group(1) or m.group(2), 16)), iri.group(1))
            i = iri.end()
        elif c in "?$":
            match = _VARIABLE.match(text, i)
            assert match is not None
            yield "var", match.group(0)
            i = max(match.end(), i + 1)
        elif c == "@" and (language := _LANGUAGE.match(text, i)):
            i = language.end()
        elif number := _NUMBER.match(text, i):
            i = number.end()
        elif name := _NAME.match(text, i):
            # A dot ending a name ends its triple: ``ex:a.SERVICE`` is one name, ``ex:a. SERVICE`` not.
            value = name.group(0).rstrip(".")
            yield "name", value
            i += len(value)
        else:
            yield "punct", c
            i += 1


def _starts_with(value: str, keyword: str) -> bool:
    """Whether ``value`` starts with ``keyword`` as SPARQL compares keywords (ASCII letters, any case)."""
    head = value[: len(keyword)]
    return head.isascii() and head.upper() == keyword


def _keyword(value: str, known: Mapping[str, str], following: str, start: bool) -> tuple[str, str]:
    """A name as pyoxigraph may read it: (the keyword it is or starts with, what follows it),
    or ``("", value)``.

    A name that only starts with a keyword is a prefixed name when its prefix is declared, unless
    it stands where only the keyword could: before a ``{`` (a subject is followed by its predicate),
    or, for ``LOAD`` and ``PREFIX``, where an operation starts; else the keyword is glued to the rest.
    """
    for keyword in _GLUED:
        if not _starts_with(value, keyword):
            continue
        if len(value) == len(keyword):
            return keyword, ""
        declared = ":" in value and value.partition(":")[0] in known
        if keyword == "PREFIX" and not start:
            continue
        if declared and not (following == "{" if keyword == "SERVICE" else start):
            continue
        return keyword, value[len(keyword) :]
    return "", value


def _resolve(kind: str, value: str, prefixes: Mapping[str, str], base: str | None) -> str | None:
    if kind == "iri":
        iri = urljoin(base, value) if base and not urlsplit(value).scheme else value
    elif kind == "name" and ":" in value:
        prefix, _, local = value.rstrip(".").partition(":")
        if prefix not in prefixes:
            return None
        iri = prefixes[prefix] + re.sub(r"\\(.)", r"\1", local)
    else:
        return None
    return iri if urlsplit(iri).scheme else None


def outbound_requests(text: str, prefixes: Mapping[str, str] | None = None) -> list[Outbound]:
    """Every ``SERVICE`` and ``LOAD`` of a query or update, with the IRI each would reach.

    ``prefixes`` are those declared outside the text (the store's); the text's own
    ``PREFIX`` and ``BASE`` declarations are applied too.

    >>> [str(o) for o in outbound_requests('SELECT * { # SERVICE <x>\\n service silent ?e { } }')]
    ['SERVICE ?e']
    """
    if _CANDIDATE.search(text) is None:
        return []
    stack = list(reversed(list(_tokens(text))))
    known = dict(prefixes or {})
    base: str | None = None
    found: list[Outbound] = []
    depth, start = 0, True  # ``start``: where a query or an update's operation may begin
    while stack:
        kind, value = stack.pop()
        if kind == "punct":
            depth += {"{": 1, "}": -1}.get(value, 0)
            start = value == ";" and depth == 0
            continue
        word = ""
        if kind == "name":
            word, rest = _keyword(value, known, stack[-1][1] if stack else "", start)
            if word and rest:
                stack.append(("name", rest))
            elif not word and value.isascii() and value.upper() == "BASE":
                word = "BASE"
        if word == "PREFIX" and len(stack) >= 2 and stack[-1][1].endswith(":") and stack[-2][0] == "iri":
            (_, name), (_, iri) = stack.pop(), stack.pop()
            known[name.removesuffix(":")] = iri
            continue
        if word == "BASE" and stack and stack[-1][0] == "iri":
            base = _resolve("iri", stack.pop()[1], known, base)
            continue
        start = False
        if word in _KEYWORDS:
            target_kind, written = _target(stack, known, base)
            shown = f"<{written}>" if target_kind == "iri" else written or "(nothing)"
            found.append(Outbound(word, _resolve(target_kind, written, known, base), shown))
    return found


def _target(stack: list[tuple[str, str]], known: Mapping[str, str], base: str | None) -> tuple[str, str]:
    """The target of a ``SERVICE`` or ``LOAD`` taken from ``stack``, after an optional ``SILENT``
    (glued to the target when the rest resolves, as pyoxigraph reads it)."""
    if not stack:
        return "punct", ""
    kind, value = stack.pop()
    if kind == "name" and _starts_with(value, "SILENT"):
        rest = value[len("SILENT") :]
        if not rest:
            return stack.pop() if stack else ("punct", "")
        if _resolve("name", rest, known, base) is not None:
            return "name", rest
    return kind, value


def check_outbound(text: str, allowed: Collection[str], prefixes: Mapping[str, str] | None = None) -> None:
    """Refuse a text that would reach anything but an ``allowed`` endpoint.

    Raises
    ------
    QueryError
        On a ``SERVICE`` or ``LOAD`` whose IRI is not in ``allowed`` (every one when it is
        empty), or cannot be known before the query runs (a variable).
    """
    for request in outbound_requests(text, prefixes):
        if not allowed:
            raise QueryError(
                f"{request} is refused: cadkg makes no outbound requests "
                "(a federated query needs its endpoint allowed: --allow-service URL)"
            )
        if request.target is None:
            raise QueryError(
                f"{request} is refused: only an endpoint written as an IRI can be checked against "
                "the allowed ones (--allow-service)"
            )
        if request.target not in allowed:
            raise QueryError(
                f"{request.keyword} <{request.target}> is refused: not one of the allowed endpoints "
                "(--allow-service)"
            )
