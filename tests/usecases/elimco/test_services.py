"""The ELIMCO services on examples/elimco-bench, against the values computed by hand in its README.

Drawing positions (mm): A918VC1A (11680, 3960), A350VC-A (11605, 2002), 7RN4A (11542, 2380),
pin_1_doble (12007, 3000), A1UZ3B (12400, 3000), A1UZ3C (12400, 2002); centroid (11939, 2724).
pin_info gives A918VC1A a connector distance of 40 mm and A1UZ3B one of 25 mm.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterator
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.elimco.bench import ElimcoModel, consistency_problems, elimco_model, frame_id
from cadkg.usecases.elimco.services import (
    PinPositionsResult,
    get_cable_list,
    get_path_positions,
    get_pin_positions,
    pin_frames,
)
from tests.conftest import EXAMPLES

BENCH = EXAMPLES / "elimco-bench"
ROOT5 = math.sqrt(5.0)
NOMINAL_MM = {
    "A918VC1A": (11680, 3960),
    "A350VC-A": (11605, 2002),
    "7RN4A": (11542, 2380),
    "pin_1_doble": (12007, 3000),
    "A1UZ3B": (12400, 3000),
    "A1UZ3C": (12400, 2002),
}
# Route direction at each pin (yaw about the drawing's z): out of A918VC1A along (0.6, -0.8),
# out of 7RN4A along (0.6, 0.8), through pin_1_doble along (0.6, 0.8) + (1, 0) ~ (2, 1), into
# A1UZ3B along (0.6, -0.8) + (1, 0) ~ (2, -1), and along x on the route A350VC-A -> A1UZ3C.
YAW = {
    "A918VC1A": math.atan2(-0.8, 0.6),
    "A350VC-A": 0.0,
    "7RN4A": math.atan2(0.8, 0.6),
    "pin_1_doble": math.atan2(1, 2),
    "A1UZ3B": math.atan2(-1, 2),
    "A1UZ3C": 0.0,
}


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(BENCH / "manifest.toml")
    yield graph
    graph.close()


@pytest.fixture(scope="module")
def model(kg: KnowledgeGraph) -> ElimcoModel:
    return elimco_model(kg)


def close(actual: tuple[float, ...], expected: tuple[float, ...], tol: float = 1e-9) -> bool:
    return all(math.isclose(a, e, abs_tol=tol) for a, e in zip(actual, expected, strict=True))


def by_name(result: PinPositionsResult) -> dict[str, Pose]:
    return {p.name: p.pose for p in result.pins}


def test_the_model_of_the_example(model: ElimcoModel) -> None:
    assert list(model.pins) == list(NOMINAL_MM)
    assert close(model.centroid, (11.939, 2.724, 0.0))
    assert [(r.index, r.cable, r.pins) for r in model.routes.values()] == [
        (0, "A4351-1669", ("A918VC1A", "A1UZ3B")),
        (1, "A4351-2401", ("A350VC-A", "A1UZ3C")),
        (2, "A4351-1677", ("7RN4A", "pin_1_doble", "A1UZ3B")),
    ]
    assert model.placed_by_manifest == {"pins_centroid"}
    assert model.problems == ()


def test_segment_lengths_are_the_distances_between_the_pins_and_add_up(model: ElimcoModel) -> None:
    for route in model.routes.values():
        assert route.total_length is not None
        assert math.isclose(sum(route.segment_lengths), route.total_length)
        for start, end, length in zip(route.pins, route.pins[1:], route.segment_lengths, strict=False):
            a, b = model.pins[start].position, model.pins[end].position
            assert math.isclose(math.dist(a, b), length)
    assert [r.total_length for r in model.routes.values()] == [1.2, 0.795, 1.168]


def test_pin_positions_in_the_drawing_frame_without_connector_distance(model: ElimcoModel) -> None:
    # 0 takes each pin's own connector distance from pin_info: only A918VC1A and A1UZ3B have one.
    result = get_pin_positions(model, use_centroid=False, pin_connector_distance=0.0)
    assert result.success and result.frame == "drawing"
    assert close(result.centroid.position if result.centroid else (), (11.939, 2.724, 0.0))
    poses = by_name(result)
    for name in ("A350VC-A", "7RN4A", "pin_1_doble", "A1UZ3C"):
        x, y = NOMINAL_MM[name]
        assert close(poses[name].position, (x / 1000, y / 1000, 0.0)), name
    for name, yaw in YAW.items():
        assert close(poses[name].orientation, quaternion_from_rpy(0.0, 0.0, yaw)), name


def test_pin_positions_in_the_centroid_frame_with_the_files_distances(model: ElimcoModel) -> None:
    result = get_pin_positions(model, use_centroid=True)
    assert result.frame == "pins_centroid"
    poses = by_name(result)
    # Nominal minus the centroid, in metres.
    assert close(poses["A350VC-A"].position, (-0.334, -0.722, 0.0))
    assert close(poses["7RN4A"].position, (-0.397, -0.344, 0.0))
    assert close(poses["pin_1_doble"].position, (0.068, 0.276, 0.0))
    assert close(poses["A1UZ3C"].position, (0.461, -0.722, 0.0))
    # A918VC1A 40 mm towards A1UZ3B along (0.6, -0.8): (11704, 3928) mm.
    assert close(poses["A918VC1A"].position, (-0.235, 1.204, 0.0))
    # A1UZ3B ends two routes: 25 mm along (-0.6, 0.8) + (-1, 0) normalised, (-2, 1)/sqrt(5).
    assert close(poses["A1UZ3B"].position, (0.461 - 0.05 / ROOT5, 0.276 + 0.025 / ROOT5, 0.0))
    moved = {p.name: p.connector_distance for p in result.pins}
    assert moved == {
        "A918VC1A": 0.04,
        "A350VC-A": 0.0,
        "7RN4A": 0.0,
        "pin_1_doble": 0.0,
        "A1UZ3B": 0.025,
        "A1UZ3C": 0.0,
    }
    double = next(p for p in result.pins if p.name == "pin_1_doble")
    assert (double.is_double, double.double_distance, double.role) == (True, 0.02, "intermediate")


def test_one_connector_distance_for_every_route_end(model: ElimcoModel) -> None:
    result = get_pin_positions(model, use_centroid=False, pin_connector_distance=0.05)
    poses = by_name(result)
    assert close(poses["A918VC1A"].position, (11.71, 3.92, 0.0))
    assert close(poses["A350VC-A"].position, (11.655, 2.002, 0.0))
    assert close(poses["7RN4A"].position, (11.572, 2.42, 0.0))
    assert close(poses["A1UZ3B"].position, (12.4 - 0.1 / ROOT5, 3.0 + 0.05 / ROOT5, 0.0))
    assert close(poses["A1UZ3C"].position, (12.35, 2.002, 0.0))
    # The intermediate pin stands at no connector.
    assert close(poses["pin_1_doble"].position, (12.007, 3.0, 0.0))
    assert all(p.connector_distance == 0.05 for p in result.pins if p.name != "pin_1_doble")
    assert result.message == "6 pins in frame drawing"


def test_a_connector_pin_on_no_route_is_not_moved_and_said_so(model: ElimcoModel) -> None:
    routes = {i: r for i, r in model.routes.items() if i != 1}  # without A350VC-A -> A1UZ3C
    result = get_pin_positions(ElimcoModel(model.pins, model.cables, routes), False, 0.05)
    poses = by_name(result)
    assert close(poses["A350VC-A"].position, (11.605, 2.002, 0.0))
    assert close(poses["A350VC-A"].orientation, (0.0, 0.0, 0.0, 1.0))
    assert (
        result.message
        == "6 pins in frame drawing; on no route, so not moved from the connector: A350VC-A, A1UZ3C"
    )


def test_pin_frames_hang_the_drawing_from_the_centroid_the_manifest_places(model: ElimcoModel) -> None:
    result = pin_frames(model)
    assert result.success
    frames = {f.name: f for f in result.frames}
    assert len(frames) == 9  # drawing, six pins, the two pins of the double pin
    drawing = frames["drawing"]
    assert drawing.parent == "pins_centroid"
    assert close(drawing.pose.position, (-11.939, -2.724, 0.0))
    first = frames[frame_id("A918VC1A")]
    assert (first.name, first.parent) == ("pin_A918VC1A", "pins_centroid")
    assert close(first.pose.position, (-0.235, 1.204, 0.0))
    # The two pins of pin_1_doble lie across the route, 10 mm each side: (-1, 2)/sqrt(5) * 0.01.
    a, b = frames["pin_pin_1_doble_a"], frames["pin_pin_1_doble_b"]
    assert a.parent == b.parent == "pin_pin_1_doble"
    middle = frames["pin_pin_1_doble"].pose
    assert close((middle * a.pose).position, (0.068 - 0.01 / ROOT5, 0.276 + 0.02 / ROOT5, 0.0))
    assert close((middle * b.pose).position, (0.068 + 0.01 / ROOT5, 0.276 - 0.02 / ROOT5, 0.0))


def test_without_a_placed_centroid_the_centroid_hangs_from_the_drawing(model: ElimcoModel) -> None:
    unplaced = ElimcoModel(model.pins, model.cables, model.routes)
    frames = {f.name: f for f in pin_frames(unplaced).frames}
    assert "drawing" not in frames
    assert frames["pins_centroid"].parent == "drawing"
    assert close(frames["pins_centroid"].pose.position, (11.939, 2.724, 0.0))


def test_cable_list(model: ElimcoModel) -> None:
    result = get_cable_list(model)
    assert result.success
    assert [
        (c.name, c.initial_connector, c.final_connector, c.length, c.path, c.wires) for c in result.cables
    ] == [
        ("A4351-1669", "A918VC1A", "A1UZ3B", 1.504, 0, ("A4351-1669B", "A4351-1669W")),
        ("A4351-2401", "A350VC-A", "A1UZ3C", 1.057, 1, ("A4351-2401B", "A4351-2401W")),
        ("A4351-1677", "7RN4A", "A1UZ3B", 1.668, 2, ("A4351-1677B", "A4351-1677W")),
    ]


def test_path_positions_of_figure_19(model: ElimcoModel) -> None:
    result = get_path_positions(model, "A4351-1677")
    assert result.success
    assert (result.cable, result.path, result.frame, result.pins) == (
        "A4351-1677", 2, "pins_centroid", ("7RN4A", "pin_1_doble", "A1UZ3B"),
    )  # fmt: skip
    assert close(result.segment_lengths, (0.775, 0.393))
    assert (result.total_length, result.cable_length) == (1.168, 1.668)
    assert close(result.poses[0].position, (-0.397, -0.344, 0.0))
    assert close(result.poses[2].position, (0.461 - 0.05 / ROOT5, 0.276 + 0.025 / ROOT5, 0.0))
    # The same poses as get_pin_positions in the centroid frame: one pin, one place.
    centroid = by_name(get_pin_positions(model, use_centroid=True))
    assert all(
        close(p.position, centroid[n].position) for n, p in zip(result.pins, result.poses, strict=True)
    )
    assert get_path_positions(model, "2").pins == result.pins


def test_unknown_cable(model: ElimcoModel) -> None:
    result = get_path_positions(model, "A4351-9999")
    assert not result.success
    assert (
        result.message
        == "no path of cable 'A4351-9999'; cables with a path: A4351-1669, A4351-2401, A4351-1677"
    )


def test_a_long_number_is_no_path_index(model: ElimcoModel) -> None:
    result = get_path_positions(model, "9" * 5000)
    assert not result.success
    assert result.message.startswith("no path of cable '999")


def test_empty_model_answers_with_a_message() -> None:
    empty = ElimcoModel({}, {}, {})
    assert (
        get_pin_positions(empty, use_centroid=True).message
        == "no bench pins in the graph: load a pin_info.xml"
    )
    assert not pin_frames(empty).success
    assert not get_cable_list(empty).success


def test_consistency_problems() -> None:
    cables = {"C": ("a", "b")}
    assert consistency_problems({"a", "b"}, cables, [(0, "C", ("a", "b"))]) == []
    assert consistency_problems({"a"}, cables, [(0, "C", ("a", "b"))]) == [
        "path 0 names pin(s) b that no pin_info places"
    ]
    assert consistency_problems({"a", "b"}, cables, [(0, "D", ("a", "b"))]) == [
        "path 0 is of cable D, which cable_info does not list"
    ]
    assert consistency_problems({"a", "b"}, cables, [(0, "C", ("b", "a"))]) == [
        "path 0 runs b to a, but cable C runs a to b"
    ]
    assert consistency_problems({"a", "b"}, None, [(0, "D", ("a", "b"))]) == []


def test_the_profile_lists_its_services() -> None:
    assert [s.name for s in services_for("elimco")] == [
        "load_files", "get_pin_positions", "pin_frames", "get_cable_list", "get_path_positions",
    ]  # fmt: skip


# --- load_files ---------------------------------------------------------------------------------------


@pytest.fixture
def served(tmp_path: Path) -> Iterator[tuple[Session, Path]]:
    """The example built in memory from a copy, and a directory of files to load."""
    cell = tmp_path / "cell"
    shutil.copytree(BENCH, cell)
    graph = KnowledgeGraph.build(cell / "manifest.toml")
    session = Session(graph.cell_model(), kg=graph)
    incoming = tmp_path / "incoming"
    incoming.mkdir()
    yield session, incoming
    graph.close()


def _pin_info(incoming: Path, name: str, old: str, new: str) -> Path:
    text = (BENCH / "pin_info.xml").read_text(encoding="utf-8")
    assert old in text
    path = incoming / name
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


def _a1uz3c(session: Session) -> tuple[float, ...]:
    result = call(session, "get_pin_positions", {"use_centroid": "false"})
    return next(p.pose.position for p in result.pins if p.name == "A1UZ3C")


def test_load_files_replaces_the_pins_online(served: tuple[Session, Path]) -> None:
    session, incoming = served
    assert close(_a1uz3c(session), (12.4, 2.002, 0.0))
    moved = _pin_info(incoming, "pins-v2.xml", 'x="12400" y="2002"', 'x="12300" y="2002"')
    result = call(session, "load_files", {"paths": f" {moved} "})
    assert result.success, result.message
    assert result.sources == ("pin_info.xml",)
    # The new file took the place of the old one: one pin source, the new content.
    assert close(_a1uz3c(session), (12.3, 2.002, 0.0))
    pin_sources = [s for s in session.kg.sources() if s["kind"] == "pin-info"]
    assert [s["path"] for s in pin_sources] == ["pin_info.xml"]
    assert len(session.kg.query("SELECT ?p WHERE { ?p a ck:BenchPin }")) == 6


def test_load_files_of_several_kinds(served: tuple[Session, Path]) -> None:
    session, incoming = served
    pins = _pin_info(incoming, "pin_info.xml", 'x="12400" y="2002"', 'x="12300" y="2002"')
    paths = incoming / "path_info.xml"
    paths.write_text(
        (BENCH / "path_info.xml").read_text(encoding="utf-8").replace("795", "695"), encoding="utf-8"
    )
    result = call(session, "load_files", {"paths": f"{pins},{paths}"})
    assert result.success, result.message
    assert set(result.sources) == {"pin_info.xml", "path_info.xml"}
    assert call(session, "get_path_positions", {"cable": "A4351-2401"}).total_length == 0.695


@pytest.mark.parametrize(
    ("files", "message"),
    [
        (["missing.xml"], "cannot read the file"),
        (["bad.xml"], "malformed XML"),
        (["path_info.xml", "bad.xml"], "malformed XML"),
        (["short.xml"], "path 1 names pin(s) A1UZ3C that no pin_info places"),
        (["pin_info.xml", "again.xml"], "a second pin-info file in one load"),
        (["hoses.csv"], "a hose file, not one of"),
    ],
)
def test_a_bad_load_changes_nothing(served: tuple[Session, Path], files: list[str], message: str) -> None:
    session, incoming = served
    _pin_info(incoming, "pin_info.xml", 'x="12400" y="2002"', 'x="12300" y="2002"')
    _pin_info(incoming, "again.xml", 'x="12400" y="2002"', 'x="12200" y="2002"')
    _pin_info(incoming, "short.xml", '<pin name="A1UZ3C" role="final" x="12400" y="2002"/>', "")
    (incoming / "bad.xml").write_text("<pin_info>\n<pin name='X'", encoding="utf-8")
    shutil.copy(EXAMPLES / "enki-hose" / "hoses.csv", incoming / "hoses.csv")
    (incoming / "path_info.xml").write_text(
        (BENCH / "path_info.xml").read_text(encoding="utf-8").replace("795", "695"), encoding="utf-8"
    )
    before = sorted(
        (str(q.subject), str(q.predicate), str(q.object), str(q.graph_name)) for q in session.kg.quads()
    )
    before = [q for q in before if "ingestedAt" not in q[1]]
    result = call(session, "load_files", {"paths": ",".join(str(incoming / f) for f in files)})
    assert not result.success
    assert result.message.startswith("nothing loaded: ") and message in result.message
    after = sorted(
        (str(q.subject), str(q.predicate), str(q.object), str(q.graph_name)) for q in session.kg.quads()
    )
    assert [q for q in after if "ingestedAt" not in q[1]] == before
    assert close(_a1uz3c(session), (12.4, 2.002, 0.0))


def test_load_files_needs_a_writable_graph(tmp_path: Path) -> None:
    store = tmp_path / "store"
    KnowledgeGraph.build(BENCH / "manifest.toml", store).close()
    with KnowledgeGraph.open(store) as graph:
        session = Session(graph.cell_model(), kg=graph)
        result = call(session, "load_files", {"paths": str(BENCH / "pin_info.xml")})
    assert not result.success
    assert "read-only" in result.message


def test_load_files_without_paths(served: tuple[Session, Path]) -> None:
    session, _ = served
    result = call(session, "load_files", {"paths": " , "})
    assert (result.success, result.message) == (
        False,
        "no file given: paths is a comma-separated list of files",
    )


@pytest.mark.parametrize(
    ("paths", "message"),
    [
        ("pin\x00info.xml", "cannot read the file: a NUL byte in its name"),
        ("~no-such-user-of-cadkg/pin_info.xml", "no home directory for the user its '~' names"),
    ],
)
def test_load_files_with_an_impossible_path(served: tuple[Session, Path], paths: str, message: str) -> None:
    session, _ = served
    result = call(session, "load_files", {"paths": paths})
    assert not result.success
    assert result.message.startswith("nothing loaded: ") and message in result.message


# --- named queries ------------------------------------------------------------------------------------


def test_named_query_of_a_route(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elimco-route", cable="A4351-1677").rows
    assert [(r["stop"], r["pin"], r["role"], r["x"], r["y"]) for r in rows] == [
        (1, "7RN4A", "initial", 11.542, 2.38),
        (2, "pin_1_doble", "intermediate", 12.007, 3.0),
        (3, "A1UZ3B", "final", 12.4, 3.0),
    ]
    assert [r["segmentM"] for r in rows] == [None, Decimal("0.775"), Decimal("0.393")]


def test_named_query_of_the_cores_of_a_cable(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elimco-wires-of-cable", cable="A4351-2401").rows
    assert [(r["wire"], r["origin"], r["destination"], r["lengthM"]) for r in rows] == [
        ("A4351-2401B", "A350VC-A:B", "A1UZ3C:13", Decimal("1.057")),
        ("A4351-2401W", "A350VC-A:A", "A1UZ3C:14", Decimal("1.057")),
    ]


def test_the_example_graph_validates(kg: KnowledgeGraph) -> None:
    # SHACL shapes and the cross-file checks: every wire has one from-pin and one to-pin ...
    assert validate(kg) == []


def test_load_files_into_a_store_opened_for_writing_persists(tmp_path: Path) -> None:
    store = tmp_path / "store"
    KnowledgeGraph.build(BENCH / "manifest.toml", store).close()
    moved = _pin_info(tmp_path, "pin_info.xml", 'x="12400" y="2002"', 'x="12300" y="2002"')
    with KnowledgeGraph.open(store, read_only=False) as graph:
        result = call(Session(graph.cell_model(), kg=graph), "load_files", {"paths": str(moved)})
        assert result.success, result.message
    with KnowledgeGraph.open(store) as graph:
        assert close(_a1uz3c(Session(graph.cell_model(), kg=graph)), (12.3, 2.002, 0.0))
