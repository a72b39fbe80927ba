"""The node's ``sparql`` service evaluates in a confined query worker: a ``SERVICE`` reaches no
address (a loopback listener counts connections), a query past its memory limit fails in one
message and the next one is answered."""

from __future__ import annotations

import json
from typing import Any

from cadkg_interfaces import srv

from tests.server.listener import Listener

ROW_COUNT = "SELECT (COUNT(*) AS ?n) WHERE { ?w a ck:Wire }"


def _doubling(levels: int) -> str:
    """A query whose one string doubles ``levels`` times: 32 bytes << levels."""
    binds = " ".join(f"BIND(CONCAT(?x{i}, ?x{i}) AS ?x{i + 1})" for i in range(levels))
    return f'SELECT (STRLEN(?x{levels}) AS ?n) WHERE {{ BIND("{"0123456789abcdef" * 2}" AS ?x0) {binds} }}'


def test_a_service_reaches_nothing(call: Any) -> None:
    with Listener() as listener:
        base = listener.url.removesuffix("sparql")
        for text in (
            f"PREFIX ex: <{base}> SELECT * WHERE {{ SERVICEex:x {{ ?s ?p ?o }} }}",
            f"PREFIX : <{base}> SELECT * WHERE {{ SERVICE:x {{ ?s ?p ?o }} }}",
            f"SELECT * WHERE {{ SERVICESILENT<{listener.url}> {{ ?s ?p ?o }} }}",
            f"SELECT * WHERE {{ # a comment\r SERVICE <{listener.url}> {{ ?s ?p ?o }} }}",
        ):
            answer = call(srv.Sparql, "sparql", query=text, format="json")
            assert not answer.success and "is refused" in answer.message, answer.message
        assert listener.connections == 0


def test_a_query_past_its_memory_is_stopped_and_the_next_answered(call: Any) -> None:
    answer = call(srv.Sparql, "sparql", query=_doubling(26), format="json", timeout=180.0)
    assert not answer.success
    assert "MiB of memory a query may take and was stopped" in answer.message, answer.message
    after = call(srv.Sparql, "sparql", query=ROW_COUNT, format="json", timeout=120.0)
    assert after.success, after.message
    assert int(json.loads(after.result)["results"]["bindings"][0]["n"]["value"]) > 0
