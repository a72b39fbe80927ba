"""The bundled ELVEZ cell through the command line: build a store, call the services, query it.

The expected poses are the hand computation of examples/elvez-cell/README.md.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from cadkg.cli import cli
from cadkg.graph import KnowledgeGraph
from tests.conftest import EXAMPLES

MANIFEST = EXAMPLES / "elvez-cell" / "manifest.toml"


def run(*args: str | Path) -> Result:
    """``cadkg ARGS`` in this process (click's runner): what a user would see, without a new Python."""
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("elvez") / "store"
    result = run("build", MANIFEST, "--store", target)
    assert result.exit_code == 0, result.output
    for kind in ("element-models", "harness-structure", "harness-components", "tools", "action-plan"):
        assert kind in result.stdout
    return target


def call(store: Path, *args: str) -> dict[str, Any]:
    result = run("call", store, *args)
    data: dict[str, Any] = json.loads(result.stdout)
    # The exit status follows the answer: 1 when it says success: false.
    assert result.exit_code == (0 if data.get("success", True) else 1), result.output
    return data


def pose(position: tuple[float, float, float], yaw_degrees: float) -> tuple[float, ...]:
    """x, y, z, qx, qy, qz, qw of a pose turned about z only."""
    half = math.radians(yaw_degrees) / 2
    return (*position, 0.0, 0.0, math.sin(half), math.cos(half))


def printed(data: dict[str, Any]) -> tuple[float, ...]:
    """The same numbers of a pose as ``cadkg call`` prints it."""
    return (*data["position"].values(), *data["orientation"].values())


def test_guide_info_prints_g4_in_the_robot_base_frame(store: Path) -> None:
    data = call(store, "guide_info", "name=G4")
    assert data["success"] is True
    assert (data["id"], data["frame"]) == ("ID000005", "robot_base")
    # README, "G4 in the robot base frame": origin (0.70, 0.10, 0.08) turned -60°; key
    # (0.705, 0.10 - 0.005√3, 0.12) and key corner (0.6975 - 0.0015√3, 0.0985 + 0.0025√3, 0.095)
    # turned 30°.
    assert printed(data["origin_frame"]) == pytest.approx(pose((0.70, 0.10, 0.08), -60), abs=1e-12)
    assert printed(data["key_frame"]) == pytest.approx(
        pose((0.705, 0.1 - 0.005 * math.sqrt(3), 0.12), 30), abs=1e-12
    )
    corner = (0.6975 - 0.0015 * math.sqrt(3), 0.0985 + 0.0025 * math.sqrt(3), 0.095)
    assert printed(data["key_corner_frame"]) == pytest.approx(pose(corner, 30), abs=1e-12)
    assert data["dimensions"] == pytest.approx([0.04, 0.03, 0.05])
    assert (data["key_length"], data["key_gap"], data["key_height"]) == pytest.approx((0.03, 0.006, 0.025))


def test_other_services_through_the_command_line(store: Path) -> None:
    assert call(store, "index_op", "index=7")["tool"] == "gripper_right"
    assert call(store, "cable_info", "name=W205")["con_index"] == [5, 1]
    routes = call(store, "wh_routes", "number=1")["routes"]
    assert [(r["cable"], r["guides"]) for r in routes][3] == ("W104", ["G1", "G4", "G5"])
    missing = call(store, "con_info", "name=X1")
    assert missing["success"] is False and missing["message"].startswith("no connector 'X1'")


def test_services_and_queries_are_listed(store: Path) -> None:
    listed = run("services").stdout
    for name in (
        "guide_info",
        "cable_info",
        "con_info",
        "wh_info",
        "all_tools",
        "tool_info",
        "all_op",
        "index_op",
    ):
        assert name in listed
    result = run("query", store, "elvez-operations-at-spot", "label=G4", "--format", "rows-json")
    assert result.exit_code == 0, result.output
    assert [row["index"] for row in json.loads(result.stdout)["rows"]] == [3, 7, 8, 9, 12, 13, 14]


def test_model_meshes_come_with_the_store(store: Path) -> None:
    with KnowledgeGraph.open(store) as kg:
        rows = kg.query(
            "SELECT DISTINCT ?code ?uri WHERE { ?m ck:commercialCode ?code ; ck:hasMesh/ck:meshUri ?uri }"
            " ORDER BY ?code"
        ).rows
        assert [r["code"] for r in rows] == [
            "0001",
            "0002",
            "0003",
            "0009",
            "0010",
            "0011",
            "0012",
            "0020",
            "0021",
        ]
        source = EXAMPLES / "elvez-cell" / "assembly" / "meshes" / "0009.stl"
        assert (kg.files_dir / "meshes/models/0009.stl").read_bytes() == source.read_bytes()


def test_a_bad_file_fails_the_build_with_its_location(tmp_path: Path) -> None:
    import shutil

    cell = tmp_path / "cell"
    shutil.copytree(EXAMPLES / "elvez-cell", cell)
    plan = cell / "action-plan.csv"
    plan.write_text(plan.read_text().replace("7,route,", "7,solder,"))
    result = run("build", cell / "manifest.toml", "--store", tmp_path / "store")
    assert result.exit_code == 2
    assert "action-plan.csv:8: unknown operation type (found 'solder'" in result.stderr
    assert not (tmp_path / "store" / "CURRENT").exists()
