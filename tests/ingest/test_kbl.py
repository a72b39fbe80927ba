"""The KBL reader: every Volkswagen sample of the prostep ivip repository counted against its own
XML, values checked by hand, a two-core cable with fixings and tape, and located errors for
broken files. Modules, variants and geometry: tests/ingest/test_kbl_modules.py."""

from __future__ import annotations

import warnings
from collections import Counter
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest
from lxml import etree

from cadkg.errors import IngestError
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
    WireRoute,
)
from cadkg.mapping.pipeline import read_source
from cadkg.registry import sniff_kind

KBL = Path(__file__).resolve().parents[1] / "data" / "kbl"
GETRIEBE = KBL / "kblxml_2.3sr-1_000971250_ltgs_getriebe_170718.kbl"
MOVO = KBL / "kblxml_2.3sr-1_000971619_ltgs_movo_170718.kbl"
VOBES = KBL / "vobes_sample_kbl24_mit_sicherungstraeger.kbl"
MODULAR = KBL / "kblxml_2.4sr-1_tab016120_modulare_ltgs._160718.kbl"
SAMPLE = KBL / "two-core-fixing-tape.kbl"
OWN_MODULAR = KBL / "modular-three-modules.kbl"
SAMPLES = sorted(p for p in KBL.glob("*.kbl") if p.name.startswith(("kblxml", "vobes")))

Write = Callable[[str, str | bytes], Path]


def of(records: list[HarnessRecord], kind: type) -> list:  # type: ignore[type-arg]
    return [r for r in records if isinstance(r, kind)]


def quietly(path: Path) -> list[HarnessRecord]:
    """The records of ``path``; the samples' centre curve warnings are checked elsewhere."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_kbl(path)


def xpath_count(path: Path, expression: str) -> int:
    """Counted on the raw XML, independently of the reader."""
    return int(etree.parse(str(path)).xpath(f"count({expression})"))


H = "/*/Harness"
# What the reader must find, each as an XPath count on the file: the harness's own occurrences
# (not the placeholders inside an Assembly_part), wires and cores, and the topology.
XPATHS = {
    "connectors": f"{H}/Connector_occurrence",
    "boxes": f"{H}/Component_box_occurrence",
    "wires": f"{H}/General_wire_occurrence[Wire_number] | {H}/General_wire_occurrence/Core_occurrence",
    "cables": f"{H}/General_wire_occurrence[Special_wire_id]",
    "nodes": "/*/Node",
    "segments": "/*/Segment",
    "routed": "/*/Routing[normalize-space(Segments)]",
    "cavities": f"{H}/Connector_occurrence/Slots/Cavities"
    f" | {H}/Component_box_occurrence/Component_box_connectors/Slots/Cavities",
    "fixings": f"{H}/Fixing_occurrence",
    "protections": f"{H}/Wire_protection_occurrence",
    "modules": f"{H}/Module",
    "positions": "/*/Node[Cartesian_point]",
}


def counted(records: list[HarnessRecord]) -> dict[str, int]:
    connectors = of(records, HarnessConnector)
    return {
        "connectors": sum(c.kind == "connector" for c in connectors),
        "boxes": sum(c.kind == "component box" for c in connectors),
        "wires": len(of(records, HarnessWire)),
        "cables": len(of(records, HarnessCable)),
        "nodes": len(of(records, HarnessNode)),
        "segments": len(of(records, HarnessSegment)),
        "routed": sum(bool(w.route) for w in of(records, HarnessWire)),
        "cavities": sum(len(c.cavities) for c in connectors),
        "fixings": len(of(records, HarnessFixing)),
        "protections": len(of(records, HarnessProtection)),
        "modules": sum(1 for r in records if type(r).__name__ == "HarnessModule" and r.kind != "option code"),
        "positions": sum(n.position is not None for n in of(records, HarnessNode)),
    }


@pytest.mark.parametrize("path", [*SAMPLES, SAMPLE, OWN_MODULAR], ids=lambda p: p.stem[:32])
def test_counts_match_the_xml(path: Path) -> None:
    """Every sample reads, and what it holds is what an XPath count of its XML says."""
    records = quietly(path)
    (head,) = of(records, Harness)
    root = etree.parse(str(path)).getroot()
    assert head.ident == root.findtext("Harness/Part_number")
    assert head.file_format == f"KBL {root.get('version_id')}"
    assert counted(records) == {name: xpath_count(path, expression) for name, expression in XPATHS.items()}


# harness, connectors, boxes, wires (of them cores), cables, nodes, segments, fixings, protections, modules
KNOWN = {
    "kblxml_2.3sr-1_000971228_ltgs_batterie_plus_170718": ("000971228", 2, 0, 1, 0, 0, 2, 1, 0, 0, 1),
    "kblxml_2.3sr-1_000971230_ltgs_generator_170718": ("000971230", 3, 0, 3, 0, 0, 4, 3, 1, 3, 1),
    "kblxml_2.3sr-1_000971235_ltgs_batt._minus_170718": ("000971235", 2, 0, 1, 0, 0, 2, 1, 0, 0, 1),
    "kblxml_2.3sr-1_000971250_ltgs_getriebe_170718": ("000971250", 2, 0, 1, 0, 0, 2, 1, 0, 0, 1),
    "kblxml_2.3sr-1_000971619_ltgs_movo_170718": ("000971619", 20, 0, 18, 0, 0, 31, 30, 0, 0, 1),
    "kblxml_2.4sr-1_tab016120_modulare_ltgs._160718": (
        "TAB016120",
        141,
        5,
        254,
        70,
        32,
        184,
        183,
        14,
        105,
        34,
    ),
    "vobes_sample_kbl24_mit_sicherungstraeger": ("LTG0011200", 14, 1, 10, 0, 0, 23, 22, 0, 0, 1),
}


def test_every_sample_of_the_repository_is_here_and_counted_by_hand() -> None:
    """The figures of the samples as the prostep ivip repository's files hold them."""
    assert {p.stem for p in SAMPLES} == set(KNOWN)
    for path in SAMPLES:
        records = quietly(path)
        cores = sum(w.cable is not None for w in of(records, HarnessWire))
        numbers = counted(records)
        assert (
            of(records, Harness)[0].ident,
            numbers["connectors"],
            numbers["boxes"],
            numbers["wires"],
            cores,
            numbers["cables"],
            numbers["nodes"],
            numbers["segments"],
            numbers["fixings"],
            numbers["protections"],
            numbers["modules"],
        ) == KNOWN[path.stem], path.name


def test_the_modular_sample_is_keyed_by_xml_id() -> None:
    """Its connector designations repeat across alternative modules; each occurrence is kept."""
    records = quietly(MODULAR)
    connectors = of(records, HarnessConnector)
    assert len(connectors) == 146 == len({c.ident for c in connectors})
    repeated = {label: n for label, n in Counter(c.label for c in connectors).items() if n > 1}
    assert repeated == {
        "XA.G46.1": 3,
        "XA.G47.1": 3,
        "XA.N336.1": 3,
        "XA.V282.1": 3,
        "XA.G233.1": 2,
        "XA.G44.1": 2,
        "XA.G45.1": 2,
        "XA.N337.1": 2,
        "XA.V283.1": 2,
    }
    assert [c.ident for c in connectors if c.label == "XA.G46.1"] == ["id_316_35", "id_316_307", "id_316_310"]
    # The 27 placeholder occurrences inside the Assembly_parts are not read.
    assert xpath_count(MODULAR, "//Connector_occurrence") == 168
    # Specified wires and cables (of the ABS assemblies) are read like the others.
    wires = {w.ident: w for w in of(records, HarnessWire)}
    specified = etree.parse(str(MODULAR)).xpath(
        f"{H}/General_wire_occurrence[contains(@xsi:type, 'Specified')]",
        namespaces={"xsi": "http://www.w3.org/2001/XMLSchema-instance"},
    )
    assert len(specified) == 25
    assert all(s.get("id") in wires or s.findtext("Special_wire_id") for s in specified)
    # The component boxes sit at their nodes through their box connectors (KBL 2.4 SR-1).
    boxes = {c.ident for c in connectors if c.kind == "component box"}
    placed = {c for n in of(records, HarnessNode) for c in n.connectors}
    assert boxes <= placed and len(boxes) == 5
    assert {n.label for n in of(records, HarnessNode) if set(n.connectors) & boxes} == {
        f"PNID{n}" for n in range(186, 191)
    }


@pytest.mark.parametrize("path", [*SAMPLES, SAMPLE, OWN_MODULAR], ids=lambda p: p.stem[:32])
def test_every_route_walks_from_one_end_to_the_other(path: Path) -> None:
    """Connectors sit on the nodes the KBL names, and each routing is a walk from the node of a
    wire's first end to that of its last, in the order the route is given."""
    records = quietly(path)
    segments = {s.ident: s for s in of(records, HarnessSegment)}
    at: dict[str, set[str]] = {}
    for node in of(records, HarnessNode):
        for connector in node.connectors:
            at.setdefault(connector, set()).add(node.ident)
    walked = 0
    for wire in of(records, HarnessWire):
        if not wire.route or not wire.ends:
            continue
        here: str | None = next(iter(at[wire.ends[0].connector]))
        for name in wire.route:
            segment = segments[name]
            here = segment.end if here == segment.start else segment.start if here == segment.end else None
        assert here in at[wire.ends[-1].connector], wire.ident
        walked += 1
    assert walked == xpath_count(path, XPATHS["routed"])


def test_getriebe_by_hand() -> None:
    """Values read off the 2.3 SR-1 gearbox harness (lengths in mm there, metres here)."""
    records = read_kbl(GETRIEBE)
    assert of(records, Harness) == [Harness("000971250", "LTGS Getriebe", "KBL 2.3 SR-1", 122)]
    # Keyed by XML id, named by designation.
    assert [(c.ident, c.label, c.cavities, c.line) for c in of(records, HarnessConnector)] == [
        ("id_316_0", "XA.14.1", ("1",), 145),
        ("id_316_1", "XB.66.1", ("1",), 161),
    ]
    # The nodes reference the ring terminals (special terminal occurrences) the connectors carry;
    # Node_1's point Cartesian_point_10 is (2495.476064, 153.084114, 284.332879) mm, x rearward
    # and y to the right: (-2.495476064, -0.153084114, 0.284332879) m in REP 103.
    assert [(n.ident, n.label, n.connectors, n.position) for n in of(records, HarnessNode)] == [
        ("Node_1", "PNID1", ("id_316_0",), (-2.495476064, -0.153084114, 0.284332879)),
        ("Node_2", "PNID2", ("id_316_1",), (-1.93888567, -0.263845793, 0.053849923)),
    ]
    point = etree.parse(str(GETRIEBE)).xpath(
        "/*/Cartesian_point[@id='Cartesian_point_10']/Coordinates/text()"
    )
    assert [float(c) for c in point] == [2495.476064, 153.084114, 284.332879]
    (wire,) = of(records, HarnessWire)
    assert wire.ends == (WireEnd("id_316_0", "1"), WireEnd("id_316_1", "1"))
    assert (wire.ident, wire.label, wire.colour, wire.cable) == ("id_350_0", "1", "br", None)
    assert wire.routes == (WireRoute("id_338_0", ("Segment_1",), ("id_331_0",)),)
    assert wire.section_mm2 == Decimal(25)
    assert wire.length_m == Decimal("0.62508")  # 625.08 mm
    assert wire.diameter_m == pytest.approx(0.0098)
    assert wire.signal == "M.31.SZS1033.MI14111B11MI66111C1"
    (segment,) = of(records, HarnessSegment)
    assert (segment.start, segment.end, segment.line, segment.length_source) == (
        "Node_1",
        "Node_2",
        255,
        "virtual",
    )
    assert segment.length_m == Decimal("0.625086846")
    assert segment.section_mm2 == Decimal("28.274334")
    assert segment.diameter_m == pytest.approx(0.006)  # a circle of 28.274334 mm² is 6 mm across


def test_movo_splice_and_shared_contact() -> None:
    records = quietly(MOVO)
    wires = {w.label: w for w in of(records, HarnessWire)}
    designation = {c.ident: c.label for c in of(records, HarnessConnector)}
    first = wires["1"]
    assert [(designation[e.connector], e.cavity) for e in first.ends] == [("D25", "1"), ("XA.F26.1", "1")]
    assert first.route == ("Segment_20", "Segment_18", "Segment_7", "Segment_24")
    assert (first.colour, first.section_mm2) == ("sw/bl", Decimal("0.5"))
    # D25 is a splice ("Plusverbindung"): one contact point joins four wires, which share its cavity.
    shared = [w.label for w in wires.values() if WireEnd("id_316_18", "1") in w.ends]
    assert shared == ["1", "2", "3", "4"]
    assert designation["id_316_18"] == "D25"
    assert xpath_count(MOVO, '/*/Harness/Connection/Extremities[Contact_point="id_372_2"]') == 4
    kinds = {n.ident: n.connectors for n in of(records, HarnessNode)}
    assert sum(1 for c in kinds.values() if not c) == 11  # branch points


def test_component_box_cavities_are_named_by_box_connector() -> None:
    records = read_kbl(VOBES)
    box = next(c for c in of(records, HarnessConnector) if c.kind == "component box")
    assert (box.ident, box.label) == ("id_417_0", "XJ.SR1.1")
    assert box.cavities[:3] == ("A/1", "B/1A", "C/1A")
    assert len(box.cavities) == 14
    ends = {e for w in of(records, HarnessWire) for e in w.ends if e.connector == box.ident}
    assert ends == {WireEnd(box.ident, "J/4")}


def test_two_core_cable_fixings_and_tape() -> None:
    """Multi-core cable, physical length over virtual, section preference, fixings, protections."""
    records = read_kbl(SAMPLE)
    assert of(records, HarnessCable) == [HarnessCable("T-1", "sw", "K1", Decimal("1.2"), 0.0042, 153)]
    wires = {w.label: w for w in of(records, HarnessWire)}
    assert wires["101"] == HarnessWire(
        harness="T-1",
        ident="co1",
        label="101",
        ends=(WireEnd("A", "1"), WireEnd("B", "1")),
        routes=(WireRoute("r1", ("s1", "s2")),),
        section_mm2=Decimal("0.35"),
        colour="rt",
        length_m=Decimal("1.21"),
        diameter_m=None,
        cable="sw",
        signal="S+",
        line=163,
    )
    # Extremities are ordered by their position on the wire, not by file order, and the route
    # is walked from the first end (B here): the file lists s2 s1.
    assert wires["102"].ends == (WireEnd("B", "2"), WireEnd("A", "2"))
    assert wires["102"].route == ("s2", "s1")
    segments = {s.ident: s for s in of(records, HarnessSegment)}
    assert segments["s1"].length_m == Decimal("0.4")  # physical 400 mm beats virtual 390 mm
    assert segments["s1"].length_source == "physical"
    assert segments["s1"].section_mm2 == Decimal("12.566371")  # calculated beats reserved
    assert segments["s1"].diameter_m == pytest.approx(0.004)
    assert segments["s2"].diameter_m is None  # a noncircular bundle has no diameter
    assert of(records, HarnessFixing) == [
        HarnessFixing("T-1", "fo1", "F1", "clip on the segment", (), ("s1",), 144),
        HarnessFixing("T-1", "fo2", "F2", None, ("n2",), (), 149),
    ]
    assert of(records, HarnessProtection) == [
        HarnessProtection("T-1", "wp", "P1", "tape", ("s1", "s2"), Decimal("0.3"), 186)
    ]
    nodes = {n.ident: n.connectors for n in of(records, HarnessNode)}
    assert nodes == {"n1": ("A",), "n2": (), "n3": ("B",)}  # n3 names B by a cavity (KBL 2.4)


@pytest.mark.parametrize(
    ("path", "schema"),
    [
        *((p, "kbl23_sr1.xsd") for p in SAMPLES if "2.3sr-1" in p.name),
        (VOBES, "kbl24.xsd"),
        (MODULAR, "kbl24_sr1.xsd"),
        (SAMPLE, "kbl24.xsd"),
        (OWN_MODULAR, "kbl24_sr1.xsd"),
    ],
    ids=lambda p: p.stem[:24] if isinstance(p, Path) else p,
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


def test_a_designation_or_wire_number_may_repeat(write: Write) -> None:
    """Things are told apart by their XML ids; designations and wire numbers are only labels."""
    text = MOVO.read_text(encoding="utf-8")
    assert text.count("<Wire_number>2</Wire_number>") == 1 and text.count("<Id>XA.N.1</Id>") == 1
    text = text.replace("<Wire_number>2</Wire_number>", "<Wire_number>1</Wire_number>")
    path = write("twice.kbl", text.replace("<Id>XA.N.1</Id>", "<Id>XA.G7.1</Id>"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", message=".*centre curve")
        records = read_kbl(path)
    assert [w.ident for w in of(records, HarnessWire) if w.label == "1"] == ["id_350_0", "id_350_1"]
    assert [c.ident for c in of(records, HarnessConnector) if c.label == "XA.G7.1"] == [
        "id_316_6",
        "id_316_4",
    ]


def test_a_splice_along_a_wire_maps_to_an_intermediate_pin(write: Write) -> None:
    """A connection with three extremities: ends by position, the middle one an intermediate pin."""
    middle = (
        '<Extremities id="e9">\n\t\t\t\t<Position_on_wire>0.5</Position_on_wire>\n'
        "\t\t\t\t<Contact_point>cpA2</Contact_point>\n\t\t\t</Extremities>\n\t\t\t"
    )
    path = broken(write, '<Extremities id="e2">', middle + '<Extremities id="e2">', SAMPLE)
    wire = next(w for w in of(read_kbl(path), HarnessWire) if w.label == "101")
    assert wire.ends == (WireEnd("A", "1"), WireEnd("A", "2"), WireEnd("B", "1"))
    data = read_source(path, "splice.kbl", "kbl", "https://example.org/c/").ntriples.decode()
    base, ck = "https://example.org/c/", "https://w3id.org/cadkg#"
    assert f"<{base}wire/T-1/co1> <{ck}fromPin> <{base}contact/T-1/A/1> ." in data
    assert f"<{base}wire/T-1/co1> <{ck}intermediatePin> <{base}contact/T-1/A/2> ." in data
    assert f"<{base}wire/T-1/co1> <{ck}toPin> <{base}contact/T-1/B/1> ." in data
    assert f"<{base}connector/T-1/B> <{ck}atNode> <{base}node/T-1/n3> ." in data
