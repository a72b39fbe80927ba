"""The KBL reader: the three Volkswagen samples counted against their own XML, values checked
by hand, a two-core cable with fixings and tape, and located errors for broken files."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest
from lxml import etree

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.harness.kbl import read_kbl
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
from cadkg.ingest.pipeline import read_source
from cadkg.registry import sniff_kind

KBL = Path(__file__).resolve().parents[1] / "data" / "kbl"
GETRIEBE = KBL / "kblxml_2.3sr-1_000971250_ltgs_getriebe_170718.kbl"
MOVO = KBL / "kblxml_2.3sr-1_000971619_ltgs_movo_170718.kbl"
VOBES = KBL / "vobes_sample_kbl24_mit_sicherungstraeger.kbl"
SAMPLE = KBL / "two-core-fixing-tape.kbl"

Write = Callable[[str, str | bytes], Path]


def of(records: list[HarnessRecord], kind: type) -> list:  # type: ignore[type-arg]
    return [r for r in records if isinstance(r, kind)]


def xpath_count(path: Path, expression: str) -> int:
    """Counted on the raw XML, independently of the reader."""
    return int(etree.parse(str(path)).xpath(f"count({expression})"))


# file, version, harness, connectors, component boxes, wires, nodes, segments, routings, cavities
COUNTS = [
    (GETRIEBE, "KBL 2.3 SR-1", "000971250", 2, 0, 1, 2, 1, 1, 2),
    (MOVO, "KBL 2.3 SR-1", "000971619", 20, 0, 18, 31, 30, 18, 31),
    (VOBES, "KBL 2.4", "LTG0011200", 14, 1, 10, 23, 22, 10, 46),
]


@pytest.mark.parametrize(
    ("path", "version", "harness", "connectors", "boxes", "wires", "nodes", "segments", "routed", "cavities"),
    COUNTS,
    ids=["getriebe", "movo", "vobes"],
)
def test_counts_match_the_xml(
    path: Path,
    version: str,
    harness: str,
    connectors: int,
    boxes: int,
    wires: int,
    nodes: int,
    segments: int,
    routed: int,
    cavities: int,
) -> None:
    records = read_kbl(path)
    head = of(records, Harness)
    assert [(h.ident, h.file_format) for h in head] == [(harness, version)]
    read_connectors = of(records, HarnessConnector)
    assert sum(c.kind == "connector" for c in read_connectors) == connectors
    assert sum(c.kind == "component box" for c in read_connectors) == boxes
    assert len(of(records, HarnessWire)) == wires
    assert len(of(records, HarnessNode)) == nodes
    assert len(of(records, HarnessSegment)) == segments
    assert sum(bool(w.route) for w in of(records, HarnessWire)) == routed
    assert sum(len(c.cavities) for c in read_connectors) == cavities
    # The same numbers, counted with XPath on the file itself.
    assert xpath_count(path, "/*/Harness/Connector_occurrence") == connectors
    assert xpath_count(path, "/*/Harness/Component_box_occurrence") == boxes
    assert xpath_count(path, "/*/Harness/General_wire_occurrence[Wire_number] | //Core_occurrence") == wires
    assert xpath_count(path, "/*/Node") == nodes
    assert xpath_count(path, "/*/Segment") == segments
    assert xpath_count(path, "/*/Routing") == routed
    occurrence_cavities = (
        "/*/Harness/Connector_occurrence/Slots/Cavities"
        " | /*/Harness/Component_box_occurrence/Component_box_connectors/Slots/Cavities"
    )
    assert xpath_count(path, occurrence_cavities) == cavities


@pytest.mark.parametrize("path", [GETRIEBE, MOVO, VOBES, SAMPLE], ids=lambda p: p.stem[:24])
def test_every_route_walks_from_one_end_to_the_other(path: Path) -> None:
    """Connectors sit on the nodes the KBL names, and each routing is a walk between a wire's ends."""
    records = read_kbl(path)
    segments = {s.ident: s for s in of(records, HarnessSegment)}
    at: dict[str, set[str]] = {}
    for node in of(records, HarnessNode):
        for connector in node.connectors:
            at.setdefault(connector, set()).add(node.ident)
    assert set(at) == {c.ident for c in of(records, HarnessConnector)}
    for wire in of(records, HarnessWire):
        assert len(wire.ends) == 2 and wire.route
        reached = set()
        for start in at[wire.ends[0].connector]:
            here: str | None = start
            for name in wire.route:
                segment = segments[name]
                here = (
                    segment.end if here == segment.start else segment.start if here == segment.end else None
                )
            reached.add(here)
        assert reached & at[wire.ends[1].connector], wire.ident


def test_getriebe_by_hand() -> None:
    """Values read off the 2.3 SR-1 gearbox harness (lengths in mm there, metres here)."""
    records = read_kbl(GETRIEBE)
    assert of(records, Harness) == [Harness("000971250", "LTGS Getriebe", "KBL 2.3 SR-1", 122)]
    assert [(c.ident, c.cavities, c.line) for c in of(records, HarnessConnector)] == [
        ("XA.14.1", ("1",), 145),
        ("XB.66.1", ("1",), 161),
    ]
    # The nodes reference the ring terminals (special terminal occurrences) the connectors carry.
    assert [(n.ident, n.label, n.connectors) for n in of(records, HarnessNode)] == [
        ("Node_1", "PNID1", ("XA.14.1",)),
        ("Node_2", "PNID2", ("XB.66.1",)),
    ]
    (wire,) = of(records, HarnessWire)
    assert wire.ends == (WireEnd("XA.14.1", "1"), WireEnd("XB.66.1", "1"))
    assert (wire.ident, wire.route, wire.colour, wire.cable) == ("1", ("Segment_1",), "br", None)
    assert wire.section_mm2 == Decimal(25)
    assert wire.length_m == Decimal("0.62508")  # 625.08 mm
    assert wire.diameter_m == pytest.approx(0.0098)
    assert wire.signal == "M.31.SZS1033.MI14111B11MI66111C1"
    (segment,) = of(records, HarnessSegment)
    assert (segment.start, segment.end, segment.line) == ("Node_1", "Node_2", 255)
    assert segment.length_m == Decimal("0.625086846")
    assert segment.section_mm2 == Decimal("28.274334")
    assert segment.diameter_m == pytest.approx(0.006)  # a circle of 28.274334 mm² is 6 mm across


def test_movo_splice_and_shared_contact() -> None:
    records = read_kbl(MOVO)
    wires = {w.ident: w for w in of(records, HarnessWire)}
    assert wires["1"].ends == (WireEnd("D25", "1"), WireEnd("XA.F26.1", "1"))
    assert wires["1"].route == ("Segment_20", "Segment_18", "Segment_7", "Segment_24")
    assert (wires["1"].colour, wires["1"].section_mm2) == ("sw/bl", Decimal("0.5"))
    # D25 is a splice ("Plusverbindung"): one contact point joins four wires, which share its cavity.
    shared = [w.ident for w in wires.values() if WireEnd("D25", "1") in w.ends]
    assert shared == ["1", "2", "3", "4"]
    assert xpath_count(MOVO, '/*/Harness/Connection/Extremities[Contact_point="id_372_2"]') == 4
    kinds = {n.ident: n.connectors for n in of(records, HarnessNode)}
    assert sum(1 for c in kinds.values() if not c) == 11  # branch points


def test_component_box_cavities_are_named_by_box_connector() -> None:
    records = read_kbl(VOBES)
    box = next(c for c in of(records, HarnessConnector) if c.kind == "component box")
    assert box.ident == "XJ.SR1.1"
    assert box.cavities[:3] == ("A/1", "B/1A", "C/1A")
    assert len(box.cavities) == 14
    ends = {e for w in of(records, HarnessWire) for e in w.ends if e.connector == "XJ.SR1.1"}
    assert ends == {WireEnd("XJ.SR1.1", "J/4")}


def test_two_core_cable_fixings_and_tape() -> None:
    """Multi-core cable, physical length over virtual, section preference, fixings, protections."""
    records = read_kbl(SAMPLE)
    assert of(records, HarnessCable) == [HarnessCable("T-1", "K1", Decimal("1.2"), 0.0042, 153)]
    wires = {w.ident: w for w in of(records, HarnessWire)}
    assert wires["101"] == HarnessWire(
        harness="T-1",
        ident="101",
        label="101",
        ends=(WireEnd("A", "1"), WireEnd("B", "1")),
        route=("s1", "s2"),
        section_mm2=Decimal("0.35"),
        colour="rt",
        length_m=Decimal("1.21"),
        diameter_m=None,
        cable="K1",
        signal="S+",
        line=163,
    )
    # Extremities are ordered by their position on the wire, not by file order.
    assert wires["102"].ends == (WireEnd("B", "2"), WireEnd("A", "2"))
    segments = {s.ident: s for s in of(records, HarnessSegment)}
    assert segments["s1"].length_m == Decimal("0.4")  # physical 400 mm beats virtual 390 mm
    assert segments["s1"].section_mm2 == Decimal("12.566371")  # calculated beats reserved
    assert segments["s1"].diameter_m == pytest.approx(0.004)
    assert segments["s2"].diameter_m is None  # a noncircular bundle has no diameter
    assert of(records, HarnessFixing) == [
        HarnessFixing("T-1", "F1", "clip on the segment", (), ("s1",), 144),
        HarnessFixing("T-1", "F2", None, ("n2",), (), 149),
    ]
    assert of(records, HarnessProtection) == [
        HarnessProtection("T-1", "P1", "tape", ("s1", "s2"), Decimal("0.3"), 186)
    ]
    nodes = {n.ident: n.connectors for n in of(records, HarnessNode)}
    assert nodes == {"n1": ("A",), "n2": (), "n3": ("B",)}  # n3 names B by a cavity (KBL 2.4)


@pytest.mark.parametrize(
    ("path", "schema"),
    [(GETRIEBE, "kbl23_sr1.xsd"), (MOVO, "kbl23_sr1.xsd"), (VOBES, "kbl24.xsd"), (SAMPLE, "kbl24.xsd")],
    ids=["getriebe", "movo", "vobes", "sample"],
)
def test_test_files_are_valid_kbl(path: Path, schema: str) -> None:
    xsd = etree.XMLSchema(etree.parse(str(KBL / "schema" / schema)))
    assert xsd.validate(etree.parse(str(path))), xsd.error_log


def test_registry_knows_kbl_by_suffix_and_content(tmp_path: Path) -> None:
    assert sniff_kind(GETRIEBE) == "kbl"
    odd = tmp_path / "harness.data"
    odd.write_bytes(GETRIEBE.read_bytes())
    assert sniff_kind(odd) == "kbl"


# -- bad input ------------------------------------------------------------------------------------------


def broken(write: Write, old: str, new: str, source: Path = GETRIEBE) -> Path:
    text = source.read_text(encoding="utf-8")
    assert text.count(old) == 1, old
    return write("broken.kbl", text.replace(old, new))


def error_of(path: Path) -> IngestError:
    with pytest.raises(IngestError) as caught:
        read_kbl(path)
    return caught.value


def test_wire_to_a_missing_cavity(write: Write) -> None:
    path = broken(
        write,
        "<Contacted_cavity>id_370_1</Contacted_cavity>",
        "<Contacted_cavity>id_370_9</Contacted_cavity>",
    )
    err = error_of(path)
    assert (err.line, err.found) == (152, "id_370_9")
    assert "<Contacted_cavity> of <Contact_points> names nothing in the file" in str(err)
    assert "expected the id of a cavity occurrence of a connector" in str(err)
    assert str(err).startswith(f"{path}:152: ")


def test_contact_in_a_housing_cavity_instead_of_an_occurrence(write: Write) -> None:
    path = broken(
        write,
        "<Contacted_cavity>id_370_1</Contacted_cavity>",
        "<Contacted_cavity>id_370_0</Contacted_cavity>",
    )
    err = error_of(path)
    assert (err.line, err.found) == (152, "id_370_0")
    assert "names a <Cavities>" in str(err)


@pytest.mark.parametrize(
    ("old", "new", "line", "found", "reason"),
    [
        (
            "<Wire>id_350_0</Wire>",
            "<Wire>id_350_7</Wire>",
            135,
            "id_350_7",
            "<Wire> of <Connection> names nothing",
        ),
        (
            "<End_node>Node_2</End_node>",
            "<End_node>Node_9</End_node>",
            268,
            "Node_9",
            "<End_node> of <Segment>",
        ),
        (
            "<Routed_wire>id_314_0</Routed_wire>",
            "<Routed_wire>id_350_0</Routed_wire>",
            252,
            "id_350_0",
            "names a",
        ),
        (
            "<Segments>Segment_1</Segments>",
            "<Segments>Segment_1 Segment_2</Segments>",
            253,
            "Segment_2",
            "<Segments>",
        ),
        (
            "<Value_component>625.086846</Value_component>",
            "<Value_component>6,25</Value_component>",
            265,
            "6,25",
            "bad number",
        ),
        ('id="id_346_1"', 'id="id_346_2"', 285, "id_346_2", "XML id given twice"),
        (
            "<Value_component>625.086846</Value_component>",
            "<Value_component>1e999999</Value_component>",
            265,
            "1e999999",
            "bad number",
        ),
    ],
    ids=[
        "connection-to-missing-wire",
        "segment-to-missing-node",
        "routing-a-wire",
        "missing-segment",
        "comma",
        "id-twice",
        "huge-exponent",
    ],
)
def test_located_errors(write: Write, old: str, new: str, line: int, found: str, reason: str) -> None:
    err = error_of(broken(write, old, new))
    assert (err.line, err.found) == (line, found)
    assert reason in str(err)


def test_length_in_grams(write: Write) -> None:
    old = "<Unit_component>id_346_1</Unit_component>\n\t\t\t<Value_component>625.086846</Value_component>"
    err = error_of(broken(write, old, old.replace("id_346_1", "id_346_2")))
    assert err.line == 263
    assert "<Virtual_length> is not given in a unit of length" in str(err)
    assert err.found == "gram"


@pytest.mark.parametrize("version", ["2.5", "2.3", "1.0", ""])
def test_unknown_version(write: Write, version: str) -> None:
    err = error_of(broken(write, 'version_id="2.3 SR-1"', f'version_id="{version}"'))
    assert err.line == 6
    assert err.found == (version or "no version_id")
    assert "unknown KBL version" in str(err)
    assert "expected version_id 2.3 SR-1 or 2.4 or 2.4 SR-1" in str(err)


def test_version_spelling_is_forgiven(write: Write) -> None:
    records = read_kbl(broken(write, 'version_id="2.3 SR-1"', 'version_id="2.3 sr1"'))
    assert of(records, Harness)[0].file_format == "KBL 2.3 SR-1"


def test_not_kbl(write: Write) -> None:
    err = error_of(write("other.kbl", '<?xml version="1.0"?>\n<data><code name="x"/></data>\n'))
    assert (err.line, err.found) == (2, "<data>")
    assert "not a KBL container" in str(err)


def test_no_harness(write: Write) -> None:
    path = write(
        "empty.kbl",
        '<kbl:KBL_container xmlns:kbl="http://www.prostep.org/Car_electric_container/KBL2.3/KBLSchema"'
        ' id="C" version_id="2.4"/>\n',
    )
    assert "no <Harness>" in str(error_of(path))


def test_entities_are_refused(write: Write) -> None:
    head = GETRIEBE.read_text(encoding="utf-8").split("\n", 1)
    path = write("entity.kbl", head[0] + '\n<!DOCTYPE x [<!ENTITY a "aaaa">]>\n' + head[1])
    err = error_of(path)
    assert err.line == 2
    assert "DOCTYPE" in str(err)


def test_malformed_xml(write: Write) -> None:
    err = error_of(broken(write, "</Segment>", "</Segmnt>"))
    assert err.line == 281
    assert "malformed XML" in str(err)


@pytest.mark.parametrize(("content", "reason"), [(b"", "empty"), (b"KBL\x00\x01", "binary")])
def test_empty_and_binary(write: Write, content: bytes, reason: str) -> None:
    assert reason in str(error_of(write("x.kbl", content)))


def test_wire_number_twice_is_told_apart(write: Write) -> None:
    text = MOVO.read_text(encoding="utf-8")
    assert text.count("<Wire_number>2</Wire_number>") == 1
    path = write("twice.kbl", text.replace("<Wire_number>2</Wire_number>", "<Wire_number>1</Wire_number>"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        records = read_kbl(path)
    wires = [w for w in of(records, HarnessWire) if w.label == "1"]
    assert [w.ident for w in wires] == ["1", "1~2"]
    (warning,) = [w.message for w in caught if isinstance(w.message, IngestWarning)]
    assert warning.found == "1" and warning.line == wires[1].line


def test_a_splice_along_a_wire_maps_to_an_intermediate_pin(write: Write) -> None:
    """A connection with three extremities: ends by position, the middle one an intermediate pin."""
    middle = (
        '<Extremities id="e9">\n\t\t\t\t<Position_on_wire>0.5</Position_on_wire>\n'
        "\t\t\t\t<Contact_point>cpA2</Contact_point>\n\t\t\t</Extremities>\n\t\t\t"
    )
    path = broken(write, '<Extremities id="e2">', middle + '<Extremities id="e2">', SAMPLE)
    wire = next(w for w in of(read_kbl(path), HarnessWire) if w.ident == "101")
    assert wire.ends == (WireEnd("A", "1"), WireEnd("A", "2"), WireEnd("B", "1"))
    data = read_source(path, "splice.kbl", "kbl", "https://example.org/c/").ntriples.decode()
    base, ck = "https://example.org/c/", "https://w3id.org/cadkg#"
    assert f"<{base}wire/T-1/101> <{ck}fromPin> <{base}contact/T-1/A/1> ." in data
    assert f"<{base}wire/T-1/101> <{ck}intermediatePin> <{base}contact/T-1/A/2> ." in data
    assert f"<{base}wire/T-1/101> <{ck}toPin> <{base}contact/T-1/B/1> ." in data
    assert f"<{base}connector/T-1/B> <{ck}atNode> <{base}node/T-1/n3> ." in data
