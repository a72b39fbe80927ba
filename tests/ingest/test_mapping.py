"""Records to N-Triples: read_source on the examples and on values that try to break the syntax."""

from __future__ import annotations

import hashlib
from pathlib import Path
from urllib.parse import quote

import pyoxigraph as ox
import pytest

from cadkg.mapping.pipeline import GraphData, read_source
from cadkg.mapping.writer import TripleWriter

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "iema-switchgear"
FIG3 = EXAMPLE / "connections-fig3.tsv"
BASE = "https://example.org/cell/iema-qe01/"
CK = "https://w3id.org/cadkg#"
RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
XSD = "http://www.w3.org/2001/XMLSchema#"


class Triples:
    """The parsed N-Triples of one graph, with small lookups."""

    def __init__(self, data: bytes) -> None:
        self.quads = list(ox.parse(data, format=ox.RdfFormat.N_TRIPLES))

    def objects(self, subject: str | ox.NamedNode, predicate: str) -> list[ox.NamedNode | ox.Literal]:
        s = ox.NamedNode(subject) if isinstance(subject, str) else subject
        p = RDF_TYPE if predicate == "type" else ox.NamedNode(CK + predicate)
        return [q.object for q in self.quads if q.subject == s and q.predicate == p]  # type: ignore[misc]

    def value(self, subject: str | ox.NamedNode, predicate: str) -> str:
        (obj,) = self.objects(subject, predicate)
        return obj.value

    def of_type(self, name: str) -> list[ox.NamedNode]:
        target = ox.NamedNode(CK + name)
        return [q.subject for q in self.quads if q.predicate == RDF_TYPE and q.object == target]  # type: ignore[misc]


@pytest.fixture(scope="module")
def fig3_graph() -> GraphData:
    return read_source(FIG3, "connections-fig3.tsv", None, BASE)


@pytest.fixture(scope="module")
def fig3_triples(fig3_graph: GraphData) -> Triples:
    return Triples(fig3_graph.ntriples)


def test_fig3_report(fig3_graph: GraphData) -> None:
    report = fig3_graph.report
    assert fig3_graph.graph == BASE + "graph/connections-fig3.tsv"
    assert (report.rel_path, report.kind, report.records, report.warnings) == (
        "connections-fig3.tsv",
        "connection-list",
        20,
        (),
    )
    assert report.triples == fig3_graph.ntriples.count(b" .\n") > 0


def test_fig3_ntriples_parse(fig3_graph: GraphData, fig3_triples: Triples) -> None:
    assert len(fig3_triples.quads) == fig3_graph.report.triples
    assert all(q.graph_name == ox.DefaultGraph() for q in fig3_triples.quads)
    assert len(fig3_triples.of_type("Wire")) == 19


def test_fig3_provenance(fig3_graph: GraphData, fig3_triples: Triples) -> None:
    graph = fig3_graph.graph
    assert fig3_triples.objects(graph, "type") == [ox.NamedNode(CK + "SourceFile")]
    assert fig3_triples.value(graph, "sha256") == hashlib.sha256(FIG3.read_bytes()).hexdigest()
    assert fig3_triples.value(graph, "sourcePath") == "connections-fig3.tsv"
    assert fig3_triples.value(graph, "readerKind") == "connection-list"
    (when,) = fig3_triples.objects(graph, "ingestedAt")
    assert isinstance(when, ox.Literal) and when.datatype == ox.NamedNode(XSD + "dateTime")


def test_fig3_first_wire(fig3_triples: Triples) -> None:
    wire = BASE + "wire/1500.51"
    assert fig3_triples.value(wire, "wireNumber") == "1500.51"
    assert fig3_triples.value(wire, "fromPin") == BASE + "pin/F1500.1/14"
    assert fig3_triples.value(wire, "toPin") == BASE + "pin/Q1500.1/A1"
    assert fig3_triples.value(wire, "inPlan") == BASE + "plan/connections-fig3"
    assert fig3_triples.objects(wire, "sequenceIndex") == [
        ox.Literal("1", datatype=ox.NamedNode(XSD + "integer"))
    ]
    assert fig3_triples.objects(wire, "sourceLine") == [
        ox.Literal("2", datatype=ox.NamedNode(XSD + "integer"))
    ]
    assert fig3_triples.objects(wire, "lengthM") == [
        ox.Literal("0.746", datatype=ox.NamedNode(XSD + "decimal"))
    ]
    assert fig3_triples.objects(wire, "crossSectionMm2") == [
        ox.Literal("0.75", datatype=ox.NamedNode(XSD + "decimal"))
    ]
    assert fig3_triples.value(wire, "colour") == "BU"


def test_terminal_level_pin(fig3_triples: Triples) -> None:
    pin = BASE + "pin/X0030.1/1L%2B.2/a2"
    assert fig3_triples.value(pin, "pinName") == "1L+.2"
    assert fig3_triples.value(pin, "level") == "a2"
    assert fig3_triples.value(pin, "pinOf") == BASE + "component/X0030.1"
    wire = BASE + "wire/1L%2B"
    assert fig3_triples.value(wire, "fromPin") == pin
    assert fig3_triples.objects(wire, "lengthM") == []


def test_duplicate_wire_numbers_get_distinct_iris(fig3_triples: Triples) -> None:
    wires = sorted(w.value for w in fig3_triples.of_type("Wire") if "/wire/0V" in w.value)
    assert wires == [BASE + "wire/0V", BASE + "wire/0V~2"]
    assert [(fig3_triples.value(w, "wireNumber"), fig3_triples.value(w, "sourceLine")) for w in wires] == [
        ("0V", "9"),
        ("0V", "10"),
    ]
    # The daisy chain: the second wire starts where the first one ends.
    assert fig3_triples.value(wires[0], "toPin") == fig3_triples.value(wires[1], "fromPin")


def test_wri_example_maps_items_labels_and_models() -> None:
    data = read_source(EXAMPLE / "ids.wri", "ids.wri", "wri", BASE)
    triples = Triples(data.ntriples)
    # 117 items, the cabinet's root item ID000001 (=-1, no code): one component more, and a point
    # of each of the 9 ducts (a row of the duct's label without a code): no component more.
    assert data.report.records == 127
    assert len(triples.of_type("CadItem")) == 127
    assert len(triples.of_type("Component")) == 63
    item = BASE + "item/ID000041"
    assert triples.value(item, "cadId") == "ID000041"
    assert triples.value(item, "instanceOf") == BASE + "model/6013277"
    assert triples.value(item, "sourceLine") == "23"
    assert ox.NamedNode(item) in triples.objects(BASE + "component/X00005.2", "hasItem")
    assert triples.value(BASE + "label/Q0010", "rawLabel") == "=-Q0010"
    assert triples.objects(BASE + "item/ID000039", "instanceOf") == []
    assert triples.objects(BASE + "item/ID000001", "instanceOf") == []
    duct, point = BASE + "item/ID000091", BASE + "item/ID000231"
    assert triples.value(duct, "instanceOf") == BASE + "model/BOCCH.60X60G"
    assert triples.objects(point, "instanceOf") == []
    assert set(triples.objects(BASE + "component/CN1", "hasItem")) == {
        ox.NamedNode(duct),
        ox.NamedNode(point),
    }


HOSTILE_LABEL = 'K"1> <http://evil.example/x> . # \\u0022 {a|b}^`'
HOSTILE_CODE = 'C "7" > <y>'
NEWLINE_LABEL = "K\r\n2"


def test_hostile_label_cannot_break_the_triples(write) -> None:
    path = write(
        "odd ids.wri",
        f"ID000001\t=-{HOSTILE_LABEL}\t{HOSTILE_CODE}\r\n"
        f'ID000002\t"{NEWLINE_LABEL}"\t6013277\r\n'
        "ID000003\tF1500.1\t6503372\r\n",
    )
    data = read_source(path, "odd ids.wri", None, BASE)
    assert data.graph == BASE + "graph/odd%20ids.wri"
    triples = Triples(data.ntriples)
    assert len(triples.quads) == data.report.triples
    assert triples.value(data.graph, "sourcePath") == "odd ids.wri"

    component = BASE + "component/" + quote(HOSTILE_LABEL, safe="")
    assert triples.value(component, "label") == HOSTILE_LABEL
    label = BASE + "label/" + quote(HOSTILE_LABEL, safe="")
    assert triples.value(label, "rawLabel") == "=-" + HOSTILE_LABEL
    model = BASE + "model/" + quote(HOSTILE_CODE, safe="")
    assert triples.value(model, "commercialCode") == HOSTILE_CODE
    assert triples.value(BASE + "item/ID000001", "instanceOf") == model

    second = BASE + "component/" + quote(NEWLINE_LABEL, safe="")
    assert triples.value(second, "label") == NEWLINE_LABEL
    # Every label literal read back is one of the three, and the third item was not swallowed.
    labels = {triples.value(c, "label") for c in triples.of_type("Component")}
    assert labels == {HOSTILE_LABEL, NEWLINE_LABEL, "F1500.1"}
    assert len(triples.of_type("CadItem")) == 3


def test_hostile_wire_number_and_pin(write) -> None:
    text = (
        "Componente:pin\tComponente:pin\tNumero filo\tSezione\tColore\n"
        '-F1500.1:1"4>\t-Q1500.1:A1\tW 1>"2\t0.75\tB U\\\n'
        '-F1500.1:1"4>\t-Q1500.1:A2\tW 1>"2\t0.75\tBU\n'
    )
    data = read_source(write("odd.tsv", text), "odd.tsv", "connection-list", BASE)
    triples = Triples(data.ntriples)
    wire = BASE + "wire/" + quote('W 1>"2', safe="")
    assert triples.value(wire, "wireNumber") == 'W 1>"2'
    assert triples.value(wire, "colour") == "B U\\"
    assert triples.value(wire + "~2", "wireNumber") == 'W 1>"2'
    pin = BASE + "pin/F1500.1/" + quote('1"4>', safe="")
    assert triples.value(pin, "pinName") == '1"4>'
    assert triples.value(wire, "fromPin") == triples.value(wire + "~2", "fromPin") == pin


def test_read_source_sniffs_the_kind(write) -> None:
    path = write("sample.dat", FIG3.read_bytes())
    data = read_source(path, "sample.dat", None, BASE)
    assert data.report.kind == "connection-list"
    assert data.report.records == 20


def test_streamed_chunks_start_small_and_grow_and_lose_no_line() -> None:
    writer = TripleWriter("https://example.org/cell/")
    chunks: list[bytes] = []
    writer.stream_to(chunks.append)
    expected = []
    for i in range(700_000):
        line = f'<https://example.org/s/{i}> <https://example.org/p> "{i}" .\n'
        expected.append(line)
        writer.add_block(line, 1)
        writer.maybe_flush()
    rest = writer.data()
    sizes = [chunk.count(b"\n") for chunk in chunks]
    # The loader waits for a file's first chunk: it comes after 16,000 lines, then each
    # chunk doubles up to 250,000 lines.
    assert sizes == [16_000, 32_000, 64_000, 128_000, 250_000]
    assert writer.triples == 700_000
    assert b"".join([*chunks, rest]).decode() == "".join(expected)


@pytest.mark.parametrize(
    ("first", "rest"),
    [(("X1600",), ("pin", "3:a")), (("=-F1 500",), ("pin", "a/b", "screw")), (("route", "7"), ("2",))],
)
def test_an_iri_under_a_node_is_the_iri_minted_with_all_parts(
    first: tuple[str, ...], rest: tuple[str, ...]
) -> None:
    writer = TripleWriter(BASE)
    under = writer.under(writer.iri("derived", *first), *rest)
    assert under == writer.iri("derived", *first, *rest)
    # Each part stays one path segment, however it is spelt.
    assert under.count("/") == BASE.count("/") + len(first) + len(rest)
