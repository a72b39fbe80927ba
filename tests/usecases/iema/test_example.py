"""The bundled IEMA cabinet end to end: every reader, the derived geometry, every Table 1 service.

Values asserted here are read from the example's own files (see its README); the
hand-computed poses are in test_iema_example_values.py.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from pathlib import Path

import pytest

import cadkg.usecases.iema.cursors as cursors
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.iema import answers as iema
from cadkg.usecases.iema.derive.cabinet import CellModel
from tests.conftest import IEMA, ROOT

VRML = IEMA.parent / "manifest-vrml.toml"
KOMAX = IEMA.parent / "manifest-komax.toml"


def _model(manifest: object) -> Iterator[CellModel]:
    kg = KnowledgeGraph.build(manifest)  # type: ignore[arg-type]
    yield kg.cell_model()
    kg.close()


@pytest.fixture(scope="module")
def model() -> Iterator[CellModel]:
    yield from _model(IEMA)


@pytest.fixture(scope="module")
def vrml_model() -> Iterator[CellModel]:
    yield from _model(VRML)


@pytest.fixture(scope="module")
def komax_model() -> Iterator[CellModel]:
    yield from _model(KOMAX)


def test_size_of_the_example(model: CellModel) -> None:
    placed = [g for g in model.components.values() if g.original is not None]
    on_rails = [g for g in placed if g.rail is not None]
    assert [(r.label, len(r.components)) for r in model.rails] == [
        ("RAIL1", 17),
        ("RAIL2", 14),
        ("RAIL3", 10),
    ]
    assert len(on_rails) == 41
    assert sum(g.terminal_block for g in placed) >= 2
    assert len(model.steps) >= 60


def test_every_placed_component_answers_every_label_service(model: CellModel) -> None:
    for label, geometry in model.components.items():
        if geometry.original is None:
            continue
        for service in (iema.cad_service, iema.full_cad_service, iema.cluster_service, iema.cad_reference):
            result = service(model, label)
            assert result.success, (service.__name__, label, result.message)
        assert iema.get_terminal_data(model, label).success is geometry.terminal_block


def test_figure_3_wires_are_the_first_in_sequence(model: CellModel) -> None:
    first = model.steps[0]
    assert (first.wire, first.origin.label, first.origin.pin) == ("1500.51", "F1500.1", "14")
    assert (first.destination.label, first.destination.pin) == ("Q1500.1", "A1")
    assert [s.wire for s in model.steps[:3]] == ["1500.51", "1500.53", "1500.55"]


def test_every_wire_end_has_pin_data(model: CellModel) -> None:
    # The example is complete; the flagging of missing data is tested on tests/data/cells/mini.
    assert [s.wire for s in model.steps if s.missing] == []


# Hand-computed in the example's README (cabinet frame, metres): origin, size, corner (the box's
# minimum corner), target (0.15 m in front of the front face's centre).
POSES = {
    "F1500.1": ((0.07, 0.56, 0.0075), (0.054, 0.097, 0.097), (0.07, 0.56, 0.0075), (0.097, 0.6085, 0.2545)),
    "SSB-10Q1": (
        (0.5544, 0.56, 0.0075),
        (0.0898, 0.0359, 0.07448),
        (0.5544, 0.56, 0.0075),
        (0.53645, 0.6049, 0.23198),
    ),
    "B0040.3": (
        (0.4178, 0.86, 0.0075),
        (0.0175, 0.06, 0.04),
        (0.4178, 0.86, 0.0075),
        (0.40905, 0.83, 0.1975),
    ),
    "E0040.1": ((0.556, 0.02, 0.0), (0.148, 0.148, 0.067), (0.542, 0.006, 0.0), (0.616, 0.08, 0.217)),
    "Q0010": ((0.07, 0.86, 0.0075), (0.054, 0.085, 0.103), (0.07, 0.86, 0.0075), (0.097, 0.9025, 0.2605)),
}
PINS = {
    ("SSB-10Q1", "1"): ((0.5454, 0.5685, 0.05246), (0.5544, 0.56, 0.0075)),
    ("SSB-10Q1", "2"): ((0.5454, 0.6413, 0.05246), (0.5454, 0.6363, 0.04446)),
    ("F1500.1", "13"): ((0.1195, 0.647, 0.0675), (0.1195, 0.642, 0.0595)),
    ("B0040.3", "1"): ((0.40905, 0.81, 0.0415), (0.40905, 0.815, 0.0335)),
    ("X1500", "1:a"): ((0.2675, 0.3355, 0.055), (0.2675, 0.3305, 0.047)),
}


def _near(a: tuple[float, ...] | None, b: tuple[float, ...]) -> bool:
    return a is not None and all(math.isclose(x, y, abs_tol=1e-6) for x, y in zip(a, b, strict=True))


@pytest.mark.parametrize("label", sorted(POSES))
def test_hand_computed_component_poses(model: CellModel, label: str) -> None:
    origin, dims, corner, target = POSES[label]
    result = iema.cad_service(model, label)
    assert result.success
    assert result.original_pose and _near(result.original_pose.position, origin)
    assert _near(result.dimensions, dims)
    assert result.corner_pose and _near(result.corner_pose.position, corner)
    assert result.target_pose and _near(result.target_pose.position, target)


@pytest.mark.parametrize(("label", "pin"), sorted(PINS))
def test_hand_computed_pin_frames(model: CellModel, label: str, pin: str) -> None:
    screw, hole = PINS[(label, pin)]
    found = model.components[label].pins[pin]
    assert found.screw and _near(found.screw.position, screw)
    assert found.hole and _near(found.hole.position, hole)


def test_hand_computed_terminal_blocks(model: CellModel) -> None:
    x1500 = iema.get_terminal_data(model, "X1500")
    # The end stops before and after the 12 terminals (0.005 each) are part of the strip; its
    # start is the first end stop's corner (the diagram's pin 0 row), as in the node.
    assert math.isclose(x1500.length, 0.0754) and math.isclose(x1500.height, 0.0675)
    assert x1500.terminal_start and _near(x1500.terminal_start.position, (0.2599, 0.28, 0.0075))
    # 12 terminals of two levels each, in block order.
    assert len(x1500.pins) == 24 and x1500.pins[:4] == ("1:a", "1:b", "2:a", "2:b")
    x1600 = iema.get_terminal_data(model, "X1600")
    assert math.isclose(x1600.length, 0.028) and math.isclose(x1600.height, 0.06)


def test_vrml_scene_gives_the_same_geometry_as_x3d(model: CellModel, vrml_model: CellModel) -> None:
    assert model.components.keys() == vrml_model.components.keys()
    for label, a in model.components.items():
        b = vrml_model.components[label]
        assert (a.original is None) == (b.original is None), label
        if a.original is None or b.original is None:
            continue
        assert a.original.close_to(b.original, 1e-9), label
        assert a.corner is not None and b.corner is not None and a.corner.close_to(b.corner, 1e-9), label
        assert a.rail == b.rail, label
        for name, pin in a.pins.items():
            other = b.pins[name]
            if pin.screw is not None:
                assert other.screw is not None and pin.screw.close_to(other.screw, 1e-9), (label, name)
    assert [r.components for r in model.rails] == [r.components for r in vrml_model.rails]


def test_komax_export_gives_the_same_sequence(model: CellModel, komax_model: CellModel) -> None:
    def ends(m: CellModel) -> list[tuple[str, str, str, str, str]]:
        return [
            (s.wire, s.origin.label, s.origin.pin, s.destination.label, s.destination.pin) for s in m.steps
        ]

    assert ends(komax_model) == ends(model)
    assert [s.ducts for s in komax_model.steps] == [s.ducts for s in model.steps]


def test_rails_are_ordered_along_x(model: CellModel) -> None:
    for rail in model.rails:
        xs = [model.components[c].rail_position for c in rail.components]
        assert xs == sorted(xs), rail.label  # type: ignore[type-var]


def test_providers_walk_every_robot_wire_once(model: CellModel) -> None:
    session = Session(model)
    seen = []
    while not (step := cursors.group_connection_provider(session)).end:
        seen.append(step.list_position)
    robot = [s.position for s in model.steps if s.performer == "robot"]
    human = [s.position for s in model.steps if s.performer == "human"]
    assert seen == robot and human and not set(seen) & set(human)
    assert 93 in human  # the overlay assigns operation 93 (from 0) to a human


def test_every_service_runs_on_the_example(model: CellModel) -> None:
    session = Session(model)
    args = {
        "label": "F1500.1",
        "detected_pose": "0.1,0.6,0.0075,0,0,0",
        "cad_pose": "0.1,0.6,0.25,3.14159265,0,0",
        "occupancy": "false",
        "data": "1500.51",
        "source": "orig",
        "connection_list": "lista-cablaggio.csv",
    }
    for service in services_for("iema"):
        name = service.name
        params = {k: args[k] for k in service.params if k in args}
        if name == "get_terminal_data":
            params["label"] = "=-X1600"
        result = call(session, name, params)
        assert getattr(result, "success", True) is not False, name
        assert getattr(result, "end", False) is False, name


def test_keypoints_run_through_the_ducts(model: CellModel) -> None:
    routed = [s for s in model.steps if s.ducts and s.keypoints]
    assert routed
    for step in routed:
        assert step.origin.hole is not None and step.destination.hole is not None
        assert step.keypoints[0].position == step.origin.hole.position
        assert step.keypoints[-1].position == step.destination.hole.position
        assert len(step.keypoints) >= 3
        total = sum(math.dist(a.position, b.position) for a, b in itertools.pairwise(step.keypoints))
        assert total >= math.dist(step.keypoints[0].position, step.keypoints[-1].position) - 1e-9


def test_relay_pins_come_from_the_parts_management_export_alone(model: CellModel) -> None:
    # components.xml gives the relay 6400170 no couple; pins.xml gives its connection points.
    result = iema.cad_service(model, "K1510.1")
    assert result.success
    pins = {p.pin: p for p in result.pins}
    assert {"A1", "A2", "11", "14"} <= pins.keys()
    assert all(p.screw is None and p.hole is not None for p in pins.values())
    # Hand-computed in the README: item origin (0.5889, 0.56, 0.0075) + (3.1, 65, 42) mm.
    a1 = pins["A1"].hole
    assert a1 is not None and _near(a1.position, (0.592, 0.625, 0.0495))
    assert _near(a1.orientation, (0.0, 0.0, 0.0, 1.0))  # wires enter along the cabinet's z
    screws = iema.get_item_screw_service(model, "K1510.1", model.components["K1510.1"].original)  # type: ignore[arg-type]
    assert screws.success and "A1" in screws.pins
    relay_steps = [s for s in model.steps if "K1510.1" in (s.origin.label, s.destination.label)]
    assert relay_steps and not any(s.missing for s in relay_steps)


def test_without_the_parts_management_export_the_relay_has_no_pin_data(tmp_path: Path) -> None:
    text = IEMA.read_text(encoding="utf-8").replace('[[source]]\npath = "pins.xml"\n\n', "")
    manifest = IEMA.parent / "without-pins.toml"
    try:
        manifest.write_text(text, encoding="utf-8")
        without = next(_model(manifest))
    finally:
        manifest.unlink()
    assert all(p.missing for p in without.components["K1510.1"].pins.values())


def test_a_model_corner_item_replaces_the_computed_corner(model: CellModel) -> None:
    # The CPU's model gives its own corner (0, 0.015, 0.075): origin (0.5533, 0.86, 0.0075) + it.
    result = iema.cad_service(model, "A0080.1")
    assert result.corner_pose is not None and _near(result.corner_pose.position, (0.5533, 0.875, 0.0825))
    assert result.original_pose is not None and _near(result.original_pose.position, (0.5533, 0.86, 0.0075))


def test_item_frames_and_markers_are_in_the_graph() -> None:
    kg = KnowledgeGraph.build(IEMA)
    try:
        frames = kg.query(
            "SELECT DISTINCT ?code ?name WHERE {"
            " ?m ck:commercialCode ?code ; ck:hasItemFrame ?f . ?f ck:label ?name }"
        ).rows
        markers = kg.query("SELECT DISTINCT ?id ?x WHERE { ?i ck:cadId ?id ; ck:markerPose/ck:tx ?x }").rows
    finally:
        kg.close()
    assert sorted((r["code"], r["name"]) for r in frames) == [
        ("6503372", "marker"),
        ("6503372", "visual"),
        ("6503515", "marker"),
        ("6503515", "visual"),
        ("6800212", "corner"),
    ]
    assert sorted(r["id"] for r in markers) == [
        "ID000045",
        "ID000048",
        "ID000049",
        "ID000052",
        "ID000054",
        "ID000056",
    ]


def test_the_older_forms_give_the_same_cell(model: CellModel, tmp_path: Path) -> None:
    """The ID table without `=` and root row, the list with CRLF, a four-line preamble and `;` paths."""
    import shutil

    cell = tmp_path / "example"
    shutil.copytree(IEMA.parent, cell)
    for name in ("ids.wri", "lista-cablaggio.csv"):
        shutil.copyfile(ROOT / "tests" / "data" / "iema-old-forms" / name, cell / name)
    assert (cell / "ids.wri").read_bytes() != (IEMA.parent / "ids.wri").read_bytes()
    with KnowledgeGraph.build(cell / "manifest.toml") as kg:
        old = kg.cell_model()
    assert set(model.components) - set(old.components) == {"1"}  # the root item row
    for label, component in old.components.items():
        assert (component.original, component.target, component.corner) == (
            model.components[label].original,
            model.components[label].target,
            model.components[label].corner,
        )
    assert sum(s.path.count(";") for s in old.steps) > 0
    assert [(s.wire, s.path, s.ducts, s.keypoints, s.performer) for s in old.steps] == [
        (s.wire, s.path.replace("'", ";"), s.ducts, s.keypoints, s.performer) for s in model.steps
    ]


def test_a_diagram_without_start_rows_places_the_same_terminals(model: CellModel, tmp_path: Path) -> None:
    """The example's terminal diagram as it was, without pin 0 rows, and the ID table without end stops."""
    import shutil

    cell = tmp_path / "example"
    shutil.copytree(IEMA.parent, cell)
    old_forms = ROOT / "tests" / "data" / "iema-old-forms"
    shutil.copyfile(old_forms / "schema-morsetti.ods", cell / "schema-morsetti.ods")
    wri = (IEMA.parent / "ids.wri").read_bytes().split(b"\r\n")
    (cell / "ids.wri").write_bytes(b"\r\n".join(line for line in wri if not line.endswith(b"\t6013270")))
    with KnowledgeGraph.build(cell / "manifest.toml") as kg:
        old = kg.cell_model()
    blocks = ["X0030.1", "X0030.2", "X0031", "X1500", "X1600", "X1700"]
    for label in blocks:
        pins, now = old.components[label].pins, model.components[label].pins
        assert pins and pins.keys() == now.keys(), label
        for name, pin in pins.items():
            other = now[name].screw
            assert pin.screw is not None and other is not None, (label, name)
            assert pin.screw.close_to(other, 1e-9), (label, name)
    # Without a start row the strip starts at its first terminal's corner.
    start = iema.get_terminal_data(old, "X1500").terminal_start
    assert start is not None and _near(start.position, (0.2649, 0.28, 0.0075))


def _same_pose(a: object, b: object) -> bool:
    """Equal to a micrometre: scene.x3d writes angles with 8 decimals, QE01_cad.x3d a double's."""
    if a is None or b is None:
        return a is b
    p, q = a.position, b.position  # type: ignore[attr-defined]
    r, s = a.orientation, b.orientation  # type: ignore[attr-defined]
    return all(math.isclose(x, y, abs_tol=1e-6) for x, y in zip(p, q, strict=True)) and (
        all(math.isclose(x, y, abs_tol=1e-6) for x, y in zip(r, s, strict=True))
        or all(math.isclose(x, -y, abs_tol=1e-6) for x, y in zip(r, s, strict=True))
    )


def test_the_scene_in_the_nodes_dialect_gives_the_same_cell(model: CellModel) -> None:
    """QE01_cad.x3d: millimetres, z up, one root item, faces directly in the items."""
    with KnowledgeGraph.build(IEMA.parent / "manifest-node.toml") as kg:
        node = kg.cell_model()
    # The root item ID000001 (=-1) has the plate's faces there and none in scene.x3d.
    assert node.components["1"].original is not None and model.components["1"].original is None
    assert set(node.components) == set(model.components)
    for label, component in model.components.items():
        if label == "1":
            continue
        other = node.components[label]
        for pose in ("original", "target", "corner"):
            assert _same_pose(getattr(component, pose), getattr(other, pose)), (label, pose)
    assert len(node.steps) == len(model.steps) == 110
    for ours, theirs in zip(model.steps, node.steps, strict=True):
        assert (ours.wire, ours.ducts, ours.performer) == (theirs.wire, theirs.ducts, theirs.performer)
        assert ours.origin is not None and theirs.origin is not None
        assert ours.destination is not None and theirs.destination is not None
        for a, b in ((ours.origin, theirs.origin), (ours.destination, theirs.destination)):
            assert _same_pose(a.screw, b.screw) and _same_pose(a.hole, b.hole), (ours.wire, a.label, a.pin)
        assert all(_same_pose(a, b) for a, b in zip(ours.keypoints, theirs.keypoints, strict=True))
