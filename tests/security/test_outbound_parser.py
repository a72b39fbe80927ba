"""The recogniser of ``SERVICE`` and ``LOAD`` held against pyoxigraph's own parser on generated
variants: pyoxigraph evaluates each text with a loopback listener as the remote endpoint, and
every address it reaches is one the recogniser found; the recogniser finds exactly what the text
asks for, and nothing in strings and comments."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pyoxigraph as ox
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cadkg.errors import QueryError
from cadkg.outbound import check_outbound, outbound_requests
from tests.security.outbound_variants import Variant, load_update, service_query
from tests.server.listener import Listener

EXAMPLES = settings(
    max_examples=300, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow]
)


@pytest.fixture(scope="module")
def listener() -> Iterator[Listener]:
    with Listener() as listening:
        yield listening


def _base(listener: Listener) -> str:
    return listener.url.removesuffix("sparql")


def _reached(listener: Listener) -> set[str]:
    """The URLs of the requests the listener received."""
    urls = set()
    for request in listener.requests:
        path = request.split(b" ", 2)[1].decode()
        urls.add(_base(listener) + path.removeprefix("/"))
    return urls


def _found(variant: Variant) -> tuple[set[str], bool]:
    requests = outbound_requests(variant.text)
    return {r.target for r in requests if r.target is not None}, any(r.target is None for r in requests)


def _run(listener: Listener, variant: Variant, evaluate: Callable[[str], object]) -> set[str]:
    """What pyoxigraph reached evaluating the variant, after checking the recogniser found it."""
    listener.requests.clear()
    try:
        evaluate(variant.text)
    except SyntaxError:
        pytest.fail(f"pyoxigraph does not parse the generated text {variant.text!r}")
    except RuntimeError:
        pass  # failed as it ran: what it reached until then counts
    reached = _reached(listener)
    expected = {_base(listener) + path for path in variant.reaches}
    found, unknown = _found(variant)
    # Whatever pyoxigraph reached was found (a variable endpoint is refused whatever it names).
    assert reached <= found or unknown
    # The recogniser finds what the text asks for, no more (strings and comments are no requests).
    assert found == expected and unknown == variant.reaches_unknown
    if found or unknown:
        with pytest.raises(QueryError, match="is refused"):
            check_outbound(variant.text, ())
    else:
        check_outbound(variant.text, ())
    return reached


@EXAMPLES
@given(data=st.data())
def test_every_service_pyoxigraph_calls_is_found(listener: Listener, data: st.DataObject) -> None:
    variant = data.draw(service_query(_base(listener)))
    # A SERVICE ?endpoint left unbound fails as it runs.
    reached = _run(listener, variant, lambda text: list(ox.Store().query(text)))
    if not variant.reaches_unknown:  # the generator's claim, held to pyoxigraph's requests
        assert reached == {_base(listener) + path for path in variant.reaches}


@EXAMPLES
@given(data=st.data())
def test_every_load_pyoxigraph_fetches_is_found(listener: Listener, data: st.DataObject) -> None:
    variant = data.draw(load_update(_base(listener)))
    # The listener's answer is no RDF: a LOAD without SILENT fails and stops the update.
    reached = _run(listener, variant, ox.Store().update)
    if variant.reaches:  # the first LOAD is always fetched
        assert _base(listener) + variant.reaches[0] in reached


def test_the_forms_pyoxigraph_reads_glued() -> None:
    base = "http://127.0.0.1:9/"
    for text in (
        f"PREFIX ex: <{base}> SELECT * WHERE {{ SERVICEex:x {{ ?s ?p ?o }} }}",
        f"PREFIX : <{base}> SELECT * WHERE {{ SERVICE:x {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ SERVICESILENT<{base}x> {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ # a comment\r SERVICE <{base}x> {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ ?s ?p ?o.SERVICE<{base}x>{{ ?s ?p ?o }} }}",
        f"LOADSILENT<{base}x>",
        f"PREFIX ex: <{base}> LOADex:x",
        f"PREFIXex:<{base}> LOAD ex:x",
    ):
        assert [r.target for r in outbound_requests(text)] == [f"{base}x"], text
