"""The package layout keeps its rules: no import cycle (counting imports inside functions and
under ``TYPE_CHECKING``), data flowing one way through the stages, no module over 500 lines,
no folder over 15 modules, each use case in its own folder importing no other use case and
no module outside them importing one, and only the ROS adapter importing rclpy."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import networkx as nx
import pytest

from tests.conftest import ROOT

PACKAGE = ROOT / "src" / "cadkg"
USE_CASES = ("iema", "elimco", "elvez", "vw", "enki")


@functools.cache
def _parsed(source: str) -> tuple[ast.AST, ...]:
    # Every rule walks every module: parse each source once for the whole module's tests.
    return tuple(ast.walk(ast.parse(source)))


def _nodes(path: Path) -> tuple[ast.AST, ...]:
    return _parsed(path.read_text(encoding="utf-8"))


def _modules() -> dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The modules of the package that ``name`` imports, wherever the import statement stands."""
    targets: set[str] = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in _nodes(path):
        if isinstance(node, ast.Import):
            targets.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([base] if base else [])])
            targets.add(base)
            targets.update(f"{base}.{alias.name}" for alias in node.names)
        elif (
            isinstance(node, ast.Call)
            and getattr(node.func, "id", getattr(node.func, "attr", None)) == "import_module"
            and node.args
            and isinstance(node.args[0], ast.Constant)
        ):
            targets.add(str(node.args[0].value))
    return {t for t in targets if t in known and t != name}


def _graph() -> nx.DiGraph:
    modules = _modules()
    graph = nx.DiGraph()
    for name, path in modules.items():
        graph.add_node(name)
        graph.add_edges_from((name, target) for target in _imports(name, path, set(modules)))
    return graph


def test_the_source_has_no_import_cycle() -> None:
    cycles = [sorted(c) for c in nx.strongly_connected_components(_graph()) if len(c) > 1]
    assert cycles == []


def test_the_cycle_check_finds_a_cycle() -> None:
    graph = _graph()
    graph.add_edge("cadkg.store", "cadkg.graph")  # the store importing the derivation's facade
    assert any(len(c) > 1 for c in nx.strongly_connected_components(graph))


def test_no_module_is_over_500_lines() -> None:
    long = {name: n for name, path in _modules().items() if (n := len(path.read_text().splitlines())) > 500}
    assert long == {}


def test_no_folder_holds_over_15_modules() -> None:
    folders = {path.parent for path in PACKAGE.rglob("*.py")}
    crowded = {str(f.relative_to(PACKAGE)): n for f in folders if (n := len(list(f.glob("*.py")))) > 15}
    assert crowded == {}


@pytest.mark.parametrize("case", USE_CASES)
def test_a_use_case_is_one_folder_that_imports_no_other(case: str) -> None:
    graph = _graph()
    prefix = f"cadkg.usecases.{case}"
    members = [m for m in graph if m == prefix or m.startswith(prefix + ".")]
    assert len(members) > 1
    others = {
        target
        for member in members
        for target in graph.successors(member)
        if target.startswith("cadkg.usecases.") and not target.startswith(prefix)
    }
    assert others == set()


def test_no_module_outside_the_use_cases_imports_one() -> None:
    # The core, transports included, finds use cases only as plug-ins, through the registry.
    graph = _graph()
    outside = [m for m in graph if not m.startswith("cadkg.usecases")]
    reaching = {m: sorted(t for t in graph.successors(m) if t.startswith("cadkg.usecases.")) for m in outside}
    assert {m: t for m, t in reaching.items() if t} == {}


# Files -> records -> triples -> store -> queries/services -> transports: a module imports only
# from its own stage or an earlier one. Each entry is a module or a package (its modules).
STAGES: list[tuple[str, tuple[str, ...]]] = [
    # What every stage may use: errors, terms, geometry, confined paths, the limited child, SPARQL text.
    (
        "base",
        (
            "cadkg.errors",
            "cadkg.ontology",
            "cadkg.geometry",
            "cadkg.confined",
            "cadkg.limited",
            # Who does a task: a pure function over data that the assignments' reader, the
            # graph's assign, the cursors, the planner and validation all take.
            "cadkg.plan.decision",
            "cadkg.sparql_text",
            "cadkg.outbound",
            "cadkg.loading",
        ),
    ),
    ("records", ("cadkg.ingest",)),
    ("triples", ("cadkg.mapping",)),
    (
        "store",
        (
            "cadkg.store",
            "cadkg.graph",
            "cadkg.building",
            "cadkg.generations",
            "cadkg.model_file",
            "cadkg.remote",
            "cadkg.push",
        ),
    ),
    # A use case adds to every stage up to its services; the package's public API re-exports
    # the store and validation.
    (
        "queries",
        (
            "cadkg.query",
            "cadkg.services",
            "cadkg.served",
            "cadkg.plan",
            "cadkg.changes",
            "cadkg.usecases",
            "cadkg",
        ),
    ),
    ("transports", ("cadkg.cli", "cadkg.server", "cadkg.ros_adapter")),
]
# The plug-in table names what each stage plugs in (readers, derivations, services) and every
# stage asks it: it stands outside the order.
ACROSS_STAGES = ("cadkg.registry", "cadkg.usecase")
# Known imports of a later stage, each with its reason.
LATER_STAGE_IMPORTS = {
    # KnowledgeGraph.named_query, .graph_view and .export(".graphml") are the public API's
    # shortcuts (the README's first example) to the query layer.
    ("cadkg.graph", "cadkg.query.named"),
    ("cadkg.graph", "cadkg.query.views"),
}


def _stage(module: str) -> int | None:
    for number, (_, members) in enumerate(STAGES):
        for member in members:
            # "cadkg" names the package's own module, not every module below it.
            if module == member or (member != "cadkg" and module.startswith(member + ".")):
                return number
    return None


def _later_stage_imports(graph: nx.DiGraph) -> set[tuple[str, str]]:
    found = set()
    for module, target in graph.edges:
        here, there = _stage(module), _stage(target)
        if here is not None and there is not None and there > here:
            found.add((module, target))
    return found - LATER_STAGE_IMPORTS


def test_every_module_has_its_stage() -> None:
    unplaced = sorted(m for m in _graph() if _stage(m) is None and m not in ACROSS_STAGES)
    assert unplaced == []


def test_no_module_imports_one_of_a_later_stage() -> None:
    graph = _graph()
    assert _later_stage_imports(graph) == set()
    # Each known exception still holds: one that no longer does leaves the list.
    assert set(graph.edges) >= LATER_STAGE_IMPORTS


def test_the_stage_check_finds_a_later_stage_import() -> None:
    graph = _graph()
    graph.add_edge("cadkg.ingest.manifest", "cadkg.store")  # a reader reaching for the store
    graph.add_edge("cadkg.query.views", "cadkg.server.app")  # a query reaching for a transport
    assert _later_stage_imports(graph) == {
        ("cadkg.ingest.manifest", "cadkg.store"),
        ("cadkg.query.views", "cadkg.server.app"),
    }


def test_only_the_ros_adapter_imports_rclpy() -> None:
    importers = {
        name
        for name, path in _modules().items()
        if any(
            isinstance(node, ast.Import | ast.ImportFrom)
            and any(
                (getattr(node, "module", None) or alias.name).split(".")[0] == "rclpy" for alias in node.names
            )
            for node in _nodes(path)
        )
    }
    assert importers and all(name.startswith("cadkg.ros_adapter") for name in importers)


def _imported_top_modules() -> set[str]:
    found: set[str] = set()
    for path in PACKAGE.rglob("*.py"):
        for node in _nodes(path):
            if isinstance(node, ast.Import):
                found.update(alias.name.partition(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.partition(".")[0])
    return found


def test_every_runtime_dependency_is_imported_by_the_package() -> None:
    import re
    import tomllib
    from importlib.metadata import packages_distributions

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    declared = {re.split(r"[<>=~!;\[ ]", dep, maxsplit=1)[0].lower() for dep in project["dependencies"]}
    # The distribution each imported top-level module comes from (python-calamine: python_calamine).
    # One scan of the installed distributions: it takes seconds, so not one for each module.
    providers = packages_distributions()
    imported = {dist.lower() for module in _imported_top_modules() for dist in providers.get(module, ())}
    assert declared - imported == set()
