"""Table 1 services on the small cabinet of tests/data/cells/mini, against hand-computed values.

The cell: RAIL1 at (0.1, 0.5, 0); relay K1 on it at x=0.05 (front of the rail z=0.0075) with an
auxiliary contact 0.02 to its right; terminal block X1 (two terminals of 5 mm and a 2 mm end plate)
at x=0.15; relay K2 placed flat in the scene at (0.3, 0.5, 0.0075), turned 180° about z; duct U1
above the rail. Wire W3 is assigned to a human; W4 ends on K9, which no file describes.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import pytest

import cadkg.usecases.iema.cursors as cursors
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.service import parse_pose, to_jsonable
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.iema import answers as iema
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"
HALF_TURN = (0.0, 0.0, 1.0, 0.0)


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(MINI)
    yield graph
    graph.close()


@pytest.fixture
def session(kg: KnowledgeGraph) -> Session:
    return Session(kg.cell_model())


def close(actual: tuple[float, ...] | None, expected: tuple[float, ...], tol: float = 1e-9) -> bool:
    assert actual is not None
    return all(math.isclose(a, e, abs_tol=tol) for a, e in zip(actual, expected, strict=True))


def same_rotation(actual: Pose | None, expected: tuple[float, ...]) -> bool:
    assert actual is not None
    dot = sum(a * e for a, e in zip(actual.orientation, expected, strict=True))
    return math.isclose(abs(dot), 1.0, abs_tol=1e-9)


def test_cad_service_on_a_rail_component(kg: KnowledgeGraph) -> None:
    result = iema.cad_service(kg.cell_model(), "K1")
    assert result.success
    assert result.original_pose is not None
    assert close(result.original_pose.position, (0.15, 0.5, 0.0075))
    # The box is the relay (20 mm) and its auxiliary contact (10 mm) side by side.
    assert close(result.dimensions, (0.03, 0.08, 0.06))
    # Corner: the box's minimum corner. Target: 0.15 m in front of the front face (z 0.0675)
    # over its centre, turned a half turn about x (z into the plate), as the cell's software.
    assert close(result.corner_pose.position if result.corner_pose else None, (0.15, 0.5, 0.0075))
    assert close(result.target_pose.position if result.target_pose else None, (0.165, 0.54, 0.2175))
    assert same_rotation(result.target_pose, (1.0, 0.0, 0.0, 0.0))
    pins = {p.pin: p for p in result.pins}
    assert sorted(pins) == ["13", "A1", "A2"]
    assert close(pins["A1"].screw.position if pins["A1"].screw else None, (0.155, 0.57, 0.0675))
    # Pin 13 sits on the child item: relay origin + child placement + couple.
    assert pins["13"].item == "ID000003"
    assert close(pins["13"].hole.position if pins["13"].hole else None, (0.175, 0.505, 0.0575))


def test_cad_service_on_a_turned_component(kg: KnowledgeGraph) -> None:
    result = iema.cad_service(kg.cell_model(), "=-K2")
    assert result.success and same_rotation(result.original_pose, HALF_TURN)
    assert close(result.corner_pose.position if result.corner_pose else None, (0.3, 0.5, 0.0075))
    assert close(result.target_pose.position if result.target_pose else None, (0.29, 0.46, 0.2175))
    # The half turn about z of the component, then the half turn about x: a half turn about y.
    assert same_rotation(result.target_pose, (0.0, 1.0, 0.0, 0.0))
    pins = {p.pin: p for p in result.pins}
    assert close(pins["A2"].screw.position if pins["A2"].screw else None, (0.285, 0.43, 0.0675))


@pytest.mark.parametrize("service", ["cad_service", "full_cad_service", "cluster_service", "cad_reference"])
def test_unknown_label_is_a_failure_not_an_exception(session: Session, service: str) -> None:
    result = call(session, service, {"label": "NOPE"})
    assert result.success is False
    assert "NOPE" in result.message


def test_full_cad_service_lists_connections_in_order(kg: KnowledgeGraph) -> None:
    result = iema.full_cad_service(kg.cell_model(), "K1")
    assert [c.wire for c in result.connections] == ["W1", "W2", "W4"]
    w4 = result.connections[-1]
    assert w4.destination == "K9:1" and w4.missing_pin_data and w4.list_position == 3  # from 0


def test_item_screws_follow_the_detected_pose(kg: KnowledgeGraph) -> None:
    model = kg.cell_model()
    at_cad = iema.get_item_screw_service(model, "K1", Pose((0.15, 0.5, 0.0075)))
    assert at_cad.pins == ("13", "A1", "A2")
    assert close(at_cad.screws[1].position, (0.155, 0.57, 0.0675))
    moved = iema.get_item_screw_service(model, "K1", Pose((0.16, 0.52, 0.0075), HALF_TURN))
    # Screw A1 is (0.005, 0.07, 0.06) from the relay origin; turned half about z it is (-0.005, -0.07).
    assert close(moved.screws[1].position, (0.155, 0.45, 0.0675))
    assert close(moved.holes[0].position, (0.16 - 0.025, 0.52 - 0.005, 0.0575))
    assert moved.screw_data[1].wire == "W1" and moved.screw_data[1].termination == "PUNTALINO_vite"


def test_terminal_data(kg: KnowledgeGraph) -> None:
    result = iema.get_terminal_data(kg.cell_model(), "X1")
    assert result.success and result.pins == ("1:a", "1:b", "2:a", "2:b")
    assert close(result.terminal_start.position if result.terminal_start else None, (0.25, 0.5, 0.0075))
    assert close(result.screws[0].position, (0.2525, 0.54, 0.0475))
    assert close(result.holes[3].position, (0.2575, 0.505, 0.0375))
    assert math.isclose(result.length, 0.012) and math.isclose(result.height, 0.05)
    assert not iema.get_terminal_data(kg.cell_model(), "K1").success


def test_clusters(kg: KnowledgeGraph) -> None:
    result = iema.cluster_service(kg.cell_model(), "K1")
    assert [c.pins for c in result.horizontal] == [("A1", "A2")]
    assert result.vertical == ()
    terminals = iema.cluster_service(kg.cell_model(), "X1")
    assert [c.pins for c in terminals.horizontal] == [("1:b", "2:b"), ("1:a", "2:a")]
    assert [c.pins for c in terminals.vertical] == [("1:b", "1:a"), ("2:b", "2:a")]


def test_cad_reference(kg: KnowledgeGraph) -> None:
    result = iema.cad_reference(kg.cell_model(), "K1")
    assert close(result.corner_pose.position if result.corner_pose else None, (0.15, 0.5, 0.0075))


def test_rail_scanner_cursor(session: Session) -> None:
    first = cursors.rail_scanner(session)
    assert not first.end and first.rail == "RAIL1"
    assert first.components_label == ("K1", "X1", "K2")
    assert close(first.rail_start.position if first.rail_start else None, (0.1, 0.5, 0.0))
    assert close(first.components_dimensions[1], (0.012, 0.05, 0.04))
    assert cursors.rail_scanner(session).end
    assert cursors.rail_scanner(session, client="other").rail == "RAIL1"
    assert cursors.reset_rail_scanner(session).success
    assert cursors.rail_scanner(session).rail == "RAIL1"


def test_group_provider_walks_robot_wires_then_ends(session: Session) -> None:
    first = cursors.group_connection_provider(session)
    assert (first.wire, first.list_position, first.wire_path) == ("W1", 0, "=-U1")  # as written
    # Origin hole → entry of duct U1 → exit towards the destination → destination hole.
    points = [p.position for p in first.path_keypoints]
    assert len(points) == 4
    assert close(points[1], (0.155, 0.62, 0.03)) and close(points[2], (0.2525, 0.62, 0.03))
    assert close(points[3], (0.2525, 0.545, 0.0375))
    # W3 is assigned to a human: skipped.
    assert [cursors.group_connection_provider(session).wire for _ in range(2)] == ["W2", "W4"]
    assert cursors.group_connection_provider(session).end
    assert cursors.reset_connection_list(session).success
    assert cursors.group_connection_provider(session).wire == "W1"


def test_missing_pin_data_is_flagged(session: Session) -> None:
    cursors.reset_to_connection_list(session, 3)
    step = cursors.group_connection_provider(session)
    assert step.wire == "W4" and step.missing_pin_data == "K9:1"
    assert step.path_keypoints == ()


def test_full_provider_hands_out_ends(session: Session) -> None:
    origin = cursors.full_connection_provider(session, False)
    again = cursors.full_connection_provider(session, False)
    assert (
        (origin.label, origin.pin, origin.direction) == ("K1", "A1", True) == (again.label, again.pin, True)
    )
    assert (origin.source, origin.connection_list, origin.list_position) == ("orig", "connections.tsv", 0)
    destination = cursors.full_connection_provider(session, True)
    assert (destination.label, destination.pin, destination.source) == ("X1", "1:a", "dest")
    # The component pose is X1's target: box (0.25, 0.5, 0.0075) + (0.012, 0.05, 0.04), front z 0.0475.
    assert close(
        destination.component_pose.position if destination.component_pose else None, (0.256, 0.525, 0.1975)
    )
    assert cursors.full_connection_provider(session, False).wire == "W2"


def test_full_provider_without_occupancy_alternates_the_ends(session: Session) -> None:
    # The cell's software's request is empty: origin, destination, next origin.
    ends = [cursors.full_connection_provider(session) for _ in range(3)]
    assert [(e.wire, e.source, e.label, e.list_position) for e in ends] == [
        ("W1", "orig", "K1", 0),
        ("W1", "dest", "X1", 0),
        ("W2", "orig", "K1", 1),
    ]


def test_reset_to_position_or_wire_number(session: Session) -> None:
    result = cursors.reset_to_connection_list(session, 1.0, connection_list="connections.tsv")
    assert result.success and "W2" in result.output
    assert cursors.group_connection_provider(session).wire == "W2"
    assert not cursors.reset_to_connection_list(session, 2.0).success  # W3 is the human's
    assert not cursors.reset_to_connection_list(session, 1.0, connection_list="other.csv").success
    assert not cursors.reset_to_connection_list(session, 1.0, "connections.tsv").success  # source: an end


def test_reset_to_with_source_dest_hands_the_destination_next(session: Session) -> None:
    # As the cell's software: reset_to_connection_list(data=3, source="dest") → W4's destination next.
    assert cursors.reset_to_connection_list(session, 3, "dest").success
    end = cursors.full_connection_provider(session)
    assert (end.wire, end.source, end.label, end.pin, end.missing_pin_data) == ("W4", "dest", "K9", "1", True)
    assert cursors.full_connection_provider(session).end


def test_cursors_are_per_client(session: Session) -> None:
    cursors.group_connection_provider(session, client="a")
    assert cursors.group_connection_provider(session, client="b").wire == "W1"
    assert cursors.group_connection_provider(session, client="a").wire == "W2"


def test_call_converts_and_checks_parameters(session: Session) -> None:
    from cadkg.errors import QueryError

    result = call(
        session, "get_item_screw_service", {"label": "K1", "detected_pose": "0.15,0.5,0.0075,0,0,0"}
    )
    assert result.success and len(result.screws) == 3
    with pytest.raises(QueryError, match="missing parameter label"):
        call(session, "cad_service", {})
    with pytest.raises(QueryError, match="unknown parameter colour"):
        call(session, "cad_service", {"label": "K1", "colour": "x"})
    with pytest.raises(QueryError, match="not a boolean"):
        call(session, "full_connection_provider", {"occupancy": "maybe"})
    with pytest.raises(QueryError, match="unknown service"):
        call(session, "nope", {})
    with pytest.raises(QueryError, match="6 or 7"):
        parse_pose("1,2,3")


def test_every_service_gives_json(session: Session) -> None:
    import json

    args = {
        "label": "K1",
        "detected_pose": "0,0,0,0,0,0,1",
        "cad_pose": "0,0,0,0,0,0,1",
        "occupancy": "false",
        "data": "1",
    }
    for service in services_for("iema"):
        name = service.name
        result = call(session, name, {k: args[k] for k in service.params if k in args})
        assert json.loads(json.dumps(to_jsonable(result))), name


def test_derived_triples_are_in_the_graph(kg: KnowledgeGraph) -> None:
    rows = kg.query(
        """SELECT DISTINCT ?x ?y ?z WHERE { ?c ck:label "K1" ; ck:cornerPose ?p .
             ?p ck:tx ?x ; ck:ty ?y ; ck:tz ?z }"""
    ).rows
    assert len(rows) == 1 and close((rows[0]["x"], rows[0]["y"], rows[0]["z"]), (0.15, 0.5, 0.0075))
    assert kg.ask('ASK { ?w ck:wireNumber "W4" ; ck:missingPinData true }')
    assert kg.ask('ASK { ?c ck:label "K1" ; ck:onRail/ck:label "RAIL1" }')
    assert kg.ask('ASK { ?k a ck:PinCluster ; ck:clusterAxis "horizontal" ; ck:clusterOf/ck:label "K1" }')
    meshes = kg.query("SELECT ?u WHERE { ?m ck:meshUri ?u }").rows
    assert len(meshes) == 8
    stl = Path(kg.files_dir, meshes[0]["u"]).read_bytes()
    assert len(stl) == 84 + 50 * 12  # a box is 12 triangles


def test_pins_sort_in_natural_order_whatever_their_length() -> None:
    names = ["A10", "10", "9", "A9", "A", "1" * 5000, "A09x", "B1", "010"]
    assert sorted(names, key=iema._natural) == ["9", "10", "010", "1" * 5000, "A", "A9", "A09x", "A10", "B1"]
