"""Answers of the endpoint: content negotiation and the result formats.

SELECT results are read row by row (so the row cap and the deadline apply between
rows) and written here as SPARQL 1.1 Query Results JSON, XML, CSV and TSV; ASK results
in JSON and XML (CSV and TSV as the bare word); CONSTRUCT and DESCRIBE triples are
written by pyoxigraph as Turtle, N-Triples, JSON-LD or RDF/XML.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import escape, quoteattr

import pyoxigraph as ox

from cadkg.errors import CadkgError
from cadkg.server.limits import Deadline
from cadkg.store import PREFIXES

__all__ = [
    "GRAPH_FORMATS",
    "RESULT_FORMATS",
    "Format",
    "NotAcceptableError",
    "Table",
    "negotiate",
    "read_solutions",
    "read_triples",
    "write_boolean",
    "write_graph",
    "write_table",
]

_XSD_STRING = "http://www.w3.org/2001/XMLSchema#string"
_LANG_STRING = "http://www.w3.org/1999/02/22-rdf-syntax-ns#langString"
_CHECK_EVERY = 128


@dataclass(frozen=True)
class Format:
    """One answer format: its short name (the ``format`` parameter) and media types, first preferred."""

    name: str
    media_types: tuple[str, ...]
    suffix: str

    @property
    def content_type(self) -> str:
        media = self.media_types[0]
        return f"{media}; charset=utf-8" if media.startswith("text/") or "json" in media else media


RESULT_FORMATS = {
    f.name: f
    for f in (
        Format("json", ("application/sparql-results+json", "application/json"), "srj"),
        Format("xml", ("application/sparql-results+xml", "application/xml", "text/xml"), "srx"),
        Format("csv", ("text/csv",), "csv"),
        Format("tsv", ("text/tab-separated-values",), "tsv"),
    )
}
GRAPH_FORMATS = {
    f.name: f
    for f in (
        Format("ttl", ("text/turtle", "application/x-turtle"), "ttl"),
        Format("nt", ("application/n-triples", "text/plain"), "nt"),
        Format("jsonld", ("application/ld+json", "application/json"), "jsonld"),
        Format("rdfxml", ("application/rdf+xml", "application/xml", "text/xml"), "rdf"),
    )
}
_RDF_FORMATS = {
    "ttl": ox.RdfFormat.TURTLE,
    "nt": ox.RdfFormat.N_TRIPLES,
    "jsonld": ox.RdfFormat.JSON_LD,
    "rdfxml": ox.RdfFormat.RDF_XML,
}
_ALIASES = {"turtle": "ttl", "ntriples": "nt", "n-triples": "nt", "json-ld": "jsonld", "rdf": "rdfxml"}


class NotAcceptableError(CadkgError):
    """No format the client accepts can carry this kind of answer."""


def _accepted(accept: str) -> list[tuple[str, float]]:
    ranges = []
    for index, part in enumerate(accept.split(",")):
        media, *params = (p.strip() for p in part.split(";"))
        quality = 1.0
        for param in params:
            key, _, value = param.partition("=")
            if key.strip() == "q":
                try:
                    quality = float(value)
                except ValueError:
                    quality = 0.0
        if media:
            # Stable for equal quality: earlier ranges first.
            ranges.append((media.lower(), quality - index * 1e-6))
    return sorted(ranges, key=lambda r: -r[1])


def negotiate(accept: str | None, fmt: str | None, formats: dict[str, Format]) -> Format:
    """The format to answer in: ``fmt`` (a short name) if given, else the best match of ``accept``.

    Raises
    ------
    NotAcceptableError
        When ``fmt`` is unknown for this kind of answer or no accepted media type matches.
    """
    default = next(iter(formats.values()))
    if fmt:
        name = _ALIASES.get(fmt.lower(), fmt.lower())
        if name not in formats:
            raise NotAcceptableError(f"format={fmt!r} is not one of {', '.join(formats)} for this answer")
        return formats[name]
    if not accept:
        return default
    for media, quality in _accepted(accept):
        if quality <= 0:
            continue
        if media in ("*/*", "*"):
            return default
        # A format's own media type first, then the general ones it also answers to.
        for position in range(max(len(f.media_types) for f in formats.values())):
            for candidate in formats.values():
                types = candidate.media_types[position : position + 1]
                if media in types or (media.endswith("/*") and any(m.startswith(media[:-1]) for m in types)):
                    return candidate
    offered = ", ".join(f.media_types[0] for f in formats.values())
    raise NotAcceptableError(f"cannot answer in {accept!r}; this answer comes as one of {offered}")


@dataclass(frozen=True)
class Table:
    """SELECT solutions read up to the row cap; ``truncated`` when more were left unread."""

    variables: tuple[str, ...]
    rows: tuple[tuple[Any, ...], ...]
    truncated: bool


def read_solutions(solutions: Any, max_rows: int, deadline: Deadline | None = None) -> Table:
    """Read at most ``max_rows`` solutions, checking the deadline every few rows.

    Raises
    ------
    TimeLimitError
        When the deadline passes while reading.
    """
    variables = tuple(v.value for v in solutions.variables)
    try:
        rows, truncated = _read_rows(solutions, tuple, max_rows, deadline)
    finally:
        del solutions  # as in _read_rows
    return Table(variables, rows, truncated)


def read_triples(triples: Iterable[ox.Triple], max_rows: int, deadline: Deadline | None = None) -> Table:
    """Read at most ``max_rows`` triples (as a table of s, p, o rows).

    Raises
    ------
    TimeLimitError
        When the deadline passes while reading.
    """
    try:
        rows, truncated = _read_rows(
            triples, lambda t: (t.subject, t.predicate, t.object), max_rows, deadline
        )
    finally:
        del triples  # as in _read_rows
    return Table(("subject", "predicate", "object"), rows, truncated)


def _read_rows(
    items: Iterable[Any],
    row: Callable[[Any], tuple[Any, ...]],
    max_rows: int,
    deadline: Deadline | None,
) -> tuple[tuple[tuple[Any, ...], ...], bool]:
    """The rows of at most ``max_rows`` items, and whether there were more."""
    rows: list[tuple[Any, ...]] = []
    truncated = False
    item = None
    try:
        for item in items:
            if len(rows) == max_rows:
                truncated = True
                break
            rows.append(row(item))
            if deadline is not None and len(rows) % _CHECK_EVERY == 0:
                deadline.check()
    finally:
        # pyoxigraph's results must be dropped on this thread: a time-out's traceback keeps
        # this frame, and the event loop thread would drop them with it.
        del items, item
    return tuple(rows), truncated


# -- writers ----------------------------------------------------------------------------


def _json_term(term: Any) -> dict[str, Any]:
    if isinstance(term, ox.NamedNode):
        return {"type": "uri", "value": term.value}
    if isinstance(term, ox.BlankNode):
        return {"type": "bnode", "value": term.value}
    if isinstance(term, ox.Literal):
        data: dict[str, Any] = {"type": "literal", "value": term.value}
        if term.language:
            data["xml:lang"] = term.language
        elif term.datatype.value != _XSD_STRING:
            data["datatype"] = term.datatype.value
        return data
    if isinstance(term, ox.Triple):
        return {
            "type": "triple",
            "value": {
                "subject": _json_term(term.subject),
                "predicate": _json_term(term.predicate),
                "object": _json_term(term.object),
            },
        }
    raise TypeError(f"not an RDF term: {term!r}")


def _xml_term(term: Any) -> str:
    if isinstance(term, ox.NamedNode):
        return f"<uri>{escape(term.value)}</uri>"
    if isinstance(term, ox.BlankNode):
        return f"<bnode>{escape(term.value)}</bnode>"
    if isinstance(term, ox.Literal):
        if term.language:
            attr = f" xml:lang={quoteattr(term.language)}"
        elif term.datatype.value not in (_XSD_STRING, _LANG_STRING):
            attr = f" datatype={quoteattr(term.datatype.value)}"
        else:
            attr = ""
        return f"<literal{attr}>{escape(term.value)}</literal>"
    if isinstance(term, ox.Triple):
        return (
            f"<triple><subject>{_xml_term(term.subject)}</subject>"
            f"<predicate>{_xml_term(term.predicate)}</predicate>"
            f"<object>{_xml_term(term.object)}</object></triple>"
        )
    raise TypeError(f"not an RDF term: {term!r}")


def _csv_field(term: Any) -> str:
    if term is None:
        text = ""
    elif isinstance(term, ox.BlankNode):
        text = f"_:{term.value}"
    elif isinstance(term, ox.NamedNode | ox.Literal):
        text = term.value
    else:
        text = str(term)
    if any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


def write_table(table: Table, fmt: Format) -> bytes:
    """``table`` in a SPARQL 1.1 results format (``json``, ``xml``, ``csv`` or ``tsv``)."""
    if fmt.name == "json":
        bindings = [
            {
                name: _json_term(term)
                for name, term in zip(table.variables, row, strict=True)
                if term is not None
            }
            for row in table.rows
        ]
        document = {"head": {"vars": list(table.variables)}, "results": {"bindings": bindings}}
        return json.dumps(document, ensure_ascii=False, separators=(",", ":")).encode("utf-8")
    if fmt.name == "xml":
        parts = ['<?xml version="1.0"?>\n<sparql xmlns="http://www.w3.org/2005/sparql-results#"><head>']
        parts += [f"<variable name={quoteattr(v)}/>" for v in table.variables]
        parts.append("</head><results>")
        for row in table.rows:
            parts.append("<result>")
            parts += [
                f"<binding name={quoteattr(name)}>{_xml_term(term)}</binding>"
                for name, term in zip(table.variables, row, strict=True)
                if term is not None
            ]
            parts.append("</result>")
        parts.append("</results></sparql>\n")
        return "".join(parts).encode("utf-8")
    if fmt.name == "csv":
        lines = [",".join(_csv_field(v) for v in table.variables)]
        lines += [",".join(_csv_field(term) for term in row) for row in table.rows]
        return ("\r\n".join(lines) + "\r\n").encode("utf-8")
    if fmt.name == "tsv":
        # TSV writes terms in Turtle syntax; pyoxigraph's str() escapes tabs and line breaks.
        lines = ["\t".join(f"?{v}" for v in table.variables)]
        lines += ["\t".join("" if term is None else str(term) for term in row) for row in table.rows]
        return ("\n".join(lines) + "\n").encode("utf-8")
    raise ValueError(f"not a results format: {fmt.name}")


def write_boolean(value: bool, fmt: Format) -> bytes:
    """An ASK answer in a SPARQL 1.1 results format (CSV and TSV: the bare word)."""
    word = "true" if value else "false"
    if fmt.name == "json":
        return json.dumps({"head": {}, "boolean": value}).encode("utf-8")
    if fmt.name == "xml":
        return (
            '<?xml version="1.0"?>\n<sparql xmlns="http://www.w3.org/2005/sparql-results#">'
            f"<head/><boolean>{word}</boolean></sparql>\n"
        ).encode()
    return f"{word}\n".encode()


def write_graph(rows: Sequence[tuple[Any, ...]], fmt: Format) -> bytes:
    """Triples (as ``(s, p, o)`` rows) in an RDF format, written by pyoxigraph."""
    triples = [ox.Triple(s, p, o) for s, p, o in rows]
    data = ox.serialize(triples, format=_RDF_FORMATS[fmt.name], prefixes=PREFIXES)
    assert data is not None  # serialize() returns bytes when given no output
    return data
