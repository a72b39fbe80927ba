"""The three real cabinets of the reference IEMA node, when a local copy is given.

The node's package has no licence, so its files are not in this repository: set
``CADKG_IEMA_CELLS`` to a local copy of its ``data`` folder (the one holding ``gearbox_zero``,
``gearbox_demo`` and ``remodel``) to run these tests. Each cabinet is built from its ID table and
one connection list; the counts and first wires are those recorded in
docs/formats/iema-real-files.md, the node's own answers on the same files.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.usecases.iema import cursors

DATA = os.environ.get("CADKG_IEMA_CELLS", "")
pytestmark = pytest.mark.skipif(not DATA, reason="CADKG_IEMA_CELLS names no local copy of the real cabinets")

ZERO_LIST = "PROGETTO WIRES_244_IEMA_HILL_Lista_cablaggio"
# cabinet, ID table, connection list → wires the providers serve, wires given to people,
# the first wire (position, origin, destination, number, duct path as written).
CASES = {
    "gearbox_zero csv": (
        "gearbox_zero",
        "gearbox00001_ids.wri",
        ZERO_LIST + ".csv",
        52,
        19,
        (0, "F1500.1:1", "F1500.2:1", "0005L1", "=-U4"),
    ),
    "gearbox_zero xlsx": (
        "gearbox_zero",
        "gearbox00001_ids.wri",
        ZERO_LIST + ".xlsx",
        52,
        19,
        (0, "F1500.1:1", "F1500.2:1", "0005L1", "=-U4"),
    ),
    "gearbox_demo": (
        "gearbox_demo",
        "gearbox_demo_ids.wri",
        "cablaggio.csv",
        50,
        0,
        (0, "F1500.1:14", "Q1500.1:A1", "1500.51", "=-CN2'=-CN3'=-CN5"),
    ),
    "remodel": (
        "remodel",
        "Q1_simplified_ids.wri",
        "TEST1_REMODEL_KOMAX.csv",
        122,
        0,
        (0, "X0V:1:a2", "10F1:X4:A2", "0V", "=-CN2;=-CN3;=-CN4"),
    ),
}


def _build(tmp_path: Path, cabinet: str, ids: str, wiring: str) -> KnowledgeGraph:
    folder = Path(DATA) / cabinet
    manifest = tmp_path / "manifest.toml"
    lines = ["[cell]", f'name = "{cabinet}"', 'profile = "iema"', 'base_iri = "https://example.org/real/"']
    for name in (ids, wiring):
        lines += ["", "[[source]]", f"path = {str(folder / name)!r}"]
    manifest.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return KnowledgeGraph.build(manifest)


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_providers_serve_the_nodes_wires(tmp_path: Path, case: str) -> None:
    cabinet, ids, wiring, served, for_people, first = CASES[case]
    with _build(tmp_path, cabinet, ids, wiring) as kg:
        session = Session(kg.cell_model())
        wires = []
        while not (wire := cursors.group_connection_provider(session)).end:
            wires.append(wire)
        assert len(wires) == served
        assert [w.list_position for w in wires] == list(range(served))
        head = wires[0]
        assert head.origin is not None and head.destination is not None
        assert (
            head.list_position,
            f"{head.origin.label}:{head.origin.pin}",
            f"{head.destination.label}:{head.destination.pin}",
            head.wire,
            head.wire_path,
        ) == first
        people = [f for f in validate(kg, shacl=False) if f.check == "wire-for-a-person"]
        assert len(people) == for_people


def test_the_name_error_row_keeps_wire_0005pe(tmp_path: Path) -> None:
    # The workbook shows #NAME? where the CSV has =-Stop:stop: the wire stays, its end flagged.
    with _build(tmp_path, "gearbox_zero", "gearbox00001_ids.wri", ZERO_LIST + ".xlsx") as kg:
        session = Session(kg.cell_model())
        assert cursors.reset_to_connection_list(session, 51).success
        wire = cursors.group_connection_provider(session)
        # Without a scene every end lacks data; the lost destination is the unknown end ?:?.
        assert wire.wire == "0005PE" and wire.missing_pin_data.split(", ")[-1] == "?:?"
        lost = [f for f in validate(kg, shacl=False) if f.check == "lost-wire-end"]
        assert [f.message for f in lost] == [
            "wire 0005PE: the list gives no reference for its destination; it is kept with missing pin data"
        ]


def test_the_plan_gives_the_robot_the_wires_the_node_serves(tmp_path: Path) -> None:
    # Under the default rules the robot gets the 52 wires of zones Q/QE, as the node serves them.
    from cadkg.plan.cell import plan_cell

    with _build(tmp_path, "gearbox_zero", "gearbox00001_ids.wri", ZERO_LIST + ".csv") as kg:
        plan = plan_cell(kg)
        robot = sorted(s.task.position for s in plan.steps if s.decision.performer == "robot")
        served = sorted(s.position for s in kg.cell_model().steps if s.performer == "robot")
        assert len(plan.steps) == 71 and robot == served and len(robot) == 52
        people = {s.decision.rule for s in plan.steps if s.decision.performer == "human"}
        assert people == {"zone"}
        assert (plan.files.tool_changes, plan.measure.tool_changes, plan.lower_bound) == (57, 35, 30)
        assert plan.files.violations == plan.measure.violations == 0
