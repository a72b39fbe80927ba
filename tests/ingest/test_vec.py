"""The VEC reader: the routing example of the VEC guidelines (2.1: a loop, a wire routed per
variant, a path through one segment twice), the multi-core snippet (no harness), two files of
our own (1.1 with B-spline geometry, 2.0 with modules, NURBS and a multi-core cable), and
located errors for broken files."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest
from lxml import etree

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.harness.records import (
    Harness,
    HarnessCable,
    HarnessConnector,
    HarnessFixing,
    HarnessModule,
    HarnessNode,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    WireEnd,
    WireRoute,
    in_variant,
)
from cadkg.ingest.harness.vec import read_vec
from cadkg.registry import sniff_kind
from tests.ingest.test_kbl import of

VEC = Path(__file__).resolve().parents[1] / "data" / "vec"
ROUTING = VEC / "routing-examples.vec"
SNIPPET = VEC / "multicore-snippet.xml"
OWN_11 = VEC / "harness-1.1.vec"
OWN_20 = VEC / "modules-2.0.vec"
NS = {"vec": "http://www.prostep.org/ecad-if/2011/vec", "xsi": "http://www.w3.org/2001/XMLSchema-instance"}

Write = Callable[[str, str | bytes], Path]


def xpath_count(path: Path, expression: str) -> int:
    return int(etree.parse(str(path)).xpath(f"count({expression})", namespaces=NS))


def typed(kind: str) -> str:
    return f"//*[@xsi:type='vec:{kind}']"


@pytest.mark.parametrize("path", [ROUTING, OWN_11, OWN_20], ids=lambda p: p.stem)
def test_counts_match_the_xml(path: Path) -> None:
    records = read_vec(path)
    wires = of(records, HarnessWire)
    assert len(of(records, Harness)) == xpath_count(
        path, "//DocumentVersion[DocumentType='HarnessDescription']"
    )
    assert len(of(records, HarnessConnector)) == xpath_count(path, typed("ConnectorHousingRole"))
    assert sum(len(c.cavities) for c in of(records, HarnessConnector)) == xpath_count(
        path, f"{typed('ConnectorHousingRole')}/SlotReference/CavityReference"
    )
    assert len(wires) == xpath_count(path, f"{typed('WireRole')}/WireElementReference[WireEnd]")
    assert len(of(records, HarnessNode)) == xpath_count(path, "//TopologyNode")
    assert len(of(records, HarnessSegment)) == xpath_count(path, "//TopologySegment")
    routed_by_wires = xpath_count(
        path, f"//Routing[RoutedElement = {typed('WireRole')}/WireElementReference[WireEnd]/@id]"
    )
    assert sum(len(w.routes) for w in wires) >= routed_by_wires
    assert len(of(records, HarnessFixing)) == xpath_count(path, typed("FixingRole"))
    assert len(of(records, HarnessProtection)) == xpath_count(path, typed("WireProtectionRole"))


def test_routing_example_by_hand() -> None:
    """The VEC guideline's example: its records as the guideline describes the harness."""
    records = read_vec(ROUTING)
    assert of(records, Harness) == [Harness("HARNESS-1", "version a", "VEC 2.1.0", 71)]
    assert [(m.ident, m.label, m.kind, m.control) for m in of(records, HarnessModule)] == [
        ("VariantConfiguration_00018", "RL", "variant configuration", "RL"),
        ("VariantConfiguration_00019", "LL", "variant configuration", "LL"),
    ]
    connectors = {c.label: c for c in of(records, HarnessConnector)}
    assert {name: c.cavities for name, c in connectors.items()} == {"A1": ("1",), "A2": ("1",), "A3": ("1",)}
    nodes = {n.label: n for n in of(records, HarnessNode)}
    at = {c: n.label for n in nodes.values() for c in n.connectors}
    assert {name: at[c.ident] for name, c in connectors.items()} == {"A1": "ND-1", "A2": "ND-3", "A3": "ND-7"}
    assert all(n.position is None for n in nodes.values())  # the example has no geometry
    segments = {s.ident: s.label for s in of(records, HarnessSegment)}
    assert all(s.length_m is None for s in of(records, HarnessSegment))
    wires = {w.label: w for w in of(records, HarnessWire)}
    a1, a2, a3 = (connectors[n].ident for n in ("A1", "A2", "A3"))
    assert {name: w.ends for name, w in wires.items()} == {
        "W1": (WireEnd(a1, "1"), WireEnd(a2, "1")),
        "W2": (WireEnd(a1, "1"), WireEnd(a3, "1")),
        "W3": (WireEnd(a1, "1"), WireEnd(a2, "1")),
    }
    assert {(w.section_mm2, w.colour) for w in wires.values()} == {(Decimal("0.5"), "BL")}

    def path(route: WireRoute) -> list[str]:
        return [segments[s] for s in route.segments]

    # W1's path is written from A2's end (SEG-1 SEG-2): it is turned to run from A1's.
    assert [path(r) for r in wires["W1"].routes] == [["SEG-2", "SEG-1"]]
    # W3 runs out to ND-4 and back (a special routing): the repeated segment is kept.
    assert [path(r) for r in wires["W3"].routes] == [["SEG-2", "SEG-3", "SEG-3", "SEG-1"]]
    # W2 has a routing per variant configuration.
    assert [(path(r), r.modules) for r in wires["W2"].routes] == [
        (["SEG-2", "SEG-3", "SEG-4", "SEG-5", "SEG-6"], ("VariantConfiguration_00018",)),
        (["SEG-2", "SEG-3", "SEG-7", "SEG-8", "SEG-6"], ("VariantConfiguration_00019",)),
    ]


@pytest.mark.parametrize(
    ("chosen", "segments", "nodes"),
    [
        (None, {f"SEG-{n}" for n in range(1, 9)}, {f"ND-{n}" for n in range(1, 9)}),
        (
            "VariantConfiguration_00018",
            {f"SEG-{n}" for n in (1, 2, 3, 4, 5, 6)},
            {f"ND-{n}" for n in (1, 2, 3, 4, 5, 6, 7)},
        ),
        (
            "VariantConfiguration_00019",
            {f"SEG-{n}" for n in (1, 2, 3, 6, 7, 8)},
            {f"ND-{n}" for n in (1, 2, 3, 4, 6, 7, 8)},
        ),
    ],
    ids=["150%", "RL", "LL"],
)
def test_routing_example_variants(chosen: str | None, segments: set[str], nodes: set[str]) -> None:
    """The 150 % topology has a loop (the RL and LL alternatives); each variant is a tree."""
    records = read_vec(ROUTING)
    picked = frozenset([chosen]) if chosen else None
    assert {s.label for s in of(records, HarnessSegment) if in_variant(s.modules, picked)} == segments
    assert {n.label for n in of(records, HarnessNode) if in_variant(n.modules, picked)} == nodes
    routes = [r for w in of(records, HarnessWire) for r in w.routes if in_variant(r.modules, picked)]
    assert len(routes) == (4 if chosen is None else 3)


def test_a_file_without_a_harness_description_gives_nothing_and_says_so() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert read_vec(SNIPPET) == []
    (warning,) = [w.message for w in caught if isinstance(w.message, IngestWarning)]
    assert warning.line == 4 and "no harness description" in str(warning)


def test_own_1_1_file_geometry_lengths_and_a_variant() -> None:
    records = read_vec(OWN_11)
    (head,) = of(records, Harness)
    assert (head.ident, head.file_format) == ("H-11", "VEC 1.1.2")
    # Points in mm of the vehicle frame (x rear, y right, z up), metres in REP 103.
    assert {n.label: n.position for n in of(records, HarnessNode)} == {
        "N1": (-1.0, 0.0, 0.0),
        "N2": (-1.25, 0.0, 0.0),
        "N3": (-1.25, -0.3, 0.4),
    }
    segments = {s.label: s for s in of(records, HarnessSegment)}
    assert (segments["S1"].length_m, segments["S1"].length_source) == (Decimal("0.25"), "designed")
    # S2 has no stated length: its degree-1 B-spline runs 300 mm across and 400 mm up.
    assert segments["S2"].length_source == "curve"
    assert float(segments["S2"].length_m or 0) == pytest.approx(0.7, abs=1e-3)
    wires = {w.label: w for w in of(records, HarnessWire)}
    assert (wires["W10"].colour, wires["W10"].section_mm2, wires["W10"].length_m) == (
        "RT/GN",
        Decimal("0.75"),
        Decimal("0.98"),
    )
    assert wires["W10"].diameter_m == pytest.approx(0.0021)
    assert wires["W11"].route == ("s1", "s2")  # written S2 S1, from the far end
    (fixing,) = of(records, HarnessFixing)
    assert (fixing.label, fixing.nodes, fixing.modules) == ("F1", ("n2",), ("vc-a",))
    (tape,) = of(records, HarnessProtection)
    assert (tape.segments, tape.length_m) == (("s1", "s2"), Decimal("0.4"))
    connectors = of(records, HarnessConnector)
    assert [(c.label, c.description) for c in connectors] == [("C1", "connector C1"), ("C2", "connector C2")]


def test_own_2_0_file_modules_cable_and_nurbs() -> None:
    records = read_vec(OWN_20)
    modules = {m.label: m for m in of(records, HarnessModule)}
    assert {name: (m.kind, m.family_label) for name, m in modules.items()} == {
        "VC-X": ("variant configuration", None),
        "MOD-A": ("module", "FAM-1"),
        "MOD-B": ("module", "FAM-1"),
    }
    assert of(records, HarnessCable) == [HarnessCable("H-20", "k", "K1", None, 0.0045, 455, ("mod-a",))]
    wires = {w.label: w for w in of(records, HarnessWire)}
    assert {name: (w.cable, w.colour, w.modules) for name, w in wires.items()} == {
        "K1-1": ("k", "BK", ("mod-a",)),
        "K1-2": ("k", "WH", ("mod-a",)),
        "W5": (None, "BK", ("mod-b",)),
    }
    # K1-1 has no routing of its own: the cable's (its sheath's) is taken.
    assert [r.ident for r in wires["K1-1"].routes] == ["r-k"]
    segments = {s.label: (s.length_m, s.length_source, s.modules) for s in of(records, HarnessSegment)}
    # S1: a NURBS line from (100, 10, 50) to (130, 10, 50) cm; S2: the chord, 40 cm.
    assert segments == {
        "S1": (Decimal("0.3"), "curve", ("mod-a", "mod-b")),
        "S2": (Decimal("0.4"), "chord", ("mod-a", "mod-b")),
    }
    # The nested constraint (VEC 2.0) of F2, and the module list completing the tape P1.
    assert [(f.label, f.modules) for f in of(records, HarnessFixing)] == [("F2", ("vc-x",))]
    assert [(p.label, p.modules) for p in of(records, HarnessProtection)] == [("P1", ("mod-a", "mod-b"))]
    connectors = {c.label: c.modules for c in of(records, HarnessConnector)}
    assert connectors == {"X1": (), "X2": ("mod-a",), "X3": ("mod-a", "mod-b")}


def test_registry_knows_vec_by_suffix_and_content(tmp_path: Path) -> None:
    assert sniff_kind(ROUTING) == "vec"
    assert sniff_kind(SNIPPET) == "vec"  # a .xml file, by its VecContent root
    odd = tmp_path / "harness.data"
    odd.write_bytes(ROUTING.read_bytes())
    assert sniff_kind(odd) == "vec"


# -- bad input ------------------------------------------------------------------------------------------


def broken(write: Write, old: str, new: str, source: Path = ROUTING) -> Path:
    text = source.read_text(encoding="utf-8")
    assert text.count(old) == 1, old
    return write("broken.vec", text.replace(old, new))


@pytest.mark.parametrize(
    ("old", "new", "line", "found", "reason"),
    [
        (
            "<ReferencedNode>TopologyNode_00030</ReferencedNode>",
            "<ReferencedNode>TopologyNode_00099</ReferencedNode>",
            190,
            "TopologyNode_00099",
            "<ReferencedNode> of <Location> names nothing in the file",
        ),
        (
            "<ReferencedNode>TopologyNode_00030</ReferencedNode>",
            "<ReferencedNode>TopologySegment_00037</ReferencedNode>",
            190,
            "TopologySegment_00037",
            "<ReferencedNode> of <Location> names a TopologySegment",
        ),
        (
            "<Segment>TopologySegment_00033 TopologySegment_00032</Segment>",
            "<Segment>TopologySegment_00033 TopologySegment_00037</Segment>",
            200,
            "SEG-6 after SEG-1",
            "the routing W1 of wire W1 is not a path",
        ),
        (
            "<SiUnitName>Metre</SiUnitName>",
            "<SiUnitName>Gram</SiUnitName>",
            44,
            "Milli Gram ^2",
            "<CrossSectionArea> is not given in a unit of area",
        ),
        (
            "<VecVersion>2.1.0</VecVersion>",
            "<VecVersion>3.0.0</VecVersion>",
            2,
            "3.0.0",
            "unknown VEC version",
        ),
        (
            'id="TopologyNode_00031"',
            'id="TopologyNode_00030"',
            123,
            "TopologyNode_00030",
            "XML id given twice",
        ),
        (
            "<ValueComponent>0.5</ValueComponent>",
            "<ValueComponent>0,5</ValueComponent>",
            46,
            "0,5",
            "bad number",
        ),
    ],
    ids=["undefined-id", "wrong-kind", "not-a-path", "grams", "version", "id-twice", "comma"],
)
def test_located_errors(write: Write, old: str, new: str, line: int, found: str, reason: str) -> None:
    with pytest.raises(IngestError) as caught:
        read_vec(broken(write, old, new))
    assert (caught.value.line, caught.value.found) == (line, found), str(caught.value)
    assert reason in str(caught.value)


def test_not_vec_and_entities(write: Write) -> None:
    with pytest.raises(IngestError, match="not a VEC document"):
        read_vec(write("other.vec", '<?xml version="1.0"?>\n<data/>\n'))
    text = ROUTING.read_text(encoding="utf-8")
    with pytest.raises(IngestError, match="DOCTYPE"):
        read_vec(write("entity.vec", '<!DOCTYPE x [<!ENTITY a "aaaa">]>\n' + text))


def test_a_harness_is_built_from_vec(tmp_path: Path) -> None:
    """Through a manifest: the kind is told from the content, the records map to the graph."""
    import cadkg

    for path in (ROUTING, SNIPPET):
        (tmp_path / path.name).write_bytes(path.read_bytes())
    manifest = tmp_path / "manifest.toml"
    manifest.write_text(
        '[cell]\nname = "vec"\nprofile = "vw"\nbase_iri = "https://example.org/cell/vec/"\n'
        f'[[source]]\npath = "{ROUTING.name}"\n[[source]]\npath = "{SNIPPET.name}"\n',
        encoding="utf-8",
    )
    kg = cadkg.build(manifest)
    rows = kg.query("SELECT ?l ?f WHERE { ?h a ck:Harness ; ck:label ?l ; ck:fileFormat ?f }").rows
    assert rows == ({"l": "HARNESS-1", "f": "VEC 2.1.0"},)
    routings = kg.query("SELECT ?r WHERE { ?r a ck:Routing }").rows
    assert len(routings) == 4
    records: list[HarnessRecord] = read_vec(ROUTING)
    assert len(records) == 1 + 2 + 3 + 8 + 8 + 3
