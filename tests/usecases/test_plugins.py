"""Use cases as plug-ins: the five shipped ones through the registry, and a sixth added as a
separate package through the ``cadkg.usecases`` entry point, used from the CLI and from Python.

The toy package is written into a temporary folder with its own ``.dist-info`` (which is all an
installed distribution is to ``importlib.metadata``) and put on ``PYTHONPATH`` of a fresh
process, so the test goes through the same entry-point discovery a ``pip install`` would.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import cadkg.registry as registry
from cadkg.usecase import UseCase
from tests.conftest import ROOT

TOY = '''
"""A toy use case: widgets listed one per line in a .toy file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.reader import Reader
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.writer import TripleWriter, term
from cadkg.services.service import Effect, Service
from cadkg.usecase import UseCase


@dataclass(frozen=True)
class Widget:
    name: str
    line: int


def read_toy(path):
    widgets = []
    for number, line in enumerate(Path(path).read_text(encoding="utf-8").splitlines(), 1):
        word, _, name = line.partition(" ")
        if word != "widget" or not name:
            raise IngestError(path, "not a widget line", line=number, found=line, expected="widget NAME")
        widgets.append(Widget(name, number))
    return widgets


@map_record.register
def _(record: Widget, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("component", record.name)
    w.add(node, term("type"), term("Component"))
    w.add(node, term("label"), w.text(record.name))
    w.add(node, term("sourceLine"), w.typed(record.line))


def widget_count(session, client="default"):
    rows = session.kg.query("SELECT (COUNT(?c) AS ?n) WHERE { ?c a ck:Component }").rows
    return {"widgets": int(rows[0]["n"])}


USE_CASE = UseCase(
    name="toy",
    title="a toy cell of widgets",
    readers=(Reader("toy-widgets", (".toy",), read_toy, "Toy widgets: one 'widget NAME' per line"),),
    services=(Service(SERVICE_NAME, "how many widgets the cell has", {}, widget_count, effect=Effect.READS),),
    queries=Path(__file__).parent / "queries",
    ros_namespace="/toy",
)
'''

QUERY = """# toy-widgets: every widget, by name.
SELECT ?name WHERE { ?w a ck:Component ; ck:label ?name } ORDER BY ?name
"""

MANIFEST = """[cell]
name = "toy bench"
profile = "toy"
base_iri = "https://example.org/toy/"

[[source]]
path = "widgets.toy"
"""


def _toy_package(root: Path, service_name: str = "widget_count") -> dict[str, str]:
    """Write the toy package and its distribution metadata under ``root``; the environment of a
    process that sees it."""
    package = root / "site" / "toycell"
    (package / "queries").mkdir(parents=True)
    (package / "__init__.py").write_text(TOY.replace("SERVICE_NAME", repr(service_name)), encoding="utf-8")
    (package / "queries" / "toy-widgets.rq").write_text(QUERY, encoding="utf-8")
    info = root / "site" / "toycell-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toycell\nVersion: 0.1\n", encoding="utf-8")
    (info / "entry_points.txt").write_text("[cadkg.usecases]\ntoy = toycell:USE_CASE\n", encoding="utf-8")
    cell = root / "cell"
    cell.mkdir()
    (cell / "manifest.toml").write_text(MANIFEST, encoding="utf-8")
    (cell / "widgets.toy").write_text("widget gear\nwidget axle\nwidget bolt\n", encoding="utf-8")
    return {**os.environ, "PYTHONPATH": str(root / "site")}


def _cadkg(env: dict[str, str], *args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cadkg.cli", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=300,
        check=False,
    )


def test_the_shipped_use_cases_are_found_through_their_entry_points() -> None:
    cases = registry.use_cases()
    assert [c.name for c in cases] == ["iema", "elimco", "elvez", "vw", "enki"]
    assert all(isinstance(c, UseCase) and c.title and c.section for c in cases)
    # Each use case's readers, services and queries are the registry's, under its own name.
    services = registry.services()
    assert services["cad_service"].profile == "iema"
    assert services["guide_info"].profile == "elvez"
    assert services["hose_info"].profile == "enki"
    assert {r.kind for r in registry.use_case("elimco").readers} == {
        "elimco-cable-list",
        "pin-info",
        "cable-info",
        "path-info",
    }
    assert registry.use_case("").name == "iema"
    with pytest.raises(KeyError, match="unknown profile 'xyz'"):
        registry.use_case("xyz")


def test_a_use_case_finds_its_folders_in_the_package_it_names(tmp_path: Path) -> None:
    # ENKI keeps the kinds of a revision diff in changes/ and has no named queries.
    enki = registry.use_case("enki")
    assert enki.changes is not None and enki.changes.joinpath("hose.rq").is_file()
    assert enki.queries is None
    iema = registry.use_case("iema")
    assert iema.queries is not None and any(e.name.endswith(".rq") for e in iema.queries.iterdir())
    # A folder given stands as given.
    given = UseCase(name="toy-folders", title="given", package="cadkg.usecases.iema", queries=tmp_path)
    assert given.queries == tmp_path
    assert given.changes is not None and given.changes.joinpath("component.rq").is_file()


def test_a_use_case_from_another_package_works_from_the_cli(tmp_path: Path) -> None:
    env = _toy_package(tmp_path)
    kinds = _cadkg(env, "kinds")
    assert kinds.returncode == 0, kinds.stderr
    assert "toy-widgets" in kinds.stdout
    store = tmp_path / "store"
    built = _cadkg(env, "build", tmp_path / "cell" / "manifest.toml", "--store", store)
    assert built.returncode == 0, built.stderr
    assert "toy-widgets" in built.stdout
    listed = _cadkg(env, "services")
    assert "widget_count" in listed.stdout and "toy" in listed.stdout
    called = _cadkg(env, "call", store, "widget_count")
    assert called.returncode == 0, called.stderr
    assert json.loads(called.stdout) == {"widgets": 3}
    queried = _cadkg(env, "query", store, "toy-widgets", "--format", "csv")
    assert queried.returncode == 0, queried.stderr
    assert queried.stdout.split() == ["name", "axle", "bolt", "gear"]
    # The shipped use cases are still there beside it: ENKI's service runs, and finds no hose here.
    hose = _cadkg(env, "call", store, "hose_info", "product=HX-16")
    assert hose.returncode == 1, hose.stderr  # answered, and said it could not
    assert json.loads(hose.stdout)["success"] is False


def test_a_use_case_from_another_package_works_from_python(tmp_path: Path) -> None:
    env = _toy_package(tmp_path)
    script = textwrap.dedent(
        f"""
        import json
        import cadkg
        from cadkg.services.session import Session
        from cadkg.services.table import call

        kg = cadkg.build({str(tmp_path / "cell" / "manifest.toml")!r})
        names = [row["name"] for row in kg.named_query("toy-widgets")]
        answer = call(Session(kg.cell_model(), kg=kg), "widget_count", {{}})
        print(json.dumps({{"names": names, "answer": answer}}))
        """
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300, check=False
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == {"names": ["axle", "bolt", "gear"], "answer": {"widgets": 3}}


def test_a_use_case_that_takes_a_service_name_is_refused_in_one_line(tmp_path: Path) -> None:
    env = _toy_package(tmp_path, service_name="cad_service")
    result = _cadkg(env, "services")
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "cadkg: error: service 'cad_service' of toy is already one of iema's"
    ]


def test_a_use_case_that_does_not_load_is_named_in_one_line(tmp_path: Path) -> None:
    env = _toy_package(tmp_path)
    (tmp_path / "site" / "toycell" / "__init__.py").write_text("raise ImportError('no widgets here')\n")
    result = _cadkg(env, "kinds")
    assert result.returncode == 2
    assert result.stderr.strip() == (
        "cadkg: error: use case 'toy' (toycell:USE_CASE) cannot be loaded: no widgets here"
    )
