"""What a SPARQL text would make the engine fetch, and the policy that refuses it.

pyoxigraph evaluates ``SERVICE <url> { ... }`` by sending the pattern to ``url``, and an update's
``LOAD <url>`` by downloading it: a query typed into a served page would make the server reach
any address (server-side request forgery). cadkg makes no outbound request unless the endpoint
is named in an allow-list (``--allow-service URL``, :attr:`cadkg.store.GraphStore.allowed_services`).

The check reads the text as SPARQL's lexer does, not as a substring: comments, strings, IRIs,
variables, prefixed names and language tags are whole tokens, so ``# SERVICE``, ``"SERVICE"``,
``?service`` or ``ex:service`` are not the keyword, while ``service``, ``Service`` and
``SERVICE SILENT ?e`` are. pyoxigraph exposes no query algebra, and rdflib's parser, which
does, refuses queries pyoxigraph runs (RDF-star) and costs milliseconds a query; the tests hold
this lexer against rdflib's algebra wherever rdflib parses. SPARQL keywords cannot be escaped
(pyoxigraph refuses ``\\u0053ERVICE``), so a text without the letters ``service`` or ``load``
in any case is passed at once; IRIs are compared after their ``\\u`` escapes, prefixes and
``BASE`` are applied, as pyoxigraph would resolve them.
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
# A name: keyword, prefixed name, blank node label, number; anything SPARQL's punctuation ends.
_NAME = re.compile(r"""[^\s{}()\[\];,<>"'#?$@!=*/+|^&]+""")
_VARIABLE = re.compile(r"[?$][\w\u00b7\u0300-\u036f\u203f-\u2040]*")
_LANGUAGE = re.compile(r"@[A-Za-z0-9-]*")
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
    comments, strings and language tags are skipped."""
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c.isspace():
            i += 1
        elif c == "#":
            end = text.find("\n", i)
            i = n if end < 0 else end + 1
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
        elif c == "@":
            match = _LANGUAGE.match(text, i)
            assert match is not None
            i = max(match.end(), i + 1)
        elif name := _NAME.match(text, i):
            yield "name", name.group(0)
            i = name.end()
        else:
            yield "punct", c
            i += 1


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
    tokens = list(_tokens(text))
    known = dict(prefixes or {})
    base: str | None = None
    found: list[Outbound] = []
    for index, (kind, value) in enumerate(tokens):
        if kind != "name":
            continue
        word = value.upper()
        following = tokens[index + 1 : index + 4]
        if word == "PREFIX" and len(following) >= 2 and following[1][0] == "iri":
            known[following[0][1].removesuffix(":")] = following[1][1]
        elif word == "BASE" and following and following[0][0] == "iri":
            base = _resolve("iri", following[0][1], known, base)
        elif word in _KEYWORDS:
            if following and following[0][0] == "name" and following[0][1].upper() == "SILENT":
                following = following[1:]
            target_kind, written = following[0] if following else ("punct", "")
            shown = f"<{written}>" if target_kind == "iri" else written or "(nothing)"
            found.append(Outbound(word, _resolve(target_kind, written, known, base), shown))
    return found


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
