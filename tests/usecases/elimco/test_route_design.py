"""The route-design files of ELIMCO: pin_info.xml, cable_info.xml, path_info.xml."""

from __future__ import annotations

from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.registry import sniff_kind
from cadkg.usecases.elimco.route_design import (
    BenchPinSpec,
    RouteCable,
    RoutePathSpec,
    looks_like_cable_info,
    looks_like_path_info,
    looks_like_pin_info,
    read_cable_info,
    read_path_info,
    read_pin_info,
)
from tests.conftest import EXAMPLES

BENCH = EXAMPLES / "elimco-bench"
Write = Callable[[str, str | bytes], Path]


def test_pin_info_of_the_example() -> None:
    pins = read_pin_info(BENCH / "pin_info.xml")
    assert [p.name for p in pins] == ["A918VC1A", "A350VC-A", "7RN4A", "pin_1_doble", "A1UZ3B", "A1UZ3C"]
    assert pins[0] == BenchPinSpec(
        "A918VC1A", "initial", 11680.0, 3960.0, "mm", 11.68, 3.96, False, None, 0.04, 5
    )
    double = pins[3]
    assert (double.role, double.double, double.double_distance_m, double.line) == (
        "intermediate",
        True,
        0.02,
        8,
    )
    # 2002 mm is 2.002 m exactly, not 2.0020000000000002.
    assert pins[1].y_m == 2.002
    assert [p.role for p in pins] == ["initial"] * 3 + ["intermediate", "final", "final"]


def test_cable_info_of_the_example() -> None:
    assert read_cable_info(BENCH / "cable_info.xml") == [
        RouteCable("A4351-1669", "A918VC1A", "A1UZ3B", Decimal("1.504"), 4),
        RouteCable("A4351-2401", "A350VC-A", "A1UZ3C", Decimal("1.057"), 5),
        RouteCable("A4351-1677", "7RN4A", "A1UZ3B", Decimal("1.668"), 6),
    ]


def test_path_info_of_the_example_figures_15_and_19() -> None:
    paths = read_path_info(BENCH / "path_info.xml")
    assert [(p.index, p.initial, p.final, p.cable_length_m) for p in paths] == [
        (0, "A918VC1A", "A1UZ3B", Decimal("1.504")),
        (1, "A350VC-A", "A1UZ3C", Decimal("1.057")),
        (2, "7RN4A", "A1UZ3B", Decimal("1.668")),
    ]
    fig19 = paths[2]
    assert fig19 == RoutePathSpec(
        2, "A4351-1677", "7RN4A", "A1UZ3B", ("pin_1_doble",), (Decimal("0.775"), Decimal("0.393")),
        Decimal("1.168"), Decimal("1.668"), 10,
    )  # fmt: skip
    assert fig19.pins == ("7RN4A", "pin_1_doble", "A1UZ3B")
    assert sum(fig19.segment_lengths_m) == fig19.total_length_m


def test_metres_and_a_total_from_the_segments(write: Write) -> None:
    path = write(
        "path_info.xml",
        '<path_info units="m"><path index="4" cable="C" initial="a" final="b">'
        '<segment from="a" to="b" length="0.5"/></path></path_info>',
    )
    (route,) = read_path_info(path)
    assert (route.segment_lengths_m, route.total_length_m, route.cable_length_m) == (
        (Decimal("0.5"),), Decimal("0.5"), None,
    )  # fmt: skip


def test_a_route_not_drawn_yet_has_no_segments(write: Write) -> None:
    path = write("p.xml", '<path_info><path index="0" cable="C" initial="a" final="b"/></path_info>')
    (route,) = read_path_info(path)
    assert (route.segment_lengths_m, route.total_length_m) == ((), None)


def test_sniffing_by_root_element(tmp_path: Path) -> None:
    for name, kind in (
        ("pin_info.xml", "pin-info"),
        ("cable_info.xml", "cable-info"),
        ("path_info.xml", "path-info"),
    ):
        assert sniff_kind(BENCH / name) == kind
        renamed = tmp_path / f"export-{kind}.xml"
        renamed.write_bytes((BENCH / name).read_bytes())
        assert sniff_kind(renamed) == kind
    assert sniff_kind(EXAMPLES / "iema-switchgear" / "components.xml") == "component-model"
    head = b'\xef\xbb\xbf<?xml version="1.0"?>\n<!-- pins -->\n<pin_info units="mm">'
    assert looks_like_pin_info(head) and not looks_like_path_info(head) and not looks_like_cable_info(head)
    assert not looks_like_pin_info(b"<data><code name='x'><pin_info/></code></data>")


# --- bad input ----------------------------------------------------------------------------------------

PIN = '<pin name="P" role="initial" x="1" y="2"/>'


def _pins(attributes: str) -> str:
    return f"<pin_info>\n<pin {attributes}/></pin_info>"


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (_pins('name="P" role="start" x="1" y="2"'), 2, "unknown role of 'P'"),
        (_pins('name="P" role="final" x="1,5" y="2"'), 2, "not a number: x of P"),
        (_pins('name="P" role="final" x="1"'), 2, "<pin> without y"),
        (_pins('name="P" role="final" x="1" y="2" z="3"'), 2, "unknown attribute 'z' of <pin>"),
        (_pins('name="" role="final" x="1" y="2"'), 2, "empty attribute 'name' of <pin>"),
        (f"<pin_info>\n{PIN}\n{PIN}</pin_info>", 3, "pin 'P' given twice (first on line 2)"),
        (_pins('name="P" role="final" x="1" y="2" type="double"'), 2,
         "double pin 'P' without double_distance"),
        (_pins('name="P" role="final" x="1" y="2" double_distance="5"'), 2,
         "double_distance on simple pin 'P'"),
        (_pins('name="P" role="final" x="1" y="2" type="double" double_distance="0"'), 2,
         "not a length: double_distance of P"),
        (_pins('name="P" role="intermediate" x="1" y="2" connector_distance="5"'), 2,
         "connector_distance on intermediate pin 'P'"),
        (_pins('name="P" role="final" x="1" y="2" connector_distance="-5"'), 2,
         "not a length: connector_distance of P"),
        ('<pin_info units="in">\n' + PIN + "</pin_info>", 1, "unknown unit"),
        ("<pin_info>\n<pins/></pin_info>", 2, "unexpected element <pins> inside <pin_info>"),
        ("<pin_info>\n</pin_info>", 1, "no <pin> inside <pin_info>"),
        ("<pins>\n" + PIN + "</pins>", 1, "the root element is not <pin_info>"),
        ('<!DOCTYPE x [<!ENTITY a "b">]>\n<pin_info>' + PIN + "</pin_info>", 1,
         "<!DOCTYPE> is not allowed in route-design XML"),
    ],
)  # fmt: skip
def test_bad_pin_info(write: Write, body: str, line: int, reason: str) -> None:
    path = write("pin_info.xml", body)
    with pytest.raises(IngestError) as info:
        read_pin_info(path)
    assert (info.value.line, info.value.reason) == (line, reason)
    assert str(info.value).startswith(f"{path}:{line}: {reason}")


def test_malformed_xml_names_its_line(write: Write) -> None:
    with pytest.raises(IngestError, match="malformed XML: Couldn't find end of Start Tag pin") as info:
        read_pin_info(write("pin_info.xml", "<pin_info>\n<pin"))
    assert info.value.line == 2


def _cables(*cables: str) -> str:
    return "<cable_info>\n" + "\n".join(f"<cable {c}/>" for c in cables) + "</cable_info>"


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (_cables('name="C" initial="a" final="a"'), 2, "cable 'C' starts and ends at one connector"),
        (_cables('name="C" initial="a" final="b" length="0"'), 2, "not a length: length of C"),
        (_cables('name="C" initial="a" final="b" length="1e99999"'), 2, "not a length: length of C"),
        (_cables('name="C" initial="a" final="b"', 'name="C" initial="a" final="b"'), 3,
         "cable 'C' given twice (first on line 2)"),
        ('<cable_info>\n<cable name="C" initial="a" final="b">1504</cable></cable_info>', 2,
         "text inside <cable>"),
    ],
)  # fmt: skip
def test_bad_cable_info(write: Write, body: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_cable_info(write("cable_info.xml", body))
    assert (info.value.line, info.value.reason) == (line, reason)


def _path(inner: str, index: str = "2") -> str:
    head = f'<path index="{index}" cable="C" initial="a" final="b" total_length="10">'
    return f"<path_info>\n{head}\n{inner}</path>\n</path_info>"


def _segment(start: str, end: str, length: str) -> str:
    return f'<segment from="{start}" to="{end}" length="{length}"/>\n'


MIDDLE = '<intermediate pin="m"/>\n'


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (_path(MIDDLE + _segment("a", "m", "4") + _segment("m", "b", "4")), 2,
         "the segment lengths of path 2 add up to 8, not its total_length"),
        (_path(MIDDLE + _segment("a", "b", "10")), 4, "path 2 has 1 segment(s) for 3 pins"),
        (_path(MIDDLE + _segment("m", "b", "4") + _segment("a", "m", "6")), 4,
         "segment of path 2 out of route order"),
        (_path(_segment("a", "b", "10") + MIDDLE), 4, "<intermediate> after a <segment>"),
        (_path('<intermediate pin="a"/>\n'), 2, "path 2 visits pin 'a' twice"),
        (_path("", "x"), 2, "not a path index"),
        (_path(_segment("a", "b", "-1")), 3, "not a length: length of segment a-b"),
        (_path('<waypoint pin="m"/>\n'), 3, "unexpected element <waypoint> inside <path>"),
        ('<path_info>\n<path index="1" cable="C" initial="a" final="b"/>\n'
         '<path index="1" cable="D" initial="a" final="b"/></path_info>', 3,
         "path 1 given twice (first on line 2)"),
        ('<path_info>\n<path index="1" cable="C" initial="a" final="b"/>\n'
         '<path index="2" cable="C" initial="a" final="b"/></path_info>', 3,
         "cable 'C' has a second path (first on line 2)"),
    ],
)  # fmt: skip
def test_bad_path_info(write: Write, body: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_path_info(write("path_info.xml", body))
    assert (info.value.line, info.value.reason) == (line, reason)


def test_segment_found_and_expected(write: Write) -> None:
    body = _path(MIDDLE + _segment("m", "b", "4") + _segment("a", "m", "6"))
    with pytest.raises(IngestError) as info:
        read_path_info(write("path_info.xml", body))
    assert (info.value.found, info.value.expected) == ("m to b", "a to m")


def test_one_millimetre_of_rounding_between_segments_and_total(write: Write) -> None:
    (route,) = read_path_info(
        write("path_info.xml", _path(MIDDLE + _segment("a", "m", "4.4") + _segment("m", "b", "4.6")))
    )
    assert (route.segment_lengths_m, route.total_length_m) == (
        (Decimal("0.0044"), Decimal("0.0046")),
        Decimal("0.01"),
    )


def test_entities_are_never_expanded(write: Write) -> None:
    body = '<?xml version="1.0"?>\n<!DOCTYPE pin_info SYSTEM "http://example.com/x.dtd">\n<pin_info/>'
    with pytest.raises(IngestError, match="DOCTYPE") as info:
        read_pin_info(write("pin_info.xml", body))
    assert info.value.line == 2
