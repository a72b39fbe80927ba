"""A cell's graph in an external SPARQL 1.1 store, read over the SPARQL 1.1 Protocol.

:class:`RemoteGraph` answers every read method of :class:`~cadkg.graph.KnowledgeGraph`
(``query``, ``ask``, ``construct``, ``named_query``, ``sources``, ``cell_model`` ...) from a
remote endpoint, so the services, exports and validation run on it unchanged. What the
embedded store gives for free a remote store must provide, see ``docs/remote.md``:

- **The union of the named graphs as the default graph** (cadkg's queries do not say
  ``GRAPH`` unless they mean one). Virtuoso and GraphDB do this out of the box; Fuseki needs
  ``unionDefaultGraph``, the Oxigraph server ``--union-default-graph``. Where that is not
  possible, ``default-graph-uri`` and ``named-graph-uri`` parameters in the endpoint URL
  are sent with every query and fix the dataset instead.
- **cadkg's prefixes**: ``ck:``, ``rdf:``, ``rdfs:``, ``owl:``, ``xsd:`` (:data:`cadkg.store.PREFIXES`)
  are declared in front of every query that does not declare them itself.
- **Bindings** are never pasted into the text: each value becomes an escaped SPARQL term
  in a ``VALUES`` block that opens the query's WHERE group (:func:`bind_values`).

Virtuoso 7.2 writes doubles in its result formats with six digits; for SELECT answers
holding doubles the digits are taken from its Turtle result set (see
:meth:`RemoteGraph._precise_doubles`).

A remote graph is read-only: it is written with ``cadkg push`` (:mod:`cadkg.push`).
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from html import unescape
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn
from urllib.parse import parse_qsl, urlencode, urlsplit, urlunsplit

import pyoxigraph as ox

from cadkg.errors import QueryError, StoreError
from cadkg.graph import KnowledgeGraph
from cadkg.ontology.terms import CK_NS, ONTOLOGY_IRI
from cadkg.sparql_text import bind_values, query_form, values_clause
from cadkg.store import PREFIXES

if TYPE_CHECKING:  # the HTTP client is imported when a store is first reached over HTTP
    import httpx

__all__ = [
    "AUTH_DIGEST_ENV",
    "AUTH_ENV",
    "Auth",
    "HttpSparql",
    "RemoteGraph",
    "auth_from_env",
    "bind_values",
    "is_url",
    "parse_auth",
    "query_form",
    "values_clause",
    "with_prefixes",
]

AUTH_ENV = "CADKG_STORE_AUTH"
AUTH_DIGEST_ENV = "CADKG_STORE_AUTH_DIGEST"
DEFAULT_TIMEOUT = 120.0

_RESULTS_JSON = "application/sparql-results+json"
_FORM_TYPE = "application/x-www-form-urlencoded"
_XSD = "http://www.w3.org/2001/XMLSchema#"
_DOUBLE_TYPES = (_XSD + "double", _XSD + "float")
_TRUNCATED = tuple(t.encode("ascii") + b'"' for t in _DOUBLE_TYPES)
_RES = "http://www.w3.org/2005/sparql-results#"
_GRAPH_TYPES = "application/n-triples, text/turtle;q=0.9, application/rdf+xml;q=0.5"
_TAGS = re.compile(r"<[^>]+>")
_READ_ONLY = "a remote store is read-only for cadkg"


@dataclass(frozen=True)
class Auth:
    """HTTP credentials for a store: basic, or digest (Virtuoso's ``*-auth`` endpoints)."""

    user: str
    password: str
    digest: bool = False

    def httpx_auth(self) -> httpx.Auth:
        import httpx

        if self.digest:
            return httpx.DigestAuth(self.user, self.password)
        return httpx.BasicAuth(self.user, self.password)

    def __repr__(self) -> str:  # never print the password
        return f"Auth(user={self.user!r}, digest={self.digest})"


def parse_auth(value: str, *, digest: bool = False) -> Auth:
    """``user:password`` as :class:`Auth` (the password may contain colons).

    Raises
    ------
    StoreError
        When there is no colon or no user name.
    """
    user, sep, password = value.partition(":")
    if not sep or not user:
        raise StoreError("credentials are written user:password")
    return Auth(user, password, digest)


def auth_from_env(environ: Mapping[str, str] | None = None) -> Auth | None:
    """Credentials from ``CADKG_STORE_AUTH`` (basic) or ``CADKG_STORE_AUTH_DIGEST`` (digest), if set.

    Raises
    ------
    StoreError
        When the variable is not ``user:password``.
    """
    environ = os.environ if environ is None else environ
    if environ.get(AUTH_DIGEST_ENV):
        return parse_auth(environ[AUTH_DIGEST_ENV], digest=True)
    if environ.get(AUTH_ENV):
        return parse_auth(environ[AUTH_ENV])
    return None


def is_url(target: str | Path) -> bool:
    """Whether a STORE argument names a remote endpoint (``http://`` or ``https://``)."""
    return isinstance(target, str) and target.lower().startswith(("http://", "https://"))


def with_prefixes(sparql: str) -> str:
    """``sparql`` with cadkg's prefixes declared in front, except those it declares itself."""
    missing = [
        f"PREFIX {name}: <{iri}>"
        for name, iri in PREFIXES.items()
        if not re.search(rf"PREFIX\s+{name}:", sparql, re.IGNORECASE)
    ]
    return "\n".join([*missing, sparql]) if missing else sparql


def _excerpt(response: httpx.Response, limit: int = 400) -> str:
    text = response.text if response.content else ""
    if "html" in response.headers.get("content-type", "") or text.lstrip().startswith("<"):
        text = unescape(_TAGS.sub(" ", text))
    text = " ".join(text.split())
    # Virtuoso repeats the whole query after its message; the message is what helps.
    text = text.split(" SPARQL query: ", 1)[0]
    return text if len(text) <= limit else text[:limit] + " ..."


class HttpSparql:
    """One HTTP client for a store: timeouts, credentials, and errors as one clean line.

    Errors name the URL and the status with the start of the store's answer; a store's
    400 answer (a query it cannot parse) is a :class:`QueryError`, everything else a
    :class:`StoreError`.
    """

    def __init__(self, auth: Auth | None = None, timeout: float = DEFAULT_TIMEOUT) -> None:
        self.auth = auth
        self.timeout = timeout
        import httpx

        self._client = httpx.Client(
            auth=auth.httpx_auth() if auth else None,
            timeout=httpx.Timeout(timeout, connect=min(timeout, 10.0)),
            headers={"User-Agent": "cadkg"},
        )

    def send(self, method: str, url: str, *, allow: tuple[int, ...] = (), **kwargs: Any) -> httpx.Response:
        """Send one request and return the response: 2xx, or a status in ``allow``.

        Raises
        ------
        QueryError
            When the store answers 400 (it rejects the query or update).
        StoreError
            When the store cannot be reached, does not answer in time, refuses the
            credentials, or answers any other error status.
        """
        import httpx

        try:
            response = self._client.request(method, url, **kwargs)
        except httpx.TimeoutException:
            raise StoreError(f"{url}: no answer within {self.timeout:g} s") from None
        except httpx.HTTPError as err:
            raise StoreError(f"{url}: cannot reach the store: {err}") from None
        if response.is_success or response.status_code in allow:
            return response
        self.fail(url, response)

    def fail(self, url: str, response: httpx.Response) -> NoReturn:
        status = f"HTTP {response.status_code} {response.reason_phrase}".rstrip()
        body = _excerpt(response)
        detail = f"{url}: {status}" + (f": {body}" if body else "")
        if response.status_code in (401, 403):
            hint = (
                "; give credentials with --auth or --auth-digest"
                if self.auth is None
                else f"; the store refused the credentials of {self.auth.user!r}"
            )
            raise StoreError(f"{detail}{hint}")
        if response.status_code == 400:
            raise QueryError(detail)
        raise StoreError(detail)

    def close(self) -> None:
        self._client.close()


def _split_endpoint(url: str) -> tuple[str, list[tuple[str, str]]]:
    """The endpoint without its query string, and that string's parameters (dataset IRIs)."""
    parts = urlsplit(url)
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise StoreError(f"{url!r} is not an http(s) URL of a SPARQL endpoint")
    params = parse_qsl(parts.query, keep_blank_values=True)
    return urlunsplit((parts.scheme, parts.netloc, parts.path, "", "")), params


def _turtle_solutions(data: bytes) -> list[dict[str, str]]:
    """The rows of a Turtle result set (``res:solution`` / ``res:binding``), in document order,
    as lexical forms by variable name."""
    solutions: dict[ox.BlankNode | ox.NamedNode, dict[str, str]] = {}
    variable: dict[Any, str] = {}
    value: dict[Any, str] = {}
    owner: dict[Any, Any] = {}
    try:
        for triple in ox.parse(data, format=ox.RdfFormat.TURTLE):
            predicate = triple.predicate.value
            if predicate == _RES + "solution" and isinstance(triple.object, ox.BlankNode | ox.NamedNode):
                solutions.setdefault(triple.object, {})
            elif predicate == _RES + "binding":
                owner[triple.object] = triple.subject
            elif predicate == _RES + "variable":
                variable[triple.subject] = str(getattr(triple.object, "value", ""))
            elif predicate == _RES + "value" and isinstance(triple.object, ox.Literal):
                value[triple.subject] = triple.object.value
    except SyntaxError:
        return []
    for binding, solution in owner.items():
        if solution in solutions and binding in variable and binding in value:
            solutions[solution][variable[binding]] = value[binding]
    return list(solutions.values())


class RemoteGraph(KnowledgeGraph):
    """The cell's graph in a SPARQL 1.1 store, with the read methods of :class:`KnowledgeGraph`.

    Parameters
    ----------
    endpoint
        The store's SPARQL query endpoint, e.g. ``http://127.0.0.1:8890/sparql``. Parameters
        in its query string (``default-graph-uri``, ``named-graph-uri``) go with every query.
    auth
        Credentials, when the endpoint wants them.
    timeout
        Seconds to wait for one answer.

    Raises
    ------
    StoreError
        When ``endpoint`` is not an http(s) URL. Nothing is sent until the first query.
    """

    remote = True

    def __init__(self, endpoint: str, *, auth: Auth | None = None, timeout: float = DEFAULT_TIMEOUT) -> None:
        self.endpoint = endpoint
        self._url, self._dataset = _split_endpoint(endpoint)
        self._http = HttpSparql(auth, timeout)
        self.directory = None
        self.read_only = True
        self.reports = []
        self._model = None
        self._changing = False
        self._scratch = None
        self._files_dir = None
        self._unwritten = {}
        self._generation = None

    # The embedded store does not exist here: a method reaching for it would read nothing,
    # so it fails loudly instead.
    @property
    def _store(self) -> ox.Store:
        raise StoreError(f"{self.endpoint}: not available on a remote store")

    @_store.setter
    def _store(self, value: ox.Store) -> None:
        raise StoreError(f"{self.endpoint}: a remote store has no local database")

    def __repr__(self) -> str:
        return f"RemoteGraph({self.endpoint!r})"

    # -- reading -------------------------------------------------------------------
    def raw_query(self, sparql: str, bindings: Mapping[str, Any] | None = None) -> Any:
        """Run SPARQL on the store with bound parameters; returns pyoxigraph results.

        ``QuerySolutions`` for SELECT, ``QueryBoolean`` for ASK, ``QueryTriples`` for
        CONSTRUCT and DESCRIBE, as :meth:`KnowledgeGraph.raw_query` does.

        Raises
        ------
        QueryError
            When the text is not a query, a binding cannot be written, the store rejects
            the query, or its answer is cut by a row limit.
        StoreError
            When the store cannot be reached or answers with an error.
        """
        return self._run(with_prefixes(bind_values(sparql, bindings or {})), self._dataset)

    def execute(
        self,
        sparql: str,
        *,
        update: bool = False,
        default_graphs: Iterable[str] | None = None,
        named_graphs: Iterable[str] | None = None,
    ) -> Any:
        """A SPARQL 1.1 Protocol query passed on to the store, over an explicit dataset if given.

        Raises
        ------
        StoreError
            On an update (a remote store is written with ``cadkg push``), or as :meth:`raw_query`.
        QueryError
            As :meth:`raw_query`.
        """
        if update:
            raise StoreError(f"{self.endpoint}: {_READ_ONLY}; updates go to the store itself")
        dataset = self._dataset
        if default_graphs is not None or named_graphs is not None:
            dataset = [("default-graph-uri", g) for g in default_graphs or ()]
            dataset += [("named-graph-uri", g) for g in named_graphs or ()]
        return self._run(with_prefixes(sparql), dataset)

    def _run(self, text: str, dataset: list[tuple[str, str]]) -> Any:
        graph = query_form(text) in ("CONSTRUCT", "DESCRIBE")
        response = self._http.send(
            "POST",
            self._url,
            content=urlencode([("query", text), *dataset]),
            headers={"Accept": _GRAPH_TYPES if graph else _RESULTS_JSON, "Content-Type": _FORM_TYPE},
        )
        self._check_complete(response)
        media = response.headers.get("content-type", "").split(";")[0].strip()
        try:
            if graph:
                return self._triples(response.content, media)
            results_format = ox.QueryResultsFormat.from_media_type(media) or ox.QueryResultsFormat.JSON
            data = response.content
            if (
                results_format == ox.QueryResultsFormat.JSON
                and response.headers.get("server", "").startswith("Virtuoso")
                and any(dt in data for dt in _TRUNCATED)
            ):
                data = self._precise_doubles(text, dataset, data)
            return ox.parse_query_results(data, format=results_format)
        except (SyntaxError, ValueError) as err:
            kind = media or "no content type"
            raise StoreError(f"{self._url}: unreadable answer ({kind}): {err}") from None

    def _precise_doubles(self, text: str, dataset: list[tuple[str, str]], data: bytes) -> bytes:
        """SPARQL JSON results with Virtuoso's doubles at full precision.

        Virtuoso (7.2) writes xsd:double and xsd:float in its result formats with six
        significant digits (0.7071067823197227 as 0.707107), but in its Turtle result set with
        all of them, though untyped there. The query is asked again for Turtle and each
        double of the JSON answer takes its digits from the same row of that; a row that
        does not match (another order, another value) leaves the JSON answer as it was.
        """
        response = self._http.send(
            "POST",
            self._url,
            content=urlencode([("query", text), *dataset]),
            headers={"Accept": "text/turtle", "Content-Type": _FORM_TYPE},
        )
        answer = json.loads(data)
        bindings = answer.get("results", {}).get("bindings", [])
        precise = _turtle_solutions(response.content)
        if len(precise) != len(bindings):
            return data
        for row, exact in zip(bindings, precise, strict=True):
            for name, cell in row.items():
                if cell.get("datatype") not in _DOUBLE_TYPES:
                    continue
                digits = exact.get(name)
                try:
                    close = digits is not None and math.isclose(
                        float(digits), float(cell["value"]), rel_tol=1e-5, abs_tol=1e-300
                    )
                except ValueError:
                    close = False
                if digits is None or not close:
                    return data
                cell["value"] = repr(float(digits))  # shortest text of the same double
        return json.dumps(answer).encode("utf-8")

    def _check_complete(self, response: httpx.Response) -> None:
        # Virtuoso cuts results at ResultSetMaxRows and says so only in this header.
        limit = response.headers.get("x-sparql-maxrows")
        if limit:
            raise QueryError(
                f"{self._url}: the store cut the answer at {limit} rows (Virtuoso: raise "
                "ResultSetMaxRows in the [SPARQL] section of virtuoso.ini)"
            )

    @staticmethod
    def _triples(data: bytes, media: str) -> ox.QueryTriples:
        # A real QueryTriples, as the embedded store returns: load the answer and read it back.
        rdf_format = ox.RdfFormat.from_media_type(media) if media else None
        store = ox.Store()
        store.load(data, format=rdf_format or ox.RdfFormat.TURTLE)
        result = store.query("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o }")
        assert isinstance(result, ox.QueryTriples)
        return result

    def named_graphs(self) -> list[str]:
        """The cell's named graphs in the store: the ontology and every graph typing something in ``ck:``.

        Other graphs of the store (Virtuoso's own, other data sets) are left out.
        """
        rows = self.query(
            f"""SELECT DISTINCT ?g WHERE {{ GRAPH ?g {{ ?s a ?type }}
                  FILTER(?g = <{ONTOLOGY_IRI}> || STRSTARTS(STR(?type), "{CK_NS}")) }}"""
        )
        return sorted(str(row["g"]) for row in rows if isinstance(row["g"], str))

    def __len__(self) -> int:
        graphs = self.named_graphs()
        if not graphs:
            return 0
        listed = " ".join(f"<{g}>" for g in graphs)
        rows = self.query(
            f"SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH ?g {{ ?s ?p ?o }} VALUES ?g {{ {listed} }} }}"
        ).rows
        return int(rows[0]["n"]) if rows else 0

    def quads(self, graphs: Iterable[str] | None = None) -> Iterator[ox.Quad]:
        """Every quad of the cell's named graphs (or of ``graphs``), read one graph at a time."""
        for graph in self.named_graphs() if graphs is None else graphs:
            node = ox.NamedNode(graph)
            for triple in self.raw_query(
                f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ GRAPH <{graph}> {{ ?s ?p ?o }} }}"
            ):
                yield ox.Quad(triple.subject, triple.predicate, triple.object, node)

    def serialize(
        self, fmt: str = "ttl", *, include_ontology: bool = False, graphs: Iterable[str] | None = None
    ) -> bytes:
        """The cell's graphs fetched from the store and written as :meth:`KnowledgeGraph.serialize` does."""
        copy = ox.Store()
        copy.extend(self.quads(graphs))
        return KnowledgeGraph(copy).serialize(fmt, include_ontology=include_ontology)

    # -- writing is done with cadkg push -------------------------------------------
    def derive(self) -> Any:
        """The derived geometry, computed here from the store (the store's derived graph is not rewritten)."""
        self._model = None
        return self.cell_model()

    def assign(self, kind: str, ident: str, performer: str, also: Any = None) -> str:
        raise StoreError(f"{self.endpoint}: {_READ_ONLY}; assign in the local store and push it again")

    def replace_source(self, *args: Any, **kwargs: Any) -> Any:
        raise StoreError(f"{self.endpoint}: {_READ_ONLY}; rebuild the local store and push it again")

    def close(self) -> None:
        self._http.close()
        if self._scratch is not None:
            self._scratch.cleanup()
            self._scratch = None

    def __enter__(self) -> RemoteGraph:
        return self
