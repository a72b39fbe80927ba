"""The ELVEZ model: what the Table 2 services answer from, read from the graph once.

:func:`build_model` reads the graph (SPARQL, plus a networkx view of the harness and plan
relations) into an :class:`ElvezModel`; the services in :mod:`cadkg.usecases.elvez.answers` are plain
functions of it.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
from urllib.parse import unquote

import networkx as nx

from cadkg.geometry.poses import Pose
from cadkg.query.views import graph_view
from cadkg.usecases.elvez.platform import PlatformModel, platform_model

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = ["BranchInfo", "ElvezModel", "OperationInfo", "build_model"]

_POSE = "?pose ck:tx ?tx ; ck:ty ?ty ; ck:tz ?tz ; ck:qx ?qx ; ck:qy ?qy ; ck:qz ?qz ; ck:qw ?qw ."
_OPERATION_TYPES = {"InsertOperation": "insert", "RouteOperation": "route", "TapeOperation": "tape"}
_TRAVERSED = (
    "hasBranch",
    "containsCable",
    "fromPin",
    "toPin",
    "pinOf",
    "involves",
    "atSpot",
    "mainConnector",
)


@dataclass(frozen=True)
class BranchInfo:
    """A branch of a harness: its connector and its cables (wh_info)."""

    connector: str
    cables: tuple[str, ...]


@dataclass(frozen=True)
class OperationInfo:
    """One operation of the plan: its type, spots and components in plan order, and its tool."""

    index: int
    type: str
    spot: tuple[str, ...]
    label: tuple[str, ...]
    tool: str


@dataclass(frozen=True)
class _Cable:
    name: str
    iri: str
    color: tuple[int, ...]
    length: float | None
    diameter: float | None


@dataclass(frozen=True)
class _Connector:
    name: str
    iri: str
    color: tuple[int, ...]
    dimensions: tuple[float, ...]
    kind: str


@dataclass(frozen=True)
class _End:
    connector: str
    pin: int


@dataclass(frozen=True)
class _Harness:
    number: int
    iri: str
    main_connector: str
    branches: tuple[BranchInfo, ...]


@dataclass(frozen=True)
class _Tool:
    name: str
    kind: str
    atc_slot: str
    dimensions: tuple[float, ...]
    base_wrist: Pose | None
    wrist_action: Pose | None


@dataclass
class ElvezModel:
    """What the ELVEZ services answer from, read from the graph by :func:`build_model`."""

    platforms: PlatformModel
    cables: dict[str, _Cable]
    connectors: dict[str, _Connector]
    ends: dict[str, tuple[_End | None, _End | None]]
    harnesses: dict[int, _Harness]
    harness_of: dict[str, int]
    tools: dict[str, _Tool]
    operations: list[OperationInfo]
    operation_index: dict[str, int]
    view: nx.MultiDiGraph


def _rgb(text: str | None) -> tuple[int, ...]:
    return tuple(int(v) for v in text.split()) if text else ()


def _pose(row: dict[str, Any]) -> Pose:
    return Pose(
        (float(row["tx"]), float(row["ty"]), float(row["tz"])),
        (float(row["qx"]), float(row["qy"]), float(row["qz"]), float(row["qw"])),
    )


def _dims(row: dict[str, Any]) -> tuple[float, ...]:
    return (float(row["x"]), float(row["y"]), float(row["z"])) if row["x"] is not None else ()


def build_model(kg: KnowledgeGraph) -> ElvezModel:
    """Read the platforms, harnesses, tools and plan of the graph into an :class:`ElvezModel`.

    Raises
    ------
    QueryError
        When the platform frames cannot be merged (see :func:`cadkg.usecases.elvez.platform.platform_model`).
    """
    cables = {
        row["name"]: _Cable(
            row["name"],
            row["c"],
            _rgb(row["rgb"]),
            float(row["len"]) if row["len"] is not None else None,
            float(row["dia"]) if row["dia"] is not None else None,
        )
        for row in kg.query(
            """SELECT ?c ?name (SAMPLE(?r) AS ?rgb) (SAMPLE(?l) AS ?len) (SAMPLE(?d) AS ?dia) WHERE {
                 ?c a ck:Cable ; ck:label ?name . OPTIONAL { ?c ck:colourRgb ?r }
                 OPTIONAL { ?c ck:lengthM ?l } OPTIONAL { ?c ck:diameterM ?d } } GROUP BY ?c ?name"""
        )
    }
    connectors = {
        row["name"]: _Connector(
            row["name"], row["c"], _rgb(row["rgb"]), _dims(row), "capacitor" if row["cap"] else "connector"
        )
        for row in kg.query(
            """SELECT ?c ?name (SAMPLE(?r) AS ?rgb) (SAMPLE(?xd) AS ?x) (SAMPLE(?yd) AS ?y)
                      (SAMPLE(?zd) AS ?z) (SAMPLE(?k) AS ?cap) WHERE {
                 { ?c a ck:Connector } UNION { ?c a ck:Capacitor }
                 ?c ck:label ?name . OPTIONAL { ?c ck:colourRgb ?r }
                 OPTIONAL { ?c ck:xDim ?xd ; ck:yDim ?yd ; ck:zDim ?zd }
                 OPTIONAL { ?c a ck:Capacitor BIND(true AS ?k) } } GROUP BY ?c ?name"""
        )
    }
    ends: dict[str, list[_End | None]] = defaultdict(lambda: [None, None])
    for row in kg.query(
        """SELECT DISTINCT ?name ?end ?connector ?index WHERE { ?c a ck:Cable ; ck:label ?name .
             { ?c ck:fromPin ?p BIND(0 AS ?end) } UNION { ?c ck:toPin ?p BIND(1 AS ?end) }
             ?p ck:pinOf/ck:label ?connector ; ck:pinIndex ?index }"""
    ):
        ends[row["name"]][int(row["end"])] = _End(row["connector"], int(row["index"]))
    harnesses: dict[int, _Harness] = {}
    harness_of: dict[str, int] = {}
    branches: dict[str, list[tuple[int, str, list[tuple[int, str]]]]] = defaultdict(list)
    branch_cables: dict[str, list[tuple[int, str]]] = defaultdict(list)
    for row in kg.query(
        """SELECT DISTINCT ?b ?cable ?line WHERE { GRAPH ?g { ?b ck:containsCable ?c .
             OPTIONAL { ?c ck:sourceLine ?line } } ?c ck:label ?cable }"""
    ):
        branch_cables[row["b"]].append((int(row["line"] or 0), row["cable"]))
    for row in kg.query(
        """SELECT DISTINCT ?h ?b ?line ?connector WHERE { ?h a ck:Harness ; ck:hasBranch ?b .
             ?b ck:hasConnector/ck:label ?connector . OPTIONAL { ?b ck:sourceLine ?line } }"""
    ):
        branches[row["h"]].append((int(row["line"] or 0), row["connector"], branch_cables[row["b"]]))
    for row in kg.query(
        """SELECT DISTINCT ?h ?number ?main WHERE { ?h a ck:Harness ; ck:harnessNumber ?number ;
             ck:mainConnector/ck:label ?main }"""
    ):
        number = int(row["number"])
        infos = tuple(
            BranchInfo(connector, tuple(name for _, name in sorted(members)))
            for _, connector, members in sorted(branches[row["h"]])
        )
        harnesses[number] = _Harness(number, row["h"], row["main"], infos)
        harness_of[row["main"]] = number
        for info in infos:
            harness_of[info.connector] = number
            for cable in info.cables:
                harness_of[cable] = number
    operations = _operations(kg)
    return ElvezModel(
        platforms=platform_model(kg),
        cables=cables,
        connectors=connectors,
        ends={name: (pair[0], pair[1]) for name, pair in ends.items()},
        harnesses=dict(sorted(harnesses.items())),
        harness_of=harness_of,
        tools=_tools(kg),
        operations=[op for _, op in operations],
        operation_index={iri: op.index for iri, op in operations},
        view=graph_view(kg, _TRAVERSED),
    )


def _tools(kg: KnowledgeGraph) -> dict[str, _Tool]:
    frames: dict[tuple[str, str], Pose] = {}
    for row in kg.query(
        f"""SELECT DISTINCT ?name ?which ?tx ?ty ?tz ?qx ?qy ?qz ?qw WHERE {{ ?t a ck:Tool ; ck:label ?name .
              {{ ?t ck:wristFrame ?f BIND("wrist" AS ?which) }}
              UNION {{ ?t ck:actionFrame ?f BIND("action" AS ?which) }}
              ?f ck:hasPose ?pose . {_POSE} }}"""
    ):
        frames[(row["name"], row["which"])] = _pose(row)
    tools = {}
    for row in kg.query(
        """SELECT ?name (SAMPLE(?k) AS ?kind) (SAMPLE(?s) AS ?slot) (SAMPLE(?xd) AS ?x) (SAMPLE(?yd) AS ?y)
                  (SAMPLE(?zd) AS ?z) WHERE { ?t a ck:Tool ; ck:label ?name .
             OPTIONAL { ?t ck:toolType ?k } OPTIONAL { ?t ck:toolSlot/ck:label ?s }
             OPTIONAL { ?t ck:xDim ?xd ; ck:yDim ?yd ; ck:zDim ?zd } } GROUP BY ?name ORDER BY ?name"""
    ):
        name = row["name"]
        tools[name] = _Tool(
            name,
            row["kind"] or "",
            row["slot"] or "",
            _dims(row),
            frames.get((name, "wrist")),
            frames.get((name, "action")),
        )
    return tools


def _operations(kg: KnowledgeGraph) -> list[tuple[str, OperationInfo]]:
    operations = []
    for row in kg.query(
        """SELECT ?op ?index (SAMPLE(?cls) AS ?class) (SAMPLE(?s) AS ?spots) (SAMPLE(?l) AS ?labels)
                  (SAMPLE(?t) AS ?tool) WHERE {
             ?op a ck:Operation ; ck:sequenceIndex ?index ; ck:inPlan ?plan .
             OPTIONAL { ?op a ?cls FILTER(?cls IN (ck:InsertOperation, ck:RouteOperation, ck:TapeOperation)) }
             OPTIONAL { ?op ck:spotLabels ?s } OPTIONAL { ?op ck:involvedLabels ?l }
             OPTIONAL { ?op ck:usesTool ?t } }
           GROUP BY ?op ?index ORDER BY ?index"""
    ):
        kind = _OPERATION_TYPES.get((row["class"] or "").rsplit("#", 1)[-1], "")
        operations.append(
            (
                row["op"],
                OperationInfo(
                    index=int(row["index"]),
                    type=kind,
                    spot=tuple(row["spots"].split(";")) if row["spots"] else (),
                    label=tuple(row["labels"].split(";")) if row["labels"] else (),
                    # Tool IRIs are minted from the tool's name (tool/NAME), in a tools file or not.
                    tool=unquote(row["tool"].rsplit("/", 1)[-1]) if row["tool"] else "",
                ),
            )
        )
    return operations
