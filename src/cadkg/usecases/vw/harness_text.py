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

import re
import shlex
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation
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
)
from cadkg.ingest.text import read_text, small_integer

__all__ = ["FILE_FORMAT", "looks_like_harness_text", "read_harness_text"]

FILE_FORMAT = "cadkg harness text 1"
_EXPECTED = (
    "a harness description: a first statement 'harness NAME', then connector, node, segment, wire ... lines"
)
_NAME = re.compile(r"^[^\s:,=#\"']+$")
_CAVITY = re.compile(r"^[^\s,=#\"']+$")
_LENGTH = re.compile(r"^(?P<number>\d+(?:\.\d*)?|\.\d+)(?P<unit>mm|cm|m)$")
_SECTION = re.compile(r"^(?P<number>\d+(?:\.\d*)?|\.\d+)(?:mm2|mm²)?$")
_RANGE = re.compile(r"^(?P<first>\d+)-(?P<last>\d+)$")
_METRES = {"mm": Decimal("0.001"), "cm": Decimal("0.01"), "m": Decimal(1)}
# Cavities of one connector: the largest connectors have a few hundred.
_MAX_CAVITIES = 1000
# Statement → (number of positional words after the keyword, required keys, optional keys).
_GRAMMAR: dict[str, tuple[tuple[str, ...], frozenset[str], frozenset[str]]] = {
    "harness": (("name",), frozenset(), frozenset({"description"})),
    "connector": (("name",), frozenset({"cavities"}), frozenset({"at", "description"})),
    "node": (("name",), frozenset(), frozenset()),
    "segment": (("name", "from-node", "to-node"), frozenset({"length"}), frozenset({"diameter", "section"})),
    "wire": (
        ("name", "from connector:cavity", "to connector:cavity"),
        frozenset(),
        frozenset({"section", "colour", "length", "diameter", "route", "cable", "signal"}),
    ),
    "cable": (("name",), frozenset(), frozenset({"length", "diameter"})),
    "fixing": (("name",), frozenset({"on"}), frozenset({"description"})),
    "protection": (("name",), frozenset({"on"}), frozenset({"length", "description"})),
}


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
    text = read_text(path, expected=_EXPECTED)
    return _Parser(path).parse(text)


@dataclass
class _Statement:
    keyword: str
    words: list[str]
    options: dict[str, str]
    line: int


@dataclass
class _Harness:
    name: str = ""
    description: str | None = None
    line: int = 0
    connectors: dict[str, _Statement] = field(default_factory=dict)
    nodes: dict[str, int] = field(default_factory=dict)
    segments: dict[str, _Statement] = field(default_factory=dict)
    wires: dict[str, _Statement] = field(default_factory=dict)
    cables: dict[str, _Statement] = field(default_factory=dict)
    fixings: dict[str, _Statement] = field(default_factory=dict)
    protections: dict[str, _Statement] = field(default_factory=dict)


class _Parser:
    def __init__(self, path: str | Path) -> None:
        self.path = path

    def error(
        self, reason: str, line: int, found: object | None = None, expected: str | None = None
    ) -> IngestError:
        return IngestError(self.path, reason, line=line, found=found, expected=expected)

    # -- statements ---------------------------------------------------------------------------------
    def parse(self, text: str) -> list[HarnessRecord]:
        statements = [s for s in (self.statement(raw, n) for n, raw in enumerate(text.split("\n"), 1)) if s]
        if not statements:
            raise self.error("no statements in the file", 1, expected=_EXPECTED)
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

    def statement(self, raw: str, line: int) -> _Statement | None:
        lexer = shlex.shlex(raw.rstrip("\r"), posix=True)
        lexer.whitespace_split = True
        lexer.commenters = "#"
        try:
            tokens = list(lexer)
        except ValueError as err:
            raise self.error(
                f"cannot split the line into words: {err}", line, expected="closed quotes"
            ) from None
        if not tokens:
            return None
        keyword, rest = tokens[0], tokens[1:]
        if keyword not in _GRAMMAR:
            raise self.error("unknown statement", line, found=keyword, expected=" | ".join(_GRAMMAR))
        positional, required, optional = _GRAMMAR[keyword]
        words = [w for w in rest if "=" not in w]
        options: dict[str, str] = {}
        for token in rest:
            key, sep, value = token.partition("=")
            if not sep:
                continue
            if key not in required | optional:
                known = ", ".join(sorted(required | optional)) or "none"
                raise self.error(f"unknown key of '{keyword}'", line, found=key, expected=f"one of: {known}")
            if key in options:
                raise self.error(f"key given twice in '{keyword}'", line, found=key, expected="each key once")
            if not value:
                raise self.error(f"empty value of {key}=", line, expected=f"{key}=VALUE")
            options[key] = value
        if len(words) != len(positional):
            raise self.error(
                f"'{keyword}' takes {len(positional)} word(s) before its options",
                line,
                found=" ".join(words) or "none",
                expected=f"{keyword} {' '.join(p.upper() for p in positional)}",
            )
        missing = sorted(required - set(options))
        if missing:
            raise self.error(f"'{keyword}' needs {missing[0]}=", line, expected=f"{missing[0]}=VALUE")
        if not _NAME.match(words[0]):
            raise self.error(
                f"malformed {keyword} name",
                line,
                found=words[0],
                expected="a name without blanks, : , = # or quotes",
            )
        return _Statement(keyword, words, options, line)

    def declare(self, h: _Harness, s: _Statement) -> None:
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

    # -- values ---------------------------------------------------------------------------------------
    def length(self, s: _Statement, key: str) -> Decimal | None:
        raw = s.options.get(key)
        if raw is None:
            return None
        match = _LENGTH.match(raw)
        if match is None or Decimal(match["number"]) == 0:
            raise self.error(
                f"malformed {key}",
                s.line,
                found=raw,
                expected="a positive number with mm, cm or m, e.g. 250mm",
            )
        return Decimal(match["number"]) * _METRES[match["unit"]]

    def section(self, s: _Statement) -> Decimal | None:
        raw = s.options.get("section")
        if raw is None:
            return None
        match = _SECTION.match(raw)
        try:
            value = Decimal(match["number"]) if match else Decimal(0)
        except InvalidOperation:
            value = Decimal(0)
        if value <= 0:
            raise self.error(
                "malformed section",
                s.line,
                found=raw,
                expected="a positive number of mm², e.g. 0.35 or 0.35mm2",
            )
        return value

    def names(self, s: _Statement, key: str) -> list[str]:
        names = s.options.get(key, "").split(",") if key in s.options else []
        for name in names:
            if not _NAME.match(name):
                raise self.error(
                    f"malformed name in {key}=",
                    s.line,
                    found=name or "an empty name",
                    expected="names separated by commas",
                )
        return names

    def cavities(self, s: _Statement) -> tuple[str, ...]:
        names: list[str] = []
        for item in s.options["cavities"].split(","):
            match = _RANGE.match(item)
            if match:
                first, last = small_integer(match["first"]), small_integer(match["last"])
                if first is None or last is None or not 0 <= last - first < _MAX_CAVITIES:
                    raise self.error(
                        "bad cavity range",
                        s.line,
                        found=item,
                        expected=f"FIRST-LAST with FIRST <= LAST, at most {_MAX_CAVITIES}",
                    )
                names.extend(str(n) for n in range(first, last + 1))
            elif _CAVITY.match(item):
                names.append(item)
            else:
                raise self.error(
                    "malformed cavity list",
                    s.line,
                    found=item or "an empty name",
                    expected="names or ranges like 1-4, separated by commas",
                )
            if len(names) > _MAX_CAVITIES:
                raise self.error(
                    "too many cavities", s.line, found=len(names), expected=f"at most {_MAX_CAVITIES}"
                )
        twice = sorted(n for n, count in Counter(names).items() if count > 1)
        if twice:
            raise self.error("cavity listed twice", s.line, found=twice[0], expected="each cavity once")
        return tuple(names)

    # -- checks and records ---------------------------------------------------------------------------
    def records(self, h: _Harness) -> list[HarnessRecord]:
        cavities = {name: self.cavities(s) for name, s in h.connectors.items()}
        located: dict[str, str] = {}
        for name, s in h.connectors.items():
            node = s.options.get("at", name)
            if node not in h.nodes:
                raise self.error(
                    f"connector {name} is at an unknown node",
                    s.line,
                    found=node,
                    expected=self.known(h.nodes),
                )
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
                raise self.error(
                    f"wire {name} is a core of an unknown cable",
                    s.line,
                    found=cable,
                    expected=self.known(h.cables),
                )
        records: list[HarnessRecord] = [Harness(h.name, h.description, FILE_FORMAT, h.line)]
        records.extend(
            HarnessConnector(h.name, name, "connector", cavities[name], s.options.get("description"), s.line)
            for name, s in h.connectors.items()
        )
        records.extend(
            HarnessNode(h.name, node, node, tuple(c for c, at in located.items() if at == node), line)
            for node, line in h.nodes.items()
        )
        records.extend(segments.values())
        records.extend(
            HarnessCable(h.name, name, self.length(s, "length"), self.diameter(s), s.line)
            for name, s in h.cables.items()
        )
        records.extend(self.wire(h, s, cavities, located, segments, graph) for s in h.wires.values())
        for name, s in h.fixings.items():
            nodes, on_segments = self.placement(h, s, allow_nodes=True)
            records.append(
                HarnessFixing(h.name, name, s.options.get("description"), nodes, on_segments, s.line)
            )
        for name, s in h.protections.items():
            _, on_segments = self.placement(h, s, allow_nodes=False)
            records.append(
                HarnessProtection(
                    h.name, name, s.options.get("description"), on_segments, self.length(s, "length"), s.line
                )
            )
        return records

    @staticmethod
    def known(table: Iterable[str]) -> str:
        names = sorted(table)
        shown = ", ".join(names[:12]) + (" ..." if len(names) > 12 else "")
        return f"one of: {shown}" if names else "a declared name (none is declared)"

    def diameter(self, s: _Statement) -> float | None:
        value = self.length(s, "diameter")
        return float(value) if value is not None else None

    def segment(self, h: _Harness, s: _Statement) -> HarnessSegment:
        name, start, end = s.words
        for node in (start, end):
            if node not in h.nodes:
                raise self.error(
                    f"segment {name} leads to an unknown node",
                    s.line,
                    found=node,
                    expected=self.known(h.nodes),
                )
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

    def end(self, s: _Statement, word: str, cavities: dict[str, tuple[str, ...]]) -> WireEnd:
        connector, sep, cavity = word.partition(":")
        if not sep or not connector or not cavity:
            raise self.error(
                f"malformed end of wire {s.words[0]}",
                s.line,
                found=word,
                expected="CONNECTOR:CAVITY, e.g. X1:3",
            )
        if connector not in cavities:
            raise self.error(
                f"wire {s.words[0]} ends at an unknown connector",
                s.line,
                found=connector,
                expected=self.known(cavities),
            )
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
        s: _Statement,
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
                    raise self.error(
                        f"route of wire {name} names an unknown segment",
                        s.line,
                        found=segment_name,
                        expected=self.known(segments),
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
            route=route,
            section_mm2=self.section(s),
            colour=s.options.get("colour"),
            length_m=self.length(s, "length"),
            diameter_m=self.diameter(s),
            cable=s.options.get("cable"),
            signal=s.options.get("signal"),
            line=s.line,
        )

    def placement(
        self, h: _Harness, s: _Statement, *, allow_nodes: bool
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
                raise self.error(
                    f"{s.keyword} {s.words[0]} is on an unknown {what}",
                    s.line,
                    found=name,
                    expected=self.known({**(h.nodes if allow_nodes else {}), **h.segments}),
                )
        return tuple(dict.fromkeys(nodes)), tuple(dict.fromkeys(on_segments))
