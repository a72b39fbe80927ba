"""The reference IEMA node's conventions, on copies of tests/data/cells/mini and the example.

Values worked by hand: the mini cell's wires W1-W4 (tests/usecases/iema/test_services.py) and the
example's README (section "The reference node's conventions").
"""

from __future__ import annotations

import shutil
import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import plan_cell
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.usecases.iema import answers, cursors
from cadkg.usecases.iema.robot_scope import scope_reason
from tests.conftest import ROOT
from tests.ingest.workbooks import replace_in_member, write_ods, write_xlsx

MINI = ROOT / "tests" / "data" / "cells" / "mini"
EXAMPLE = ROOT / "examples" / "iema-switchgear"


def _mini(tmp_path: Path, rows: dict[tuple[int, int], str] | None = None, derive: str = "") -> Path:
    """A copy of the mini cell; ``rows`` replaces cells of connections.tsv ((line, column) → text;
    column 1 is the origin's zone, 4 the destination's)."""
    cell = tmp_path / "mini"
    shutil.copytree(MINI, cell)
    lines = (cell / "connections.tsv").read_text(encoding="utf-8").splitlines()
    for (line, column), text in (rows or {}).items():
        cells = lines[line - 1].split("\t")
        cells[column] = text
        lines[line - 1] = "\t".join(cells)
    (cell / "connections.tsv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    manifest = cell / "manifest.toml"
    if derive:
        text = manifest.read_text(encoding="utf-8")
        manifest.write_text(text.replace("[derive]\n", f"[derive]\n{derive}\n"), encoding="utf-8")
    return manifest


@pytest.fixture
def built() -> Iterator[list[KnowledgeGraph]]:
    graphs: list[KnowledgeGraph] = []
    yield graphs
    for kg in graphs:
        kg.close()


def _build(built: list[KnowledgeGraph], manifest: Path) -> KnowledgeGraph:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kg = KnowledgeGraph.build(manifest)
    built.append(kg)
    return kg


def _served(kg: KnowledgeGraph) -> list[str]:
    session = Session(kg.cell_model())
    wires = []
    while not (wire := cursors.group_connection_provider(session)).end:
        wires.append(wire.wire)
    return wires


# -- 4. which wires the robot is handed ------------------------------------------------------
def test_the_scope_rule_names_its_value() -> None:
    zones = ("Q", "QE")
    assert scope_reason(("Q", "QE"), ("K1", "X1"), zones, {"K1"}) is None  # the zones decide, not the labels
    assert (
        scope_reason(("P", "Q"), ("K1",), zones, {"K1"}) == "origin zone P is not among the robot zones Q, QE"
    )
    # Both ends must be reachable: a wire from the cabinet to a motor (zone B) is a person's.
    assert scope_reason(("Q", "B"), ("K1",), zones, {"K1"}) == (
        "destination zone B is not among the robot zones Q, QE"
    )
    assert scope_reason(("Q", None), ("K1", "M1"), zones, {"K1"}) is None  # an end without a zone: not judged
    assert scope_reason((None, None), ("K1", "M1"), zones, {"K1"}) == (
        "label M1 is not in the CAD (no ID table row)"
    )
    assert scope_reason(("", ""), ("K1",), zones, {"K1"}) is None


def test_a_wire_of_another_zone_goes_to_a_person_with_the_reason(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # Line 3 of connections.tsv is W2 (K1:13 → X1:2:b); its origin zone becomes P.
    kg = _build(built, _mini(tmp_path, {(3, 1): "P"}))
    assert _served(kg) == ["W1", "W4"]  # W3 is assigned to a person by the overlay
    w2 = next(c for c in answers.full_cad_service(kg.cell_model(), "K1").connections if c.wire == "W2")
    assert (w2.performer, w2.reason) == ("human", "origin zone P is not among the robot zones Q, QE")
    rows = kg.query(
        """SELECT ?number ?who ?why WHERE { GRAPH ?g { ?w ck:assignedTo ?who ; ck:assignmentReason ?why }
             ?w ck:wireNumber ?number }"""
    ).rows
    assert [(r["number"], r["who"].rsplit("#")[-1], r["why"]) for r in rows] == [
        ("W2", "human", "origin zone P is not among the robot zones Q, QE")
    ]
    findings = [str(f) for f in validate(kg, shacl=False) if f.check == "wire-for-a-person"]
    assert findings == [
        "connections.tsv:3: warning: wire W2 is given to a person:"
        " origin zone P is not among the robot zones Q, QE [wire-for-a-person]"
    ]


def test_a_wire_whose_destination_is_outside_the_zones_goes_to_a_person(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # Line 4 is W3 (a person's by the overlay), line 5 W4: its destination zone becomes B (a motor).
    kg = _build(built, _mini(tmp_path, {(5, 4): "B"}))
    assert _served(kg) == ["W1", "W2"]
    w4 = next(c for c in answers.full_cad_service(kg.cell_model(), "K1").connections if c.wire == "W4")
    assert (w4.performer, w4.reason) == ("human", "destination zone B is not among the robot zones Q, QE")
    findings = [str(f) for f in validate(kg, shacl=False) if f.check == "wire-for-a-person"]
    assert findings == [
        "connections.tsv:5: warning: wire W4 is given to a person:"
        " destination zone B is not among the robot zones Q, QE [wire-for-a-person]"
    ]
    step = next(s for s in plan_cell(kg).steps if s.task.label == "W4")
    assert (step.decision.rule, step.decision.reason) == (
        "zone",
        "destination zone B is not among the robot zones Q, QE (the default [derive] robot_zones)",
    )


def test_the_manifest_names_the_robot_zones(tmp_path: Path, built: list[KnowledgeGraph]) -> None:
    kg = _build(built, _mini(tmp_path, {(3, 1): "P"}, 'robot_zones = ["Q", "P"]'))
    assert _served(kg) == ["W1", "W2", "W4"]
    assert sorted(r["z"] for r in kg.query("SELECT ?z WHERE { ?c ck:robotZone ?z }")) == ["P", "Q"]


def test_a_list_without_zones_hands_the_robot_the_wires_between_cad_labels(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # W4 ends on K9, which no ID table row names.
    kg = _build(built, _mini(tmp_path, {(line, column): "" for line in (2, 3, 4, 5) for column in (1, 4)}))
    assert _served(kg) == ["W1", "W2"]
    w4 = answers.full_cad_service(kg.cell_model(), "K1").connections[-1]
    assert (w4.wire, w4.reason) == ("W4", "label K9 is not in the CAD (no ID table row)")


# -- 8. an end without data keeps its wire --------------------------------------------------
def _as_workbook(tmp_path: Path, form: str) -> Path:
    """The mini cell with its list as a workbook whose W2 destination (F3) lost its value."""
    manifest = _mini(tmp_path)
    cell = manifest.parent
    rows: list[list[object]] = [
        line.split("\t") for line in (cell / "connections.tsv").read_text(encoding="utf-8").splitlines()
    ]
    if form == "ods":
        rows[2][5] = None  # LibreOffice's form of the formula EPLAN could not evaluate
        write_ods(cell / "connections.ods", [("Lista", rows)])
    else:
        rows[2][5] = "LOST"
        path = write_xlsx(cell / "connections.xlsx", [("Lista", rows)])
        replace_in_member(
            path,
            "xl/worksheets/sheet1.xml",
            b'<c r="F3" t="inlineStr"><is><t>LOST</t></is></c>',
            b'<c r="F3" t="e"><f>-basta</f><v>#NAME?</v></c>',
        )
    text = manifest.read_text(encoding="utf-8").replace(
        'path = "connections.tsv"', f'path = "connections.{form}"'
    )
    manifest.write_text(text.replace('kind = "connection-list"\n', ""), encoding="utf-8")
    return manifest


@pytest.mark.parametrize("form", ["xlsx", "ods"])
def test_a_lost_wire_end_keeps_its_wire_flagged(
    tmp_path: Path, built: list[KnowledgeGraph], form: str
) -> None:
    kg = _build(built, _as_workbook(tmp_path, form))
    session = Session(kg.cell_model())
    assert cursors.reset_to_connection_list(session, 1).success
    w2 = cursors.group_connection_provider(session)
    assert (w2.wire, w2.list_position, w2.missing_pin_data) == ("W2", 1, "?:?")
    end = cursors.full_connection_provider(session, True)
    assert end.wire == "W4"  # the cursor moved past W2 (W3 is a person's)
    assert [f.message for f in validate(kg, shacl=False) if f.check == "lost-wire-end"] == [
        "wire W2: the list gives no reference for its destination; it is kept with missing pin data"
    ]


# -- 1 and 2 on the example: positions from 0, duct paths as written --------------------------
def test_positions_count_from_0_and_paths_are_as_written(built: list[KnowledgeGraph]) -> None:
    kg = _build(built, EXAMPLE / "manifest.toml")
    session = Session(kg.cell_model())
    first = cursors.group_connection_provider(session)
    assert first.origin is not None and first.destination is not None
    assert (first.list_position, first.origin.label, first.origin.pin) == (0, "F1500.1", "14")
    assert (first.destination.label, first.destination.pin, first.wire_path) == ("Q1500.1", "A1", "=-CN2")
    fourth = next(s for s in session.model.steps if s.position == 3)
    assert (fourth.wire, fourth.path) == ("1500.50", "=-CN2'=-CN5'=-CN3")  # as gearbox_demo writes it
    assert cursors.reset_to_connection_list(session, 0, "dest").success
    end = cursors.full_connection_provider(session)
    assert (end.source, end.label, end.pin, end.list_position) == ("dest", "Q1500.1", "A1", 0)


def test_a_semicolon_separated_duct_path_gives_the_same_keypoints(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # The example writes gearbox_demo's "'", gearbox_zero's list and the Komax export ';'.
    cell = tmp_path / "example"
    shutil.copytree(EXAMPLE, cell)
    listing = cell / "lista-cablaggio.csv"
    listing.write_bytes(listing.read_bytes().replace(b"'=-", b";=-"))
    quotes = _build(built, EXAMPLE / "manifest.toml").cell_model()
    semicolons = _build(built, cell / "manifest.toml").cell_model()
    several = [s for s in quotes.steps if len(s.ducts) > 1]
    assert several and several[0].path.count("'") == len(several[0].ducts) - 1
    by_wire = {s.iri: s for s in semicolons.steps}
    for step in quotes.steps:
        other = by_wire[step.iri]
        assert other.path == step.path.replace("'", ";")
        assert (other.ducts, other.keypoints) == (step.ducts, step.keypoints)


# -- 6 and 7 on the mini cell: component poses, the node's own service names --------------
def test_the_group_provider_gives_each_end_its_component_target(built: list[KnowledgeGraph]) -> None:
    kg = _build(built, MINI / "manifest.toml")
    w1 = cursors.group_connection_provider(Session(kg.cell_model()))
    assert w1.origin is not None and w1.destination is not None
    assert w1.origin.component_pose is not None and w1.destination.component_pose is not None
    # K1's box front z 0.0675 + 0.15; X1's 0.0475 + 0.15; both over their front faces' centres.
    assert w1.origin.component_pose.position == pytest.approx((0.165, 0.54, 0.2175))
    assert w1.destination.component_pose.position == pytest.approx((0.256, 0.525, 0.1975))


def test_get_item_screw_targets_moves_the_pins_with_the_detected_target(built: list[KnowledgeGraph]) -> None:
    from cadkg.geometry.poses import Pose

    model = _build(built, MINI / "manifest.toml").cell_model()
    # K1's target (0.165, 0.54, 0.2175) detected 0.12 m lower: every pin 0.12 m lower.
    moved = answers.get_item_screw_targets(model, "K1", Pose((0.165, 0.42, 0.2175), (1.0, 0.0, 0.0, 0.0)))
    assert moved.success and moved.pins == ("13", "A1", "A2")
    assert moved.screws[1].position == pytest.approx((0.155, 0.45, 0.0675))
    assert not answers.get_item_screw_targets(model, "NOPE", Pose()).success


def test_full_cad_service_by_cad_item_gives_the_nodes_fields(built: list[KnowledgeGraph]) -> None:
    model = _build(built, MINI / "manifest.toml").cell_model()
    # ID000003 is K1's auxiliary contact, which carries pin 13: W2 K1:13 → X1:2:b (terminal item ID000005).
    result = answers.full_cad_service(model, cad_item="ID000003")
    assert result.success and len(result.connections) == 1
    w2 = result.connections[0]
    assert (w2.wire, w2.source, w2.pin, w2.target_item, w2.target_pin, w2.list_position) == (
        "W2",
        "orig",
        "13",
        "ID000005",
        "2:b",
        1,
    )
    assert w2.hole_pose is not None and w2.hole_pose.position == pytest.approx((0.175, 0.505, 0.0575))
    by_label = answers.full_cad_service(model, "K1").connections
    assert [(c.wire, c.source) for c in by_label] == [("W1", "orig"), ("W2", "orig"), ("W4", "orig")]
    assert not answers.full_cad_service(model, cad_item="ID999999").success


def test_the_older_provider_and_the_display_switch(built: list[KnowledgeGraph]) -> None:
    from cadkg.usecases.iema.services import cabinet_frames

    session = Session(_build(built, MINI / "manifest.toml").cell_model())
    ends = [cursors.connection_provider_service(session) for _ in range(3)]
    assert [(e.wire, e.source) for e in ends] == [("W1", "orig"), ("W1", "dest"), ("W2", "orig")]
    shown = len(cabinet_frames(session))
    assert shown and cursors.gearbox_display(session).display is False
    assert cabinet_frames(session) == []
    assert cursors.gearbox_display(session).display is True and len(cabinet_frames(session)) == shown


# -- 4, 6 and 7 on the example: the values of its README ("The reference node's conventions") --
def test_the_example_serves_the_robot_103_wires(built: list[KnowledgeGraph]) -> None:
    session = Session(_build(built, EXAMPLE / "manifest.toml").cell_model())
    served = []
    while not (wire := cursors.group_connection_provider(session)).end:
        served.append(wire.list_position)
    assert len(served) == 103 and 93 not in served and served[0] == 0


def test_the_example_hands_the_target_as_component_pose(built: list[KnowledgeGraph]) -> None:
    model = _build(built, EXAMPLE / "manifest.toml").cell_model()
    end = cursors.full_connection_provider(Session(model))
    assert (end.source, end.label, end.pin) == ("orig", "F1500.1", "14")
    assert end.component_pose is not None
    assert end.component_pose.position == pytest.approx((0.097, 0.6085, 0.2545))
    assert end.component_pose.orientation == pytest.approx((1.0, 0.0, 0.0, 0.0))
    wire = cursors.group_connection_provider(Session(model))
    assert wire.origin is not None and wire.origin.component_pose is not None
    assert wire.origin.component_pose.position == pytest.approx((0.097, 0.6085, 0.2545))


def test_the_example_moves_the_pins_with_the_detected_target(built: list[KnowledgeGraph]) -> None:
    from cadkg.geometry.poses import Pose

    model = _build(built, EXAMPLE / "manifest.toml").cell_model()
    turned = (1.0, 0.0, 0.0, 0.0)  # a half turn about x
    at_cad = answers.get_item_screw_targets(model, "F1500.1", Pose((0.097, 0.6085, 0.2545), turned))
    moved = answers.get_item_screw_targets(model, "F1500.1", Pose((0.107, 0.6085, 0.2545), turned))
    assert at_cad.success and moved.success
    pin = moved.pins.index("13")
    assert at_cad.screws[pin].position == pytest.approx((0.1195, 0.647, 0.0675))
    assert moved.screws[pin].position == pytest.approx((0.1295, 0.647, 0.0675))
    assert moved.holes[pin].position == pytest.approx((0.1295, 0.642, 0.0595))


# -- 5 on the example: the target turned a half turn about x, the corner the box's minimum ------
@pytest.mark.parametrize(
    ("label", "corner", "orientation"),
    [
        ("F1500.1", (0.07, 0.56, 0.0075), (1.0, 0.0, 0.0, 0.0)),
        ("SSB-10Q1", (0.5544, 0.56, 0.0075), (0.70710678, 0.70710678, 0.0, 0.0)),  # turned +90° about z
        ("B0040.3", (0.4178, 0.86, 0.0075), (0.0, 1.0, 0.0, 0.0)),  # turned 180° about z
    ],
)
def test_the_example_targets_point_into_the_plate(
    built: list[KnowledgeGraph], label: str, corner: tuple[float, ...], orientation: tuple[float, ...]
) -> None:
    result = answers.cad_reference(_build(built, EXAMPLE / "manifest.toml").cell_model(), label)
    assert result.success and result.corner_pose is not None and result.target_pose is not None
    assert result.corner_pose.position == pytest.approx(corner, abs=1e-6)
    q = result.target_pose.orientation
    assert q == pytest.approx(orientation, abs=1e-6) or q == pytest.approx(
        [-v for v in orientation], abs=1e-6
    )


# -- 7 on the example: full_cad_service by the node's cad_item ------------------------------------
def test_the_example_answers_full_cad_service_by_cad_item(built: list[KnowledgeGraph]) -> None:
    model = _build(built, EXAMPLE / "manifest.toml").cell_model()
    # ID000046 is F1500.1's auxiliary contact: the component's target, the wires on its pins.
    result = answers.full_cad_service(model, cad_item="ID000046")
    assert result.success and result.target_pose is not None
    assert result.target_pose.position == pytest.approx((0.097, 0.6085, 0.2545))
    assert {c.pin for c in result.connections} <= {"13", "14", "21", "22"}
    first = [c for c in result.connections if c.pin == "14"]
    assert [(c.wire, c.source, c.target_item, c.target_pin, c.list_position) for c in first] == [
        ("1500.51", "orig", "ID000052", "A1", 0)
    ]


def test_the_example_keeps_a_wire_whose_end_the_workbook_lost(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # As on the real gearbox_zero workbook: a destination EPLAN could not evaluate shows #NAME?.
    cell = tmp_path / "cell"
    shutil.copytree(EXAMPLE, cell)
    replace_in_member(
        cell / "lista-cablaggio.xlsx",
        "xl/worksheets/sheet1.xml",
        b'<c r="F5" t="inlineStr"><is><t>=-Q1500.1:A1</t></is></c>',
        b'<c r="F5" t="e"><f>-basta</f><v>#NAME?</v></c>',
    )
    kg = _build(built, cell / "manifest-vrml.toml")
    session = Session(kg.cell_model())
    first = cursors.group_connection_provider(session)
    assert (first.wire, first.list_position, first.missing_pin_data) == ("1500.51", 0, "?:?")
    assert first.origin is not None and (first.origin.label, first.origin.pin) == ("F1500.1", "14")
    assert len(session.model.steps) == 110  # no wire left out
    assert [f.message for f in validate(kg, shacl=False) if f.check == "lost-wire-end"] == [
        "wire 1500.51: the list gives no reference for its destination; it is kept with missing pin data"
    ]
