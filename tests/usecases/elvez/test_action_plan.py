"""The ELVEZ action plan reader: the example's plan in order, and located errors."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.usecases.elvez.action_plan import PlannedOperation, read_action_plan
from tests.conftest import ROOT

PLAN = ROOT / "examples" / "elvez-cell" / "action-plan.csv"

Write = Callable[[str, str | bytes], Path]


def test_example_plan_in_order() -> None:
    plan = read_action_plan(PLAN)
    assert [op.index for op in plan] == list(range(1, 15))
    assert "".join(op.kind[0] for op in plan) == "irrtirrrtirrrt"
    assert plan[0] == PlannedOperation(1, "insert", ("C10",), ("H1", "CH1"), "gripper_left", 2)
    assert plan[6] == PlannedOperation(
        7, "route", ("W205", "W206", "W207"), ("G1", "G4", "G6"), "gripper_right", 8
    )
    assert len(plan[13].components) == 11 and plan[13].tool == "taping_gun"


def test_tab_separated_with_capitals(write: Write) -> None:
    path = write("p.tsv", "Index\tOperation\tComponents\tSpots\tTool\n1\tTAPE\tW1;W2\tG1\tgun\n")
    assert read_action_plan(path) == [PlannedOperation(1, "tape", ("W1", "W2"), ("G1",), "gun", 2)]


HEADER = "index,operation,components,spots,tool\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEADER, r"p\.csv:1: no operations after the header"),
        ("index,operation,components,tool\n1,route,W1,g\n", r"p\.csv:1: missing column 'spots'"),
        (HEADER + "2,route,W1,G1,g\n", r"p\.csv:2: operation index out of sequence \(found '2', expected 1"),
        (
            HEADER + "1,route,W1,G1,g\n1,tape,W1,G1,g\n",
            r"p\.csv:3: operation index out of sequence \(found '1'",
        ),
        (HEADER + "1,solder,W1,G1,g\n", r"p\.csv:2: unknown operation type \(found 'solder'"),
        (HEADER + "1,route,,G1,g\n", r"p\.csv:2: malformed components of operation 1"),
        (HEADER + "1,route,W1;;W2,G1,g\n", r"p\.csv:2: malformed components of operation 1 \(found 'W1;;W2'"),
        (HEADER + "1,route,W1,G1;G1,g\n", r"p\.csv:2: a name is given twice in the spots of operation 1"),
        (HEADER + "1,insert,C1;C2,H1,g\n", r"p\.csv:2: insert operation 1 names 2 components"),
        (HEADER + "1,route,W1,G1,\n", r"p\.csv:2: malformed tool of operation 1"),
        ("step,kind\n1,route\n", r"p\.csv:1: no header row found"),
    ],
)
def test_located_errors(write: Write, text: str, message: str) -> None:
    with pytest.raises(IngestError, match=message):
        read_action_plan(write("p.csv", text))
