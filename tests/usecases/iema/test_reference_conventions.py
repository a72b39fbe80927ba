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
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.usecases.iema import answers, cursors
from cadkg.usecases.iema.robot_scope import scope_reason
from tests.conftest import ROOT
from tests.ingest.workbooks import replace_in_member, write_ods, write_xlsx

MINI = ROOT / "tests" / "data" / "cells" / "mini"
EXAMPLE = ROOT / "examples" / "iema-switchgear"


def _mini(tmp_path: Path, rows: dict[int, tuple[int, str]] | None = None, derive: str = "") -> Path:
    """A copy of the mini cell; ``rows`` replaces cells of connections.tsv (line → column, text)."""
    cell = tmp_path / "mini"
    shutil.copytree(MINI, cell)
    lines = (cell / "connections.tsv").read_text(encoding="utf-8").splitlines()
    for line, (column, text) in (rows or {}).items():
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
    assert scope_reason("Q", ("K1", "X1"), zones, {"K1"}) is None  # the zone decides, not the labels
    assert scope_reason("P", ("K1",), zones, {"K1"}) == "zone P is not among the robot zones Q, QE"
    assert scope_reason(None, ("K1", "M1"), zones, {"K1"}) == "label M1 is not in the CAD (no ID table row)"
    assert scope_reason("", ("K1",), zones, {"K1"}) is None


def test_a_wire_of_another_zone_goes_to_a_person_with_the_reason(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # Line 3 of connections.tsv is W2 (K1:13 → X1:2:b); its origin zone becomes P.
    kg = _build(built, _mini(tmp_path, {3: (1, "P")}))
    assert _served(kg) == ["W1", "W4"]  # W3 is assigned to a person by the overlay
    w2 = next(c for c in answers.full_cad_service(kg.cell_model(), "K1").connections if c.wire == "W2")
    assert (w2.performer, w2.reason) == ("human", "zone P is not among the robot zones Q, QE")
    rows = kg.query(
        """SELECT ?number ?who ?why WHERE { GRAPH ?g { ?w ck:assignedTo ?who ; ck:assignmentReason ?why }
             ?w ck:wireNumber ?number }"""
    ).rows
    assert [(r["number"], r["who"].rsplit("#")[-1], r["why"]) for r in rows] == [
        ("W2", "human", "zone P is not among the robot zones Q, QE")
    ]
    findings = [str(f) for f in validate(kg, shacl=False) if f.check == "wire-for-a-person"]
    assert findings == [
        "connections.tsv:3: warning: wire W2 is given to a person:"
        " zone P is not among the robot zones Q, QE [wire-for-a-person]"
    ]


def test_the_manifest_names_the_robot_zones(tmp_path: Path, built: list[KnowledgeGraph]) -> None:
    kg = _build(built, _mini(tmp_path, {3: (1, "P")}, 'robot_zones = ["Q", "P"]'))
    assert _served(kg) == ["W1", "W2", "W4"]
    assert sorted(r["z"] for r in kg.query("SELECT ?z WHERE { ?c ck:robotZone ?z }")) == ["P", "Q"]


def test_a_list_without_zones_hands_the_robot_the_wires_between_cad_labels(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    # W4 ends on K9, which no ID table row names.
    kg = _build(built, _mini(tmp_path, {line: (1, "") for line in (2, 3, 4, 5)}))
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
    assert (first.destination.label, first.destination.pin, first.wire_path) == ("Q1500.1", "A1", "=-U2")
    assert cursors.reset_to_connection_list(session, 0, "dest").success
    end = cursors.full_connection_provider(session)
    assert (end.source, end.label, end.pin, end.list_position) == ("dest", "Q1500.1", "A1", 0)


def test_a_quote_separated_duct_path_gives_the_same_keypoints(
    tmp_path: Path, built: list[KnowledgeGraph]
) -> None:
    cell = tmp_path / "example"
    shutil.copytree(EXAMPLE, cell)
    listing = cell / "lista-cablaggio.csv"
    listing.write_bytes(listing.read_bytes().replace(b";=-", b"'=-"))
    semicolons = _build(built, EXAMPLE / "manifest.toml").cell_model()
    quotes = _build(built, cell / "manifest.toml").cell_model()
    several = [s for s in semicolons.steps if len(s.ducts) > 1]
    assert several and several[0].path.count(";") == len(several[0].ducts) - 1
    by_wire = {s.iri: s for s in quotes.steps}
    for step in semicolons.steps:
        other = by_wire[step.iri]
        assert other.path == step.path.replace(";", "'")
        assert (other.ducts, other.keypoints) == (step.ducts, step.keypoints)
