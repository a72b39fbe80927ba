"""Start-up: ``import cadkg`` loads none of the heavy libraries, and every kind is still there.

Each check runs in a fresh interpreter, since this test session has imported everything.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from cadkg.errors import RegistryError
from cadkg.ingest.reader import Reader, lazy, resolve
from cadkg.registry import kinds

# What only some commands need: a mesh, a data frame, a graph view, a table on a terminal, a
# server, the container of a legacy XLS.
HEAVY = ("trimesh", "pandas", "networkx", "numpy", "rich", "starlette", "uvicorn", "httpx", "olefile")


def _fresh(code: str) -> object:
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    return json.loads(out.stdout)


def test_import_cadkg_loads_no_heavy_library() -> None:
    loaded = _fresh(
        "import json, sys\nimport cadkg\n"
        "assert cadkg.KnowledgeGraph and cadkg.build\n"
        f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    assert loaded == []


def test_listing_the_kinds_imports_no_reader() -> None:
    found = _fresh(
        "import json, sys\nfrom cadkg.registry import kinds\n"
        "names = [r.kind for r in kinds()]\n"
        "heavy = [m for m in ('trimesh', 'pandas', 'networkx') if m in sys.modules]\n"
        "print(json.dumps({'kinds': names, 'heavy': heavy}))"
    )
    assert isinstance(found, dict)
    assert found["kinds"] == [r.kind for r in kinds()]
    assert {"wri", "connection-list", "kbl", "vec", "x3d", "vrml", "component-model"} <= set(found["kinds"])
    assert found["heavy"] == []


@pytest.mark.parametrize("reader", kinds(), ids=lambda r: r.kind)
def test_every_named_function_of_a_reader_resolves(reader: Reader) -> None:
    assert callable(reader.read)
    assert reader.stream is None or callable(reader.stream)
    assert reader.sniffs() == (reader.sniff is not None)
    assert reader.sniff is None or callable(reader.sniff)


def test_a_named_function_is_the_function_itself() -> None:
    from cadkg.ingest.wri import looks_like_wri, read_wri

    reader = Reader(
        "lazy-wri", (".x",), "cadkg.ingest.wri:read_wri", "a test", "cadkg.ingest.wri:looks_like_wri"
    )
    assert reader.sniffs() and reader.stream is None
    assert reader.read is read_wri and reader.sniff is looks_like_wri
    assert lazy("cadkg.ingest.wri:looks_like_wri")(b"") is looks_like_wri(b"")


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("cadkg.ingest.wri", "is not a 'module:attribute' name"),
        ("cadkg.ingest.wri:no_such_reader", "module cadkg.ingest.wri has no 'no_such_reader'"),
    ],
)
def test_a_misnamed_function_says_which(spec: str, message: str) -> None:
    with pytest.raises(RegistryError, match=message):
        resolve(spec)
    reader = Reader("misnamed", (".x",), spec, "a test")
    with pytest.raises(RegistryError, match=message):
        reader.read("file.x")
