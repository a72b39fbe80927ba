"""Start-up: ``import cadkg`` loads none of the heavy libraries, and every kind is still there.

Each check runs in a fresh interpreter, since this test session has imported everything.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from cadkg.errors import RegistryError
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.reader import Reader, lazy, resolve
from cadkg.registry import kinds

# What only some commands need: a mesh, a data frame, a graph view, a table on a terminal, a
# server, the container of a legacy XLS.
MINI = Path(__file__).parent / "data" / "cells" / "mini"
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


OTHER_CASES = ("elvez", "elimco", "vw", "enki")


def test_one_call_imports_only_its_own_use_case_and_command(tmp_path: Path) -> None:
    """``cadkg call`` on a cabinet's store imports the cabinet's services, and no other use
    case's services or answers, nor another command's module; ``cadkg services`` lists them all."""
    store = tmp_path / "store"
    KnowledgeGraph.build(MINI / "manifest.toml", store).close()
    found = _fresh(
        "import json, sys, contextlib, io\nfrom cadkg.cli import cli\n"
        "out = io.StringIO()\n"
        "with contextlib.redirect_stdout(out):\n"
        f"    cli.main(['call', {str(store)!r}, 'cad_service', 'label=K1'], standalone_mode=False)\n"
        "print(json.dumps({'answer': json.loads(out.getvalue()),\n"
        "    'modules': sorted(m for m in sys.modules if m.startswith(('cadkg.usecases.', 'cadkg.cli.'))),\n"
        "    'planner': 'cadkg.plan.order' in sys.modules, 'numpy': 'numpy' in sys.modules}))"
    )
    assert isinstance(found, dict)
    assert found["answer"]["success"] is True
    modules = found["modules"]
    assert "cadkg.usecases.iema.services" in modules and "cadkg.cli.service_commands" in modules
    # Another use case's package (its declaration) is imported, nothing of its modules.
    others = [m for m in modules if m.startswith(tuple(f"cadkg.usecases.{c}." for c in OTHER_CASES))]
    assert others == []
    commands = {f"cadkg.cli.{name}_commands" for name in ("graph", "change", "plan", "serve")}
    assert not commands & set(modules), sorted(commands & set(modules))
    # The cursors read the cell's progress reports; the planner (and numpy) only a re-plan needs.
    assert (found["planner"], found["numpy"]) == (False, False)


def test_every_use_case_service_is_listed_when_all_are_asked_for() -> None:
    from cadkg.registry import services, use_cases

    listed = services()
    assert {s.profile for s in listed.values()} == {c.name for c in use_cases() if c.services}
    assert {"cad_service", "guide_info", "pin_frames", "hose_info"} <= set(listed)


# In a fresh interpreter: the installed modules that the command line and the endpoint import
# whose .pyc is missing or not that of the source (its header: flags, source mtime and size).
_STALE = """
import json, os, sys, sysconfig
from importlib.util import cache_from_source
import cadkg.cli, cadkg.server.app, cadkg.server.workbench.routes, starlette.routing

def fresh(path):
    source = os.stat(path)
    try:
        with open(cache_from_source(path), "rb") as cached:
            header = cached.read(16)
    except OSError:
        return False
    mtime, size = (int.from_bytes(header[at : at + 4], "little") for at in (8, 12))
    return header[4:8] == bytes(4) and (mtime, size) == (
        int(source.st_mtime) & 0xFFFFFFFF, source.st_size & 0xFFFFFFFF
    )

installed = sysconfig.get_paths()["purelib"]
paths = [getattr(module, "__file__", None) or "" for module in list(sys.modules.values())]
print(json.dumps(sorted(p for p in paths if p.startswith(installed) and p.endswith(".py") and not fresh(p))))
"""


def test_the_modules_a_process_imports_were_compiled_by_the_set_up() -> None:
    # Where PYTHONDONTWRITEBYTECODE is set (containers, CI), a module without its .pyc is
    # compiled anew by every process; scripts/venv.sh compiles the venv's at set-up (and cadkg's,
    # which a developer's edits then leave stale: the installed ones are checked).
    assert _fresh(_STALE) == []
