"""KBL modules and variants (the 150 % harness), positions and centre curves, and the located
errors of broken routings, module lists and points."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.harness.kbl import read_kbl
from cadkg.ingest.harness.records import (
    HarnessConfiguration,
    HarnessConnector,
    HarnessFixing,
    HarnessModule,
    HarnessNode,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    in_variant,
)
from tests.ingest.test_kbl import GETRIEBE, MODULAR, MOVO, OWN_MODULAR, SAMPLES, broken, of, quietly

Write = Callable[[str, str | bytes], Path]


def variant(records: list[HarnessRecord], *labels: str) -> dict[str, set[str]]:
    """The things of the variant of the modules (or configuration) ``labels``, by kind, as labels."""
    modules = {m.label: m.ident for m in of(records, HarnessModule)}
    configurations = {c.label: c.modules for c in of(records, HarnessConfiguration)}
    chosen: set[str] = set()
    for label in labels:
        chosen.update(configurations.get(label) or (modules[label],))
    picked = frozenset(chosen)
    found: dict[str, set[str]] = {}
    for kind, name in (
        (HarnessConnector, "connectors"),
        (HarnessWire, "wires"),
        (HarnessSegment, "segments"),
        (HarnessNode, "nodes"),
        (HarnessFixing, "fixings"),
        (HarnessProtection, "protections"),
    ):
        found[name] = {r.ident for r in of(records, kind) if in_variant(r.modules, picked)}
    found["routes"] = {
        route.ident
        for wire in of(records, HarnessWire)
        for route in wire.routes
        if in_variant(route.modules, picked) and in_variant(wire.modules, picked)
    }
    return found


def test_own_modular_file_modules_and_configurations() -> None:
    records = read_kbl(OWN_MODULAR)
    assert [
        (m.ident, m.label, m.kind, m.control, m.family_label, m.family_description)
        for m in of(records, HarnessModule)
    ] == [
        ("m1", "M-BASE", "module", "L0L+B00", "000", "BASE"),
        ("m2", "M-OPT1", "module", "L0L+V01", "010", "LAMP"),
        ("m3", "M-OPT2", "module", "L0L+V02", "010", "LAMP"),
    ]
    assert [(c.label, c.modules) for c in of(records, HarnessConfiguration)] == [
        ("FULL", ("m1", "m2", "m3")),
        ("SMALL", ("m1",)),
    ]


@pytest.mark.parametrize(
    ("chosen", "expected"),
    [
        # The base wire o3 ends in cb, which only M-OPT1 controls: cb is in the base variant too.
        (
            ("M-BASE",),
            {
                "connectors": {"ca", "cb"},
                "wires": {"o3"},
                "segments": {"s1", "s2"},
                "nodes": {"n1", "n2", "n3"},
            },
        ),
        # The tape wp1 is a completion part of the module list (M-OPT1 M-OPT2).
        (
            ("M-BASE", "M-OPT1"),
            {
                "connectors": {"ca", "cb"},
                "wires": {"o1", "o3"},
                "segments": {"s1", "s2"},
                "nodes": {"n1", "n2", "n3"},
                "protections": {"wp1"},
            },
        ),
        (
            ("M-BASE", "M-OPT2"),
            {
                "connectors": {"ca", "cb", "cc"},
                "wires": {"o2", "o3"},
                "segments": {"s1", "s2", "s3"},
                "nodes": {"n1", "n2", "n3", "n4"},
                "fixings": {"f1"},
                "protections": {"wp1"},
            },
        ),
        (
            ("SMALL",),
            {
                "connectors": {"ca", "cb"},
                "wires": {"o3"},
                "segments": {"s1", "s2"},
                "nodes": {"n1", "n2", "n3"},
            },
        ),
    ],
    ids=["base", "base+opt1", "base+opt2", "configuration"],
)
def test_own_modular_file_variants(chosen: tuple[str, ...], expected: dict[str, set[str]]) -> None:
    found = variant(read_kbl(OWN_MODULAR), *chosen)
    expected = {"fixings": set(), "protections": set(), **expected}
    expected["routes"] = {f"r{w[1]}" for w in expected["wires"]}
    assert found == expected


def test_every_module_chosen_is_the_whole_file() -> None:
    for path in [*SAMPLES, OWN_MODULAR]:
        records = quietly(path)
        whole = variant(records, *(m.label for m in of(records, HarnessModule)))
        assert whole == {
            name: {r.ident for r in of(records, kind)}
            for name, kind in (
                ("connectors", HarnessConnector),
                ("wires", HarnessWire),
                ("segments", HarnessSegment),
                ("nodes", HarnessNode),
                ("fixings", HarnessFixing),
                ("protections", HarnessProtection),
            )
        } | {"routes": {r.ident for w in of(records, HarnessWire) for r in w.routes}}, path.name


def figures(found: dict[str, set[str]], records: list[HarnessRecord]) -> tuple[int, ...]:
    connectors = {c.ident: c for c in of(records, HarnessConnector)}
    wires = {w.ident: w for w in of(records, HarnessWire)}
    return (
        len(found["wires"]),
        sum(wires[w].cable is not None for w in found["wires"]),
        sum(connectors[c].kind == "connector" for c in found["connectors"]),
        sum(connectors[c].kind == "component box" for c in found["connectors"]),
        len(found["segments"]),
        len(found["nodes"]),
        len(found["fixings"]),
        len(found["protections"]),
    )


@pytest.mark.parametrize(
    ("chosen", "expected"),
    [
        # wires (of them cores), connectors, boxes, segments, nodes, fixings, protections
        (("aaa108a1aaa", "aaa108a1a4a"), (131, 2, 78, 3, 115, 116, 3, 72)),
        (("aaa108a1aaa",), (128, 0, 76, 3, 113, 114, 3, 70)),
        (("aaa108a1a4a",), (4, 2, 5, 0, 13, 14, 0, 9)),
        (("aaa108a1aa61B",), (8, 8, 7, 0, 11, 12, 0, 0)),
        (("Kombination_MINI",), (165, 14, 100, 5, 148, 149, 10, 101)),
    ],
    ids=["base+heating", "base", "heating", "abs-1B", "mini"],
)
def test_modular_sample_variants(chosen: tuple[str, ...], expected: tuple[int, ...]) -> None:
    """The base harness with the heating module, and other variants of the Old Beetle's kit."""
    records = quietly(MODULAR)
    assert figures(variant(records, *chosen), records) == expected


def test_modular_sample_modules() -> None:
    records = quietly(MODULAR)
    modules = of(records, HarnessModule)
    assert len(modules) == 34 and len({m.label for m in modules}) == 34
    assert len({m.family for m in modules}) == 8
    base = next(m for m in modules if m.label == "aaa108a1aaa")
    assert (base.ident, base.kind, base.control, base.family_label, base.family_description) == (
        "id_331_0",
        "module",
        "L0L+K8S",
        "000",
        "LEITUNGSSTRANG",
    )
    assert {c.label: len(c.modules) for c in of(records, HarnessConfiguration)} == {
        "Kombination_MAXI": 34,
        "Kombination_MINI": 7,
        "Freie Kombination": 0,
    }
    # In the variant of one ABS module a designation names two occurrences: the wire-carrying
    # one of another module's assembly and this module's own, placed nowhere.
    connectors = {c.ident: c for c in of(records, HarnessConnector)}
    found = variant(records, "aaa108a1aa61B")["connectors"]
    assert sorted(connectors[c].label for c in found).count("XA.G46.1") == 2


# -- positions and centre curves ------------------------------------------------------------------------


def test_own_file_lengths_from_curve_chord_and_virtual_length() -> None:
    segments = {s.ident: s for s in of(read_kbl(OWN_MODULAR), HarnessSegment)}
    # s1: a degree-1 curve through (1000,-200,500) (1150,-120,500) (1300,-200,500): 2 x 170 mm.
    assert segments["s1"].length_source == "curve"
    # The curve is sampled (512 points): its kink at q1 is cut by less than a tenth of a millimetre.
    assert float(segments["s1"].length_m or 0) == pytest.approx(0.34, abs=1e-4)
    assert (segments["s2"].length_m, segments["s2"].length_source) == (Decimal("0.3"), "chord")
    assert (segments["s3"].length_m, segments["s3"].length_source) == (Decimal("0.5"), "virtual")


def test_centre_curves_are_unclamped_uniform_b_splines(write: Write) -> None:
    """Without its Virtual_length, a sample segment's length comes from its degree-6 curve,
    read as an unclamped uniform B-spline: the length the file states, to 1e-5."""
    stated = Decimal("0.625086846")
    text = GETRIEBE.read_text(encoding="utf-8")
    start, end = text.index("<Virtual_length"), text.index("</Virtual_length>") + len("</Virtual_length>")
    (segment,) = of(read_kbl(write("curve.kbl", text[:start] + text[end:])), HarnessSegment)
    assert segment.length_source == "curve"
    assert math.isclose(float(segment.length_m or 0), float(stated), rel_tol=1e-5)


def test_a_curve_that_does_not_fit_its_segment_is_a_warning() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        records = read_kbl(MOVO)
    (warning,) = [w.message for w in caught if isinstance(w.message, IngestWarning)]
    assert warning.line == 3533
    assert "the centre curve of segment Segment_6 does not fit the segment" in str(warning)
    assert "its length 105.9 mm is not the Virtual_length 55.9 mm" in str(warning)
    segment = next(s for s in of(records, HarnessSegment) if s.ident == "Segment_6")
    assert (segment.length_m, segment.length_source) == (Decimal("0.055867535"), "virtual")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_kbl(MODULAR)
    found = sorted(str(w.message).split("segment ")[1].split(" ")[0] for w in caught)
    assert found == ["Segment_119", "Segment_163", "Segment_17", "Segment_170", "Segment_55"]


# -- bad input ---------------------------------------------------------------------------------------------


def error_of(path: Path) -> IngestError:
    with pytest.raises(IngestError) as caught:
        quietly(path)
    return caught.value


@pytest.mark.parametrize(
    ("old", "new", "source", "line", "found", "reason"),
    [
        (
            "<Segments>s1 s3</Segments>",
            "<Segments>s1 s3 s1</Segments>",
            OWN_MODULAR,
            341,
            "s1",
            "a routing names a segment twice",
        ),
        (
            "<Segments>s1 s3</Segments>",
            "<Segments>s2 s3 s1</Segments>",
            OWN_MODULAR,
            341,
            "s1 after s3",
            "the routing of wire 2 is not a path",
        ),
        (
            "<Logistic_control_information>m2 m3</Logistic_control_information>",
            "<Logistic_control_information>m2 m9</Logistic_control_information>",
            OWN_MODULAR,
            303,
            "m9",
            "a module list names no module",
        ),
        (
            "<Coordinates>1600</Coordinates>",
            "<Coordinates>1600,5</Coordinates>",
            OWN_MODULAR,
            19,
            "1600,5",
            "bad number in <Coordinates>",
        ),
        (
            "<Control_points>p1 q1 p2</Control_points>",
            "<Control_points>p1 q9 p2</Control_points>",
            OWN_MODULAR,
            353,
            "q9",
            "<Control_points> of <Center_curve> names nothing in the file",
        ),
        (
            "<Cartesian_point>p4</Cartesian_point>",
            "<Cartesian_point>s3</Cartesian_point>",
            OWN_MODULAR,
            332,
            "s3",
            "<Cartesian_point> of <Node> names a <Segment>",
        ),
        (
            "<Of_family>fam0</Of_family>",
            "<Of_family>m1</Of_family>",
            OWN_MODULAR,
            263,
            "m1",
            "<Of_family> of <Module> names a <Module>",
        ),
    ],
    ids=["segment-twice", "not-a-path", "module-list", "coordinate", "control-point", "point-kind", "family"],
)
def test_located_errors(
    write: Write, old: str, new: str, source: Path, line: int, found: str, reason: str
) -> None:
    err = error_of(broken(write, old, new, source))
    assert (err.line, err.found) == (line, found), str(err)
    assert reason in str(err)


def test_a_point_needs_two_or_three_coordinates(write: Write) -> None:
    path = broken(write, "<Coordinates>1600</Coordinates>", "", OWN_MODULAR)
    err = error_of(
        broken(write, "<Coordinates>-200</Coordinates>\n\t\t<Coordinates>900</Coordinates>", "", path)
    )
    assert "<Cartesian_point> does not have 2 or 3 coordinates" in str(err)
    assert err.found == "0"
