"""``cadkg serve`` stops when told to (SIGTERM, Ctrl-C) while pages hold event streams open.

An event stream never ends by itself and uvicorn waits for every response in flight, so with
one page open the server used to run on until killed. Now the streams end first, each client
seeing its stream close, and the server stops; a stream asked for while it stops ends at once.
"""

from __future__ import annotations

import signal
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from tests.cli import run
from tests.conftest import EXAMPLES
from tests.server.serving import cadkg_serve_process

# It stops in about 2 s on a quiet machine (the query workers end with it); never, before.
STOPPED_WITHIN = 20.0


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    store = tmp_path_factory.mktemp("closing") / "store"
    built = run("build", EXAMPLES / "elimco-bench" / "manifest.toml", "--store", store)
    assert built.returncode == 0, built.stderr
    return store


def _listen(base: str, heard: list[str], opened: threading.Event) -> None:
    """One page's stream: read until the server ends it; what it read goes into ``heard``."""
    with httpx.stream("GET", f"{base}/api/changes", timeout=httpx.Timeout(5, read=120)) as answer:
        assert answer.status_code == 200
        for chunk in answer.iter_text():
            heard.append(chunk)
            opened.set()
    heard.append("<end>")


@pytest.fixture
def listening() -> Iterator[list[tuple[threading.Thread, list[str], threading.Event]]]:
    streams: list[tuple[threading.Thread, list[str], threading.Event]] = []
    yield streams
    for thread, _, _ in streams:
        thread.join(5)


@pytest.mark.parametrize(
    ("sig", "pages"), [(signal.SIGTERM, 4), (signal.SIGINT, 1)], ids=["SIGTERM-4-pages", "SIGINT-1-page"]
)
def test_the_server_stops_with_pages_listening(
    store: Path, listening: list[tuple[threading.Thread, list[str], threading.Event]], sig: int, pages: int
) -> None:
    with cadkg_serve_process(str(store), "--watch", "0") as (base, process):
        for _ in range(pages):
            heard: list[str] = []
            opened = threading.Event()
            thread = threading.Thread(target=_listen, args=(base, heard, opened), daemon=True)
            thread.start()
            listening.append((thread, heard, opened))
        assert all(opened.wait(30) for _, _, opened in listening)
        process.send_signal(sig)
        try:
            process.wait(STOPPED_WITHIN)
        except subprocess.TimeoutExpired:
            pytest.fail(f"cadkg serve still ran {STOPPED_WITHIN} s after {signal.Signals(sig).name}")
        for thread, heard, _ in listening:
            thread.join(10)
            assert not thread.is_alive() and heard[-1] == "<end>", heard
            assert heard[0].startswith("retry: 3000")
        _, err = process.communicate()
        assert "Traceback" not in err, err
