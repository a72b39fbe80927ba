"""Reader of the harness text description (``.harness``): a small line format for one harness.

One statement per line, words separated by blanks, ``key=value`` options, ``#`` comments and
``"double quotes"`` around values with blanks::

    harness DOOR-L description="door harness, left"
    connector X1 cavities=1-4 description="door control unit"
    connector X2 cavities=1,2
    node B1
    segment S1 X1 B1 length=250mm diameter=8mm
    segment S2 B1 X2 length=0.4m diameter=6mm
    wire W1 X1:1 X2:1 section=0.35 colour=BK route=S1,S2
    fixing F1 on=B1
    protection P1 on=S1 description="tape"

A connector sits on a node named like itself unless ``at=`` names another node. Names may
be used before the line that declares them; every name is checked once the file is read, and
an unknown one is an error at the line that uses it. A wire without ``route=`` runs along
the shortest chain of segments between its connectors' nodes. See docs/formats/harness-text.md.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path

import networkx as nx

from cadkg.errors import IngestError
from cadkg.ingest.harness.records import (
    Harness,
    HarnessCable,
    HarnessConnector,
    HarnessFixing,
    HarnessNode,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    WireEnd,
    WireRoute,
)
from cadkg.ingest.text import read_text
from cadkg.usecases.vw.harness_statements import EXPECTED, FILE_FORMAT, Statement, StatementReader

__all__ = ["FILE_FORMAT", "looks_like_harness_text", "read_harness_text"]


def looks_like_harness_text(head: bytes) -> bool:
    """Whether the first statement of a file is ``harness NAME`` (for the registry)."""
    for raw in head.decode("utf-8", errors="replace").lstrip("\ufeff").splitlines():
        line = raw.split("#", 1)[0].strip()
        if line:
            return line.split()[0] == "harness" and len(line.split()) >= 2
    return False


def read_harness_text(path: str | Path) -> list[HarnessRecord]:
    """Read a harness text description into the records the KBL reader also gives.

    Raises
    ------
    IngestError
        On an empty or binary file, an unclosed quote, an unknown statement or key, a
        missing or extra word, a missing required key, a malformed name, length, section or
        cavity list, a name declared twice, a reference to an unknown connector, cavity,
        node (a segment to an unknown node ...), segment or cable, a route that does not
        lead from one end of its wire to the other, and connectors no segments join; located
        at file:line.
    """
    text = read_text(path, expected=EXPECTED)
    return _Parser(path).parse(text)


@dataclass
class _Harness:
    name: str = ""
    description: str | None = None
    line: int = 0
    connectors: dict[str, Statement] = field(default_factory=dict)
    nodes: dict[str, int] = field(default_factory=dict)
    # The statement giving a node's position=: the node's own, or its connector's.
    positions: dict[str, Statement] = field(default_factory=dict)
    segments: dict[str, Statement] = field(default_factory=dict)
    wires: dict[str, Statement] = field(default_factory=dict)
    cables: dict[str, Statement] = field(default_factory=dict)
    fixings: dict[str, Statement] = field(default_factory=dict)
    protections: dict[str, Statement] = field(default_factory=dict)


class _Parser(StatementReader):
    def parse(self, text: str) -> list[HarnessRecord]:
        statements = [s for s in (self.statement(raw, n) for n, raw in enumerate(text.split("\n"), 1)) if s]
        if not statements:
            raise self.error("no statements in the file", 1, expected=EXPECTED)
        first = statements[0]
        if first.keyword != "harness":
            raise self.error(
                "the first statement must name the harness",
                first.line,
                found=first.keyword,
                expected="harness NAME",
            )
        h = _Harness(first.words[0], first.options.get("description"), first.line)
        for statement in statements[1:]:
            self.declare(h, statement)
        return self.records(h)

    def declare(self, h: _Harness, s: Statement) -> None:
        name = s.words[0]
        if s.keyword == "harness":
            raise self.error(
                "a second harness statement", s.line, found=name, expected=f"one harness per file ({h.name})"
            )
        table = {
            "connector": h.connectors,
            "segment": h.segments,
            "wire": h.wires,
            "cable": h.cables,
            "fixing": h.fixings,
            "protection": h.protections,
        }.get(s.keyword)
        if table is not None:
            if name in table:
                raise self.error(
                    f"{s.keyword} declared twice",
                    s.line,
                    found=name,
                    expected=f"unique names (first on line {table[name].line})",
                )
            table[name] = s
        if s.keyword == "connector" and "at" in s.options and "position" in s.options:
            raise self.error(
                f"connector {name} has both at= and position=",
                s.line,
                found=f"at={s.options['at']}",
                expected=f"position= on node {s.options['at']}, where the connector sits",
            )
        if s.keyword == "node" or (s.keyword == "connector" and "at" not in s.options):
            if name in h.nodes:
                raise self.error(
                    "node declared twice",
                    s.line,
                    found=name,
                    # A connector without at= sits on a node of its own name.
                    expected=f"unique node and connector names (first on line {h.nodes[name]})",
                )
            h.nodes[name] = s.line
            if "position" in s.options:
                h.positions[name] = s

    # -- values ---------------------------------------------------------------------------------------
    def records(self, h: _Harness) -> list[HarnessRecord]:
        cavities = {name: self.cavities(s) for name, s in h.connectors.items()}
        located: dict[str, str] = {}
        for name, s in h.connectors.items():
            node = s.options.get("at", name)
            if node not in h.nodes:
                raise self.unknown(f"connector {name} is at an unknown node", s, node, h.nodes)
            located[name] = node
        segments = {name: self.segment(h, s) for name, s in h.segments.items()}
        graph = nx.Graph()
        graph.add_nodes_from(h.nodes)
        for segment in sorted(segments.values(), key=lambda seg: (seg.length_m or 0, seg.ident)):
            if not graph.has_edge(segment.start, segment.end):
                graph.add_edge(
                    segment.start, segment.end, segment=segment.ident, length=float(segment.length_m or 0)
                )
        for name, s in h.wires.items():
            cable = s.options.get("cable")
            if cable is not None and cable not in h.cables:
                raise self.unknown(f"wire {name} is a core of an unknown cable", s, cable, h.cables)
        records: list[HarnessRecord] = [Harness(h.name, h.description, FILE_FORMAT, h.line)]
        records.extend(
            HarnessConnector(
                h.name, name, name, "connector", cavities[name], s.options.get("description"), s.line
            )
            for name, s in h.connectors.items()
        )
        records.extend(
            HarnessNode(
                h.name,
                node,
                node,
                tuple(c for c, at in located.items() if at == node),
                h.nodes[node],
                self.position(h.positions[node]) if node in h.positions else None,
            )
            for node in h.nodes
        )
        records.extend(segments.values())
        records.extend(
            HarnessCable(h.name, name, name, self.length(s, "length"), self.diameter(s), s.line)
            for name, s in h.cables.items()
        )
        records.extend(self.wire(h, s, cavities, located, segments, graph) for s in h.wires.values())
        for name, s in h.fixings.items():
            nodes, on_segments = self.placement(h, s, allow_nodes=True)
            records.append(
                HarnessFixing(h.name, name, name, s.options.get("description"), nodes, on_segments, s.line)
            )
        for name, s in h.protections.items():
            _, on_segments = self.placement(h, s, allow_nodes=False)
            records.append(
                HarnessProtection(
                    h.name,
                    name,
                    name,
                    s.options.get("description"),
                    on_segments,
                    self.length(s, "length"),
                    s.line,
                )
            )
        return records

    def unknown(self, reason: str, s: Statement, name: str, table: Iterable[str]) -> IngestError:
        """The error of ``s`` naming ``name``, which ``table`` does not declare: it shows what does."""
        names = sorted(table)
        shown = ", ".join(names[:12]) + (" ..." if len(names) > 12 else "")
        expected = f"one of: {shown}" if names else "a declared name (none is declared)"
        return self.error(reason, s.line, found=name, expected=expected)

    def diameter(self, s: Statement) -> float | None:
        value = self.length(s, "diameter")
        return float(value) if value is not None else None

    def segment(self, h: _Harness, s: Statement) -> HarnessSegment:
        name, start, end = s.words
        for node in (start, end):
            if node not in h.nodes:
                raise self.unknown(f"segment {name} leads to an unknown node", s, node, h.nodes)
        if start == end:
            raise self.error(
                f"segment {name} starts and ends at the same node", s.line, found=start, expected="two nodes"
            )
        return HarnessSegment(
            h.name,
            name,
            name,
            start,
            end,
            self.length(s, "length"),
            self.diameter(s),
            self.section(s),
            s.line,
        )

    def end(self, s: Statement, word: str, cavities: dict[str, tuple[str, ...]]) -> WireEnd:
        connector, sep, cavity = word.partition(":")
        if not sep or not connector or not cavity:
            raise self.error(
                f"malformed end of wire {s.words[0]}",
                s.line,
                found=word,
                expected="CONNECTOR:CAVITY, e.g. X1:3",
            )
        if connector not in cavities:
            raise self.unknown(f"wire {s.words[0]} ends at an unknown connector", s, connector, cavities)
        if cavity not in cavities[connector]:
            raise self.error(
                f"wire {s.words[0]} ends in a cavity connector {connector} does not have",
                s.line,
                found=word,
                expected=f"a cavity of {connector}: {', '.join(cavities[connector])}",
            )
        return WireEnd(connector, cavity)

    def wire(
        self,
        h: _Harness,
        s: Statement,
        cavities: dict[str, tuple[str, ...]],
        located: dict[str, str],
        segments: dict[str, HarnessSegment],
        graph: nx.Graph,
    ) -> HarnessWire:
        name = s.words[0]
        ends = (self.end(s, s.words[1], cavities), self.end(s, s.words[2], cavities))
        start, goal = located[ends[0].connector], located[ends[1].connector]
        if "route" in s.options:
            route = tuple(self.names(s, "route"))
            at = start
            for segment_name in route:
                segment = segments.get(segment_name)
                if segment is None:
                    raise self.unknown(
                        f"route of wire {name} names an unknown segment", s, segment_name, segments
                    )
                if at not in (segment.start, segment.end):
                    raise self.error(
                        f"route of wire {name} breaks at segment {segment_name}",
                        s.line,
                        found=f"{segment_name} ({segment.start}-{segment.end})",
                        expected=f"a segment from node {at}",
                    )
                at = segment.end if at == segment.start else segment.start
            if at != goal:
                raise self.error(
                    f"route of wire {name} does not reach its other end",
                    s.line,
                    found=f"ends at node {at}",
                    expected=f"node {goal}",
                )
        else:
            try:
                path = nx.shortest_path(graph, start, goal, weight="length")
            except nx.NetworkXNoPath:
                raise self.error(
                    f"no chain of segments joins the ends of wire {name}",
                    s.line,
                    found=f"nodes {start} and {goal}",
                    expected="segments joining them, or a route= option",
                ) from None
            route = tuple(graph.edges[a, b]["segment"] for a, b in pairwise(path))
        return HarnessWire(
            harness=h.name,
            ident=name,
            label=name,
            ends=ends,
            routes=(WireRoute(name, route),),
            section_mm2=self.section(s),
            colour=s.options.get("colour"),
            length_m=self.length(s, "length"),
            diameter_m=self.diameter(s),
            cable=s.options.get("cable"),
            signal=s.options.get("signal"),
            line=s.line,
        )

    def placement(
        self, h: _Harness, s: Statement, *, allow_nodes: bool
    ) -> tuple[tuple[str, ...], tuple[str, ...]]:
        nodes: list[str] = []
        on_segments: list[str] = []
        for name in self.names(s, "on"):
            if allow_nodes and name in h.nodes and name in h.segments:
                raise self.error(
                    f"{s.keyword} {s.words[0]} is on an ambiguous name",
                    s.line,
                    found=name,
                    expected="a name that is either a node or a segment",
                )
            if allow_nodes and name in h.nodes:
                nodes.append(name)
            elif name in h.segments:
                on_segments.append(name)
            else:
                what = "node or segment" if allow_nodes else "segment"
                declared = {**(h.nodes if allow_nodes else {}), **h.segments}
                raise self.unknown(f"{s.keyword} {s.words[0]} is on an unknown {what}", s, name, declared)
        return tuple(dict.fromkeys(nodes)), tuple(dict.fromkeys(on_segments))
