"""The ELVEZ model: the platforms, definitions, harnesses, components and sequence of a cell,
read from the graph once (:func:`build_model`); the services are plain functions of it.

What the files said is read back into the readers' own records (element definitions,
harnesses, components, sequence steps), so the services compute from the same shapes the
files have; the platform elements and the frames that place them form a :class:`FrameTree`.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cadkg.errors import QueryError
from cadkg.geometry.poses import Pose
from cadkg.usecases.elvez.files.components import HarnessComponent
from cadkg.usecases.elvez.files.definitions import AtcTool, ElementDefinition, Guide, Key, PlacedBox
from cadkg.usecases.elvez.files.harnesses import EndConnector, HarnessCable, WiringHarness
from cadkg.usecases.elvez.files.sequence import SequenceStep, SpotRef
from cadkg.usecases.elvez.platform import FrameTree, element_frame

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph
    from cadkg.services.session import Session

__all__ = [
    "PROFILE",
    "ROBOT_BASE",
    "Element",
    "ElvezModel",
    "build_model",
    "known",
    "model_of",
    "operation_iris",
    "unresolved",
]

PROFILE = "elvez"

ROBOT_BASE = "robot_base"
"""The frame answers are given in when the manifest places it (the robot's base); else the
root of the platforms' frame tree (``cell``)."""

_SHOWN = 12
_POSE = "?pose ck:tx ?tx ; ck:ty ?ty ; ck:tz ?tz ; ck:qx ?qx ; ck:qy ?qy ; ck:qz ?qz ; ck:qw ?qw ."
_ZERO = Pose()


@dataclass(frozen=True)
class Element:
    """A platform element: its WRI row (label, type, model) and its frame's name."""

    platform: str
    cad_id: str
    label: str
    type: str
    model: str | None
    frame: str
    where: str  # file:line of its WRI row

    @property
    def tool(self) -> str:
        """The tool an ATC station element holds: its label without the leading ``A``."""
        return self.label[1:] if self.type == "atc_station" else ""


@dataclass
class ElvezModel:
    """What the ELVEZ services answer from (see :func:`build_model`)."""

    tree: FrameTree
    reference: str
    elements: list[Element]
    definitions: dict[str, ElementDefinition]
    harnesses: list[WiringHarness]
    components: dict[str, HarnessComponent]
    sequence: list[SequenceStep]
    step_where: list[str] = field(default_factory=list)
    meshes: dict[tuple[str, str], str] = field(default_factory=dict)
    frame_meshes: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.by_label: dict[str, Element] = {}
        for element in self.elements:
            if element.type and element.type != "table":
                self.by_label.setdefault(element.label, element)

    def element(self, label: str) -> Element | None:
        return self.by_label.get(label.strip())

    def definition(self, element: Element) -> ElementDefinition | None:
        return self.definitions.get(element.model or "")

    def pose(self, frame: str, reference: str | None = None) -> Pose:
        """The pose of ``frame`` in ``reference`` (the model's reference frame when None)."""
        return self.tree.pose(frame, reference or self.reference)

    def tools(self) -> list[Element]:
        return [e for e in self.elements if e.type == "atc_station"]

    def harness_of(self, label: str) -> tuple[WiringHarness, EndConnector | None, HarnessCable | None] | None:
        """The harness a first connector, end connector or cable belongs to (the last that
        names it, as the reference reads the file), with the end connector and cable."""
        found: tuple[WiringHarness, EndConnector | None, HarnessCable | None] | None = None
        for harness in self.harnesses:
            if harness.first_connector == label:
                found = (harness, None, None)
            for end in harness.end_connectors:
                if end.label == label:
                    found = (harness, end, None)
                for cable in end.cables:
                    if cable.label == label:
                        found = (harness, end, cable)
        return found


def known(names: list[str] | set[str] | tuple[str, ...]) -> str:
    """Some of ``names`` for a message: ``J1, J2 and 9 more`` (``none`` when empty)."""
    listed = list(dict.fromkeys(names))
    if not listed:
        return "none"
    shown = ", ".join(listed[:_SHOWN])
    return shown + (f" and {len(listed) - _SHOWN} more" if len(listed) > _SHOWN else "")


def _pose(row: dict[str, Any]) -> Pose:
    return Pose(
        (float(row["tx"]), float(row["ty"]), float(row["tz"])),
        (float(row["qx"]), float(row["qy"]), float(row["qz"]), float(row["qw"])),
    )


def _where(row: dict[str, Any]) -> str:
    return f"{row['path']}:{row['line']}" if row.get("path") else ""


def build_model(kg: KnowledgeGraph) -> ElvezModel:
    """Read the ELVEZ files' content from the graph into an :class:`ElvezModel`.

    Raises
    ------
    QueryError
        When a frame is placed twice with different poses (two scenes of one platform name).
    """
    tree = FrameTree(_frames(kg))
    elements = _elements(kg)
    placed = [e.frame for e in elements if e.frame in tree]
    reference = ROBOT_BASE if ROBOT_BASE in tree or not placed else tree.rooted(placed[0])[0]
    steps = _sequence(kg)
    meshes: dict[tuple[str, str], str] = {}
    frame_meshes: dict[str, str] = {}
    for row in kg.query(
        """SELECT DISTINCT ?platform ?name ?uri WHERE { ?m a ck:Mesh ; ck:label ?name ; ck:meshUri ?uri ;
             ck:partOf/ck:label ?platform }"""
    ):
        meshes[(row["platform"], row["name"])] = row["uri"]
    for row in kg.query(
        "SELECT ?frame ?uri WHERE { ?f a ck:Frame ; ck:label ?frame ; ck:hasMesh/ck:meshUri ?uri }"
    ):
        frame_meshes[row["frame"]] = row["uri"]
    return ElvezModel(
        tree=tree,
        reference=reference,
        elements=elements,
        definitions=_definitions(kg),
        harnesses=_harnesses(kg),
        components=_components(kg),
        sequence=[step for step, _ in steps],
        step_where=[where for _, where in steps],
        meshes=meshes,
        frame_meshes=frame_meshes,
    )


def _frames(kg: KnowledgeGraph) -> dict[str, tuple[str, Pose]]:
    found: dict[str, set[tuple[str, Pose]]] = defaultdict(set)
    for row in kg.query(
        f"""SELECT DISTINCT ?name ?parent ?tx ?ty ?tz ?qx ?qy ?qz ?qw WHERE {{
              ?f a ck:Frame ; ck:label ?name ; ck:hasPose ?pose .
              ?pose ck:parentFrame/ck:label ?parent . {_POSE} }}"""
    ):
        found[row["name"]].add((row["parent"], _pose(row)))
    doubled = sorted(name for name, entries in found.items() if len(entries) > 1)
    if doubled:
        raise QueryError(
            f"frame {doubled[0]!r} is placed more than once"
            + (f" (and {len(doubled) - 1} more frames)" if len(doubled) > 1 else "")
            + ": two scenes of one platform name, or a manifest frame named like an element"
        )
    return {name: next(iter(entries)) for name, entries in found.items()}


def _elements(kg: KnowledgeGraph) -> list[Element]:
    rows = kg.query(
        """SELECT DISTINCT ?platform ?id ?label ?type ?code ?line ?path WHERE {
             ?e a ck:Element ; ck:cadId ?id ; ck:onPlatform/ck:label ?platform .
             GRAPH ?g { ?e ck:label ?label ; ck:sourceLine ?line } ?g ck:sourcePath ?path .
             OPTIONAL { ?e ck:elementType ?type } OPTIONAL { ?e ck:instanceOf/ck:commercialCode ?code } }
           ORDER BY ?platform ?line"""
    )
    return [
        Element(
            platform=row["platform"],
            cad_id=row["id"],
            label=row["label"],
            type=row["type"] or "",
            model=row["code"],
            frame=element_frame(row["id"], row["platform"]),
            where=_where(row),
        )
        for row in rows
    ]


def _definitions(kg: KnowledgeGraph) -> dict[str, ElementDefinition]:
    parts: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in kg.query(
        f"""SELECT DISTINCT ?code ?kind ?id ?guide ?line ?x ?y ?z ?length ?gap ?height ?corner ?x1 ?x2 ?y1 ?y2
                  ?tx ?ty ?tz ?qx ?qy ?qz ?qw WHERE {{
              ?m ck:modelKind ?modelKind ; ck:commercialCode ?code ; ck:definesKeypoint ?k .
              ?k ck:keypointKind ?kind ; ck:sourceLine ?line .
              OPTIONAL {{ ?k ck:label ?id }} OPTIONAL {{ ?k ck:guideId ?guide }}
              OPTIONAL {{ ?k ck:xDim ?x ; ck:yDim ?y ; ck:zDim ?z }}
              OPTIONAL {{ ?k ck:keyLength ?length ; ck:keyGap ?gap ; ck:keyHeight ?height ;
                          ck:keyHeightCorner ?corner }}
              OPTIONAL {{ ?k ck:collisionXFrom ?x1 ; ck:collisionXTo ?x2 ; ck:collisionYFrom ?y1 ;
                          ck:collisionYTo ?y2 }}
              OPTIONAL {{ ?k ck:hasPose ?pose . {_POSE} }} }}"""
    ):
        parts[row["code"]].append(row)
    definitions = {}
    for row in kg.query(
        """SELECT DISTINCT ?code ?kind ?line ?x ?y ?z ?x1 ?x2 ?y1 ?y2 ?tool WHERE {
             ?m ck:modelKind ?kind ; ck:commercialCode ?code ; ck:sourceLine ?line ;
                ck:xDim ?x ; ck:yDim ?y ; ck:zDim ?z .
             OPTIONAL { ?m ck:collisionXFrom ?x1 ; ck:collisionXTo ?x2 ; ck:collisionYFrom ?y1 ;
                        ck:collisionYTo ?y2 }
             OPTIONAL { ?m ck:stationTool ?tool } }"""
    ):
        definitions[row["code"]] = _definition(row, parts[row["code"]])
    return definitions


def _size(row: dict[str, Any]) -> tuple[float, float, float]:
    return (
        (float(row["x"]), float(row["y"]), float(row["z"])) if row.get("x") is not None else (0.0, 0.0, 0.0)
    )


def _extents(row: dict[str, Any]) -> tuple[float, float, float, float] | None:
    if row.get("x1") is None:
        return None
    return (float(row["x1"]), float(row["x2"]), float(row["y1"]), float(row["y2"]))


def _definition(row: dict[str, Any], parts: list[dict[str, Any]]) -> ElementDefinition:
    parts = sorted(parts, key=lambda p: (int(p["line"]), p["kind"], p["id"] or ""))
    by_kind: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for part in parts:
        by_kind[part["kind"]].append(part)

    def pose(part: dict[str, Any]) -> Pose:
        return _pose(part) if part.get("tx") is not None else _ZERO

    def box(part: dict[str, Any]) -> PlacedBox:
        return PlacedBox(part["id"] or "", _size(part), pose(part), int(part["line"]), part["guide"] or "")

    collisions = {p["guide"]: box(p) for p in by_kind["collision"]}
    guides = tuple(
        Guide(
            couple=p["id"],
            key=Key(
                float(p["length"]),
                float(p["gap"]),
                float(p["height"]),
                float(p["corner"]),
                _extents(p) or (0.0, 0.0, 0.0, 0.0),
                pose(p),
                int(p["line"]),
            ),
            collision=collisions.get(p["id"]),
            line=int(p["line"]),
        )
        for p in by_kind["key"]
    )
    centre = by_kind["centre"][0] if by_kind["centre"] else None
    single = {kind: rows[0] for kind, rows in by_kind.items() if rows}
    tool = None
    if row["kind"] == "ATC_station" and "tool_base" in single and "tool_end" in single:
        tool = AtcTool(
            kind=row["tool"] or "",
            base=pose(single["tool_base"]),
            end=pose(single["tool_end"]),
            size=_size(single["tool_size"]) if "tool_size" in single else (0.0, 0.0, 0.0),
            fingers=_size(single["finger_size"]) if "finger_size" in single else None,
            nail=pose(single["gripper_nail"]) if "gripper_nail" in single else None,
        )
    return ElementDefinition(
        kind=row["kind"],
        model=row["code"],
        size=_size(row),
        extents=_extents(row),
        centre=(pose(centre).position[0], pose(centre).position[1]) if centre else None,
        footprint=(float(centre["x"]), float(centre["y"])) if centre and centre["x"] is not None else None,
        guides=guides,
        tape_spots=tuple(box(p) for p in by_kind["tape_spot"]),
        trays=tuple(box(p) for p in by_kind["tray"]),
        tool=tool,
        line=int(row["line"]),
    )


def _harnesses(kg: KnowledgeGraph) -> list[WiringHarness]:
    cables: dict[str, list[HarnessCable]] = defaultdict(list)
    for row in kg.query(
        """SELECT DISTINCT ?b ?cable ?line ?r1 ?c1 ?r2 ?c2 WHERE { ?b a ck:Branch ; ck:containsCable ?c .
             ?c ck:label ?cable . ?h ck:hasBranch ?b .
             GRAPH ?g { ?h a ck:Harness . ?c ck:sourceLine ?line ; ck:fromPin ?from }
             ?from ck:cavityRow ?r1 ; ck:cavityColumn ?c1 .
             OPTIONAL { GRAPH ?g { ?c ck:toPin ?to } ?to ck:cavityRow ?r2 ; ck:cavityColumn ?c2 } }"""
    ):
        end = (int(row["r2"]), int(row["c2"])) if row["r2"] is not None else None
        cables[row["b"]].append(
            HarnessCable(row["cable"], (int(row["r1"]), int(row["c1"])), end, int(row["line"]))
        )
    ends: dict[str, list[EndConnector]] = defaultdict(list)
    for row in kg.query(
        """SELECT DISTINCT ?h ?b ?label ?line WHERE { ?h a ck:Harness ; ck:hasBranch ?b .
             ?b ck:label ?label ; ck:sourceLine ?line }"""
    ):
        members = tuple(sorted(cables[row["b"]], key=lambda c: c.line))
        ends[row["h"]].append(EndConnector(row["label"], members, int(row["line"])))
    harnesses = [
        WiringHarness(
            row["id"],
            row["first"],
            row["tray"] or "",
            tuple(sorted(ends[row["h"]], key=lambda e: e.line)),
            int(row["line"]),
        )
        for row in kg.query(
            """SELECT DISTINCT ?h ?id ?first ?tray ?line WHERE { ?h a ck:Harness ; ck:label ?id ;
                 ck:sourceLine ?line ; ck:mainConnector/ck:label ?first .
                 OPTIONAL { ?h ck:trayLabel ?tray } }"""
        )
    ]
    return sorted(harnesses, key=lambda h: h.line)


def _components(kg: KnowledgeGraph) -> dict[str, HarnessComponent]:
    rows = kg.query(
        """SELECT DISTINCT ?label ?cable ?connector ?colour ?rgb ?reference ?device ?model ?length ?diameter
                  ?x ?y ?z ?line WHERE {
             GRAPH ?g { ?c ck:label ?label ; ck:sourceLine ?line } ?g ck:readerKind "elvez-components" .
             OPTIONAL { ?c a ck:Cable BIND(true AS ?cable) }
             OPTIONAL { ?c a ck:Connector BIND(true AS ?connector) }
             OPTIONAL { ?c ck:colourName ?colour } OPTIONAL { ?c ck:colourRgb ?rgb }
             OPTIONAL { ?c ck:referenceCode ?reference } OPTIONAL { ?c ck:deviceType ?device }
             OPTIONAL { ?c ck:instanceOf/ck:commercialCode ?model } OPTIONAL { ?c ck:lengthM ?length }
             OPTIONAL { ?c ck:diameterM ?diameter } OPTIONAL { ?c ck:xDim ?x ; ck:yDim ?y ; ck:zDim ?z } }
           ORDER BY ?line"""
    )
    found = {}
    for row in rows:
        rgb = tuple(int(v) for v in row["rgb"].split()) if row["rgb"] else None
        found[row["label"]] = HarnessComponent(
            kind="cable" if row["cable"] else "connector" if row["connector"] else "device",
            model=row["model"] or "",
            reference=row["reference"] or "",
            label=row["label"],
            colour=row["colour"] or "",
            rgb=(rgb[0], rgb[1], rgb[2]) if rgb and len(rgb) == 3 else None,
            length=float(row["length"]) if row["length"] is not None else None,
            diameter=float(row["diameter"]) if row["diameter"] is not None else None,
            size=_size(row) if row["x"] is not None else None,
            device_type=row["device"] or "",
            line=int(row["line"]),
        )
    return found


def _sequence(kg: KnowledgeGraph) -> list[tuple[SequenceStep, str]]:
    spots: dict[str, list[tuple[int, SpotRef]]] = defaultdict(list)
    for row in kg.query(
        """SELECT DISTINCT ?op ?n ?jig ?guide ?side WHERE { ?op ck:operationCode ?code ; ck:atSpot ?s .
             ?s ck:sequenceIndex ?n ; ck:label ?jig ; ck:guideId ?guide . OPTIONAL { ?s ck:side ?side } }"""
    ):
        spots[row["op"]].append((int(row["n"]), SpotRef(row["jig"], row["guide"], row["side"] or "")))
    steps = []
    for row in kg.query(
        """SELECT DISTINCT ?op ?order ?code ?labels ?line ?path WHERE {
             GRAPH ?g { ?op ck:operationCode ?code ; ck:sequenceIndex ?order ; ck:involvedLabels ?labels ;
                        ck:sourceLine ?line } ?g ck:sourcePath ?path }
           ORDER BY ?path ?line"""
    ):
        refs = tuple(ref for _, ref in sorted(spots[row["op"]], key=lambda s: s[0]))
        text = "-".join(f"{r.jig}.{r.guide}" + (f".{r.side}" if r.side else "") for r in refs)
        step = SequenceStep(
            int(row["order"]), row["code"], tuple(row["labels"].split(";")), text, refs, int(row["line"])
        )
        steps.append((step, _where(row)))
    return steps


def model_of(session: Session) -> ElvezModel:
    """The ELVEZ model of a session, built from its graph once."""
    return session.profile_model(PROFILE, build_model)


def unresolved(model: ElvezModel, step: SequenceStep) -> list[str]:
    """What an operation names that the other files do not define: a label that is no
    harness's first or end connector, cable or component, a spot's element or guide."""
    notes = []
    for label in step.labels:
        if label not in model.components and model.harness_of(label) is None:
            notes.append(f"{label} is in no harness of the harness configuration and not in the components")
    for spot in step.spots:
        element = model.element(spot.jig)
        if element is None:
            notes.append(f"spot {spot.jig}.{spot.guide}: {spot.jig} is on no platform")
            continue
        definition = model.definition(element)
        if definition is None:
            notes.append(
                f"spot {spot.jig}.{spot.guide}: {spot.jig} has no definition (model {element.model})"
            )
        elif spot.guide not in {g.couple for g in definition.guides}:
            notes.append(f"spot {spot.jig}.{spot.guide}: {spot.jig} has no guide {spot.guide}")
    return notes


def operation_iris(kg: Any) -> dict[int, str]:
    """The IRI of each operation of the sequence, by its line in the file."""
    return {
        int(row["line"]): row["op"]
        for row in kg.query("SELECT ?op ?line WHERE { ?op ck:operationCode ?c ; ck:sourceLine ?line }")
    }
